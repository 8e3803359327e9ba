#!/usr/bin/env python3
"""Run the published IK anchors (TRAC-IK, KDL) on exactly the targets of `ik_bench`.

Reads `<targets>/<arm>.csv` and `<arm>.json` written by
`DUMP_TARGETS=<targets> cargo run --release --example ik_bench -- ...`, solves every
target with each anchor from the same mid-limit seed, checks every answer independently
with our convention (position error <= 1e-5 m and rotation angle of R*.R^T <= 1e-5 rad,
on an FK of this script's own, from the URDF; joint values inside the limits), and prints
the ik_bench markdown row (success %, mean / median / p99 microseconds per call).

Anchors (`--anchors`, comma separated):
  tracik      TRAC-IK (pytracik 0.0.3 wheel), solve type Speed, timeout 5 ms, eps 1e-5
  kdl         KDL ChainIkSolverPos_NR_JL + ChainIkSolverVel_pinv, maxiter 100, eps 1e-5,
              one call from the seed (no restarts)
  tracik-strict, kdl-strict
              the same with eps = 1e-5/sqrt(3): both libraries test |component| <= eps
              on each of the six components of the error twist, which lets the
              Euclidean position error and rotation angle reach sqrt(3) eps; eps/sqrt(3)
              is the largest eps that guarantees our 1e-5 m / 1e-5 rad
  kdl-5ms     the same NR_JL iterated from the seed until it converges or 5 ms have passed,
              as in TRAC-IK's own test harness (trac_ik_examples/ik_tests.cpp calls NR_JL
              with maxiter 1 in a timed loop); here 10 iterations per call
  kdl-lma     KDL ChainIkSolverPos_LMA, default weights L = (1,1,1,0.01,0.01,0.01),
              eps 1e-7 on the weighted error norm (the tolerance that guarantees 1e-5 rad),
              maxiter 500, one call from the seed; LMA ignores joint limits, so answers
              are moved by whole turns into the limits before the check

Timing: time.perf_counter_ns() around the solve call only (for kdl-5ms: around the whole
timed loop); Python's garbage collector is disabled while timing; the first 10 targets
are solved once, untimed, before each timed pass (warm-up). The binding's call
overhead is measured separately and printed (see the "call overhead" table).
"""

import argparse
import ctypes
import gc
import json
import math
import os
import platform
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

ARMS = [
    "kuka_kr210_r2700_extra",
    "abb_irb4600_60_205",
    "ur5",
    "franka_panda",
    "kuka_lbr_iiwa14_r820",
]
REPO = Path(__file__).resolve().parents[2]
POS_TOL = 1e-5  # m
ROT_TOL = 1e-5  # rad
LIMIT_TOL = 1e-9  # rad, floating noise only
BUDGET_S = 0.005
EPS = 1e-5
STRICT_EPS = 1e-5 / math.sqrt(3.0)
WARMUP = 10  # untimed solves of the first targets before each timed pass


# ----------------------------------------------------------------------------- own FK


def rpy_matrix(r, p, y):
    """URDF rpy: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def axis_angle_matrix(axis, angle):
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def quat_matrix(qx, qy, qz, qw):
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    qx, qy, qz, qw = qx / n, qy / n, qz / n, qw / n
    return np.array(
        [
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
        ]
    )


def rotation_angle(R):
    """Angle of a rotation matrix, accurate near 0 (atan2 of sin and cos)."""
    s = 0.5 * math.sqrt((R[2, 1] - R[1, 2]) ** 2 + (R[0, 2] - R[2, 0]) ** 2 + (R[1, 0] - R[0, 1]) ** 2)
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    return math.atan2(s, c)


class UrdfChain:
    """The serial chain base_link -> tip_link of a URDF, read with ElementTree."""

    def __init__(self, urdf_path, base, tip):
        root = ET.parse(urdf_path).getroot()
        by_child = {}
        for j in root.findall("joint"):
            by_child[j.find("child").get("link")] = j
        path = []
        link = tip
        while link != base:
            j = by_child[link]
            path.append(j)
            link = j.find("parent").get("link")
        path.reverse()
        # segments: (name, type, R_origin, p_origin, axis)
        self.segments = []
        self.joint_names = []
        for j in path:
            o = j.find("origin")
            xyz = [float(v) for v in (o.get("xyz", "0 0 0").split() if o is not None else "0 0 0".split())]
            rpy = [float(v) for v in (o.get("rpy", "0 0 0").split() if o is not None else "0 0 0".split())]
            kind = j.get("type")
            a = j.find("axis")
            axis = np.array([float(v) for v in a.get("xyz").split()]) if a is not None else np.array([1.0, 0, 0])
            if kind != "fixed":
                axis = axis / np.linalg.norm(axis)
                self.joint_names.append(j.get("name"))
            if kind not in ("fixed", "revolute", "continuous"):
                raise ValueError(f"joint type {kind} not handled here")
            self.segments.append((j.get("name"), kind, rpy_matrix(*rpy), np.array(xyz), axis))
        self.dof = len(self.joint_names)

    def fk(self, q):
        R = np.eye(3)
        p = np.zeros(3)
        i = 0
        for _, kind, Ro, po, axis in self.segments:
            p = p + R @ po
            R = R @ Ro
            if kind != "fixed":
                R = R @ axis_angle_matrix(axis, q[i])
                i += 1
        return R, p

    def kdl_chain(self):
        import PyKDL as K

        chain = K.Chain()
        for name, kind, Ro, po, axis in self.segments:
            F = K.Frame(
                K.Rotation(*[float(v) for v in Ro.reshape(-1)]),
                K.Vector(*[float(v) for v in po]),
            )
            if kind == "fixed":
                joint = K.Joint(name, K.Joint.Fixed)
            else:
                # as kdl_parser: joint at the origin of the segment, axis in the parent frame
                a = Ro @ axis
                joint = K.Joint(name, F.p, K.Vector(*[float(v) for v in a]), K.Joint.RotAxis)
            chain.addSegment(K.Segment(name, joint, F))
        return chain


# ----------------------------------------------------------------------------- data


def load_targets(targets_dir, arm, limit):
    meta = json.loads((Path(targets_dir) / f"{arm}.json").read_text())
    rows = np.loadtxt(Path(targets_dir) / f"{arm}.csv", delimiter=",", skiprows=1, ndmin=2)
    if limit:
        rows = rows[:limit]
    dof = len(meta["joints"])
    assert rows.shape[1] == dof + 7, (rows.shape, dof)
    return meta, rows[:, :dof], rows[:, dof : dof + 3], rows[:, dof + 3 :]


class Checker:
    def __init__(self, chain, lower, upper, pos, quat):
        self.chain = chain
        self.lower = np.array(lower)
        self.upper = np.array(upper)
        self.pos = pos
        self.rots = [quat_matrix(*q) for q in quat]

    def errors(self, i, q):
        R, p = self.chain.fk(q)
        return float(np.linalg.norm(p - self.pos[i])), rotation_angle(self.rots[i] @ R.T)

    def wrap_into_limits(self, q):
        """Whole turns only (same pose): for solvers that ignore limits (LMA)."""
        q = np.array(q, dtype=float)
        for k in range(len(q)):
            while q[k] > self.upper[k] + LIMIT_TOL and q[k] - 2 * math.pi >= self.lower[k] - LIMIT_TOL:
                q[k] -= 2 * math.pi
            while q[k] < self.lower[k] - LIMIT_TOL and q[k] + 2 * math.pi <= self.upper[k] + LIMIT_TOL:
                q[k] += 2 * math.pi
        return q

    def in_limits(self, q):
        return bool(np.all(q >= self.lower - LIMIT_TOL) and np.all(q <= self.upper + LIMIT_TOL))


# ----------------------------------------------------------------------------- machine


def proc_stat():
    """(busy, steal) seconds of all CPUs since boot, from /proc/stat."""
    f = [int(v) for v in open("/proc/stat").readline().split()[1:]]
    hz = os.sysconf("SC_CLK_TCK")
    # user nice system idle iowait irq softirq steal ...
    return (f[0] + f[1] + f[2] + f[5] + f[6]) / hz, f[7] / hz


class Usage:
    """CPU used during a pass: by this process (all threads), by everything else on the
    machine, and stolen by the hypervisor; in cores (CPU seconds per wall second)."""

    def __enter__(self):
        self.stat0, self.cpu0, self.wall0 = proc_stat(), time.process_time(), time.perf_counter()
        return self

    def __exit__(self, *exc):
        (b1, s1), cpu1, wall1 = proc_stat(), time.process_time(), time.perf_counter()
        wall = wall1 - self.wall0
        own = cpu1 - self.cpu0
        self.own = own / wall
        self.others = max(0.0, (b1 - self.stat0[0]) - own) / wall
        self.steal = (s1 - self.stat0[1]) / wall


# ----------------------------------------------------------------------------- anchors


class StdoutToStderr:
    """pytracik's constructor prints to C stdout; keep the markdown output clean."""

    def __enter__(self):
        sys.stdout.flush()
        ctypes.CDLL(None).fflush(None)
        self.saved = os.dup(1)
        os.dup2(2, 1)

    def __exit__(self, *exc):
        ctypes.CDLL(None).fflush(None)
        os.dup2(self.saved, 1)
        os.close(self.saved)


def make_tracik(urdf_path, meta, exact_limits, eps):
    import pytracik

    with StdoutToStderr():
        solver = pytracik.TRAC_IK(
            meta["base_link"],
            meta["tip_link"],
            Path(urdf_path).read_text(),
            BUDGET_S,
            eps,
            pytracik.SolveType.Speed,
        )
    urdf_lower = list(pytracik.get_joint_lower_bounds(solver))
    urdf_upper = list(pytracik.get_joint_upper_bounds(solver))
    info = {
        "dof": pytracik.get_num_joints(solver),
        "max |URDF limit as parsed by TRAC-IK - exact|": max(
            abs(a - b) for a, b in zip(urdf_lower + urdf_upper, meta["lower"] + meta["upper"])
        ),
    }
    if exact_limits:
        pytracik.set_joint_limits(solver, meta["lower"], meta["upper"])
        got = list(pytracik.get_joint_lower_bounds(solver)) + list(pytracik.get_joint_upper_bounds(solver))
        info["max |limit after set_joint_limits - exact|"] = max(
            abs(a - b) for a, b in zip(got, meta["lower"] + meta["upper"])
        )
    return solver, info


def run_tracik(solver, seed, pos, quat):
    import pytracik

    ik = pytracik.ik
    seed = np.array(seed, dtype=np.float64)
    n = len(pos)
    times = np.empty(n)
    sols = [None] * n
    reported = np.zeros(n, dtype=bool)
    args = [(float(p[0]), float(p[1]), float(p[2]), float(q[0]), float(q[1]), float(q[2]), float(q[3])) for p, q in zip(pos, quat)]
    clock = time.perf_counter_ns
    for i, (x, y, z, qx, qy, qz, qw) in enumerate(args):
        t0 = clock()
        r = ik(solver, seed, x, y, z, qx, qy, qz, qw)
        t1 = clock()
        times[i] = (t1 - t0) * 1e-3
        if r[0] >= 0:
            reported[i] = True
            sols[i] = np.array(r[1:])
    return times, sols, reported


def kdl_frames(pos, quat):
    import PyKDL as K

    return [
        K.Frame(K.Rotation.Quaternion(float(q[0]), float(q[1]), float(q[2]), float(q[3])), K.Vector(float(p[0]), float(p[1]), float(p[2])))
        for p, q in zip(pos, quat)
    ]


def jnt_array(values):
    import PyKDL as K

    a = K.JntArray(len(values))
    for k, v in enumerate(values):
        a[k] = float(v)
    return a


def from_jnt_array(a, dof):
    return np.array([a[k] for k in range(dof)])


def run_kdl(kind, kchain, meta, pos, quat):
    import PyKDL as K

    dof = len(meta["seed"])
    fk = K.ChainFkSolverPos_recursive(kchain)
    vel = K.ChainIkSolverVel_pinv(kchain)  # defaults: eps 1e-5, maxiter 150 (SVD)
    qmin, qmax = jnt_array(meta["lower"]), jnt_array(meta["upper"])
    if kind == "kdl":
        solver = K.ChainIkSolverPos_NR_JL(kchain, qmin, qmax, fk, vel, 100, EPS)
    elif kind == "kdl-strict":
        solver = K.ChainIkSolverPos_NR_JL(kchain, qmin, qmax, fk, vel, 100, STRICT_EPS)
    elif kind == "kdl-5ms":
        chunk = 10
        solver = K.ChainIkSolverPos_NR_JL(kchain, qmin, qmax, fk, vel, chunk, EPS)
    elif kind == "kdl-lma":
        # Default weights L = (1, 1, 1, 0.01, 0.01, 0.01) (the constructor taking L
        # segfaults in Debian's PyKDL 1.5.1); LMA stops when the weighted error norm
        # sqrt(|dp|^2 + 1e-4 |dr|^2) < eps, so eps = 1e-7 is what guarantees
        # |dr| <= 1e-5 rad (and |dp| <= 1e-7 m).
        solver = K.ChainIkSolverPos_LMA(kchain, 1e-7, 500, 1e-15)
    else:
        raise ValueError(kind)
    seed = jnt_array(meta["seed"])
    frames = kdl_frames(pos, quat)
    n = len(frames)
    times = np.empty(n)
    sols = [None] * n
    reported = np.zeros(n, dtype=bool)
    out = K.JntArray(dof)
    clock = time.perf_counter_ns
    cart_to_jnt = solver.CartToJnt
    if kind == "kdl-5ms":
        budget_ns = int(BUDGET_S * 1e9)
        other = K.JntArray(dof)
        for i, f in enumerate(frames):
            a, b = out, other
            t0 = clock()
            rc = cart_to_jnt(seed, f, a)
            while rc < 0 and clock() - t0 < budget_ns:
                # continue from the last iterate (NR_JL restarts from q_init each call)
                rc = cart_to_jnt(a, f, b)
                a, b = b, a
            t1 = clock()
            out, other = a, b
            times[i] = (t1 - t0) * 1e-3
            reported[i] = rc >= 0
            sols[i] = from_jnt_array(out, dof)
    else:
        for i, f in enumerate(frames):
            t0 = clock()
            rc = cart_to_jnt(seed, f, out)
            t1 = clock()
            times[i] = (t1 - t0) * 1e-3
            reported[i] = rc >= 0
            sols[i] = from_jnt_array(out, dof)
    return times, sols, reported


# ----------------------------------------------------------------------------- overhead


def median_call_ns(fn, reps=20000):
    clock = time.perf_counter_ns
    ts = np.empty(reps)
    for k in range(reps):
        t0 = clock()
        fn()
        ts[k] = clock() - t0
    return float(np.median(ts)), float(np.mean(ts))


def overhead_rows(tracik_solver, kchain, meta, pos, quat):
    rows = []
    rows.append(("perf_counter_ns() pair, nothing between", _empty_pair()))
    rows.append(("Python no-op function call", median_call_ns(_noop)))
    if tracik_solver is not None:
        import pytracik

        q = np.array(meta["seed"], dtype=np.float64)
        rows.append(("pytracik.get_num_joints (copies the KDL chain)", median_call_ns(lambda: pytracik.get_num_joints(tracik_solver))))
        rows.append(("pytracik.fk (chain copy + FK solver + 4x4 array)", median_call_ns(lambda: pytracik.fk(tracik_solver, q))))
    if kchain is not None:
        import PyKDL as K

        fk = K.ChainFkSolverPos_recursive(kchain)
        seed = jnt_array(meta["seed"])
        frame = K.Frame()
        rows.append(("PyKDL Chain.getNrOfJoints", median_call_ns(kchain.getNrOfJoints)))
        rows.append(("PyKDL ChainFkSolverPos_recursive.JntToCart", median_call_ns(lambda: fk.JntToCart(seed, frame))))
    return rows


def _noop():
    return None


def _empty_pair(reps=100000):
    clock = time.perf_counter_ns
    ts = np.empty(reps)
    for k in range(reps):
        t0 = clock()
        ts[k] = clock() - t0
    return float(np.median(ts)), float(np.mean(ts))


def tracik_floor(args, arms):
    """TRAC-IK seeded at the answer: its KDL thread converges on the first check, so the
    time is the per-call floor (two std::thread spawns and joins, the binding, one FK)."""
    print("| arm | N | TRAC-IK seeded at its answer: success % | mean µs | median µs | p99 µs | CPU used (cores) | other processes (cores) | stolen (cores) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for arm in arms:
        meta, qs, pos, quat = load_targets(args.targets, arm, args.n or 1000)
        solver, _ = make_tracik(Path(args.urdf_dir) / f"{arm}.urdf", meta, not args.tracik_urdf_limits, EPS)
        import pytracik

        for i in range(WARMUP):
            pytracik.ik(solver, np.array(qs[i]), *map(float, pos[i]), *map(float, quat[i]))
        n = len(qs)
        seeds = [np.array(q) for q in qs]
        args7 = [tuple(map(float, p)) + tuple(map(float, q)) for p, q in zip(pos, quat)]
        times = np.empty(n)
        ok = 0
        clock = time.perf_counter_ns
        gc.disable()
        try:
            with Usage() as usage:
                for i in range(n):
                    t0 = clock()
                    r = pytracik.ik(solver, seeds[i], *args7[i])
                    times[i] = (clock() - t0) * 1e-3
                    ok += r[0] >= 0
        finally:
            gc.enable()
        st = np.sort(times)
        print(
            f"| {arm} | {n} | {100.0 * ok / n:.2f} | {times.mean():.1f} | {st[n // 2]:.1f} | {st[(n * 99) // 100]:.1f} | "
            f"{usage.own:.2f} | {usage.others:.2f} | {usage.steal:.2f} |",
            flush=True,
        )


# ----------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--targets", default="/tmp/ik_targets", help="directory written by DUMP_TARGETS")
    ap.add_argument("--arms", default=",".join(ARMS))
    ap.add_argument("--anchors", default="tracik,tracik-strict,kdl,kdl-strict,kdl-5ms,kdl-lma")
    ap.add_argument("-n", type=int, default=0, help="use only the first N targets (0: all)")
    ap.add_argument("--urdf-dir", default=str(REPO / "crates/kinplan-core/src/robot/builtin"))
    ap.add_argument(
        "--tracik-floor",
        action="store_true",
        help="instead of the anchors: time TRAC-IK seeded at each target's own sampled joints "
        "(first -n targets, default 1000): the fixed cost of a call that converges at once",
    )
    ap.add_argument(
        "--tracik-urdf-limits",
        action="store_true",
        help="keep TRAC-IK's limits as parsed from the URDF (stored as float) instead of "
        "setting the exact double limits with set_joint_limits",
    )
    args = ap.parse_args()
    anchors = [a for a in args.anchors.split(",") if a]
    arms = [a for a in args.arms.split(",") if a]
    if args.tracik_floor:
        tracik_floor(args, arms)
        return

    print(f"python {platform.python_version()} ({sys.executable}), numpy {np.__version__}")
    if any(a.startswith("tracik") for a in anchors):
        import importlib.metadata as md

        import pytracik

        print(f"pytracik {md.version('pytracik')} ({pytracik.__file__})")
    if any(a.startswith("kdl") for a in anchors):
        import PyKDL

        print(f"PyKDL {getattr(PyKDL, '__version__', '?')} ({PyKDL.__file__})")
    print()

    table = []
    details = []
    overhead = None
    for arm in arms:
        meta, qs, pos, quat = load_targets(args.targets, arm, args.n)
        urdf = Path(args.urdf_dir) / f"{arm}.urdf"
        chain = UrdfChain(urdf, meta["base_link"], meta["tip_link"])
        assert chain.joint_names == meta["joints"], (chain.joint_names, meta["joints"])
        checker = Checker(chain, meta["lower"], meta["upper"], pos, quat)
        n = len(qs)
        # Same chain? FK of the sampled joints (ours, written to the CSV) vs this script's FK,
        # KDL's FK and TRAC-IK's FK, on the first 200 samples.
        m = min(n, 200)
        own = max(max(checker.errors(i, qs[i])) for i in range(m))
        fk_check = {"own FK vs CSV (max of pos m / rot rad)": own}
        kchain = None
        if any(a.startswith("kdl") for a in anchors):
            import PyKDL as K

            kchain = chain.kdl_chain()
            kfk = K.ChainFkSolverPos_recursive(kchain)
            worst = 0.0
            for i in range(m):
                f = K.Frame()
                kfk.JntToCart(jnt_array(qs[i]), f)
                p = np.array([f.p[k] for k in range(3)])
                R = np.array([[f.M[r, c] for c in range(3)] for r in range(3)])
                worst = max(worst, float(np.linalg.norm(p - pos[i])), rotation_angle(checker.rots[i] @ R.T))
            fk_check["KDL FK vs CSV"] = worst
        tracik_solver = None
        tracik_strict = None
        if "tracik" in anchors or "tracik-strict" in anchors:
            import pytracik

            tracik_solver, tinfo = make_tracik(urdf, meta, not args.tracik_urdf_limits, EPS)
            if "tracik-strict" in anchors:
                tracik_strict, _ = make_tracik(urdf, meta, not args.tracik_urdf_limits, STRICT_EPS)
            assert tinfo["dof"] == chain.dof
            worst = 0.0
            for i in range(m):
                H = pytracik.fk(tracik_solver, np.array(qs[i]))
                worst = max(worst, float(np.linalg.norm(H[:3, 3] - pos[i])), rotation_angle(checker.rots[i] @ H[:3, :3].T))
            fk_check["TRAC-IK FK vs CSV"] = worst
            fk_check.update(tinfo)
        print(f"[{arm}] base {meta['base_link']} -> tip {meta['tip_link']}, {chain.dof} joints, N = {n}", file=sys.stderr)
        for k, v in fk_check.items():
            print(f"[{arm}]   {k}: {v:.3g}", file=sys.stderr)
        if overhead is None:
            overhead = overhead_rows(tracik_solver, kchain, meta, pos, quat)

        for anchor in anchors:
            print(f"[{arm}] {anchor} ... (uptime: {os.getloadavg()})", file=sys.stderr)
            if anchor == "tracik":
                run = lambda p, o: run_tracik(tracik_solver, meta["seed"], p, o)  # noqa: E731
            elif anchor == "tracik-strict":
                run = lambda p, o: run_tracik(tracik_strict, meta["seed"], p, o)  # noqa: E731
            else:
                run = lambda p, o: run_kdl(anchor, kchain, meta, p, o)  # noqa: E731
            run(pos[:WARMUP], quat[:WARMUP])  # warm-up, not counted
            gc.collect()
            gc.disable()
            try:
                with Usage() as usage:
                    times, sols, reported = run(pos, quat)
            finally:
                gc.enable()
            ok = 0
            pose_ok = 0
            rep_but_fail = 0
            worst_pos = worst_rot = 0.0
            for i in range(n):
                q = sols[i]
                if q is None:
                    continue
                if anchor == "kdl-lma":
                    q = checker.wrap_into_limits(q)
                if not reported[i]:
                    continue  # the solver said it failed: a failure whatever q is
                ep, er = checker.errors(i, q)
                good_pose = ep <= POS_TOL and er <= ROT_TOL
                good = good_pose and checker.in_limits(q)
                pose_ok += good_pose
                ok += good
                worst_pos, worst_rot = max(worst_pos, ep), max(worst_rot, er)
                if not good:
                    rep_but_fail += 1
            st = np.sort(times)
            row = (
                f"| {arm} | {anchor} | {n} | {100.0 * ok / n:.2f} | {times.mean():.1f} | "
                f"{st[n // 2]:.1f} | {st[(n * 99) // 100]:.1f} | {'–' if anchor.startswith('tracik') else '1'} | – |"
            )
            print(row, flush=True)
            table.append(row)
            details.append(
                f"| {arm} | {anchor} | {100.0 * reported.mean():.2f} | {100.0 * ok / n:.2f} | "
                f"{100.0 * pose_ok / n:.2f} | {rep_but_fail} | {worst_pos:.2e} | {worst_rot:.2e} | "
                f"{usage.own:.2f} | {usage.others:.2f} | {usage.steal:.2f} |"
            )
        tracik_solver = tracik_strict = None  # noqa: F841 (frees the solvers before the next arm)

    print()
    print("| arm | method | N | success % | mean µs | median µs | p99 µs | mean attempts | mean iterations |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in table:
        print(r)
    print()
    print(
        "| arm | anchor | self-reported success % | verified success % (reported, pose and limits) | "
        "reported and pose within tolerance % | reported but failed our check | max pos err of reported (m) | "
        "max rot err of reported (rad) | CPU used by this process (cores) | "
        "CPU used by other processes (cores) | CPU stolen by the hypervisor (cores) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in details:
        print(r)
    print()
    print("| call overhead (not subtracted above) | median ns | mean ns |")
    print("|---|---|---|")
    for name, (med, mean) in overhead or []:
        print(f"| {name} | {med:.0f} | {mean:.0f} |")


if __name__ == "__main__":
    main()
