"""Measures shed-rejection latency (200 calls, concurrent and sequential) and health
latency under a saturated CPU pool, against a kinplan binary started here.
Run from the repository root: python clients/python/examples/measure_admission.py target/release/kinplan"""
from typing import Any

import asyncio, os, socket, subprocess, sys, time, statistics
import grpc
sys.path.insert(0, "clients/python")
from kinplan.v1 import kinematics_pb2, kinematics_pb2_grpc, robot_pb2, robot_pb2_grpc, common_pb2

def free_port() -> int:
    s = socket.socket(); s.bind(("127.0.0.1", 0)); p = int(s.getsockname()[1]); s.close(); return p

def pct(xs: Any, p: float) -> Any:
    xs = sorted(xs); return xs[min(len(xs) - 1, int(p / 100 * len(xs)))]

async def main(binary: str) -> None:
    port = free_port()
    proc = subprocess.Popen([binary, "serve", "--listen", f"127.0.0.1:{port}", "--cpu-threads", "2",
                             "--concurrency-limit", "4"], stderr=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    try:
        ch = grpc.aio.insecure_channel(f"127.0.0.1:{port}")
        await asyncio.wait_for(ch.channel_ready(), 10)
        ik = kinematics_pb2_grpc.KinematicsServiceStub(ch)
        robots = robot_pb2_grpc.RobotServiceStub(ch)
        check = ch.unary_unary('/grpc.health.v1.Health/Check', request_serializer=lambda x: x, response_deserializer=lambda x: x)
        far = common_pb2.Pose(position=common_pb2.Vec3(x=10, y=0, z=0.5))
        req = kinematics_pb2.SolveIkRequest(robot=common_pb2.RobotRef(name="ur5"), target=far,
                                            options=kinematics_pb2.IkOptions(max_restarts=2**32 - 1, time_budget=3.0))
        busy = [asyncio.ensure_future(ik.SolveIk(req)) for _ in range(4)]
        await asyncio.sleep(0.3)
        # health under a saturated pool (4 admitted, 2 pool threads busy)
        hl = []
        for _ in range(100):
            t = time.perf_counter(); await check(b''); hl.append(time.perf_counter() - t)
        # 200-call burst, every call shed (4 in flight already)
        async def one() -> Any:
            t = time.perf_counter()
            try:
                await robots.ListRobots(robot_pb2.ListRobotsRequest()); code = "OK"
            except grpc.aio.AioRpcError as e:
                code = e.code().name
            return time.perf_counter() - t, code
        res = await asyncio.gather(*[one() for _ in range(200)])
        shed = [t for t, c in res if c == "RESOURCE_EXHAUSTED"]
        print(f"health under saturated pool: n=100 p50={pct(hl,50)*1e3:.2f} ms p99={pct(hl,99)*1e3:.2f} ms max={max(hl)*1e3:.2f} ms")
        print(f"burst of 200 while 4/4 admitted: {len(shed)} shed; client-side latency p50={pct(shed,50)*1e3:.2f} ms p99={pct(shed,99)*1e3:.2f} ms max={max(shed)*1e3:.2f} ms")
        seq = []
        for _ in range(200):
            d, c = await one()
            if c == "RESOURCE_EXHAUSTED":
                seq.append(d)
        print(f"200 sequential calls while 4/4 admitted: {len(seq)} shed; latency p50={pct(seq,50)*1e3:.3f} ms p99={pct(seq,99)*1e3:.3f} ms max={max(seq)*1e3:.3f} ms")
        for b in busy:
            await b
    finally:
        proc.terminate(); proc.wait(5)

asyncio.run(main(sys.argv[1]))
