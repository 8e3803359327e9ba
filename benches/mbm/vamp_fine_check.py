"""Do VAMP's RRT-Connect paths survive a finer check with VAMP's own model?

Plans every valid MotionBenchMaker Panda problem exactly as the anchors'
bench_rrtc.py does (VAMP's RRT-Connect defaults, Halton sampler reset per
problem, raw path, no simplification), then walks every segment of the
returned path at <= 0.01 rad per joint (ceil(span/0.01) uniform steps, ends
included) with `vamp.panda.validate` on the same environment: the same
independent check examples/mbm_bench.rs applies to kinplan's paths, with
VAMP's sphere model as the truth instead of ours.

    target/vamp/venv/bin/python benches/mbm/vamp_fine_check.py target/vamp/src/resources/panda/problems.pkl
"""
import math
import pickle
import sys

import numpy as np
import vamp


def main():
    with open(sys.argv[1], 'rb') as f:
        data = pickle.load(f)
    module, planner, settings, _ = vamp.configure_robot_and_planner_with_kwargs('panda', 'rrtc')
    sampler = module.halton()
    print('| set | valid | solved | paths failing the 0.01 rad check | states checked |')
    print('|---|---|---|---|---|')
    for name, pset in data['problems'].items():
        valid = solved = failing = checked = 0
        for p in pset:
            if not p['valid']:
                continue
            valid += 1
            env = vamp.problem_dict_to_vamp(p)
            sampler.reset()
            r = planner(p['start'], p['goals'], env, settings, sampler)
            if not r.solved:
                continue
            solved += 1
            # index, do not iterate: Path's iterator does not stop
            pts = [np.asarray(r.path[i], dtype = float) for i in range(len(r.path))]
            ok = True
            for a, b in zip(pts, pts[1:]):
                n = max(1, math.ceil(np.abs(b - a).max() / 0.01))
                for i in range(n + 1):
                    checked += 1
                    if not module.validate(list(a + (b - a) * (i / n)), env):
                        ok = False
                        break
                if not ok:
                    break
            failing += not ok
        print(f'| {name} | {valid} | {solved} | {failing} | {checked} |', flush = True)


if __name__ == '__main__':
    main()
