"""Cost of one state check on the MotionBenchMaker scenes with pinocchio + coal:
the Franka Panda of `example-robot-data` with its collision meshes (the
geometry MoveIt plans with), against each problem's MoveIt scene, on the
states `state_cost_vamp.py` wrote (so the three checkers see the same states).

One `pinocchio.computeCollisions(model, data, geom, geom_data, q, True)` per
state: forward kinematics, placements and every collision pair until the
first contact, all in C++ (coal checks each mesh as its triangles). Pairs:
every robot geometry against every scene object, and the robot's own pairs
less those the SRDF disables (`--srdf`: example-robot-data's by default;
MoveIt's own Panda configuration, the one MotionBenchMaker plans with, checks
more pairs: pass it, e.g. VAMP's `resources/panda/panda.srdf`). Fingers held at 0.04 m each (the problems'
open grasps, as `mbm_bench --clamp-fingers`). The Python loop's own cost is
timed apart (the same loop calling `pinocchio.neutral`) and reported; it is
not subtracted.

Also counts, against the verdicts VAMP's harness wrote (`states*.bin.vamp`,
one byte per state, 1 = free) and ours (`states*.bin.ours`, written by
`mbm_bench --states-from`: the built-in capsule Panda), the states each
calls free that collide on the meshes, and the other way round: how well
each model stands for the meshes.

    /work/py-venv-coal/bin/python benches/mbm/state_cost_coal.py \\
        --problems target/mbm/problems --states target/mbm_states
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np
import pinocchio as pin
import yaml

sys.path.insert(0, os.path.dirname(__file__))
from panda_coal import scene_primitives  # noqa: E402

SETS = ['table_pick', 'table_under_pick', 'box', 'bookshelf_small', 'bookshelf_tall', 'bookshelf_thin', 'cage']
FINGER = 0.04


def robot_dir():
    here = os.path.dirname(pin.__file__)
    share = os.path.normpath(os.path.join(here, '..', '..', '..', '..', 'share'))
    path = os.path.join(share, 'example-robot-data', 'robots', 'panda_description')
    if not os.path.isdir(path):
        sys.exit(f'example-robot-data not found under {share}: pip install example-robot-data')
    return share, path


def scene_objects(path):
    """(name, SE3, coal geometry) of a MoveIt PlanningScene's primitives."""
    with open(path) as f:
        doc = yaml.safe_load(f)
    return [(name, pin.SE3(m[:3, :3], m[:3, 3]), g) for name, m, g in scene_primitives(doc, path)]


class MeshPanda:
    """The Panda with its meshes in pinocchio, self pairs per the SRDF."""

    def __init__(self, srdf=None):
        share, root = robot_dir()
        urdf = os.path.join(root, 'urdf', 'panda.urdf')
        self.model = pin.buildModelFromUrdf(urdf)
        self.robot_geom = pin.buildGeomFromUrdf(self.model, urdf, pin.COLLISION, package_dirs=[share])
        self.srdf = srdf or os.path.join(root, 'srdf', 'panda.srdf')
        self.arm = [self.model.getJointId(f'panda_joint{i}') for i in range(1, 8)]
        self.fingers = [self.model.getJointId(f'panda_finger_joint{i}') for i in (1, 2)]

    def q(self, arm):
        q = pin.neutral(self.model)
        for jid, v in zip(self.arm, arm):
            q[self.model.joints[jid].idx_q] = v
        for jid in self.fingers:
            q[self.model.joints[jid].idx_q] = FINGER
        return q

    def with_scene(self, objects):
        """A geometry model: the robot's pairs (SRDF-filtered) plus robot × scene."""
        geom = self.robot_geom.copy()
        geom.addAllCollisionPairs()
        pin.removeCollisionPairs(self.model, geom, self.srdf)
        n_robot = len(geom.geometryObjects)
        for name, placement, g in objects:
            k = geom.addGeometryObject(pin.GeometryObject(name, 0, placement, g))
            for r in range(n_robot):
                geom.addCollisionPair(pin.CollisionPair(r, k))
        return geom


def time_loop(fn, qs, passes):
    best = float('inf')
    for _ in range(passes):
        t = time.perf_counter_ns()
        for q in qs:
            fn(q)
        best = min(best, (time.perf_counter_ns() - t) / max(len(qs), 1))
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--problems', required=True, help='the extracted MotionBenchMaker problems')
    ap.add_argument('--states', required=True, help="state_cost_vamp.py's --out directory")
    ap.add_argument('--sets', default=','.join(SETS))
    ap.add_argument('--problems-per-set', type=int, default=20)
    ap.add_argument('--passes', type=int, default=3)
    ap.add_argument('--srdf', help="the SRDF whose disabled pairs the robot's own checks leave out")
    ap.add_argument('--json')
    args = ap.parse_args()

    panda = MeshPanda(args.srdf)
    data = panda.model.createData()
    summary = {}
    print('| set | problems | coal (meshes): all states | coal: free states | Python loop alone | '
          'free (coal) | VAMP free, meshes collide | VAMP refuses, meshes free | ours free, meshes collide | '
          'ours refuses, meshes free |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for name in args.sets.split(','):
        d = os.path.join(args.states, f'{name}_panda')
        files = sorted(f for f in os.listdir(d) if f.startswith('states') and f.endswith('.bin'))
        rows = []
        for f in files[:args.problems_per_set]:
            k = int(f[len('states'):-len('.bin')])
            arm = np.fromfile(os.path.join(d, f), dtype='<f8').reshape(-1, 7)
            vamp_free = np.fromfile(os.path.join(d, f + '.vamp'), dtype=np.uint8).astype(bool)
            ours_free = np.fromfile(os.path.join(d, f + '.ours'), dtype=np.uint8).astype(bool)
            objects = scene_objects(os.path.join(args.problems, f'{name}_panda', f'scene{k:04}.yaml'))
            geom = panda.with_scene(objects)
            gdata = geom.createData()
            qs = [panda.q(a) for a in arm]
            free = np.array([not pin.computeCollisions(panda.model, data, geom, gdata, q, True) for q in qs])
            check = lambda q: pin.computeCollisions(panda.model, data, geom, gdata, q, True)
            all_ns = time_loop(check, qs, args.passes)
            free_qs = [q for q, ok in zip(qs, free) if ok]
            free_ns = time_loop(check, free_qs, args.passes)
            loop_ns = time_loop(lambda q: pin.neutral(panda.model), qs, args.passes)
            rows.append({'problem': k, 'states': len(qs), 'free': int(free.sum()), 'all_ns': all_ns,
                         'free_ns': free_ns, 'loop_ns': loop_ns,
                         'vamp_free_mesh_collides': int((vamp_free & ~free).sum()),
                         'vamp_refuses_mesh_free': int((~vamp_free & free).sum()),
                         'ours_free_mesh_collides': int((ours_free & ~free).sum()),
                         'ours_refuses_mesh_free': int((~ours_free & free).sum()),
                         'pairs': len(geom.collisionPairs)})
        med = lambda key: statistics.median(r[key] for r in rows)
        n = rows[0]['states']
        summary[name] = {'rows': rows}
        print(f"| {name} | {len(rows)} | {med('all_ns'):.0f} ns | {med('free_ns'):.0f} ns | {med('loop_ns'):.0f} ns | "
              f"{med('free') / n:.3f} | {med('vamp_free_mesh_collides') / n:.4f} | "
              f"{med('vamp_refuses_mesh_free') / n:.4f} | {med('ours_free_mesh_collides') / n:.4f} | "
              f"{med('ours_refuses_mesh_free') / n:.4f} |", flush=True)
    total = lambda key: sum(r[key] for v in summary.values() for r in v['rows'])
    print(f"in all: {total('states')} states; called free where the meshes collide: "
          f"VAMP {total('vamp_free_mesh_collides')}, ours {total('ours_free_mesh_collides')}")
    if args.json:
        json.dump(summary, open(args.json, 'w'), indent=1)


if __name__ == '__main__':
    main()
