"""kinplan.viz against a real server: recordings are written headless to
.rrd files and read back with Rerun's chunk reader; what they hold is
checked against the service (FK of the plan's states, octree_info's counts,
the views' poses). Skipped without rerun-sdk (the optional extra
``kinplan[viz]``)."""
import collections

import numpy as np
import pytest

import kinplan

rr = pytest.importorskip("rerun")
viz = pytest.importorskip("kinplan.viz")
from rerun.chunk import RrdReader  # noqa: E402

START = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
GOAL = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])


@pytest.fixture(scope="module")
def c(server_address):
    with kinplan.Client(server_address, timeout=30) as client:
        yield client


def read(path):
    """{entity: [record batches]} of the recording's chunks."""
    out = collections.defaultdict(list)
    for chunk in RrdReader(str(path)).stream():
        out[chunk.entity_path].append(chunk.to_record_batch())
    return out


def rows(batches, component, timeline=None):
    """(time, value) of every row holding `component` on `timeline`, in time
    order (durations in seconds); `timeline` None: every row, time None."""
    out = []
    for b in batches:
        names = b.schema.names
        if component not in names or (timeline is not None and timeline not in names):
            continue
        values = b.column(names.index(component)).to_pylist()
        times = b.column(names.index(timeline)).to_pylist() if timeline in names else [None] * len(values)
        for t, v in zip(times, values):
            if v is not None:
                if hasattr(t, "total_seconds"):
                    t = t.total_seconds()
                elif isinstance(t, int) and timeline.endswith("time"):
                    t = t * 1e-9
                out.append((t, v))
    return sorted(out, key=lambda tv: (tv[0] is not None, tv[0] or 0))


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def transforms(batches, timeline):
    """(time, 4x4) of an entity's Transform3D rows."""
    tr = rows(batches, "Transform3D:translation", timeline)
    qu = rows(batches, "Transform3D:quaternion", timeline)
    assert len(tr) == len(qu)
    out = []
    for (t, p), (_, q) in zip(tr, qu):
        T = np.eye(4)
        T[:3, :3] = quat_matrix(q[0])
        T[:3, 3] = p[0]
        out.append((t, T))
    return out


def ball_scene(ur5):
    centre = ur5.fk((START + GOAL) / 2)[:3, 3]
    return [kinplan.Sphere(0.12, centre, id="ball"), kinplan.Box((2, 2, 0.02), [0, 0, -0.3], id="floor")]


def test_importing_kinplan_does_not_import_rerun():
    import subprocess
    import sys

    code = "import sys, kinplan; assert 'rerun' not in sys.modules and 'kinplan.viz' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_a_plan_recording_holds_the_links_where_kinplans_fk_puts_them(c, tmp_path):
    ur5 = c.robot("ur5")
    scene = ball_scene(ur5)
    plan = ur5.plan(START, GOAL, algorithm="stomp", scene=scene, seed=1)
    assert plan.success
    path = tmp_path / "plan.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.plan(ur5, plan, scene=scene)
    data = read(path)
    links = ur5.describe().link_names
    for name in links:
        got = transforms(data[f"/world/robot/{name}"], "plan_time")
        assert len(got) == len(plan.q)
        for (t, T), ti in zip(got, plan.t):
            assert t == pytest.approx(ti, abs=1e-9)
    # every waypoint: the recorded link poses are the service's FK of the state at that time
    by_link = {name: transforms(data[f"/world/robot/{name}"], "plan_time") for name in links}
    for k, q in enumerate(plan.q):
        _, fk = ur5.fk(q, links=True)
        for name in links:
            np.testing.assert_allclose(by_link[name][k][1], fk[name], atol=1e-6)
    # the collision bodies are there (capsules), static; the scene and the plots too
    assert rows(data["/world/robot/link_2/collision_0"], "Capsules3D:radii")
    assert rows(data["/world/scene/ball"], "Ellipsoids3D:half_sizes")[0][1] == [pytest.approx([0.12] * 3)]
    assert len(rows(data["/plots/plan/clearance"], "Scalars:scalars", "plan_time")) == len(plan.q)
    strip = rows(data["/world/plan/tool_path"], "LineStrips3D:strips")[0][1][0]
    np.testing.assert_allclose(strip[0], ur5.fk(START)[:3, 3], atol=1e-6)
    np.testing.assert_allclose(strip[-1], ur5.fk(GOAL)[:3, 3], atol=1e-6)


def test_the_built_in_pandas_meshes_are_drawn(c, tmp_path):
    panda = c.robot("franka_panda")
    path = tmp_path / "panda.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.robot(panda, np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0]))
    data = read(path)
    # link_5's polytope: the service's vertices, placed in the link frame (its origin is the identity)
    link = next(l for l in panda.describe().raw.links if l.name == "link_5")
    sent = np.array([[v.x, v.y, v.z] for v in link.collision[0].mesh.vertices])
    drawn = np.array(rows(data["/world/robot/link_5/collision_0"], "Mesh3D:vertex_positions")[0][1])
    assert len(sent) >= 4
    np.testing.assert_allclose(drawn, sent, atol=1e-6)


def test_a_colliding_plan_turns_links_red_and_ccstomp_shows_its_tube(c, tmp_path):
    ur5 = c.robot("ur5")
    scene = ball_scene(ur5)
    q = np.linspace(START, GOAL, 20)  # straight through the ball
    checks = ur5.check(q, scene)
    assert not checks.valid.all()
    plan = kinplan.Plan(status="NO_VALID_TRAJECTORY", message="", q=q, t=np.linspace(0, 1, 20), valid=False,
                        cost_history=np.zeros(0), deviation=np.column_stack([np.linspace(0, 0.3, 20), np.zeros(20)]),
                        violates_tolerance=False, scores={}, colliding=[], goal=GOAL, iterations=0, duration=1.0,
                        timings={})
    path = tmp_path / "collide.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.plan(ur5, plan, scene=scene, translation_tolerance=0.25)
    data = read(path)
    red = [k for k, pairs in enumerate(checks.colliding) if any(p.startswith("link_") for p in pairs)]
    assert red
    colored = {name.split("/")[3] for name, batches in data.items()
               if name.startswith("/world/robot/") and rows(batches, "Capsules3D:colors", "plan_time")}
    hit = {p.split(":")[0] for k in red for p in checks.colliding[k]}
    assert hit <= colored
    tube = data["/world/plan/tolerance_tube"]
    assert rows(tube, "Capsules3D:radii")[0][1] == [pytest.approx(0.25)]
    assert len(rows(data["/world/plan/invalid_waypoints"], "Points3D:positions")[0][1]) == int((~checks.valid).sum())


def test_an_octree_recording_counts_what_octree_info_reports(c, tmp_path):
    rng = np.random.default_rng(3)
    wall = np.column_stack([np.full(2000, 2.0), rng.uniform(-1, 1, (2000, 2))])
    tree = c.insert_scan(None, wall, origin=[0, 0, 0], resolution=0.1)
    info = c.octree_info(tree)
    # cell-aligned, the wall inside: no occupied cell touches its faces
    region = (np.array([0.0, -1.5, -1.5]), np.array([2.5, 1.5, 1.5]))
    path = tmp_path / "octree.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        whole = rec.octree(tree, path="world/whole", static=True)
        part = rec.octree(tree, region, path="world/part", static=True)
    data = read(path)
    occupied = rows(data["/world/whole/occupied"], "Boxes3D:half_sizes")[0][1]
    assert len(occupied) == whole["occupied"] == info["occupied_leaves"]
    assert len(rows(data["/world/whole/free"], "Boxes3D:half_sizes")[0][1]) == info["free_leaves"]
    assert sum(8 * np.prod(h) for h in occupied) == pytest.approx(info["occupied_volume"], rel=1e-5)
    in_box = c.octree_info(tree, box=region)
    volumes = {s: sum(8 * np.prod(h) for h in rows(data[f"/world/part/{s}"], "Boxes3D:half_sizes")[0][1])
               for s in ("occupied", "free", "unknown")}
    assert volumes["occupied"] == pytest.approx(in_box["occupied_volume"], rel=1e-5)
    assert sum(volumes.values()) == pytest.approx(np.prod(region[1] - region[0]), rel=1e-5)
    assert part["unknown"] > 0 and part["occupied"] == whole["occupied"]
    colors = {s: rows(data[f"/world/part/{s}"], "Boxes3D:colors")[0][1] for s in ("occupied", "free", "unknown")}
    assert len({tuple(v) for v in colors.values()}) == 3  # one colour per state


def test_view_frusta_sit_at_the_candidates_poses(c, tmp_path):
    rng = np.random.default_rng(4)
    wall = np.column_stack([np.full(1500, 2.0), rng.uniform(-1, 1, (1500, 2))])
    tree = c.insert_scan(None, wall, origin=[0, 0, 0], resolution=0.1)
    views = c.next_best_view(tree, camera_pose=np.eye(4), weights=(1, 0.25, 0.1), max_results=5)
    assert len(views) >= 2
    path = tmp_path / "views.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.views(views)
    data = read(path)
    for k, T in enumerate(views.poses):
        (_, got), = transforms(data[f"/world/views/{k}"], "log_time")
        np.testing.assert_allclose(got, T, atol=1e-6)
        fov = rows(data[f"/world/views/{k}"], "Pinhole:image_from_camera")
        assert fov
    colors = [rows(data[f"/world/views/{k}"], "Pinhole:color")[0][1][0] for k in range(len(views))]
    assert colors[0] != colors[-1]  # the best and the worst differ


def test_an_exploration_recording_follows_the_run(c, tmp_path):
    from test_explore import START as X_START, scene as x_scene

    irb = c.robot("abb_irb4600_60_205")
    region = ([1.4, -1.2, -0.29], [3.2, 1.2, 1.0])
    *steps, summary = c.explore(irb, start=X_START, scene=x_scene(), region=region, resolution=0.2,
                                pixel_stride=8, known_ratio=1.0, max_iterations=2, seed=5)
    path = tmp_path / "explore.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.scene(x_scene())
        rec.explore([*steps, summary], irb, region=region)
    data = read(path)
    ratios = rows(data["/plots/known_ratio"], "Scalars:scalars", "iteration")
    assert [r[1][0] for r in ratios] == pytest.approx([summary.initial_known_ratio] + [s.known_ratio for s in steps])
    moved = [s for s in steps if len(s.trajectory)]
    assert moved
    for name in ("link_3", "tool0"):
        got = transforms(data[f"/world/robot/{name}"], "explore_time")
        assert len(got) == sum(len(s.trajectory) for s in moved)
        _, fk = irb.fk(moved[-1].trajectory[-1], links=True)
        np.testing.assert_allclose(got[-1][1], fk[name], atol=1e-6)
    views = transforms(data["/world/explore/view"], "iteration")
    np.testing.assert_allclose(views[-1][1], [s.view for s in steps if s.view is not None][-1], atol=1e-6)
    occupied = rows(data["/world/octree/occupied"], "Boxes3D:half_sizes", "iteration")
    assert occupied[-1][0] == summary.iterations and len(occupied[-1][1]) > 0


MESHY = """<?xml version="1.0"?>
<robot name="meshy">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.05"/></geometry></visual></link>
  <link name="l1"><visual><geometry><mesh filename="link.stl"/></geometry></visual>
    <collision><origin xyz="0 0 0.2"/><geometry><capsule radius="0.04" length="0.32"/></geometry></collision></link>
  <link name="l2"><visual><geometry><mesh filename="link.stl"/></geometry></visual></link>
  <link name="tool"/>
  <link name="camera"><visual><geometry><box size="0.05 0.05 0.05"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.05"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0 0 0.4"/></joint>
  <joint name="j4" type="fixed"><parent link="l1"/><child link="camera"/><origin xyz="0.1 0 0.2"/></joint>
</robot>"""


def write_stl_box(path, sx, sy, sz):
    """A binary STL box standing on z = 0."""
    import struct

    v = [(x * sx / 2, y * sy / 2, (z + 1) * sz / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
             (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v[i]) for i in f) + b"\0\0"
    path.write_bytes(bytes(out))


def test_a_urdf_with_meshes_is_drawn_by_rerun_and_posed_by_kinplans_fk(c, tmp_path):
    write_stl_box(tmp_path / "link.stl", 0.08, 0.08, 0.4)
    urdf = tmp_path / "meshy.urdf"
    urdf.write_text(MESHY)
    robot = c.robot(urdf=MESHY, base_link="base", tip_link="tool")
    q = np.linspace([0.0, 0.0], [1.5, 1.0], 12)
    path = tmp_path / "urdf.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        rec.robot(robot, urdf_file=str(urdf))
        rec.plan(robot, kinplan.Plan(status="SUCCEEDED", message="", q=q, t=np.linspace(0, 2, 12), valid=True,
                                     cost_history=np.zeros(0), deviation=np.zeros((0, 2)), violates_tolerance=False,
                                     scores={}, colliding=[], goal=q[-1], iterations=0, duration=2.0, timings={}))
    data = read(path)
    meshes = sorted(e for e, b in data.items() if rows(b, "Asset3D:blob"))
    # l1's and l2's visual mesh, read from link.stl by Rerun's loader, under the link entities
    assert len(meshes) == 2 and meshes[0].startswith("/world/robot/l1/urdf/") and meshes[1].startswith("/world/robot/l2/")
    for name in ("l1", "l2", "tool"):
        got = transforms(data[f"/world/robot/{name}"], "plan_time")
        assert len(got) == len(q)
        for (t, T), qk in zip(got, q):
            np.testing.assert_allclose(T, robot.fk(qk, links=True)[1][name], atol=1e-6)
    # the link off the chain hangs from its parent link by its URDF joint, statically
    (_, T), = transforms(data["/world/robot/l1/camera"], None)
    np.testing.assert_allclose(T[:3, 3], [0.1, 0, 0.2], atol=1e-7)
    assert rows(data["/world/robot/l1/camera/urdf/meshy/visual_geometries/camera/visual_0"], "Boxes3D:half_sizes")


def test_stomp_iterations_are_on_their_own_timeline(c, tmp_path):
    ur5 = c.robot("ur5")
    scene = ball_scene(ur5)
    frames = list(ur5.plan_stream(START, GOAL, scene=scene, seed=1,
                                  stomp={"straight_line_start": True, "iterations_after_valid": 2}))
    trajectories = frames[:-1]
    assert isinstance(frames[-1], kinplan.Plan) and len(trajectories) >= 2
    path = tmp_path / "stomp.rrd"
    with viz.Recording("test", save=str(path)) as rec:
        plan = rec.plan_iterations(ur5, frames, scene=scene)
    assert plan is frames[-1]
    data = read(path)
    strips = rows(data["/world/stomp/tool_path"], "LineStrips3D:strips", "stomp_iteration")
    assert [k for k, _ in strips] == list(range(len(trajectories)))
    for (k, strip), q in zip(strips, trajectories):
        np.testing.assert_allclose(strip[0], ur5.fk_batch(q)[:, :3, 3], atol=1e-6)
    got = transforms(data["/world/robot/link_3"], "stomp_iteration")
    for (k, T), q in zip(got, trajectories):
        np.testing.assert_allclose(T, ur5.fk(q[len(q) // 2], links=True)[1]["link_3"], atol=1e-6)
    assert len(rows(data["/plots/stomp/cost"], "Scalars:scalars", "stomp_iteration")) == len(plan.cost_history)
