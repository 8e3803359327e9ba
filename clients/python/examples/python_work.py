"""The client's own Python work per call, with and without the caches warm:

    python python_work.py [host:port] [rounds]

A second client runs on a channel that replays the answers the server gave
(recorded once as bytes per method, then parsed by the method's own
deserializer, as a real call would), so no network time is in its figures.
The generated stub on the same replaying channel (it serializes the request
and parses the answer) is the baseline. "cold": every timed call follows a
real gRPC call through a real channel, as in a program that calls the server
in a loop (that call's code and data evict the client's from the caches);
"warm": the same call repeated on its own. Rows as in call_overhead.py.
"""
from typing import Any, Callable, Dict, List, Optional, Tuple

import statistics
import sys
import time

import grpc
import numpy as np

import kinplan
from kinplan.kinematics import ik_options, target_to_pose
from kinplan.v1 import kinematics_pb2, kinematics_pb2_grpc, robot_pb2, robot_pb2_grpc


class Recorder:
    """A channel that passes unary calls to `channel` and keeps each method's last answer (bytes)."""

    def __init__(self, channel: Any):
        self.channel = channel
        self.answers: Dict[str, bytes] = {}

    def unary_unary(self, method: str, request_serializer: Optional[Callable[..., Any]] = None,
                    response_deserializer: Optional[Callable[..., Any]] = None, **_: Any) -> Callable[..., Any]:
        real = self.channel.unary_unary(method, request_serializer, None)

        def call(request: Any, timeout: Optional[float] = None, **__: Any) -> Any:
            wire: bytes = real(request, timeout=timeout)
            self.answers[method] = wire
            return wire if response_deserializer is None else response_deserializer(wire)

        return call

    def __getattr__(self, name: str) -> Any:
        return getattr(self.channel, name)


class Replay:
    """A channel whose unary calls serialize the request and answer the recorded bytes."""

    def __init__(self, answers: Dict[str, bytes]):
        self.answers = answers

    def unary_unary(self, method: str, request_serializer: Optional[Callable[..., Any]] = None,
                    response_deserializer: Optional[Callable[..., Any]] = None, **_: Any) -> Callable[..., Any]:
        answers = self.answers

        def call(request: Any, timeout: Optional[float] = None, **__: Any) -> Any:
            if request_serializer is not None:
                request_serializer(request)
            wire = answers[method]
            return wire if response_deserializer is None else response_deserializer(wire)

        return call

    def unary_stream(self, *_: Any, **__: Any) -> None:
        return None

    stream_unary = stream_stream = unary_stream


def timed(a: Callable[[], Any], b: Callable[[], Any], evict: Callable[[], Any], n: int) -> Tuple[float, ...]:
    """Median µs of `a` and `b`, each after a real call (cold), then each in a loop of its own (warm)."""
    for _ in range(50):
        evict()
        a()
        evict()
        b()
    ta: List[float] = []
    tb: List[float] = []
    for _ in range(n):
        evict()
        t0 = time.perf_counter()
        a()
        ta.append(time.perf_counter() - t0)
        evict()
        t0 = time.perf_counter()
        b()
        tb.append(time.perf_counter() - t0)
    warm = []
    for f in (a, b):
        t0 = time.perf_counter()
        for _ in range(n):
            f()
        warm.append((time.perf_counter() - t0) / n)
    return statistics.median(ta) * 1e6, statistics.median(tb) * 1e6, warm[0] * 1e6, warm[1] * 1e6


def main() -> None:
    address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 3000
    recorder = Recorder(grpc.insecure_channel(address))
    recording = kinplan.Client(address, timeout=10, channel=recorder)
    q = np.array([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    seed = q + 0.02
    T = recording.robot("ur5").fk(q)
    recording.robot("ur5").ik(T, seed=seed)
    ur5 = kinplan.Client(address, timeout=10, channel=Replay(recorder.answers)).robot("ur5")
    ref = ur5._ref()
    fk_req = robot_pb2.ForwardKinematicsRequest(robot=ref, joint_positions=q.tolist())
    ik_req = kinematics_pb2.SolveIkRequest(robot=ref, target=target_to_pose(T), seed=seed.tolist(),
                                           options=ik_options("lm", "svd"))
    robots = robot_pb2_grpc.RobotServiceStub(Replay(recorder.answers))
    kinematics = kinematics_pb2_grpc.KinematicsServiceStub(Replay(recorder.answers))
    with kinplan.Client(address, timeout=10) as real:
        real_ik = kinematics_pb2_grpc.KinematicsServiceStub(real._channel).SolveIk

        def evict() -> None:
            real_ik(ik_req, timeout=10)

        def stub_read() -> Any:
            r = kinematics.SolveIk(ik_req, timeout=10)
            return r.success, np.array(r.solutions[0].joints[:])

        def ours_read() -> Any:
            r = ur5.ik(T, seed=seed)
            return r.success, r.q

        rows: List[Tuple[str, Callable[[], Any], Callable[[], Any]]] = [
            ("ForwardKinematics", lambda: robots.ForwardKinematics(fk_req, timeout=10), lambda: ur5.fk(q)),
            ("SolveIk (warm, seed built per call)", lambda: kinematics.SolveIk(ik_req, timeout=10),
             lambda: ur5.ik(T, seed=q + 0.02)),
            ("SolveIk (warm)", lambda: kinematics.SolveIk(ik_req, timeout=10), lambda: ur5.ik(T, seed=seed)),
            ("SolveIk (warm) read", stub_read, ours_read),
        ]
        np.testing.assert_array_equal(ur5.fk(q), T)
        for name, a, b in rows:
            cold_a, cold_b, warm_a, warm_b = timed(a, b, evict, n)
            print(f"{name:36s} cold: stub {cold_a:5.1f} client {cold_b:5.1f} difference {cold_b - cold_a:5.1f} us   "
                  f"warm: stub {warm_a:5.1f} client {warm_b:5.1f} difference {warm_b - warm_a:5.1f} us")


if __name__ == "__main__":
    main()
