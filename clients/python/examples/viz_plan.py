"""A UR5 plan around obstacles in the Rerun viewer: STOMP and CCSTOMP swing
the base by 2.4 rad past a ball and a post; each plan is played back on the
``plan_time`` timeline (the arm's collision bodies posed by kinplan's FK at
every waypoint), with the tool path, the closest robot-obstacle pair and the
clearance per waypoint, and for CCSTOMP the tolerance tube around the
straight tool line and the deviation plots.

    python viz_plan.py [host:port] [out.rrd]

Needs ``pip install 'kinplan[viz]'`` and a running `kinplan serve`; writes
out.rrd (default plan.rrd; ``rerun plan.rrd`` opens it).
``examples/plan_paths.py`` draws the tool paths with matplotlib.
"""
import sys
import time
from typing import List

import numpy as np

import kinplan
import kinplan.viz

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "plan.rrd"
start = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
goal = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])

with kinplan.Client(address, timeout=60) as c:
    ur5 = c.robot("ur5")
    centre = ur5.fk((start + goal) / 2)[:3, 3]
    scene: List[kinplan.planning.Obstacle] = [
        kinplan.Sphere(0.12, centre, id="ball"),
        kinplan.Cylinder(0.04, 0.8, [centre[0] - 0.25, centre[1] + 0.25, 0.1], id="post"),
        kinplan.Box((2, 2, 0.02), [0, 0, -0.3], id="floor"),
    ]
    stomp = ur5.plan(start, goal, algorithm="stomp", scene=scene, seed=1, stomp={"timesteps": 100})
    ccstomp = ur5.plan(start, pose=ur5.fk(goal), algorithm="ccstomp", scene=scene, seed=1,
                       stomp={"timesteps": 40}, cartesian={"translation_tolerance": 0.5, "rotation_tolerance": 3.0})
    print(stomp)
    print(ccstomp)
    t0 = time.perf_counter()
    with kinplan.viz.Recording("kinplan_plan", save=out, eye=((1.4, -1.4, 0.9), (0.0, 0.0, 0.2))) as viz:
        viz.plan(ur5, stomp, scene=scene, name="stomp")
        # the CCSTOMP plan after the STOMP one, on the same timeline
        viz.plan(ur5, ccstomp, scene=scene, name="ccstomp", t0=float(stomp.t[-1]) + 1.0,
                 translation_tolerance=0.5, rotation_tolerance=3.0)
    wall = time.perf_counter() - t0
    print(f"logged {len(stomp.q)} + {len(ccstomp.q)} waypoints in {wall:.2f} s, {viz.service_seconds:.2f} s of it "
          f"waiting for the service; wrote {out}")
