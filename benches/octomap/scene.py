"""A seeded synthetic room shared by the OctoMap comparison scripts.

A 6 x 5 x 3 m box room (walls, floor, ceiling) with two axis-aligned boxes and a
sphere inside; a simulated depth sensor returns, for each beam, the first surface hit.
All coordinates are float32 so OctoMap and kinplan see identical points.
"""
import numpy as np

ROOM_MIN = np.array([-3.0, -2.5, 0.0])
ROOM_MAX = np.array([3.0, 2.5, 3.0])
BOXES = [(np.array([0.8, -1.2, 0.0]), np.array([1.6, -0.2, 1.1])),
         (np.array([-2.2, 0.6, 0.0]), np.array([-1.4, 1.8, 0.7]))]
SPHERE = (np.array([0.5, 1.2, 1.4]), 0.45)


def _box_entry(o, d, lo, hi):
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (lo - o) / d
        b = (hi - o) / d
    t0 = np.nanmax(np.minimum(a, b), axis=1)
    t1 = np.nanmin(np.maximum(a, b), axis=1)
    return np.where((t1 >= t0) & (t0 > 0), t0, np.inf)


def beams(origin, yaw, width, height, hfov=np.radians(70.6), vfov=np.radians(60.0), noise=0.0, seed=0):
    """Endpoints (float32, N x 3) of a width x height pinhole-like beam fan looking
    along yaw (rad, about z) from origin, hitting the room."""
    rng = np.random.default_rng(seed)
    u = np.tan(np.linspace(-hfov / 2, hfov / 2, width))
    v = np.tan(np.linspace(-vfov / 2, vfov / 2, height))
    uu, vv = np.meshgrid(u, v)
    d_cam = np.stack([np.ones_like(uu), -uu, -vv], axis=-1).reshape(-1, 3)
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    d = d_cam @ rot.T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.broadcast_to(np.asarray(origin, dtype=float), d.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (ROOM_MIN - o) / d
        b = (ROOM_MAX - o) / d
    t = np.nanmin(np.where(np.maximum(a, b) > 0, np.maximum(a, b), np.inf), axis=1)
    for lo, hi in BOXES:
        t = np.minimum(t, _box_entry(o, d, lo, hi))
    c0, r = SPHERE
    oc = o - c0
    bq = np.sum(oc * d, axis=1)
    disc = bq * bq - (np.sum(oc * oc, axis=1) - r * r)
    ts = -bq - np.sqrt(np.maximum(disc, 0))
    t = np.minimum(t, np.where((disc > 0) & (ts > 0), ts, np.inf))
    if noise > 0:
        t = t + rng.normal(0, noise, t.shape)
    return (o + d * t[:, None]).astype(np.float32)
