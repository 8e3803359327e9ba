"""kinplan's Retime against toppra (time-optimal) and ruckig (jerk-limited) on
the same 6- and 7-joint paths, side by side in one run.

Paths: seeded random walks of 50 waypoints (each joint steps uniformly in
+-0.3 rad) for the Franka Panda (7 joints, datasheet limits) and the UR5
(6 joints), plus an RRT-Connect plan of the UR5 around a ball.

- Time-optimal: kinplan's TIME_OPTIMAL rounds the corners with circular
  blends (path_tolerance 0.05 rad) and times the blended path with TOPP-RA.
  toppra times *the same blended path*: it is rebuilt here in numpy from the
  waypoints (Kunz & Stilman 2012, eqs. 3-8) as a toppra geometric path, and
  every kinplan sample is checked to lie on it. toppra runs on a grid of
  0.0025 rad (8x finer than kinplan's default 0.02) with the piece ends added.
- Jerk-limited: kinplan's JERK_LIMITED passes each waypoint within
  path_tolerance without stopping (straight segments joined by S-curve blends
  in time). ruckig's community edition takes no intermediate waypoints, so it
  is run state to state through the states kinplan's trajectory passes nearest
  each waypoint (position, velocity and acceleration of that 1 ms sample):
  ruckig's time-optimal profile between two such states bounds from below any
  motion joining them, and the sum of its durations is the anchor. ruckig run
  waypoint to waypoint from rest to rest (what stopping at every waypoint
  costs) is printed beside it. kinplan's 1 kHz samples are checked by finite
  differences, and their distance to each waypoint against path_tolerance.

Run (a kinplan binary and the client on the path):
    python -m venv /tmp/venv-timing && /tmp/venv-timing/bin/pip install toppra ruckig numpy grpcio protobuf
    KINPLAN_BIN=target/debug/kinplan PYTHONPATH=clients/python /tmp/venv-timing/bin/python benches/timing/compare.py
"""
import json
import sys
import time

import numpy as np
import ruckig
import toppra
import toppra.algorithm
import toppra.constraint
from toppra.interpolator import AbstractGeometricPath

import kinplan

toppra.setup_logging("WARNING")

ROBOTS = {
    "franka_panda": dict(
        v=[2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61],
        a=[15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0],
        j=[7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0],
        start=[0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
    ),
    "ur5": dict(
        v=[3.15] * 6,
        a=[8.0, 8.0, 8.0, 12.0, 12.0, 12.0],
        j=[200.0, 200.0, 200.0, 400.0, 400.0, 400.0],
        start=[-1.2, -1.3, 1.4, -1.6, -1.57, 0.0],
    ),
}
TOLERANCE = 0.05


class BlendedPath(AbstractGeometricPath):
    """Straight segments joined by circular arcs at most `delta` from each waypoint."""

    def __init__(self, waypoints, delta):
        pts = [np.asarray(waypoints[0], float)]
        for w in waypoints[1:]:
            if np.linalg.norm(w - pts[-1]) > 1e-12:
                pts.append(np.asarray(w, float))
        self.n = len(pts[0])
        self.pieces = []  # (s0, length, kind, data)
        self.length = 0.0
        seg = [pts[k + 1] - pts[k] for k in range(len(pts) - 1)]
        lens = [np.linalg.norm(d) for d in seg]
        dirs = [d / l for d, l in zip(seg, lens)]
        start = pts[0]
        for i in range(1, len(pts) - 1):
            yi, yo = dirs[i - 1], dirs[i]
            alpha = np.arccos(np.clip(yi @ yo, -1, 1))
            if alpha < 1e-9:
                continue
            half = alpha / 2
            ell = min(lens[i - 1] / 2, lens[i] / 2, delta * np.sin(half) / (1 - np.cos(half)))
            r = ell / np.tan(half)
            corner_in = pts[i] - ell * yi
            self._line(start, corner_in)
            bis = (yo - yi) / np.linalg.norm(yo - yi)
            centre = pts[i] + r / np.cos(half) * bis
            x = (corner_in - centre) / r
            self.pieces.append((self.length, r * alpha, "arc", (centre, x, yi, r)))
            self.length += r * alpha
            start = pts[i] + ell * yo
        self._line(start, pts[-1])
        self.starts = np.array([p[0] for p in self.pieces])

    def _line(self, a, b):
        l = np.linalg.norm(b - a)
        if l > 1e-12:
            self.pieces.append((self.length, l, "line", (a, (b - a) / l)))
            self.length += l

    def __call__(self, ss, order=0):
        scalar = np.isscalar(ss)
        ss = np.atleast_1d(np.asarray(ss, float))
        out = np.empty((len(ss), self.n))
        idx = np.clip(np.searchsorted(self.starts, ss, side="right") - 1, 0, len(self.pieces) - 1)
        for k in np.unique(idx):
            m = idx == k
            s0, l, kind, data = self.pieces[k]
            sig = np.clip(ss[m] - s0, 0, l)[:, None]
            if kind == "line":
                p, d = data
                out[m] = p + sig * d if order == 0 else (d + 0 * sig if order == 1 else 0 * sig + 0 * d)
            else:
                c, x, y, r = data
                th = sig / r
                if order == 0:
                    out[m] = c + r * (x * np.cos(th) + y * np.sin(th))
                elif order == 1:
                    out[m] = -x * np.sin(th) + y * np.cos(th)
                else:
                    out[m] = -(x * np.cos(th) + y * np.sin(th)) / r
        return out[0] if scalar else out

    @property
    def dof(self):
        return self.n

    @property
    def path_interval(self):
        return np.array([0.0, self.length])


def toppra_time(path, v, a, step=0.0025):
    grid = np.union1d(np.linspace(0, path.length, int(np.ceil(path.length / step)) + 1), path.starts)
    grid = grid[(grid >= 0) & (grid <= path.length)]
    cons = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-np.array(v), v])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-np.array(a), a])),
    ]
    t0 = time.perf_counter()
    algo = toppra.algorithm.TOPPRA(cons, path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = algo.compute_trajectory(0, 0)
    elapsed = time.perf_counter() - t0
    return traj.duration, elapsed


def ruckig_time(waypoints, v, a, j):
    dof = waypoints.shape[1]
    total, elapsed = 0.0, 0.0
    for q0, q1 in zip(waypoints[:-1], waypoints[1:]):
        if np.allclose(q0, q1):
            continue
        otg = ruckig.Ruckig(dof)
        inp = ruckig.InputParameter(dof)
        inp.current_position, inp.target_position = list(q0), list(q1)
        inp.current_velocity = inp.current_acceleration = [0.0] * dof
        inp.target_velocity = inp.target_acceleration = [0.0] * dof
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(v), list(a), list(j)
        traj = ruckig.Trajectory(dof)
        t0 = time.perf_counter()
        result = otg.calculate(inp, traj)
        elapsed += time.perf_counter() - t0
        assert result == ruckig.Result.Working, result
        total += traj.duration
    return total, elapsed


def ruckig_through_states(tr, waypoints, v, a, j):
    """ruckig from state to state through the samples of `tr` nearest each interior waypoint.

    Returns (sum of ruckig durations, kinplan's own time between the same samples,
    largest distance of those samples from their waypoints, failures)."""
    dof = waypoints.shape[1]
    idx = [0]
    for w in waypoints[1:-1]:
        d = np.linalg.norm(tr.q - w, axis=1)
        d[: idx[-1]] = np.inf  # in order along the trajectory
        idx.append(int(np.argmin(d)))
    idx.append(len(tr.t) - 1)
    gap = max([float(np.linalg.norm(tr.q[i] - w)) for i, w in zip(idx[1:-1], waypoints[1:-1])] + [0.0])
    total, failures = 0.0, 0
    for i0, i1 in zip(idx[:-1], idx[1:]):
        if i1 <= i0:
            continue
        otg = ruckig.Ruckig(dof)
        inp = ruckig.InputParameter(dof)
        inp.current_position, inp.target_position = list(tr.q[i0]), list(tr.q[i1])
        inp.current_velocity, inp.target_velocity = list(tr.qd[i0]), list(tr.qd[i1])
        # ruckig refuses an acceleration on its limit: kinplan's blends reach it
        # exactly, so the states are clipped a part in 1e9 inside
        acc = lambda i: list(np.clip(tr.qdd[i], -a * (1 - 1e-9), a * (1 - 1e-9)))  # noqa: E731
        inp.current_acceleration, inp.target_acceleration = acc(i0), acc(i1)
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(v), list(a), list(j)
        traj = ruckig.Trajectory(dof)
        try:
            result = otg.calculate(inp, traj)
        except ruckig.RuckigError:
            result = None
        if result != ruckig.Result.Working:
            failures += 1
            total += tr.t[i1] - tr.t[i0]  # counted at kinplan's own time
            continue
        total += traj.duration
    return total, tr.t[idx[-1]] - tr.t[idx[0]], gap, failures


def fd_worst(q, h, v, a, j):
    """Largest finite-difference velocity, acceleration, jerk as fractions of the limits."""
    q = q[:-1]  # the last sample may be closer than h
    return (
        float((np.abs(np.diff(q, 1, axis=0)) / h / v).max()),
        float((np.abs(np.diff(q, 2, axis=0)) / h**2 / a).max()),
        float((np.abs(np.diff(q, 3, axis=0)) / h**3 / j).max()),
    )


def random_walk(rng, start, n=50, step=0.3):
    steps = rng.uniform(-step, step, size=(n - 1, len(start)))
    return np.vstack([start, start + np.cumsum(steps, axis=0)])


def main():
    rows = []
    with kinplan.LocalServer() as server:
        client = server.client()
        for name, lim in ROBOTS.items():
            robot = client.robot(name)
            v, a, j = (np.array(lim[k]) for k in "vaj")
            paths = [(f"walk seed {s}", random_walk(np.random.default_rng(s), np.array(lim["start"])))
                     for s in range(5)]
            if name == "ur5":
                start = np.array(lim["start"])
                goal = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
                ball = kinplan.Sphere(0.12, robot.fk((start + goal) / 2)[:3, 3])
                plan = robot.plan(start, goal, algorithm="rrt_connect", scene=[ball], seed=3)
                paths.append((f"RRT-Connect plan ({len(plan.q)} waypoints)", plan.q))
            for label, w in paths:
                ours = robot.retime(w, max_velocity=v, max_acceleration=a, path_tolerance=TOLERANCE)
                path = BlendedPath(w, TOLERANCE)
                # every kinplan sample lies on the numpy path: the same geometry
                dense = path(np.linspace(0, path.length, 200001))
                off = max(np.linalg.norm(dense - q, axis=1).min() for q in ours.q[:: max(1, len(ours.q) // 50)])
                t_toppra, c_toppra = toppra_time(path, v, a)
                jerk = robot.retime(w, method="jerk_limited", max_velocity=v, max_acceleration=a, max_jerk=j,
                                    sample_period=1e-3, path_tolerance=TOLERANCE)
                t_rest, c_ruckig = ruckig_time(w, v, a, j)
                t_ruckig, _, passing, failures = ruckig_through_states(jerk, w, v, a, j)
                # the farthest any sample passes from its waypoint (closest approach)
                farthest = max([float(np.linalg.norm(jerk.q - x, axis=1).min()) for x in w[1:-1]] + [0.0])
                rows.append(dict(
                    robot=name, path=label, waypoints=len(w),
                    kinplan_time_optimal=ours.duration, toppra=t_toppra,
                    ratio_toppra=ours.duration / t_toppra, path_gap=off,
                    kinplan_jerk_limited=jerk.duration, ruckig=t_ruckig, ratio_ruckig=jerk.duration / t_ruckig,
                    ruckig_failures=failures, ruckig_rest_to_rest=t_rest, passing=farthest,
                    compute_jerk_s=jerk.compute_time,
                    fd_worst=fd_worst(jerk.q, 1e-3, v, a, j),
                    samples_within_limits=bool(np.all(np.abs(ours.qd) <= v * (1 + 1e-9))
                                               and np.all(np.abs(ours.qdd) <= a * (1 + 1e-9))),
                    compute_kinplan_s=ours.compute_time, compute_toppra_s=c_toppra, compute_ruckig_s=c_ruckig,
                ))
                r = rows[-1]
                print(f"{name:13s} {label:32s} TOPP {r['kinplan_time_optimal']:.4f}/{r['toppra']:.4f} = "
                      f"{r['ratio_toppra']:.4f} (gap {off:.1e})  jerk {r['kinplan_jerk_limited']:.4f}/"
                      f"{r['ruckig']:.4f} = {r['ratio_ruckig']:.4f} (ruckig fails {failures}, rest-to-rest "
                      f"{t_rest:.4f}, passing {farthest:.4f})  fd v/a/j "
                      + "/".join(f"{x:.4f}" for x in r["fd_worst"])
                      + f"  compute TO {1e6 * ours.compute_time:.0f} us JL {1e6 * jerk.compute_time:.0f} us",
                      flush=True)
    json.dump(rows, sys.stdout if "--json" in sys.argv else open("/dev/null", "w"), indent=1)


if __name__ == "__main__":
    main()
