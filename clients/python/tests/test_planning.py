"""c.plan / c.plan_stream / c.check_states against a real server: paths
re-checked at a finer resolution, speeds against the model's limits, pose goals
against FK, an OctoMap tree built by hand as an obstacle, errors by field."""
import numpy as np
import pytest

import kinplan

START = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
GOAL = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])


@pytest.fixture()
def ur5(client):
    return client.robot("ur5")


def blocking_ball(ur5):
    """A ball where the tool passes halfway along the straight joint-space line."""
    return kinplan.Sphere(0.12, ur5.fk((START + GOAL) / 2)[:3, 3], id="ball")


def interpolate(q, step):
    out = []
    for a, b in zip(q[:-1], q[1:]):
        n = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        out.extend(a + (b - a) * k / n for k in range(n + 1))
    return np.array(out)


@pytest.mark.parametrize("algorithm", ["rrt_connect", "stomp"])
def test_a_plan_goes_around_the_ball_within_the_speed_limits(client, ur5, algorithm):
    ball = blocking_ball(ur5)
    line = client.check_states(ur5, [START, (START + GOAL) / 2, GOAL], [ball])
    assert list(line.valid) == [True, False, True]

    plan = client.plan(ur5, start=START, goal=GOAL, algorithm=algorithm, scene=[ball], seed=3)
    assert plan.success and plan.valid, plan.message
    np.testing.assert_array_equal(plan.q[0], START)
    np.testing.assert_array_equal(plan.q[-1], GOAL)
    assert plan.t[0] == 0 and np.all(np.diff(plan.t) > 0)
    vmax = ur5.describe().max_velocity
    speeds = np.abs(np.diff(plan.q, axis=0)) / np.diff(plan.t)[:, None]
    assert np.all(speeds <= vmax * (1 + 1e-9))
    assert client.check_states(ur5, interpolate(plan.q, 0.01), [ball]).valid.all()
    assert plan.scores["JD"] == pytest.approx(np.abs(np.diff(plan.q, axis=0)).sum())
    assert "SUCCEEDED" in repr(plan)


def test_padded_motions_give_a_path_free_at_a_fine_resolution(client, ur5):
    ball = blocking_ball(ur5)
    plan = client.plan(ur5, start=START, goal=GOAL, algorithm="rrt_connect", scene=[ball], seed=5,
                       padded_motion=True)
    assert plan.success and plan.valid, plan.message
    assert client.check_states(ur5, interpolate(plan.q, 0.002), [ball]).valid.all()


def test_a_pose_goal_ends_at_the_pose(client, ur5):
    T = ur5.fk(GOAL)
    plan = client.plan(ur5, start=START, pose=T, algorithm="rrt_connect")
    assert plan.success, plan.message
    np.testing.assert_allclose(ur5.fk(plan.q[-1]), T, atol=1e-5)


def test_invalid_start_names_the_obstacle(client, ur5):
    crate = kinplan.Box((0.2, 0.2, 0.2), ur5.fk(START)[:3, 3], id="crate")
    plan = client.plan(ur5, start=START, goal=GOAL, scene=[crate])
    assert plan.status == "INVALID_START"
    assert any(c.endswith(":crate") for c in plan.colliding), plan.colliding


def test_plan_stream_yields_iterations_then_the_plan(client, ur5):
    items = list(client.plan_stream(ur5, start=START, goal=GOAL, algorithm="stomp", scene=[blocking_ball(ur5)]))
    *frames, final = items
    assert isinstance(final, kinplan.Plan) and final.success
    assert frames and all(f.shape == (40, 6) for f in frames)


def hand_made_bt(resolution):
    """A .bt file with one occupied cell at key (32768, 32768, 32768), the cube
    [0, res)^3: child 7 at depth 0, child 0 down to depth 15, an occupied leaf."""
    nodes = bytes([0x00, 0xC0]) + bytes([0x03, 0x00]) * 14 + bytes([0x02, 0x00])
    header = f"# Octomap OcTree binary file\nid OcTree\nsize 16\nres {resolution}\ndata\n".encode()
    return header + nodes


def test_an_octree_cell_is_an_obstacle_where_the_pose_puts_it(client, ur5):
    res = 0.1
    tool = ur5.fk(START)[:3, 3]
    # The cube [0, res)^3 moved so that its centre is the tool point.
    cell = kinplan.OctreeObstacle.from_bt_file_bytes(hand_made_bt(res), pose=tool - res / 2)
    assert cell.resolution == res and len(cell.data) == 32
    hit = client.check_states(ur5, [START], [cell])
    assert not hit.valid[0] and any(c.endswith(":octreeobstacle_0") for c in hit.colliding[0])
    # 0.5 m above the tool, the same cell is clear by about 0.5 - 0.05 m less the tool's size.
    away = kinplan.OctreeObstacle.from_bt_file_bytes(hand_made_bt(res), pose=tool + [0, 0, 0.5] - res / 2)
    clear = client.check_states(ur5, [START], [away], max_distance=2.0)
    assert clear.valid[0] and 0.0 < clear.clearance[0] < 0.45


def test_bad_input_is_named(client, ur5):
    with pytest.raises(kinplan.KinplanError) as e:
        client.plan(ur5, start=[0, 0, np.nan, 0, 0, 0], goal=GOAL)
    assert "start[2]" in str(e.value)
    with pytest.raises(ValueError):
        kinplan.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 5]]).to_proto()
    with pytest.raises(ValueError):
        client.plan(ur5, start=START)
    with pytest.raises(ValueError):
        client.plan(ur5, start=START, goal=GOAL, algorithm="prm")


V = np.array([1.0, 1.2, 1.5, 2.0, 2.0, 2.5])
A = np.array([2.0, 2.5, 3.0, 4.0, 4.0, 5.0])
J = np.array([10.0, 12.0, 15.0, 20.0, 20.0, 25.0])
PATH = np.array([START, [-0.4, -1.0, 1.0, -1.2, -1.2, 0.3], [0.5, -1.4, 1.3, -1.5, -1.5, 0.1], GOAL])


def test_retime_a_line_takes_the_bang_bang_time_and_a_path_keeps_the_limits(ur5):
    line = np.array([START, START + [1.0, 0, 0, 0, 0, 0]])
    # 1 rad at v = 1, a = 2 from rest to rest: 1/1 + 1/2 s
    tr = ur5.retime(line, max_velocity=V, max_acceleration=A)
    assert tr.duration == pytest.approx(1.5, abs=2e-3)
    tr = ur5.retime(PATH, max_velocity=V, max_acceleration=A, path_tolerance=0.05)
    assert tr.q.shape == tr.qd.shape == tr.qdd.shape == (len(tr.t), 6)
    assert np.all(np.abs(tr.qd) <= V * (1 + 1e-6)) and np.all(np.abs(tr.qdd) <= A * (1 + 1e-6))
    np.testing.assert_allclose(tr.q[[0, -1]], PATH[[0, -1]], atol=1e-9)
    # the velocities are the positions' derivative (central differences, 10 ms)
    h = 0.01
    fd = (tr.q[2:-1] - tr.q[:-3]) / (2 * h)
    assert np.all(np.abs(fd - tr.qd[1:-2]) <= A * h + 1e-9)
    assert {"JJ_time", "CMJ_time", "CD"} <= set(tr.scores)


def test_jerk_limited_retime_keeps_every_limit_by_finite_differences_at_1_khz(ur5):
    tr = ur5.retime(PATH, method="jerk_limited", max_velocity=V, max_acceleration=A, max_jerk=J,
                    sample_period=1e-3)
    q = tr.q[:-1]  # the last point may be closer than 1 ms
    h = 1e-3
    assert np.all(np.abs(np.diff(q, 1, axis=0)) / h <= V * (1 + 1e-9))
    assert np.all(np.abs(np.diff(q, 2, axis=0)) / h**2 <= A * (1 + 1e-6))
    assert np.all(np.abs(np.diff(q, 3, axis=0)) / h**3 <= J * (1 + 1e-3))
    one = ur5.retime(np.array([START, START + [1.0, 0, 0, 0, 0, 0]]), method="jerk_limited", max_velocity=V,
                     max_acceleration=A, max_jerk=J)
    # hand-derived S-curve: T_j = a/j = 0.2, T_a = v/a - a/j = 0.3, cruise 0.3
    assert one.duration == pytest.approx(1.7, abs=1e-9)


def test_plan_exposes_velocities_and_accelerations(ur5):
    plan = ur5.plan(START, GOAL, algorithm="rrt_connect",
                    timing={"method": "time_optimal", "max_velocity": V, "max_acceleration": A})
    assert plan.success, plan.message
    assert plan.qd.shape == plan.q.shape == plan.qdd.shape
    assert np.all(np.abs(plan.qd) <= V * (1 + 1e-6)) and np.all(np.abs(plan.qdd) <= A * (1 + 1e-6))
    assert plan.duration == pytest.approx(plan.t[-1])
    default = ur5.plan(START, GOAL, algorithm="rrt_connect")
    assert default.qd.shape == default.q.shape
    np.testing.assert_array_equal(default.qd[[0, -1]], 0.0)


def test_retime_errors_name_the_field(ur5):
    with pytest.raises(kinplan.KinplanError, match="timing.max_jerk"):
        ur5.retime(PATH, method="jerk_limited", max_acceleration=A)
    with pytest.raises(ValueError, match="timing method"):
        ur5.retime(PATH, method="fastest")
