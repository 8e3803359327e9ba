"""Cost of one state check on the MotionBenchMaker scenes: VAMP's beside ours,
on the same states.

VAMP's Python API cannot time it: `validate` costs more in binding and
argument conversion (the environment is converted on every call) than the
check, and `validate_motion` checks one block of eight states at the
binding's resolution whatever the motion's length. So the check is timed in
C++ (`vamp_state_cost.cc`, VAMP's headers, its own compiler flags): per
problem, this script writes the scene's primitives as
`vamp.problem_dict_to_vamp` builds them (the box set's cylinders as boxes,
the others' as capsules) and `--states` states drawn uniformly within both
Panda models' joint limits (numpy, seed = problem number), runs the harness, which times
VAMP's `fkcc` on blocks of eight (all states; then only the states VAMP
finds free, the whole check) and writes its verdicts, then runs
`mbm_bench --states-from`, which times our `is_valid` on the same states
(the free ones only; groups of eight that stop at their first collision, as
VAMP's blocks; one by one) and counts the states where the verdicts differ
(the geometries differ: VAMP's spheres against our capsules and hand).
Per set, the medians over its problems.

    g++ ... benches/mbm/vamp_state_cost.cc -o target/vamp_state_cost   (flags in its header)
    cargo build --release -p kinplan-core --example mbm_bench
    /work/vampwork/venv/bin/python benches/mbm/state_cost_vamp.py \\
        --vamp-dataset /work/vampwork/src/resources/panda/problems.pkl \\
        --harness target/vamp_state_cost --ours target/release/examples/mbm_bench \\
        --problems target/mbm/problems --out target/mbm_states
"""
import argparse
import json
import os
import pickle
import statistics
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import vamp

URDF = 'crates/kinplan-core/src/robot/builtin/franka_panda_hand.urdf'

SETS = ['table_pick', 'table_under_pick', 'box', 'bookshelf_small', 'bookshelf_tall', 'bookshelf_thin', 'cage']


def panda_limits():
    """The arm joints' limits of our built-in Panda (VAMP's are wider on
    joints 1, 3, 4, 5, 6 and 7: a state outside ours is refused by our limit
    check, not by a collision test, so the states are drawn where both agree)."""
    root = ET.parse(URDF).getroot()
    limit = {j.get('name'): j.find('limit') for j in root.iter('joint')}
    lo = [float(limit[f'joint_{i}'].get('lower')) for i in range(1, 8)]
    hi = [float(limit[f'joint_{i}'].get('upper')) for i in range(1, 8)]
    return np.array(lo), np.array(hi)


def write_env(p, path):
    """The primitives of vamp.problem_dict_to_vamp(p), one per line."""
    lines = []
    for o in p['sphere']:
        lines.append('sphere %r %r %r %r' % (*o['position'], o['radius']))
    for o in p['cylinder']:
        c, e = o['position'], o['orientation_euler_xyz']
        if p['problem'] == 'box':
            lines.append('cuboid %r %r %r %r %r %r %r %r %r' % (*c, *e, o['radius'], o['radius'], o['length'] / 2))
        else:
            lines.append('capsule %r %r %r %r %r %r %r %r' % (*c, *e, o['radius'], o['length']))
    for o in p['box']:
        lines.append('cuboid %r %r %r %r %r %r %r %r %r' % (*o['position'], *o['orientation_euler_xyz'],
                                                           *o['half_extents']))
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--vamp-dataset', required=True)
    ap.add_argument('--harness', required=True)
    ap.add_argument('--ours', required=True)
    ap.add_argument('--problems', required=True, help='the extracted MotionBenchMaker problems')
    ap.add_argument('--out', required=True)
    ap.add_argument('--problems-per-set', type=int, default=20)
    ap.add_argument('--states', type=int, default=4000)
    ap.add_argument('--passes', type=int, default=5)
    ap.add_argument('--sets', default=','.join(SETS))
    args = ap.parse_args()

    data = pickle.load(open(args.vamp_dataset, 'rb'))['problems']
    ours_lo, ours_hi = panda_limits()
    lo = np.maximum(vamp.panda.lower_bounds().astype(float), ours_lo)
    hi = np.minimum(vamp.panda.upper_bounds().astype(float), ours_hi)
    summary = {}
    print('| set | problems | VAMP: free states | ours: free states | ours / VAMP | **ours, 8 lanes: free states** | '
          '**8 lanes / VAMP** | VAMP: blocks of 8 | ours: groups of 8 | ours / VAMP | ours, 8 lanes: groups of 8 | '
          '8 lanes / VAMP | ours: one by one | free (VAMP / ours) | verdicts differ |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    for name in args.sets.split(','):
        d = f'{args.out}/{name}_panda'
        os.makedirs(d, exist_ok=True)
        rows = []
        for p in [p for p in data[name] if p['valid']][:args.problems_per_set]:
            k = p['index']
            env, states = f'{d}/env{k:04}.txt', f'{d}/states{k:04}.bin'
            write_env(p, env)
            rng = np.random.default_rng(k)
            rng.uniform(lo, hi, size=(args.states, 7)).astype('<f8').tofile(states)
            n, free, all_ns, free_ns = subprocess.run(
                [args.harness, env, states, str(args.passes)], check=True, capture_output=True,
                text=True).stdout.split()
            ours = json.loads(subprocess.run(
                [args.ours, args.problems, '--set', name, '--problems', str(k), '--states-from', states,
                 '--passes', '1', '--clamp-fingers', '--out', f'{d}/ours{k:04}'], check=True, capture_output=True,
                text=True).stdout.strip().splitlines()[-1])
            rows.append({'problem': k, 'states': int(n), 'vamp_free': int(free), 'vamp_ns': float(all_ns),
                         'vamp_free_ns': float(free_ns), **ours})
        med = lambda key: statistics.median(r[key] for r in rows)
        s = {key: med(key) for key in ['vamp_ns', 'vamp_free_ns', 'ours_ns', 'ours_groups_ns', 'ours_free_ns',
                                        'ours_lanes_groups_ns', 'ours_lanes_free_ns', 'vamp_free', 'ours_free', 'differ']}
        s['problems'] = len(rows)
        summary[name] = {'median': s, 'rows': rows}
        print(f"| {name} | {len(rows)} | {s['vamp_free_ns']:.1f} ns | {s['ours_free_ns']:.1f} ns | "
              f"{s['ours_free_ns'] / s['vamp_free_ns']:.1f}× | **{s['ours_lanes_free_ns']:.1f} ns** | "
              f"**{s['ours_lanes_free_ns'] / s['vamp_free_ns']:.2f}×** | {s['vamp_ns']:.1f} ns | {s['ours_groups_ns']:.1f} ns | "
              f"{s['ours_groups_ns'] / s['vamp_ns']:.1f}× | {s['ours_lanes_groups_ns']:.1f} ns | "
              f"{s['ours_lanes_groups_ns'] / s['vamp_ns']:.2f}× | {s['ours_ns']:.1f} ns | {s['vamp_free'] / args.states:.3f} / "
              f"{s['ours_free'] / args.states:.3f} | {s['differ'] / args.states:.4f} |", flush=True)
    json.dump(summary, open(f'{args.out}/state_cost.json', 'w'), indent=1)


if __name__ == '__main__':
    main()
