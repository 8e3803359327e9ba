"""MotionBenchMaker problems planned for the real Panda — example-robot-data's
URDF with its own collision meshes, hand and fingers — beside kinplan's
built-in capsule Panda on the same problems, over loopback gRPC; every
returned path re-checked against the meshes by pinocchio + coal (exact
triangles) at 0.01 rad.

    KINPLAN_BIN=target/release/kinplan python benches/real_robots/mbm_real_panda.py \\
        ../shared/bench/mbm/panda_problems.tar.bz2 [--per-set 10]

Needs example-robot-data, pin, coal and pyyaml (pip) beside the client.
Scenes whose start or goal a model finds in collision are counted apart
(INVALID_START / INVALID_GOAL), not dropped.

The problems' goals are grasps with the fingers open around an object, so
both models hold the fingers open at their 40 mm limit (`held_joints`; the
problems write 65 mm, past the URDF's limit), and so does the re-check.
"""
import argparse
import io
import math
import statistics
import sys
import tarfile
import time

import coal
import numpy as np
import pinocchio as pin
import yaml

import kinplan

ARM = [f"panda_joint{i}" for i in range(1, 8)]
FINGERS = {"panda_finger_joint1": 0.04, "panda_finger_joint2": 0.04}


def share_dir():
    for p in sys.path:
        cand = f"{p}/cmeel.prefix/share"
        try:
            import os

            if os.path.isdir(f"{cand}/example-robot-data"):
                return cand
        except OSError:
            pass
    raise SystemExit("example-robot-data is not installed")


def quat_matrix(x, y, z, w):
    return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()


def problems(archive, per_set):
    """{set: [(scene objects, start, goal)]}, `per_set` problems of each set."""
    out = {}
    with tarfile.open(archive) as tar:
        members = {m.name: m for m in tar.getmembers() if m.isfile()}

        def load(name):
            return yaml.safe_load(io.TextIOWrapper(tar.extractfile(members[name])))

        for name in sorted(members):
            if not name.endswith(".yaml") or "/scene" not in name:
                continue
            folder, file = name.rsplit("/", 1)
            pset = folder.rsplit("/", 1)[-1].removesuffix("_panda")
            if len(out.setdefault(pset, [])) >= per_set:
                continue
            request = load(f"{folder}/{file.replace('scene', 'request')}")
            scene = load(name)
            objects = []
            for obj in scene["world"]["collision_objects"]:
                for prim, pose in zip(obj["primitives"], obj["primitive_poses"]):
                    p, o = pose["position"], pose["orientation"]  # [x, y, z], [x, y, z, w]
                    T = np.eye(4)
                    T[:3, :3] = quat_matrix(*o)
                    T[:3, 3] = p
                    objects.append((prim["type"], prim["dimensions"], T))
            js = request["start_state"]["joint_state"]
            start = [js["position"][js["name"].index(j)] for j in ARM]
            constraints = request["goal_constraints"][0]["joint_constraints"]
            goal_by = {c["joint_name"]: c["position"] for c in constraints}
            out[pset].append((objects, np.array(start), np.array([goal_by[j] for j in ARM])))
    return out


def kinplan_scene(objects):
    scene = []
    for k, (kind, dims, T) in enumerate(objects):
        if kind == "box":
            scene.append(kinplan.Box(dims, T, id=f"o{k}"))
        elif kind == "cylinder":
            scene.append(kinplan.Cylinder(dims[1], dims[0], T, id=f"o{k}"))
        elif kind == "sphere":
            scene.append(kinplan.Sphere(dims[0], T, id=f"o{k}"))
    return scene


class CoalCheck:
    """The real Panda's meshes (fingers at 0) against a scene's primitives, by coal."""

    def __init__(self, urdf, share):
        self.model = pin.buildModelFromUrdf(urdf)
        self.geom = pin.buildGeomFromUrdf(self.model, urdf, pin.COLLISION, package_dirs=[share])
        self.n_robot = len(self.geom.geometryObjects)
        self.data = self.model.createData()
        self.arm_q = [self.model.joints[self.model.getJointId(j)].idx_q for j in ARM]
        self.q0 = pin.neutral(self.model)
        for name, value in FINGERS.items():
            self.q0[self.model.joints[self.model.getJointId(name)].idx_q] = value

    def path_collides(self, objects, path, step=0.01):
        geom = self.geom.copy()
        for k, (kind, dims, T) in enumerate(objects):
            shape = {"box": lambda d: coal.Box(*d), "cylinder": lambda d: coal.Cylinder(d[1], d[0]),
                     "sphere": lambda d: coal.Sphere(d[0])}[kind](dims)
            oid = geom.addGeometryObject(pin.GeometryObject(f"o{k}", 0, 0, pin.SE3(T[:3, :3], T[:3, 3]), shape))
            for i in range(self.n_robot):
                geom.addCollisionPair(pin.CollisionPair(i, oid))
        gdata = pin.GeometryData(geom)
        q = self.q0.copy()
        for a, b in zip(path[:-1], path[1:]):
            n = max(1, math.ceil(np.max(np.abs(b - a)) / step))
            for s in np.linspace(0.0, 1.0, n + 1):
                q[self.arm_q] = a + s * (b - a)
                if pin.computeCollisions(self.model, self.data, geom, gdata, q, True):
                    return True
        return False


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("archive")
    ap.add_argument("--per-set", type=int, default=10)
    ap.add_argument("--target", help="a running kinplan server (default: kinplan.LocalServer)")
    args = ap.parse_args()
    share = share_dir()
    urdf = f"{share}/example-robot-data/robots/panda_description/urdf/panda.urdf"
    sets = problems(args.archive, args.per_set)
    coal_check = CoalCheck(urdf, share)
    server = None if args.target else kinplan.LocalServer().start()
    with kinplan.Client(args.target or server.address, timeout=60) as c:
        real = c.robot(urdf=urdf, package_dirs=[share], base_link="panda_link0", tip_link="panda_hand",
                       held_joints=FINGERS)
        capsules = c.robot("franka_panda_hand", held_joints=FINGERS)
        print("| set | problems | real: solved | real: start/goal in collision | real: median ms | real: paths colliding at 0.01 rad (coal, meshes) | capsules: solved | capsules: median ms |")
        print("|---|---|---|---|---|---|---|---|")
        for pset, probs in sets.items():
            row = {"real": [], "caps": []}
            invalid = colliding = 0
            for objects, start, goal in probs:
                scene = kinplan_scene(objects)
                for key, robot in (("real", real), ("caps", capsules)):
                    t0 = time.perf_counter()
                    plan = robot.plan(start, goal, algorithm="rrt_connect", scene=scene, seed=1, padded_motion=True)
                    ms = 1e3 * (time.perf_counter() - t0)
                    if plan.status == "SUCCEEDED":
                        row[key].append(ms)
                        if key == "real" and coal_check.path_collides(objects, np.asarray(plan.q)):
                            colliding += 1
                    elif key == "real" and plan.status in ("INVALID_START", "INVALID_GOAL"):
                        invalid += 1
            med = lambda v: f"{statistics.median(v):.1f}" if v else "-"  # noqa: E731
            print(f"| {pset} | {len(probs)} | {len(row['real'])} | {invalid} | {med(row['real'])} | {colliding} | "
                  f"{len(row['caps'])} | {med(row['caps'])} |")
    if server is not None:
        server.stop()


if __name__ == "__main__":
    main()
