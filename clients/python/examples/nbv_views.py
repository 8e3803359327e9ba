"""Scan a small room with a doorway, then plot a horizontal slice of the
octree, the frontier cells the next-best-view candidates look at, and the
chosen camera views.

    python nbv_views.py [host:port] [out.png]

Needs matplotlib and a running `kinplan serve`. The tree travels as OctoMap
.bt node bytes; `Octree.occupied_cells()` decodes them to draw the
occupied cells.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import kinplan

RES = 0.1


def room_points(rng: np.random.Generator) -> np.ndarray:
    """Walls of a 4 m x 3 m room, 1 m high, with a doorway in the far wall."""
    n = 4000
    walls = []
    x = rng.uniform(-2, 2, n)
    z = rng.uniform(0, 1, n)
    far = x[(x < -0.5) | (x > 0.5)]
    walls.append(np.column_stack([far, np.full(len(far), 3.0), rng.uniform(0, 1, len(far))]))
    y = rng.uniform(0, 3, n)
    walls.append(np.column_stack([np.full(n, -2.0), y, z]))
    walls.append(np.column_stack([np.full(n, 2.0), y, z]))
    return np.vstack(walls)


address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "nbv_views.png"
rng = np.random.default_rng(1)
with kinplan.Client(address, timeout=60) as c:
    tree = c.insert_scan(None, room_points(rng), origin=[0.0, 0.2, 0.5], resolution=RES)
    info = c.octree_info(tree)
    camera = np.eye(4)
    camera[:3, 3] = (0.0, 0.2, 0.5)
    views = c.next_best_view(tree, camera_pose=camera, weights=(1.0, 0.25, 0.1), max_results=5)
    print(info["occupied_leaves"], "occupied leaves;", views)
    cells = tree.occupied_cells()
    fig, ax = plt.subplots(figsize=(6, 5))
    band = cells[np.abs(cells[:, 2] - 0.5) < RES]
    ax.scatter(band[:, 0], band[:, 1], s=4, c="k", label=f"occupied (z ≈ 0.5 m), {len(cells)} leaves")
    if len(views):
        f = views.frontier[~np.isnan(views.frontier[:, 0])]
        ax.scatter(f[:, 0], f[:, 1], c="tab:orange", marker="x", label="frontier cells looked at")
        p = views.poses[:, :3, 3]
        d = views.poses[:, :3, 2]  # optical +z: the view direction
        ax.quiver(p[:, 0], p[:, 1], d[:, 0], d[:, 1], color="tab:blue", angles="xy", scale=8, label="views (best first)")
        for k, (x, y) in enumerate(p[:, :2]):
            ax.annotate(f"{k + 1}: f={views.utility[k]:.2f}", (x, y), fontsize=7)
    ax.plot(0, 0.2, "r^", label="current camera")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Next-best views after one scan (utility f = Ig + 0.25 D + 0.1 R)")
    ax.legend(fontsize=7, loc="center")
    fig.savefig(out, dpi=110)
    print("wrote", out)
