"""The client's plumbing against real server processes: LocalServer, ping,
wait_for_ready, addresses, the exception hierarchy (pickled too), and calls
spread over two replicas surviving the loss of one."""
import os
import pickle

import numpy as np

import grpc
import pytest

import kinplan
from conftest import BACKENDS
from kinplan.client import normalize_target


@pytest.mark.parametrize(
    "typed, target",
    [
        ("localhost", "localhost:50051"),
        ("10.1.2.3:7000", "10.1.2.3:7000"),
        ("http://10.1.2.3:7000/", "10.1.2.3:7000"),
        ("dns:///kinplan.default.svc:50051", "dns:///kinplan.default.svc:50051"),
        ("10.0.0.1, 10.0.0.2:7", "ipv4:10.0.0.1:50051,10.0.0.2:7"),
        (["127.0.0.1:1", "localhost:2"], "ipv4:127.0.0.1:1,127.0.0.1:2"),
        ("::1", "[::1]:50051"),
    ],
)
def test_addresses_people_type_become_grpc_targets(typed, target):
    assert normalize_target(typed) == target


def test_a_tls_url_or_a_path_is_refused_locally():
    with pytest.raises(kinplan.InvalidArgument, match="target"):
        normalize_target("https://example.com")
    with pytest.raises(ValueError):
        normalize_target("host:1/path")


@pytest.mark.parametrize("in_thread", [False, True] if BACKENDS == ["remote", "local"] else [False])
def test_a_local_server_starts_answers_and_stops(in_thread):
    # in_thread: the server a pip install without cargo gets (native extension)
    with kinplan.LocalServer(in_thread=in_thread) as server:
        assert server.running and server.in_thread == in_thread
        with server.client(timeout=5) as c:
            assert 0 < c.ping() < 5
            assert any(r["name"] == "ur5" for r in c.list_robots())
        address = server.address
    assert not server.running
    with kinplan.Client(address, timeout=2) as c:
        with pytest.raises(kinplan.Unavailable) as err:
            c.ping()
    # an Unavailable is a ConnectionError and says what to do
    assert isinstance(err.value, ConnectionError)
    assert "kinplan serve" in str(err.value)


def test_wait_for_ready_gives_up_with_unavailable():
    with kinplan.LocalServer() as server:
        address = server.address
        pid = server.pid
        assert pid is not None and pid != os.getpid()
        os.kill(pid, 0)  # the server process is there
    assert server.pid is None
    with pytest.raises(kinplan.Unavailable):
        kinplan.Client(address, timeout=0.5, wait_for_ready=True)


def test_server_errors_are_builtin_exceptions_too_and_pickle(client):
    with pytest.raises(ValueError) as err:  # InvalidArgument is a ValueError
        client.robot("ur5").fk([0.0] * 5)
    e = err.value
    assert isinstance(e, kinplan.InvalidArgument) and e.code == grpc.StatusCode.INVALID_ARGUMENT
    again = pickle.loads(pickle.dumps(e))
    assert type(again) is kinplan.InvalidArgument and str(again) == str(e)
    assert again.field_violations == e.field_violations
    with pytest.raises(LookupError):  # NotFound
        client.robot("no_such_robot").fk([0.0])
    from test_robot import long_chain_urdf

    with pytest.raises(TimeoutError):  # DeadlineExceeded: a 900-joint model takes > 1 ms to parse
        client.robot(urdf=long_chain_urdf(900)).describe(timeout=1e-3)


def test_calls_over_two_replicas_survive_the_loss_of_one():
    with kinplan.LocalServer() as a, kinplan.LocalServer() as b:
        with kinplan.Client([a.address, b.address], timeout=5, wait_for_ready=True) as c:
            for _ in range(10):
                c.ping()
            a.stop()
            # every call still answers: the gone replica is retried on the other
            for _ in range(20):
                assert c.ping() < 5


def test_notebook_reprs_are_short_and_a_bare_position_means_position_only(client):
    ur5 = client.robot("ur5")
    T = ur5.fk([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    r = ur5.ik(T[:3, 3])
    assert r.success
    # the position is reached, the orientation is free
    np.testing.assert_allclose(ur5.fk(r.q)[:3, 3], T[:3, 3], atol=1e-4)
    assert len(repr(r)) < 300
    path = np.array([T @ np.diag([1, 1, 1, 1]) for _ in range(50)])
    path[:, 0, 3] += np.linspace(0, 0.1, 50)
    track = ur5.track(path)
    assert len(repr(track)) < 300 and "targets" in repr(track)
    run = client.mobile.navigate(start=(0, 0, 0), goal=(2, 0))
    assert len(repr(run)) < 300 and "outcome" in repr(run)


def test_a_urdf_path_gets_a_hint_instead_of_a_parser_error(client):
    with pytest.raises(kinplan.InvalidArgument, match="open\\(path\\).read"):
        client.robot(urdf="robots/arm.urdf")


def test_batch_fk_equals_single_calls_and_batch_jacobians_equal_single_ones(client):
    ur5 = client.robot("ur5")
    rng = np.random.default_rng(3)
    qs = rng.uniform(-2.5, 2.5, size=(25, 6))
    T, J = ur5.fk_batch(qs, jacobians=True)
    assert T.shape == (25, 4, 4) and J.shape == (25, 6, 6)
    for q, t, j in zip(qs, T, J):
        np.testing.assert_allclose(t, ur5.fk(q), atol=1e-12)
        np.testing.assert_allclose(j, ur5.jacobian(q), atol=1e-12)
    with pytest.raises(kinplan.InvalidArgument, match=r"joint_positions\[1\]"):
        ur5.fk_batch([[0.0] * 6, [np.nan] * 6])


def test_ik_batch_takes_one_seed_per_target(client):
    ur5 = client.robot("ur5")
    rng = np.random.default_rng(5)
    qs = rng.uniform(-2.5, 2.5, size=(6, 6))
    Ts = ur5.fk_batch(qs)
    r = ur5.ik_batch(Ts, seed=qs + 0.03, max_restarts=0)
    assert r.succeeded == 6
    for res, q in zip(r.results, qs):
        np.testing.assert_allclose(res.q, q, atol=1e-2)  # each stayed on its own seed's branch (another is > 0.5 rad away)
    with pytest.raises(kinplan.InvalidArgument, match="seeds"):
        ur5.ik_batch(Ts, seed=qs[:5])


@pytest.mark.parametrize("shape", [(1, 1), (3, 6), (200, 7), (1, 200)])
def test_the_fast_matrix_encoder_equals_protobufs_own(shape):
    from kinplan._convert import matrix_to_proto
    from kinplan.v1 import common_pb2

    a = np.random.default_rng(1).normal(size=shape) * 1e3
    a.flat[0] = -0.0
    slow = common_pb2.Matrix(rows=shape[0], cols=shape[1], data=a.ravel().tolist())
    fast = matrix_to_proto(a)
    assert fast == slow and fast.SerializeToString() == slow.SerializeToString()
    assert matrix_to_proto(a.T.copy(order="F").T).data == slow.data  # any memory layout


def test_a_builtin_urdf_comes_back_standard_and_loads_as_the_same_robot(client):
    kr = client.robot("kuka_kr210_r2700_extra")
    text = kr.urdf()
    assert "<robot" in text and "capsule" not in text
    assert "<capsule" in kr.urdf(keep_capsules=True)
    again = client.robot(urdf=text)
    q = [0.2, -1.0, 1.1, 0.3, 0.7, -0.4]
    np.testing.assert_allclose(again.fk(q), kr.fk(q), atol=1e-12)
    assert again.urdf() == text  # an inline model's own text


class _PinocchioLikeSE3:
    """Stands in for pinocchio.SE3 (attribute `homogeneous`)."""

    def __init__(self, m):
        self.homogeneous = m


class _SpatialmathLikeSE3:
    """Stands in for spatialmath.SE3 (attribute `A`)."""

    def __init__(self, m):
        self.A = m


class _ScalarFirstQuaternion:
    """Stands in for spatialmath.UnitQuaternion: `.s` scalar, `.v` vector,
    and `.vec` in w-first order (the trap the issue names)."""

    def __init__(self, xyzw):
        self.s, self.v = xyzw[3], np.asarray(xyzw[:3])
        self.vec = np.r_[xyzw[3], xyzw[:3]]


def test_pose_objects_of_pinocchio_and_spatialmath_are_read_right(client):
    from kinplan._convert import matrix_to_quat

    ur5 = client.robot("ur5")
    T = ur5.fk([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    xyzw = matrix_to_quat(T[:3, :3])
    for target in (_PinocchioLikeSE3(T), _SpatialmathLikeSE3(T), (T[:3, 3], _ScalarFirstQuaternion(xyzw))):
        r = ur5.ik(target)
        assert r.success
        np.testing.assert_allclose(ur5.fk(r.q), T, atol=1e-5)


def test_results_render_as_html_tables_in_notebooks(client):
    ur5 = client.robot("ur5")
    T = ur5.fk([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    ik_html = ur5.ik(T)._repr_html_()
    assert ik_html.startswith("<table>") and "position error (m)" in ik_html
    plan = client.plan(ur5, start=[0.0] * 6, goal=[0.5] * 6, algorithm="rrt_connect")
    assert "JD" in plan._repr_html_() and plan.status in plan._repr_html_()
    *_, summary = client.explore("abb_irb4600_60_205", scene=kinplan.scenes.s0_open_cell(client),
                                 resolution=0.2, pixel_stride=8, max_iterations=1)
    h = summary._repr_html_()
    assert "known ratio" in h and "S0 Tab. 5.3" in h and "&lt;" not in h.split("caption")[0]


def test_the_fast_quaternion_is_bit_identical_to_the_numpy_one():
    from kinplan._convert import _quat_of_rows, matrix_to_quat, quat_to_matrix

    rng = np.random.default_rng(0)
    branches = set()
    for _ in range(3000):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        R = quat_to_matrix(*q)
        branches.add(int(np.trace(R) > 0) if np.trace(R) > 0 else 10 + int(np.argmax(np.diag(R))))
        assert np.array_equal(np.array(_quat_of_rows(R.tolist())), matrix_to_quat(R))
        # and it is the rotation's quaternion, up to sign
        fast = np.array(_quat_of_rows(R.tolist()))
        assert min(np.abs(fast - q).max(), np.abs(fast + q).max()) < 1e-12
    assert branches == {1, 10, 11, 12}  # every branch was exercised


def test_the_ik_request_encoded_by_hand_parses_as_the_message_built_one():
    from kinplan.kinematics import _ik_options_field, _target_wire, ik_options, target_to_pose
    from kinplan._convert import length_delimited, packed_doubles
    from kinplan.v1 import common_pb2, kinematics_pb2

    rng = np.random.default_rng(3)
    short_ref = common_pb2.RobotRef(name="ur5", tip_link="tool0")
    # a reference over 127 bytes: its length takes a two-byte varint
    long_ref = common_pb2.RobotRef(urdf="<robot name='r'>" + " " * 300 + "</robot>", tip_link="tool0")
    for k in range(200):
        ref = long_ref if k % 7 == 0 else short_ref
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        T = np.eye(4)
        T[:3, :3] = q * np.sign(np.linalg.det(q))
        T[:3, 3] = rng.normal(size=3)
        seed = rng.normal(size=6).tolist() if k % 2 else []
        extra = {"max_iterations": 50, "rng_seed": k} if k % 3 else {}
        wire = (length_delimited(1, ref.SerializeToString())
                + length_delimited(2, _target_wire(T if k % 5 else (T[:3, 3], [0.0, 0.0, 0.0, 1.0])))
                + packed_doubles(3, seed)
                + _ik_options_field("lm", "svd", 1e-6, None, False, extra.get("max_iterations"), None, 10, None,
                                    extra.get("rng_seed", 0), None, None, None, None, None, None, False))
        expected = kinematics_pb2.SolveIkRequest(
            robot=ref, target=target_to_pose(T if k % 5 else (T[:3, 3], [0.0, 0.0, 0.0, 1.0])), seed=seed,
            options=ik_options("lm", "svd", max_restarts=10, position_tolerance=1e-6, **extra),
        )
        assert kinematics_pb2.SolveIkRequest.FromString(wire) == expected
