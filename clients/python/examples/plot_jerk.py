"""Per-waypoint pseudo-jerk of a KR 210 trajectory with its peaks (S0 §2).

Start a server (`cargo run --release -- serve`), then
    MPLBACKEND=Agg python clients/python/examples/plot_jerk.py [address] [out.png]
(needs matplotlib: pip install 'kinplan[plot]'). Plots the joint pseudo-jerk
sum_j |third difference of q_j| (rad) and the Cartesian one |third
difference of p| (m) per waypoint, marks the peaks that enter JJP and CJP
with their predicted slowdowns, and saves a PNG (default jerk.png).
With the regressions as printed (the default), peaks below 10^(-4/3) rad
predict a negative joint slowdown; pass jerk_peaks={"slowdown_floor": 1.0}
to c.score to bound them (see src/score/README.md).
"""
import sys

import matplotlib.pyplot as plt
import numpy as np

import kinplan

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "jerk.png"

# A smooth move of all six axes with two kinks, as a planner's waypoints
# might have them: A2 and A3 change direction abruptly at 35 % and 70 %.
n = 200
s = np.linspace(0.0, 1.0, n)
q = np.column_stack(
    [
        0.9 * s,
        -1.5 + 0.4 * np.abs(s - 0.35),
        1.4 - 0.5 * np.abs(s - 0.7),
        0.3 * np.sin(2 * np.pi * s),
        0.5 + 0.2 * s,
        -0.4 * s,
    ]
)

with kinplan.Client(address, timeout=10) as c:
    scores = c.robot("kuka_kr210_r2700_extra").score(q, series=True)

series = scores.series
assert series is not None, "series=True returns the per-waypoint series"
fig, (ax_j, ax_c) = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
for ax, values, peaks, unit, key in (
    (ax_j, series.joint_jerk, series.joint_peaks, "rad", "JJP"),
    (ax_c, series.cartesian_jerk, series.cartesian_peaks, "m", "CJP"),
):
    ax.plot(np.arange(len(values)), values, lw=1.0)
    idx = [p.index for p in peaks]
    ax.plot(idx, [values[i] for i in idx], "v", color="C3", label=f"peaks ({key} = {scores[key]:.3g})")
    for p in peaks:
        ax.annotate(f"{p.slowdown:.2f}", (p.index, p.height), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_ylabel(f"pseudo-jerk [{unit}]")
    ax.set_yscale("symlog", linthresh=1e-9)
    ax.legend(loc="upper right")
ax_j.set_title(f"KR 210: JJ = {scores['JJ']:.3g} rad, CJ = {scores['CJ']:.3g} m (peak labels: predicted slowdown)")
ax_c.set_xlabel("waypoint")
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"saved {out}: {len(series.joint_peaks)} joint peaks, {len(series.cartesian_peaks)} Cartesian peaks")
print({k: round(v, 6) for k, v in scores.items()})
