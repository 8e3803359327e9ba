#!/usr/bin/env python3
"""The hardening issue's reproductions against a server binary, one fresh
server process per case: the answer (code, or status), the wall time, the
server's peak resident memory (VmHWM) and the CPU it burns after answering.

    python benches/hardening/run.py --bin target/release/kinplan [--bin other/kinplan]

Needs the Python client (pip install ./clients/python) for its generated
stubs and grpcio. Loopback only; every case is bounded by its deadline.
"""
import argparse
import math
import os
import socket
import subprocess
import time

import grpc
from kinplan.v1 import common_pb2 as c
from kinplan.v1 import exploration_pb2 as e
from kinplan.v1 import exploration_pb2_grpc as eg
from kinplan.v1 import planning_pb2 as p
from kinplan.v1 import planning_pb2_grpc as pg


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def proc_stat(pid: int) -> tuple[float, int]:
    """CPU seconds used so far and peak resident KiB."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    with open(f"/proc/{pid}/status") as f:
        hwm = next(int(l.split()[1]) for l in f if l.startswith("VmHWM"))
    return cpu, hwm


def ur5() -> c.RobotRef:
    return c.RobotRef(name="ur5")


def stomp_plan(timesteps: int, budget: float) -> p.PlanRequest:
    return p.PlanRequest(
        robot=ur5(), start=[-1.2, -1.3, 1.4, -1.6, -1.57, 0],
        goal_joints=p.JointState(positions=[1.2, -1.3, 1.4, -1.6, -1.57, 0]),
        algorithm=p.PLAN_ALGORITHM_STOMP,
        options=p.PlanOptions(stomp=p.StompOptions(timesteps=timesteps), time_budget=budget))


def sphere_scan(n: int, radius: float, resolution: float) -> e.InsertScanRequest:
    xyz = []
    for i in range(n):
        z = 1 - 2 * (i + 0.5) / n
        r, phi = math.sqrt(1 - z * z), i * 2.399963
        xyz += [radius * r * math.cos(phi), radius * r * math.sin(phi), radius * z]
    return e.InsertScanRequest(resolution=resolution, sensor_pose=c.Pose(),
                               points=e.PointCloud(xyz=xyz))


def tetra_and_sphere() -> p.CheckStateRequest:
    at = c.Pose(position=c.Vec3(x=-0.4223, y=-0.1914, z=0.4184))
    v = [c.Vec3(), c.Vec3(x=0.1), c.Vec3(y=0.1), c.Vec3(z=0.1)]
    mesh = c.CollisionObject(id="tetra", pose=at, mesh=c.TriangleMesh(
        vertices=v, indices=[0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3]))
    ball = c.CollisionObject(id="ball", pose=at, sphere=c.Sphere(radius=0.05))
    return p.CheckStateRequest(robot=ur5(), states=[p.JointState(positions=[0, -1.5, 1.5, 0, 0, 0])],
                               scene=c.Scene(objects=[mesh, ball]))


def one_mesh_named(times: int) -> p.CheckStateRequest:
    """A one-joint arm whose link names one ball mesh of 20,000 vertices
    `times` times (each element a few dozen bytes of URDF)."""
    uri, rings, around = "package://many/ball.obj", 100, 200
    lines = []
    for i in range(rings):
        polar = math.pi * (i + 0.5) / rings
        for j in range(around):
            azimuth = 2 * math.pi * j / around
            lines.append(f"v {0.05 * math.sin(polar) * math.cos(azimuth)} "
                         f"{0.05 * math.sin(polar) * math.sin(azimuth)} {0.05 * math.cos(polar)}")
    for i in range(rings - 1):
        for j in range(around):
            a, b = i * around + j + 1, i * around + (j + 1) % around + 1
            lines += [f"f {a} {b} {b + around}", f"f {a} {b + around} {a + around}"]
    element = f'<collision><geometry><mesh filename="{uri}"/></geometry></collision>'
    urdf = (f'<robot name="many"><link name="base"/><link name="arm">{element * times}</link>'
            '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>')
    robot = c.RobotRef(urdf=urdf, meshes=[c.MeshFile(uri=uri, data="\n".join(lines).encode())])
    return p.CheckStateRequest(robot=robot, states=[p.JointState(positions=[0.3])])


CASES = [
    # (name, service, method, request, deadline s)
    ("STOMP 2,000 timesteps, 0.5 s budget", "plan", "Plan", stomp_plan(2000, 0.5), 30.0),
    ("STOMP 10,000 timesteps, 6 s deadline", "plan", "Plan", stomp_plan(10000, 60.0), 6.0),
    ("InsertScan 300 pts on a 300 m sphere at 1 cm", "explore", "InsertScan", sphere_scan(300, 300.0, 0.01), 30.0),
    ("the same scan, 500 ms deadline", "explore", "InsertScan", sphere_scan(300, 300.0, 0.01), 0.5),
    ("CheckState: mesh then sphere, penetrated", "plan", "CheckState", tetra_and_sphere(), 5.0),
    ("OctreeInfo of a root with 8 leaves", "explore", "OctreeInfo",
     e.OctreeInfoRequest(octree=c.Octree(id="OcTree", resolution=0.1, binary=True, data=b"\x66\x66")), 5.0),
    ("CheckState: one 20,000-vertex mesh named 300 times", "plan", "CheckState", one_mesh_named(300), 10.0),
    ("the same mesh named 45 times (within the budget), 1 s deadline", "plan", "CheckState",
     one_mesh_named(45), 1.0),
]


def run(binary: str, only: list[str]) -> None:
    print(f"\n{binary}")
    print("| case | answer | wall s | peak RSS MiB | CPU s in the 2 s after the answer |")
    print("|---|---|---|---|---|")
    for name, service, method, request, deadline in CASES:
        if only and not any(o in name for o in only):
            continue
        port = free_port()
        server = subprocess.Popen([binary, "serve", "--listen", f"127.0.0.1:{port}"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            channel = grpc.insecure_channel(f"127.0.0.1:{port}")
            grpc.channel_ready_future(channel).result(timeout=20)
            stub = (pg.PlanningServiceStub if service == "plan" else eg.ExplorationServiceStub)(channel)
            call = getattr(stub, method)
            t0 = time.perf_counter()
            try:
                reply = call(request, timeout=deadline)
                answer = "OK"
                if method == "Plan":
                    answer += " " + p.PlanStatus.Name(reply.status)
                if method == "OctreeInfo":
                    answer += f" free {reply.free_volume:.3g} m3"
            except grpc.RpcError as err:
                answer = f"{err.code().name}: {err.details()[:60]}"
            wall = time.perf_counter() - t0
            cpu0, _ = proc_stat(server.pid)
            time.sleep(2.0)
            cpu1, hwm = proc_stat(server.pid)
            print(f"| {name} | {answer} | {wall:.3f} | {hwm / 1024:.0f} | {cpu1 - cpu0:.2f} |")
        finally:
            server.kill()
            server.wait()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", action="append", required=True, help="a kinplan server binary (repeatable)")
    ap.add_argument("--case", action="append", default=[], help="run only the cases whose name holds this (repeatable)")
    args = ap.parse_args()
    for b in args.bin:
        run(b, args.case)


if __name__ == "__main__":
    main()
