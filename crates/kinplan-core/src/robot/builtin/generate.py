#!/usr/bin/env python3
"""Writes the built-in robots' URDF files (src/robot/builtin/*.urdf) from their
published kinematic data (mm, degrees), with one capsule per link as collision
geometry (the Panda's and the UR5's: shapes fitted around their real meshes, fit_covers.py). Run: python3 src/robot/builtin/generate.py

The URDFs are committed; this script documents where every number comes from.
"""
import json
import math
import os

OUT = os.path.dirname(os.path.abspath(__file__))


def fmt(v):
    return " ".join(repr(float(x)) for x in v)


def capsule_origin(p0, p1):
    """Origin (xyz, rpy) of a URDF capsule (along z, centred) spanning p0 -> p1."""
    d = [b - a for a, b in zip(p0, p1)]
    length = math.sqrt(sum(x * x for x in d))
    mid = [(a + b) / 2 for a, b in zip(p0, p1)]
    if length < 1e-12:
        return mid, [0.0, 0.0, 0.0], 0.0
    pitch = math.atan2(math.hypot(d[0], d[1]), d[2])
    yaw = math.atan2(d[1], d[0])
    return mid, [0.0, pitch, yaw], length


def shape_link_xml(name, xyz, rpy, geom):
    """A link with one collision shape `geom` (URDF geometry element) at (xyz, rpy)."""
    return (
        f'  <link name="{name}">\n'
        f"    <collision>\n"
        f'      <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>\n'
        f"      <geometry>{geom}</geometry>\n"
        f"    </collision>\n"
        f"  </link>\n"
    )


def link_xml(name, segment, radius):
    if segment is None:
        return f'  <link name="{name}"/>\n'
    (p0, p1) = segment
    xyz, rpy, length = capsule_origin(p0, p1)
    if length < 1e-9:
        geom = f'<sphere radius="{float(radius)!r}"/>'
    else:
        geom = f'<capsule radius="{float(radius)!r}" length="{float(length)!r}"/>'
    return shape_link_xml(name, xyz, rpy, geom)


def joint_xml(name, kind, parent, child, xyz, rpy, axis=None, limit=None):
    s = f'  <joint name="{name}" type="{kind}">\n'
    s += f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
    s += f'    <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>\n'
    if axis is not None:
        s += f'    <axis xyz="{fmt(axis)}"/>\n'
    if limit is not None:
        lo, hi, vel = limit
        s += f'    <limit lower="{float(lo)!r}" upper="{float(hi)!r}" effort="0" velocity="{float(vel)!r}"/>\n'
    s += "  </joint>\n"
    return s


def write_robot(name, comment, joints, tool, radii, base_radius):
    """joints: list of (xyz, rpy, axis, (lo_rad, hi_rad, vel_rad_s)) for joint_1..n.
    tool: list of (child_name, xyz, rpy) fixed frames after the last link."""
    n = len(joints)
    links = ["base_link"] + [f"link_{i}" for i in range(1, n + 1)]
    out = f'<?xml version="1.0"?>\n<!-- {comment} -->\n<robot name="{name}">\n'
    # Link i's capsule spans from its own origin to the next joint's origin.
    next_origins = [j[0] for j in joints[1:]] + [tool[0][1]]
    out += link_xml("base_link", ([0, 0, 0], [0, 0, 0]) if base_radius else None, base_radius or 0)
    for i in range(n):
        out += link_xml(links[i + 1], ([0, 0, 0], next_origins[i]), radii[i])
    parent = links[-1]
    for child, _, _ in tool:
        out += link_xml(child, None, 0)
    for i, (xyz, rpy, axis, limit) in enumerate(joints):
        kind = "revolute" if limit is not None else "continuous"
        out += joint_xml(f"joint_{i + 1}", kind, links[i], links[i + 1], xyz, rpy, axis, limit)
    for child, xyz, rpy in tool:
        out += joint_xml(f"{parent}-{child}", "fixed", parent, child, xyz, rpy)
        parent = child
    out += "</robot>\n"
    with open(os.path.join(OUT, f"{name}.urdf"), "w") as f:
        f.write(out)


def lim(lo_deg, hi_deg, vel_deg):
    return (math.radians(lo_deg), math.radians(hi_deg), math.radians(vel_deg))


def industrial(name, comment, d1, a1, a2, a3, d4, d6, signs, vertical_arm2, limits, speeds, radii):
    """Six-axis industrial arm in the ROS-Industrial layout: joint 1 about z,
    2 and 3 about y, 4 about x, 5 about y, 6 about x; `signs` flips an axis
    to follow the controller's sign convention. Lengths in mm."""
    m = 1e-3
    axes = [[0, 0, 1], [0, 1, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]]
    axes = [[s * c for c in ax] for s, ax in zip(signs, axes)]
    if vertical_arm2:  # ABB: arm 2 vertical at zero, offset a3 upwards
        origins = [[0, 0, 0], [a1, 0, d1], [0, 0, a2], [0, 0, a3], [d4, 0, 0], [0, 0, 0]]
    else:  # KUKA: arm 2 horizontal at zero, a3 is a z offset of axis 4
        origins = [[0, 0, d1], [a1, 0, 0], [a2, 0, 0], [d4, 0, a3], [0, 0, 0], [0, 0, 0]]
    joints = []
    for i in range(6):
        joints.append(([c * m for c in origins[i]], [0, 0, 0], axes[i], lim(*limits[i], speeds[i])))
    tool = [("flange", [d6 * m, 0, 0], [0, 0, 0]), ("tool0", [0, 0, 0], [0, math.pi / 2, 0])]
    write_robot(name, comment, joints, tool, radii, 0.3)


def standard_dh(name, comment, d, a, alpha, limits, speeds, radii, base_radius=0.1):
    """Joint i+1's origin is link i's Tz(d_i) Tx(a_i) Rx(alpha_i); the first
    joint sits at the base origin; tool0 is the last DH frame."""
    joints = []
    prev = ([0, 0, 0], [0, 0, 0])
    for i in range(len(d)):
        joints.append((prev[0], prev[1], [0, 0, 1], limits[i] and lim(*limits[i], speeds[i])))
        prev = ([a[i], 0, d[i]], [alpha[i], 0, 0])
    tool = [("tool0", prev[0], prev[1])]
    write_robot(name, comment, joints, tool, radii, base_radius)


def craig_dh(name, comment, d, a, alpha, flange, limits, speeds, radii):
    """Modified (Craig) DH: joint i's origin is Rx(alpha_{i-1}) Tx(a_{i-1}) Tz(d_i),
    i.e. xyz = (a, -d sin(alpha), d cos(alpha)), rpy = (alpha, 0, 0)."""
    joints = []
    for i in range(len(d)):
        al = alpha[i]
        xyz = [a[i], -d[i] * math.sin(al), d[i] * math.cos(al)]
        joints.append((xyz, [al, 0, 0], [0, 0, 1], lim(*limits[i], speeds[i])))
    tool = [("flange", [0, 0, flange], [0, 0, 0])]
    write_robot(name, comment, joints, tool, radii, 0.12)


def cover_link_xml(name, cover):
    """A link whose one collision shape is `cover` (<robot>_covers.json): a
    mesh the library embeds (`kinplan://builtin/<robot>/<link>.obj`, the
    grown convex hull fit_covers.py wrote), a capsule between two points or a
    box between two corners, link frame."""
    if "mesh" in cover:
        xyz, rpy = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        geom = f'<mesh filename="{BUILTIN_MESH_SCHEME}{cover["mesh"]}"/>'
    elif "capsule" in cover:
        c = cover["capsule"]
        xyz, rpy, length = capsule_origin(c["p0"], c["p1"])
        geom = f'<capsule radius="{float(c["radius"])!r}" length="{float(length)!r}"/>'
    else:
        lo, hi = cover["box"]["min"], cover["box"]["max"]
        xyz, rpy = [(a + b) / 2 for a, b in zip(lo, hi)], [0.0, 0.0, 0.0]
        geom = f'<box size="{fmt([b - a for a, b in zip(lo, hi)])}"/>'
    return shape_link_xml(name, xyz, rpy, geom)


# The URI prefix of the meshes embedded in the library (robot::builtin).
BUILTIN_MESH_SCHEME = "kinplan://builtin/"


def covers_of(robot):
    """The shapes fit_covers.py fitted around the real robot's collision
    meshes (example-robot-data, the meshes MoveIt plans with): one convex
    shape per link holding every vertex of the link's mesh, so a state the
    built-in model finds free is free for the real arm."""
    with open(os.path.join(OUT, f"{robot}_covers.json")) as f:
        return json.load(f)["covers"]


def with_covers(text, covers, links):
    """`text` with the `<link>` element of every name in `links` replaced by its cover."""
    for name in links:
        start = text.index(f'  <link name="{name}"')
        end = text.index("</link>\n", start) + len("</link>\n")
        text = text[:start] + cover_link_xml(name, covers[name]) + text[end:]
    return text


PANDA_ARM_LINKS = ["base_link"] + [f"link_{i}" for i in range(1, 8)]

# The pairs MoveIt's Panda configuration (panda_moveit_config, the SRDF
# MotionBenchMaker plans with) disables as in contact at the default pose on the
# real meshes: designed contacts, which the built-in model inherits (its own
# shapes are larger than the meshes, so its own default pose says nothing).
# example-robot-data's SRDF also disables link_5 against link_7 and the hand;
# those meshes do meet when the hand folds back, so they stay checked.
PANDA_DEFAULT_PAIRS = [("panda_leftfinger", "panda_rightfinger")]


def panda_srdf(name, links):
    """A MoveIt SRDF holding the built-in's designed contacts."""
    out = f'<?xml version="1.0"?>\n<!-- {name}: the pairs MoveIt\'s Panda configuration (panda_moveit_config) disables as in contact at the default pose (generate.py) -->\n'
    out += f'<robot name="{name}">\n'
    for a, b in PANDA_DEFAULT_PAIRS:
        if a in links and b in links:
            out += f'  <disable_collisions link1="{a}" link2="{b}" reason="Default"/>\n'
    out += "</robot>\n"
    with open(os.path.join(OUT, f"{name}.srdf"), "w") as f:
        f.write(out)


def fitted(name, robot, links):
    """The built-in `name`'s links get the shapes fitted around the real meshes."""
    path = os.path.join(OUT, f"{name}.urdf")
    with open(path) as f:
        text = f.read()
    text = with_covers(text, covers_of(robot), links)
    text = text.replace(" -->", f"; collision shapes hold the real meshes ({robot}_covers.json) -->", 1)
    with open(path, "w") as f:
        f.write(text)


def panda_hand():
    """franka_panda plus the Franka Hand: `panda_hand` fixed to the flange,
    turned -45 deg about z (as Franka mounts it), and two prismatic fingers
    0.0584 m above the hand frame, opening along +y / -y (0 to 0.04 m each).
    The hand (a polytope) and each finger (a box) hold their real meshes
    (panda_covers.json), as the arm's links do.
    A tool-centre frame `panda_hand_tcp` sits 0.1034 m along the hand's z."""
    with open(os.path.join(OUT, "franka_panda.urdf")) as f:
        text = f.read()
    covers = covers_of("panda")
    extra = cover_link_xml("panda_hand", covers["panda_hand"])
    extra += cover_link_xml("panda_leftfinger", covers["panda_leftfinger"])
    extra += cover_link_xml("panda_rightfinger", covers["panda_rightfinger"])
    extra += '  <link name="panda_hand_tcp"/>\n'
    extra += joint_xml("flange-panda_hand", "fixed", "flange", "panda_hand", [0, 0, 0], [0, 0, -math.pi / 4])
    extra += joint_xml("panda_hand-panda_hand_tcp", "fixed", "panda_hand", "panda_hand_tcp", [0, 0, 0.1034], [0, 0, 0])
    extra += joint_xml("panda_finger_joint1", "prismatic", "panda_hand", "panda_leftfinger",
                       [0, 0, 0.0584], [0, 0, 0], [0, 1, 0], (0.0, 0.04, 0.2))
    extra += joint_xml("panda_finger_joint2", "prismatic", "panda_hand", "panda_rightfinger",
                       [0, 0, 0.0584], [0, 0, 0], [0, -1, 0], (0.0, 0.04, 0.2))
    text = text.replace('<robot name="franka_panda">', '<robot name="franka_panda_hand">')
    text = text.replace("-->", "+ Franka Hand (panda_hand, two fingers; see generate.py panda_hand) -->", 1)
    text = text.replace("</robot>\n", extra + "</robot>\n")
    with open(os.path.join(OUT, "franka_panda_hand.urdf"), "w") as f:
        f.write(text)


def main():
    os.makedirs(OUT, exist_ok=True)
    kuka_signs = [-1, 1, 1, -1, 1, -1]
    industrial(
        "kuka_kr210_r2700_extra",
        "KUKA KR 210 R2700 extra: d1 675, a1 350, a2 1150, a3 -41 (z offset), d4 1200, d6 215 mm; "
        "A1 about -z, A4/A6 about -x as on the KUKA controller",
        675, 350, 1150, -41, 1200, 215, kuka_signs, False,
        [(-185, 185), (-140, -5), (-120, 155), (-350, 350), (-125, 125), (-350, 350)],
        [123, 115, 112, 179, 172, 219],
        [0.25, 0.2, 0.17, 0.14, 0.1, 0.08],
    )
    industrial(
        "kuka_kr120_r2500_pro",
        "KUKA KR 120 R2500 pro: d1 675, a1 350, a2 1150, a3 -41 (z offset), d4 1000, d6 215 mm; "
        "A1 about -z, A4/A6 about -x; speeds of A4-A6 unverified",
        675, 350, 1150, -41, 1000, 215, kuka_signs, False,
        [(-185, 185), (-155, 35), (-130, 154), (-350, 350), (-130, 130), (-350, 350)],
        [156, 156, 156, 330, 330, 615],
        [0.25, 0.2, 0.17, 0.14, 0.1, 0.08],
    )
    industrial(
        "abb_irb4600_60_205",
        "ABB IRB 4600-60/2.05: d1 495, a1 175, a2 900, a3 175, d4 960, d6 135 mm",
        495, 175, 900, 175, 960, 135, [1] * 6, True,
        [(-180, 180), (-90, 150), (-180, 75), (-400, 400), (-125, 120), (-400, 400)],
        [175, 175, 175, 250, 250, 360],
        [0.25, 0.2, 0.15, 0.12, 0.09, 0.07],
    )
    standard_dh(
        "ur5",
        "Universal Robots UR5, standard DH: d1 89.159, a2 -425, a3 -392.25, d4 109.15, d5 94.65, d6 82.3 mm",
        [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
        [0, -0.425, -0.39225, 0, 0, 0],
        [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0],
        [(-360, 360)] * 6, [180] * 6,
        [0.075, 0.06, 0.05, 0.045, 0.045, 0.04],
    )
    fitted("ur5", "ur5", ["base_link"] + [f"link_{i}" for i in range(1, 7)])
    r2d = math.degrees
    craig_dh(
        "franka_panda",
        "Franka Emika Panda, Craig DH: a 0 0 0 82.5 -82.5 0 88, d 333 0 316 0 384 0 0, flange 107 mm",
        [0.333, 0, 0.316, 0, 0.384, 0, 0],
        [0, 0, 0, 0.0825, -0.0825, 0, 0.088],
        [0, -math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2, math.pi / 2, math.pi / 2],
        0.107,
        [(r2d(-2.8973), r2d(2.8973)), (r2d(-1.7628), r2d(1.7628)), (r2d(-2.8973), r2d(2.8973)),
         (r2d(-3.0718), r2d(-0.0698)), (r2d(-2.8973), r2d(2.8973)), (r2d(-0.0175), r2d(3.7525)),
         (r2d(-2.8973), r2d(2.8973))],
        [r2d(2.175)] * 4 + [r2d(2.61)] * 3,
        [0.09, 0.09, 0.08, 0.08, 0.07, 0.06, 0.05],
    )
    fitted("franka_panda", "panda", PANDA_ARM_LINKS)
    panda_hand()
    panda_srdf("franka_panda", PANDA_ARM_LINKS)
    panda_srdf("franka_panda_hand", PANDA_ARM_LINKS + ["panda_hand", "panda_leftfinger", "panda_rightfinger"])
    standard_dh(
        "kuka_lbr_iiwa14_r820",
        "KUKA LBR iiwa 14 R820, standard DH: d1 360, d3 420, d5 400, d7 81 mm, "
        "alpha -90 90 90 -90 -90 90 0 deg",
        [0.36, 0, 0.42, 0, 0.4, 0, 0.081],
        [0] * 7,
        [-math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, math.pi / 2, 0],
        [(-170, 170), (-120, 120), (-170, 170), (-120, 120), (-170, 170), (-120, 120), (-175, 175)],
        [85, 85, 100, 75, 130, 135, 135],
        [0.1, 0.1, 0.09, 0.09, 0.08, 0.07, 0.05],
    )
    for n in range(2, 11):
        length = 1.0 / n
        joints = [([length if i else 0, 0, 0], [0, 0, 0], [0, 0, 1], lim(-180, 180, 180)) for i in range(n)]
        write_robot(
            f"planar_{n}",
            f"Planar manipulator: {n} revolute joints about z, equal links of {length:.6g} m, reach 1 m",
            joints, [("tool0", [length, 0, 0], [0, 0, 0])], [0.02] * n, 0,
        )


if __name__ == "__main__":
    main()
