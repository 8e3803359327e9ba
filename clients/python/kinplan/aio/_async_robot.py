"""``kinplan.aio.AsyncRobot``: the robot handle for asyncio, with the
arguments, results and errors of :class:`kinplan.Robot`. Requests and replies
are built and read by :mod:`kinplan._services`; each method only awaits its
call."""
from __future__ import annotations

from typing import (TYPE_CHECKING, Any, AsyncIterator, Callable, Dict, Iterable, Literal, Mapping, Optional, Sequence,
                    Union)

import grpc
import grpc.aio
import numpy as np
import numpy.typing as npt

from .._codec import joints
from .._services import Call
from .._services import kinematics as _kinematics
from .._services import planning as _planning
from .._services import robot as _robot
from .._services import scoring as _scoring
from .._services.robot import RobotRefs
from ..description import JointLimits, RobotDescription
from ..errors import KinplanError, error_for
from ..kinematics import (IkBatchResult, IkMethodName, IkOptions, IkResult, LinearSolverName, TrackResult,
                          resolve_ik_args)
from ..planning import Obstacle, Plan, StateChecks, TimedTrajectory
from ..scoring import Comparison, Scores, Trajectory, _check_trajectory_limits
from ..v1 import common_pb2, kinematics_pb2

if TYPE_CHECKING:
    from . import Client


class AsyncRobot(RobotRefs):
    """A robot on a server, for asyncio: the model-id rule of
    :class:`kinplan.Robot` (inline URDFs sent once, resent on NOT_FOUND)."""

    def __init__(self, client: "Client", *, name: Optional[str], urdf: Optional[str], base_link: str,
                 tip_link: str, strict: bool = False):
        self.client = client
        self.name, self.urdf_text = name, urdf
        self.mesh_files: Dict[str, bytes] = {}
        self.srdf_text: Optional[str] = None
        self.group = ""
        self.held_joints: Dict[str, float] = {}
        self.base_link, self.tip_link = base_link, tip_link
        self.strict = strict
        self.model_id: bytes = b""

    def __repr__(self) -> str:
        return f"kinplan.aio.AsyncRobot({self.name or 'urdf'!r})"

    async def _call(self, method: Callable[..., Any], build: Callable[[common_pb2.RobotRef], Any],
                    timeout: Optional[float]) -> Any:
        try:
            reply = await self.client._call(method, build(self._ref()), timeout)
        except KinplanError as err:
            if not (err.code == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise
            self.model_id = b""
            reply = await self.client._call(method, build(self._ref(inline=True)), timeout)
        self._learn(reply)
        return reply

    async def _run(self, call: Call[Any], timeout: Optional[float]) -> Any:
        """Awaits a :class:`kinplan._services.Call` about this robot."""
        assert call.build is not None
        return call.read(await self._call(self.client._stubs.method(call), call.build, timeout))

    async def _limits(self) -> JointLimits:
        cache = self.client.__dict__.setdefault("_limits_cache", {})
        key = self.limits_key()
        if key not in cache:
            cache[key] = JointLimits(await self.describe())
        limits: JointLimits = cache[key]
        return limits

    async def check_limits(self, q: Any, field_name: str = "q") -> None:
        """As :meth:`kinplan.Robot.check_limits` (warns, or raises when strict)."""
        (await self._limits()).check(q, field_name, self.strict)

    async def describe(self, *, timeout: Optional[float] = None) -> RobotDescription:
        """As :meth:`kinplan.Robot.describe`."""
        out: RobotDescription = await self._run(_robot.describe(), timeout)
        return out

    async def urdf(self, *, keep_capsules: bool = False, timeout: Optional[float] = None) -> str:
        """As :meth:`kinplan.Robot.urdf`."""
        if self.urdf_text is not None:
            return self.urdf_text
        out: str = await self._run(_robot.urdf(keep_capsules), timeout)
        return out

    async def fk(self, q: npt.ArrayLike, *, links: bool = False, timeout: Optional[float] = None) -> Any:
        """As :meth:`kinplan.Robot.fk`."""
        positions = joints(q)
        await self.check_limits(positions)
        return await self._run(_robot.fk(positions, links), timeout)

    async def fk_batch(self, qs: Any, *, jacobians: bool = False, timeout: Optional[float] = None) -> Any:
        """As :meth:`kinplan.Robot.fk_batch`."""
        arr = _robot.batch_states(qs)
        await self.check_limits(arr, "qs")
        return await self._run(_robot.fk_batch(arr, jacobians), timeout)

    async def jacobian(self, q: npt.ArrayLike, *, timeout: Optional[float] = None) -> np.ndarray:
        """As :meth:`kinplan.Robot.jacobian`."""
        positions = joints(q)
        await self.check_limits(positions)
        out: np.ndarray = await self._run(_robot.jacobian(positions), timeout)
        return out

    async def ik(
        self,
        T: Any,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[IkMethodName] = "lm",
        linear_solver: Optional[LinearSolverName] = "svd",
        *,
        options: Optional[IkOptions] = None,
        max_restarts: Optional[int] = None,
        num_solutions: Optional[int] = None,
        position_tolerance: Optional[float] = None,
        orientation_tolerance: Optional[float] = None,
        position_only: bool = False,
        max_iterations: Optional[int] = None,
        damping: Optional[float] = None,
        rng_seed: int = 0,
        joint_limits: Optional[Literal["clamp", "ignore"]] = None,
        time_budget: Optional[float] = None,
        adaptive_damping: Optional[bool] = None,
        max_step: Optional[float] = None,
        distinct_tolerance: Optional[float] = None,
        rlxa_max_iterations: Optional[int] = None,
        history: bool = False,
        hold_configuration: Optional[bool] = None,
        nearest_turn_only: bool = False,
        redundant_joint: Optional[int] = None,
        analytic_start: bool = False,
        search_redundant: bool = False,
        redundant_samples: Optional[int] = None,
        search_samples: Optional[int] = None,
        timeout: Optional[float] = None,
    ) -> IkResult:
        """As :meth:`kinplan.Robot.ik`."""
        args = (method, linear_solver, position_tolerance, orientation_tolerance, position_only, max_iterations,
                damping, max_restarts, num_solutions, rng_seed, joint_limits, time_budget, adaptive_damping,
                max_step, distinct_tolerance, rlxa_max_iterations, history, hold_configuration, nearest_turn_only,
                redundant_joint, analytic_start, search_redundant, redundant_samples, search_samples)
        T, args = _kinematics.ik_target(T, resolve_ik_args(options, args))
        out: IkResult = await self._run(_kinematics.ik(T, seed, args), timeout)
        return out

    async def ik_batch(self, Ts: Any, seed: Optional[npt.ArrayLike] = None, method: Optional[str] = "lm",
                       linear_solver: Optional[str] = "svd", *, options: Optional[IkOptions] = None,
                       timeout: Optional[float] = None, **shortcuts: Any) -> IkBatchResult:
        """As :meth:`kinplan.Robot.ik_batch`."""
        o = _kinematics.options_of(options, method, linear_solver, shortcuts)
        out: IkBatchResult = await self._run(_kinematics.ik_batch(Ts, seed, o), timeout)
        return out

    async def track(self, poses: Any = None, seed: Optional[npt.ArrayLike] = None, *,
                    line: Optional[Mapping[str, Any]] = None, circle: Optional[Mapping[str, Any]] = None,
                    method: Optional[str] = "lm", linear_solver: Optional[str] = "svd", stop_on_failure: bool = False,
                    options: Optional[IkOptions] = None, timeout: Optional[float] = None,
                    **shortcuts: Any) -> TrackResult:
        """As :meth:`kinplan.Robot.track`."""
        o = _kinematics.options_of(options, method, linear_solver, shortcuts)
        out: TrackResult = await self._run(_kinematics.track(poses, seed, line, circle, o, stop_on_failure), timeout)
        return out

    def stream_ik(self, seed: Optional[npt.ArrayLike] = None, method: Optional[str] = "lm",
                  linear_solver: Optional[str] = "svd", *, options: Optional[IkOptions] = None,
                  timeout: Optional[float] = None, **shortcuts: Any) -> "AsyncIkStream":
        """An ``async with`` StreamIk session (as :meth:`kinplan.Robot.stream_ik`)."""
        return AsyncIkStream(self, _kinematics.options_of(options, method, linear_solver, shortcuts), seed, timeout)

    async def plan(self, start: Any, goal: Any = None, *, pose: Any = None, algorithm: str = "rrt_connect",
                   scene: Optional[Sequence[Obstacle]] = None, seed: int = 0, time_budget: Optional[float] = None,
                   motion_resolution: Optional[float] = None, padded_motion: bool = False,
                   return_cost_history: bool = True, stomp: Optional[Mapping[str, Any]] = None,
                   cartesian: Optional[Mapping[str, Any]] = None, rrt_connect: Optional[Mapping[str, Any]] = None,
                   timing: Optional[Mapping[str, Any]] = None, timeout: Optional[float] = None) -> Plan:
        """As :meth:`kinplan.Robot.plan`."""
        call = _planning.plan(start, goal, pose, algorithm, scene, seed, time_budget, motion_resolution,
                              padded_motion, return_cost_history, stomp, cartesian, rrt_connect, timing)
        out: Plan = await self._run(call, timeout)
        return out

    async def plan_stream(self, start: Any, goal: Any = None, *, pose: Any = None, algorithm: str = "stomp",
                          scene: Optional[Sequence[Obstacle]] = None, seed: int = 0, timeout: Optional[float] = None,
                          **options: Any) -> AsyncIterator[Union[np.ndarray, Plan]]:
        """As :meth:`kinplan.Robot.plan_stream`, an async iterator: the
        trajectory after every STOMP / CCSTOMP iteration, then the :class:`Plan`."""
        call = _planning.plan_stream(start, goal, pose, algorithm, scene, seed, options)
        assert call.build is not None
        async for message in self.client._stream(call, call.build(self._ref()), timeout):
            yield message

    async def check(self, qs: Any, scene: Optional[Sequence[Obstacle]] = None, *, max_distance: float = 1.0,
                    timeout: Optional[float] = None) -> StateChecks:
        """As :meth:`kinplan.Robot.check`."""
        out: StateChecks = await self._run(_planning.check(qs, scene, max_distance), timeout)
        return out

    async def retime(self, path: Any, *, method: str = "time_optimal",
                     max_velocity: Optional[Sequence[float]] = None,
                     max_acceleration: Optional[Sequence[float]] = None, max_jerk: Optional[Sequence[float]] = None,
                     path_tolerance: Optional[float] = None, start_velocity: Optional[Sequence[float]] = None,
                     sample_period: Optional[float] = None, grid_step: Optional[float] = None,
                     velocity_scale: Optional[float] = None, timeout: Optional[float] = None) -> TimedTrajectory:
        """As :meth:`kinplan.Robot.retime`."""
        timing = dict(method=method, max_velocity=max_velocity, max_acceleration=max_acceleration,
                      max_jerk=max_jerk, path_tolerance=path_tolerance, start_velocity=start_velocity,
                      sample_period=sample_period, grid_step=grid_step, velocity_scale=velocity_scale)
        out: TimedTrajectory = await self._run(_planning.retime(path, timing), timeout)
        return out

    async def score(self, q: Trajectory, timestamps: Optional[Iterable[float]] = None,
                    weights: Optional[Iterable[float]] = None, series: bool = False, *,
                    robot_points: Optional[str] = None, max_velocity: Optional[Iterable[float]] = None,
                    max_acceleration: Optional[Iterable[float]] = None, jerk_peaks: Optional[Mapping[str, Any]] = None,
                    potential_tolerance: Optional[float] = None, timeout: Optional[float] = None) -> Scores:
        """As :meth:`kinplan.Robot.score`."""
        limits = await self._limits()
        _check_trajectory_limits(lambda states, field: limits.check(states, field, self.strict), q)
        call = _scoring.score(q, timestamps, weights, series, robot_points, max_velocity, max_acceleration,
                              jerk_peaks, potential_tolerance)
        out: Scores = await self._run(call, timeout)
        return out

    async def compare(self, sets: Mapping[str, Sequence[Trajectory]], *, weights: Optional[Iterable[float]] = None,
                      robot_points: Optional[str] = None, max_velocity: Optional[Iterable[float]] = None,
                      max_acceleration: Optional[Iterable[float]] = None,
                      jerk_peaks: Optional[Mapping[str, Any]] = None, potential_tolerance: Optional[float] = None,
                      timeout: Optional[float] = None) -> Comparison:
        """As :meth:`kinplan.Robot.compare`."""
        call = _scoring.compare(sets, weights, robot_points, max_velocity, max_acceleration, jerk_peaks,
                                potential_tolerance)
        out: Comparison = await self._run(call, timeout)
        return out


class AsyncIkStream:
    """A ``StreamIk`` call for asyncio: ``await s.solve(T)`` per controller
    cycle, or ``await s.send(T)`` then ``await s.receive()`` to pipeline."""

    def __init__(self, robot: AsyncRobot, options: kinematics_pb2.IkOptions, seed: Optional[npt.ArrayLike],
                 timeout: Optional[float]):
        self._robot, self._options = robot, options
        self._seed = None if seed is None else joints(seed, "seed")
        self._sequence = 0
        self._call = robot.client._kinematics.StreamIk(timeout=timeout, metadata=robot.client._metadata)

    async def send(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> int:
        self._sequence += 1
        first = self._sequence == 1
        values = joints(seed, "seed") if seed is not None else (self._seed if first else None)
        msg = _kinematics.stream_request(self._robot, self._sequence, T, values, first, self._options)
        try:
            await self._call.write(msg)
        except grpc.aio.AioRpcError as err:
            raise KinplanError.from_rpc_error(err) from None
        return self._sequence

    async def receive(self) -> IkResult:
        try:
            reply = await self._call.read()
        except grpc.aio.AioRpcError as err:
            raise KinplanError.from_rpc_error(err) from None
        if reply is grpc.aio.EOF:
            code = await self._call.code()
            raise error_for(code, await self._call.details() or "the stream ended", [])
        return _kinematics.stream_answer(reply)

    async def solve(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> IkResult:
        await self.send(T, seed)
        return await self.receive()

    async def close(self) -> None:
        await self._call.done_writing()

    async def __aenter__(self) -> "AsyncIkStream":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        if exc[0] is None:
            await self.close()
        else:
            self._call.cancel()
