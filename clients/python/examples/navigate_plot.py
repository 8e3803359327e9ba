"""Vector-distance navigation (S1 §3.5, §4.2.4) and grid A* + pure pursuit
among circles and polygons, plotted.

Start a server (`cargo run --release -- serve`), then
    MPLBACKEND=Agg python clients/python/examples/navigate_plot.py [address] [out.png]
(needs matplotlib: pip install 'kinplan[plot]'). Draws the world, the robot's
disc at the start and the goal, both driven paths coloured by navigator mode
(R / L / T) with the hit points H and leave points L, and saves a PNG
(default navigate.png).
"""
import sys
from typing import Any, Dict, List

import matplotlib.pyplot as plt
from matplotlib.patches import Circle, Polygon

import kinplan

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "navigate.png"

RADIUS = 0.22
start, goal = (0.0, 0.0, 0.0), (8.0, 1.0)
# A U-shaped trap (concave: its mouth faces the start), a disc and a square.
world: List[Dict[str, Any]] = [
    {"polygon": [(3.0, -1.5), (4.0, -1.5), (4.0, 1.5), (3.0, 1.5), (3.0, 1.2), (3.7, 1.2), (3.7, -1.2), (3.0, -1.2)]},
    {"circle": (6.0, 1.6, 0.6)},
    {"polygon": [(6.2, -0.6), (7.0, -0.6), (7.0, 0.2), (6.2, 0.2)]},
    {"circle": (1.8, 1.6, 0.4)},
]

with kinplan.Client(address, timeout=60) as c:
    local = c.mobile.navigate(chassis="differential", start=start, goal=goal, world=world, robot_radius=RADIUS)
    glob = c.mobile.navigate(
        chassis="differential", start=start, goal=goal, world=world, robot_radius=RADIUS, navigator="grid_astar"
    )

fig, ax = plt.subplots(figsize=(9, 5))
for o in world:
    if "circle" in o:
        x, y, r = o["circle"]
        ax.add_patch(Circle((x, y), r, color="0.55"))
    else:
        ax.add_patch(Polygon(o["polygon"], closed=True, color="0.55"))
colours = {"R": "tab:blue", "L": "tab:orange", "T": "tab:red"}
s = local.states
for k, mode in enumerate(local.modes):
    ax.plot(s[k : k + 2, 0], s[k : k + 2, 1], color=colours[mode], lw=2)
for mode, colour in colours.items():
    ax.plot([], [], color=colour, lw=2, label=f"vector distance, mode {mode}")
ax.plot(glob.states[:, 0], glob.states[:, 1], "--", color="tab:green", lw=1.5, label="grid A* + pure pursuit")
if len(local.hit_points):
    ax.plot(*local.hit_points.T, "kx", ms=9, label="hit points H")
if len(local.leave_points):
    ax.plot(*local.leave_points.T, "k+", ms=11, label="leave points L")
ax.add_patch(Circle(start[:2], RADIUS, fill=False, color="k"))
ax.plot(*goal, "g*", ms=14, label="goal")
ax.set_aspect("equal")
ax.set_xlabel("x [m]")
ax.set_ylabel("y [m]")
ax.set_title(
    f"vector distance: {local.outcome}, {local.path_length:.2f} m in {local.time:.1f} s, "
    f"min clearance {local.min_clearance:.3f} m\n"
    f"grid A*: {glob.outcome}, {glob.path_length:.2f} m in {glob.time:.1f} s"
)
ax.legend(loc="lower left", fontsize=8)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"vector distance: {local.outcome}, {local.steps} steps, {len(local.hit_points)} hit points")
print(f"grid A*: {glob.outcome}, {glob.steps} steps")
print(f"saved {out}")
