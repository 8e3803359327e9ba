"""S0 §5.2-5.3 in pictures: explore kinplan's reference cells with the
IRB 4600 and a simulated Kinect v2, and plot

1. the known ratio per iteration for S0's weight sets (S0 Fig. 5.9),
2. histograms of CD and OC per trajectory for RRT-Connect, STOMP and
   CCSTOMP on the open cell (S0 Fig. 5.4, 5.7, 5.10, 5.11),
3. the final octree of one run, occupied cells in 3-D.

    python explore_s0.py [host:port] [out_prefix]

Needs matplotlib and a running `kinplan serve`; writes
<out_prefix>_known_ratio.png, _criteria.png and _octree.png.
"""
from typing import Any

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import kinplan

WEIGHTS = {
    "IG1_T0_R0": (1.0, 0.0, 0.0),
    "IG0_T1_R0": (0.0, 1.0, 0.0),
    "IG0_T0_R1": (0.0, 0.0, 1.0),
    "IG1_T1_R1": (1.0, 1.0, 1.0),
    "IG1_T025_R01": (1.0, 0.25, 0.1),
    "IG1_T05_R01": (1.0, 0.5, 0.1),
}
SETS = {
    "s0_open_cell": ["IG1_T0_R0", "IG0_T1_R0", "IG0_T0_R1", "IG1_T1_R1"],
    "s0_walled_cell": ["IG1_T0_R0", "IG0_T1_R0", "IG1_T025_R01", "IG1_T05_R01"],
}


def run(client: Any, scene: Any, **kw: Any) -> Any:
    *steps, summary = client.explore(scene=scene, timeout=300, **kw)
    return steps, summary


def main() -> None:
    address = sys.argv[1] if len(sys.argv) > 1 else "localhost:50051"
    prefix = sys.argv[2] if len(sys.argv) > 2 else "explore_s0"
    client = kinplan.Client(address, timeout=300)
    scenes = {"s0_open_cell": kinplan.scenes.s0_open_cell, "s0_walled_cell": kinplan.scenes.s0_walled_cell}

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    last: Any = None
    for ax, (name, sets) in zip(axes, SETS.items()):
        scene = scenes[name](client)
        for w in sets:
            steps, summary = run(client, scene, planner="rrt_connect", weights=WEIGHTS[w])
            ratios = [summary.initial_known_ratio] + [s.known_ratio for s in steps]
            ax.plot(range(len(ratios)), ratios, marker=".", label=f"{w} ({summary.status.lower()})")
            print(f"{name} {w}: {summary}  totals {summary.totals}")
            last = (scene, summary)
        ax.set_title(name)
        ax.set_xlabel("iteration")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("known share of the observable cells")
    fig.suptitle("Known ratio per iteration (S0 Fig. 5.9 form)")
    fig.tight_layout()
    fig.savefig(f"{prefix}_known_ratio.png", dpi=120)

    open_cell = kinplan.scenes.s0_open_cell(client)
    per_planner = {}
    for planner in ["rrt_connect", "stomp", "ccstomp"]:
        cd, oc = [], []
        for seed in range(3):
            steps, _ = run(client, open_cell, planner=planner, seed=seed)
            cd += [s.criteria["CD"] for s in steps if s.criteria]
            oc += [s.criteria["OC"] for s in steps if s.criteria]
        per_planner[planner] = (np.array(cd), np.array(oc))
        print(f"{planner}: {len(cd)} trajectories, CD mean {np.mean(cd):.3f} m, OC mean {np.mean(oc):.3f} rad")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for k, (ax, label) in enumerate(zip(axes, ["CD per trajectory (m)", "OC per trajectory (rad)"])):
        data = [v[k] for v in per_planner.values()]
        ax.hist(data, bins=15, label=list(per_planner), alpha=0.8)
        ax.set_xlabel(label)
        ax.legend()
    axes[0].set_ylabel("trajectories")
    fig.suptitle("Open cell, three planners, seeds 0-2 (S0 Fig. 5.10/5.11 form)")
    fig.tight_layout()
    fig.savefig(f"{prefix}_criteria.png", dpi=120)

    assert last is not None, "no run finished"
    scene, summary = last
    cells = summary.octree.occupied_cells()
    lo, hi = scene.region
    inside = np.all((cells >= lo - 0.5) & (cells <= hi + 0.5), axis=1)
    cells = cells[inside]
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    ax.scatter(cells[:, 0], cells[:, 1], cells[:, 2], c=cells[:, 2], s=4, cmap="viridis")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"{scene.name}: occupied cells after {summary.iterations} iterations")
    fig.tight_layout()
    fig.savefig(f"{prefix}_octree.png", dpi=120)


if __name__ == "__main__":
    main()
