"""OMPL's RRTConnect (PyPI `ompl`) on the MotionBenchMaker Panda problems,
with the coal checker of `panda_coal.py` (kinplan's Panda-with-hand shapes
and self pairs, posed by numpy FK, against the scene's primitives).

    target/anchor-venv/bin/python benches/mbm/ompl_rrtc.py target/mbm/problems \
        --acm target/mbm_bench.acm.json [--per-set 100] [--timeout 10] [--out target/mbm_ompl.json]

Settings chosen to match ours: range 1.0 rad (as kinplan and VAMP), motion
checked every 0.05 rad (OMPL's longest valid segment, Euclidean: at least as
fine as kinplan's 0.05 rad max-norm), sampling in the joint limits, global
seed 1 (OMPL seeds once per process). Time: `getLastPlanComputationTime()`
(planner only, no simplification), which includes every Python call of the
validity callback — the coal checks cost tens of µs per state from Python,
so this times "OMPL driven from Python", not OMPL's C++ alone; the count of
checked states is reported so the checker's share can be separated.
"""
import argparse
import json
import os
import platform
import sys
import time

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from panda_coal import URDF, Panda, Scene, request  # noqa: E402

SETS = ['table_pick', 'table_under_pick', 'box', 'bookshelf_small', 'bookshelf_tall', 'bookshelf_thin', 'cage']


def stats(v):
    a = np.asarray(v, dtype = float)
    if a.size == 0:
        return {}
    return {'median': float(np.median(a)), 'mean': float(a.mean()), 'p95': float(np.percentile(a, 95)),
            'max': float(a.max())}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('problems')
    ap.add_argument('--acm', default = 'target/mbm_bench.acm.json')
    ap.add_argument('--per-set', type = int, default = 100)
    ap.add_argument('--timeout', type = float, default = 10.0)
    ap.add_argument('--out', default = 'target/mbm_ompl.json')
    args = ap.parse_args()
    ou.setLogLevel(ou.LogLevel.LOG_ERROR)
    ou.RNG.setSeed(1)
    robots = {}
    out = {'planner': 'ompl RRTConnect', 'ompl': '2.0.1', 'python': platform.python_version(), 'range': 1.0,
           'longest_valid_segment': 0.05, 'timeout_s': args.timeout, 'sets': {}}
    for name in SETS:
        d = os.path.join(args.problems, f'{name}_panda')
        times, checks_per_ms, lengths, check_us = [], [], [], []
        n = valid = solved = 0
        invalid = []
        for k in range(1, args.per_set + 1):
            sp = os.path.join(d, f'scene{k:04d}.yaml')
            if not os.path.exists(sp):
                continue
            n += 1
            start, goal, opening = request(os.path.join(d, f'request{k:04d}.yaml'))
            if opening not in robots:
                robots[opening] = Panda(URDF, args.acm, opening)
            robot = robots[opening]
            scene = Scene(sp)
            if not (robot.valid(start, scene) and robot.valid(goal, scene)):
                invalid.append(k)
                continue
            valid += 1
            space = ob.RealVectorStateSpace(7)
            bounds = ob.RealVectorBounds(7)
            for i in range(7):
                bounds.setLow(i, float(robot.lower[i]))
                bounds.setHigh(i, float(robot.upper[i]))
            space.setBounds(bounds)
            ss = og.SimpleSetup(space)
            counter = [0]
            q = np.zeros(7)

            def is_valid(s):
                counter[0] += 1
                for i in range(7):
                    q[i] = s[i]
                return robot.valid(q, scene)

            ss.setStateValidityChecker(is_valid)
            si = ss.getSpaceInformation()
            # Euclidean segment length 0.05 rad as a fraction of the space's extent
            si.setStateValidityCheckingResolution(0.05 / space.getMaximumExtent())
            planner = og.RRTConnect(si)
            planner.setRange(1.0)
            ss.setPlanner(planner)
            s0, s1 = space.allocState(), space.allocState()
            for i in range(7):
                s0[i] = float(start[i])
                s1[i] = float(goal[i])
            ss.setStartAndGoalStates(s0, s1)
            ss.setup()
            status = ss.solve(args.timeout)
            t = ss.getLastPlanComputationTime()
            if ss.haveExactSolutionPath():
                solved += 1
                times.append(t * 1e3)
                path = ss.getSolutionPath()
                pts = np.array([[path.getState(i)[j] for j in range(7)] for i in range(path.getStateCount())])
                lengths.append(float(np.linalg.norm(np.diff(pts, axis = 0), axis = 1).sum()))
                if counter[0]:
                    check_us.append(t * 1e6 / counter[0])
            print(f'{name} {k}: {status} {t * 1e3:.1f} ms, {counter[0]} states', file = sys.stderr)
        out['sets'][name] = {'problems': n, 'valid': valid, 'solved': solved, 'time_ms': stats(times),
                             'us_per_checked_state': stats(check_us), 'length_rad': stats(lengths),
                             'invalid_problems': invalid}
        s = out['sets'][name]
        print(f"| {name} | {n} | {valid} | {solved} | {s['time_ms'].get('median', float('nan')):.1f} / "
              f"{s['time_ms'].get('p95', float('nan')):.1f} | {s['us_per_checked_state'].get('median', float('nan')):.1f} | "
              f"{s['length_rad'].get('median', float('nan')):.3f} |", flush = True)
    with open(args.out, 'w') as f:
        json.dump(out, f, indent = 1)


if __name__ == '__main__':
    main()
