"""Every hand-written encoding of kinplan._codec against the generated classes
in kinplan.v1, on seeded random messages (no server needed)."""
import math
import pathlib
import struct

import numpy as np
import pytest

from kinplan import _codec
from kinplan._rotation import (matrix_to_quat, pose_values_to_matrix, poses_to_matrices, quat_of_rows, quat_to_matrix,
                               rotation_rows)
from kinplan.v1 import common_pb2, kinematics_pb2, robot_pb2

PACKAGE = pathlib.Path(_codec.__file__).parent


def random_quat(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def random_pose(rng):
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(*random_quat(rng))
    T[:3, 3] = rng.normal(size=3) * 10.0 ** rng.integers(-3, 3)
    return T


def random_double(rng):
    """Doubles of every kind the wire carries: zeros of both signs, tiny, huge, infinite, ordinary."""
    k = rng.integers(8)
    return [0.0, -0.0, 5e-324, 1e300, math.inf, -math.inf, float(rng.normal()), float(rng.normal() * 1e-9)][k]


def pose_message(px, py, pz, x, y, z, w):
    return common_pb2.Pose(position=common_pb2.Vec3(x=px, y=py, z=pz),
                           orientation=common_pb2.Quaternion(x=x, y=y, z=z, w=w))


def test_field_numbers_are_the_descriptors():
    assert _codec.FK_JOINTS == robot_pb2.ForwardKinematicsRequest.DESCRIPTOR.fields_by_name["joint_positions"].number
    assert _codec.IK_TARGET == kinematics_pb2.SolveIkRequest.DESCRIPTOR.fields_by_name["target"].number
    assert _codec.IK_SEED == kinematics_pb2.SolveIkRequest.DESCRIPTOR.fields_by_name["seed"].number
    assert _codec.IK_OPTIONS == kinematics_pb2.SolveIkRequest.DESCRIPTOR.fields_by_name["options"].number
    assert _codec.ROBOT_REF == kinematics_pb2.SolveIkRequest.DESCRIPTOR.fields_by_name["robot"].number


def test_varints_are_protobufs():
    rng = np.random.default_rng(20)
    values = [0, 1, 127, 128, 255, 16383, 16384, 2 ** 32 - 1, 2 ** 63, 2 ** 64 - 1]
    values += [int(rng.integers(0, 2 ** 63)) >> int(rng.integers(0, 63)) for _ in range(2000)]
    rng_seed = kinematics_pb2.IkOptions.DESCRIPTOR.fields_by_name["rng_seed"].number
    for n in values:
        wire = _codec.varint(_codec.tag(rng_seed, _codec.VARINT)) + _codec.varint(n)
        assert wire == kinematics_pb2.IkOptions(rng_seed=n).SerializeToString() or n == 0
        assert kinematics_pb2.IkOptions.FromString(wire).rng_seed == n


def test_length_delimited_fields_are_protobufs():
    rng = np.random.default_rng(21)
    urdf = common_pb2.RobotRef.DESCRIPTOR.fields_by_name["urdf"].number
    for _ in range(500):
        text = "x" * int(rng.choice([0, 1, 127, 128, 300, 16384, int(rng.integers(0, 20000))]))
        wire = _codec.length_delimited(urdf, text.encode())
        assert common_pb2.RobotRef.FromString(wire) == common_pb2.RobotRef(urdf=text)
        if text:
            assert wire == common_pb2.RobotRef(urdf=text).SerializeToString()
    # a field number of 16 or more takes a two-byte key
    assert _codec.length_delimited(17, b"ab") == _codec.varint(17 << 3 | 2) + b"\x02ab"


@pytest.mark.parametrize("kind", ["list", "f64", "f32", "int", "strided", "big_endian"])
def test_joint_fields_are_the_generated_packed_doubles(kind):
    rng = np.random.default_rng(22)
    for _ in range(300):
        n = int(rng.choice([0, 1, 6, 7, 15, 16, 17, 40, int(rng.integers(0, 100))]))
        values = np.array([random_double(rng) for _ in range(n)])
        if kind == "list":
            q = values.tolist()
        elif kind == "f64":
            q = values
        elif kind == "f32":
            q = rng.normal(size=n).astype(np.float32)
        elif kind == "int":
            q = rng.integers(-10, 10, n)
        elif kind == "strided":
            q = np.repeat(values, 2)[::2]
        else:
            q = values.astype(">f8")
        expected = robot_pb2.ForwardKinematicsRequest(joint_positions=np.asarray(q, dtype=float).tolist())
        field = _codec.FK_JOINTS
        for wire in (_codec.joints_field(field, q, "q"), _codec.joints_and_field(field, q, "q")[1],
                     _codec.packed_doubles(field, _codec.joints(q))):
            assert wire == expected.SerializeToString()
        assert _codec.joints_and_field(field, q, "q")[0] == expected.joint_positions[:]


def test_poses_are_the_generated_pose_messages():
    rng = np.random.default_rng(23)
    for k in range(3000):
        T = random_pose(rng)
        if k % 10 == 0:
            T[:3, 3] = [random_double(rng) for _ in range(3)]
        x, y, z, w = quat_of_rows(T.tolist())
        expected = pose_message(T[0, 3], T[1, 3], T[2, 3], x, y, z, w)
        assert common_pb2.Pose.FromString(_codec.pose_wire(T)) == expected
        request = kinematics_pb2.SolveIkRequest.FromString(_codec.target_field(T))
        assert request == kinematics_pb2.SolveIkRequest(target=expected)
        field = int(rng.integers(1, 16))
        assert _codec.pose_field(field, T) == _codec.length_delimited(field, _codec.pose_wire(T))


def random_fk_reply(rng):
    """A ForwardKinematicsResponse of any content the proto allows, and its encodings."""
    values = [random_double(rng) if rng.random() < 0.3 else float(rng.normal()) for _ in range(3)]
    quat = random_quat(rng)
    quat[rng.random(4) < 0.1] = 0.0
    reply = robot_pb2.ForwardKinematicsResponse(tool_pose=pose_message(*values, *quat.tolist()))
    if rng.random() < 0.2:
        reply.model_id = bytes(rng.integers(0, 256, int(rng.integers(0, 40)), dtype=np.uint8))
    if rng.random() < 0.2:
        reply.links.add(name="link", pose=pose_message(*rng.normal(size=7).tolist()))
    if rng.random() < 0.05:
        reply.ClearField("tool_pose")
    wires = [reply.SerializeToString()]
    # a tool pose sent twice (a parser merges them: a value the second omits
    # is the first's), and an unknown field appended
    earlier = common_pb2.Pose(position=common_pb2.Vec3(x=1.5, y=-2.0), orientation=common_pb2.Quaternion(z=0.6))
    wires.append(_codec.length_delimited(1, earlier.SerializeToString()) + reply.SerializeToString())
    wires.append(reply.SerializeToString() + _codec.varint(_codec.tag(99, _codec.VARINT)) + b"\x01")
    return wires


def test_fk_replies_of_any_layout_read_as_the_generated_parser_reads_them():
    rng = np.random.default_rng(24)
    fixed = 0
    for _ in range(3000):
        for wire in random_fk_reply(rng):
            parsed = robot_pb2.ForwardKinematicsResponse.FromString(wire)
            p, o = parsed.tool_pose.position, parsed.tool_pose.orientation
            expected = pose_values_to_matrix(p.x, p.y, p.z, o.x, o.y, o.z, o.w)
            tool, model_id = _codec.read_fk_reply(wire)
            np.testing.assert_array_equal(tool, expected)
            assert model_id == parsed.model_id
            fast = _codec.tool_pose_of_fk_reply(wire)
            if fast is not None:
                fixed += 1
                np.testing.assert_array_equal(fast, expected)
                assert not parsed.links and not parsed.model_id
    assert fixed > 1000  # the usual layout was met, and read from its bytes


def test_matrices_are_the_generated_matrix_messages():
    rng = np.random.default_rng(25)
    for _ in range(300):
        shape = (int(rng.integers(0, 40)), int(rng.integers(1, 40)))
        a = rng.normal(size=shape) * 10.0 ** rng.integers(-5, 5)
        expected = common_pb2.Matrix(rows=shape[0], cols=shape[1], data=a.ravel().tolist())
        for form in (a, np.asfortranarray(a), a.astype(">f8")):
            assert _codec.matrix_message(form) == expected
    with pytest.raises(ValueError, match="two-dimensional"):
        _codec.matrix_message(np.zeros(3))


def test_trajectories_are_the_generated_trajectory_messages():
    rng = np.random.default_rng(26)
    for k in range(300):
        n, m = int(rng.integers(1, 60)), int(rng.integers(1, 30))
        q = rng.normal(size=(n, m))
        ts = np.cumsum(rng.random(n)) if k % 2 else None
        expected = common_pb2.JointTrajectory(points=[
            common_pb2.JointPoint(positions=row, time_from_start=0.0 if ts is None else float(ts[i]))
            for i, row in enumerate(q.tolist())])
        assert _codec.trajectory_message(q, ts) == expected
        assert _codec.trajectory_message(np.asfortranarray(q), ts) == expected


def test_quaternions_and_matrices_are_one_rotation():
    rng = np.random.default_rng(27)
    quats = np.array([random_quat(rng) for _ in range(2000)])
    branches = set()
    for q in quats:
        R = quat_to_matrix(*q)
        branches.add(1 if np.trace(R) > 0 else 10 + int(np.argmax(np.diag(R))))
        back = matrix_to_quat(R)
        assert min(np.abs(back - q).max(), np.abs(back + q).max()) < 1e-12
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert branches == {1, 10, 11, 12}
    poses = np.column_stack([rng.normal(size=(len(quats), 3)), quats])
    batch = poses_to_matrices(poses)
    for T, p in zip(batch, poses.tolist()):
        np.testing.assert_array_equal(T, pose_values_to_matrix(*p))  # the same products, bit for bit
    rows = rotation_rows(*quats.T)
    np.testing.assert_array_equal(np.array(rows).transpose(2, 0, 1), batch[:, :3, :3])


def test_no_other_module_writes_protobuf_by_hand():
    for path in PACKAGE.rglob("*.py"):
        if path.name == "_codec.py" or "v1" in path.relative_to(PACKAGE).parts:
            continue
        text = path.read_text()
        assert "import struct" not in text and "struct.Struct" not in text, path
        assert "def _varint" not in text and "<< 3" not in text and 'b"\\x' not in text, path
