"""numpy <-> proto conversions. Quaternion arrays use the order (x, y, z, w)."""
from __future__ import annotations

import math
import struct
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

from .v1 import common_pb2


def joints(q: npt.ArrayLike, name: str = "q") -> List[float]:
    """A 1-D float list from any array-like; the server validates the values."""
    arr = np.asarray(q, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    out: List[float] = arr.tolist()
    return out


_SMALL_VARINTS = [bytes((n,)) for n in range(128)]
#: Little-endian float64 (the dtype numpy gives float arrays on this kind of machine).
_F64 = np.dtype("<f8")


def _varint(n: int) -> bytes:
    if n < 128:
        return _SMALL_VARINTS[n]
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def matrix_to_proto(arr: np.ndarray) -> common_pb2.Matrix:
    """A 2-D array as a proto Matrix, fast: the message is encoded directly
    (rows, cols, then the doubles as one packed little-endian block) and
    parsed, instead of handing protobuf 8-byte numbers one by one (10,000 x 6
    values: ~0.1 ms instead of ~9 ms)."""
    a = np.ascontiguousarray(arr, dtype="<f8")
    if a.ndim != 2:
        raise ValueError(f"a matrix must be two-dimensional, got shape {a.shape}")
    rows, cols = a.shape
    payload = a.tobytes()
    raw = b"\x08" + _varint(rows) + b"\x10" + _varint(cols) + b"\x1a" + _varint(len(payload)) + payload
    return common_pb2.Matrix.FromString(raw)


def quat_to_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(r: np.ndarray) -> np.ndarray:
    """Unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method)."""
    m = np.asarray(r, dtype=float)
    t = np.trace(m)
    if t > 0:
        s = 2.0 * np.sqrt(t + 1.0)
        q: List[Any] = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    v = np.asarray(q)
    out: np.ndarray = v / np.linalg.norm(v)
    return out


def pose_to_matrix(pose: common_pb2.Pose) -> np.ndarray:
    """4x4 homogeneous matrix of a proto Pose (metres): one array built from
    plain floats (the same products as :func:`quat_to_matrix`)."""
    o, p = pose.orientation, pose.position
    return pose_values_to_matrix(p.x, p.y, p.z, o.x, o.y, o.z, o.w)


def pose_values_to_matrix(px: float, py: float, pz: float, x: float, y: float, z: float, w: float) -> np.ndarray:
    """4x4 homogeneous matrix of a position and a unit quaternion (x, y, z, w)
    given as floats; an all-zero quaternion (an unset proto field) is the
    identity. The rotation is :func:`quat_to_matrix`'s products."""
    if x == 0.0 and y == 0.0 and z == 0.0 and w == 0.0:
        x = y = z = 0.0
        w = 1.0
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), px],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), py],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), pz],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


# A ForwardKinematicsResponse holding only the tool pose with all seven values
# non-zero (what the server sends for a built-in robot, links not asked):
# field 1 (67 bytes) = position (field 1: three tagged doubles) and
# orientation (field 2: four tagged doubles). One struct reads the 13 tag and
# length bytes (skipping the doubles), another the 7 doubles (skipping the tags).
_FK_TOOL_ONLY_TAGS = struct.Struct("<5B8xB8xB8x3B8xB8xB8xB8x")
_FK_TOOL_ONLY_VALUES = struct.Struct("<5xdxdxd3xdxdxdxd")
_FK_TOOL_ONLY_EXPECTED = (0x0A, 67, 0x0A, 27, 0x09, 0x11, 0x19, 0x12, 36, 0x09, 0x11, 0x19, 0x21)


def tool_pose_of_fk_reply(wire: bytes) -> Optional[np.ndarray]:
    """The tool's 4x4 pose from an encoded ForwardKinematicsResponse when it
    has exactly the layout above (no links, no model id, no zero value
    omitted), read without building message objects; ``None`` for any other
    encoding (the caller then parses the message)."""
    if len(wire) != 69 or _FK_TOOL_ONLY_TAGS.unpack(wire) != _FK_TOOL_ONLY_EXPECTED:
        return None
    return pose_values_to_matrix(*_FK_TOOL_ONLY_VALUES.unpack(wire))


def as_homogeneous(t: object) -> object:
    """The 4x4 array of a pose object from the libraries people pair with
    kinplan (pinocchio ``SE3``: ``.homogeneous``; spatialmath ``SE3``:
    ``.A``); anything else is returned unchanged."""
    h = getattr(t, "homogeneous", None)
    if h is not None and np.shape(h) == (4, 4):
        return np.asarray(h, dtype=float)
    a = getattr(t, "A", None)
    if a is not None and not isinstance(t, np.ndarray) and np.shape(a) == (4, 4):
        return np.asarray(a, dtype=float)
    return t


def as_quat_xyzw(q: object) -> np.ndarray:
    """A quaternion as (x, y, z, w): arrays are taken in that order;
    spatialmath ``UnitQuaternion`` (scalar first: ``.s`` and ``.v``) and
    pinocchio/Eigen quaternions (``.x``, ``.y``, ``.z``, ``.w``) by their
    named parts, so a scalar-first object cannot be misread."""
    if hasattr(q, "s") and hasattr(q, "v"):
        v = np.asarray(getattr(q, "v"), dtype=float).ravel()
        return np.array([v[0], v[1], v[2], float(getattr(q, "s"))])
    if all(hasattr(q, k) for k in ("x", "y", "z", "w")) and not isinstance(q, np.ndarray):
        return np.array([float(getattr(q, k)) for k in ("x", "y", "z", "w")])
    return np.asarray(q, dtype=float)


def _quat_of_rows(r: Sequence[Sequence[float]]) -> Tuple[float, float, float, float]:
    """:func:`matrix_to_quat` on a rotation given as nested float lists, with
    the same branches and operation order (the hot path of every IK call:
    plain floats are ~10x faster than numpy here)."""
    r0, r1, r2 = r[0], r[1], r[2]
    t = r0[0] + r1[1] + r2[2]
    if t > 0:  # the usual branch, on locals
        s = 2.0 * math.sqrt(t + 1.0)
        x, y, z, w = (r2[1] - r1[2]) / s, (r0[2] - r2[0]) / s, (r1[0] - r0[1]) / s, 0.25 * s
    else:
        m = r
        d = (m[0][0], m[1][1], m[2][2])
        i = d.index(max(d))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
        q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j][i] + m[i][j]) / s
        q[k] = (m[k][i] + m[i][k]) / s
        x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w)
    return (x / n, y / n, z / n, w / n)


# A Pose on the wire: position (field 1: three doubles, 27 bytes) and
# orientation (field 2: four doubles, 36 bytes), every double tagged.
_POSE_WIRE = struct.Struct("<BBBdBdBdBBBdBdBdBd")


def pose_bytes(t: Any) -> bytes:
    """The encoded proto Pose of anything :func:`matrix_to_pose` takes; a 4x4
    array is packed directly (the same quaternion, no message objects)."""
    if isinstance(t, np.ndarray) and t.shape == (4, 4):
        rows = t.tolist()
        x, y, z, w = _quat_of_rows(rows)
        return _POSE_WIRE.pack(
            0x0A, 27, 0x09, rows[0][3], 0x11, rows[1][3], 0x19, rows[2][3],
            0x12, 36, 0x09, x, 0x11, y, 0x19, z, 0x21, w,
        )
    out: bytes = matrix_to_pose(t).SerializeToString()
    return out


# The same Pose framed as field 2 of a SolveIkRequest (tag 0x12, 67 bytes).
_TARGET_FIELD_WIRE = struct.Struct("<BBBBBdBdBdBBBdBdBdBd")


def target_field(t: np.ndarray) -> bytes:
    """:func:`pose_bytes` of a 4x4 array framed as field 2 (the IK target) in
    one pack: the hot path of every ``robot.ik``."""
    rows = t.tolist()
    x, y, z, w = _quat_of_rows(rows)
    return _TARGET_FIELD_WIRE.pack(
        0x12, 67, 0x0A, 27, 0x09, rows[0][3], 0x11, rows[1][3], 0x19, rows[2][3],
        0x12, 36, 0x09, x, 0x11, y, 0x19, z, 0x21, w,
    )


def length_delimited(field: int, payload: bytes) -> bytes:
    """A length-delimited field (a message, bytes or a packed array) on the wire."""
    n = len(payload)
    if n < 128:  # tag and length in one two-byte header
        return bytes((field << 3 | 2, n)) + payload
    return bytes((field << 3 | 2,)) + _varint(n) + payload


def packed_doubles(field: int, values: List[float]) -> bytes:
    """A packed repeated double field (empty when there are no values)."""
    if not values:
        return b""
    return length_delimited(field, struct.pack(f"<{len(values)}d", *values))


def joints_field(field: int, q: Any, name: str) -> bytes:
    """A joint vector as a packed repeated double field, checked as
    :func:`joints` checks it: a one-dimensional little-endian float64 array
    is sent as its own bytes (no list, no struct), anything else through
    :func:`joints` and :func:`packed_doubles`."""
    if isinstance(q, np.ndarray) and q.dtype is _F64 and q.ndim == 1:
        return _doubles_field(field, q.tobytes())
    return packed_doubles(field, joints(q, name))


def joints_and_field(field: int, q: Any, name: str) -> Tuple[List[float], bytes]:
    """:func:`joints` and :func:`joints_field` of `q` together (one check,
    one conversion)."""
    if isinstance(q, np.ndarray) and q.dtype is _F64 and q.ndim == 1:
        values: List[float] = q.tolist()
        return values, _doubles_field(field, q.tobytes())
    values = joints(q, name)
    return values, packed_doubles(field, values)


def _doubles_field(field: int, payload: bytes) -> bytes:
    """Packed little-endian doubles framed as `field` (nothing when empty)."""
    n = len(payload)
    if n == 0:
        return b""
    if n < 128:
        return bytes((field << 3 | 2, n)) + payload
    return length_delimited(field, payload)


def matrix_to_pose(t: np.ndarray) -> common_pb2.Pose:
    """Proto Pose of a 4x4 homogeneous matrix (or of a (position, quaternion
    x-y-z-w) pair, or of a pinocchio / spatialmath SE3)."""
    if isinstance(t, np.ndarray) and t.shape == (4, 4):
        rows = t.tolist()
        x, y, z, w = _quat_of_rows(rows)
        return common_pb2.Pose(
            position=common_pb2.Vec3(x=rows[0][3], y=rows[1][3], z=rows[2][3]),
            orientation=common_pb2.Quaternion(x=x, y=y, z=z, w=w),
        )
    t = as_homogeneous(t)  # type: ignore[assignment]
    if isinstance(t, tuple) and len(t) == 2:
        p, q = np.asarray(t[0], dtype=float), as_quat_xyzw(t[1])
    else:
        m = np.asarray(t, dtype=float)
        if m.shape != (4, 4):
            raise ValueError(f"a pose must be a 4x4 matrix, got shape {m.shape}")
        p, q = m[:3, 3], matrix_to_quat(m[:3, :3])
    return common_pb2.Pose(
        position=common_pb2.Vec3(x=p[0], y=p[1], z=p[2]),
        orientation=common_pb2.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
    )


def matrix_from_proto(m: common_pb2.Matrix) -> np.ndarray:
    data = m.data
    # small: through a list (asarray's fixed cost dominates); large: asarray reads the buffer
    arr = np.array(data[:], dtype=float) if len(data) <= 256 else np.asarray(data, dtype=float)
    return arr.reshape(m.rows, m.cols)
