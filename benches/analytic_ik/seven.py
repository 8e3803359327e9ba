"""7-joint arms with the redundant joint given (and searched) beside EAIK's locked joint.

For the Panda (joint 7 held) and the iiwa (joint 3 held), the Rust runner
(examples/analytic_ik.rs, release build) times kinplan's closed form with the
held joint at each pose's sampled value, through ``IkSolver`` as the service
answers, and with it searched for the solution nearest a seed beside
Levenberg-Marquardt from the same seed; it also writes N poses whose held
joint is 0.5 rad and the chain's H/P vectors. This script runs the PyPI
package ``EAIK`` (C++, pybind11; ``HPRobot(H, P, fixed_axes=[(j, 0.5)])``, a
joint locked at construction) on exactly those poses, checks its answers with
an independent numpy product-of-exponentials FK, and prints one markdown table.

    python benches/analytic_ik/seven.py --runner target/release/examples/analytic_ik [--n 10000]

Needs ``pip install eaik numpy`` (a venv of its own).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile

import numpy as np

# the H/P FK and the timer of the 6R script beside this one (its directory is on sys.path
# when this file runs as a script)
from run import best_of, fk  # noqa: E402

ARMS = ["franka_panda", "kuka_lbr_iiwa14_r820"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runner", required=True)
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--check", type=int, default=2000, help="poses whose EAIK answers are FK-checked")
    args = ap.parse_args()
    from eaik.IK_HP import HPRobot

    out = tempfile.mkdtemp(prefix="analytic_ik7_")
    rows_out = []
    for arm in ARMS:
        res = subprocess.run([args.runner, arm, str(args.n), out], capture_output=True, text=True, check=True)
        print(res.stdout.splitlines()[0], file=sys.stderr)
        line = next(l for l in res.stdout.splitlines() if l.startswith("RESULT7"))
        (_, label, family, reversed_, n, total, missing, bad, held_us, service_us, fixed_us, search_us,
         search_solved, search_near, search_d, lm_us, lm_solved, lm_near, lm_d, j) = line.split()
        j = int(j)
        rows = np.loadtxt(f"{out}/{label}.csv")
        hp = np.loadtxt(f"{out}/{label}_hp.txt")
        H, P = hp[:7], hp[7:]
        robot = HPRobot(H, P, fixed_axes=[(j, 0.5)])
        Ts = []
        for row in rows:
            T = np.eye(4)
            T[:3, :3] = row[7:16].reshape(3, 3)
            T[:3, 3] = row[16:19]
            Ts.append(T)
        eaik_us = best_of(3, lambda: [robot.IK(T) for T in Ts]) / len(rows) * 1e6
        eaik_batch = best_of(3, lambda: robot.IK_batched(Ts, 1)) / len(rows) * 1e6
        per = miss = badfk = 0
        ours = rows[:, 19].sum() / len(rows)
        for row, T in zip(rows[: args.check], Ts[: args.check]):
            s = robot.IK(T)
            sols = [q for q, ls in zip(np.asarray(s.Q), np.asarray(s.is_LS)) if not ls]
            per += len(sols)
            q = row[:7]
            d = lambda a: (np.asarray(a) - q + np.pi) % (2 * np.pi) - np.pi
            if not any(np.all(np.abs(d(a)) < 1e-6) for a in sols):
                miss += 1
            for a in sols:
                R, p = fk(H, P, a)
                if np.abs(R - T[:3, :3]).max() > 1e-9 or np.abs(p - T[:3, 3]).max() > 1e-9:
                    badfk += 1
        check = min(args.check, len(rows))
        fixed_us = float(fixed_us)
        rows_out.append(
            f"| {label} | {j + 1} | {family}{' (reversed)' if reversed_ == 'true' else ''} "
            f"| {float(held_us):.2f} | {float(service_us):.2f} | {fixed_us:.2f} | {eaik_us:.2f} ({eaik_us / fixed_us:.2f}) "
            f"| {eaik_batch:.2f} ({eaik_batch / fixed_us:.2f}) | {ours:.2f} · {per / check:.2f} "
            f"| {missing}/{n} · {miss}/{check} | {bad} · {badfk} "
            f"| {float(search_us):.1f} | {search_near}/{n} | {float(search_d):.4f} "
            f"| {float(lm_us):.1f} ({float(lm_us) / float(search_us):.2f}) | {lm_near}/{n} | {float(lm_d):.4f} |")
    print("| arm | held joint | family | kinplan µs, held at sampled value | via IkSolver µs | kinplan µs, held at 0.5 "
          "| EAIK µs (ratio) | EAIK batched µs (ratio) | solutions/pose (limits) kinplan · EAIK (none) "
          "| sampled config missing kinplan · EAIK | FK > 1e-9 kinplan · EAIK "
          "| searched µs | searched as near as pose's joints | searched mean d² "
          "| LM µs (ratio) | LM as near | LM mean d² |")
    print("|" + "---|" * 16)
    for r in rows_out:
        print(r)


if __name__ == "__main__":
    main()
