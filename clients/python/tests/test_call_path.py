"""The hot call path of robot.fk and robot.ik: requests encoded by hand,
answers read from bytes, IkResult fields built on first read. Each is checked
against an independent computation: the request the generated message
classes build, the reply the generated classes parse, the eager build of an
answer from its proto, and the FK of the returned joints."""
import copy
import dataclasses
import math
import pickle

import numpy as np
import pytest

from kinplan._convert import (joints, joints_and_field, joints_field, length_delimited, matrix_to_quat, packed_doubles,
                              pose_bytes, pose_to_matrix, quat_to_matrix, target_field, tool_pose_of_fk_reply)
from kinplan.kinematics import IkResult, IkSolution, ik_options, target_to_pose
from kinplan.v1 import common_pb2, kinematics_pb2, robot_pb2

from test_kinematics import TWO_LINK, pose_distance, random_q


def random_pose(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(*q)
    T[:3, 3] = rng.normal(size=3)
    return T


def spy_on_raw_calls(client, monkeypatch):
    """Records the bytes every raw (hand-encoded) call sends (undone after the test:
    the in-process client is shared by the session)."""
    sent = []
    original = client._raw_unary

    def spy(path, response):
        method = original(path, response)

        def call(request, timeout=None):
            sent.append((path, request))
            return method(request, timeout=timeout)

        return call

    monkeypatch.setattr(client, "_raw_unary", spy)
    return sent


# ---- encoding -------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("q", [
    np.array([0.3, -1.2, 1.4, -0.6, 1.2, 0.1]),
    np.arange(12.0)[::2],                                  # not contiguous
    np.array([0.5, -0.25, 2.0], dtype=">f8"),              # big-endian
    np.array([0.1, 0.2, 0.3], dtype=np.float32),
    np.array([1, 2, 3]),
    [0.3, 1, -2.5],
    (0.1, 0.2),
    np.zeros(0),
    [],
    np.linspace(-1.0, 1.0, 40),                            # 320 bytes: a two-byte length
])
def test_joint_fields_are_the_packed_doubles_of_the_joint_list(q):
    expected = packed_doubles(3, joints(q, "seed"))
    assert joints_field(3, q, "seed") == expected
    values, wire = joints_and_field(2, q, "q")
    assert values == joints(q) and all(type(v) is float for v in values)
    assert wire == packed_doubles(2, joints(q))
    # and the generated classes read the same numbers back
    parsed = robot_pb2.ForwardKinematicsRequest.FromString(wire)
    assert list(parsed.joint_positions) == [float(v) for v in np.asarray(q, dtype=float)]


def test_joint_fields_refuse_what_joints_refuses():
    for f in (lambda q: joints_field(3, q, "seed"), lambda q: joints_and_field(3, q, "seed")):
        with pytest.raises(ValueError, match="seed must be one-dimensional, got shape \\(2, 3\\)"):
            f(np.zeros((2, 3)))


def test_the_target_field_is_the_pose_of_the_generated_classes():
    rng = np.random.default_rng(11)
    branches = set()
    for k in range(2000):
        T = random_pose(rng)
        R = T[:3, :3]
        branches.add(1 if np.trace(R) > 0 else 10 + int(np.argmax(np.diag(R))))
        forms = [T, np.asfortranarray(T), T.astype(np.float32)] if k % 50 == 0 else [T]
        for form in forms:
            wire = target_field(form)
            assert wire == length_delimited(2, pose_bytes(form))
            parsed = kinematics_pb2.SolveIkRequest.FromString(wire).target
            quat = matrix_to_quat(np.asarray(form, dtype=float)[:3, :3])
            expected = common_pb2.Pose(
                position=common_pb2.Vec3(x=float(form[0, 3]), y=float(form[1, 3]), z=float(form[2, 3])),
                orientation=common_pb2.Quaternion(x=quat[0], y=quat[1], z=quat[2], w=quat[3]),
            )
            assert parsed == expected
    assert branches == {1, 10, 11, 12}
    I = np.eye(4, dtype=int)  # an integer matrix goes through the list path
    assert target_field(I) == length_delimited(2, pose_bytes(I.astype(float)))


def test_robot_ik_sends_the_request_the_generated_classes_build(client, monkeypatch):
    robot = client.robot("ur5")
    sent = spy_on_raw_calls(client, monkeypatch)
    rng = np.random.default_rng(5)
    T = robot.fk(random_q(robot, rng))
    seeds = [None, np.array([0.1, -1.0, 1.2, 0.0, 0.5, 0.3]), [0, -1, 1, 0, 1, 0], np.arange(6, dtype=np.float32)]
    targets = [T, np.asfortranarray(T), (T[:3, 3], matrix_to_quat(T[:3, :3])), T[:3, 3]]
    for k, (seed, target) in enumerate(zip(seeds, targets)):
        robot.ik(target, seed=seed, max_restarts=k, rng_seed=k)
        path, wire = sent[-1]
        assert path == "/kinplan.v1.KinematicsService/SolveIk"
        position_only = k == 3
        pose = (target if k < 3 else (T[:3, 3], [0.0, 0.0, 0.0, 1.0]))
        expected = kinematics_pb2.SolveIkRequest(
            robot=robot._ref(), target=target_to_pose(pose), seed=[] if seed is None else joints(seed),
            options=ik_options("lm", "svd", max_restarts=k, rng_seed=k, position_only=position_only),
        )
        assert kinematics_pb2.SolveIkRequest.FromString(wire) == expected


def test_robot_fk_sends_the_request_the_generated_classes_build(client, monkeypatch):
    robot = client.robot("franka_panda")
    sent = spy_on_raw_calls(client, monkeypatch)
    for q in (np.array([0.1, -0.2, 0.3, -1.5, 0.2, 1.0, 0.4]), [0, 0, 0, -1, 0, 1, 0]):
        robot.fk(q)
        path, wire = sent[-1]
        assert path == "/kinplan.v1.RobotService/ForwardKinematics"
        assert robot_pb2.ForwardKinematicsRequest.FromString(wire) == robot_pb2.ForwardKinematicsRequest(
            robot=robot._ref(), joint_positions=joints(q))


# ---- FK answers read from bytes --------------------------------------------------------------------------------

def fk_reply(position, quat, **extra):
    return robot_pb2.ForwardKinematicsResponse(
        tool_pose=common_pb2.Pose(position=common_pb2.Vec3(x=position[0], y=position[1], z=position[2]),
                                  orientation=common_pb2.Quaternion(x=quat[0], y=quat[1], z=quat[2], w=quat[3])),
        **extra)


def test_fk_replies_read_from_bytes_equal_the_parsed_message():
    rng = np.random.default_rng(2)
    for _ in range(500):
        T = random_pose(rng)
        reply = fk_reply(T[:3, 3], matrix_to_quat(T[:3, :3]))
        fast = tool_pose_of_fk_reply(reply.SerializeToString())
        assert fast is not None
        np.testing.assert_array_equal(fast, pose_to_matrix(reply.tool_pose))  # bit for bit
        assert np.abs(fast - T).max() < 1e-12  # and the pose it encodes
        assert fast.flags.writeable and fast.dtype == np.float64 and fast.shape == (4, 4)


def test_fk_replies_of_another_layout_are_left_to_the_parser():
    q = [0.1, 0.2, 0.3, math.sqrt(1 - 0.14)]
    other = [
        fk_reply([0.0, 0.5, 1.0], q),                    # a zero coordinate is not on the wire
        fk_reply([0.3, 0.5, 1.0], [0.0, 0.0, 0.0, 1.0]),  # nor are zero quaternion parts
        fk_reply([0.0, 0.5, 1.0], q, model_id=b"m" * 7),  # a zero coordinate and a model id: 69 bytes, other tags
        fk_reply([0.3, 0.5, 1.0], q, links=[robot_pb2.LinkPose(name="a")]),
        robot_pb2.ForwardKinematicsResponse(),
    ]
    for reply in other:
        assert tool_pose_of_fk_reply(reply.SerializeToString()) is None
    assert len(other[2].SerializeToString()) == 69  # the length alone would not tell it apart
    full = fk_reply([0.3, 0.5, 1.0], q).SerializeToString()
    assert tool_pose_of_fk_reply(full[:-1]) is None and tool_pose_of_fk_reply(full + b"\x00") is None


def test_robot_fk_equals_the_generated_stub_and_inline_models_still_learn_their_id(client):
    robot = client.robot("ur5")
    rng = np.random.default_rng(4)
    for _ in range(20):
        q = random_q(robot, rng)
        stub = client._robots.ForwardKinematics(
            robot_pb2.ForwardKinematicsRequest(robot=robot._ref(), joint_positions=q.tolist()), timeout=10)
        np.testing.assert_array_equal(robot.fk(q), pose_to_matrix(stub.tool_pose))
    inline = client.robot(urdf=TWO_LINK)
    T = inline.fk([0.7, 0.0])  # the tool on the elbow axis: 0.4 (cos a, sin a) at height 0.5
    assert np.abs(T[:3, 3] - (0.4 * math.cos(0.7), 0.4 * math.sin(0.7), 0.5)).max() < 1e-12
    assert len(inline.model_id) == 32  # read from the reply that the fast reader left to the parser
    np.testing.assert_array_equal(inline.fk([0.7, 0.0]), T)  # sent by model id now


# ---- IK answers built on first read ----------------------------------------------------------------------------

STATUS = {v: kinematics_pb2.IkStatus.Name(v)[len("IK_STATUS_"):].lower() for v in kinematics_pb2.IkStatus.values()}


def eager_solution(s):
    """An IkSolution built field by field from its proto, independently of the client's code."""
    history = None
    if len(s.position_error_history):
        history = np.array([list(s.position_error_history), list(s.orientation_error_history)]).T
    return (list(s.joints), s.position_error, s.orientation_error, s.iterations, s.elapsed_us, STATUS[s.status],
            s.attempt, history)


def as_tuple(sol):
    return (sol.q.tolist(), sol.position_error, sol.orientation_error, sol.iterations, sol.elapsed_us, sol.status,
            sol.attempt, sol.history)


def check_against_the_proto(r):
    raw = r.raw
    solutions = [eager_solution(s) for s in raw.solutions]
    best = eager_solution(raw.best_attempt) if raw.HasField("best_attempt") else None
    head = solutions[0] if solutions else best
    assert r.success is raw.success and bool(r) is raw.success
    assert r.status == STATUS[raw.status]
    assert (r.attempts, r.total_iterations, r.elapsed_us) == (raw.attempts, raw.total_iterations, raw.elapsed_us)
    assert len(r.solutions) == len(solutions)
    for got, want in zip(r.solutions, solutions):
        g, w = as_tuple(got), want
        assert g[:7] == w[:7]
        assert (g[7] is None and w[7] is None) or np.array_equal(g[7], w[7])
    if best is None:
        assert r.best_attempt is None
    else:
        assert as_tuple(r.best_attempt)[:7] == best[:7]
    if head is None:
        assert r.q is None and math.isnan(r.position_error) and math.isnan(r.orientation_error)
        assert r.iterations == 0
    else:
        assert r.q.tolist() == head[0] and r.q.dtype == np.float64
        assert (r.position_error, r.orientation_error, r.iterations) == head[1:4]
        # one array, as the eager build shared it
        assert r.q is (r.solutions[0].q if r.solutions else r.best_attempt.q)


ORDERS = [
    ("q", "success", "solutions", "best_attempt"),
    ("solutions", "q", "position_error", "status"),
    ("best_attempt", "orientation_error", "solutions", "q"),
    ("status", "elapsed_us", "iterations", "solutions"),
]


@pytest.mark.parametrize("order", ORDERS)
def test_ik_fields_read_in_any_order_equal_the_eager_build_and_the_fk(client, order):
    robot = client.robot("ur5")
    rng = np.random.default_rng(8)
    T = robot.fk(random_q(robot, rng))
    far = np.eye(4)
    far[:3, 3] = (5.0, 0.0, 0.5)
    answers = [
        robot.ik(T, seed=np.zeros(6)),
        robot.ik(T, num_solutions=3, rng_seed=2),
        robot.ik(T, history=True, max_restarts=0),
        robot.ik(far, max_restarts=3),  # unreachable: only a best attempt
    ]
    for r in answers:
        for name in order:
            getattr(r, name)
        check_against_the_proto(r)
    for r in answers[:3]:
        assert r.success
        dp, dr = pose_distance(robot.fk(r.q), T)
        assert dp <= 1e-5 and dr <= 1e-5
        assert abs(r.position_error - dp) < 1e-9
    assert not answers[3].success and answers[3].solutions == [] and answers[3].position_error > 3.0


def test_an_unread_ik_answer_pickles_copies_and_prints_as_the_eager_one(client):
    robot = client.robot("ur5")
    T = robot.fk([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    for make in (pickle.loads, copy.deepcopy, copy.copy):
        r = robot.ik(T, num_solutions=2)
        again = make(pickle.dumps(r)) if make is pickle.loads else make(r)
        check_against_the_proto(again)
        check_against_the_proto(r)
        np.testing.assert_array_equal(again.q, r.q)
    r = robot.ik(T)
    d = dataclasses.asdict(r)
    assert d["q"].tolist() == list(r.raw.solutions[0].joints) and d["status"] == "converged"
    assert repr(robot.ik(T)).startswith("IkResult(success=True, status='converged'")
    assert [f.name for f in dataclasses.fields(IkResult)][:3] == ["success", "q", "position_error"]


def test_an_ik_result_built_by_hand_keeps_its_values():
    q = np.array([1.0, 2.0])
    s = IkSolution(q, 0.1, 0.2, 3, 4, "converged", 0)
    r = IkResult(True, q, 0.1, 0.2, 3, "converged", [s], None, 1, 3, 4)
    assert r.q is q and r.solutions == [s] and r.best_attempt is None and r.raw is None and r.attempts == 1
    with pytest.raises(AttributeError):
        r.not_a_field
    r.__dict__.pop("solutions")
    with pytest.raises(AttributeError, match="solutions"):
        r.solutions  # no proto to build it from


def test_hand_encoded_calls_resend_the_urdf_when_the_server_lost_the_model_id(client):
    robot = client.robot(urdf=TWO_LINK)
    T = robot.fk([0.7, 0.0])
    learned = robot.model_id
    assert len(learned) == 32
    # a model id the server never gave (as after a restart or on another replica): NOT_FOUND, then
    # the request goes again with the URDF text, and the id is learned again
    robot.model_id = bytes(32)
    np.testing.assert_array_equal(robot.fk([0.7, 0.0]), T)
    assert robot.model_id == learned
    robot.model_id = bytes(32)
    r = robot.ik(T, seed=[0.0, 0.0], position_only=True)
    assert r.success and abs(r.q[0] - 0.7) < 1e-4
    assert robot.model_id == learned
