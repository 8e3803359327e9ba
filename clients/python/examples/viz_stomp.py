"""STOMP at work in the Rerun viewer: ``plan_stream`` yields the UR5's
trajectory after every iteration; the recording shows the tool path of each
iteration on the ``stomp_iteration`` timeline (the arm at the trajectory's
middle waypoint) beside the cost per iteration, then plays the final plan
back on ``plan_time``.

    python viz_stomp.py [host:port] [out.rrd]

Needs ``pip install 'kinplan[viz]'`` and a running `kinplan serve`; writes
out.rrd (default stomp.rrd).
"""
import sys
import time
from typing import List

import numpy as np

import kinplan
import kinplan.viz

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "stomp.rrd"
start = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
goal = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])

with kinplan.Client(address, timeout=60) as c:
    ur5 = c.robot("ur5")
    centre = ur5.fk((start + goal) / 2)[:3, 3]
    scene: List[kinplan.planning.Obstacle] = [kinplan.Sphere(0.12, centre, id="ball"), kinplan.Box((2, 2, 0.02), [0, 0, -0.3], id="floor")]
    # from the straight joint line through the ball (MoveIt's STOMP start), 20 iterations after the first valid one
    frames = list(ur5.plan_stream(start, goal, scene=scene, seed=1,
                                  stomp={"straight_line_start": True, "iterations_after_valid": 20}))
    t0 = time.perf_counter()
    with kinplan.viz.Recording("kinplan_stomp", save=out, eye=((1.4, -1.4, 0.9), (0.0, 0.0, 0.2))) as viz:
        plan = viz.plan_iterations(ur5, frames, scene=scene)
    wall = time.perf_counter() - t0
    print(plan)
    print(f"logged {len(frames) - 1} iterations in {wall:.2f} s, {viz.service_seconds:.2f} s of it waiting for "
          f"the service; wrote {out}")
