"""Quaternion (x, y, z, w) <-> rotation matrix, written once for the package.

:func:`rotation_rows` takes floats (one rotation) or numpy arrays of the same
shape (a batch: every entry of its answer is then an array), so the single
poses of ``fk`` and the stacked poses of ``fk_batch`` use the same products.
"""
from __future__ import annotations

import math
from typing import Any, Sequence, Tuple

import numpy as np

Rows = Tuple[Tuple[Any, Any, Any], Tuple[Any, Any, Any], Tuple[Any, Any, Any]]


def rotation_rows(x: Any, y: Any, z: Any, w: Any) -> Rows:
    """The rows of the rotation matrix of the unit quaternion (x, y, z, w)."""
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )


def quat_to_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    return np.array(rotation_rows(x, y, z, w))


def pose_values_to_matrix(px: float, py: float, pz: float, x: float, y: float, z: float, w: float) -> np.ndarray:
    """4x4 homogeneous matrix of a position and a unit quaternion (x, y, z, w)
    given as floats; an all-zero quaternion (an unset proto field) is the
    identity."""
    if x == 0.0 and y == 0.0 and z == 0.0 and w == 0.0:
        x = y = z = 0.0
        w = 1.0
    r0, r1, r2 = rotation_rows(x, y, z, w)
    return np.array([[r0[0], r0[1], r0[2], px], [r1[0], r1[1], r1[2], py], [r2[0], r2[1], r2[2], pz],
                     [0.0, 0.0, 0.0, 1.0]])


def poses_to_matrices(p: np.ndarray) -> np.ndarray:
    """(n, 4, 4) matrices of an (n, 7) array of poses (x, y, z, qx, qy, qz, qw)."""
    p = np.asarray(p, dtype=np.float64).reshape(-1, 7)
    rows = rotation_rows(p[:, 3], p[:, 4], p[:, 5], p[:, 6])
    T = np.zeros((len(p), 4, 4))
    for i in range(3):
        for j in range(3):
            T[:, i, j] = rows[i][j]
    T[:, :3, 3] = p[:, :3]
    T[:, 3, 3] = 1.0
    return T


def quat_of_rows(r: Sequence[Sequence[float]]) -> Tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a rotation given as nested float
    lists (Shepperd's method), on plain floats: the path of every pose a
    request carries."""
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


def matrix_to_quat(r: Any) -> np.ndarray:
    """Unit quaternion (x, y, z, w) of a rotation matrix, as an array
    (:func:`quat_of_rows` on its rows)."""
    rows = np.asarray(r, dtype=float).tolist()
    return np.array(quat_of_rows(rows))
