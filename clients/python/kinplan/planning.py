"""Motion planning in a collision scene: STOMP, CCSTOMP (S0's Cartesian-
constrained STOMP) and RRT-Connect, and validity checks of joint states.

``robot.plan(start=q0, goal=q1 | pose=T, algorithm="ccstomp",
scene=[kinplan.Box(...), ...])`` returns a :class:`Plan`; ``robot.check(qs,
scene)`` a :class:`StateChecks`. Obstacles are placed in the
robot's base frame; units are metres and radians (proto/kinplan/v1/planning.proto).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from ._display import html_table
from ._convert import matrix_to_pose
from .v1 import common_pb2, planning_pb2

#: Planner names accepted by ``algorithm=``.
ALGORITHMS = {
    "rrt_connect": planning_pb2.PLAN_ALGORITHM_RRT_CONNECT,
    "stomp": planning_pb2.PLAN_ALGORITHM_STOMP,
    "ccstomp": planning_pb2.PLAN_ALGORITHM_CCSTOMP,
}

PoseLike = Union[None, np.ndarray, Sequence[float]]


def _pose(pose: PoseLike) -> common_pb2.Pose:
    """A 4x4 matrix, a 3-vector position (identity rotation) or None (identity)."""
    if pose is None:
        return common_pb2.Pose()
    arr = np.asarray(pose, dtype=float)
    if arr.shape == (3,):
        return common_pb2.Pose(position=common_pb2.Vec3(x=arr[0], y=arr[1], z=arr[2]))
    if arr.shape == (4, 4):
        return matrix_to_pose(arr)
    raise ValueError(f"pose must be a 4x4 matrix or a 3-vector position, got shape {arr.shape}")


@dataclass
class Box:
    """A box with full edge lengths ``size`` (x, y, z), metres, centred on ``pose``."""

    size: Sequence[float]
    pose: PoseLike = None
    id: str = ""

    def to_proto(self) -> common_pb2.CollisionObject:
        x, y, z = (float(v) for v in self.size)
        return common_pb2.CollisionObject(
            id=self.id, pose=_pose(self.pose), box=common_pb2.Box(size=common_pb2.Vec3(x=x, y=y, z=z))
        )


@dataclass
class Sphere:
    """A sphere of ``radius`` metres centred at ``pose`` (a 3-vector or 4x4)."""

    radius: float
    pose: PoseLike = None
    id: str = ""

    def to_proto(self) -> common_pb2.CollisionObject:
        return common_pb2.CollisionObject(
            id=self.id, pose=_pose(self.pose), sphere=common_pb2.Sphere(radius=float(self.radius))
        )


@dataclass
class Cylinder:
    """A cylinder along the z axis of ``pose``: radius and full length, metres."""

    radius: float
    length: float
    pose: PoseLike = None
    id: str = ""

    def to_proto(self) -> common_pb2.CollisionObject:
        return common_pb2.CollisionObject(
            id=self.id,
            pose=_pose(self.pose),
            cylinder=common_pb2.Cylinder(radius=float(self.radius), length=float(self.length)),
        )


@dataclass
class Capsule:
    """A capsule along z: radius and the distance between its cap centres, metres."""

    radius: float
    length: float
    pose: PoseLike = None
    id: str = ""

    def to_proto(self) -> common_pb2.CollisionObject:
        return common_pb2.CollisionObject(
            id=self.id,
            pose=_pose(self.pose),
            capsule=common_pb2.Capsule(radius=float(self.radius), length=float(self.length)),
        )


@dataclass
class Mesh:
    """A triangle mesh: ``vertices`` (n x 3, metres) and ``faces`` (m x 3 vertex indices)."""

    vertices: Any
    faces: Any
    pose: PoseLike = None
    id: str = ""

    def to_proto(self) -> common_pb2.CollisionObject:
        v = np.asarray(self.vertices, dtype=float)
        f = np.asarray(self.faces)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices must be n x 3, got shape {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"faces must be m x 3, got shape {f.shape}")
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise ValueError(f"faces index vertices 0..{len(v) - 1}, got {f.min()}..{f.max()}")
        mesh = common_pb2.TriangleMesh(
            vertices=[common_pb2.Vec3(x=a, y=b, z=c) for a, b, c in v.tolist()],
            indices=f.astype(np.uint32).ravel().tolist(),
        )
        return common_pb2.CollisionObject(id=self.id, pose=_pose(self.pose), mesh=mesh)


@dataclass
class OctreeObstacle:
    """An OctoMap tree as an obstacle: the node bytes of a ``.bt`` file (or of
    a ``.ot`` file with ``binary=False``) without its text header, as ROS
    ``octomap_msgs/Octomap.data`` carries them; or a whole ``.bt`` file via
    :meth:`from_bt_file_bytes`. Occupied leaves are obstacles; with
    ``unknown_as_obstacle`` so are the unknown cells inside its known bounds."""

    data: bytes
    resolution: float
    binary: bool = True
    tree_id: str = "OcTree"
    pose: PoseLike = None
    unknown_as_obstacle: bool = False
    id: str = ""

    @classmethod
    def from_bt_file_bytes(cls, content: bytes, **kwargs: Any) -> "OctreeObstacle":
        """Splits a ``.bt`` file's header (``id``, ``res``, ``data`` lines) from its nodes."""
        from .octree import _split_header

        tree_id, resolution, data = _split_header(content)
        return cls(data=data, resolution=resolution, tree_id=tree_id, binary=True, **kwargs)

    def to_proto(self) -> common_pb2.CollisionObject:
        return common_pb2.CollisionObject(
            id=self.id,
            pose=_pose(self.pose),
            octree=common_pb2.Octree(
                id=self.tree_id, resolution=float(self.resolution), binary=self.binary, data=bytes(self.data)
            ),
            unknown_as_obstacle=self.unknown_as_obstacle,
        )


Obstacle = Union[Box, Sphere, Cylinder, Capsule, Mesh, OctreeObstacle, common_pb2.CollisionObject]


def scene_to_proto(scene: Optional[Sequence[Obstacle]]) -> common_pb2.Scene:
    objects = []
    for k, o in enumerate(scene or []):
        if isinstance(o, common_pb2.CollisionObject):
            objects.append(o)
        elif hasattr(o, "to_proto"):
            p = o.to_proto()
            if not p.id:
                p.id = f"{type(o).__name__.lower()}_{k}"
            objects.append(p)
        else:
            raise TypeError(f"scene[{k}] is a {type(o).__name__}, not a kinplan obstacle")
    return common_pb2.Scene(objects=objects)


#: Timing method names accepted by ``timing={"method": ...}`` and ``retime(method=...)``.
TIMING_METHODS = {
    "waypoint": planning_pb2.TIMING_METHOD_WAYPOINT,
    "time_optimal": planning_pb2.TIMING_METHOD_TIME_OPTIMAL,
    "jerk_limited": planning_pb2.TIMING_METHOD_JERK_LIMITED,
}


def timing_options(timing: Optional[Mapping[str, Any]]) -> planning_pb2.TimingOptions:
    """``TimingOptions`` from a mapping of its fields; ``method`` may be a name
    of :data:`TIMING_METHODS` (or the enum value)."""
    fields = dict(timing or {})
    method = fields.get("method")
    if isinstance(method, str):
        if method not in TIMING_METHODS:
            raise ValueError(f"timing method must be one of {sorted(TIMING_METHODS)}, got {method!r}")
        fields["method"] = TIMING_METHODS[method]
    return planning_pb2.TimingOptions(**fields)


def _rates(points: Any, name: str, dof: int) -> np.ndarray:
    """``velocities`` or ``accelerations`` of every point as n x dof (NaN where a point has none)."""
    rows = [list(getattr(p, name)) or [np.nan] * dof for p in points]
    return np.array(rows, dtype=float).reshape(len(rows), dof)


@dataclass
class TimedTrajectory:
    """A timed joint trajectory from ``robot.retime``: ``t`` (s), ``q``
    (rad, or m for prismatic joints), ``qd`` (rad/s) and ``qdd`` (rad/s^2),
    n x dof each; ``duration`` (s); ``scores`` the S0 criteria of its points
    with the jerk on the real time axis ("JJ_time", "JMJ_time" rad/s^3,
    "CJ_time", "CMJ_time" m/s^3); ``compute_time`` the server's time for the
    timing alone (s)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float
    scores: Dict[str, float]
    compute_time: float
    raw: Any = field(default=None, repr=False)

    def __repr__(self) -> str:
        return f"TimedTrajectory(points={len(self.t)}, duration={self.duration:.3f} s)"

    @classmethod
    def from_proto(cls, r: planning_pb2.RetimeResponse) -> "TimedTrajectory":
        points = r.trajectory.points
        dof = len(points[0].positions) if points else 0
        return cls(
            t=np.array([p.time_from_start for p in points], dtype=float),
            q=np.array([list(p.positions) for p in points], dtype=float).reshape(len(points), dof),
            qd=_rates(points, "velocities", dof),
            qdd=_rates(points, "accelerations", dof),
            duration=r.duration,
            scores=dict(r.criteria),
            compute_time=r.compute_time,
            raw=r,
        )


@dataclass
class Plan:
    """A planned trajectory. ``q`` is n x dof (rad, or m for prismatic
    joints), ``t`` the time of each point (s), ``qd`` and ``qdd`` the joint
    velocities (rad/s) and accelerations (rad/s^2) there (None in a Plan
    built by hand), all timed by
    ``timing={"method": ...}`` within the limits: one point per waypoint for
    "waypoint" (the default), points every ``sample_period`` for
    "time_optimal" and "jerk_limited".
    ``status`` is one of SUCCEEDED, NO_VALID_TRAJECTORY, INVALID_START,
    INVALID_GOAL, GOAL_UNREACHABLE, TIMEOUT, CANCELLED; ``valid`` says the
    trajectory is collision-free (and, for CCSTOMP, within the Cartesian
    tolerances). ``deviation`` is n x 2: the tool's translation (m) and
    rotation (rad) from the straight Cartesian line between the start and goal
    tool poses. ``scores`` holds the S0 criteria (see ``Robot.score``)."""

    status: str
    message: str
    q: np.ndarray
    t: np.ndarray
    valid: bool
    cost_history: np.ndarray
    deviation: np.ndarray
    violates_tolerance: bool
    scores: Dict[str, float]
    colliding: List[str]
    goal: np.ndarray
    iterations: int
    duration: float
    timings: Dict[str, float]
    qd: Optional[np.ndarray] = None
    qdd: Optional[np.ndarray] = None
    raw: Any = field(default=None, repr=False)

    @property
    def success(self) -> bool:
        return self.status == "SUCCEEDED"

    def _repr_html_(self) -> str:
        rows = [("status", self.status), ("waypoints", len(self.q)), ("valid", self.valid),
                ("duration (s)", float(self.t[-1]) if len(self.t) else 0.0)]
        rows += [(k, v) for k, v in self.scores.items() if k in ("CD", "JD", "OC", "CPC", "RDM")]
        return html_table("Plan", rows, "CD, RDM in m; JD, OC in rad (S0 criteria)")

    def __repr__(self) -> str:
        return (
            f"Plan(status={self.status}, waypoints={len(self.q)}, valid={self.valid}, "
            f"duration={self.duration:.3f} s, planning={self.timings.get('total', 0.0) * 1e3:.1f} ms)"
        )

    @classmethod
    def from_proto(cls, r: planning_pb2.PlanResponse) -> "Plan":
        points = r.trajectory.points
        q = np.array([list(p.positions) for p in points], dtype=float) if points else np.zeros((0, 0))
        return cls(
            status=planning_pb2.PlanStatus.Name(r.status).removeprefix("PLAN_STATUS_"),
            message=r.message,
            q=q,
            t=np.array([p.time_from_start for p in points], dtype=float),
            qd=_rates(points, "velocities", q.shape[1]),
            qdd=_rates(points, "accelerations", q.shape[1]),
            valid=r.valid,
            cost_history=np.array(r.cost_history, dtype=float),
            deviation=np.column_stack(
                [np.array(r.deviation.translation, dtype=float), np.array(r.deviation.rotation, dtype=float)]
            )
            if len(r.deviation.translation)
            else np.zeros((0, 2)),
            violates_tolerance=r.deviation.violates_tolerance,
            scores=dict(r.criteria),
            colliding=list(r.colliding),
            goal=np.array(r.goal, dtype=float),
            iterations=r.iterations,
            duration=r.duration,
            timings={
                "goal_ik": r.timings.goal_ik,
                "rrt_connect": r.timings.rrt_connect,
                "stomp": r.timings.stomp,
                "verify": r.timings.verify,
                "total": r.timings.total,
            },
            raw=r,
        )


@dataclass
class StateChecks:
    """Per state: ``valid``, ``within_limits``, ``clearance`` (m, negative when
    penetrating, capped at max_distance), the colliding pairs, the closest
    pair and its witness points (n x 3, NaN where nothing was within reach)."""

    valid: np.ndarray
    within_limits: np.ndarray
    clearance: np.ndarray
    colliding: List[List[str]]
    closest_pair: List[str]
    robot_points: np.ndarray
    obstacle_points: np.ndarray

    @classmethod
    def from_proto(cls, reply: planning_pb2.CheckStateResponse) -> "StateChecks":
        s = reply.states
        return cls(
            valid=np.array([c.valid for c in s], dtype=bool),
            within_limits=np.array([c.within_limits for c in s], dtype=bool),
            clearance=np.array([c.clearance for c in s], dtype=float),
            colliding=[list(c.colliding) for c in s],
            closest_pair=[c.closest_pair for c in s],
            robot_points=np.array([_vec(c.robot_point, c.HasField("robot_point")) for c in s]).reshape(-1, 3),
            obstacle_points=np.array([_vec(c.obstacle_point, c.HasField("obstacle_point")) for c in s]).reshape(-1, 3),
        )

    def __repr__(self) -> str:
        return f"StateChecks({int(self.valid.sum())}/{len(self.valid)} valid, min clearance {self.clearance.min(initial=np.inf):.4f} m)"


def _vec(v: Any, present: bool) -> List[float]:
    return [v.x, v.y, v.z] if present else [np.nan] * 3


__all__ = ["ALGORITHMS", "Box", "Capsule", "Cylinder", "Mesh", "Obstacle", "OctreeObstacle", "Plan", "Sphere",
           "StateChecks", "TIMING_METHODS", "TimedTrajectory", "scene_to_proto", "timing_options"]


def __getattr__(name: str) -> Any:
    """The client mixins of earlier releases: the classes that now hold their methods."""
    if name == "PlanningMixin":
        from .client import Client

        return Client
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
