"""Round-trip latency of SolveIk and the sustained rate of StreamIk from the
Python client, on a KUKA KR 210 R2700 extra.

Start a server (`cargo run --release -- serve`), then
    python clients/python/examples/ik_latency.py [address] [calls]
(defaults 127.0.0.1:50051 and 2000). Prints, in µs: SolveIk on random
reachable poses with the seed at the middle of the limits (cold) and with a
seed 0.01 rad from the answer (warm), through robot.ik and through the raw
generated stub; StreamIk along a 10 mm circle in lockstep (send, await the
answer) and pipelined (send everything, read the answers), as targets/s.
"""
from typing import Any

import sys
import time

import numpy as np

import kinplan
from kinplan.kinematics import target_to_pose
from kinplan.v1 import common_pb2, kinematics_pb2

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
calls = int(sys.argv[2]) if len(sys.argv) > 2 else 2000
NAME = "kuka_kr210_r2700_extra"


def report(label: str, samples: Any, server_us: Any = None, failures: int = 0) -> None:
    us = np.array(samples) * 1e6
    extra = f"; server solve median {np.median(server_us):.1f} µs" if server_us is not None else ""
    print(f"python {label} x{len(us)}: median {np.median(us):.1f} µs, p99 {np.percentile(us, 99):.1f} µs, "
          f"mean {us.mean():.1f} µs{extra}; not converged {failures}")


with kinplan.Client(address, timeout=10) as c:
    robot = c.robot(NAME)
    d = robot.describe()
    rng = np.random.default_rng(2026)
    qs = rng.uniform(d.lower, d.upper, size=(calls, d.dof))
    Ts = [robot.fk(q) for q in qs]

    for label, seeds in (("SolveIk cold (mid-limit seed)", [None] * calls),
                         ("SolveIk warm (seed 0.01 rad away)", list(qs + 0.01))):
        for T, s in list(zip(Ts, seeds))[:200]:
            robot.ik(T, seed=s)
        samples, server, failures = [], [], 0
        for T, s in zip(Ts, seeds):
            t0 = time.perf_counter()
            r = robot.ik(T, seed=s)
            samples.append(time.perf_counter() - t0)
            server.append(r.elapsed_us)
            failures += not r.success
        report(f"robot.ik {label}", samples, server, failures)

    # the raw stub: protobuf messages built before timing
    stub = c._kinematics.SolveIk
    ref = common_pb2.RobotRef(name=NAME)
    requests = [kinematics_pb2.SolveIkRequest(robot=ref, target=target_to_pose(T), seed=(q + 0.01).tolist())
                for T, q in zip(Ts, qs)]
    samples = []
    for req in requests:
        t0 = time.perf_counter()
        stub(req, timeout=10)
        samples.append(time.perf_counter() - t0)
    report("raw stub SolveIk warm", samples)

    # StreamIk along a 10 mm circle, 1000 steps per turn
    q0 = np.array([0.2, -1.6, 1.7, 0.3, 0.8, -0.2])
    T0 = robot.fk(q0)
    centre = T0[:3, 3] - [0.01, 0, 0]
    circle = []
    for k in range(calls):
        a = 2 * np.pi * k / 1000
        T = T0.copy()
        T[:3, 3] = centre + 0.01 * np.array([np.cos(a), np.sin(a), 0.0])
        circle.append(T)
    with robot.stream_ik(seed=q0) as s:
        samples, server, failures = [], [], 0
        began = time.perf_counter()
        for T in circle:
            t0 = time.perf_counter()
            r = s.solve(T)
            samples.append(time.perf_counter() - t0)
            server.append(r.elapsed_us)
            failures += not r.success
        rate = calls / (time.perf_counter() - began)
    report("StreamIk lockstep (10 mm circle)", samples, server, failures)
    print(f"python StreamIk lockstep sustained rate: {rate:.0f} targets/s")
    with robot.stream_ik(seed=q0) as s:
        began = time.perf_counter()
        for T in circle:
            s.send(T)
        failures = sum(not next(s).success for _ in circle)
        elapsed = time.perf_counter() - began
    print(f"python StreamIk pipelined x{calls}: {calls / elapsed:.0f} targets/s "
          f"({elapsed * 1e6 / calls:.1f} µs per target); not converged {failures}")
