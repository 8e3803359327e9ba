#!/usr/bin/env python3
"""Fits a built-in robot's collision shapes around the real robot's collision
meshes, so that a state the built-in model finds free is free for the real arm.

Reads the robot of `example-robot-data` (its collision meshes, the ones MoveIt
plans with; pip install example-robot-data pin): the Franka Panda with its hand
(`franka_panda_hand.urdf`) and the UR5 (`ur5.urdf`). Every mesh vertex is placed
in the built-in model's link frames: both models are posed at the same joint
values, and the one rigid transform between their bases (the UR5's ROS base is
turned half a turn from the DH base) is found at one state and checked at
others against the tool frame, so the kinematics agree. Then it writes

- `<robot>_covers.json`: per link one convex shape holding every vertex of the
  link's mesh, so it holds the mesh (a convex set holding a mesh's vertices
  holds their hull). For the links listed in `hulls` that shape is a
  polytope of at most `PLANES` faces around the hull (`outer_polytope`),
  written as
  `meshes/<robot>/<link>.obj`, which the built-in URDF names and the library
  embeds. For the others a primitive: a capsule for the arm links (for each
  axis direction of a search, the smallest circle around the vertices
  projected across the axis, caps as short as the vertices allow, the radius
  grown while that shrinks the volume), a box for the fingers (the
  vertices' bounds in the link frame); every size grown by `MARGIN` and
  rounded outwards to 0.1 mm. A capsule or a box leaves room between
  itself and a rounded or flat mesh, and at the Panda's wrist, where link 5,
  link 7 and the hand stay close in most states, that room made the
  built-in model refuse many states the meshes find free (benches/RESULTS.md);
  the polytopes refuse little more than the meshes do;
- `<robot>_mesh_points.txt`: the vertices, `link x y z` per line in metres,
  which the Rust tests hold the committed URDFs against.

generate.py reads the covers. Run by hand, with a Python that has
`example-robot-data` and `pin` installed:

    python src/robot/builtin/fit_covers.py
"""
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin
from scipy.spatial import ConvexHull, HalfspaceIntersection

OUT = os.path.dirname(os.path.abspath(__file__))
MARGIN = 0.0005
PLANES = 20
STEP = 1e-4
ROBOTS = {
    'panda': dict(
        urdf=('panda_description', 'panda.urdf'), builtin='franka_panda_hand.urdf',
        joints=[f'panda_joint{i}' for i in range(1, 8)], held={'panda_finger_joint1': 0.0, 'panda_finger_joint2': 0.0},
        tool=('panda_hand', 'panda_hand'),
        names={**{f'panda_link{i}': f'link_{i}' for i in range(1, 8)}, 'panda_link0': 'base_link',
               'panda_hand': 'panda_hand', 'panda_leftfinger': 'panda_leftfinger',
               'panda_rightfinger': 'panda_rightfinger'},
        boxes={'panda_leftfinger', 'panda_rightfinger'},
        hulls={'base_link', 'link_1', 'link_2', 'link_3', 'link_4', 'link_5', 'link_6', 'link_7', 'panda_hand'}),
    'ur5': dict(
        urdf=('ur_description', 'ur5_robot.urdf'), builtin='ur5.urdf',
        joints=['shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint', 'wrist_1_joint', 'wrist_2_joint',
                'wrist_3_joint'], held={},
        tool=('tool0', 'tool0'),
        names={'base_link': 'base_link', 'shoulder_link': 'link_1', 'upper_arm_link': 'link_2',
               'forearm_link': 'link_3', 'wrist_1_link': 'link_4', 'wrist_2_link': 'link_5',
               'wrist_3_link': 'link_6', 'ee_link': 'link_6'},
        boxes=set(), hulls=set()),
}


def robot_urdf(package, file):
    share = os.path.normpath(os.path.join(os.path.dirname(pin.__file__), '..', '..', '..', '..', 'share'))
    path = os.path.join(share, 'example-robot-data', 'robots', package, 'urdf', file)
    if not os.path.isfile(path):
        sys.exit(f'{path} not found: pip install example-robot-data')
    return share, path


def rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
            @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]))


def builtin_frames(builtin, q):
    """Pose (4x4) of every link of the built-in URDF at state q (joints
    `joint_1`, `joint_2`, ...), other moving joints at 0 (a finger frame's own
    coordinates do not depend on its opening)."""
    import xml.etree.ElementTree as ET
    root = ET.parse(os.path.join(OUT, builtin)).getroot()
    joints = {j.find('child').get('link'): j for j in root.findall('joint')}
    poses = {'base_link': np.eye(4)}

    def pose(link):
        if link in poses:
            return poses[link]
        j = joints[link]
        o = j.find('origin')
        t = np.eye(4)
        t[:3, 3] = [float(v) for v in o.get('xyz').split()]
        t[:3, :3] = rpy(*[float(v) for v in o.get('rpy').split()])
        t = pose(j.find('parent').get('link')) @ t
        if j.get('type') in ('revolute', 'continuous') and j.get('name').startswith('joint_'):
            k = int(j.get('name').split('_')[1]) - 1
            c, s = math.cos(q[k]), math.sin(q[k])
            t = t @ np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
        poses[link] = t
        return t
    for link in joints:
        pose(link)
    return poses


def pinocchio_pose(model, robot, q_arm):
    q = pin.neutral(model)
    for name, v in list(zip(robot['joints'], q_arm)) + list(robot['held'].items()):
        q[model.joints[model.getJointId(name)].idx_q] = v
    return q


def mesh_points(robot):
    share, urdf = robot_urdf(*robot['urdf'])
    model = pin.buildModelFromUrdf(urdf)
    geom = pin.buildGeomFromUrdf(model, urdf, pin.COLLISION, package_dirs=[share])
    data, gdata = model.createData(), geom.createData()
    rng = np.random.default_rng(3)
    ours_tool, theirs_tool = robot['tool']
    base = None  # built-in base in the example's world: ours = base @ theirs
    for trial in range(4):
        q_arm = rng.uniform(-2.5, 2.5, len(robot['joints']))
        pin.framesForwardKinematics(model, data, pinocchio_pose(model, robot, q_arm))
        theirs = data.oMf[model.getFrameId(theirs_tool)].homogeneous
        ours = builtin_frames(robot['builtin'], q_arm)[ours_tool]
        if base is None:
            base = ours @ np.linalg.inv(theirs)
        assert np.abs(base @ theirs - ours).max() < 1e-9, f'{robot["builtin"]}: the kinematics differ'
    q = pinocchio_pose(model, robot, q_arm)
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, geom, gdata)
    frames = builtin_frames(robot['builtin'], q_arm)
    points = {}
    for i, g in enumerate(geom.geometryObjects):
        shape = g.geometry
        if hasattr(shape, 'vertices'):
            v = np.array(shape.vertices())
        else:  # a box
            e = shape.halfSide
            v = np.array([[sx * e[0], sy * e[1], sz * e[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        world = base @ gdata.oMg[i].homogeneous @ np.c_[v, np.ones(len(v))].T
        link = robot['names'][model.frames[g.parentFrame].name]
        points.setdefault(link, []).append((np.linalg.inv(frames[link]) @ world).T[:, :3])
    return {k: np.vstack(v) for k, v in points.items()}


def min_circle(p):
    """Smallest circle around 2-D points (Welzl's incremental algorithm)."""
    rng = np.random.default_rng(0)
    p = p[rng.permutation(len(p))]

    def two(a, b):
        c = (a + b) / 2
        return c, np.linalg.norm(a - c)

    def three(a, b, c):
        d = 2 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
        if abs(d) < 1e-15:
            return max([two(a, b), two(a, c), two(b, c)], key=lambda t: t[1])
        sa, sb, sc = a @ a, b @ b, c @ c
        u = np.array([sa * (b[1] - c[1]) + sb * (c[1] - a[1]) + sc * (a[1] - b[1]),
                      sa * (c[0] - b[0]) + sb * (a[0] - c[0]) + sc * (b[0] - a[0])]) / d
        return u, np.linalg.norm(a - u)

    def inside(x, c, r):
        return np.linalg.norm(x - c) <= r * (1 + 1e-12)
    c, r = p[0], 0.0
    for i in range(1, len(p)):
        if inside(p[i], c, r):
            continue
        c, r = p[i], 0.0
        for j in range(i):
            if inside(p[j], c, r):
                continue
            c, r = two(p[i], p[j])
            for k in range(j):
                if not inside(p[k], c, r):
                    c, r = three(p[i], p[j], p[k])
    return c, r


def capsule_along(p, u):
    """(volume, end 0, end 1, radius) of the smallest capsule of axis u found."""
    u = u / np.linalg.norm(u)
    a = np.cross(u, [1.0, 0, 0] if abs(u[0]) < 0.9 else [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(u, a)
    t = p @ u
    c, r0 = min_circle(np.c_[p @ a, p @ b])
    d = np.hypot(p @ a - c[0], p @ b - c[1])
    best = None
    for r in r0 * np.linspace(1.0, 1.6, 25):
        h = np.sqrt(np.maximum(r * r - d * d, 0))
        t1, t0 = np.max(t - h), np.min(t + h)
        if t1 < t0:
            t0 = t1 = (t0 + t1) / 2
        volume = math.pi * r * r * (t1 - t0) + 4 / 3 * math.pi * r ** 3
        if best is None or volume < best[0]:
            base = c[0] * a + c[1] * b
            best = (volume, base + t0 * u, base + t1 * u, r)
    return best


def fit_capsule(p):
    rng = np.random.default_rng(1)
    n = 1200
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), math.pi * (1 + 5 ** 0.5) * i
    dirs = np.c_[np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)]
    dirs = dirs[dirs[:, 2] >= 0]
    found = sorted(((capsule_along(p, u), u) for u in dirs), key=lambda t: t[0][0])[:5]
    best, best_u = found[0]
    for fit, u0 in found:
        for s in [0.05, 0.02, 0.005, 0.001]:
            for _ in range(30):
                u = u0 + rng.normal(0, s, 3)
                f = capsule_along(p, u)
                if f[0] < best[0]:
                    best, best_u, u0 = f, u, u
    _, e0, e1, _ = best
    e0, e1 = np.round(e0 / STEP) * STEP, np.round(e1 / STEP) * STEP
    # the radius the rounded ends need, grown by the margin, rounded up
    seg = e1 - e0
    s = np.clip(((p - e0) @ seg) / max(seg @ seg, 1e-300), 0, 1)
    need = np.linalg.norm(p - (e0 + s[:, None] * seg), axis=1).max()
    return {'capsule': {'p0': e0.tolist(), 'p1': e1.tolist(), 'radius': math.ceil((need + MARGIN) / STEP) * STEP}}


def fit_box(p):
    lo = np.floor((p.min(0) - MARGIN) / STEP) * STEP
    hi = np.ceil((p.max(0) + MARGIN) / STEP) * STEP
    return {'box': {'min': lo.tolist(), 'max': hi.tolist()}}


def outer_polytope(p):
    """(vertices, outward triangles) of a polytope of at most `PLANES` faces
    holding the convex hull of `p` with `MARGIN` to spare: the intersection
    of half-spaces whose planes support the hull (n·x ≤ max n·p), each moved
    out by `MARGIN`. It starts from the six axis directions and adds, one at
    a time, the hull face plane that shrinks the volume most. Fewer faces
    than the hull's make each support query of the exact test cheaper; any
    intersection of supporting half-spaces holds the hull."""
    hull = ConvexHull(p)
    centre = p[hull.vertices].mean(0)
    faces = {tuple(np.round(e[:3], 6)): e[:3] for e in hull.equations}
    candidates = list(faces.values())

    def plane(n):
        n = n / np.linalg.norm(n)
        return np.r_[n, -(p @ n).max() - MARGIN]

    def corners(planes):
        return HalfspaceIntersection(np.array(planes), centre).intersections

    planes = [plane(np.array(n, float)) for n in np.vstack([np.eye(3), -np.eye(3)])]
    while len(planes) < PLANES:
        volume, best = min((ConvexHull(corners(planes + [plane(n)])).volume, k) for k, n in enumerate(candidates))
        planes.append(plane(candidates.pop(best)))
    v = corners(planes)
    outer = ConvexHull(v)
    v = v[outer.vertices]
    index = {k: i for i, k in enumerate(outer.vertices)}
    triangles = []
    for tri, eq in zip(outer.simplices, outer.equations):
        a, b, c = outer.points[tri]
        if np.cross(b - a, c - a) @ eq[:3] < 0:
            tri = tri[[0, 2, 1]]
        triangles.append([index[k] for k in tri])
    return v, triangles


def write_obj(path, source, vertices, faces):
    with open(path, 'w') as f:
        f.write(f'# {source}: a polytope of at most {PLANES} faces holding its convex hull with {MARGIN} m to spare (fit_covers.py)\n')
        for x in vertices:
            f.write(f'v {x[0]:.9f} {x[1]:.9f} {x[2]:.9f}\n')
        for t in faces:
            f.write(f'f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n')


def main():
    for name, robot in ROBOTS.items():
        points = mesh_points(robot)
        covers = {}
        for link, p in sorted(points.items()):
            if link in robot['hulls']:
                os.makedirs(os.path.join(OUT, 'meshes', name), exist_ok=True)
                write_obj(os.path.join(OUT, 'meshes', name, f'{link}.obj'),
                          f'{link} of example-robot-data {robot["urdf"][0]}', *outer_polytope(p))
                covers[link] = {'mesh': f'{name}/{link}.obj'}
            else:
                covers[link] = fit_box(p) if link in robot['boxes'] else fit_capsule(p)
        covers = json.loads(json.dumps(covers, default=float), parse_float=lambda s: round(float(s), 4))
        package, file = robot['urdf']
        with open(os.path.join(OUT, f'{name}_covers.json'), 'w') as f:
            json.dump({'source': f'example-robot-data {package}/urdf/{file} collision meshes',
                       'margin_m': MARGIN, 'covers': covers}, f, indent=1)
            f.write('\n')
        with open(os.path.join(OUT, f'{name}_mesh_points.txt'), 'w') as f:
            f.write(f'# Vertices of the collision meshes of example-robot-data {package}/urdf/{file}, in the link\n'
                    f'# frames of {robot["builtin"]}, metres; written by fit_covers.py.\n')
            for link, p in sorted(points.items()):
                for x in p:
                    f.write(f'{link} {x[0]:.6f} {x[1]:.6f} {x[2]:.6f}\n')
        for link, c in covers.items():
            print(name, link, c)


if __name__ == '__main__':
    main()
