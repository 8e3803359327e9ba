"""The robot part of the client against a real server, checked against
hand-derived kinematics and finite differences."""
import math

import grpc
import numpy as np
import pytest

import kinplan

TWO_LINK = """<robot name="two_link">
  <link name="base"/><link name="upper"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
</robot>"""


def test_list_and_describe(client):
    names = {r["name"]: r["dof"] for r in client.list_robots()}
    assert names["ur5"] == 6 and names["kuka_lbr_iiwa14_r820"] == 7 and names["planar_3"] == 3
    d = client.robot("kuka_kr210_r2700_extra").describe()
    assert d.dof == 6
    assert d.joint_types == ["revolute"] * 6
    # A2 limits −140…−5 degrees, A1 speed 123 deg/s, from the data sheet.
    assert np.allclose(np.degrees([d.lower[1], d.upper[1]]), [-140, -5])
    assert math.isclose(np.degrees(d.max_velocity[0]), 123)


def test_fk_matches_hand_derivation(client):
    kr210 = client.robot("kuka_kr210_r2700_extra")
    with pytest.warns(kinplan.JointLimitWarning):  # A2 = 0 is outside [-140°, -5°]: still computed
        T = kr210.fk(np.zeros(6))
    assert T.shape == (4, 4)
    assert np.allclose(T[:3, 3], [2.915, 0.0, 0.634], atol=1e-9)
    planar = client.robot("planar_2")
    T = planar.fk([0.0, math.pi / 2])
    assert np.allclose(T[:3, 3], [0.5, 0.5, 0.0], atol=1e-12)
    # Tool x axis turned by 90 degrees about z.
    assert np.allclose(T[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)
    T, links = planar.fk([0.3, 0.2], links=True)
    assert list(links) == ["base_link", "link_1", "link_2", "tool0"]
    assert np.allclose(links["tool0"], T)


def test_jacobian_matches_finite_differences(client):
    robot = client.robot("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.4, 0.8, 0.2])
    J = robot.jacobian(q)
    assert J.shape == (6, 6)
    h = 1e-6
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        p_plus = robot.fk(q + dq)[:3, 3]
        p_minus = robot.fk(q - dq)[:3, 3]
        assert np.allclose(J[:3, i], (p_plus - p_minus) / (2 * h), atol=1e-6)


def test_inline_urdf_is_sent_once_then_by_hash(client):
    robot = client.robot(urdf=TWO_LINK)
    a, b = 0.4, -0.7
    T = robot.fk([a, b])
    assert np.allclose(T[:3, 3], [0.4 * math.cos(a), 0.4 * math.sin(a), 0.5])
    assert len(robot.model_id) == 32
    assert robot._ref().WhichOneof("source") == "model_id"
    # A replica that never saw the model: the client resends the URDF.
    robot.model_id = bytes(32)
    T2 = robot.fk([a, b])
    assert np.allclose(T, T2)
    assert len(robot.model_id) == 32 and robot.model_id != bytes(32)


def test_errors_carry_code_and_field(client):
    robot = client.robot("ur5")
    with pytest.raises(kinplan.KinplanError) as err:
        robot.fk([0, float("nan"), 0, 0, 0, 0])
    assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "joint_positions[1]" in err.value.message
    assert err.value.field_violations[0][0] == "joint_positions[1]"
    with pytest.raises(kinplan.KinplanError) as err:
        robot.fk([0, 0, 0])
    assert err.value.code_name == "INVALID_ARGUMENT"
    with pytest.raises(kinplan.KinplanError) as err:
        client.robot("r2d2").fk([])
    assert err.value.code == grpc.StatusCode.NOT_FOUND
    with pytest.raises(kinplan.KinplanError) as err:
        client.robot(urdf="<robot name='broken'><link").describe()
    assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT
    with pytest.raises(ValueError):
        client.robot("ur5", urdf=TWO_LINK)
    # The server still answers.
    assert robot.fk(np.zeros(6)).shape == (4, 4)


def long_chain_urdf(n: int) -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="continuous"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0.01 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>'
        for i in range(n)
    )
    return f'<robot name="long">{links}{joints}</robot>'


def test_timeout_is_honoured(client):
    # A 900-joint model takes far longer than 1 ms to parse.
    robot = client.robot(urdf=long_chain_urdf(900))
    with pytest.raises(kinplan.KinplanError) as err:
        robot.describe(timeout=1e-3)
    assert err.value.code == grpc.StatusCode.DEADLINE_EXCEEDED
    assert robot.describe(timeout=30).dof == 900


def test_pose_conversions_round_trip():
    rng = np.random.default_rng(3)
    for _ in range(50):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(-math.pi, math.pi)
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K  # Rodrigues
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = rng.normal(size=3)
        assert np.allclose(kinplan.pose_to_matrix(kinplan.matrix_to_pose(T)), T, atol=1e-12)


def test_joints_outside_the_limits_warn_and_strict_robots_refuse(client):
    import warnings

    ur5 = client.robot("ur5")
    kr210 = client.robot("kuka_kr210_r2700_extra")
    # radians within the limits: silent
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kr210.fk([0.2, -1.6, 1.7, 0.3, 0.8, -0.2])
    # the KR 210's A2 spans [-140°, -5°]: -90 (meant as degrees) is far outside in radians
    degrees = [10, -90, 90, 0, 45, 0]
    with pytest.warns(kinplan.JointLimitWarning, match="np.radians") as w:
        T = kr210.fk(degrees)
    assert "joint_1 = 10 not in" in str(w[0].message), "names the first joint outside"
    assert T.shape == (4, 4), "a warning, not a refusal: the call still answers"
    with pytest.warns(kinplan.JointLimitWarning):
        kr210.fk_batch(np.array([degrees, np.radians(degrees)]))
    with pytest.warns(kinplan.JointLimitWarning):
        client.score("kuka_kr210_r2700_extra", np.linspace(np.zeros(6), degrees, 10))
    strict = client.robot("kuka_kr210_r2700_extra", strict=True)
    with pytest.raises(kinplan.InvalidArgument, match="radians"):
        strict.jacobian(degrees)
    # the UR5's joints span ±2π: 6.3 rad is outside, 6.2 inside
    with pytest.warns(kinplan.JointLimitWarning):
        ur5.fk([6.3, 0, 0, 0, 0, 0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ur5.fk([6.2, 0, 0, 0, 0, 0])
