"""Side-by-side table of the MotionBenchMaker runs: ours (examples/mbm_bench.rs
JSON), VAMP (bench_rrtc.py JSON from the anchors dir) and OMPL
(benches/mbm/ompl_rrtc.py JSON), with the ratio of per-set medians
ours / VAMP (pass-1 and robust = median over passes).

    python3 benches/mbm/compare.py target/mbm_bench.json target/vamp/rrtc_panda.json [target/mbm_ompl.json]
"""
import csv
import json
import statistics
import sys

SETS = ['table_pick', 'table_under_pick', 'box', 'bookshelf_small', 'bookshelf_tall', 'bookshelf_thin', 'cage']


def main():
    ours = json.load(open(sys.argv[1]))
    vamp = json.load(open(sys.argv[2]))
    ompl = json.load(open(sys.argv[3])) if len(sys.argv) > 3 else None
    # Every path the planner returned, whether or not it passed the fine check
    # (planning time does not depend on the verdict).
    returned = {}
    with open(sys.argv[1][:-len('.json')] + '.csv') as f:
        for r in csv.DictReader(f):
            if r['stop'] == 'Connected':
                returned.setdefault(r['set'], []).append(float(r['search_robust_us']))
    print('| set | valid ours (VAMP) | solved ours (VAMP) | ours median / p95 µs | ours robust median µs '
          '| VAMP median / p95 µs | VAMP robust median µs | ratio ours/VAMP (robust) | OMPL solved, median ms '
          '| path length ours, median rad | returned by ours, robust median µs (ratio) |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for s in SETS:
        o = ours['sets'][s]
        v = vamp['sets'].get(s) or vamp['sets'].get(f'{s}_panda')
        om = (ompl or {}).get('sets', {}).get(s)
        ratio = o['search_median_us'] / v['pass1']['median_us']
        ratio_r = o['search_robust_median_us'] / v['robust']['median_us']
        om_txt = '–'
        if om:
            med = om['time_ms'].get('median')
            om_txt = f"{om['solved']}/{om['valid']}, {med:.1f}" if med is not None else f"{om['solved']}/{om['valid']}"
        print(f"| {s} | {o['valid']} ({v['valid']}) | {o['solved']} ({v['solved']}) | "
              f"{o['search_median_us']:.0f} / {o['search_p95_us']:.0f} | {o['search_robust_median_us']:.0f} | "
              f"{v['pass1']['median_us']:.0f} / {v['pass1']['p95_us']:.0f} | {v['robust']['median_us']:.0f} | "
              f"{ratio:.1f}× ({ratio_r:.1f}×) | {om_txt} | {o['length_median_rad']:.2f} | "
              f"{len(returned[s])}, {statistics.median(returned[s]):.0f} "
              f"({statistics.median(returned[s]) / v['robust']['median_us']:.1f}×) |")
    a, va = ours['all'], vamp['all']
    print(f"| all | {a['valid']} ({va['valid']}) | {a['solved']} ({va['solved']}) | "
          f"{a['search_median_us']:.0f} / {a['search_p95_us']:.0f} | | {va['pass1']['median_us']:.0f} / "
          f"{va['pass1']['p95_us']:.0f} | {va['robust']['median_us']:.0f} | "
          f"{a['search_median_us'] / va['pass1']['median_us']:.1f}× | | | "
          f"{sum(len(x) for x in returned.values())} |")


if __name__ == '__main__':
    main()
