"""MobileService: wheel kinematics, controller steps and simulated runs —
requests built and replies read for both clients."""
from __future__ import annotations

from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from ..mobile import (_MODE_LETTERS, NAVIGATORS, MobileRun, Obstacle, StepResult, WheelKinematics, _controller, _fill,
                      _pose, _saturation, _twist, _wheels_in, _wheels_out, _xy, chassis_to_proto, follow_options,
                      path_to_proto, world_to_proto)
from ..v1 import mobile_pb2
from . import Call


def wheels(chassis: str, twist: Optional[Sequence[float]], wheels: Optional[Mapping[str, Any]],
           chassis_params: Optional[Mapping[str, float]]) -> Call[WheelKinematics]:
    """WheelKinematics: the wheels of a body ``twist``, or the twist of ``wheels``."""
    if (twist is None) == (wheels is None):
        raise ValueError("give exactly one of twist or wheels=")
    c = chassis_to_proto(chassis, chassis_params)
    req = mobile_pb2.WheelKinematicsRequest(chassis=c)
    if twist is not None:
        req.twist.CopyFrom(mobile_pb2.Twist2D(vx=float(twist[0]), vy=float(twist[1]), omega=float(twist[2])))
    else:
        req.wheels.CopyFrom(_wheels_in(c.WhichOneof("kind"), wheels or {}))
    return Call("mobile", "WheelKinematics", _wheels_reply, request=req)


def _wheels_reply(r: mobile_pb2.WheelKinematicsResponse) -> WheelKinematics:
    """The :class:`WheelKinematics` of a WheelKinematics reply."""
    return WheelKinematics(_twist(r.twist), _wheels_out(r.wheels), _saturation(r.saturation), raw=r)


def step(
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
) -> Call[StepResult]:
    """ControlStep: one stateless controller step (its memory in ``token``)."""
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
    return Call("mobile", "ControlStep", lambda r: _step_reply(req, r), request=req)


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


def follow(
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
) -> Call[MobileRun]:
    """FollowPath: a simulated run of a path follower."""
    req = mobile_pb2.FollowPathRequest(
        chassis=chassis_to_proto(chassis, chassis_params),
        start=_pose(start),
        path=path_to_proto(path),
        controller=_controller(controller),
        follow=follow_options(controller, gains),
        world=world_to_proto(world),
        sim=_sim(robot_radius, dt, max_time),
    )
    return Call("mobile", "FollowPath", MobileRun.from_proto, request=req)


def navigate(
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
) -> Call[MobileRun]:
    """Navigate: a simulated run from a start to a goal among obstacles."""
    try:
        nav = NAVIGATORS[navigator]
    except KeyError:
        raise ValueError(f"unknown navigator {navigator!r}; one of {sorted(NAVIGATORS)}") from None
    req = mobile_pb2.NavigateRequest(
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
    return Call("mobile", "Navigate", MobileRun.from_proto, request=req)
