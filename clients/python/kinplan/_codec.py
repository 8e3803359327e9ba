"""The protobuf encodings kinplan writes and reads by hand, in one place.

Hand-written bytes are kept only on the hot calls where a benchmark showed
them to pay (``examples/codec_benchmark.py`` times each against the generated
classes): a joint vector as a packed double field, a 4x4 pose as a ``Pose``
(the IK target), a float array as a ``Matrix`` or a ``JointTrajectory``, and
the usual ``ForwardKinematicsResponse`` read from its bytes. Everything else
goes through the generated classes in :mod:`kinplan.v1`.

Field numbers and tags are read from the generated descriptors, never
written as literals; ``tests/test_codec.py`` checks every function here
against the generated classes on random messages.
"""
from __future__ import annotations

import struct
from typing import Any, List, Optional, Tuple

import numpy as np

from ._rotation import pose_values_to_matrix, quat_of_rows
from .v1 import common_pb2, kinematics_pb2, robot_pb2

#: Wire types (https://protobuf.dev/programming-guides/encoding/).
VARINT, I64, LEN = 0, 1, 2


def field_number(message: Any, name: str) -> int:
    """The number of field `name` of a generated message class."""
    return int(message.DESCRIPTOR.fields_by_name[name].number)


def tag(field: int, wire_type: int) -> int:
    """The key of a field (field numbers below 16 give a one-byte key)."""
    return field << 3 | wire_type


def _one_byte_tag(message: Any, name: str, wire_type: int) -> int:
    t = tag(field_number(message, name), wire_type)
    if t >= 128:  # the struct layouts below hold one-byte keys
        raise RuntimeError(f"{message.DESCRIPTOR.full_name}.{name}: field number too large for the fixed layouts")
    return t


_SMALL_VARINTS = [bytes((n,)) for n in range(128)]
#: Little-endian float64 (what numpy gives float arrays on little-endian machines).
F64 = np.dtype("<f8")


def varint(n: int) -> bytes:
    """A non-negative integer as a base-128 varint."""
    if n < 128:
        return _SMALL_VARINTS[n]
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def length_delimited(field: int, payload: bytes) -> bytes:
    """A length-delimited field (a message, bytes or a packed array)."""
    n = len(payload)
    if n < 128 and field < 16:  # key and length in two bytes
        return bytes((field << 3 | LEN, n)) + payload
    return varint(tag(field, LEN)) + varint(n) + payload


def packed_doubles(field: int, values: List[float]) -> bytes:
    """A packed repeated double field (nothing when there are no values)."""
    if not values:
        return b""
    return length_delimited(field, struct.pack(f"<{len(values)}d", *values))


def doubles_field(field: int, payload: bytes) -> bytes:
    """Packed little-endian doubles already as bytes, framed as `field`
    (nothing when empty)."""
    if not payload:
        return b""
    return length_delimited(field, payload)


def joints(q: Any, name: str = "q") -> List[float]:
    """A 1-D float list from any array-like; the server validates the values."""
    arr = np.asarray(q, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    out: List[float] = arr.tolist()
    return out


def joints_field(field: int, q: Any, name: str) -> bytes:
    """A joint vector as a packed repeated double field, checked as
    :func:`joints` checks it: a one-dimensional little-endian float64 array
    is sent as its own bytes, anything else through :func:`joints`."""
    if isinstance(q, np.ndarray) and q.dtype is F64 and q.ndim == 1:
        return doubles_field(field, q.tobytes())
    return packed_doubles(field, joints(q, name))


def joints_and_field(field: int, q: Any, name: str) -> Tuple[List[float], bytes]:
    """:func:`joints` and :func:`joints_field` of `q` together (one check,
    one conversion)."""
    if isinstance(q, np.ndarray) and q.dtype is F64 and q.ndim == 1:
        values: List[float] = q.tolist()
        return values, doubles_field(field, q.tobytes())
    values = joints(q, name)
    return values, packed_doubles(field, values)


# ---- Pose -----------------------------------------------------------------------------------------------------
# position (three tagged doubles) and orientation (four tagged doubles), every
# double written, zeros too: the generated parser reads the same message.
_POSITION = _one_byte_tag(common_pb2.Pose, "position", LEN)
_ORIENTATION = _one_byte_tag(common_pb2.Pose, "orientation", LEN)
_VX, _VY, _VZ = (_one_byte_tag(common_pb2.Vec3, n, I64) for n in ("x", "y", "z"))
_QX, _QY, _QZ, _QW = (_one_byte_tag(common_pb2.Quaternion, n, I64) for n in ("x", "y", "z", "w"))
_VEC3_BYTES, _QUAT_BYTES = 3 * 9, 4 * 9
POSE_BYTES = 2 + _VEC3_BYTES + 2 + _QUAT_BYTES  # 67: a one-byte length
_POSE_LAYOUT = "BBBdBdBdBBBdBdBdBd"
_POSE = struct.Struct("<" + _POSE_LAYOUT)
_FRAMED_POSE = struct.Struct("<BB" + _POSE_LAYOUT)


def pose_wire(t: np.ndarray) -> bytes:
    """The encoded ``Pose`` of a 4x4 homogeneous array (the quaternion of
    :func:`kinplan._rotation.quat_of_rows`)."""
    rows = t.tolist()
    x, y, z, w = quat_of_rows(rows)
    return _POSE.pack(
        _POSITION, _VEC3_BYTES, _VX, rows[0][3], _VY, rows[1][3], _VZ, rows[2][3],
        _ORIENTATION, _QUAT_BYTES, _QX, x, _QY, y, _QZ, z, _QW, w,
    )


def pose_field(field: int, t: np.ndarray) -> bytes:
    """:func:`pose_wire` of a 4x4 array framed as message field `field` (below 16), in one pack."""
    rows = t.tolist()
    x, y, z, w = quat_of_rows(rows)
    return _FRAMED_POSE.pack(
        tag(field, LEN), POSE_BYTES,
        _POSITION, _VEC3_BYTES, _VX, rows[0][3], _VY, rows[1][3], _VZ, rows[2][3],
        _ORIENTATION, _QUAT_BYTES, _QX, x, _QY, y, _QZ, z, _QW, w,
    )


def pose_to_matrix(pose: common_pb2.Pose) -> np.ndarray:
    """4x4 homogeneous matrix of a proto Pose (metres)."""
    o, p = pose.orientation, pose.position
    return pose_values_to_matrix(p.x, p.y, p.z, o.x, o.y, o.z, o.w)


# ---- ForwardKinematicsResponse -----------------------------------------------------------------------------------
# The usual reply: only the tool pose, all seven values non-zero (a built-in
# robot, links not asked). One struct reads the 13 key and length bytes
# (skipping the doubles), another the 7 doubles (skipping the keys).
_FK_TOOL_POSE = _one_byte_tag(robot_pb2.ForwardKinematicsResponse, "tool_pose", LEN)
_FK_FIXED_BYTES = 2 + POSE_BYTES
_FK_FIXED_KEYS = struct.Struct("<5B8xB8xB8x3B8xB8xB8xB8x")
_FK_FIXED_VALUES = struct.Struct("<5xdxdxd3xdxdxdxd")
_FK_FIXED_EXPECTED = (_FK_TOOL_POSE, POSE_BYTES, _POSITION, _VEC3_BYTES, _VX, _VY, _VZ,
                      _ORIENTATION, _QUAT_BYTES, _QX, _QY, _QZ, _QW)


def tool_pose_of_fk_reply(wire: bytes) -> Optional[np.ndarray]:
    """The tool's 4x4 pose from an encoded ForwardKinematicsResponse when it
    has exactly the usual layout (no links, no model id, no zero value
    omitted), read without building message objects; ``None`` for any other
    encoding."""
    if len(wire) != _FK_FIXED_BYTES or _FK_FIXED_KEYS.unpack(wire) != _FK_FIXED_EXPECTED:
        return None
    return pose_values_to_matrix(*_FK_FIXED_VALUES.unpack(wire))


def read_fk_reply(wire: bytes) -> Tuple[np.ndarray, bytes]:
    """The tool's 4x4 pose and the model id of any encoded
    ForwardKinematicsResponse: the usual layout read from its bytes, every
    other one parsed by the generated class."""
    tool = tool_pose_of_fk_reply(wire)
    if tool is not None:
        return tool, b""
    r = robot_pb2.ForwardKinematicsResponse.FromString(wire)
    return pose_to_matrix(r.tool_pose), r.model_id


# ---- Matrix ------------------------------------------------------------------------------------------------------
_MATRIX_ROWS = tag(field_number(common_pb2.Matrix, "rows"), VARINT)
_MATRIX_COLS = tag(field_number(common_pb2.Matrix, "cols"), VARINT)
_MATRIX_DATA = field_number(common_pb2.Matrix, "data")


def matrix_message(arr: np.ndarray) -> common_pb2.Matrix:
    """A 2-D array as a proto Matrix: rows, cols and the doubles as one
    packed little-endian block, encoded with numpy and parsed once."""
    a = np.ascontiguousarray(arr, dtype=F64)
    if a.ndim != 2:
        raise ValueError(f"a matrix must be two-dimensional, got shape {a.shape}")
    rows, cols = a.shape
    raw = (varint(_MATRIX_ROWS) + varint(rows) + varint(_MATRIX_COLS) + varint(cols)
           + length_delimited(_MATRIX_DATA, a.tobytes()))
    return common_pb2.Matrix.FromString(raw)


# ---- JointTrajectory -------------------------------------------------------------------------------------------
_TRAJECTORY_POINTS = field_number(common_pb2.JointTrajectory, "points")
_POINT_POSITIONS = field_number(common_pb2.JointPoint, "positions")
_POINT_TIME = _one_byte_tag(common_pb2.JointPoint, "time_from_start", I64)


def trajectory_message(arr: np.ndarray, ts: Optional[np.ndarray]) -> common_pb2.JointTrajectory:
    """A JointTrajectory of an (n x m) float array, m >= 1: one JointPoint
    per row, its positions packed and its time (when `ts` is given) after
    them, every row's bytes written at once by numpy and the message parsed
    once."""
    n, m = arr.shape
    positions = varint(tag(_POINT_POSITIONS, LEN)) + varint(8 * m)
    point_len = len(positions) + 8 * m + (9 if ts is not None else 0)
    head = varint(tag(_TRAJECTORY_POINTS, LEN)) + varint(point_len) + positions
    width = len(head) + point_len - len(positions)
    buf = np.empty((n, width), dtype=np.uint8)
    buf[:, : len(head)] = np.frombuffer(head, dtype=np.uint8)
    end = len(head) + 8 * m
    buf[:, len(head) : end] = np.ascontiguousarray(arr, dtype=F64).view(np.uint8).reshape(n, 8 * m)
    if ts is not None:
        buf[:, end] = _POINT_TIME
        buf[:, end + 1 :] = np.ascontiguousarray(ts, dtype=F64).view(np.uint8).reshape(n, 8)
    return common_pb2.JointTrajectory.FromString(buf.tobytes())


# ---- request fields of the hand-encoded calls ------------------------------------------------------------------
#: ForwardKinematicsRequest and SolveIkRequest field numbers.
FK_ROBOT = field_number(robot_pb2.ForwardKinematicsRequest, "robot")
FK_JOINTS = field_number(robot_pb2.ForwardKinematicsRequest, "joint_positions")
IK_ROBOT = field_number(kinematics_pb2.SolveIkRequest, "robot")
IK_TARGET = field_number(kinematics_pb2.SolveIkRequest, "target")
IK_SEED = field_number(kinematics_pb2.SolveIkRequest, "seed")
IK_OPTIONS = field_number(kinematics_pb2.SolveIkRequest, "options")


def target_field(t: np.ndarray) -> bytes:
    """A 4x4 array as the target field of a SolveIkRequest, in one pack."""
    return pose_field(IK_TARGET, t)

#: The robot reference's field number, the same in both hand-encoded requests
#: (a robot caches its reference encoded once under it).
ROBOT_REF = FK_ROBOT
if IK_ROBOT != ROBOT_REF:  # pragma: no cover - a proto change would need a per-request cache
    raise RuntimeError("ForwardKinematicsRequest.robot and SolveIkRequest.robot have different numbers")
