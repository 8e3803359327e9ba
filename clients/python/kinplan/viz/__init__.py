"""kinplan's visual layer on Rerun (``pip install 'kinplan[viz]'``, which
adds ``rerun-sdk``; the core client never imports it).

::

    import kinplan, kinplan.viz

    viz = kinplan.viz.Recording("demo", save="demo.rrd")   # or spawn=True, or serve=True (a browser)
    viz.robot(ur5, q0)                     # the robot's collision bodies, posed by kinplan's FK
    viz.scene(obstacles)                   # kinplan obstacles (or a ReferenceScene)
    viz.plan(ur5, plan, scene=obstacles)   # the arm moving on the "plan_time" timeline (plan.t),
                                           # tool path, collisions and clearance, CCSTOMP's tube
    viz.plan_iterations(ur5, ur5.plan_stream(q0, q1, scene=obstacles))   # STOMP iterations
    viz.octree(tree, region=(lo, hi))      # occupied / free / unknown boxes, coloured by state
    viz.views(views)                       # NBV candidates as camera frusta coloured by utility
    viz.explore(steps, irb, scene=cell)    # a whole exploration run on the "iteration" timeline
    viz.close()

Everything is drawn in the robot's base frame (the world frame of the
exploration calls), metres, z up, under ``world/``; plots go under
``plots/``. Every pose comes from the service (``fk(..., links=True)``,
``fk_batch``), so the picture shows kinplan's kinematics. Methods that call
the service add the seconds they spent waiting for it to
``Recording.service_seconds``.
"""
from __future__ import annotations

import importlib
import time
import urllib.parse
import uuid
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ..exploration_loop import ExploreStep, ExploreSummary, ReferenceScene
from ..octree import Octree, Views
from ..planning import Obstacle, Plan, scene_to_proto

try:
    rr: Any = importlib.import_module("rerun")
except ImportError as err:  # pragma: no cover - exercised without the extra
    raise ImportError("kinplan.viz needs rerun-sdk: pip install 'kinplan[viz]'") from err

#: Colours (RGBA) of the octree states and of the drawing.
COLORS: Dict[str, Tuple[int, int, int, int]] = {
    "occupied": (200, 80, 40, 255),
    "free": (60, 180, 90, 40),
    "unknown": (120, 120, 200, 70),
    "link": (170, 175, 185, 255),
    "collision": (230, 30, 30, 255),
    "obstacle": (110, 110, 110, 90),
    "tool_path": (30, 120, 230, 255),
    "tube": (250, 200, 40, 45),
    "region": (250, 200, 40, 255),
    "failed": (230, 30, 30, 255),
}

#: Kinect v2, the default camera of NextBestView and Explore (proto CameraModel).
KINECT = {"horizontal_fov": np.radians(70.6), "vertical_fov": np.radians(60.0), "near_range": 0.5,
          "far_range": 4.5}

Box3 = Tuple[Any, Any]


def quaternions(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (x, y, z, w) of rotation matrices (..., 3, 3)."""
    R = np.asarray(R, dtype=float)
    shape = R.shape[:-2]
    m = R.reshape(-1, 3, 3)
    t = np.trace(m, axis1=1, axis2=2)
    q = np.empty((len(m), 4))
    for k in range(len(m)):  # Shepperd's method: the largest of w, x, y, z first
        a = m[k]
        if t[k] > 0:
            s = 2.0 * np.sqrt(t[k] + 1.0)
            q[k] = ((a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s, s / 4)
        elif a[0, 0] > a[1, 1] and a[0, 0] > a[2, 2]:
            s = 2.0 * np.sqrt(1.0 + a[0, 0] - a[1, 1] - a[2, 2])
            q[k] = (s / 4, (a[0, 1] + a[1, 0]) / s, (a[0, 2] + a[2, 0]) / s, (a[2, 1] - a[1, 2]) / s)
        elif a[1, 1] > a[2, 2]:
            s = 2.0 * np.sqrt(1.0 + a[1, 1] - a[0, 0] - a[2, 2])
            q[k] = ((a[0, 1] + a[1, 0]) / s, s / 4, (a[1, 2] + a[2, 1]) / s, (a[0, 2] - a[2, 0]) / s)
        else:
            s = 2.0 * np.sqrt(1.0 + a[2, 2] - a[0, 0] - a[1, 1])
            q[k] = ((a[0, 2] + a[2, 0]) / s, (a[1, 2] + a[2, 1]) / s, s / 4, (a[1, 0] - a[0, 1]) / s)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q.reshape(shape + (4,))


def utility_colors(values: Any) -> np.ndarray:
    """RGBA (n x 4, uint8) for values: blue (lowest) -> green -> yellow (highest)."""
    v = np.asarray(values, dtype=float)
    if not len(v):
        return np.zeros((0, 4), dtype=np.uint8)
    span = float(np.ptp(v))
    x = (v - v.min()) / span if span > 0 else np.ones_like(v)
    anchors = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], dtype=float)
    pos = x * (len(anchors) - 1)
    i = np.minimum(pos.astype(int), len(anchors) - 2)
    f = (pos - i)[:, None]
    rgb = anchors[i] * (1 - f) + anchors[i + 1] * f
    return np.column_stack([rgb, np.full(len(v), 255)]).astype(np.uint8)


def _pose_matrix(p: Any) -> np.ndarray:
    """A proto Pose as a 4x4 matrix (identity when unset)."""
    from .._convert import pose_to_matrix

    return pose_to_matrix(p)


class Recording:
    """One Rerun recording of kinplan values. Give one way (Rerun's own modes):

    - ``save="run.rrd"``: write a file (open it with ``rerun run.rrd``),
    - ``spawn=True``: start a native viewer and stream to it,
    - ``serve=True``: serve a web viewer (``self.url``, ``web_port``, ``grpc_port``),
    - none: buffered in memory (``self.stream`` is the ``rerun.RecordingStream``
      for any other sink or your own logging).

    Use as a context manager, or call :meth:`close` to flush the data. With
    ``blueprint`` (default), :meth:`close` sends a layout: the 3-D view of
    ``world/`` (seen from ``eye`` = (position, target) when given, z up)
    beside one plot per quantity logged under ``plots/``."""

    def __init__(self, name: str = "kinplan", *, save: Optional[str] = None, spawn: bool = False,
                 serve: bool = False, web_port: Optional[int] = None, grpc_port: Optional[int] = None,
                 open_browser: bool = False, recording_id: Optional[str] = None, blueprint: bool = True,
                 eye: Optional[Tuple[Sequence[float], Sequence[float]]] = None):
        self.stream: Any = rr.RecordingStream(name, recording_id=recording_id or str(uuid.uuid4()))
        self.url: Optional[str] = None
        self.service_seconds = 0.0
        self._robots: Dict[str, Dict[str, Any]] = {}
        self._views_logged: Dict[str, int] = {}
        self._plots: List[str] = []
        self.blueprint = blueprint
        self.eye = eye
        if save is not None:
            self.stream.save(save)
        if spawn:
            self.stream.spawn()
        if serve:
            uri = self.stream.serve_grpc(grpc_port=grpc_port)
            rr.serve_web_viewer(web_port=web_port, open_browser=open_browser, connect_to=uri)
            self.url = f"http://localhost:{web_port or 9090}/?url={urllib.parse.quote(uri, safe='')}"
        self.stream.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)

    def __enter__(self) -> "Recording":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        """Sends the layout (with ``blueprint``), flushes everything logged
        and closes the sinks (a saved file is complete)."""
        if self.blueprint:
            self.stream.send_blueprint(self.layout())
        self.stream.flush()
        self.stream.disconnect()

    def layout(self) -> Any:
        """The default blueprint: the 3-D view of ``world/`` beside a
        column of plots, one per quantity logged under ``plots/``."""
        rrb = importlib.import_module("rerun.blueprint")
        eye = None
        if self.eye is not None:
            eye = rrb.EyeControls3D(position=self.eye[0], look_target=self.eye[1], eye_up=(0.0, 0.0, 1.0))
        world = rrb.Spatial3DView(origin="/world", name="world", eye_controls=eye)
        if not self._plots:
            return rrb.Blueprint(world, collapse_panels=False)
        plots = [rrb.TimeSeriesView(origin=f"/{p}", name=p.split("/", 1)[1]) for p in self._plots]
        return rrb.Blueprint(rrb.Horizontal(world, rrb.Vertical(*plots), column_shares=[3, 1]))

    def _plot(self, group: str) -> str:
        """Registers a plot (an entity path under ``plots/``) for the layout."""
        if group not in self._plots:
            self._plots.append(group)
        return group

    def _service(self, fn: Any, *args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            self.service_seconds += time.perf_counter() - t0

    # ---- the robot ------------------------------------------------------------------------------------------------

    def robot(self, robot: Any, q: Optional[Any] = None, *, path: str = "world/robot",
              color: Optional[Sequence[int]] = None, urdf_file: Optional[str] = None) -> None:
        """Draws ``robot``'s collision bodies (the capsules, spheres, boxes,
        cylinders and built-in meshes of ``robot.describe()``: kinplan's own
        geometry; a mesh file a URDF names is not read, and its link is drawn
        as its frame only)
        under ``path/<link>``; each link entity carries its pose. With
        ``urdf_file`` (the robot's URDF on disk, its mesh files where it
        names them), the URDF's visual and collision geometry instead, read
        by Rerun's URDF loader and put under ``path/<link>/urdf``: posed the
        same way, by kinplan's FK (a link off the chain hangs from its parent
        link by its URDF joint at 0). With ``q``, poses it there (at the
        current time of the recording)."""
        if path not in self._robots and urdf_file is not None:
            self._urdf_robot(robot, path, urdf_file)
        if path not in self._robots:
            d = self._service(robot.describe)
            shapes: Dict[str, List[Tuple[str, Any]]] = {}
            rgba = tuple(color) if color is not None else COLORS["link"]
            for link in d.raw.links:
                entries = shapes.setdefault(link.name, [])
                for k, g in enumerate(link.collision):
                    arch = _shape_archetype(g.WhichOneof("shape"), g, _pose_matrix(g.origin), rgba)
                    if arch is None:
                        continue
                    entity = f"{path}/{link.name}/collision_{k}"
                    self.stream.log(entity, arch, static=True)
                    entries.append((entity, type(arch)))
                self.stream.log(f"{path}/{link.name}", rr.TransformAxes3D(0.05), static=True)
            self._robots[path] = {"links": d.link_names, "shapes": shapes, "color": rgba, "colored": set()}
        if q is not None:
            self.pose(robot, q, path=path)

    def _urdf_robot(self, robot: Any, path: str, urdf_file: str) -> None:
        """The URDF's geometry by Rerun's loader, moved under the link
        entities (``path/<link>/urdf/...``) that kinplan's FK poses; a link
        off the chain hangs from its parent link by its URDF joint (at 0)."""
        d = self._service(robot.describe)
        tree = rr.urdf.UrdfTree.from_file_path(urdf_file)
        entity = {name: f"{path}/{name}" for name in d.link_names}
        pending = [j for j in tree.joints() if j.child_link not in entity]
        while pending:  # the links off the chain, parents first
            placed = [j for j in pending if j.parent_link in entity]
            if not placed:
                break  # links above the chain's base: not drawn
            for j in placed:
                entity[j.child_link] = f"{entity[j.parent_link]}/{j.child_link}"
                R = _rpy_matrix(*j.origin_rpy)
                self.stream.log(entity[j.child_link], rr.Transform3D(translation=j.origin_xyz,
                                                                     quaternion=quaternions(R)), static=True)
            pending = [j for j in pending if j not in placed]
        chunks = list(tree.stream(include_joint_transforms=False))
        frame_of: Dict[str, str] = {}
        for ch in chunks:
            names = ch.to_record_batch().schema.names
            if "CoordinateFrame:frame" in names:
                column = ch.to_record_batch().column(names.index("CoordinateFrame:frame"))
                frame_of[ch.entity_path] = column[0][0].as_py()
        moved = []
        for ch in chunks:
            link = frame_of.get(ch.entity_path)
            if link in entity and "CoordinateFrame:frame" not in ch.to_record_batch().schema.names:
                moved.append(ch.with_entity_path(f"/{entity[link]}/urdf{ch.entity_path}"))
        rr.send_chunks(moved, recording=self.stream)
        for name in d.link_names:
            self.stream.log(f"{path}/{name}", rr.TransformAxes3D(0.05), static=True)
        self._robots[path] = {"links": d.link_names, "shapes": {}, "color": COLORS["link"], "colored": set()}

    def pose(self, robot: Any, q: Any, *, path: str = "world/robot") -> Dict[str, np.ndarray]:
        """Poses the robot drawn at ``path`` at joints ``q`` (at the current
        time): each link's transform is kinplan's FK of ``q``. Returns the
        link poses (name -> 4x4)."""
        if path not in self._robots:
            self.robot(robot, path=path)
        _, links = self._service(robot.fk, q, links=True)
        for name, T in links.items():
            self.stream.log(f"{path}/{name}", rr.Transform3D(translation=T[:3, 3], quaternion=quaternions(T[:3, :3])))
        return dict(links)

    def _link_columns(self, robot: Any, qs: np.ndarray, path: str, indexes: List[Any]) -> List[Dict[str, np.ndarray]]:
        """Sends the link transforms of every row of ``qs`` at ``indexes``
        (TimeColumns), from kinplan's FK; returns the link poses per row."""
        if path not in self._robots:
            self.robot(robot, path=path)
        poses: List[Dict[str, np.ndarray]] = [self._service(robot.fk, q, links=True)[1] for q in qs]
        if not poses:
            return poses
        for name in poses[0]:
            T = np.stack([p[name] for p in poses])
            self.stream.send_columns(
                f"{path}/{name}", indexes=indexes,
                columns=rr.Transform3D.columns(translation=T[:, :3, 3], quaternion=quaternions(T[:, :3, :3])))
        return poses

    def _color_links(self, path: str, links: Iterable[str]) -> None:
        """Colours the named links red and the others back (at the current time)."""
        info = self._robots[path]
        red = set(links) & set(info["shapes"])
        for name in red ^ info["colored"]:
            rgba = COLORS["collision"] if name in red else info["color"]
            for entity, cls in info["shapes"][name]:
                self.stream.log(entity, cls.from_fields(colors=[rgba]))
        info["colored"] = red

    # ---- the scene ------------------------------------------------------------------------------------------------

    def scene(self, scene: Union[ReferenceScene, Sequence[Obstacle]], *, path: str = "world/scene",
              color: Optional[Sequence[int]] = None) -> None:
        """Draws obstacles (kinplan's Box, Sphere, Cylinder, Capsule, Mesh,
        OctreeObstacle or CollisionObject messages; a :class:`ReferenceScene`
        adds its region as an outline) statically under ``path/<id>``."""
        rgba = tuple(color) if color is not None else COLORS["obstacle"]
        objects = scene.obstacles if isinstance(scene, ReferenceScene) else scene_to_proto(scene).objects
        for k, o in enumerate(objects):
            kind = o.WhichOneof("shape")
            entity = f"{path}/{rr.escape_entity_path_part(o.id or f'{kind}_{k}')}"
            T = _pose_matrix(o.pose)
            if kind == "mesh":
                v = np.array([[p.x, p.y, p.z] for p in o.mesh.vertices]).reshape(-1, 3)
                v = v @ T[:3, :3].T + T[:3, 3]
                self.stream.log(entity, rr.Mesh3D(vertex_positions=v,
                                                  triangle_indices=np.array(o.mesh.indices).reshape(-1, 3),
                                                  albedo_factor=rgba), static=True)
            elif kind == "octree":
                tree = Octree.from_proto(o.octree)
                mins, edges, occupied = tree.leaves()
                c = (mins + edges[:, None] / 2)[occupied] @ T[:3, :3].T + T[:3, 3]
                self.stream.log(entity, rr.Boxes3D(centers=c, half_sizes=np.repeat(edges[occupied, None] / 2, 3, 1),
                                                   quaternions=[quaternions(T[:3, :3])], colors=[rgba],
                                                   fill_mode="solid"), static=True)
            else:
                arch = _shape_archetype(kind, o, T, rgba)
                if arch is not None:
                    self.stream.log(entity, arch, static=True)
        if isinstance(scene, ReferenceScene):
            lo, hi = scene.region
            self.stream.log(f"{path}/region", rr.Boxes3D(mins=[lo], sizes=[hi - lo], colors=[COLORS["region"]],
                                                         fill_mode="majorwireframe"), static=True)

    # ---- plans ----------------------------------------------------------------------------------------------------

    def plan(self, robot: Any, plan: Plan, *, scene: Optional[Sequence[Obstacle]] = None,
             path: str = "world/robot", timeline: str = "plan_time", t0: float = 0.0, check: bool = True,
             translation_tolerance: Optional[float] = None, rotation_tolerance: Optional[float] = None,
             joint_step: float = 0.02, name: str = "plan") -> None:
        """Plays ``plan`` back: the robot at every waypoint on the
        ``timeline`` (a duration timeline: waypoint i at ``t0 + plan.t[i]``
        s), the tool path as a line (FK at ``joint_step`` rad along the
        joint-space segments) and the waypoints as points, under
        ``world/<name>``. With a ``scene``, the scene is drawn and, with
        ``check``, every waypoint is checked (``robot.check``): links in
        collision turn red, the closest pair is a segment, the clearance a
        plot. The tool's deviation from the straight Cartesian line
        (``plan.deviation``) is plotted; given CCSTOMP's
        ``translation_tolerance`` (m; CartesianOptions' default is 1) and
        ``rotation_tolerance`` (rad; default 0.2), the tolerance tube is
        drawn too (the capsule of that radius around the straight tool line)
        and the tolerances go beside the deviations."""
        base = f"world/{name}"
        if scene is not None:
            self.scene(scene)
        if plan.colliding or not len(plan.q):
            self.stream.log(f"{base}/status", rr.TextLog(
                f"{plan.status}: {', '.join(plan.colliding) or plan.message}", level="WARN"), static=True)
        if not len(plan.q):
            return
        q = np.asarray(plan.q, dtype=float)
        times = t0 + np.asarray(plan.t, dtype=float)
        if len(times) != len(q):
            times = t0 + np.arange(len(q), dtype=float)
        idx = [rr.TimeColumn(timeline, duration=times)]
        self._link_columns(robot, q, path, idx)
        tool_wp = self._service(robot.fk_batch, q)
        self.stream.log(f"{base}/waypoints", rr.Points3D(tool_wp[:, :3, 3], radii=0.006,
                                                         colors=[COLORS["tool_path"]]), static=True)
        dense = _densify(q, joint_step)
        tool = self._service(robot.fk_batch, dense)[:, :3, 3]
        self.stream.log(f"{base}/tool_path", rr.LineStrips3D([tool], radii=0.003, colors=[COLORS["tool_path"]]),
                        static=True)
        self.stream.send_columns(f"{base}/tool", indexes=idx,
                                 columns=rr.Points3D.columns(positions=tool_wp[:, :3, 3]))
        if scene is not None and check:
            checks = self._service(robot.check, q, scene)
            self.stream.send_columns(self._plot(f"plots/{name}/clearance"), indexes=idx,
                                     columns=rr.Scalars.columns(scalars=checks.clearance))
            for k, t in enumerate(times):
                self.stream.set_time(timeline, duration=float(t))
                pairs = checks.colliding[k]
                self._color_links(path, {p.split(":")[0] for p in pairs} | {p.split(":")[-1] for p in pairs})
                a, b = checks.robot_points[k], checks.obstacle_points[k]
                if np.all(np.isfinite(a)) and np.all(np.isfinite(b)):
                    rgba = COLORS["collision"] if not checks.valid[k] else (240, 160, 0, 255)
                    self.stream.log(f"{base}/closest_pair", rr.LineStrips3D(
                        [[a, b]], radii=0.004, colors=[rgba], labels=[checks.closest_pair[k]], show_labels=False))
                else:
                    self.stream.log(f"{base}/closest_pair", rr.Clear(recursive=False))
            bad = ~checks.valid
            if bad.any():
                self.stream.log(f"{base}/invalid_waypoints", rr.Points3D(tool_wp[bad, :3, 3], radii=0.015,
                                                                         colors=[COLORS["collision"]]), static=True)
        if len(plan.deviation) == len(q):
            self._deviation(plan, name, idx, times, timeline, translation_tolerance, rotation_tolerance)
        if translation_tolerance is not None:
            a, b = tool_wp[0, :3, 3], tool_wp[-1, :3, 3]
            axis = b - a
            length = float(np.linalg.norm(axis))
            R = _frame_with_z(axis / length if length > 0 else np.array([0.0, 0.0, 1.0]))
            self.stream.log(f"{base}/tolerance_tube", rr.Capsules3D(
                lengths=[length], radii=[float(translation_tolerance)], translations=[a],
                quaternions=[quaternions(R)], colors=[COLORS["tube"]], fill_mode="solid"), static=True)

    def _deviation(self, plan: Plan, name: str, idx: List[Any], times: np.ndarray, timeline: str,
                   translation_tolerance: Optional[float], rotation_tolerance: Optional[float]) -> None:
        """The deviation plots of :meth:`plan`, with the tolerances given."""
        dev = np.asarray(plan.deviation, dtype=float)
        ends = [rr.TimeColumn(timeline, duration=[times[0], times[-1]])]
        for k, (kind, tol) in enumerate((("translation", translation_tolerance), ("rotation", rotation_tolerance))):
            group = self._plot(f"plots/{name}/{kind}_deviation")
            self.stream.send_columns(f"{group}/deviation", indexes=idx, columns=rr.Scalars.columns(scalars=dev[:, k]))
            if tol is not None:
                self.stream.send_columns(f"{group}/tolerance", indexes=ends,
                                         columns=rr.Scalars.columns(scalars=[float(tol)] * 2))

    def plan_iterations(self, robot: Any, frames: Iterable[Union[np.ndarray, Plan]], *,
                        scene: Optional[Sequence[Obstacle]] = None, path: str = "world/robot",
                        timeline: str = "stomp_iteration", name: str = "stomp") -> Optional[Plan]:
        """Animates an optimisation: ``frames`` as ``robot.plan_stream(...)``
        yields them (a trajectory per STOMP / CCSTOMP iteration, then the
        :class:`Plan`). Iteration k on the ``timeline`` (a sequence) shows
        that iteration's tool path and the robot at its middle waypoint under
        ``world/<name>``; the final plan's cost history is plotted, and the
        plan itself is played back with :meth:`plan`. Returns the Plan."""
        trajectories: List[np.ndarray] = []
        final: Optional[Plan] = None
        for f in frames:
            if isinstance(f, Plan):
                final = f
            else:
                trajectories.append(np.asarray(f, dtype=float))
        if scene is not None:
            self.scene(scene)
        if trajectories:
            n = len(trajectories)
            idx = [rr.TimeColumn(timeline, sequence=np.arange(n))]
            stacked = np.vstack(trajectories)
            tool = self._service(robot.fk_batch, stacked)[:, :3, 3]
            strips, start = [], 0
            for tr in trajectories:
                strips.append(tool[start:start + len(tr)])
                start += len(tr)
            self.stream.send_columns(f"world/{name}/tool_path", indexes=idx,
                                     columns=rr.LineStrips3D.columns(strips=strips))
            self._link_columns(robot, np.array([tr[len(tr) // 2] for tr in trajectories]), path, idx)
        if final is not None:
            if len(final.cost_history):
                self.stream.send_columns(
                    self._plot(f"plots/{name}/cost"), indexes=[rr.TimeColumn(timeline, sequence=np.arange(len(final.cost_history)))],
                    columns=rr.Scalars.columns(scalars=final.cost_history))
            self.plan(robot, final, scene=scene, path=path)
        return final

    # ---- octrees and views ----------------------------------------------------------------------------------------

    def octree(self, tree: Octree, region: Optional[Box3] = None, *, path: str = "world/octree",
               states: Sequence[str] = ("occupied", "free", "unknown"), static: bool = False) -> Dict[str, int]:
        """Draws ``tree`` inside ``region`` = (min xyz, max xyz) (default: the
        bounds of its known cells) as boxes under ``path/<state>``, one
        colour per state (:data:`COLORS`): the occupied and free leaves
        (a pruned leaf is one box) and the unknown cells, each clipped to the
        region (:meth:`kinplan.Octree.boxes`). At the current time unless
        ``static``. Returns the number of boxes per state."""
        boxes = tree.boxes(region)
        counts = {}
        for state in states:
            a, b = boxes[state]
            counts[state] = len(a)
            self.stream.log(f"{path}/{state}", rr.Boxes3D(
                centers=(a + b) / 2, half_sizes=(b - a) / 2, colors=[COLORS[state]], fill_mode="solid"),
                static=static)
        return counts

    def views(self, views: Views, *, path: str = "world/views", camera: Optional[Mapping[str, float]] = None,
              depth: float = 0.3, frontier: bool = True) -> None:
        """Draws ranked next-best views as camera frusta (``path/<rank>``:
        a transform at the view's pose and a pinhole of the camera's fields
        of view, ``depth`` m deep), coloured by utility (blue lowest,
        yellow highest), labelled rank and utility; with ``frontier``, the
        frontier cells they look at as points. ``camera``: horizontal_fov,
        vertical_fov (rad; default Kinect v2's). At the current time."""
        cam = dict(KINECT, **(camera or {}))
        hfov, vfov = float(cam["horizontal_fov"]), float(cam["vertical_fov"])
        colors = utility_colors(views.utility)
        poses = np.asarray(views.poses, dtype=float).reshape(-1, 4, 4)
        before = self._views_logged.get(path, 0)
        for k in range(len(poses)):
            T = poses[k]
            entity = f"{path}/{k}"
            self.stream.log(entity, rr.Transform3D(translation=T[:3, 3], quaternion=quaternions(T[:3, :3])),
                            rr.Pinhole(fov_y=vfov, aspect_ratio=np.tan(hfov / 2) / np.tan(vfov / 2),
                                       camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=depth,
                                       color=colors[k], line_width=0.004),
                            rr.Points3D([[0.0, 0.0, 0.0]], radii=0.01, colors=[colors[k]],
                                        labels=[f"{k}: f={views.utility[k]:.3f}"]))
        for k in range(len(poses), before):
            self.stream.log(f"{path}/{k}", rr.Clear(recursive=True))
        self._views_logged[path] = len(poses)
        if frontier and len(views.frontier):
            f = np.asarray(views.frontier, dtype=float).reshape(-1, 3)
            keep = np.all(np.isfinite(f), axis=1)
            self.stream.log(f"{path}_frontier", rr.Points3D(f[keep], radii=0.02, colors=colors[keep]))

    # ---- exploration runs -----------------------------------------------------------------------------------------

    def explore(self, steps: Sequence[Union[ExploreStep, ExploreSummary]], robot: Any, *,
                scene: Optional[ReferenceScene] = None, trees: Optional[Mapping[int, Octree]] = None,
                region: Optional[Box3] = None, path: str = "world/robot", camera: Optional[Mapping[str, float]] = None,
                timeline: str = "iteration", time_timeline: str = "explore_time",
                octree_states: Sequence[str] = ("occupied", "unknown")) -> None:
        """Draws an exploration run (the items ``client.explore`` yields, the
        summary last) on two timelines: ``timeline`` (a sequence, the
        iteration number; 0 is the start) and ``time_timeline`` (the
        executed trajectories end to end, seconds). Per iteration: the arm
        moving along its trajectory, the tool path, the chosen view as a
        frustum (``world/explore/view``), the views that failed as red
        points, and the known ratio as a plot. The octree: ``trees[k]``
        after iteration k when given (:func:`replay_trees` gets them from
        the service), the summary's final tree at the last iteration; its
        ``octree_states`` inside the region (default: the scene's)."""
        items = list(steps)
        summary = items[-1] if items and isinstance(items[-1], ExploreSummary) else None
        run = [s for s in items if isinstance(s, ExploreStep)]
        if scene is not None:
            self.scene(scene)
            region = scene.region if region is None else region
        cam = dict(KINECT, **(camera or {}))
        if summary is not None:
            self.stream.set_time(timeline, sequence=0)
            self.stream.set_time(time_timeline, duration=0.0)
            self.stream.log(self._plot("plots/known_ratio"), rr.Scalars(summary.initial_known_ratio))
        clock = 0.0
        for s in run:
            k = s.iteration
            traj = np.asarray(s.trajectory, dtype=float)
            if len(traj):
                t = clock + np.asarray(s.times_from_start, dtype=float)
                if len(t) != len(traj):
                    t = clock + np.arange(len(traj), dtype=float)
                idx = [rr.TimeColumn(time_timeline, duration=t), rr.TimeColumn(timeline, sequence=np.full(len(t), k))]
                self._link_columns(robot, traj, path, idx)
                clock = float(t[-1])
            self.stream.set_time(timeline, sequence=k)
            self.stream.set_time(time_timeline, duration=clock)
            if len(traj):
                tool = self._service(robot.fk_batch, _densify(traj, 0.05))[:, :3, 3]
                self.stream.log("world/explore/trajectory", rr.LineStrips3D([tool], radii=0.004,
                                                                           colors=[COLORS["tool_path"]]))
            else:
                self.stream.log("world/explore/trajectory", rr.Clear(recursive=False))
            if s.view is not None:
                T = np.asarray(s.view, dtype=float)
                self.stream.log("world/explore/view", rr.Transform3D(translation=T[:3, 3],
                                                                     quaternion=quaternions(T[:3, :3])),
                                rr.Pinhole(fov_y=float(cam["vertical_fov"]),
                                           aspect_ratio=np.tan(cam["horizontal_fov"] / 2) / np.tan(cam["vertical_fov"] / 2),
                                           camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=0.3,
                                           color=(250, 200, 40), line_width=0.006))
            if s.failures:
                self.stream.log("world/explore/failed_views", rr.Points3D(
                    [p for p, _ in s.failures], radii=0.03, colors=[COLORS["failed"]], labels=[r for _, r in s.failures]))
            else:
                self.stream.log("world/explore/failed_views", rr.Clear(recursive=False))
            self.stream.log(self._plot("plots/known_ratio"), rr.Scalars(s.known_ratio))
            if trees is not None and k in trees:
                self.octree(trees[k], region, path="world/octree", states=octree_states)
        if summary is not None:
            if trees is None or summary.iterations not in trees:
                self.stream.set_time(timeline, sequence=summary.iterations)
                self.stream.set_time(time_timeline, duration=clock)
                self.octree(summary.octree, region, path="world/octree", states=octree_states)
            self.stream.log("world/explore/summary", rr.TextLog(repr(summary)))


def replay_trees(client: Any, steps: Sequence[Union[ExploreStep, ExploreSummary]], *, every: int = 1,
                 **explore_kwargs: Any) -> Dict[int, Octree]:
    """The octree after iterations every, 2 every, ... of a run, from the
    service: Explore streams only the final tree, and the same request gives
    the same run, so the run is repeated with ``max_iterations=k`` (the
    ``explore_kwargs`` must be the run's own). Each replay's known ratio is
    checked against the run's; a mismatch raises RuntimeError. Costs about
    n^2 / (2 every) iterations of service time."""
    run = {s.iteration: s for s in steps if isinstance(s, ExploreStep)}
    last = max(run, default=0)
    out: Dict[int, Octree] = {}
    for k in range(every, last, every):
        *replayed, summary = client.explore(max_iterations=k, **explore_kwargs)
        if not isinstance(summary, ExploreSummary) or abs(summary.known_ratio - run[k].known_ratio) > 1e-12:
            raise RuntimeError(f"the replay to iteration {k} differs from the run (known ratio "
                               f"{getattr(summary, 'known_ratio', None)} against {run[k].known_ratio})")
        out[k] = summary.octree
    return out


def _densify(q: np.ndarray, step: float) -> np.ndarray:
    """Joint states at most ``step`` apart (max norm) along the segments of ``q``."""
    q = np.asarray(q, dtype=float)
    if len(q) < 2:
        return q
    rows = [q[:1]]
    for a, b in zip(q[:-1], q[1:]):
        n = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        f = (np.arange(1, n + 1) / n)[:, None]
        rows.append(a + (b - a) * f)
    return np.vstack(rows)


def _rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _frame_with_z(z: np.ndarray) -> np.ndarray:
    """A rotation whose z axis is the unit vector ``z``."""
    x = np.cross([0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _shape_archetype(kind: Optional[str], g: Any, T: np.ndarray, rgba: Sequence[int]) -> Any:
    """The Rerun archetype of one kinplan shape (its proto message ``g``
    with ``box`` / ``sphere`` / ``cylinder`` / ``capsule``, or a robot's
    ``mesh``) posed by ``T`` (4x4); None for a shape drawn otherwise (a
    scene mesh, octree, mesh_reference)."""
    q = quaternions(T[:3, :3])
    p = T[:3, 3]
    if kind == "mesh" and hasattr(g, "origin"):
        v = np.array([[x.x, x.y, x.z] for x in g.mesh.vertices]).reshape(-1, 3) @ T[:3, :3].T + p
        return rr.Mesh3D(vertex_positions=v, triangle_indices=np.array(g.mesh.indices).reshape(-1, 3),
                         albedo_factor=rgba)
    if kind == "box":
        s = g.box.size
        return rr.Boxes3D(centers=[p], half_sizes=[[s.x / 2, s.y / 2, s.z / 2]], quaternions=[q], colors=[rgba],
                          fill_mode="solid")
    if kind == "sphere":
        r = g.sphere.radius
        return rr.Ellipsoids3D(centers=[p], half_sizes=[[r, r, r]], colors=[rgba], fill_mode="solid")
    if kind == "cylinder":
        return rr.Cylinders3D(lengths=[g.cylinder.length], radii=[g.cylinder.radius], centers=[p], quaternions=[q],
                              colors=[rgba], fill_mode="solid")
    if kind == "capsule":
        length = g.capsule.length
        # kinplan's capsule is centred on its pose; Rerun's starts at its translation
        return rr.Capsules3D(lengths=[length], radii=[g.capsule.radius], translations=[p - T[:3, 2] * length / 2],
                             quaternions=[q], colors=[rgba], fill_mode="solid")
    return None


__all__ = ["COLORS", "KINECT", "Recording", "quaternions", "replay_trees", "utility_colors"]
