"""Tool paths of RRT-Connect, STOMP and CCSTOMP around a ball, in 3-D.

    python plan_paths.py [host:port] [out.png]

Needs matplotlib (pip install 'kinplan[plot]') and a running `kinplan serve`.
The UR5 swings its base by 2.4 rad; the ball sits where the tool would pass
halfway along the straight joint-space line, so every planner must go around.
"""
import sys
from typing import List

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import kinplan

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
out = sys.argv[2] if len(sys.argv) > 2 else "plan_paths.png"
start = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
goal = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])

with kinplan.Client(address, timeout=60) as c:
    ur5 = c.robot("ur5")
    centre = ur5.fk((start + goal) / 2)[:3, 3]
    ball = kinplan.Sphere(0.12, centre, id="ball")
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    for algorithm, stomp in [("rrt_connect", None), ("stomp", None), ("ccstomp", {"timesteps": 10})]:
        plan = ur5.plan(start, goal, algorithm=algorithm, scene=[ball], seed=1, stomp=stomp)
        # the tool path at 0.02 rad joint steps
        dense: List[np.ndarray] = []
        for a, b in zip(plan.q[:-1], plan.q[1:]):
            n = max(1, int(np.ceil(np.abs(b - a).max() / 0.02)))
            dense.extend(a + (b - a) * k / n for k in range(n))
        dense.append(plan.q[-1])
        tool = np.array([ur5.fk(q)[:3, 3] for q in dense])
        label = f"{algorithm}: {plan.status}, CD {plan.scores.get('CD', float('nan')):.2f} m, {plan.timings['total'] * 1e3:.0f} ms"
        ax.plot(*tool.T, label=label)
        print(label)
    u, v = np.mgrid[0 : 2 * np.pi : 24j, 0 : np.pi : 12j]
    ax.plot_surface(
        centre[0] + 0.12 * np.cos(u) * np.sin(v),
        centre[1] + 0.12 * np.sin(u) * np.sin(v),
        centre[2] + 0.12 * np.cos(v),
        color="grey",
        alpha=0.4,
    )
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title("UR5 tool paths around a ball (base frame)")
    ax.legend(fontsize=8)
    fig.savefig(out, dpi=110)
    print("wrote", out)
