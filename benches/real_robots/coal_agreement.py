#!/usr/bin/env python3
"""kinplan's robot-vs-box verdicts on example-robot-data's arms, meshes included,
against pinocchio + coal (buildGeomFromUrdf(model, urdf, COLLISION, package_dirs):
every collision mesh as its exact triangles, a BVHModelOBBRSS).

Per robot: load it in kinplan (c.robot(urdf=path, package_dirs=[share])) and in
pinocchio; FK of the chain tip on random states; then `--pairs` random pairs
(state within kinplan's joint limits, one box of 2-10 cm sides with a random
orientation placed uniformly in the world AABB, grown by 6 cm (--grow), of a randomly
chosen collision geometry of the robot). Joints not on kinplan's chain are held
at 0 clamped into their limits on the pinocchio side, as kinplan does.

Verdicts: kinplan says "collides" when a `.colliding` entry of CheckState names
the box (entries are "link:box"; self-collision entries are ignored); coal says
"collides" when pinocchio.computeCollisions finds any (robot geometry, box)
pair in contact (only those pairs are registered: no self-collision).

coal checks a mesh as its triangles, so a box wholly inside a link is "free" for
it; such pairs are counted (box centre inside a watertight mesh, by trimesh) and
the refusal rate is given with and without them. A refusal is also checked
against coal's own convex hull of each mesh (qhull): one that touches no hull is
not explained by a convex-hull cover (kinplan fits a polytope of at most 20
faces around a hull of more, which refuses a little more) and is listed in the
JSON.

Times: coal = one pinocchio.computeCollisions call (FK, geometry placements,
narrow phase, stop at first contact), C++ from Python; kinplan = one CheckState
round trip over loopback gRPC (each pair has its own scene, so one call per
pair), and, for reference, the per-state cost of one batched call of 1000
states against a single box.

Run by hand (not in CI); see README.md beside this file.
"""
import argparse
import io
import json
import os
import re
import sys
import time

import numpy as np
import pinocchio as pin
import coal

import kinplan

# name, URDF under example-robot-data/robots, kinplan base_link, tip_link ("" = the server's default)
ROBOTS = [
    ("ur5", "ur_description/urdf/ur5_robot.urdf", "", "tool0"),
    ("ur10", "ur_description/urdf/ur10_robot.urdf", "", "tool0"),
    ("panda", "panda_description/urdf/panda.urdf", "", "panda_hand"),
    ("xarm7", "xarm_description/urdf/xarm7.urdf", "", "link_eef"),
    ("kinova_gen2", "kinova_description/robots/kinova.urdf", "", "j2s6s200_end_effector"),
    ("z1", "z1_description/urdf/z1.urdf", "", "gripperStator"),
    ("baxter", "baxter_description/urdf/baxter.urdf", "", "right_gripper"),
]


def share_dir():
    """cmeel.prefix/share (the package dir for package://example-robot-data/...)."""
    here = os.path.dirname(pin.__file__)  # cmeel.prefix/lib/pythonX.Y/site-packages/pinocchio
    share = os.path.normpath(os.path.join(here, "..", "..", "..", "..", "share"))
    if not os.path.isdir(os.path.join(share, "example-robot-data", "robots")):
        sys.exit(f"example-robot-data not found under {share}: pip install example-robot-data")
    return share


def se3_of(T):
    return pin.SE3(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


def random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return pin.Quaternion(q[3], q[0], q[1], q[2]).toRotationMatrix()


def collision_mesh_uris(urdf_text):
    return sorted({m for block in re.findall(r"<collision>.*?</collision>", urdf_text, flags=re.S)
                   for m in re.findall(r'<mesh[^>]*filename="([^"]+)"', block)})


def mesh_path(uri, urdf_path, share):
    if uri.startswith("package://"):
        return os.path.join(share, uri[len("package://"):])
    if uri.startswith("file://"):
        return uri[len("file://"):]
    return os.path.join(os.path.dirname(urdf_path), uri)


def rewritten_meshes(urdf_text, urdf_path, share, convert_dae, drop_degenerate):
    """Client-side mesh repairs with trimesh: COLLADA collision meshes converted
    to binary STL (`convert_dae`), and/or STL meshes with their zero-area
    triangles (area <= 1e-11 in the file's units, kinplan refuses <= 1e-12 m²)
    dropped (`drop_degenerate`). Returns the URDF with the repaired meshes'
    URIs renamed, {new uri: STL bytes} and a list of what was done."""
    import trimesh

    meshes, notes, text = {}, [], urdf_text
    for uri in collision_mesh_uris(urdf_text):
        ext = uri.rsplit(".", 1)[-1].lower()
        if not ((convert_dae and ext == "dae") or (drop_degenerate and ext == "stl")):
            continue
        mesh = trimesh.load(mesh_path(uri, urdf_path, share), force="mesh")
        note = "converted DAE->STL" if ext == "dae" else "re-exported"
        if drop_degenerate:
            keep = mesh.area_faces > 1e-11
            if not keep.all():
                note += f", dropped {int((~keep).sum())} of {len(keep)} zero-area triangles"
                mesh.update_faces(keep)
            elif ext == "stl":
                continue
        buf = io.BytesIO()
        mesh.export(buf, file_type="stl")
        new = uri.rsplit(".", 1)[0] + ".client.stl"
        meshes[new] = buf.getvalue()
        notes.append(f"{uri}: {note}")
        text = text.replace(f'filename="{uri}"', f'filename="{new}"')
    return text, meshes, notes


def error_file(message, urdf_text):
    """The mesh file a kinplan error names (by URI, or by links[NAME].collision[K])."""
    m = re.search(r"meshes\[([^\]]+)\]", message)
    if m:
        return m.group(1)
    m = re.search(r"links\[([^\]]+)\]\.collision\[(\d+)\]", message)
    if m:
        link = re.search(r'<link\s+name="%s".*?</link>' % re.escape(m.group(1)), urdf_text, flags=re.S)
        if link:
            blocks = re.findall(r"<collision>.*?</collision>", link.group(0), flags=re.S)
            k = int(m.group(2))
            if k < len(blocks):
                f = re.search(r'filename="([^"]+)"', blocks[k])
                return f.group(1) if f else "(a primitive)"
    return ""


class PinSide:
    def __init__(self, urdf, share, chain_joints, base, tip):
        self.model = pin.buildModelFromUrdf(urdf)
        self.geom = pin.buildGeomFromUrdf(self.model, urdf, pin.COLLISION, package_dirs=[share])
        m = self.model
        self.n_robot = len(self.geom.geometryObjects)
        self.box_half = np.array([0.01, 0.01, 0.01])
        box = pin.GeometryObject("box", 0, 0, pin.SE3.Identity(), coal.Box(0.02, 0.02, 0.02))
        self.box_id = self.geom.addGeometryObject(box)
        for i in range(self.n_robot):
            self.geom.addCollisionPair(pin.CollisionPair(i, self.box_id))
        self.data = m.createData()
        self.gdata = pin.GeometryData(self.geom)
        self.box_geom = self.geom.geometryObjects[self.box_id].geometry
        # the configuration: chain joints from kinplan's q, the rest 0 clamped into limits
        self.chain_idx = []
        for name in chain_joints:
            if not m.existJointName(name):
                raise RuntimeError(f"pinocchio has no joint {name}")
            self.chain_idx.append(m.getJointId(name))
        self.q_rest = pin.neutral(m)
        for jid in range(1, m.njoints):
            j = m.joints[jid]
            if j.nq == 1:
                lo, hi = m.lowerPositionLimit[j.idx_q], m.upperPositionLimit[j.idx_q]
                self.q_rest[j.idx_q] = min(max(0.0, lo), hi)
        self.base = m.getFrameId(base, pin.BODY) if base else 0
        self.tip = m.getFrameId(tip, pin.BODY)
        self.names = [g.name for g in self.geom.geometryObjects]
        for g in self.geom.geometryObjects[: self.n_robot]:
            g.geometry.computeLocalAABB()
        # each robot geometry's convex hull (meshes: qhull via coal; primitives: themselves),
        # to tell whether a refusal of a coal-free pair is explained by kinplan's hull cover
        self.hulls = []
        for g in self.geom.geometryObjects[: self.n_robot]:
            geo = g.geometry
            if isinstance(geo, coal.BVHModelBase):
                geo.buildConvexHull(True, "Qt")
                geo = geo.convex
            self.hulls.append(geo)
        # the meshes as closed solids (trimesh), for "is the box inside a link?": coal checks a
        # mesh as its surface triangles, so a box wholly inside a link touches none of them
        self.solids = {}
        for i, g in enumerate(self.geom.geometryObjects[: self.n_robot]):
            if isinstance(g.geometry, coal.BVHModelBase) and g.meshPath:
                try:
                    import trimesh

                    mesh = trimesh.load(g.meshPath, force="mesh")
                    mesh.apply_scale(np.asarray(g.meshScale))
                    self.solids[i] = mesh
                except Exception:  # noqa: BLE001 - the test is skipped for this mesh
                    pass
        self.open_meshes = [self.names[i] for i, m in self.solids.items() if not m.is_watertight]
        self.local_aabb = [
            (np.array(g.geometry.aabb_local.min_), np.array(g.geometry.aabb_local.max_))
            for g in self.geom.geometryObjects[: self.n_robot]
        ]

    def q(self, qk):
        q = self.q_rest.copy()
        for jid, v in zip(self.chain_idx, qk):
            j = self.model.joints[jid]
            if j.nq == 1:
                q[j.idx_q] = v
            else:  # continuous joint: (cos, sin)
                q[j.idx_q], q[j.idx_q + 1] = np.cos(v), np.sin(v)
        return q

    def fk(self, qk):
        pin.framesForwardKinematics(self.model, self.data, self.q(qk))
        T = (self.data.oMf[self.base].inverse() * self.data.oMf[self.tip]).homogeneous
        return T

    def placements(self, q):
        pin.updateGeometryPlacements(self.model, self.data, self.geom, self.gdata, q)
        return [self.gdata.oMg[i].homogeneous for i in range(self.n_robot)]

    def world_aabb(self, i, T):
        lo, hi = self.local_aabb[i]
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        w = corners @ T[:3, :3].T + T[:3, 3]
        return w.min(0), w.max(0)

    def set_box(self, size, T):
        self.box_geom.halfSide = np.asarray(size, dtype=float) / 2
        self.box_geom.computeLocalAABB()
        self.geom.geometryObjects[self.box_id].placement = se3_of(T)

    def collide(self, q, stop_first=True):
        return pin.computeCollisions(self.model, self.data, self.geom, self.gdata, q, stop_first)

    def colliding_geoms(self):
        out = []
        for k, res in enumerate(self.gdata.collisionResults):
            if res.isCollision():
                out.append(self.names[self.geom.collisionPairs[k].first])
        return out

    def hulls_collide(self):
        """Does the box (as last placed by collide) touch any robot geometry's convex hull?"""
        B = self.gdata.oMg[self.box_id]
        box_tf = coal.Transform3s(B.rotation, B.translation)
        box = coal.Box(*(2 * np.array(self.box_geom.halfSide)))
        for i in range(self.n_robot):
            M = self.gdata.oMg[i]
            req, res = coal.CollisionRequest(), coal.CollisionResult()
            if coal.collide(self.hulls[i], coal.Transform3s(M.rotation, M.translation), box, box_tf, req, res):
                return True
        return False

    def box_inside_solid(self):
        """Is the box's centre inside a closed (watertight) robot mesh? With no contact
        between the box and the mesh surface, the whole box then lies inside the link."""
        c = np.array(self.gdata.oMg[self.box_id].translation)
        for i, mesh in self.solids.items():
            if not mesh.is_watertight:
                continue
            M = self.gdata.oMg[i]
            local = M.rotation.T @ (c - M.translation)
            if mesh.contains([local])[0]:
                return True
        return False

    def collide_direct(self, q):
        """The same verdict by coal.collide per geometry (a cross-check of the
        computeCollisions set-up)."""
        pin.updateGeometryPlacements(self.model, self.data, self.geom, self.gdata, q)
        box_tf = coal.Transform3s(self.gdata.oMg[self.box_id].rotation, self.gdata.oMg[self.box_id].translation)
        box = coal.Box(*(2 * np.array(self.box_geom.halfSide)))
        for i in range(self.n_robot):
            M = self.gdata.oMg[i]
            req, res = coal.CollisionRequest(), coal.CollisionResult()
            if coal.collide(self.geom.geometryObjects[i].geometry, coal.Transform3s(M.rotation, M.translation),
                            box, box_tf, req, res):
                return True
        return False


def mesh_formats(urdf_path):
    text = open(urdf_path).read()
    exts = re.findall(r"<collision>.*?</collision>", text, flags=re.S)
    fmts = {}
    for block in exts:
        m = re.search(r'<mesh[^>]*filename="[^"]*\.(\w+)"', block)
        key = m.group(1).lower() if m else re.search(r'<geometry>\s*<(\w+)', block).group(1)
        fmts[key] = fmts.get(key, 0) + 1
    return fmts


def run_robot(c, name, rel, base, tip, share, args, rng):
    robots_dir = os.path.join(share, "example-robot-data", "robots")
    urdf = os.path.join(robots_dir, rel)
    row = {"robot": name, "urdf": rel, "collision_geometry": mesh_formats(urdf), "meshes_repaired_client_side": []}
    print(f"== {name}: {rel} collision geometry {row['collision_geometry']}", flush=True)
    text = open(urdf).read()

    def load(text, meshes):
        robot = c.robot(urdf=text if meshes else urdf, package_dirs=[share], meshes=meshes,
                        base_link=base, tip_link=tip)
        d = robot.describe()
        robot.check([np.clip(0, d.lower, d.upper)], [kinplan.Box((0.02,) * 3, [9, 9, 9], id="box")])
        return robot, d

    try:
        robot, d = load(text, {})
    except Exception as e:  # noqa: BLE001 - reported as is
        row["load_error"] = f"{type(e).__name__}: {e}"
        row["load_error_file"] = error_file(str(e), text)
        print("  kinplan refuses it:", row["load_error"], "| file:", row["load_error_file"], flush=True)
        # repair only what the error names, then try again (a repaired model may fail on the next thing)
        convert, drop, err = False, False, str(e)
        while True:
            if args.convert_dae and not convert and "COLLADA" in err:
                convert = True
            elif args.drop_degenerate and not drop and "degenerate" in err:
                drop = True
            else:
                return row
            text2, meshes, notes = rewritten_meshes(text, urdf, share, convert, drop)
            row["meshes_repaired_client_side"] = notes
            try:
                robot, d = load(text2, meshes)
                for n_ in notes:
                    print("  client-side (trimesh):", n_, flush=True)
                break
            except Exception as e2:  # noqa: BLE001
                err = f"{type(e2).__name__}: {e2}"
                row["load_error_repaired"] = err
                row["load_error_repaired_file"] = error_file(err, text2)
                print("  after client-side repair", notes, "still refused:", err, flush=True)
    row["chain"] = f"{d.base_link} -> {d.tip_link} ({d.dof} joints)"
    row["kinplan_links"] = len(d.link_names)
    print("  kinplan chain", row["chain"], flush=True)

    p = PinSide(urdf, share, d.joint_names, d.base_link, d.tip_link)
    row["coal_geometries"] = p.n_robot
    row["meshes_not_closed"] = p.open_meshes
    if p.open_meshes:
        print("  meshes not watertight (the inside test skips them):", p.open_meshes, flush=True)
    lower = np.where(np.isfinite(d.lower), d.lower, -np.pi)
    upper = np.where(np.isfinite(d.upper), d.upper, np.pi)

    # FK agreement
    qs = rng.uniform(lower, upper, (args.fk_states, d.dof))
    Ts = robot.fk_batch(qs)
    perr, rerr = 0.0, 0.0
    for q, T in zip(qs, Ts):
        P = p.fk(q)
        perr = max(perr, float(np.linalg.norm(P[:3, 3] - T[:3, 3])))
        rerr = max(rerr, float(np.linalg.norm(pin.log3(P[:3, :3].T @ T[:3, :3]))))
    row["fk_max_position_error_m"] = perr
    row["fk_max_rotation_error_rad"] = rerr
    print(f"  FK vs pinocchio over {len(qs)} states: max {perr:.2e} m, {rerr:.2e} rad", flush=True)

    # robot-vs-box pairs
    n = args.pairs
    counts = dict(pairs=0, coal_colliding=0, colliding_reported_free=0, free_refused=0,
                  free_refused_touching_coal_hull=0, free_refused_box_inside_closed_mesh=0, cross_check_mismatch=0)
    unexplained = []
    t_coal, t_kin = [], []
    misses = []
    for k in range(n):
        qk = rng.uniform(lower, upper)
        q = p.q(qk)
        Tg = p.placements(q)
        i = int(rng.integers(p.n_robot))
        lo, hi = p.world_aabb(i, Tg[i])
        centre = rng.uniform(lo - args.grow, hi + args.grow)
        size = rng.uniform(args.box_min, args.box_max, 3)
        T = np.eye(4)
        T[:3, :3] = random_rotation(rng)
        T[:3, 3] = centre
        p.set_box(size, T)
        t0 = time.perf_counter()
        coal_hit = bool(p.collide(q, True))
        t_coal.append(time.perf_counter() - t0)
        if k < args.cross_check and coal_hit != p.collide_direct(q):
            counts["cross_check_mismatch"] += 1
        t0 = time.perf_counter()
        ch = robot.check([qk], [kinplan.Box(tuple(size), T, id="box")], max_distance=args.max_distance)
        t_kin.append(time.perf_counter() - t0)
        kin_pairs = [e for e in ch.colliding[0] if "box" in e.split(":")]
        kin_hit = bool(kin_pairs)
        counts["pairs"] += 1
        counts["coal_colliding"] += coal_hit
        if coal_hit and not kin_hit:
            counts["colliding_reported_free"] += 1
            p.collide(q, False)
            misses.append({"robot": name, "q": qk.tolist(), "box_size": size.tolist(), "box_pose": T.tolist(),
                           "coal_colliding_geometries": p.colliding_geoms(), "kinplan_colliding": ch.colliding[0]})
        elif kin_hit and not coal_hit:
            counts["free_refused"] += 1
            if p.box_inside_solid():
                counts["free_refused_box_inside_closed_mesh"] += 1
            if p.hulls_collide():
                counts["free_refused_touching_coal_hull"] += 1
            else:
                unexplained.append({"robot": name, "q": qk.tolist(), "box_size": size.tolist(), "box_pose": T.tolist(),
                                    "kinplan_colliding": ch.colliding[0]})
    row.update(counts)
    free = counts["pairs"] - counts["coal_colliding"]
    row["free_refused_pct"] = 100.0 * counts["free_refused"] / free if free else float("nan")
    truly_free = free - counts["free_refused_box_inside_closed_mesh"]
    row["free_refused_pct_box_outside_meshes"] = (
        100.0 * (counts["free_refused"] - counts["free_refused_box_inside_closed_mesh"]) / truly_free
        if truly_free else float("nan"))
    row["coal_us_per_check"] = 1e6 * float(np.median(t_coal))
    row["kinplan_us_per_check_rpc"] = 1e6 * float(np.median(t_kin))

    # batched kinplan: 1000 states, one box (server-side cost per state plus one round trip)
    qs = rng.uniform(lower, upper, (1000, d.dof))
    box = kinplan.Box((0.05, 0.05, 0.05), p.placements(p.q(qs[0]))[p.n_robot - 1][:3, 3].tolist(), id="box")
    robot.check(qs[:10], [box], max_distance=args.max_distance)
    t0 = time.perf_counter()
    robot.check(qs, [box], max_distance=args.max_distance)
    row["kinplan_us_per_state_batched"] = 1e6 * (time.perf_counter() - t0) / len(qs)
    row["misses"] = misses[:20]
    row["free_refused_not_touching_coal_hull"] = unexplained[:20]
    print("  " + ", ".join(f"{k}={row[k]}" for k in counts), flush=True)
    print(f"  free refused {row['free_refused_pct']:.1f}% of coal-free pairs "
          f"({row['free_refused_pct_box_outside_meshes']:.1f}% of those with the box outside every closed mesh); median us per check: coal "
          f"{row['coal_us_per_check']:.1f}, kinplan rpc {row['kinplan_us_per_check_rpc']:.1f}, kinplan batched "
          f"{row['kinplan_us_per_state_batched']:.1f} per state", flush=True)
    for m in misses[:3]:
        print("  MISS:", json.dumps(m), flush=True)
    for m in unexplained[:3]:
        print("  REFUSED, free even for coal's convex hulls:", json.dumps(m), flush=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--target", help="a running kinplan server host:port (default: kinplan.LocalServer, KINPLAN_BIN)")
    ap.add_argument("--robots", nargs="*", default=[r[0] for r in ROBOTS])
    ap.add_argument("--pairs", type=int, default=10000)
    ap.add_argument("--fk-states", type=int, default=1000)
    ap.add_argument("--box-min", type=float, default=0.02)
    ap.add_argument("--box-max", type=float, default=0.10)
    ap.add_argument("--grow", type=float, default=0.06, help="m added around a geometry's AABB for the box centre")
    ap.add_argument("--max-distance", type=float, default=0.001, help="CheckState max_distance (m)")
    ap.add_argument("--cross-check", type=int, default=500,
                    help="pairs also checked by coal.collide per geometry (validates the pinocchio set-up)")
    ap.add_argument("--convert-dae", action="store_true",
                    help="when kinplan refuses a COLLADA mesh, retry with it converted to STL by trimesh (client side)")
    ap.add_argument("--drop-degenerate", action="store_true",
                    help="when kinplan refuses a zero-area triangle, retry with such triangles dropped by trimesh")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", default="coal_agreement.json")
    args = ap.parse_args()
    share = share_dir()
    rng = np.random.default_rng(args.seed)
    rows = []
    server = None
    if args.target:
        c = kinplan.Client(args.target, timeout=60)
    else:
        server = kinplan.LocalServer()
        server.__enter__()
        c = server.client()
        c.timeout = 60
    try:
        for name, rel, base, tip in ROBOTS:
            if name in args.robots:
                rows.append(run_robot(c, name, rel, base, tip, share, args, rng))
                with open(args.json, "w") as f:
                    json.dump({"args": vars(args), "pinocchio": pin.__version__, "coal": coal.__version__,
                               "rows": rows}, f, indent=1)
    finally:
        if server is not None:
            server.__exit__(None, None, None)
    print(f"\nwritten {args.json}")


if __name__ == "__main__":
    main()
