"""Round-trip latency of ForwardKinematics from the Python client.

Start a server (`cargo run --release -- serve`), then
    python clients/python/examples/fk_latency.py [address] [calls]
Prints median, p99 and mean in microseconds, for the numpy wrapper and for
the raw generated stub.
"""
from typing import Any

import sys
import time

import numpy as np

import kinplan
from kinplan.v1 import common_pb2, robot_pb2

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
calls = int(sys.argv[2]) if len(sys.argv) > 2 else 10000


def report(label: str, samples: Any) -> None:
    us = np.array(samples) * 1e6
    print(f"python {label} ForwardKinematics x{len(us)}: median {np.median(us):.1f} µs, "
          f"p99 {np.percentile(us, 99):.1f} µs, mean {us.mean():.1f} µs")


with kinplan.Client(address, timeout=5) as c:
    robot = c.robot("kuka_kr210_r2700_extra")
    q = np.array([0.1, -1.5, 1.4, 0.2, 0.3, 0.4])
    for _ in range(500):
        robot.fk(q)
    samples = []
    for _ in range(calls):
        t0 = time.perf_counter()
        robot.fk(q)
        samples.append(time.perf_counter() - t0)
    report("numpy client", samples)

    stub = c._robots.ForwardKinematics
    request = robot_pb2.ForwardKinematicsRequest(
        robot=common_pb2.RobotRef(name="kuka_kr210_r2700_extra"), joint_positions=q.tolist()
    )
    samples = []
    for _ in range(calls):
        t0 = time.perf_counter()
        stub(request, timeout=5)
        samples.append(time.perf_counter() - t0)
    report("raw stub", samples)
