"""Round-trip latency of Robot.score for a 10,000-waypoint KR 210 trajectory
from Python: numpy -> JointTrajectory, gRPC, FK and every criterion on the
server, reply -> Scores.

Start a server (`cargo run --release -- serve`), then
    python clients/python/examples/score_latency.py [address] [calls] [waypoints]
(defaults 127.0.0.1:50051, 30 and 10000). Prints median, p90 and mean in ms,
and the share spent building the request in Python.
"""
from typing import Any

import sys
import time

import numpy as np

import kinplan
from kinplan.scoring import trajectory_to_proto

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
calls = int(sys.argv[2]) if len(sys.argv) > 2 else 30
n = int(sys.argv[3]) if len(sys.argv) > 3 else 10000

s = np.arange(n)[:, None] / n
q = np.hstack([0.9 * s, -1.5 + 0.4 * s, 1.4 - 0.5 * s, 0.3 * np.sin(6 * s), 0.5 + 0.2 * s, -0.4 * s])


def report(label: str, samples: Any) -> None:
    ms = np.array(samples) * 1e3
    print(f"python {label} x{n} waypoints, {len(ms)} calls: median {np.median(ms):.2f} ms, "
          f"p90 {np.percentile(ms, 90):.2f} ms, mean {ms.mean():.2f} ms")


with kinplan.Client(address, timeout=30, max_message_bytes=64 * 1024 * 1024) as c:
    robot = c.robot("kuka_kr210_r2700_extra")
    for series in (False, True):
        for _ in range(3):
            robot.score(q, series=series)
        samples = []
        for _ in range(calls):
            t0 = time.perf_counter()
            robot.score(q, series=series)
            samples.append(time.perf_counter() - t0)
        report("Robot.score" + (" (series)" if series else ""), samples)
    build = []
    for _ in range(calls):
        t0 = time.perf_counter()
        trajectory_to_proto(q)
        build.append(time.perf_counter() - t0)
    report("numpy -> JointTrajectory only", build)
