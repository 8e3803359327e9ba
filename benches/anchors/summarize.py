#!/usr/bin/env python3
"""Tables for README.md from one session directory of run_session.sh.

    python3 benches/anchors/summarize.py /tmp/anchor-session-A

Ratios are anchor mean / ours mean, where "ours" is the average of the two ik_bench runs
of the same session (one right before the anchors, one right after).
"""

import sys
from pathlib import Path

ANCHORS = ["tracik", "tracik-strict", "kdl", "kdl-strict", "kdl-5ms", "kdl-lma"]
LABEL = {
    "ours": "ours (lm-svd)",
    "tracik": "TRAC-IK, eps 1e-5",
    "tracik-strict": "TRAC-IK, eps 1e-5/√3",
    "kdl": "KDL NR_JL, 100 it, eps 1e-5",
    "kdl-strict": "KDL NR_JL, 100 it, eps 1e-5/√3",
    "kdl-5ms": "KDL NR_JL, until 5 ms",
    "kdl-lma": "KDL LMA",
}


def rows(path, ncols=9):
    out = {}
    for line in Path(path).read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != ncols or cells[0] in ("arm", "---") or cells[0].startswith("-"):
            continue
        out[(cells[0], cells[1])] = cells
    return out


def main():
    d = Path(sys.argv[1])
    ours1, ours2 = rows(d / "ours_1.md"), rows(d / "ours_2.md")
    anchors = {**rows(d / "anchors_tracik.md"), **rows(d / "anchors_kdl.md")}
    arms = [k[0] for k in ours1]
    print("| arm | method | N | success % | mean µs | median µs | p99 µs | mean / ours |")
    print("|---|---|---|---|---|---|---|---|")
    summary = []
    for arm in arms:
        a, b = ours1[(arm, "lm-svd")], ours2[(arm, "lm-svd")]
        ours_mean = 0.5 * (float(a[4]) + float(b[4]))
        print(
            f"| {arm} | {LABEL['ours']} (before / after) | {a[2]} | {a[3]} / {b[3]} | {a[4]} / {b[4]} | "
            f"{a[5]} / {b[5]} | {a[6]} / {b[6]} | 1 |"
        )
        line = [arm, f"{a[3]} / {b[3]} % · {ours_mean:.1f} µs"]
        for name in ANCHORS:
            r = anchors.get((arm, name))
            if r is None:
                line.append("–")
                continue
            ratio = float(r[4]) / ours_mean
            print(f"| {arm} | {LABEL[name]} | {r[2]} | {r[3]} | {r[4]} | {r[5]} | {r[6]} | {ratio:.1f} |")
            line.append(f"{r[3]} % · {r[4]} µs (×{ratio:.0f})")
        summary.append(line)
    print()
    print("| arm | ours | " + " | ".join(LABEL[n] for n in ANCHORS) + " |")
    print("|---" * (2 + len(ANCHORS)) + "|")
    for line in summary:
        print("| " + " | ".join(line) + " |")


if __name__ == "__main__":
    main()
