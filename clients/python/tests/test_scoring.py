"""Trajectory scoring against a real server, checked against hand-derived
values on planar_2 (two 0.5 m links turning about z, speed limits pi rad/s)."""
import math

import grpc
import numpy as np
import pytest

import kinplan
from kinplan.scoring import Comparison, Scores, trajectory_to_proto

CHORD = 2 * math.sin(0.05)  # tool step on the unit circle for a 0.1 rad turn


def arc(n=5):
    """planar_2: joint 1 stepping 0.1 rad, joint 2 still."""
    return np.column_stack([0.1 * np.arange(n), np.zeros(n)])


def test_straight_joint_move_by_hand(client):
    s = client.score("planar_2", arc(), weights=[2.0, 3.0], series=True)
    assert isinstance(s, Scores)
    assert list(s)[:4] == ["CD", "JD", "OC", "OC_geodesic"]
    assert s["JD"] == pytest.approx(0.4, abs=1e-12)
    assert s["CPC"] == pytest.approx(0.8, abs=1e-12)
    assert s["CD"] == pytest.approx(4 * CHORD, abs=1e-12)
    assert s["OC"] == pytest.approx(0.2, abs=1e-12)
    assert s["OC_geodesic"] == pytest.approx(0.4, abs=1e-12)
    assert s["RDM"] == pytest.approx(4 * CHORD, abs=1e-12)
    assert s["CJ"] == pytest.approx(2 * CHORD**3, abs=1e-12)
    assert s["JJ"] == pytest.approx(0.0, abs=1e-12)
    assert s["cycle_time"] == pytest.approx(0.4 / math.pi, abs=1e-12)
    assert s.waypoints == 5 and s.robot_points == 4
    assert s.cycle_time.segments == pytest.approx([0.1 / math.pi] * 4)
    assert list(s.cycle_time.limiting_joints) == [0, 0, 0, 0]
    assert s.cycle_time.with_potential == []
    assert s.series.cd == pytest.approx([0, CHORD, CHORD, CHORD, CHORD])
    assert s.series.joint_jerk_rate is None and s.time_scaled is None
    # A list of waypoints and a JointTrajectory give the same answer.
    assert dict(client.score("planar_2", arc().tolist(), weights=[2, 3])) == pytest.approx(dict(s))
    assert dict(client.score("planar_2", trajectory_to_proto(arc()), weights=[2, 3])) == pytest.approx(dict(s))
    # Collision vertices: link 2's capsule tip is 1.02 m out.
    v = client.score(client.robot("planar_2"), arc(), robot_points="collision_vertices")
    assert v["RDM"] == pytest.approx(4 * 1.02 * CHORD, abs=1e-12)
    assert "RDM" not in client.score("planar_2", arc(), robot_points="none")


def test_jerk_spike_peaks_time_scaling_and_potential(client):
    d, h = 0.5, 0.5
    q = np.zeros((7, 2))
    q[3, 1] = d  # joint pseudo-jerk 0,0,0,d,3d,3d,d
    s = client.score("planar_2", q, timestamps=h * np.arange(7), series=True)
    assert s["JJ"] == pytest.approx(8 * d)
    assert s["JMJ"] == pytest.approx(3 * d)
    assert s["JJP"] == pytest.approx(3 * math.log10(3 * d) + 4)
    assert s.joint_peak_count == 1
    assert [p.index for p in s.series.joint_peaks] == [4]
    assert s.series.joint_jerk == pytest.approx([0, 0, 0, d, 3 * d, 3 * d, d])
    assert s.time_scaled["JJ"] == pytest.approx(8 * d / h**3)
    assert s.series.joint_jerk_rate[4] == pytest.approx(3 * d / h**3)
    assert s.cycle_time.total == pytest.approx(2 * d / math.pi)
    [p] = s.cycle_time.with_potential
    assert p.index == 3 and p.gain == pytest.approx(2 * d / math.pi)
    # Configurable regression: a = 1, b = 0, floored at 0.
    t = client.score("planar_2", q, jerk_peaks={"joint_log_gain": 1.0, "joint_offset": 0.0, "slowdown_floor": 0.0})
    assert t["JJP"] == pytest.approx(math.log10(3 * d))


def test_reversal_and_short_trajectories(client):
    s = np.linspace(0, 1, 30)[:, None]
    q = np.hstack([0.8 * s, -1.2 + 0.5 * np.sin(3 * s), 1.0 - 0.4 * s**2, 0.3 * np.cos(5 * s), 0.6 * s, -0.9 * s])
    fwd = client.score("kuka_kr210_r2700_extra", q, robot_points="collision_vertices")
    back = client.score("kuka_kr210_r2700_extra", q[::-1], robot_points="collision_vertices")
    for key in ["CD", "JD", "OC", "OC_geodesic", "CPC", "RDM", "cycle_time"]:
        assert fwd[key] > 0 and back[key] == pytest.approx(fwd[key], rel=1e-9), key
    one = client.score("planar_2", arc(1))
    assert all(v == 0.0 for v in one.values())
    three = client.score("planar_2", arc(3))
    assert three["JD"] == pytest.approx(0.2) and three["JJ"] == three["CJ"] == three["JJP"] == 0.0


def test_compare_table(client):
    def ramp(steps):
        return arc(steps + 1)

    c = client.compare({"rrt": [ramp(4), ramp(2)], "ccstomp": [ramp(3)]}, robot="planar_2")
    assert isinstance(c, Comparison)
    assert c.labels == ["rrt", "ccstomp"]
    jd = c["rrt"]["JD"]
    assert jd["mean"] == pytest.approx(0.3)
    assert jd["variance"] == pytest.approx(0.02)
    assert jd["population_variance"] == pytest.approx(0.01)
    assert jd["sum"] == pytest.approx(0.6)
    assert c["ccstomp"]["JD"]["variance"] is None
    assert c.scores["rrt"][1]["JD"] == pytest.approx(0.2)
    rows = c.rows("JD")
    assert [r["set"] for r in rows] == ["rrt", "ccstomp"]
    pd = pytest.importorskip("pandas")
    df = c.to_pandas()
    assert df.loc[("rrt", "JD"), "sum"] == pytest.approx(0.6)
    assert df.index.names == ["set", "criterion"]
    tab = c.to_dataframe("JD")
    assert list(tab.index) == ["rrt", "ccstomp"]
    assert tab.loc["ccstomp", "mean"] == pytest.approx(0.3)
    assert pd.isna(tab.loc["ccstomp", "variance"])


@pytest.mark.parametrize(
    "q, timestamps, field",
    [
        ([[0.0, 0.0], [0.1, 0.0], [0.2, 0.0, 0.0]], None, "trajectory.points[2].positions"),
        ([[0.0, 0.0], [float("nan"), 0.0]], None, "trajectory.points[1].positions[0]"),
        (np.zeros((4, 3)), None, "trajectory.points[0].positions"),
        (arc(4), [0.0, 0.1, 0.1, 0.2], "trajectory.points[2].time_from_start"),
    ],
)
def test_bad_trajectories_name_the_field(client, q, timestamps, field):
    with pytest.raises(kinplan.KinplanError) as err:
        client.score("planar_2", q, timestamps=timestamps)
    assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert err.value.message.startswith(field)
    assert err.value.field_violations[0][0] == field
    assert client.score("planar_2", arc())["JD"] == pytest.approx(0.4)  # still serving


def test_bad_options_and_sets(client):
    with pytest.raises(kinplan.KinplanError) as err:
        client.score("planar_2", arc(), weights=[-1.0, 1.0])
    assert err.value.field_violations[0][0] == "options.joint_weights[0]"
    with pytest.raises(kinplan.KinplanError) as err:
        client.compare({"a": [arc()], "b": []}, robot="planar_2")
    assert err.value.field_violations[0][0] == "sets[1].trajectories"
    with pytest.raises(ValueError):
        client.score("planar_2", arc(), robot_points="vertices")
    with pytest.raises(ValueError):
        client.score("planar_2", arc(), timestamps=[0.0, 1.0])
    with pytest.raises(ValueError):
        client.compare({"a": [arc()]})


@pytest.mark.parametrize("n, m", [(1, 1), (3, 2), (17, 6), (2000, 7), (5, 16)])
def test_fast_encoding_equals_one_point_per_row(n, m):
    rng = np.random.default_rng(n * 100 + m)
    q = rng.normal(size=(n, m))
    q[0, 0] = -0.0
    slow = kinplan.v1.common_pb2.JointTrajectory(
        points=[kinplan.v1.common_pb2.JointPoint(positions=row) for row in q.tolist()]
    )
    assert trajectory_to_proto(q) == slow
    ts = np.cumsum(rng.uniform(0.1, 1.0, size=n))
    for point, t in zip(slow.points, ts):
        point.time_from_start = t
    assert trajectory_to_proto(q, ts) == slow
    assert trajectory_to_proto(q.astype(np.float32)).points[0].positions[0] == pytest.approx(q[0, 0], rel=1e-6)
    with pytest.raises(ValueError):
        trajectory_to_proto(q, ts[:-1])
