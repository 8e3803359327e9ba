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

from .v1 import mobile_pb2, mobile_pb2_grpc

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


def _wheels_request(chassis: str, twist: Optional[Sequence[float]], wheels: Optional[Mapping[str, Any]],
                    chassis_params: Optional[Mapping[str, float]]) -> mobile_pb2.WheelKinematicsRequest:
    """The WheelKinematicsRequest of :meth:`Mobile.wheels`'s arguments
    (shared by the blocking and asyncio clients)."""
    if (twist is None) == (wheels is None):
        raise ValueError("give exactly one of twist or wheels=")
    c = chassis_to_proto(chassis, chassis_params)
    req = mobile_pb2.WheelKinematicsRequest(chassis=c)
    if twist is not None:
        req.twist.CopyFrom(mobile_pb2.Twist2D(vx=float(twist[0]), vy=float(twist[1]), omega=float(twist[2])))
    else:
        req.wheels.CopyFrom(_wheels_in(c.WhichOneof("kind"), wheels or {}))
    return req


def _wheels_reply(r: mobile_pb2.WheelKinematicsResponse) -> WheelKinematics:
    """The :class:`WheelKinematics` of a WheelKinematics reply."""
    return WheelKinematics(_twist(r.twist), _wheels_out(r.wheels), _saturation(r.saturation), raw=r)


def _step_request(
    state: Sequence[float],
    chassis: str,
    controller: str,
    path: Optional[Iterable[Sequence[float]]],
    goal: Optional[Sequence[float]],
    gains: Optional[Mapping[str, Any]],
    params: Optional[Mapping[str, Any]],
    sensors: Optional[Mapping[str, Any]],
    readings: Optional[Iterable[float]],
    world: Optional[Iterable[Obstacle]],
    robot_radius: Optional[float],
    seed: int,
    dt: Optional[float],
    token: Union[bytes, StepResult, None],
    chassis_params: Optional[Mapping[str, float]],
) -> mobile_pb2.ControlStepRequest:
    """The ControlStepRequest of :meth:`Mobile.step`'s arguments."""
    if isinstance(token, StepResult):
        token = token.token
    req = mobile_pb2.ControlStepRequest(
        chassis=chassis_to_proto(chassis, chassis_params),
        state=_pose(state),
        controller=_controller(controller),
        path=path_to_proto(path or []),
        follow=follow_options(controller, gains) if controller != "vector_distance" else None,
        vdf=_fill(mobile_pb2.VectorDistanceParams(), params),
        sensors=_fill(mobile_pb2.RangeSensorParams(), sensors),
        readings=[float(r) for r in (readings if readings is not None else [])],
        world=world_to_proto(world),
        seed=seed,
        state_token=token or b"",
    )
    if goal is not None:
        req.goal.CopyFrom(_xy(goal))
    if robot_radius is not None:
        req.robot_radius = float(robot_radius)
    if dt is not None:
        req.dt = float(dt)
    return req


def _step_reply(req: mobile_pb2.ControlStepRequest, r: mobile_pb2.ControlStepResponse) -> StepResult:
    """The :class:`StepResult` of the ControlStep reply `r` to `req`."""
    vd = req.controller == mobile_pb2.CONTROLLER_VECTOR_DISTANCE
    return StepResult(
        command=_twist(r.command),
        applied=_twist(r.applied),
        saturation=_saturation(r.saturation),
        reached=r.reached,
        token=r.state_token,
        target_node=r.target_node,
        mode=_MODE_LETTERS.get(r.mode) if vd else None,
        readings=np.array(r.readings, dtype=float),
        force=np.array([r.force.x, r.force.y]) if vd else None,
        hit_point=np.array([r.hit_point.x, r.hit_point.y]) if r.HasField("hit_point") else None,
        leave_point=np.array([r.leave_point.x, r.leave_point.y]) if r.HasField("leave_point") else None,
        no_path=r.no_path,
        raw=r,
    )


def _sim(robot_radius: Optional[float], dt: Optional[float], max_time: Optional[float]) -> mobile_pb2.SimOptions:
    sim = mobile_pb2.SimOptions()
    if robot_radius is not None:
        sim.robot_radius = float(robot_radius)
    if dt is not None:
        sim.dt = float(dt)
    if max_time is not None:
        sim.max_time = float(max_time)
    return sim


def _follow_request(
    chassis: str,
    start: Sequence[float],
    path: Iterable[Sequence[float]],
    controller: str,
    gains: Optional[Mapping[str, Any]],
    world: Optional[Iterable[Obstacle]],
    robot_radius: Optional[float],
    dt: Optional[float],
    max_time: Optional[float],
    chassis_params: Optional[Mapping[str, float]],
) -> mobile_pb2.FollowPathRequest:
    """The FollowPathRequest of :meth:`Mobile.follow`'s arguments (the reply
    reads as :meth:`MobileRun.from_proto`)."""
    return mobile_pb2.FollowPathRequest(
        chassis=chassis_to_proto(chassis, chassis_params),
        start=_pose(start),
        path=path_to_proto(path),
        controller=_controller(controller),
        follow=follow_options(controller, gains),
        world=world_to_proto(world),
        sim=_sim(robot_radius, dt, max_time),
    )


def _navigate_request(
    chassis: str,
    start: Sequence[float],
    goal: Sequence[float],
    world: Optional[Iterable[Obstacle]],
    robot_radius: Optional[float],
    navigator: str,
    params: Optional[Mapping[str, Any]],
    sensors: Optional[Mapping[str, Any]],
    seed: int,
    controller: str,
    gains: Optional[Mapping[str, Any]],
    astar: Optional[Mapping[str, Any]],
    dt: Optional[float],
    max_time: Optional[float],
    chassis_params: Optional[Mapping[str, float]],
) -> mobile_pb2.NavigateRequest:
    """The NavigateRequest of :meth:`Mobile.navigate`'s arguments (the reply
    reads as :meth:`MobileRun.from_proto`)."""
    try:
        nav = NAVIGATORS[navigator]
    except KeyError:
        raise ValueError(f"unknown navigator {navigator!r}; one of {sorted(NAVIGATORS)}") from None
    return mobile_pb2.NavigateRequest(
        chassis=chassis_to_proto(chassis, chassis_params),
        start=_pose(start),
        goal=_xy(goal),
        world=world_to_proto(world),
        sim=_sim(robot_radius, dt, max_time),
        navigator=nav,
        sensors=_fill(mobile_pb2.RangeSensorParams(), sensors),
        vdf=_fill(mobile_pb2.VectorDistanceParams(), params),
        seed=seed,
        astar=_fill(mobile_pb2.GridAstarOptions(), astar),
        follow=follow_options(controller, gains),
        controller=_controller(controller),
    )


class Mobile:
    """The MobileService calls; reach it as ``client.mobile``."""

    def __init__(self, client: Any):
        self._client = client
        self._stub = mobile_pb2_grpc.MobileServiceStub(client._channel)

    def wheels(
        self,
        chassis: str = "differential",
        twist: Optional[Sequence[float]] = None,
        *,
        wheels: Optional[Mapping[str, Any]] = None,
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> WheelKinematics:
        """Inverse kinematics of ``twist`` = (vx, vy, ω), or forward kinematics
        of ``wheels`` (a dict as in :class:`WheelKinematics`)."""
        req = _wheels_request(chassis, twist, wheels, chassis_params)
        return _wheels_reply(self._client._call(self._stub.WheelKinematics, req, timeout))

    def step(
        self,
        state: Sequence[float],
        *,
        chassis: str = "differential",
        controller: str = "lyapunov",
        path: Optional[Iterable[Sequence[float]]] = None,
        goal: Optional[Sequence[float]] = None,
        gains: Optional[Mapping[str, Any]] = None,
        params: Optional[Mapping[str, Any]] = None,
        sensors: Optional[Mapping[str, Any]] = None,
        readings: Optional[Iterable[float]] = None,
        world: Optional[Iterable[Obstacle]] = None,
        robot_radius: Optional[float] = None,
        seed: int = 0,
        dt: Optional[float] = None,
        token: Union[bytes, StepResult, None] = b"",
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> StepResult:
        """One stateless controller step. Path followers take ``path`` and
        ``gains``; "vector_distance" takes ``goal``, ``params`` (navigator),
        ``sensors`` and either ``readings`` (gaps from the rim, m) or a
        ``world`` to sense. Pass the previous result (or its ``token``) as
        ``token=`` to continue; empty starts a fresh controller."""
        req = _step_request(state, chassis, controller, path, goal, gains, params, sensors, readings, world,
                            robot_radius, seed, dt, token, chassis_params)
        return _step_reply(req, self._client._call(self._stub.ControlStep, req, timeout))

    def follow(
        self,
        chassis: str = "differential",
        start: Sequence[float] = (0.0, 0.0, 0.0),
        path: Iterable[Sequence[float]] = (),
        controller: str = "lyapunov",
        gains: Optional[Mapping[str, Any]] = None,
        *,
        world: Optional[Iterable[Obstacle]] = None,
        robot_radius: Optional[float] = None,
        dt: Optional[float] = None,
        max_time: Optional[float] = None,
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> MobileRun:
        """Simulates ``controller`` along ``path`` ([(x, y[, θ]), ...]; a
        heading is honoured on the last node) from ``start`` = (x, y, θ),
        optionally among obstacles (collisions end the run)."""
        req = _follow_request(chassis, start, path, controller, gains, world, robot_radius, dt, max_time,
                              chassis_params)
        return MobileRun.from_proto(self._client._call(self._stub.FollowPath, req, timeout))

    def navigate(
        self,
        chassis: str = "differential",
        start: Sequence[float] = (0.0, 0.0, 0.0),
        goal: Sequence[float] = (0.0, 0.0),
        world: Optional[Iterable[Obstacle]] = None,
        robot_radius: Optional[float] = None,
        *,
        navigator: str = "vector_distance",
        params: Optional[Mapping[str, Any]] = None,
        sensors: Optional[Mapping[str, Any]] = None,
        seed: int = 0,
        controller: str = "pure_pursuit",
        gains: Optional[Mapping[str, Any]] = None,
        astar: Optional[Mapping[str, Any]] = None,
        dt: Optional[float] = None,
        max_time: Optional[float] = None,
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> MobileRun:
        """Simulates navigation from ``start`` to ``goal`` = (x, y) among
        ``world``: the vector-distance navigator (``params``, ``sensors``,
        noise ``seed``) or ``navigator="grid_astar"`` (``astar`` options, then
        ``controller`` with ``gains`` follows the grid path)."""
        req = _navigate_request(chassis, start, goal, world, robot_radius, navigator, params, sensors, seed,
                                controller, gains, astar, dt, max_time, chassis_params)
        return MobileRun.from_proto(self._client._call(self._stub.Navigate, req, timeout))


class MobileMixin:
    """Adds the :attr:`mobile` namespace to :class:`kinplan.Client`."""

    @property
    def mobile(self) -> Mobile:
        m = self.__dict__.get("_mobile")
        if m is None:
            m = Mobile(self)
            self.__dict__["_mobile"] = m
        return m
