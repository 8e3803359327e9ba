"""numpy <-> proto conversions. Quaternion arrays use the order (x, y, z, w).

The wire-level encodings live in :mod:`kinplan._codec` and the quaternion
arithmetic in :mod:`kinplan._rotation`; their names are re-exported here for
code that imported them from this module.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ._codec import (  # noqa: F401  (re-exported)
    doubles_field as _doubles_field,
    joints,
    joints_and_field,
    joints_field,
    length_delimited,
    matrix_message as matrix_to_proto,
    packed_doubles,
    pose_to_matrix,
    pose_wire,
    target_field,
    tool_pose_of_fk_reply,
    varint as _varint,
)
from ._rotation import (  # noqa: F401  (re-exported)
    matrix_to_quat,
    pose_values_to_matrix,
    quat_of_rows as _quat_of_rows,
    quat_to_matrix,
)
from .v1 import common_pb2


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


def pose_bytes(t: Any) -> bytes:
    """The encoded proto Pose of anything :func:`matrix_to_pose` takes; a 4x4
    array is packed directly (:func:`kinplan._codec.pose_wire`)."""
    if isinstance(t, np.ndarray) and t.shape == (4, 4):
        return pose_wire(t)
    out: bytes = matrix_to_pose(t).SerializeToString()
    return out


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
    """The 2-D array of a proto Matrix."""
    data = m.data
    # small: through a list (asarray's fixed cost dominates); large: asarray reads the buffer
    arr = np.array(data[:], dtype=float) if len(data) <= 256 else np.asarray(data, dtype=float)
    return arr.reshape(m.rows, m.cols)


__all__ = [
    "as_homogeneous",
    "as_quat_xyzw",
    "joints",
    "joints_and_field",
    "joints_field",
    "length_delimited",
    "matrix_from_proto",
    "matrix_to_pose",
    "matrix_to_proto",
    "matrix_to_quat",
    "packed_doubles",
    "pose_bytes",
    "pose_to_matrix",
    "pose_values_to_matrix",
    "quat_to_matrix",
    "target_field",
    "tool_pose_of_fk_reply",
]
