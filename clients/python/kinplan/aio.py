"""``kinplan.aio``: the client for asyncio programs, on ``grpc.aio``.

    async with kinplan.aio.Client("127.0.0.1:50051") as c:
        robot = c.robot("kuka_kr210_r2700_extra")
        T = await robot.fk(q)
        sols = await asyncio.gather(*(robot.ik(T_k) for T_k in targets))  # concurrent calls
        async with robot.stream_ik(seed=q) as s:
            answer = await s.solve(T)
        async for frame in c.plan_stream(ur5, start=q0, goal=q1):     # server streams: async iterators
            ...

Same names, arguments, results and errors as the blocking client
(:class:`kinplan.Client`, :class:`kinplan.Robot`) for: ``ping``,
``wait_for_ready``, ``list_robots``, ``robot``, ``solve_linear``, ``plan``,
``plan_stream``, ``check_states``, ``score``, ``compare``, ``mobile``
(``wheels``, ``step``, ``follow``, ``navigate``), ``next_best_view``,
``insert_scan``, ``octree_info``, ``reference_scene``, ``explore``; and on a
robot ``describe``, ``urdf``, ``fk``, ``fk_batch``, ``jacobian``, ``ik``,
``ik_batch``, ``track``, ``stream_ik``. Each method awaits its call; many
calls can be in flight on one channel. ``plan_stream`` and ``explore`` are
async iterators (``async for``). Requests and replies are built and read by
the same functions as the blocking client's, so both give the same answers.
"""
from __future__ import annotations

import asyncio
from typing import Any, AsyncIterator, Callable, Dict, Iterable, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import grpc
import grpc.aio
import numpy as np
import numpy.typing as npt

from ._aio_mobile import AsyncMobile
from ._convert import joints, matrix_from_proto, matrix_to_proto, pose_to_matrix
from .client import (
    DEFAULT_TIMEOUT,
    JointLimits,
    Robot,
    RobotDescription,
    RobotRefs,
    _channel_options,
    _check_robot_args,
    _no_server,
    _pem,
    _urdf_request,
    normalize_target,
)
from .errors import KinplanError, error_for, invalid_argument
from .exploration import (
    Octree,
    Views,
    _insert_scan_request,
    _nbv_request,
    _octree_info,
    _octree_info_request,
    _views,
    _with_robot,
)
from .explore import (
    ExploreStep,
    ExploreSummary,
    ReferenceScene,
    _explore_message,
    _explore_request,
    _reference_scene,
    _reference_scene_request,
)
from .kinematics import (
    IkBatchResult,
    IkMethodName,
    IkResult,
    LinearSolverName,
    LinearSolution,
    TrackResult,
    _is_position,
    _linear_solution,
    _solve_linear_request,
    _targets,
    _track_request,
    ik_options,
    target_to_pose,
)
from .planning import (
    Obstacle,
    Plan,
    StateChecks,
    _plan_request,
    _plan_stream_message,
    _plan_stream_request,
    scene_to_proto,
)
from .scoring import Comparison, Scores, Trajectory, _check_trajectory_limits, _compare_request, score_options, trajectory_to_proto
from .v1 import (
    common_pb2,
    exploration_pb2_grpc,
    kinematics_pb2,
    kinematics_pb2_grpc,
    planning_pb2,
    planning_pb2_grpc,
    robot_pb2,
    robot_pb2_grpc,
    scoring_pb2,
    scoring_pb2_grpc,
)

__all__ = ["AsyncIkStream", "AsyncMobile", "AsyncRobot", "Client"]


class Client:
    """An asyncio connection to a kinplan server (or replicas: the same
    `target` forms as :class:`kinplan.Client`). `timeout` (s) is every call's
    default deadline. Use ``async with``, or ``await client.close()``."""

    def __init__(
        self,
        target: Union[str, Sequence[str]] = "127.0.0.1:50051",
        *,
        timeout: Optional[float] = DEFAULT_TIMEOUT,
        max_message_bytes: int = 16 * 1024 * 1024,
        token: Optional[str] = None,
        tls_ca: Union[None, str, bytes] = None,
        tls_cert: Union[None, str, bytes] = None,
        tls_key: Union[None, str, bytes] = None,
    ):
        self.target = normalize_target(target)
        self.timeout = timeout
        options = _channel_options(self.target, max_message_bytes)
        self._metadata = None if token is None else (("authorization", f"Bearer {token}"),)
        if tls_ca is not None:
            creds = grpc.ssl_channel_credentials(
                root_certificates=_pem(tls_ca),
                private_key=_pem(tls_key) if tls_key is not None else None,
                certificate_chain=_pem(tls_cert) if tls_cert is not None else None,
            )
            self._channel = grpc.aio.secure_channel(self.target, creds, options=options)
        elif tls_cert is not None or tls_key is not None:
            raise invalid_argument("tls_ca", "a client certificate needs TLS: give tls_ca too")
        else:
            self._channel = grpc.aio.insecure_channel(self.target, options=options)
        self._attach_stubs()

    @classmethod
    def local(cls, *, timeout: Optional[float] = DEFAULT_TIMEOUT, cpu_threads: int = 0,
              acm_samples: int = 10_000) -> "Client":
        """As :meth:`kinplan.Client.local`: the services inside this process
        (``pip install kinplan-native``), each call run on a worker thread so
        the event loop keeps running."""
        from .inprocess import AioLocalChannel

        client = cls.__new__(cls)
        client.target, client.timeout, client._metadata = "in-process", timeout, None
        client._channel = AioLocalChannel(cpu_threads, acm_samples)
        client._attach_stubs()
        return client

    def _attach_stubs(self) -> None:
        self._robots = robot_pb2_grpc.RobotServiceStub(self._channel)
        self._kinematics = kinematics_pb2_grpc.KinematicsServiceStub(self._channel)
        self._planning = planning_pb2_grpc.PlanningServiceStub(self._channel)
        self._scoring = scoring_pb2_grpc.ScoringServiceStub(self._channel)
        self._exploration = exploration_pb2_grpc.ExplorationServiceStub(self._channel)
        self.mobile = AsyncMobile(self)
        """The MobileService calls (as :attr:`kinplan.Client.mobile`)."""

    async def __aenter__(self) -> "Client":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await self.close()

    async def close(self) -> None:
        await self._channel.close()

    def __repr__(self) -> str:
        return f"kinplan.aio.Client({self.target!r}, timeout={self.timeout})"

    async def _call(self, method: Callable[..., Any], request: Any, timeout: Optional[float]) -> Any:
        try:
            return await method(request, timeout=self.timeout if timeout is None else timeout, metadata=self._metadata)
        except grpc.aio.AioRpcError as err:
            raise KinplanError.from_rpc_error(err) from None

    async def _stream(self, method: Callable[..., Any], request: Any, timeout: Optional[float]) -> AsyncIterator[Any]:
        """The messages of a server-streaming call; its errors as :class:`KinplanError`.
        Leaving the loop early cancels the call."""
        call = method(request, timeout=self.timeout if timeout is None else timeout, metadata=self._metadata)
        try:
            async for message in call:
                yield message
        except grpc.aio.AioRpcError as err:
            raise KinplanError.from_rpc_error(err) from None
        finally:
            call.cancel()

    async def wait_for_ready(self, timeout: Optional[float] = None) -> None:
        """As :meth:`kinplan.Client.wait_for_ready`: waits until the channel
        connects (at most `timeout` s, default the client's)."""
        t = self.timeout if timeout is None else timeout
        try:
            await asyncio.wait_for(self._channel.channel_ready(), t)
        except asyncio.TimeoutError:
            raise _no_server(self.target, t) from None

    async def ping(self, *, timeout: Optional[float] = None) -> float:
        """Round-trip time (s) of the cheapest call."""
        t0 = asyncio.get_running_loop().time()
        await self._call(self._robots.ListRobots, robot_pb2.ListRobotsRequest(), timeout)
        return asyncio.get_running_loop().time() - t0

    async def list_robots(self, *, timeout: Optional[float] = None) -> List[Dict[str, Any]]:
        reply = await self._call(self._robots.ListRobots, robot_pb2.ListRobotsRequest(), timeout)
        return [
            {"name": r.name, "dof": r.dof, "description": r.description, "base_link": r.base_link, "tip_link": r.tip_link}
            for r in reply.robots
        ]

    def robot(self, name: Optional[str] = None, *, urdf: Optional[str] = None, base_link: str = "",
              tip_link: str = "", strict: bool = False) -> "AsyncRobot":
        """As :meth:`kinplan.Client.robot`."""
        _check_robot_args(name, urdf)
        return AsyncRobot(self, name=name, urdf=urdf, base_link=base_link, tip_link=tip_link, strict=strict)

    def _robot_of(self, robot: Any) -> "AsyncRobot":
        if robot is None:
            raise ValueError("robot= is required (a name or client.robot(...))")
        return self.robot(robot) if isinstance(robot, str) else robot

    async def plan(self, robot: Any, *, start: Any, goal: Any = None, pose: Any = None,
                   algorithm: str = "rrt_connect", scene: Optional[Sequence[Obstacle]] = None, seed: int = 0,
                   time_budget: Optional[float] = None, motion_resolution: Optional[float] = None,
                   padded_motion: bool = False, return_cost_history: bool = True, stomp: Any = None, cartesian: Any = None,
                   rrt_connect: Any = None, timing: Any = None, timeout: Optional[float] = None) -> Plan:
        """As :meth:`kinplan.Client.plan`."""
        build = _plan_request(
            start, goal, pose, algorithm, scene, seed, time_budget, motion_resolution, padded_motion,
            return_cost_history, stomp, cartesian, rrt_connect, timing,
        )
        return Plan.from_proto(await self._robot_of(robot)._call(self._planning.Plan, build, timeout))

    async def plan_stream(self, robot: Any, *, start: Any, goal: Any = None, pose: Any = None,
                          algorithm: str = "stomp", scene: Optional[Sequence[Obstacle]] = None, seed: int = 0,
                          timeout: Optional[float] = None, **options: Any) -> AsyncIterator[Union[np.ndarray, Plan]]:
        """As :meth:`kinplan.Client.plan_stream`, an async iterator: the
        trajectory after every STOMP / CCSTOMP iteration, then the :class:`Plan`."""
        build = _plan_stream_request(start, goal, pose, algorithm, scene, seed, options)
        request = build(self._robot_of(robot)._ref())
        async for message in self._stream(self._planning.PlanStream, request, timeout):
            yield _plan_stream_message(message)

    async def check_states(self, robot: Any, qs: Any, scene: Optional[Sequence[Obstacle]] = None, *,
                           max_distance: float = 1.0, timeout: Optional[float] = None) -> StateChecks:
        """As :meth:`kinplan.Client.check_states`."""
        arr = np.atleast_2d(np.asarray(qs, dtype=float))
        proto_scene = scene_to_proto(scene)

        def build(ref: common_pb2.RobotRef) -> planning_pb2.CheckStateRequest:
            return planning_pb2.CheckStateRequest(
                robot=ref, states=[planning_pb2.JointState(positions=row) for row in arr.tolist()],
                scene=proto_scene, max_distance=float(max_distance),
            )

        reply = await self._robot_of(robot)._call(self._planning.CheckState, build, timeout)
        return StateChecks.from_proto(reply)

    async def score(self, robot: Any, q: Any, timestamps: Any = None, weights: Any = None, series: bool = False, *,
                    robot_points: Optional[str] = None, max_velocity: Any = None, max_acceleration: Any = None,
                    jerk_peaks: Any = None, potential_tolerance: Optional[float] = None,
                    timeout: Optional[float] = None) -> Scores:
        """As :meth:`kinplan.Client.score`."""
        r = self._robot_of(robot)
        limits = await r._limits()
        _check_trajectory_limits(lambda states, field: limits.check(states, field, r.strict), q)
        traj = trajectory_to_proto(q, timestamps)
        options = score_options(weights, series, robot_points, max_velocity, max_acceleration, jerk_peaks,
                                potential_tolerance)
        reply = await r._call(
            self._scoring.ScoreTrajectory,
            lambda ref: scoring_pb2.ScoreTrajectoryRequest(robot=ref, trajectory=traj, options=options),
            timeout,
        )
        return Scores.from_proto(reply)

    async def compare(self, sets: Mapping[str, Sequence[Trajectory]], robot: Any = None, *,
                      weights: Optional[Iterable[float]] = None, robot_points: Optional[str] = None,
                      max_velocity: Optional[Iterable[float]] = None, max_acceleration: Optional[Iterable[float]] = None,
                      jerk_peaks: Optional[Mapping[str, Any]] = None, potential_tolerance: Optional[float] = None,
                      timeout: Optional[float] = None) -> Comparison:
        """As :meth:`kinplan.Client.compare`."""
        r = self._robot_of(robot)
        build = _compare_request(sets, weights, robot_points, max_velocity, max_acceleration, jerk_peaks,
                                 potential_tolerance)
        return Comparison(await r._call(self._scoring.CompareTrajectories, build, timeout))

    async def solve_linear(self, A: Any, b: Any, method: Optional[str] = "svd", *,
                           max_iterations: Optional[int] = None, tolerance: Optional[float] = None,
                           relative_tolerance: Optional[float] = None, rng_seed: int = 0, history: bool = False,
                           singular_value_tolerance: Optional[float] = None,
                           timeout: Optional[float] = None) -> LinearSolution:
        """As :meth:`kinplan.Client.solve_linear`."""
        request = _solve_linear_request(A, b, method, max_iterations, tolerance, relative_tolerance, rng_seed,
                                        history, singular_value_tolerance)
        return _linear_solution(await self._call(self._kinematics.SolveLinearSystem, request, timeout))

    async def next_best_view(self, octree: Any, *, camera_pose: Any = None, robot: Any = None,
                             camera_mount: Any = None, candidate_poses: Sequence[Any] = (),
                             weights: Optional[Sequence[float]] = None, gain: str = "intersection",
                             ray_fraction: Optional[float] = None, max_results: int = 10,
                             camera: Optional[Dict[str, Any]] = None, timeout: Optional[float] = None,
                             **options: Any) -> Views:
        """As :meth:`kinplan.Client.next_best_view`."""
        req = _nbv_request(octree, camera_pose, camera_mount, candidate_poses, weights, gain, ray_fraction,
                           max_results, camera, options)
        if robot is not None:
            reply = await self._robot_of(robot)._call(self._exploration.NextBestView, _with_robot(req), timeout)
        else:
            reply = await self._call(self._exploration.NextBestView, req, timeout)
        return _views(reply)

    async def insert_scan(self, octree: Optional[Octree], points: Any, origin: Any = None, *,
                          resolution: float = 0.05, max_range: Optional[float] = None, discretize: bool = False,
                          timeout: Optional[float] = None) -> Octree:
        """As :meth:`kinplan.Client.insert_scan`."""
        req = _insert_scan_request(octree, points, origin, resolution, max_range, discretize)
        return Octree.from_proto((await self._call(self._exploration.InsertScan, req, timeout)).octree)

    async def octree_info(self, octree: Any, *, box: Any = None, timeout: Optional[float] = None) -> Dict[str, Any]:
        """As :meth:`kinplan.Client.octree_info`."""
        req = _octree_info_request(octree, box)
        return _octree_info(await self._call(self._exploration.OctreeInfo, req, timeout))

    async def reference_scene(self, name: str = "s0_open_cell", *, seed: int = 1,
                              timeout: Optional[float] = None) -> ReferenceScene:
        """As :meth:`kinplan.Client.reference_scene`."""
        req = _reference_scene_request(name, seed)
        return _reference_scene(name, await self._call(self._exploration.ReferenceScene, req, timeout))

    async def explore(
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
    ) -> AsyncIterator[Union[ExploreStep, ExploreSummary]]:
        """As :meth:`kinplan.Client.explore`, an async iterator: an
        :class:`ExploreStep` per iteration, then the :class:`ExploreSummary`."""
        req = _explore_request(
            self.robot, robot, scene, start, region, planner, weights, seed, resolution, pixel_stride, known_ratio,
            max_iterations, max_consecutive_failures, camera, camera_mount, nbv, plan_options, options,
        )
        async for message in self._stream(self._exploration.Explore, req, timeout):
            yield _explore_message(message)


class AsyncRobot(RobotRefs):
    """A robot on a server, for asyncio: the model-id rule of
    :class:`kinplan.Robot` (inline URDFs sent once, resent on NOT_FOUND)."""

    def __init__(self, client: Client, *, name: Optional[str], urdf: Optional[str], base_link: str, tip_link: str,
                 strict: bool = False):
        self.client = client
        self.name, self.urdf_text = name, urdf
        self.base_link, self.tip_link = base_link, tip_link
        self.strict = strict
        self.model_id: bytes = b""

    def __repr__(self) -> str:
        return f"kinplan.aio.AsyncRobot({self.name or 'urdf'!r})"

    async def _call(self, method: Callable[..., Any], build: Callable[[common_pb2.RobotRef], Any], timeout: Optional[float]) -> Any:
        try:
            reply = await self.client._call(method, build(self._ref()), timeout)
        except KinplanError as err:
            if not (err.code == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise
            self.model_id = b""
            reply = await self.client._call(method, build(self._ref(inline=True)), timeout)
        model_id = getattr(reply, "model_id", b"")
        if model_id and self.urdf_text is not None:
            self.model_id = model_id
        return reply

    async def _limits(self) -> JointLimits:
        cache = self.client.__dict__.setdefault("_limits_cache", {})
        key = Robot.limits_key(self)  # type: ignore[arg-type]  # the same fields as Robot's
        if key not in cache:
            cache[key] = JointLimits(await self.describe())
        limits: JointLimits = cache[key]
        return limits

    async def check_limits(self, q: Any, field_name: str = "q") -> None:
        """As :meth:`kinplan.Robot.check_limits` (warns, or raises when strict)."""
        (await self._limits()).check(q, field_name, self.strict)

    async def describe(self, *, timeout: Optional[float] = None) -> RobotDescription:
        r = await self._call(self.client._robots.DescribeRobot,
                             lambda ref: robot_pb2.DescribeRobotRequest(robot=ref), timeout)
        return RobotDescription.from_proto(r)

    async def urdf(self, *, keep_capsules: bool = False, timeout: Optional[float] = None) -> str:
        """As :meth:`kinplan.Robot.urdf`."""
        if self.urdf_text is not None:
            return self.urdf_text
        return str((await self._call(self.client._robots.DescribeRobot, _urdf_request(keep_capsules), timeout)).urdf)

    async def fk(self, q: npt.ArrayLike, *, links: bool = False, timeout: Optional[float] = None) -> Any:
        positions = joints(q)
        await self.check_limits(positions)
        r = await self._call(
            self.client._robots.ForwardKinematics,
            lambda ref: robot_pb2.ForwardKinematicsRequest(robot=ref, joint_positions=positions, include_links=links),
            timeout,
        )
        tool = pose_to_matrix(r.tool_pose)
        if links:
            return tool, {link.name: pose_to_matrix(link.pose) for link in r.links}
        return tool

    async def fk_batch(self, qs: Any, *, jacobians: bool = False, timeout: Optional[float] = None) -> Any:
        arr = np.ascontiguousarray(qs, dtype=np.float64)
        if arr.ndim == 1:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[0] == 0:
            raise invalid_argument("qs", f"must be n x dof with n >= 1, got shape {arr.shape}")
        await self.check_limits(arr, "qs")
        matrix = matrix_to_proto(arr)
        r = await self._call(
            self.client._robots.ForwardKinematicsBatch,
            lambda ref: robot_pb2.ForwardKinematicsBatchRequest(robot=ref, joint_positions=matrix,
                                                                include_jacobians=jacobians),
            timeout,
        )
        return Robot._batch_reply(r, arr.shape[1], jacobians)

    async def jacobian(self, q: npt.ArrayLike, *, timeout: Optional[float] = None) -> np.ndarray:
        positions = joints(q)
        await self.check_limits(positions)
        r = await self._call(
            self.client._robots.Jacobian,
            lambda ref: robot_pb2.JacobianRequest(robot=ref, joint_positions=positions),
            timeout,
        )
        return matrix_from_proto(r.jacobian)

    async def ik(
        self,
        T: Any,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[IkMethodName] = "lm",
        linear_solver: Optional[LinearSolverName] = "svd",
        *,
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
        timeout: Optional[float] = None,
    ) -> IkResult:
        """As :meth:`kinplan.Robot.ik`."""
        if _is_position(T):
            T = (np.asarray(T, dtype=float), np.array([0.0, 0.0, 0.0, 1.0]))
            position_only = True
        o = ik_options(
            method, linear_solver, position_tolerance=position_tolerance, orientation_tolerance=orientation_tolerance,
            position_only=position_only, max_iterations=max_iterations, damping=damping, max_restarts=max_restarts,
            num_solutions=num_solutions, rng_seed=rng_seed, joint_limits=joint_limits, time_budget=time_budget,
            adaptive_damping=adaptive_damping, max_step=max_step, distinct_tolerance=distinct_tolerance,
            rlxa_max_iterations=rlxa_max_iterations, history=history,
        )
        target = target_to_pose(T)
        seed_list = [] if seed is None else joints(seed, "seed")
        reply = await self._call(
            self.client._kinematics.SolveIk,
            lambda ref: kinematics_pb2.SolveIkRequest(robot=ref, target=target, seed=seed_list, options=o),
            timeout,
        )
        return IkResult.from_proto(reply)

    async def ik_batch(self, Ts: Any, seed: Any = None, method: Optional[str] = "lm",
                       linear_solver: Optional[str] = "svd", *, timeout: Optional[float] = None,
                       **options: Any) -> IkBatchResult:
        """As :meth:`kinplan.Robot.ik_batch`."""
        o = ik_options(method, linear_solver, **options)
        targets = _targets(Ts)
        seed_arr = None if seed is None else np.asarray(seed, dtype=np.float64)
        per_target = matrix_to_proto(seed_arr) if seed_arr is not None and seed_arr.ndim == 2 else None
        seed_list = joints(seed, "seed") if seed is not None and per_target is None else []
        reply = await self._call(
            self.client._kinematics.SolveIkBatch,
            lambda ref: kinematics_pb2.SolveIkBatchRequest(robot=ref, targets=targets, seed=seed_list, options=o,
                                                           seeds=per_target),
            timeout,
        )
        return IkBatchResult(results=[IkResult.from_proto(r) for r in reply.results], succeeded=reply.succeeded,
                             elapsed_us=reply.elapsed_us)

    async def track(self, poses: Any = None, seed: Optional[npt.ArrayLike] = None, *,
                    line: Optional[Mapping[str, Any]] = None, circle: Optional[Mapping[str, Any]] = None,
                    method: Optional[str] = "lm", linear_solver: Optional[str] = "svd", stop_on_failure: bool = False,
                    timeout: Optional[float] = None, **options: Any) -> TrackResult:
        """As :meth:`kinplan.Robot.track`."""
        build = _track_request(poses, seed, line, circle, method, linear_solver, stop_on_failure, options)
        return TrackResult.from_proto(await self._call(self.client._kinematics.TrackPath, build, timeout))

    def stream_ik(self, seed: Optional[npt.ArrayLike] = None, method: Optional[str] = "lm",
                  linear_solver: Optional[str] = "svd", *, timeout: Optional[float] = None,
                  **options: Any) -> "AsyncIkStream":
        """An ``async with`` StreamIk session (as :meth:`kinplan.Robot.stream_ik`)."""
        return AsyncIkStream(self, ik_options(method, linear_solver, **options), seed, timeout)


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
        msg = kinematics_pb2.StreamIkRequest(sequence=self._sequence, target=target_to_pose(T))
        if self._sequence == 1:
            msg.robot.CopyFrom(self._robot._ref(inline=self._robot.urdf_text is not None))
            msg.options.CopyFrom(self._options)
            if seed is None:
                seed = self._seed
        if seed is not None:
            msg.seed.extend(joints(seed, "seed"))
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
        out = IkResult.from_proto(reply.result)
        out.sequence = reply.sequence
        return out

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
