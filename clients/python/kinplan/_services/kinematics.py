"""KinematicsService: inverse kinematics (single, batch, paths, streams) and
linear solves — requests built and replies read for both clients."""
from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np
import numpy.typing as npt

from .. import _codec
from .._codec import joints, length_delimited, matrix_message
from ..kinematics import (IkBatchResult, IkOptions, IkResult, LINEAR_SOLVERS, LinearSolution, TrackResult, _choice,
                          _ik_options_field, _is_position, _target_wire, _targets, ik_args, ik_options_of_args,
                          resolve_ik_args, target_to_pose)
from ..v1 import common_pb2, kinematics_pb2
from . import Call

#: The hand-encoded IK call of the blocking client.
SOLVE_IK = "/kinplan.v1.KinematicsService/SolveIk"

_POSITION_ONLY = 4  # index of position_only in the IK arguments
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def ik_target(T: Any, args: Tuple[Any, ...]) -> Tuple[Any, Tuple[Any, ...]]:
    """A bare 3-vector target as (position, identity quaternion), and
    ``position_only`` set: a position is solved for alone."""
    if _is_position(T):
        T = (np.asarray(T, dtype=float), _IDENTITY)
        args = args[:_POSITION_ONLY] + (True,) + args[_POSITION_ONLY + 1:]
    return T, args


def ik_body(T: Any, seed: Optional[npt.ArrayLike], args: Tuple[Any, ...]) -> bytes:
    """The fields after the robot of a hand-encoded SolveIkRequest: the
    target, the seed and the options (``args`` from :func:`ik_target`,
    the encoded options cached per distinct set)."""
    if isinstance(T, np.ndarray) and T.shape == (4, 4):  # the usual target: packed in one step
        target = _codec.target_field(T)
    else:
        target = length_delimited(_codec.IK_TARGET, _target_wire(T))
    seed_field = b"" if seed is None else _codec.joints_field(_codec.IK_SEED, seed, "seed")
    return target + seed_field + _ik_options_field(*args)


def ik(T: Any, seed: Optional[npt.ArrayLike], args: Tuple[Any, ...]) -> Call[IkResult]:
    """SolveIk through the generated classes (``T`` and ``args`` from :func:`ik_target`)."""
    target = target_to_pose(T)
    seed_list = [] if seed is None else joints(seed, "seed")
    o = ik_options_of_args(args)
    return Call("kinematics", "SolveIk", IkResult.from_proto,
                build=lambda ref: kinematics_pb2.SolveIkRequest(robot=ref, target=target, seed=seed_list, options=o))


def options_of(options: Optional[IkOptions], method: Any, linear_solver: Any,
               shortcuts: Mapping[str, Any]) -> kinematics_pb2.IkOptions:
    """The IkOptions message of ``options=`` and the keyword shortcuts over it."""
    return ik_options_of_args(resolve_ik_args(options, ik_args(method, linear_solver, shortcuts)))


def _batch_result(reply: kinematics_pb2.SolveIkBatchResponse) -> IkBatchResult:
    return IkBatchResult(results=[IkResult.from_proto(r) for r in reply.results], succeeded=reply.succeeded,
                         elapsed_us=reply.elapsed_us)


def ik_batch(Ts: Any, seed: Any, o: kinematics_pb2.IkOptions) -> Call[IkBatchResult]:
    """SolveIkBatch: every target of ``Ts`` from ``seed`` (one joint vector,
    or one row per target)."""
    targets = _targets(Ts)
    seed_arr = None if seed is None else np.asarray(seed, dtype=np.float64)
    per_target = matrix_message(seed_arr) if seed_arr is not None and seed_arr.ndim == 2 else None
    seed_list = joints(seed, "seed") if seed is not None and per_target is None else []
    return Call("kinematics", "SolveIkBatch", _batch_result,
                build=lambda ref: kinematics_pb2.SolveIkBatchRequest(robot=ref, targets=targets, seed=seed_list,
                                                                     options=o, seeds=per_target))


def stream_request(robot: Any, sequence: int, T: Any, seed: Optional[List[float]], first: bool,
                   options: kinematics_pb2.IkOptions) -> kinematics_pb2.StreamIkRequest:
    """One StreamIkRequest; the first of a stream carries the robot (its URDF
    inline for a model: a stream is not resent) and the options."""
    msg = kinematics_pb2.StreamIkRequest(sequence=sequence, target=target_to_pose(T))
    if first:
        msg.robot.CopyFrom(robot._ref(inline=robot.urdf_text is not None))
        msg.options.CopyFrom(options)
    if seed is not None:
        msg.seed.extend(seed)
    return msg


def stream_answer(reply: kinematics_pb2.StreamIkResponse) -> IkResult:
    """The :class:`IkResult` of a StreamIk answer, its sequence number set."""
    out = IkResult.from_proto(reply.result)
    out.sequence = reply.sequence
    return out


def track(poses: Any, seed: Optional[npt.ArrayLike], line: Optional[Mapping[str, Any]],
          circle: Optional[Mapping[str, Any]], o: kinematics_pb2.IkOptions, stop_on_failure: bool) -> Call[TrackResult]:
    """TrackPath: a Cartesian path (``poses``, ``line`` or ``circle``)
    followed step by step from ``seed``."""
    seed_list = [] if seed is None else joints(seed, "seed")
    kwargs: Dict[str, Any] = {}
    if poses is not None:
        kwargs["poses"] = _targets(poses)
    if line is not None:
        spec = dict(line)
        lp = kinematics_pb2.LinePath(steps=int(spec.pop("steps", 0)))
        if spec.get("start") is not None:
            lp.start.CopyFrom(target_to_pose(spec["start"]))
        spec.pop("start", None)
        if spec.get("end") is not None:
            lp.end.CopyFrom(target_to_pose(spec["end"]))
        spec.pop("end", None)
        if spec:
            raise ValueError(f"unknown line keys {sorted(spec)}")
        kwargs["line"] = lp
    if circle is not None:
        spec = dict(circle)
        cp = kinematics_pb2.CirclePath(angle_step=float(spec.pop("angle_step", 0.0)), steps=int(spec.pop("steps", 0)))
        if spec.get("start") is not None:
            cp.start.CopyFrom(target_to_pose(spec["start"]))
        spec.pop("start", None)
        for key in ("centre", "normal"):
            value = spec.pop(key, spec.pop("center", None) if key == "centre" else None)
            if value is not None:
                v = np.asarray(value, dtype=float).ravel()
                getattr(cp, key).CopyFrom(common_pb2.Vec3(x=v[0], y=v[1], z=v[2]))
        if spec:
            raise ValueError(f"unknown circle keys {sorted(spec)}")
        kwargs["circle"] = cp

    def build(ref: common_pb2.RobotRef) -> kinematics_pb2.TrackPathRequest:
        return kinematics_pb2.TrackPathRequest(
            robot=ref, seed=seed_list, options=o, stop_on_failure=stop_on_failure, **kwargs
        )

    return Call("kinematics", "TrackPath", TrackResult.from_proto, build=build)


def solve_linear(A: Any, b: Any, method: Optional[str], max_iterations: Optional[int],
                 tolerance: Optional[float], relative_tolerance: Optional[float], rng_seed: int,
                 history: bool, singular_value_tolerance: Optional[float]) -> Call[LinearSolution]:
    """SolveLinearSystem: ``A x = b``."""
    a = np.asarray(A, dtype=float)
    if a.ndim != 2:
        raise ValueError(f"A must be two-dimensional, got shape {a.shape}")
    rhs = np.asarray(b, dtype=float).ravel()
    request = kinematics_pb2.SolveLinearSystemRequest(
        a=matrix_message(a),
        b=rhs.tolist(),
        method=_choice(LINEAR_SOLVERS, method, "method"),
        max_iterations=int(max_iterations or 0),
        rng_seed=int(rng_seed),
        record_history=bool(history),
    )
    if tolerance is not None:
        request.tolerance = float(tolerance)
    if relative_tolerance is not None:
        request.relative_tolerance = float(relative_tolerance)
    if singular_value_tolerance is not None:
        request.singular_value_tolerance = float(singular_value_tolerance)
    return Call("kinematics", "SolveLinearSystem", _linear_solution, request=request)


def _linear_solution(reply: kinematics_pb2.SolveLinearSystemResponse) -> LinearSolution:
    """The :class:`LinearSolution` of a SolveLinearSystem reply."""
    return LinearSolution(
        x=np.asarray(reply.x, dtype=float),
        residual_norm=reply.residual_norm,
        iterations=reply.iterations,
        status=kinematics_pb2.LinearSolveStatus.Name(reply.status).removeprefix("LINEAR_SOLVE_STATUS_").lower(),
        history=np.asarray(reply.residual_history, dtype=float),
        elapsed_us=reply.elapsed_us,
    )


