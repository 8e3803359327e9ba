"""PlanningService: plans and state checks — requests built and replies
read for both clients."""
from __future__ import annotations

from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Union

import numpy as np

from .._codec import joints
from ..planning import ALGORITHMS, Obstacle, Plan, StateChecks, TimedTrajectory, _pose, scene_to_proto, timing_options
from ..v1 import common_pb2, planning_pb2
from . import Call


def _plan_build(
    start: Any,
    goal: Any,
    pose: Any,
    algorithm: str,
    scene: Optional[Sequence[Obstacle]],
    seed: int,
    time_budget: Optional[float],
    motion_resolution: Optional[float],
    padded_motion: bool,
    return_cost_history: bool,
    stomp: Optional[Mapping[str, Any]],
    cartesian: Optional[Mapping[str, Any]],
    rrt_connect: Optional[Mapping[str, Any]],
    timing: Optional[Mapping[str, Any]],
) -> Callable[[common_pb2.RobotRef], planning_pb2.PlanRequest]:
    """The PlanRequest of ``robot.plan``'s arguments, as a function of the robot's reference."""
    if (goal is None) == (pose is None):
        raise ValueError("give exactly one of goal= (joints) or pose= (4x4 tool pose)")
    if algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm must be one of {sorted(ALGORITHMS)}, got {algorithm!r}")
    options = planning_pb2.PlanOptions(
        stomp=planning_pb2.StompOptions(**dict(stomp or {})),
        cartesian=planning_pb2.CartesianOptions(**dict(cartesian or {})),
        rrt_connect=planning_pb2.RrtConnectOptions(**dict(rrt_connect or {})),
        timing=timing_options(timing),
        return_cost_history=return_cost_history,
    )
    if time_budget is not None:
        options.time_budget = float(time_budget)
    if motion_resolution is not None:
        options.motion_resolution = float(motion_resolution)
    options.padded_motion = bool(padded_motion)
    proto_scene = scene_to_proto(scene)

    def build(ref: common_pb2.RobotRef) -> planning_pb2.PlanRequest:
        req = planning_pb2.PlanRequest(
            robot=ref,
            start=joints(start, "start"),
            scene=proto_scene,
            algorithm=ALGORITHMS[algorithm],
            options=options,
            seed=int(seed),
        )
        if goal is not None:
            req.goal_joints.positions.extend(joints(goal, "goal"))
        else:
            req.goal_pose.CopyFrom(_pose(pose))
        return req

    return build


def plan(start: Any, goal: Any, pose: Any, algorithm: str, scene: Optional[Sequence[Obstacle]], seed: int,
         time_budget: Optional[float], motion_resolution: Optional[float], padded_motion: bool,
         return_cost_history: bool, stomp: Optional[Mapping[str, Any]], cartesian: Optional[Mapping[str, Any]],
         rrt_connect: Optional[Mapping[str, Any]], timing: Optional[Mapping[str, Any]]) -> Call[Plan]:
    """Plan: from ``start`` to ``goal`` (joints) or ``pose`` (4x4 tool pose) among ``scene``."""
    build = _plan_build(start, goal, pose, algorithm, scene, seed, time_budget, motion_resolution, padded_motion,
                        return_cost_history, stomp, cartesian, rrt_connect, timing)
    return Call("planning", "Plan", Plan.from_proto, build=build)


def plan_stream(start: Any, goal: Any, pose: Any, algorithm: str, scene: Optional[Sequence[Obstacle]],
                seed: int, options: Dict[str, Any]) -> Call[Union[np.ndarray, Plan]]:
    """PlanStream (`options` those of :func:`plan`; TypeError on others):
    each message read as a trajectory (waypoints x dof), the last as the :class:`Plan`."""
    options = dict(options)
    build = _plan_build(
        start, goal, pose, algorithm, scene, seed, options.pop("time_budget", None),
        options.pop("motion_resolution", None), options.pop("padded_motion", False),
        options.pop("return_cost_history", True),
        options.pop("stomp", None), options.pop("cartesian", None), options.pop("rrt_connect", None),
        options.pop("timing", None),
    )
    if options:
        raise TypeError(f"unknown options: {sorted(options)}")
    return Call("planning", "PlanStream", _plan_stream_message, build=build, streaming=True)


def _plan_stream_message(m: planning_pb2.PlanStreamResponse) -> Union[np.ndarray, Plan]:
    """The trajectory (waypoints x dof) or final :class:`Plan` a PlanStream message carries."""
    if m.HasField("result"):
        return Plan.from_proto(m.result)
    return np.array([list(p.positions) for p in m.trajectory.points], dtype=float)


def check(qs: Any, scene: Optional[Sequence[Obstacle]], max_distance: float) -> Call[StateChecks]:
    """CheckState: validity and clearance of each row of ``qs`` (n x dof) in ``scene``."""
    arr = np.asarray(qs, dtype=float)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2:
        raise ValueError(f"qs must be n x dof, got shape {arr.shape}")
    proto_scene = scene_to_proto(scene)
    states = arr.tolist()

    def build(ref: common_pb2.RobotRef) -> planning_pb2.CheckStateRequest:
        return planning_pb2.CheckStateRequest(
            robot=ref, states=[planning_pb2.JointState(positions=row) for row in states], scene=proto_scene,
            max_distance=float(max_distance))

    return Call("planning", "CheckState", StateChecks.from_proto, build=build)


def retime(path: Any, timing: Mapping[str, Any]) -> Call[TimedTrajectory]:
    """Retime: the joint path ``path`` (n x dof) timed by ``timing`` (TimingOptions fields)."""
    arr = np.asarray(path, dtype=float)
    if arr.ndim != 2:
        raise ValueError(f"path must be n x dof, got shape {arr.shape}")
    options = timing_options({k: v for k, v in timing.items() if v is not None})
    rows = arr.tolist()

    def build(ref: common_pb2.RobotRef) -> planning_pb2.RetimeRequest:
        return planning_pb2.RetimeRequest(
            robot=ref, waypoints=[planning_pb2.JointState(positions=row) for row in rows], timing=options)

    return Call("planning", "Retime", TimedTrajectory.from_proto, build=build)
