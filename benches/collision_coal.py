#!/usr/bin/env python3
"""Times coal (the maintained FCL, PyPI `coal`) on the shapes of
benches/collision.rs: the Franka Panda's link primitives against 50 seeded
primitives, at the same 1024 states.

Run the Rust bench first (it writes target/collision_bench/scene.json with
the obstacles, the robot shapes and every shape's link pose per state):

    cargo bench -p kinplan-core --bench collision
    python3 benches/collision_coal.py [target/collision_bench/scene.json]

What is timed per state (robot vs scene only: coal's broad phase has no
allowed-collision matrix, and a Python callback per self pair would time
Python): `robot_manager.update()` and `scene_manager.collide(robot_manager,
CollisionCallBackDefault())`, both DynamicAABBTree managers, stopping at the
first contact, as our `is_valid` does. The robot shapes' transforms are set
before the clock starts (our figure includes forward kinematics; coal's does
not). The cost of two empty Python->C++ calls and of the clock, measured the
same way on empty managers, is subtracted. Verdicts are compared with ours.
"""
import json
import platform
import statistics
import sys
import time

import coal
import numpy as np


def rotation(q_xyzw):
    x, y, z, w = q_xyzw
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def homogeneous(pose):
    t = np.eye(4)
    t[:3, :3] = rotation(pose["q_xyzw"])
    t[:3, 3] = pose["t"]
    return t


def geometry(g):
    # coal: Box takes full sides; Cylinder and Capsule (radius, full length), along z.
    if "box" in g:
        return coal.Box(*(2.0 * np.array(g["box"])))
    if "sphere" in g:
        return coal.Sphere(g["sphere"])
    if "cylinder" in g:
        return coal.Cylinder(*g["cylinder"])
    if "capsule" in g:
        return coal.Capsule(*g["capsule"])
    if "mesh" in g:
        # a robot mesh is used as its convex hull, as kinplan uses it
        m = coal.BVHModelOBBRSS()
        v, t = np.array(g["mesh"]["vertices"]), np.array(g["mesh"]["indices"]).reshape(-1, 3)
        m.beginModel(len(t), len(v))
        m.addVertices(v)
        m.addTriangles(t)
        m.endModel()
        m.buildConvexHull(False, "Qt")
        return m.convex
    raise ValueError(g)


def transform(m):
    return coal.Transform3s(np.ascontiguousarray(m[:3, :3]), np.ascontiguousarray(m[:3, 3]))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "target/collision_bench/scene.json"
    with open(path) as f:
        data = json.load(f)
    scene = coal.DynamicAABBTreeCollisionManager()
    obstacles = []
    for o in data["obstacles"]:
        obj = coal.CollisionObject(geometry(o["geometry"]), transform(homogeneous(o["pose"])))
        obj.computeAABB()
        obstacles.append(obj)
    for obj in obstacles:
        scene.registerObject(obj)
    scene.setup()

    shapes = data["robot_shapes"]
    robot_objs = [coal.CollisionObject(geometry(s["geometry"])) for s in shapes]
    robot = coal.DynamicAABBTreeCollisionManager()
    for obj in robot_objs:
        robot.registerObject(obj)
    robot.setup()
    origins = [homogeneous(s["origin"]) for s in shapes]
    states = data["states"]
    poses = [
        [transform(homogeneous(st["links"][s["link"]]) @ origins[k]) for k, s in enumerate(shapes)]
        for st in states
    ]

    empty_a, empty_b = coal.DynamicAABBTreeCollisionManager(), coal.DynamicAABBTreeCollisionManager()
    empty_a.setup()
    empty_b.setup()

    def overhead(n=20000):
        times = []
        for _ in range(n):
            cb = coal.CollisionCallBackDefault()
            t0 = time.perf_counter_ns()
            empty_b.update()
            empty_a.collide(empty_b, cb)
            times.append(time.perf_counter_ns() - t0)
        return statistics.median(times)

    def run():
        times, verdicts = [], []
        for tfs in poses:
            for obj, tf in zip(robot_objs, tfs):
                obj.setTransform(tf)
                obj.computeAABB()
            cb = coal.CollisionCallBackDefault()
            t0 = time.perf_counter_ns()
            robot.update()
            scene.collide(robot, cb)
            times.append(time.perf_counter_ns() - t0)
            verdicts.append(not cb.data.result.isCollision())
        return times, verdicts

    def cpu_ns():
        # This thread's CPU time (ns): excludes time descheduled on a busy machine.
        with open("/proc/thread-self/schedstat") as f:
            return int(f.read().split()[0])

    def cpu_per_state(collide, rounds=5):
        t0 = cpu_ns()
        for _ in range(rounds):
            for tfs in poses:
                for obj, tf in zip(robot_objs, tfs):
                    obj.setTransform(tf)
                    obj.computeAABB()
                cb = coal.CollisionCallBackDefault()
                if collide:
                    robot.update()
                    scene.collide(robot, cb)
                else:
                    empty_b.update()
                    empty_a.collide(empty_b, cb)
        return (cpu_ns() - t0) / (rounds * len(poses))

    run()  # warm up
    rounds = [run() for _ in range(5)]
    times = [t for r in rounds for t in r[0]]
    verdicts = rounds[0][1]
    base = overhead()
    ours = [s["scene_valid"] for s in states]
    agree = sum(a == b for a, b in zip(verdicts, ours))
    mean = statistics.fmean(times)
    med = statistics.median(times)
    print(f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}, coal {coal.__version__}")
    print(f"{len(states)} states x {len(rounds)} rounds; robot shapes {len(shapes)}, obstacles {len(obstacles)}")
    print(f"coal per state (update + collide): mean {mean / 1e3:.3f} us, median {med / 1e3:.3f} us (wall, incl. call overhead)")
    print(f"empty-manager call overhead: median {base / 1e3:.3f} us")
    print(f"coal per state, overhead subtracted: mean {(mean - base) / 1e3:.3f} us, median {(med - base) / 1e3:.3f} us")
    cpu = cpu_per_state(True) - cpu_per_state(False)
    print(f"coal per state, thread CPU time, same loop with empty managers subtracted: {cpu / 1e3:.3f} us")
    print(f"free of the scene: coal {sum(verdicts)}, ours {sum(ours)}; verdicts agree on {agree} of {len(states)}")


if __name__ == "__main__":
    main()
