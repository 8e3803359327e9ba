"""Ours beside VAMP on the MotionBenchMaker Panda sets, interleaved set by set.

On a shared host the speed of the machine drifts by tens of percent over
seconds to minutes (the same binary's set median moved 300 -> 480 us between
runs a minute apart in session 5), so two back-to-back whole runs can land in
different speed regimes.  Here every round times VAMP on a set and then ours on
the same set (the order flips every round), so each ratio compares two runs
made within seconds of each other; the report gives every round's pair, the
median ratio over rounds per set, and the medians of the pooled times.

VAMP is timed in this process through its Python API, as
../../shared/anchors/vamp/bench_rrtc.py does (same settings: RRT-Connect with
vamp.configure_robot_and_planner_with_kwargs defaults, Halton sampler reset
before every problem, planner's own nanosecond timer, per-problem median over
passes, then the median over solved problems).  Ours is examples/mbm_bench
(--padded unless --plain), whose JSON gives the same statistic.

    python benches/mbm/interleaved.py --vamp-dataset /work/vampwork/src/resources/panda/problems.pkl \\
        --ours target/release/examples/mbm_bench [--before <older build>/mbm_bench] \\
        --problems target/mbm/problems --rounds 5 --passes 3 --out target/interleaved.json
"""
import argparse
import csv
import json
import pickle
import statistics
import subprocess
import time

import numpy as np
import vamp

SETS = ['table_pick', 'table_under_pick', 'box', 'bookshelf_small', 'bookshelf_tall', 'bookshelf_thin', 'cage']


def vamp_set(pset, passes, module, planner, settings, sampler):
    """Median over solved problems of the per-problem median over passes (us),
    solved, valid, and the per-problem medians by problem index."""
    envs = [(p, vamp.problem_dict_to_vamp(p)) for p in pset if p['valid']]
    times = np.zeros((len(envs), passes))
    solved = np.zeros(len(envs), dtype=bool)
    for k in range(passes):
        for j, (p, env) in enumerate(envs):
            sampler.reset()
            r = planner(p['start'], p['goals'], env, settings, sampler)
            times[j, k] = r.nanoseconds / 1e3
            if k == 0:
                solved[j] = bool(r.solved)
    per_problem = {p['index']: float(np.median(times[j])) for j, (p, _) in enumerate(envs) if solved[j]}
    return float(np.median(np.median(times[solved], axis=1))), int(solved.sum()), len(envs), per_problem


def ours_set(binary, problems, name, passes, padded, out):
    cmd = [binary, problems, '--passes', str(passes), '--set', name, '--out', out]
    if padded:
        cmd.append('--padded')
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    s = json.load(open(out + '.json'))['sets'][name]
    with open(out + '.csv') as f:
        rows = list(csv.DictReader(f))
    per_problem = {int(r['problem']): float(r['search_robust_us']) for r in rows
                   if r['set'] == name and r['solved'] == 'true'}
    return s['search_robust_median_us'], s['solved'], s['valid'], per_problem


def common_ratio(ours, vamp_times):
    """Median of ours over the median of VAMP's on the problems both solved
    (each checks the problems valid for its own model), and their count."""
    both = sorted(set(ours) & set(vamp_times))
    if not both:
        return float('nan'), 0
    return statistics.median(ours[k] for k in both) / statistics.median(vamp_times[k] for k in both), len(both)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--vamp-dataset', required=True)
    ap.add_argument('--ours', required=True)
    ap.add_argument('--before', help='an earlier build of mbm_bench, timed in the same rounds')
    ap.add_argument('--problems', required=True)
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--passes', type=int, default=3)
    ap.add_argument('--plain', action='store_true', help='our interpolated check instead of --padded')
    ap.add_argument('--sets', default=','.join(SETS))
    ap.add_argument('--out', default='target/interleaved.json')
    args = ap.parse_args()

    data = pickle.load(open(args.vamp_dataset, 'rb'))['problems']
    module, planner, settings, _ = vamp.configure_robot_and_planner_with_kwargs('panda', 'rrtc')
    sampler = module.halton()
    sets = args.sets.split(',')
    rows = {s: [] for s in sets}
    tick = time.time()
    for r in range(args.rounds):
        for name in sets:
            pset = data.get(name) or data[f'{name}_panda']
            run_vamp = lambda: vamp_set(pset, args.passes, module, planner, settings, sampler)
            run_ours = lambda: ours_set(args.ours, args.problems, name, args.passes, not args.plain,
                                        args.out[:-len('.json')] + '_ours')
            run_before = lambda: ours_set(args.before, args.problems, name, args.passes, not args.plain,
                                          args.out[:-len('.json')] + '_before')
            if r % 2 == 0:
                v, o = run_vamp(), run_ours()
                b = run_before() if args.before else None
            else:
                b = run_before() if args.before else None
                o = run_ours()
                v = run_vamp()
            common, n_common = common_ratio(o[3], v[3])
            row = {'round': r + 1, 'vamp_us': v[0], 'vamp_solved': v[1], 'vamp_valid': v[2],
                   'ours_us': o[0], 'ours_solved': o[1], 'ours_valid': o[2], 'ratio': o[0] / v[0],
                   'common_ratio': common, 'common_problems': n_common}
            if b:
                row.update({'before_us': b[0], 'before_solved': b[1], 'before_ratio': b[0] / v[0],
                            'before_common_ratio': common_ratio(b[3], v[3])[0]})
            rows[name].append(row)
            extra = f', before {b[0]:.1f} us ({b[1]}, ratio {b[0] / v[0]:.2f})' if b else ''
            print(f'round {r + 1} {name}: VAMP {v[0]:.1f} us ({v[1]}/{v[2]}), ours {o[0]:.1f} us '
                  f'({o[1]}/{o[2]}), ratio {o[0] / v[0]:.2f}{extra}', flush=True)
    summary = {}
    print('\n| set | VAMP median of rounds, us | ours median of rounds, us | ratio per round | median ratio |'
          ' same problems: median ratio (problems) | before: median of rounds, us | before: median ratio |'
          ' before, same problems |')
    print('|---|---|---|---|---|---|---|---|---|')
    for name in sets:
        rs = rows[name]
        v = statistics.median(x['vamp_us'] for x in rs)
        o = statistics.median(x['ours_us'] for x in rs)
        ratios = [x['ratio'] for x in rs]
        summary[name] = {'vamp_us': v, 'ours_us': o, 'median_ratio': statistics.median(ratios),
                         'ratios': ratios, 'rounds': rs}
        common = statistics.median(x['common_ratio'] for x in rs)
        summary[name]['common_median_ratio'] = common
        before = '– | – | –'
        if args.before:
            bu = statistics.median(x['before_us'] for x in rs)
            br = statistics.median(x['before_ratio'] for x in rs)
            bc = statistics.median(x['before_common_ratio'] for x in rs)
            summary[name].update({'before_us': bu, 'before_median_ratio': br, 'before_common_median_ratio': bc})
            before = f'{bu:.1f} | {br:.2f} | {bc:.2f}'
        print(f"| {name} | {v:.1f} | {o:.1f} | {' '.join(f'{x:.2f}' for x in ratios)} | "
              f"**{statistics.median(ratios):.2f}** | {common:.2f} ({rs[0]['common_problems']}) | {before} |")
    json.dump({'rounds': args.rounds, 'passes': args.passes, 'padded': not args.plain,
               'wall_s': time.time() - tick, 'sets': summary}, open(args.out, 'w'), indent=1)
    print(f'wrote {args.out} ({time.time() - tick:.0f} s)')


if __name__ == '__main__':
    main()
