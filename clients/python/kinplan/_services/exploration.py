"""ExplorationService: next-best views, scans into octrees, tree
statistics, reference cells and the exploration loop — requests built and
replies read for both clients."""
from __future__ import annotations

from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from .._codec import pose_to_matrix
from ..exploration_loop import SCENES, ExploreStep, ExploreSummary, ReferenceScene, _step, _summary
from ..octree import GAINS, Octree, Views
from ..planning import ALGORITHMS, Obstacle, _pose, scene_to_proto
from ..v1 import common_pb2, exploration_pb2, planning_pb2
from . import Call


def nbv_options(options: Mapping[str, Any], argument: str = "options") -> exploration_pb2.NbvOptions:
    """``NbvOptions`` of keyword values, each checked against the message's
    fields (an unknown name is a TypeError listing the known ones);
    ``region`` may be a (min xyz, max xyz) pair."""
    known = exploration_pb2.NbvOptions.DESCRIPTOR.fields_by_name
    values = dict(options)
    for name in values:
        if name not in known:
            raise TypeError(f"{argument}: NbvOptions has no field {name!r}; the fields are {sorted(known)}")
    region = values.pop("region", None)
    opts = exploration_pb2.NbvOptions(**values)
    if region is not None:
        opts.region.CopyFrom(bounding_box(region, "region"))
    return opts


def bounding_box(box: Any, name: str) -> exploration_pb2.BoundingBox:
    """A BoundingBox of (min xyz, max xyz), or one given as the message."""
    if isinstance(box, exploration_pb2.BoundingBox):
        return box
    try:
        lo, hi = (np.asarray(b, dtype=float).reshape(3) for b in box)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (min xyz, max xyz), two 3-vectors in metres") from None
    return exploration_pb2.BoundingBox(min=common_pb2.Vec3(x=lo[0], y=lo[1], z=lo[2]),
                                       max=common_pb2.Vec3(x=hi[0], y=hi[1], z=hi[2]))


def next_best_view(octree: Any, camera_pose: Any, camera_mount: Any, candidate_poses: Sequence[Any],
                   weights: Optional[Sequence[float]], gain: str, ray_fraction: Optional[float], max_results: int,
                   camera: Optional[Dict[str, Any]], options: Dict[str, Any], robot: bool) -> Call[Views]:
    """NextBestView; with `robot` the request is built from the robot's
    reference (the reach filter and IK checks of the best candidates)."""
    req = _nbv_request_of(octree, camera_pose, camera_mount, candidate_poses, weights, gain, ray_fraction,
                          max_results, camera, options)
    if robot:
        return Call("exploration", "NextBestView", _views, build=_with_robot(req))
    return Call("exploration", "NextBestView", _views, request=req)


_REACH = {0: None, 1: True, 2: False}


def _nbv_request_of(octree: Any, camera_pose: Any, camera_mount: Any, candidate_poses: Sequence[Any],
                 weights: Optional[Sequence[float]], gain: str, ray_fraction: Optional[float], max_results: int,
                 camera: Optional[Dict[str, Any]], options: Dict[str, Any]) -> exploration_pb2.NextBestViewRequest:
    """The NextBestViewRequest of ``Client.next_best_view``'s arguments, without a robot."""
    tree = Octree.read(octree)
    if gain not in GAINS:
        raise ValueError(f"gain must be one of {sorted(GAINS)}, got {gain!r}")
    opts = nbv_options(options)
    opts.gain = GAINS[gain]
    opts.max_results = int(max_results)
    if ray_fraction is not None:
        opts.ray_fraction = float(ray_fraction)
    if weights is not None:
        w_i, w_d, w_r = (float(v) for v in weights)
        opts.weights.CopyFrom(exploration_pb2.UtilityWeights(information_gain=w_i, distance=w_d, rotation=w_r))
    req = exploration_pb2.NextBestViewRequest(
        octree=tree.to_proto(),
        camera=exploration_pb2.CameraModel(**(camera or {})),
        camera_pose=_pose(camera_pose),
        candidate_poses=[_pose(p) for p in candidate_poses],
        options=opts,
    )
    if camera_mount is not None:
        req.camera_mount.CopyFrom(_pose(camera_mount))
    return req


def _with_robot(req: exploration_pb2.NextBestViewRequest,
                ) -> Callable[[common_pb2.RobotRef], exploration_pb2.NextBestViewRequest]:
    """`req` with a robot reference (for a robot's ``_call``)."""
    def build(ref: common_pb2.RobotRef) -> exploration_pb2.NextBestViewRequest:
        r = exploration_pb2.NextBestViewRequest()
        r.CopyFrom(req)
        r.robot.CopyFrom(ref)
        return r

    return build


def _views(reply: exploration_pb2.NextBestViewResponse) -> Views:
    """The :class:`Views` of a NextBestView reply."""
    c = reply.candidates
    s = reply.stages
    return Views(
        poses=np.array([pose_to_matrix(v.pose) for v in c]).reshape(-1, 4, 4),
        utility=np.array([v.utility for v in c]),
        gain=np.array([v.information_gain for v in c]),
        distance=np.array([v.distance_score for v in c]),
        rotation=np.array([v.rotation_score for v in c]),
        unknown_cells=np.array([v.unknown_cells for v in c]),
        frontier=np.array(
            [[v.frontier.x, v.frontier.y, v.frontier.z] if v.HasField("frontier") else [np.nan] * 3 for v in c]
        ).reshape(-1, 3),
        reachable=[_REACH[v.reachability] for v in c],
        joints=[np.array(v.joints) if len(v.joints) else None for v in c],
        stages={f.name: getattr(s, f.name) for f in s.DESCRIPTOR.fields},
        status=exploration_pb2.NbvStatus.Name(reply.status).removeprefix("NBV_STATUS_"),
        weights={
            "information_gain": reply.weights.information_gain,
            "distance": reply.weights.distance,
            "rotation": reply.weights.rotation,
        },
        raw=reply,
    )


def insert_scan(octree: Any, points: Any, origin: Any, resolution: float,
                max_range: Optional[float], discretize: bool, depth: Any = None,
                intrinsics: Optional[Sequence[float]] = None,
                camera: Optional[Dict[str, Any]] = None,
                near_ray_spacing: float = 0.0) -> Call[Octree]:
    """InsertScan: ``points`` seen from ``origin``, or a ``depth`` image taken
    from the sensor pose ``origin``, into ``octree`` (any form
    :meth:`Octree.read` takes; a new tree when None)."""
    req = exploration_pb2.InsertScanRequest(
        resolution=float(resolution),
        sensor_pose=_pose(origin),
        discretize=discretize,
        near_ray_spacing=float(near_ray_spacing),
    )
    if (points is None) == (depth is None):
        raise ValueError("give points or depth, not both")
    if depth is not None:
        req.depth_image.CopyFrom(_depth_image(depth, intrinsics, camera))
    else:
        pts = np.asarray(points, dtype=np.float32)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise ValueError(f"points must be n x 3, got shape {pts.shape}")
        req.points.CopyFrom(exploration_pb2.PointCloud(xyz=pts.ravel().tolist()))
    if octree is not None:
        req.octree.CopyFrom(Octree.read(octree).to_proto())
    if max_range is not None:
        req.max_range = float(max_range)
    return Call("exploration", "InsertScan", lambda r: Octree.from_proto(r.octree), request=req)


def _depth_image(depth: Any, intrinsics: Optional[Sequence[float]],
                 camera: Optional[Dict[str, Any]]) -> exploration_pb2.DepthImage:
    """A DepthImage of a height x width array: uint16 in millimetres (sent as
    little-endian bytes) or float in metres; 0 or NaN is no return."""
    d = np.asarray(depth)
    if d.ndim != 2:
        raise ValueError(f"depth must be a height x width image, got shape {d.shape}")
    h, w = d.shape
    msg = exploration_pb2.DepthImage(width=w, height=h)
    if d.dtype == np.uint16:
        msg.depth_mm = d.astype("<u2").tobytes()
    elif np.issubdtype(d.dtype, np.floating):
        msg.depth.extend(d.astype(np.float32).ravel().tolist())
    else:
        raise ValueError(f"depth must be uint16 (mm) or float (m), got {d.dtype}")
    if (intrinsics is None) == (camera is None):
        raise ValueError("give intrinsics=(fx, fy, cx, cy) or camera=..., not both")
    if intrinsics is not None:
        fx, fy, cx, cy = (float(v) for v in intrinsics)
        msg.fx, msg.fy, msg.cx, msg.cy = fx, fy, cx, cy
    else:
        msg.camera.CopyFrom(exploration_pb2.CameraModel(**dict(camera or {})))
    return msg


def octree_info(octree: Any, box: Any) -> Call[Dict[str, Any]]:
    """OctreeInfo: counts, bounds and volumes of a tree (inside ``box`` when given)."""
    req = exploration_pb2.OctreeInfoRequest(octree=Octree.read(octree).to_proto())
    if box is not None:
        req.box.CopyFrom(bounding_box(box, "box"))
    return Call("exploration", "OctreeInfo", _octree_info, request=req)


def _octree_info(r: exploration_pb2.OctreeInfoResponse) -> Dict[str, Any]:
    """The dict of an OctreeInfo reply."""
    s = r.stats
    return {
        "resolution": s.resolution,
        "nodes": s.nodes,
        "leaves": s.leaves,
        "occupied_leaves": s.occupied_leaves,
        "free_leaves": s.free_leaves,
        "bounds": (
            np.array([s.bounds.min.x, s.bounds.min.y, s.bounds.min.z]),
            np.array([s.bounds.max.x, s.bounds.max.y, s.bounds.max.z]),
        ),
        "occupied_volume": r.occupied_volume,
        "free_volume": r.free_volume,
        "unknown_volume": r.unknown_volume,
    }




def _explore_message(m: exploration_pb2.ExploreResponse) -> Union[ExploreStep, ExploreSummary]:
    """The step or summary an Explore stream message carries."""
    if m.HasField("summary"):
        return _summary(m.summary)
    return _step(m.iteration)


def reference_scene(name: str, seed: int) -> Call[ReferenceScene]:
    """ReferenceScene: the seeded reference cell ``name``."""
    if name not in SCENES:
        raise ValueError(f"name must be one of {sorted(SCENES)}, got {name!r}")
    req = exploration_pb2.ReferenceSceneRequest(name=SCENES[name], seed=int(seed))
    return Call("exploration", "ReferenceScene", lambda r: _reference_scene(name, r), request=req)


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


def explore(
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
) -> Call[Union[ExploreStep, ExploreSummary]]:
    """Explore (a server stream): a robot given by name (or a
    :class:`ReferenceScene`'s) is made by `make_robot` (the client's
    ``robot``); each message reads as an :class:`ExploreStep`, the last as
    the :class:`ExploreSummary`."""
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
    nbv_opts = nbv_options(nbv or {}, "nbv")
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
    return Call("exploration", "Explore", _explore_message, request=req, streaming=True)


