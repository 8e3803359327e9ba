"""Closed-form IK beside ik-geo and EAIK on the same poses, one core.

For each arm the Rust runner (examples/analytic_ik.rs, a release build) draws
N random configurations inside the limits (ChaCha8 seed 2026), solves their
poses with kinplan's analytic solver (checks: FK of every solution, the sampled
configuration found, Levenberg-Marquardt from 64 seeds finds nothing it
missed; timing: best of 5 passes) and writes the poses and the arm's H/P
vectors. This script then runs the PyPI packages ``ik-geo`` (Rust, Python
bindings) and ``EAIK`` (C++, pybind11) on exactly those poses, checks their
answers with an independent numpy product-of-exponentials FK, and prints one
markdown table with the times as ratios to kinplan's.

ik-geo and EAIK return the (up to 8) configurations with angles in (-pi, pi]
and no joint limits; kinplan's "8-configuration" column is the matching mode
(each joint's turn nearest zero, joints outside the limits dropped), and
"all turns" adds every whole-turn variant inside the limits. ik-geo and EAIK
are timed per call from Python, so their figures include the binding's call
overhead; EAIK's batched call (one worker thread) is given as well, which
amortises it.

    python benches/analytic_ik/run.py --runner target/release/examples/analytic_ik [--n 10000]

Needs ``pip install ik-geo eaik numpy`` (a venv of its own).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ERD = "/work/py-venv-coal/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots/ur_description/urdf"
ARMS = [
    ("kuka_kr210_r2700_extra", None),
    ("kuka_kr120_r2500_pro", None),
    ("abb_irb4600_60_205", None),
    ("ur5", None),
    (f"{ERD}/ur5_robot.urdf", "tool0"),
    (f"{ERD}/ur10_robot.urdf", "tool0"),
]
HERE = os.path.dirname(os.path.abspath(__file__))
# hand-made offset-wrist arms (family searched_6r): `--searched` runs these
SEARCHED = [
    (f"{HERE}/offset_wrist_45.urdf", "tool"),
    (f"{HERE}/offset_wrist_56.urdf", "tool"),
]


def rot(h: np.ndarray, q: float) -> np.ndarray:
    """Rodrigues: rotation about unit axis h by q."""
    k = np.array([[0, -h[2], h[1]], [h[2], 0, -h[0]], [-h[1], h[0], 0]])
    return np.eye(3) + np.sin(q) * k + (1 - np.cos(q)) * (k @ k)


def fk(H: np.ndarray, P: np.ndarray, q) -> tuple[np.ndarray, np.ndarray]:
    """Product-of-exponentials FK in the H/P convention: p = P0 + R1 P1 + ... ."""
    R = np.eye(3)
    p = P[0].copy()
    for i in range(6):
        R = R @ rot(H[i], q[i])
        p = p + R @ P[i + 1]
    return R, p


def wrapped_equal(a, b, tol=1e-6) -> bool:
    d = (np.asarray(a) - np.asarray(b) + np.pi) % (2 * np.pi) - np.pi
    return bool(np.all(np.abs(d) <= tol))


def check(H, P, rows, answers):
    """(exact solutions per pose, poses whose sampled configuration is missing,
    exact solutions whose FK is off by more than 1e-9)."""
    total = missing = bad = 0
    for row, sols in zip(rows, answers):
        q, R, t = row[:6], row[6:15].reshape(3, 3), row[15:18]
        total += len(sols)
        if not any(wrapped_equal(s, q) for s in sols):
            missing += 1
        for s in sols:
            Rs, ps = fk(H, P, s)
            if np.abs(Rs - R).max() > 1e-9 or np.abs(ps - t).max() > 1e-9:
                bad += 1
    return total / len(rows), missing, bad


def best_of(passes, fn):
    best = float("inf")
    for _ in range(passes):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runner", required=True)
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--check", type=int, default=2000, help="poses whose ik-geo/EAIK answers are FK-checked")
    ap.add_argument("--searched", action="store_true",
                    help="the offset-wrist arms (searched_6r) instead: ik-geo's 1-D search solver "
                         "(two_parallel) beside kinplan's; EAIK has no decomposition for them")
    ap.add_argument("--geo-n", type=int, default=None, help="poses ik-geo is timed on (default: all)")
    args = ap.parse_args()
    import ik_geo
    from eaik.IK_HP import HPRobot

    out = tempfile.mkdtemp(prefix="analytic_ik_")
    print("| arm | family | kinplan µs (8 configs) | kinplan µs (all turns) | ik-geo µs | ratio ik-geo/kinplan "
          "| EAIK µs | ratio | EAIK batched µs | ratio | solutions/pose kinplan · ik-geo · EAIK "
          "| sampled config missing kinplan · ik-geo · EAIK | FK > 1e-9 ik-geo · EAIK | LM 64 seeds: found, missed |")
    print("|" + "---|" * 14)
    for arm, tip in (SEARCHED if args.searched else ARMS):
        cmd = [args.runner, arm, str(args.n), out] + ([tip] if tip else [])
        res = subprocess.run(cmd, capture_output=True, text=True, check=True)
        line = next(l for l in res.stdout.splitlines() if l.startswith("RESULT"))
        print(res.stdout.splitlines()[0], file=sys.stderr)
        _, label, family, n, total, all_count, missing, bad_fk, lm_found, lm_missed, us8, usall = line.split()
        rows = np.loadtxt(f"{out}/{label}.csv")
        hp = np.loadtxt(f"{out}/{label}_hp.txt")
        H, P = hp[:6], hp[6:]
        # ik-geo: the decomposition matching our family; it takes rotations column-major
        make = {
            "spherical_wrist": ik_geo.Robot.spherical_two_parallel,
            "three_parallel": ik_geo.Robot.three_parallel_two_intersecting,
            "searched_6r": ik_geo.Robot.two_parallel,
        }[family]
        geo = make(H.tolist(), P.tolist())
        geo_in = [(row[6:15].reshape(3, 3).T.tolist(), row[15:18].tolist()) for row in rows]
        geo_n = min(args.geo_n or len(rows), len(rows))
        if family == "searched_6r":
            try:
                geo.get_ik(*geo_in[0])
            except BaseException as e:  # pyo3 turns a Rust panic into PanicException
                print(f"| {label} | {family} | {float(us8):.2f} | {float(usall):.2f} | ik-geo two_parallel panics "
                      f"({type(e).__name__}) | — | — | — | — | — | {int(total) / int(n):.2f} · — · — "
                      f"| {missing}/{n} · — · — | — | {lm_found}, {lm_missed} |", flush=True)
                continue
        geo_time = best_of(3, lambda: [geo.get_ik(R, t) for R, t in geo_in[:geo_n]]) / geo_n * 1e6
        if family == "searched_6r":
            # ik-geo flags every searched answer least-squares and refines it
            # coarsely: keep those whose FK reaches the pose to 1e-4 (rotation
            # entries, m), and count the sampled configuration found at 1e-3 rad
            rows_c = rows[: args.check]
            g_total = g_miss = g_worst = 0.0
            for (R, t), row in zip(geo_in[: args.check], rows_c):
                Rw, tw = row[6:15].reshape(3, 3), row[15:18]
                kept = []
                for s in geo.get_ik(R, t):
                    Rs, ts = fk(H, P, s[0])
                    err = max(np.abs(Rs - Rw).max(), np.abs(ts - tw).max())
                    if err <= 1e-4:
                        kept.append(s[0])
                        g_worst = max(g_worst, err)
                g_total += len(kept)
                g_miss += not any(wrapped_equal(s, row[:6], 1e-3) for s in kept)
            g_per, g_bad = g_total / len(rows_c), f"worst FK {g_worst:.1e}"
            us8, usall = float(us8), float(usall)
            print(f"| {label} | {family} | {us8:.2f} | {usall:.2f} | {geo_time:.2f} | {geo_time / us8:.2f} "
                  f"| — | — | — | — | {int(total) / int(n):.2f} · {g_per:.2f} · — "
                  f"| {missing}/{n} · {int(g_miss)}/{len(rows_c)} (1e-3 rad) · — | {g_bad} · — "
                  f"| {lm_found}, {lm_missed} |", flush=True)
            continue
        geo_ans = [[s[0] for s in geo.get_ik(R, t) if not s[1]] for R, t in geo_in[: args.check]]
        eaik = HPRobot(H, P)
        Ts = []
        for row in rows:
            T = np.eye(4)
            T[:3, :3] = row[6:15].reshape(3, 3)
            T[:3, 3] = row[15:18]
            Ts.append(T)
        eaik_time = best_of(3, lambda: [eaik.IK(T) for T in Ts]) / len(rows) * 1e6
        eaik_batch = best_of(3, lambda: eaik.IK_batched(Ts, 1)) / len(rows) * 1e6
        eaik_ans = []
        for T in Ts[: args.check]:
            s = eaik.IK(T)
            eaik_ans.append([q for q, ls in zip(np.asarray(s.Q), np.asarray(s.is_LS)) if not ls])
        rows_c = rows[: args.check]
        g_per, g_miss, g_bad = check(H, P, rows_c, geo_ans)
        e_per, e_miss, e_bad = check(H, P, rows_c, eaik_ans)
        us8, usall = float(us8), float(usall)
        print(f"| {label} | {family} | {us8:.2f} | {usall:.2f} | {geo_time:.2f} | {geo_time / us8:.2f} "
              f"| {eaik_time:.2f} | {eaik_time / us8:.2f} | {eaik_batch:.2f} | {eaik_batch / us8:.2f} "
              f"| {int(total) / int(n):.2f} · {g_per:.2f} · {e_per:.2f} "
              f"| {missing}/{n} · {g_miss}/{len(rows_c)} · {e_miss}/{len(rows_c)} | {g_bad} · {e_bad} "
              f"| {lm_found}, {lm_missed} |", flush=True)
    print(f"\n(kinplan: {args.n} poses per arm; ik-geo/EAIK timed on the same {args.n}, their answers checked on "
          f"the first {args.check}.)")


if __name__ == "__main__":
    main()
