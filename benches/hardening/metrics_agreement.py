#!/usr/bin/env python3
"""Do the server's metrics say what the clients saw? A mixed, partly hostile
load against one server process, every call's final status tallied on the
client side per (method, code), then `grpc_server_handled_total` scraped from
the server's Prometheus endpoint and compared series by series.

    python benches/hardening/metrics_agreement.py --bin target/release/kinplan [--calls 6000]

The load: ForwardKinematics (valid and invalid), SolveIk with deadlines from
1 to 40 ms (many expire), Plan (STOMP) with deadlines that expire, StreamIk
streams that end normally, streams whose deadline expires mid-stream and
streams the client cancels. Exit status 1 when any series disagrees.
"""
import argparse
import collections
import random
import re
import socket
import subprocess
import sys
import threading
import time
import urllib.request

import grpc
from kinplan.v1 import common_pb2 as c
from kinplan.v1 import kinematics_pb2 as k
from kinplan.v1 import kinematics_pb2_grpc as kg
from kinplan.v1 import planning_pb2 as p
from kinplan.v1 import planning_pb2_grpc as pg
from kinplan.v1 import robot_pb2 as r
from kinplan.v1 import robot_pb2_grpc as rg


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


UR5 = c.RobotRef(name="ur5")
Q0 = [0.3, -1.2, 1.4, -1.6, -1.57, 0.2]
# FK of Q0 would need the client; any pose near the arm is a fair IK target.
TARGET = c.Pose(position=c.Vec3(x=0.4, y=0.2, z=0.4), orientation=c.Quaternion(w=0.0, x=1.0, y=0.0, z=0.0))


class Tally:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.codes: "collections.Counter[tuple[str, str]]" = collections.Counter()

    def add(self, method: str, code: grpc.StatusCode) -> None:
        with self.lock:
            self.codes[(method, code.name)] += 1


def code_of(call) -> grpc.StatusCode:
    try:
        call()
        return grpc.StatusCode.OK
    except grpc.RpcError as err:
        return err.code()


def stream_targets(n: int, pause: float, stop: threading.Event):
    for i in range(n):
        if stop.is_set():
            return
        yield k.StreamIkRequest(sequence=i + 1, robot=UR5 if i == 0 else None, target=TARGET,
                                seed=Q0 if i == 0 else [])
        time.sleep(pause)


def one_call(rng: random.Random, robot, kin, plan, tally: Tally) -> None:
    kind = rng.random()
    if kind < 0.25:
        bad = rng.random() < 0.3
        q = Q0[:5] if bad else Q0
        req = r.ForwardKinematicsRequest(robot=UR5, joint_positions=q)
        tally.add("ForwardKinematics", code_of(lambda: robot.ForwardKinematics(req, timeout=1.0)))
    elif kind < 0.60:
        req = k.SolveIkRequest(robot=UR5, target=TARGET, seed=[] if rng.random() < 0.5 else Q0,
                               options=k.IkOptions(max_restarts=200))
        timeout = rng.choice([0.001, 0.002, 0.003, 0.005, 0.01, 0.02, 0.04])
        tally.add("SolveIk", code_of(lambda: kin.SolveIk(req, timeout=timeout)))
    elif kind < 0.70:
        req = p.PlanRequest(robot=UR5, start=Q0, goal_joints=p.JointState(positions=[-x for x in Q0]),
                            algorithm=p.PLAN_ALGORITHM_STOMP,
                            options=p.PlanOptions(stomp=p.StompOptions(timesteps=rng.choice([50, 400]))))
        timeout = rng.choice([0.005, 0.02, 0.08, 0.3])
        tally.add("Plan", code_of(lambda: plan.Plan(req, timeout=timeout)))
    else:
        mode = rng.random()
        stop = threading.Event()
        if mode < 0.4:  # ends normally
            call = kin.StreamIk(stream_targets(rng.randint(1, 8), 0.0005, stop), timeout=2.0)
            tally.add("StreamIk", code_of(lambda: [None for _ in call]))
        elif mode < 0.7:  # the deadline expires mid-stream
            call = kin.StreamIk(stream_targets(1000, 0.002, stop), timeout=rng.choice([0.01, 0.03]))
            code = code_of(lambda: [None for _ in call])
            stop.set()
            tally.add("StreamIk", code)
        else:  # the client cancels after a few answers
            call = kin.StreamIk(stream_targets(1000, 0.001, stop), timeout=2.0)
            for _ in range(rng.randint(0, 3)):
                try:
                    next(call)
                except (grpc.RpcError, StopIteration):
                    break
            call.cancel()
            stop.set()
            code = code_of(lambda: [None for _ in call])
            tally.add("StreamIk", code)


def scrape(url: str) -> "collections.Counter[tuple[str, str]]":
    text = urllib.request.urlopen(url, timeout=5).read().decode()
    out: "collections.Counter[tuple[str, str]]" = collections.Counter()
    for line in text.splitlines():
        if not line.startswith("grpc_server_handled_total{"):
            continue
        labels = dict(re.findall(r'(\w+)="([^"]*)"', line))
        if not labels.get("grpc_service", "").startswith("kinplan."):
            continue
        out[(labels["grpc_method"], labels["grpc_code"])] += int(float(line.rsplit(" ", 1)[1]))
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/kinplan")
    ap.add_argument("--calls", type=int, default=6000)
    ap.add_argument("--threads", type=int, default=16)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    port, mport = free_port(), free_port()
    server = subprocess.Popen([args.bin, "serve", "--listen", f"127.0.0.1:{port}",
                               "--metrics-listen", f"127.0.0.1:{mport}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        channel = grpc.insecure_channel(f"127.0.0.1:{port}")
        grpc.channel_ready_future(channel).result(timeout=30)
        robot, kin, plan = rg.RobotServiceStub(channel), kg.KinematicsServiceStub(channel), pg.PlanningServiceStub(channel)
        tally = Tally()
        counter = iter(range(args.calls))
        lock = threading.Lock()

        def worker(w: int) -> None:
            rng = random.Random(args.seed * 1000 + w)
            while True:
                with lock:
                    if next(counter, None) is None:
                        return
                one_call(rng, robot, kin, plan, tally)

        started = time.monotonic()
        threads = [threading.Thread(target=worker, args=(w,)) for w in range(args.threads)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        elapsed = time.monotonic() - started
        time.sleep(0.5)  # streams the client left are finished on the server
        seen = scrape(f"http://127.0.0.1:{mport}/metrics")
        keys = sorted(set(seen) | set(tally.codes))
        bad = 0
        print(f"{args.calls} calls in {elapsed:.1f} s on {args.threads} threads")
        print(f"{'method':<18} {'code':<20} {'client':>7} {'server':>7}")
        for key in keys:
            a, b = tally.codes.get(key, 0), seen.get(key, 0)
            mark = "" if a == b else "   <-- differs"
            bad += a != b
            print(f"{key[0]:<18} {key[1]:<20} {a:>7} {b:>7}{mark}")
        print(f"series differing: {bad} of {len(keys)}")
        # Per method: calls counted on each side, and how many of them ended
        # because the client stopped waiting (its deadline or its cancel).
        ended = ("DEADLINE_EXCEEDED", "CANCELLED")
        for method in sorted({m for m, _ in keys}):
            total_c = sum(n for (m, _), n in tally.codes.items() if m == method)
            total_s = sum(n for (m, _), n in seen.items() if m == method)
            other_c = {c: n for (m, c), n in tally.codes.items() if m == method and c not in ended}
            other_s = {c: n for (m, c), n in seen.items() if m == method and c not in ended}
            print(f"{method:<18} calls client {total_c:>5} server {total_s:>5}; "
                  f"answers other than deadline/cancel agree: {other_c == other_s}")
        return 1 if bad else 0
    finally:
        server.terminate()
        server.wait(timeout=20)


if __name__ == "__main__":
    sys.exit(main())
