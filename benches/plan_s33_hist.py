"""Histograms of the S0 §3.3 deviations written by `examples/plan_s0 s33`.

Usage: target/plotenv/bin/python benches/plan_s33_hist.py OUT.png LABEL=CSV [LABEL=CSV ...]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    t, r = [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            t.append(float(row["translation_m"]))
            r.append(float(row["rotation_rad"]))
    return t, r


def main():
    out = sys.argv[1]
    runs = [a.rsplit("=", 1) for a in sys.argv[2:]]
    fig, axes = plt.subplots(len(runs), 2, figsize=(10, 3.2 * len(runs)), squeeze=False)
    for (label, path), (ax_t, ax_r) in zip(runs, axes):
        t, r = load(path)
        ax_t.hist(t, bins=50, range=(0, max(1.05, max(t))), color="tab:blue")
        ax_t.axvline(1.0, color="red", ls="--", label="t_t = 1 m")
        ax_t.set_title(f"{label}: e_t, {len(t)} waypoints", fontsize=9)
        ax_t.set_xlabel("e_t [m]")
        ax_t.set_ylabel("waypoints")
        ax_t.set_yscale("log")
        ax_t.legend()
        ax_r.hist(r, bins=50, range=(0, max(0.21, max(r))), color="tab:green")
        ax_r.axvline(0.2, color="red", ls="--", label="t_r = 0.2 rad")
        ax_r.set_title(f"{label}: e_r", fontsize=9)
        ax_r.set_xlabel("e_r [rad]")
        ax_r.set_yscale("log")
        ax_r.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
