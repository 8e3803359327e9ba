"""KinematicsService through the Python client, against a real server. IK
answers are checked with the server's forward kinematics (robot.fk), linear
solves with numpy (lstsq, pinv)."""
import math
import pathlib

import grpc
import numpy as np
import pytest

import kinplan
from kinplan._convert import matrix_to_quat

ARMS = ["kuka_kr210_r2700_extra", "ur5", "franka_panda"]


def random_q(robot, rng):
    d = robot.describe()
    lo, hi = np.maximum(d.lower, -np.pi), np.minimum(d.upper, np.pi)
    return rng.uniform(lo, hi)


def pose_distance(a, b):
    """Position (m) and rotation angle (rad) between two 4x4 poses."""
    dp = np.linalg.norm(a[:3, 3] - b[:3, 3])
    c = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
    return dp, math.acos(max(-1.0, min(1.0, c)))


@pytest.mark.parametrize("name", ARMS)
def test_fk_of_ik_is_the_target(client, name):
    robot = client.robot(name)
    rng = np.random.default_rng(7)
    for _ in range(3):
        T = robot.fk(random_q(robot, rng))
        r = robot.ik(T)
        assert r.success and r.status == "converged", r
        assert isinstance(r.q, np.ndarray) and r.q.shape == (robot.describe().dof,)
        dp, dr = pose_distance(robot.fk(r.q), T)
        assert dp <= 1e-5 and dr <= 1e-5, (dp, dr)
        assert abs(r.position_error - dp) < 1e-9
        assert r.iterations >= 1 and r.best_attempt is None


def test_target_as_position_and_quaternion_and_methods(client):
    robot = client.robot("ur5")
    q = np.array([0.4, -1.1, 1.3, -0.6, 1.2, 0.3])
    T = robot.fk(q)
    pair = (T[:3, 3], matrix_to_quat(T[:3, :3]))  # quaternion x, y, z, w
    for method in ("lm", "jacobian_inverse", "newton"):
        r = robot.ik(pair, seed=np.zeros(6), method=method)
        assert r.success, method
        dp, dr = pose_distance(robot.fk(r.q), T)
        assert dp <= 1e-5 and dr <= 1e-5, method
    r = robot.ik(T, method="lm", linear_solver="angle_relaxation", time_budget=3.0)
    if r.success:
        assert pose_distance(robot.fk(r.q), T)[0] <= 1e-5
    planar = client.robot("planar_6")
    Tp = planar.fk([0.3, 0.4, -0.2, 0.5, 0.1, 0.3])
    for method in ("ccd", "fabrik", "length_relaxation"):
        r = planar.ik(Tp, method=method, position_only=True, max_iterations=1000)
        assert r.success, method
        assert np.linalg.norm(planar.fk(r.q)[:3, 3] - Tp[:3, 3]) <= 1e-5, method
        assert r.orientation_error == 0.0


def test_distinct_solutions_and_determinism(client):
    robot = client.robot("ur5")
    T = robot.fk([1.0, -0.7, 1.9, 0.5, -1.0, 2.0])
    a = robot.ik(T, num_solutions=3, rng_seed=9)
    b = robot.ik(T, num_solutions=3, rng_seed=9)
    assert len(a.solutions) == 3
    for s, t in zip(a.solutions, b.solutions):
        np.testing.assert_array_equal(s.q, t.q)
    qs = np.array([s.q for s in a.solutions])
    for i in range(3):
        assert pose_distance(robot.fk(qs[i]), T)[0] <= 1e-5
        for j in range(i):
            assert np.max(np.abs(qs[i] - qs[j])) >= 1e-3


def test_unreachable_target_flags_the_best_attempt(client):
    robot = client.robot("kuka_kr210_r2700_extra")
    T = np.eye(4)
    T[:3, 3] = (10.0, 0.0, 0.5)
    r = robot.ik(T, max_restarts=10**9, time_budget=0.05)
    assert not r.success and not r
    assert r.status == "time_budget"
    assert r.best_attempt is not None and r.solutions == []
    assert r.position_error > 7.0
    # the call's deadline is the budget when none is given
    r = robot.ik(T, max_restarts=10**9, timeout=0.3)
    assert r.status == "time_budget" and r.elapsed_us < 300_000


def test_batch(client):
    robot = client.robot("kuka_lbr_iiwa14_r820")
    rng = np.random.default_rng(3)
    Ts = np.array([robot.fk(random_q(robot, rng)) for _ in range(10)])
    batch = robot.ik_batch(Ts)
    assert len(batch) == 10 and batch.succeeded == 10 and batch.success.all()
    assert batch.q.shape == (10, 7)
    for q, T in zip(batch.q, Ts):
        assert pose_distance(robot.fk(q), T)[0] <= 1e-5


def test_track_circle_and_line(client):
    robot = client.robot("kuka_kr210_r2700_extra")
    seed = np.array([0.2, -1.6, 1.7, 0.3, 0.8, -0.2])
    T0 = robot.fk(seed)
    centre = T0[:3, 3] - [0.01, 0, 0]
    path = robot.track(seed=seed, circle={"centre": centre, "normal": (0, 0, 1), "angle_step": np.pi / 50, "steps": 100})
    assert path.all_converged and len(path) == 101 and path.q.shape == (101, 6)
    radii = np.linalg.norm(path.targets[:, :3, 3] - centre, axis=1)
    np.testing.assert_allclose(radii, 0.01, atol=1e-12)
    for k in (0, 37, 100):
        assert pose_distance(robot.fk(path.q[k]), path.targets[k])[0] <= 1e-5
    steps = np.max(np.abs(np.diff(np.vstack([seed, path.q]), axis=0)), axis=1)
    np.testing.assert_allclose(steps, path.joint_step, atol=1e-12)
    assert path.max_joint_step < 0.05
    end = T0.copy()
    end[:3, 3] += (0, 0.1, -0.05)
    line = robot.track(seed=seed, line={"end": end, "steps": 10})
    assert line.all_converged and len(line) == 11
    assert pose_distance(robot.fk(line.q[-1]), end)[0] <= 1e-5
    again = robot.track(line.targets, seed=seed)
    np.testing.assert_array_equal(again.q, line.q)


def test_stream(client):
    robot = client.robot("ur5")
    seed = np.array([0.4, -1.1, 1.3, -0.6, 1.2, 0.3])
    T0 = robot.fk(seed)
    with robot.stream_ik(seed=seed, time_budget=0.5) as s:
        prev = seed
        for k in range(8):
            T = T0.copy()
            T[0, 3] += 0.002 * k
            r = s.solve(T)
            assert r.success and r.sequence == k + 1
            assert pose_distance(robot.fk(r.q), T)[0] <= 1e-5
            assert np.max(np.abs(r.q - prev)) < 0.05
            prev = r.q
        # pipelined: answers come back in order
        seqs = [s.send(T0), s.send(T0)]
        assert [next(s).sequence, next(s).sequence] == seqs
    # a bad target ends the stream with the field named
    bad = (T0[:3, 3], (0.0, 0.0, 0.0, 3.0))
    with robot.stream_ik() as s:
        assert s.solve(T0).success
        with pytest.raises(kinplan.KinplanError) as err:
            s.solve(bad)
        assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT
        assert err.value.field_violations[0][0] == "target.orientation"
        assert "sequence 2" in err.value.message


def test_errors_carry_code_and_field(client):
    robot = client.robot("ur5")
    T = robot.fk(np.zeros(6))
    cases = [
        (lambda: robot.ik(T, seed=[0.0] * 5), "seed"),
        (lambda: robot.ik(T, position_tolerance=0.0), "options.position_tolerance"),
        (lambda: robot.ik(T, orientation_tolerance=-1.0), "options.orientation_tolerance"),
        (lambda: robot.ik(T, method="fabrik"), "options.method"),
        (lambda: robot.ik((T[:3, 3], (0, 0, 0.5, 0.5))), "target.orientation"),
        (lambda: robot.ik((T[:3, 3] * np.nan, (0, 0, 0, 1))), "target.position.x"),
        (lambda: robot.track(seed=np.zeros(6), circle={"centre": (0, 0, 0), "normal": (0, 0, 0), "angle_step": 0.1, "steps": 5}), "circle.normal"),
        (lambda: robot.ik_batch([]), "targets"),
        (lambda: client.solve_linear(np.eye(2), [1.0]), "b"),
        (lambda: client.solve_linear(np.eye(2), [1.0, 1.0], "angle_relaxation", tolerance=0.0), "tolerance"),
        (lambda: client.solve_linear(np.zeros((101, 100)), np.zeros(101)), "a"),
    ]
    for call, field in cases:
        with pytest.raises(kinplan.KinplanError) as err:
            call()
        assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT, field
        assert err.value.field_violations[0][0] == field, (field, err.value)
    with pytest.raises(kinplan.KinplanError) as err:
        client.robot("kr1000").ik(T)
    assert err.value.code == grpc.StatusCode.NOT_FOUND
    with pytest.raises(ValueError):
        robot.ik(T, method="simplex")
    assert robot.ik(T).success  # still serving


def test_solve_linear_against_numpy(client):
    rng = np.random.default_rng(5)
    # square, consistent
    A = np.array([[2.0, 1.0], [1.0, 3.0]])
    b = np.array([3.0, 5.0])
    s = client.solve_linear(A, b)
    np.testing.assert_allclose(s.x, np.linalg.solve(A, b), atol=1e-12)
    assert s.converged and s.iterations == 1
    r = client.solve_linear(A, b, "angle_relaxation", tolerance=1e-8, max_iterations=200_000, history=True)
    np.testing.assert_allclose(r.x, [0.8, 1.4], atol=1e-6)
    assert r.converged and len(r.history) == r.iterations and r.history[-1] == r.residual_norm
    # tall, inconsistent: the least-squares solution and residual
    A = rng.normal(size=(6, 3))
    b = rng.normal(size=6)
    x_ls, res, *_ = np.linalg.lstsq(A, b, rcond=None)
    s = client.solve_linear(A, b, "svd")
    np.testing.assert_allclose(s.x, x_ls, atol=1e-10)
    assert abs(s.residual_norm - math.sqrt(res[0])) < 1e-10
    r = client.solve_linear(A, b, "angle_relaxation", tolerance=1e-12, max_iterations=100_000, rng_seed=1)
    assert r.status == "iteration_cap"
    assert math.sqrt(res[0]) - 1e-12 <= r.residual_norm <= math.sqrt(res[0]) + 0.05
    # wide: the minimum-norm solution (pinv)
    A = rng.normal(size=(2, 4))
    b = rng.normal(size=2)
    s = client.solve_linear(A, b)
    np.testing.assert_allclose(s.x, np.linalg.pinv(A) @ b, atol=1e-10)
    # singular square with a zero column: the pseudoinverse solution
    A = np.array([[1.0, 0.0, 2.0], [2.0, 0.0, 4.0], [0.0, 0.0, 1.0]])
    b = np.array([1.0, 2.0, 1.0])
    s = client.solve_linear(A, b, "svd")
    np.testing.assert_allclose(s.x, np.linalg.pinv(A) @ b, atol=1e-10)
    r = client.solve_linear(A, b, "angle_relaxation_safeguarded", tolerance=1e-6, max_iterations=200_000)
    assert r.residual_norm < 1e-6 and r.x[1] == 0.0  # the zero column is skipped


TWO_LINK = """<robot name="two_link">
  <link name="base"/><link name="upper"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
</robot>"""


def test_inline_urdf_by_hand(client):
    # the tool sits on the elbow axis: 0.4 (cos a, sin a) at height 0.5
    robot = client.robot(urdf=TWO_LINK)
    a = 0.7
    T = np.eye(4)
    T[:3, 3] = (0.4 * math.cos(a), 0.4 * math.sin(a), 0.5)
    r = robot.ik(T, seed=[0.0, 0.0], position_only=True)
    assert r.success and abs(r.q[0] - a) < 1e-4
    assert len(robot.model_id) == 32
    again = robot.ik(T, seed=[0.0, 0.0], position_only=True)  # sent by model id now
    np.testing.assert_array_equal(again.q, r.q)


def test_error_history_on_request(client):
    robot = client.robot("ur5")
    q = np.array([1.0, -0.7, 1.9, 0.5, -1.0, 2.0])
    seed = q - 0.1
    T = robot.fk(q)
    r = robot.ik(T, seed=seed, history=True)
    s = r.solutions[0]
    assert s.history.shape == (s.iterations + 1, 2)
    dp, dr = pose_distance(robot.fk(seed), T)
    assert abs(s.history[0, 0] - dp) < 1e-9 and abs(s.history[0, 1] - dr) < 1e-6
    assert tuple(s.history[-1]) == (s.position_error, s.orientation_error)
    assert robot.ik(T, seed=seed).solutions[0].history is None


@pytest.mark.parametrize("name", ["kuka_kr120_r2500_pro", "ur5"])
def test_analytic_ik_returns_every_solution_with_flags(client, name):
    robot = client.robot(name)
    d = robot.describe()
    assert d.analytic_family in ("spherical_wrist", "three_parallel") and d.analytic_reason == ""
    rng = np.random.default_rng(3)
    q = random_q(robot, rng)
    T = robot.fk(q)
    r = robot.ik(T, seed=q, method="analytic", num_solutions=1000)
    assert r.success and r.status == "converged", r
    # the seed's configuration first; every solution reaches T by the server's FK
    assert np.allclose(r.solutions[0].q, q, atol=1e-9)
    configs = set()
    for s in r.solutions[:24]:
        # the 4x4 difference (acos of the trace would lose half the digits)
        err = np.abs(robot.fk(s.q) - T).max()
        assert err <= 1e-9, err
        assert isinstance(s.config, kinplan.ConfigFlags) and not s.singular
        configs.add(s.config)
    dist = [float(np.sum((s.q - q) ** 2)) for s in r.solutions]
    assert dist == sorted(dist)
    assert len(configs) >= 2
    # the iterative methods carry no flags
    assert robot.ik(T, seed=q).solutions[0].config is None


def test_analytic_ik_refuses_a_7_joint_arm_naming_why(client):
    robot = client.robot("planar_7")
    assert robot.describe().analytic_family == ""
    assert "holding any one of them" in robot.describe().analytic_reason
    T = robot.fk([0.1] * 7)
    with pytest.raises(kinplan.InvalidArgument) as e:
        robot.ik(T, method="analytic")
    assert "chain is not analytic" in str(e.value)


def test_analytic_ik_panda_with_joint_7_held_or_searched(client):
    robot = client.robot("franka_panda")
    d = robot.describe()
    assert d.analytic_family == "spherical_two_intersecting" and d.analytic_reversed
    assert d.analytic_held_joint == 6
    q = np.array([0.2, -0.4, 0.3, -2.1, 0.4, 1.8, 0.5])
    T = robot.fk(q)
    seed = q.copy()
    seed[6] += 0.4
    held = robot.ik(T, seed=seed, method="analytic", num_solutions=1000)
    assert held.success and all(s.q[6] == seed[6] for s in held.solutions)
    for s in held.solutions:  # each checked by the server's forward kinematics
        assert np.allclose(robot.fk(s.q), T, atol=1e-9)
    searched = robot.ik(T, seed=seed, method="analytic", search_redundant=True, redundant_samples=64)
    best = searched.solutions[0].q
    assert np.allclose(robot.fk(best), T, atol=1e-9)
    # at least as near the seed as the pose's own joints, which lie 0.4 rad away
    assert np.sum((best - seed) ** 2) <= np.sum((q - seed) ** 2) + 1e-12
    with pytest.raises(kinplan.InvalidArgument) as e:
        robot.ik(T, seed=seed, method="analytic", search_redundant=True, redundant_samples=1)
    assert "redundant_samples" in str(e.value)


def test_analytic_options_hold_turns_and_start(client):
    robot = client.robot("ur5")
    q = np.array([0.3, -1.2, 1.4, -0.8, 1.1, 0.2])
    T = robot.fk(q)
    # one whole-turn variant per joint: the 8 configurations of a generic pose
    r = robot.ik(T, seed=q, method="analytic", num_solutions=1000, nearest_turn_only=True)
    assert len(r.solutions) == 8 and len({s.config for s in r.solutions}) == 8
    # hold_configuration: the seed's flags first even when another configuration is nearer
    other = r.solutions[1]
    held = robot.ik(T, seed=other.q + 0.4, method="analytic", num_solutions=3, hold_configuration=True,
                    options=kinplan.IkOptions(method="analytic", nearest_turn_only=True))
    assert held.solutions[0].config == other.config
    # analytic_start: LM from a far seed begins on the nearest closed-form solution
    far = np.array([1.5, -0.2, 0.3, 0.9, -0.7, 1.4])
    s = robot.ik(T, seed=far, max_restarts=0, analytic_start=True)
    assert s.success and s.iterations == 0


def test_analytic_ik_offset_wrist_is_searched(client):
    # a hand-made 6R arm with an offset wrist (no three axes meet or are parallel)
    text = (pathlib.Path(__file__).resolve().parents[3] / "benches" / "analytic_ik" / "offset_wrist_45.urdf").read_text()
    robot = client.robot(urdf=text)
    d = robot.describe()
    assert d.analytic_family == "searched_6r" and d.analytic_reason == "" and not d.analytic_reversed
    q = np.array([0.4, -0.9, 0.7, 1.0, 0.8, -0.5])
    T = robot.fk(q)
    r = robot.ik(T, seed=q, method="analytic", num_solutions=1000)
    assert r.success and len(r.solutions) >= 2
    assert np.allclose(r.solutions[0].q, q, atol=1e-8)
    for s in r.solutions:
        assert np.abs(robot.fk(s.q) - T).max() <= 1e-9
        assert isinstance(s.config, kinplan.ConfigFlags)
    # the searched joint's sampling density: denser finds the same solutions
    # here (also through IkOptions); below 8 is refused, naming the field
    dense = robot.ik(T, seed=q, method="analytic", num_solutions=1000, search_samples=1024)
    assert len(dense.solutions) == len(r.solutions)
    assert all(np.allclose(a.q, b.q, atol=1e-9) for a, b in zip(dense.solutions, r.solutions))
    opts = kinplan.IkOptions(method="analytic", num_solutions=1000, search_samples=1024)
    assert len(robot.ik(T, seed=q, options=opts).solutions) == len(r.solutions)
    with pytest.raises(kinplan.InvalidArgument) as e:
        robot.ik(T, seed=q, method="analytic", search_samples=4)
    assert "search_samples" in str(e.value)
    # the IkOptions path sends the field too: the same refusal
    with pytest.raises(kinplan.InvalidArgument) as e:
        robot.ik(T, seed=q, options=kinplan.IkOptions(method="analytic", search_samples=4))
    assert "search_samples" in str(e.value)
