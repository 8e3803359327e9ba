"""The exploration loop end to end (ExplorationService.Explore; S0 §4-5):
``for step in client.explore(robot, start=..., scene=..., region=...)`` yields
one :class:`ExploreStep` per iteration and finally an :class:`ExploreSummary`
holding the totals and the final octree."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._display import html_table
from ._convert import pose_to_matrix
from .exploration import Octree
from .planning import ALGORITHMS, Obstacle, _pose, scene_to_proto
from .v1 import common_pb2, exploration_pb2, planning_pb2


SCENES = {
    "s0_open_cell": exploration_pb2.REFERENCE_SCENE_NAME_S0_OPEN_CELL,
    "s0_walled_cell": exploration_pb2.REFERENCE_SCENE_NAME_S0_WALLED_CELL,
}


@dataclass
class ReferenceScene:
    """One of kinplan's seeded reference cells: the robot's name, the
    obstacles (CollisionObject messages, usable as ``scene=``), the region
    (min xyz, max xyz) and the start joints. Pass it as ``scene=`` to
    :meth:`ExploreMixin.explore` and the region, start and robot follow."""

    name: str
    robot: str
    obstacles: List[common_pb2.CollisionObject]
    region: Tuple[np.ndarray, np.ndarray]
    start: np.ndarray

    def __repr__(self) -> str:
        lo, hi = self.region
        return f"ReferenceScene({self.name!r}, {len(self.obstacles)} obstacles, region {lo.tolist()} - {hi.tolist()})"


@dataclass
class ExploreStep:
    """One iteration: the view moved to (4x4 camera pose in the world, or
    None when every tried view failed) with its utility terms, the executed
    trajectory (waypoints x dof, rad) and its S0 criteria (CD m, JD rad, OC
    rad, CPC, RDM m, ...), the views that failed and why, the known ratio
    after the scan, and the seconds spent per stage."""

    iteration: int
    known_ratio: float
    view: Optional[np.ndarray]
    terms: Dict[str, float]
    trajectory: np.ndarray
    times_from_start: np.ndarray
    criteria: Dict[str, float]
    failures: List[Tuple[Tuple[float, float, float], str]]
    hits_scene: bool
    joints: np.ndarray
    times: Dict[str, float]

    def __repr__(self) -> str:
        moved = "no motion" if self.view is None else f"{len(self.trajectory)} waypoints"
        return (
            f"ExploreStep({self.iteration}: known {self.known_ratio:.3f}, {moved}, "
            f"{len(self.failures)} failed views, {self.times.get('total', 0.0):.3f} s)"
        )


@dataclass
class ExploreSummary:
    """How the run ended (status "EXPLORED", "ITERATION_CAP",
    "CONSECUTIVE_FAILURES", "NO_CANDIDATES", "TIMEOUT" or "CANCELLED"),
    the known ratio before the first iteration and at the end, the S0
    criteria summed over every trajectory (S0 Tab. 5.3) and the final tree."""

    status: str
    iterations: int
    initial_known_ratio: float
    known_ratio: float
    observable_cells: int
    totals: Dict[str, float]
    failures: int
    scene_hits: int
    final_joints: np.ndarray
    octree: Octree
    scans: int
    elapsed: float

    def _repr_html_(self) -> str:
        rows = [("status", self.status), ("iterations", self.iterations),
                ("known ratio", f"{self.initial_known_ratio:.3f} -> {self.known_ratio:.3f}"),
                ("observable cells", self.observable_cells), ("failed views", self.failures),
                ("trajectories hitting the scene", self.scene_hits), ("elapsed (s)", self.elapsed)]
        rows += [(f"{k} (sum)", v) for k, v in self.totals.items()]
        return html_table("ExploreSummary", rows, "CD, RDM in m; JD, OC in rad; sums over every executed trajectory (S0 Tab. 5.3)")

    def __repr__(self) -> str:
        return (
            f"ExploreSummary({self.status} after {self.iterations} iterations, known "
            f"{self.initial_known_ratio:.3f} -> {self.known_ratio:.3f}, {self.failures} failed views, "
            f"{self.elapsed:.2f} s)"
        )


def _step(m: exploration_pb2.ExploreIteration) -> ExploreStep:
    pts = m.trajectory.points
    v = m.view if m.HasField("view") else None
    return ExploreStep(
        iteration=m.iteration,
        known_ratio=m.known_ratio,
        view=pose_to_matrix(v.pose) if v is not None else None,
        terms={} if v is None else {
            "distance": v.distance_score,
            "rotation": v.rotation_score,
            "information_gain": v.information_gain,
            "utility": v.utility,
            "rank": float(m.view_rank),
        },
        trajectory=np.array([list(p.positions) for p in pts], dtype=float).reshape(len(pts), -1),
        times_from_start=np.array([p.time_from_start for p in pts], dtype=float),
        criteria=dict(m.criteria),
        failures=[((f.position.x, f.position.y, f.position.z), f.reason) for f in m.failures],
        hits_scene=m.hits_scene,
        joints=np.array(m.joints, dtype=float),
        times={f.name: getattr(m.times, f.name) for f in m.times.DESCRIPTOR.fields},
    )


def _summary(s: exploration_pb2.ExploreSummary) -> ExploreSummary:
    t = s.totals
    return ExploreSummary(
        status=exploration_pb2.ExploreStatus.Name(s.status).removeprefix("EXPLORE_STATUS_"),
        iterations=s.iterations,
        initial_known_ratio=s.initial_known_ratio,
        known_ratio=s.known_ratio,
        observable_cells=s.observable_cells,
        totals={"JD": t.jd, "CPC": t.cpc, "CD": t.cd, "OC": t.oc, "RDM": t.rdm, "trajectories": float(t.trajectories)},
        failures=s.failures,
        scene_hits=s.scene_hits,
        final_joints=np.array(s.final_joints, dtype=float),
        octree=Octree.from_proto(s.octree),
        scans=s.scans,
        elapsed=s.elapsed,
    )


def _explore_message(m: exploration_pb2.ExploreResponse) -> Union[ExploreStep, ExploreSummary]:
    """The step or summary an Explore stream message carries."""
    if m.HasField("summary"):
        return _summary(m.summary)
    return _step(m.iteration)


def _reference_scene_request(name: str, seed: int) -> exploration_pb2.ReferenceSceneRequest:
    """The ReferenceSceneRequest of :meth:`ExploreMixin.reference_scene`'s
    arguments (shared by the blocking and asyncio clients)."""
    if name not in SCENES:
        raise ValueError(f"name must be one of {sorted(SCENES)}, got {name!r}")
    return exploration_pb2.ReferenceSceneRequest(name=SCENES[name], seed=int(seed))


def _reference_scene(name: str, r: exploration_pb2.ReferenceSceneResponse) -> ReferenceScene:
    """The :class:`ReferenceScene` `name` of a ReferenceScene reply."""
    def v(p: Any) -> np.ndarray:
        return np.array([p.x, p.y, p.z], dtype=float)

    return ReferenceScene(
        name=name,
        robot=r.robot,
        obstacles=list(r.scene.objects),
        region=(v(r.region.min), v(r.region.max)),
        start=np.array(r.start, dtype=float),
    )


def _explore_request(
    make_robot: Callable[[str], Any],
    robot: Any,
    scene: Union[ReferenceScene, Sequence[Obstacle]],
    start: Any,
    region: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]],
    planner: str,
    weights: Optional[Sequence[float]],
    seed: int,
    resolution: Optional[float],
    pixel_stride: Optional[int],
    known_ratio: Optional[float],
    max_iterations: Optional[int],
    max_consecutive_failures: Optional[int],
    camera: Optional[Mapping[str, Any]],
    camera_mount: Any,
    nbv: Optional[Mapping[str, Any]],
    plan_options: Optional[Mapping[str, Any]],
    options: Dict[str, Any],
) -> exploration_pb2.ExploreRequest:
    """The ExploreRequest of :meth:`ExploreMixin.explore`'s arguments; a
    robot given by name (or a :class:`ReferenceScene`'s) is made by
    `make_robot` (the client's ``robot``)."""
    if isinstance(scene, ReferenceScene):
        start = scene.start if start is None else start
        region = scene.region if region is None else region
        if robot is None:
            robot = make_robot(scene.robot)
        scene = scene.obstacles
    if isinstance(robot, str):
        robot = make_robot(robot)
    if robot is None or start is None or region is None:
        raise ValueError("robot, start and region are required unless scene is a ReferenceScene")
    if planner not in ALGORITHMS:
        raise ValueError(f"planner must be one of {sorted(ALGORITHMS)}, got {planner!r}")
    lo, hi = (np.asarray(b, dtype=float).reshape(3) for b in region)
    nbv_opts = exploration_pb2.NbvOptions(**dict(nbv or {}))
    if weights is not None:
        w_i, w_d, w_r = (float(v) for v in weights)
        nbv_opts.weights.CopyFrom(exploration_pb2.UtilityWeights(information_gain=w_i, distance=w_d, rotation=w_r))
    req = exploration_pb2.ExploreRequest(
        start=[float(v) for v in np.asarray(start, dtype=float).ravel()],
        scene=scene_to_proto(scene),
        region=exploration_pb2.BoundingBox(
            min=common_pb2.Vec3(x=lo[0], y=lo[1], z=lo[2]), max=common_pb2.Vec3(x=hi[0], y=hi[1], z=hi[2])
        ),
        camera=exploration_pb2.CameraModel(**dict(camera or {})),
        nbv=nbv_opts,
        algorithm=ALGORITHMS[planner],
        plan_options=planning_pb2.PlanOptions(**dict(plan_options or {})),
        seed=int(seed),
        **options,
    )
    if camera_mount is not None:
        req.camera_mount.CopyFrom(_pose(camera_mount))
    for name, value in (("resolution", resolution), ("pixel_stride", pixel_stride)):
        if value is not None:
            setattr(req, name, value)
    for name, value in (
        ("known_ratio", known_ratio),
        ("max_iterations", max_iterations),
        ("max_consecutive_failures", max_consecutive_failures),
    ):
        if value is not None:
            setattr(req.stop, name, value)
    req.robot.CopyFrom(robot._ref())
    return req


class ExploreMixin:
    """``Client.explore``, ``Client.reference_scene``."""

    def reference_scene(self, name: str = "s0_open_cell", *, seed: int = 1,
                        timeout: Optional[float] = None) -> ReferenceScene:
        """The reference cell ``name`` ("s0_open_cell" or "s0_walled_cell")
        built with ``seed``."""
        req = _reference_scene_request(name, seed)
        r = self._call(self._exploration().ReferenceScene, req, timeout)  # type: ignore[attr-defined]
        return _reference_scene(name, r)

    def explore(
        self,
        robot: Any = None,
        *,
        scene: Union[ReferenceScene, Sequence[Obstacle]],
        start: Any = None,
        region: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None,
        planner: str = "rrt_connect",
        weights: Optional[Sequence[float]] = None,
        seed: int = 0,
        resolution: Optional[float] = None,
        pixel_stride: Optional[int] = None,
        known_ratio: Optional[float] = None,
        max_iterations: Optional[int] = None,
        max_consecutive_failures: Optional[int] = None,
        camera: Optional[Mapping[str, Any]] = None,
        camera_mount: Any = None,
        nbv: Optional[Mapping[str, Any]] = None,
        plan_options: Optional[Mapping[str, Any]] = None,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> Iterator[Union[ExploreStep, ExploreSummary]]:
        """Explores ``region`` = (min xyz, max xyz) of the simulated ``scene``
        with a depth camera on ``robot`` from joints ``start`` (all three
        taken from ``scene`` when it is a :class:`ReferenceScene`; ``robot``
        may be a built-in's name): yields an
        :class:`ExploreStep` per iteration, then the :class:`ExploreSummary`.
        ``planner``: "rrt_connect", "stomp" or "ccstomp"; ``weights`` =
        (w_i, w_d, w_r) of the NBV utility (S0's IG1_T025_R01 = (1, 0.25, 0.1)
        by default). ``nbv`` takes ``NbvOptions`` fields, ``plan_options``
        ``PlanOptions`` fields (e.g. ``{"stomp": {"timesteps": 20}}``), and
        further ``options`` the remaining ``ExploreRequest`` fields
        (``noise_stddev``, ``candidates_per_iteration``, ``plan_time_budget``,
        ``time_budget``)."""
        req = _explore_request(
            self.robot, robot, scene, start, region, planner, weights, seed,  # type: ignore[attr-defined]
            resolution, pixel_stride, known_ratio, max_iterations, max_consecutive_failures, camera, camera_mount,
            nbv, plan_options, options,
        )
        from .errors import KinplanError
        import grpc

        stub = self._exploration()  # type: ignore[attr-defined]
        t = self.timeout if timeout is None else timeout  # type: ignore[attr-defined]
        try:
            for m in stub.Explore(req, timeout=t):
                yield _explore_message(m)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None
