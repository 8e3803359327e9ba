"""A collision checker of its own for the MotionBenchMaker anchors: the Panda
with hand as kinplan's built-in `franka_panda_hand` URDF describes it (the
same spheres, capsules and boxes, read from that file), posed by forward
kinematics computed here in numpy, against a MoveIt scene's primitives
(boxes, cylinders, spheres), all checked by coal (PyPI `coal`, the maintained
FCL). Nothing of kinplan's collision code is used: only the geometry
description and the list of self-collision pairs kinplan checks (written by
`examples/mbm_bench.rs` as `<out>.acm.json`), so both sides answer the same
question.
"""
import json
import math
import xml.etree.ElementTree as ET

import coal
import numpy as np
import yaml

URDF = 'crates/kinplan-core/src/robot/builtin/franka_panda_hand.urdf'


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def origin(el):
    t = np.eye(4)
    if el is not None:
        t[:3, 3] = [float(v) for v in el.get('xyz', '0 0 0').split()]
        t[:3, :3] = rpy_matrix(*[float(v) for v in el.get('rpy', '0 0 0').split()])
    return t


def quat_matrix(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def geometry(g):
    s = g[0]
    if s.tag == 'sphere':
        return coal.Sphere(float(s.get('radius')))
    if s.tag == 'capsule':  # cylindrical part `length` along z, as coal.Capsule
        return coal.Capsule(float(s.get('radius')), float(s.get('length')))
    if s.tag == 'cylinder':
        return coal.Cylinder(float(s.get('radius')), float(s.get('length')))
    if s.tag == 'box':
        return coal.Box(*[float(v) for v in s.get('size').split()])
    raise ValueError(f'unsupported robot geometry {s.tag}')


def transform(m):
    return coal.Transform3s(m[:3, :3].copy(), m[:3, 3].copy())


class Panda:
    """FK over the URDF's joint tree: arm joints from q, the fingers at a
    fixed opening; every collision element becomes one coal object."""

    def __init__(self, urdf_path, acm_path, opening):
        root = ET.parse(urdf_path).getroot()
        self.joints = {}
        for j in root.findall('joint'):
            axis = j.find('axis')
            lim = j.find('limit')
            self.joints[j.find('child').get('link')] = dict(
                name = j.get('name'), type = j.get('type'), parent = j.find('parent').get('link'),
                origin = origin(j.find('origin')),
                axis = np.array([float(v) for v in axis.get('xyz').split()]) if axis is not None else None,
                lower = float(lim.get('lower')) if lim is not None else None,
                upper = float(lim.get('upper')) if lim is not None else None)
        self.arm = [self.joints[c] for c in self.joints if self.joints[c]['type'] == 'revolute']
        self.arm.sort(key = lambda j: j['name'])
        self.lower = np.array([j['lower'] for j in self.arm])
        self.upper = np.array([j['upper'] for j in self.arm])
        self.opening = opening
        # links in an order where parents come first
        links = [l.get('name') for l in root.findall('link')]
        order, seen = [], set()
        def visit(l):
            if l in seen:
                return
            if l in self.joints:
                visit(self.joints[l]['parent'])
            seen.add(l)
            order.append(l)
        for l in links:
            visit(l)
        self.order = order
        arm_index = {j['name']: i for i, j in enumerate(self.arm)}
        for j in self.arm:
            assert np.allclose(j['axis'], [0, 0, 1]), 'revolute axes must be z'
        self.plan = [(l, self.joints.get(l), arm_index.get(self.joints[l]['name']) if l in self.joints else None)
                     for l in order]
        self.shapes = []  # (link, offset, coal object)
        for l in root.findall('link'):
            for c in l.findall('collision'):
                obj = coal.CollisionObject(geometry(c.find('geometry')), coal.Transform3s())
                self.shapes.append((l.get('name'), origin(c.find('origin')), obj))
        with open(acm_path) as f:
            acm = json.load(f)
        self.pairs = []
        by_link = {}
        for i, (link, _, _) in enumerate(self.shapes):
            by_link.setdefault(link, []).append(i)
        for a, b in acm['checked_pairs']:
            for i in by_link.get(a, []):
                for k in by_link.get(b, []):
                    self.pairs.append((self.shapes[i][2], self.shapes[k][2]))
        self.manager = coal.DynamicAABBTreeCollisionManager()
        for _, _, obj in self.shapes:
            self.manager.registerObject(obj)
        self.manager.setup()
        self.request = coal.CollisionRequest()
        self.result = coal.CollisionResult()

    def link_poses(self, q):
        """Pose of every link (4x4, base frame). Revolute joints turn about
        their z axis (every arm joint of this URDF): t·Rz(θ) mixes t's first
        two columns."""
        poses = {}
        for l, j, ji in self.plan:
            if j is None:
                poses[l] = np.eye(4)
                continue
            t = poses[j['parent']] @ j['origin']
            if ji is not None:
                c, s = math.cos(q[ji]), math.sin(q[ji])
                x = t[:, 0].copy()
                t[:, 0] = c * x + s * t[:, 1]
                t[:, 1] = c * t[:, 1] - s * x
            elif j['type'] == 'prismatic':
                t = t.copy()
                t[:3, 3] += t[:3, :3] @ (j['axis'] * self.opening)
            poses[l] = t
        return poses

    def pose(self, q):
        poses = self.link_poses(q)
        for link, off, obj in self.shapes:
            obj.setTransform(transform(poses[link] @ off))
            obj.computeAABB()  # setTransform leaves the cached AABB stale
        self.manager.update()

    def valid(self, q, scene):
        if np.any(q < self.lower) or np.any(q > self.upper):
            return False
        self.pose(q)
        cb = coal.CollisionCallBackDefault()
        scene.manager.collide(self.manager, cb)
        if cb.data.result.isCollision():
            return False
        for a, b in self.pairs:
            self.result.clear()
            if coal.collide(a, b, self.request, self.result):
                return False
        return True


def scene_primitives(doc, path):
    """(name, 4x4 pose, coal geometry) of every primitive of a MoveIt
    PlanningScene document (`path` names it in errors)."""
    out = []
    for o in doc.get('world', {}).get('collision_objects', []):
        base = np.eye(4)
        if 'pose' in o:
            base[:3, 3] = o['pose']['position']
            base[:3, :3] = quat_matrix(*o['pose']['orientation'])
        for i, (prim, pose) in enumerate(zip(o.get('primitives', []), o.get('primitive_poses', []))):
            d, kind = prim['dimensions'], prim['type']
            if kind in ('box', 1):
                g = coal.Box(*d)
            elif kind in ('sphere', 2):
                g = coal.Sphere(d[0])
            elif kind in ('cylinder', 3):
                g = coal.Cylinder(d[1], d[0])
            else:
                raise ValueError(f'{path}: unsupported primitive {kind}')
            m = np.eye(4)
            m[:3, 3] = pose['position']
            m[:3, :3] = quat_matrix(*pose['orientation'])
            out.append((f"{o['id']}_{i}", base @ m, g))
    return out


class Scene:
    """A MoveIt PlanningScene's world primitives as coal objects."""

    def __init__(self, path):
        with open(path) as f:
            doc = yaml.safe_load(f)
        self.objects = []
        for _, m, g in scene_primitives(doc, path):
            obj = coal.CollisionObject(g, transform(m))
            obj.computeAABB()
            self.objects.append(obj)
        self.manager = coal.DynamicAABBTreeCollisionManager()
        for obj in self.objects:
            self.manager.registerObject(obj)
        self.manager.setup()


def request(path):
    with open(path) as f:
        doc = yaml.safe_load(f)
    js = doc['start_state']['joint_state']
    start = dict(zip(js['name'], js['position']))
    goal = {c['joint_name']: c['position'] for c in doc['goal_constraints'][0]['joint_constraints']}
    names = [f'panda_joint{i}' for i in range(1, 8)]
    return (np.array([start[n] for n in names], dtype = float),
            np.array([goal[n] for n in names], dtype = float),
            float(start.get('panda_finger_joint1', 0.04)))
