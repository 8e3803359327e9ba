"""S0's open-cell exploration run in the Rerun viewer: the IRB 4600 with a
simulated Kinect v2 explores kinplan's reference cell (CCSTOMP, weights
IG1_T025_R01) and the whole run goes on a timeline — the octree growing
(occupied and unknown cells of the region), the view chosen at each
iteration as a camera frustum, the arm moving along each trajectory, the
views that failed, the known ratio as a plot.

    python viz_explore_s0.py [host:port] [out.rrd] [every]

Needs ``pip install 'kinplan[viz]'`` and a running `kinplan serve`; writes
out.rrd (default explore_s0.rrd; open it with ``rerun explore_s0.rrd``).
Explore streams only the final tree, so the tree after every `every`-th
iteration (default 1) is fetched by replaying the same request with fewer
iterations (:func:`kinplan.viz.replay_trees`): the replays cost more service
time than the run itself. ``examples/explore_s0.py`` draws the same run's
matplotlib figures.
"""
import sys
import time
from typing import Any, Dict

import kinplan
import kinplan.viz

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "explore_s0.rrd"
every = int(sys.argv[3]) if len(sys.argv) > 3 else 1

with kinplan.Client(address, timeout=300) as c:
    cell = kinplan.scenes.s0_open_cell(c)
    irb = c.robot(cell.robot)
    run: Dict[str, Any] = dict(scene=cell, planner="ccstomp", weights=(1.0, 0.25, 0.1), seed=0)
    t0 = time.perf_counter()
    items = list(c.explore(**run))
    t_run = time.perf_counter() - t0
    print(items[-1], f"({t_run:.2f} s)")
    t0 = time.perf_counter()
    trees = kinplan.viz.replay_trees(c, items, every=every, **run)
    print(f"{len(trees)} intermediate trees replayed in {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    with kinplan.viz.Recording("kinplan_explore_s0", save=out, eye=((-1.0, -3.0, 3.0), (2.0, 0.0, 0.2))) as viz:
        viz.robot(irb, cell.start)
        viz.explore(items, irb, scene=cell, trees=trees)
    wall = time.perf_counter() - t0
    print(f"logged in {wall:.2f} s, {viz.service_seconds:.2f} s of it waiting for the service; wrote {out}")
