"""Mobile robots: wheel kinematics, controller steps and simulated runs.

``client.mobile`` is a :class:`Mobile` namespace:

>>> with kinplan.Client() as c:                                   # doctest: +SKIP
...     run = c.mobile.navigate(chassis="omni", start=(0, 0, 0), goal=(5, 2),
...                             world=[{"circle": (2, 1, 0.5)}], robot_radius=0.22)
...     run.outcome, run.states[-1], run.path_length

Units: metres, radians, seconds; poses (x, y, θ) and obstacles in the world
frame, twists (vx, vy, ω) in the body frame (see proto/kinplan/v1/mobile.proto).
Chassis: "differential" (default), "omni" (OMR-III preset), "car" (MOBIL-II
preset), "tricycle"; ``chassis_params`` overrides their dimensions and limits.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .v1 import mobile_pb2

#: Chassis names and their proto messages (aliases: the presets' names).
CHASSIS = {
    "differential": "differential",
    "diff": "differential",
    "omni": "omni",
    "omr_iii": "omni",
    "car": "car",
    "mobil_ii": "car",
    "tricycle": "tricycle",
}

#: Controller names.
CONTROLLERS = {
    "lyapunov": mobile_pb2.CONTROLLER_LYAPUNOV,
    "pure_pursuit": mobile_pb2.CONTROLLER_PURE_PURSUIT,
    "goal_seeking": mobile_pb2.CONTROLLER_GOAL_SEEKING,
    "shortest": mobile_pb2.CONTROLLER_SHORTEST_PATH,
    "shortest_path": mobile_pb2.CONTROLLER_SHORTEST_PATH,
    "vector_distance": mobile_pb2.CONTROLLER_VECTOR_DISTANCE,
}

#: Navigators of :meth:`Mobile.navigate`.
NAVIGATORS = {
    "vector_distance": mobile_pb2.NAVIGATOR_VECTOR_DISTANCE,
    "grid_astar": mobile_pb2.NAVIGATOR_GRID_ASTAR,
}

_MODE_LETTERS = {
    mobile_pb2.NAV_MODE_ROTATE: "R",
    mobile_pb2.NAV_MODE_LOCK: "L",
    mobile_pb2.NAV_MODE_TRACK: "T",
}

_FOLLOW_KEYS = ("switching_distance", "goal_tolerance", "heading_tolerance")
_GAIN_GROUPS = {
    "lyapunov": ("lyapunov", mobile_pb2.LyapunovGains),
    "pure_pursuit": ("pure_pursuit", mobile_pb2.PurePursuitGains),
    "goal_seeking": ("steering", mobile_pb2.SteeringGains),
    "shortest": ("steering", mobile_pb2.SteeringGains),
    "shortest_path": ("steering", mobile_pb2.SteeringGains),
}

Obstacle = Union[Mapping[str, Any], Tuple[float, float, float]]


def _xy(p: Sequence[float]) -> mobile_pb2.Point2D:
    return mobile_pb2.Point2D(x=float(p[0]), y=float(p[1]))


def _pose(p: Sequence[float]) -> mobile_pb2.Pose2D:
    if len(p) != 3:
        raise ValueError(f"a pose is (x, y, theta), got {len(p)} values")
    return mobile_pb2.Pose2D(x=float(p[0]), y=float(p[1]), theta=float(p[2]))


def chassis_to_proto(chassis: str, params: Optional[Mapping[str, float]] = None) -> mobile_pb2.Chassis:
    """``"omni"`` etc. with optional parameter overrides (proto field names)."""
    try:
        kind = CHASSIS[chassis.lower()]
    except KeyError:
        raise ValueError(f"unknown chassis {chassis!r}; one of {sorted(set(CHASSIS.values()))}") from None
    msg = mobile_pb2.Chassis()
    getattr(msg, kind).SetInParent()
    for k, v in (params or {}).items():
        setattr(getattr(msg, kind), k, float(v))
    return msg


def world_to_proto(world: Optional[Iterable[Obstacle]]) -> List[mobile_pb2.Obstacle]:
    """``[{"circle": (x, y, r)}, {"polygon": [(x, y), ...]}, (x, y, r), ...]``."""
    out = []
    for i, o in enumerate(world or []):
        if isinstance(o, Mapping):
            if "circle" in o:
                x, y, r = o["circle"]
                out.append(mobile_pb2.Obstacle(circle=mobile_pb2.Circle(center=_xy((x, y)), radius=float(r))))
            elif "polygon" in o:
                out.append(mobile_pb2.Obstacle(polygon=mobile_pb2.Polygon(vertices=[_xy(v) for v in o["polygon"]])))
            else:
                raise ValueError(f"world[{i}]: give 'circle' or 'polygon'")
        else:
            x, y, r = o
            out.append(mobile_pb2.Obstacle(circle=mobile_pb2.Circle(center=_xy((x, y)), radius=float(r))))
    return out


def path_to_proto(path: Iterable[Sequence[float]]) -> List[mobile_pb2.PathNode]:
    """``[(x, y), (x, y, heading), ...]``."""
    nodes = []
    for p in path:
        n = mobile_pb2.PathNode(x=float(p[0]), y=float(p[1]))
        if len(p) > 2 and p[2] is not None:
            n.heading = float(p[2])
        nodes.append(n)
    return nodes


def _controller(name: str) -> Any:
    try:
        return CONTROLLERS[name.lower()]
    except KeyError:
        raise ValueError(f"unknown controller {name!r}; one of {sorted(CONTROLLERS)}") from None


def follow_options(controller: str, gains: Optional[Mapping[str, Any]]) -> mobile_pb2.FollowOptions:
    """Gains of ``controller`` (its proto field names) plus the follower's
    ``switching_distance``, ``goal_tolerance`` and ``heading_tolerance``."""
    opts = mobile_pb2.FollowOptions()
    group = _GAIN_GROUPS.get(controller.lower())
    for k, v in (gains or {}).items():
        if k in _FOLLOW_KEYS:
            setattr(opts, k, float(v))
        elif group is not None:
            sub = getattr(opts, group[0])
            setattr(sub, k, v)
        else:
            raise ValueError(f"controller {controller!r} takes no gain {k!r}")
    return opts


def _fill(msg: Any, values: Optional[Mapping[str, Any]]) -> Any:
    for k, v in (values or {}).items():
        if k == "turn" and isinstance(v, str):
            v = mobile_pb2.TurnPreference.Value("TURN_PREFERENCE_" + v.upper())
        setattr(msg, k, v)
    return msg


def _points(ps: Iterable[mobile_pb2.Point2D]) -> np.ndarray:
    return np.array([(p.x, p.y) for p in ps], dtype=float).reshape(-1, 2)


def _twist(t: mobile_pb2.Twist2D) -> np.ndarray:
    return np.array([t.vx, t.vy, t.omega], dtype=float)


@dataclass
class MobileRun:
    """A simulated run. ``states``: (n, 3) x, y, θ (start first);
    ``commands``: (n - 1, 3) applied vx, vy, ω; ``modes``: "R"/"L"/"T" per
    step (vector distance); ``outcome``: "REACHED", "NO_PATH", "TIMEOUT",
    "COLLISION" or "CANCELLED"; metrics in m and s (``min_clearance`` None
    without obstacles)."""

    outcome: str
    states: np.ndarray
    commands: np.ndarray
    modes: List[str]
    hit_points: np.ndarray
    leave_points: np.ndarray
    no_path_reason: Optional[str]
    collided_with: Optional[int]
    path_length: float
    time: float
    min_clearance: Optional[float]
    steps: int
    raw: Any = field(default=None, repr=False)

    def __repr__(self) -> str:
        clearance = "n/a" if self.min_clearance is None else f"{self.min_clearance:.3f} m"
        return (
            f"MobileRun(outcome={self.outcome!r}, {self.steps} steps, {self.time:.2f} s, "
            f"path {self.path_length:.2f} m, min clearance {clearance})"
        )

    @property
    def reached(self) -> bool:
        return self.outcome == "REACHED"

    @property
    def metrics(self) -> Dict[str, Any]:
        return {
            "path_length": self.path_length,
            "time": self.time,
            "min_clearance": self.min_clearance,
            "steps": self.steps,
        }

    @classmethod
    def from_proto(cls, r: mobile_pb2.MobileRun) -> "MobileRun":
        m = r.metrics
        reason = mobile_pb2.NoPathReason.Name(r.no_path_reason).removeprefix("NO_PATH_REASON_")
        return cls(
            outcome=mobile_pb2.Outcome.Name(r.outcome).removeprefix("OUTCOME_"),
            states=np.array([(s.x, s.y, s.theta) for s in r.states], dtype=float).reshape(-1, 3),
            commands=np.array([(c.vx, c.vy, c.omega) for c in r.commands], dtype=float).reshape(-1, 3),
            modes=[_MODE_LETTERS.get(k, "?") for k in r.modes],
            hit_points=_points(r.hit_points),
            leave_points=_points(r.leave_points),
            no_path_reason=None if reason == "UNSPECIFIED" else reason,
            collided_with=r.collided_with if r.HasField("collided_with") else None,
            path_length=m.path_length,
            time=m.time,
            min_clearance=m.min_clearance if m.HasField("min_clearance") else None,
            steps=m.steps,
            raw=r,
        )


@dataclass
class StepResult:
    """One controller step: ``command`` (vx, vy, ω) of the controller,
    ``applied`` after the chassis limits, ``token`` to pass to the next step,
    and for the vector-distance navigator the ``mode`` ("R"/"L"/"T"), the
    ``readings`` used, the sum ``force`` and any ``hit_point``/``leave_point``."""

    command: np.ndarray
    applied: np.ndarray
    saturation: Dict[str, Any]
    reached: bool
    token: bytes
    target_node: int
    mode: Optional[str]
    readings: np.ndarray
    force: Optional[np.ndarray]
    hit_point: Optional[np.ndarray]
    leave_point: Optional[np.ndarray]
    no_path: bool
    raw: Any = field(default=None, repr=False)


@dataclass
class WheelKinematics:
    """``twist`` (vx, vy, ω; for the inverse: the saturated twist the wheels
    realise), ``wheels`` (rad/s and rad by name: omni ``speeds``;
    differential ``left``/``right``; car ``rear_left``, ``rear_right``,
    ``steer_left``, ``steer_right``; tricycle ``speed``, ``steer``) and the
    ``saturation`` report."""

    twist: np.ndarray
    wheels: Dict[str, Any]
    saturation: Dict[str, Any]
    raw: Any = field(default=None, repr=False)


def _saturation(s: mobile_pb2.Saturation) -> Dict[str, Any]:
    return {
        "speed_scale": s.speed_scale,
        "steering_clamped": s.steering_clamped,
        "lateral_dropped": s.lateral_dropped,
    }


def _wheels_out(w: mobile_pb2.WheelState) -> Dict[str, Any]:
    kind = w.WhichOneof("kind")
    if kind is None:
        return {}
    msg = getattr(w, kind)
    if kind == "omni":
        return {"speeds": np.array(msg.speeds, dtype=float)}
    return {f.name: getattr(msg, f.name) for f in msg.DESCRIPTOR.fields}


def _wheels_in(kind: str, wheels: Mapping[str, Any]) -> mobile_pb2.WheelState:
    msg = mobile_pb2.WheelState()
    sub = getattr(msg, kind)
    sub.SetInParent()
    for k, v in wheels.items():
        if k == "speeds":
            sub.speeds.extend(float(x) for x in v)
        else:
            setattr(sub, k, float(v))
    return msg


def __getattr__(name: str) -> Any:
    """``Mobile``, the client's namespace of these calls, is in :mod:`kinplan.client`."""
    if name == "Mobile":
        from .client import Mobile

        return Mobile
    if name == "MobileMixin":  # the client mixins of earlier releases: the classes that now hold their methods
        from .client import Client

        return Client
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
