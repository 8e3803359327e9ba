"""The blocking robot handle, :class:`Robot` (``client.robot(name)``): every
call about one robot — forward kinematics and Jacobians, inverse kinematics
(single, batch, paths, streams), planning, state checks and trajectory
scoring. Requests are built and replies read by :mod:`kinplan._services`,
shared with :class:`kinplan.aio.AsyncRobot`."""
from __future__ import annotations

import operator
import queue
import threading
from typing import (TYPE_CHECKING, Any, Callable, Dict, Iterable, Iterator, Literal, Mapping, Optional, Sequence, Tuple,
                    Union, overload)

import grpc
import numpy as np
import numpy.typing as npt

from ._codec import joints, read_fk_reply
from ._services import Call
from ._services import kinematics as _kinematics
from ._services import planning as _planning
from ._services import robot as _robot
from ._services import scoring as _scoring
from ._services.robot import RobotRefs
from .description import JointLimits, RobotDescription
from .errors import KinplanError
from .kinematics import (IkBatchResult, IkMethodName, IkOptions, IkResult, LinearSolverName, TrackResult,
                         resolve_ik_args)
from .planning import Obstacle, Plan, StateChecks, TimedTrajectory
from .scoring import Comparison, Scores, Trajectory, _check_trajectory_limits
from .v1 import common_pb2, kinematics_pb2

if TYPE_CHECKING:
    from .client import Client


class Robot(RobotRefs):
    """A robot on a server: the handle of every call about it. Inline URDFs
    are sent once, then referred to by the content hash the server returns;
    if a replica does not hold it (NOT_FOUND), the URDF is sent again by
    itself."""

    def __init__(self, client: "Client", *, name: Optional[str], urdf: Optional[str], base_link: str,
                 tip_link: str, strict: bool = False):
        self.client = client
        self.name = name
        self.urdf_text = urdf
        self.mesh_files: Dict[str, bytes] = {}
        self.srdf_text: Optional[str] = None
        self.group = ""
        self.held_joints: Dict[str, float] = {}
        self.base_link = base_link
        self.tip_link = tip_link
        self.strict = strict
        self.model_id: bytes = b""

    def __repr__(self) -> str:
        return f"kinplan.Robot({self.name or 'urdf'!r})"

    # ---- the call machinery ------------------------------------------------------------------------------------

    def _limits(self) -> JointLimits:
        """The chain's joint limits, fetched once per model and chain per client."""
        key = self.limits_key()
        try:
            limits: JointLimits = self.client.__dict__["_limits_cache"][key]
        except KeyError:
            limits = self.client.__dict__.setdefault("_limits_cache", {})[key] = JointLimits(self.describe())
        return limits

    def check_limits(self, q: Any, field_name: str = "q") -> None:
        """Warns with :class:`kinplan.JointLimitWarning` (raises
        :class:`kinplan.InvalidArgument` when the robot is strict) if a joint
        value of `q` (one state or rows of states) lies outside the limits:
        kinplan takes radians, and degrees are the usual cause."""
        self._limits().check(q, field_name, self.strict)

    def _send(self, path: str, response: Any, body: bytes, timeout: Optional[float]) -> Any:
        """A hand-encoded call: this robot's reference and then `body`, the
        request's other fields already encoded; the answer is parsed as
        `response` (``None``: its bytes are returned, and a model id in them
        is the caller's to read). Retried with the URDF inline when a
        replica does not hold the model id."""
        client = self.client
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[0] == (False, self.model_id):
            ref_field: bytes = cached[2]
        else:
            ref_field = self._ref_field(self._ref())
        method = client._raw_unary(path, response)
        try:
            reply = method(ref_field + body, timeout=client.timeout if timeout is None else timeout)
        except grpc.RpcError as err:
            if not (err.code() == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise KinplanError.from_rpc_error(err) from None
            self.model_id = b""
            reply = client._call(method, self._ref_field(self._ref(inline=True)) + body, timeout)
        if response is not None and self.urdf_text is not None and reply.model_id:
            self.model_id = reply.model_id
        return reply

    def _call(self, method: Callable[..., Any], build: Callable[[common_pb2.RobotRef], Any],
              timeout: Optional[float]) -> Any:
        """A unary call whose request `build` makes from this robot's
        reference, resent with the URDF inline on NOT_FOUND of a model id."""
        try:
            reply = self.client._call(method, build(self._ref()), timeout)
        except KinplanError as err:
            if not (err.code == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise
            self.model_id = b""
            reply = self.client._call(method, build(self._ref(inline=True)), timeout)
        self._learn(reply)
        return reply

    def _run(self, call: Call[Any], timeout: Optional[float]) -> Any:
        """Runs a :class:`kinplan._services.Call` about this robot."""
        assert call.build is not None
        return call.read(self._call(self.client._stubs.method(call), call.build, timeout))

    # ---- RobotService --------------------------------------------------------------------------------------------

    def describe(self, *, timeout: Optional[float] = None) -> RobotDescription:
        """The chain: joints with their limits and speeds, links, model id."""
        out: RobotDescription = self._run(_robot.describe(), timeout)
        return out

    def urdf(self, *, keep_capsules: bool = False, timeout: Optional[float] = None) -> str:
        """The robot's URDF text: a built-in's from the server, in standard URDF
        (each ``<capsule>``, a ROS extension urdfdom and pinocchio refuse,
        written as a cylinder and two end spheres) unless `keep_capsules`;
        an inline model's own text as given."""
        if self.urdf_text is not None:
            return self.urdf_text
        out: str = self._run(_robot.urdf(keep_capsules), timeout)
        return out

    @overload
    def fk(self, q: npt.ArrayLike, *, links: Literal[False] = False,
           timeout: Optional[float] = None) -> npt.NDArray[np.float64]: ...

    @overload
    def fk(self, q: npt.ArrayLike, *, links: Literal[True],
           timeout: Optional[float] = None) -> Tuple[npt.NDArray[np.float64], Dict[str, npt.NDArray[np.float64]]]: ...

    def fk(self, q: npt.ArrayLike, *, links: bool = False, timeout: Optional[float] = None) -> Any:
        """Tool pose (4x4, base frame, metres) for joint vector `q`; with
        `links=True`, also a dict of every link's 4x4 pose."""
        if links:
            positions = joints(q)
            self.check_limits(positions)
            return self._run(_robot.fk(positions, True), timeout)
        # the hot path: the request as bytes (reference, packed joints), the
        # answer read from its bytes when it has the usual layout
        positions, body = _robot.fk_body(q)
        limits = self._limits()
        lower, upper = limits._lower_list, limits._upper_list
        if not (len(positions) == len(lower) and all(map(operator.le, lower, positions))
                and all(map(operator.le, positions, upper))):
            self.check_limits(positions)  # the whole check: it warns, or raises, naming the joint
        tool, model_id = read_fk_reply(self._send(_robot.FORWARD_KINEMATICS, None, body, timeout))
        if model_id and self.urdf_text is not None:
            self.model_id = model_id
        return tool

    def fk_batch(self, qs: Any, *, jacobians: bool = False, timeout: Optional[float] = None) -> Any:
        """Tool poses of every row of `qs` (n x dof, rad) in one call: an
        (n, 4, 4) array; with `jacobians=True` also the (n, 6, dof)
        Jacobians (rows 0-2 linear, 3-5 angular, base frame)."""
        arr = _robot.batch_states(qs)
        self.check_limits(arr, "qs")
        return self._run(_robot.fk_batch(arr, jacobians), timeout)

    def jacobian(self, q: npt.ArrayLike, *, timeout: Optional[float] = None) -> np.ndarray:
        """6 x n geometric Jacobian in the base frame (rows: vx, vy, vz, wx, wy, wz)."""
        positions = joints(q)
        self.check_limits(positions)
        out: np.ndarray = self._run(_robot.jacobian(positions), timeout)
        return out

    # ---- KinematicsService ---------------------------------------------------------------------------------------

    def ik(
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
        """Joints that put the tool at ``T`` (4x4, or (position, quaternion
        xyzw), or a bare position 3-vector, which means ``position_only``),
        base frame, starting from ``seed`` (default: the middle of the
        limits).

        ``options``: an :class:`kinplan.IkOptions`; the keywords are
        shortcuts for its fields (``history`` is ``return_history``), and one
        given beside ``options`` replaces its field unless it is at its
        default. ``method``: "lm" (default), "jacobian_inverse", "newton",
        "ccd", "fabrik", "length_relaxation", "analytic" (closed form:
        with ``num_solutions=1000`` every solution inside the limits, each
        solution's ``config`` flags set; 6- and 7-joint arms whose
        ``describe().analytic_family`` is not empty; a 7-joint arm's
        redundant joint is held at the seed's value, or with
        ``search_redundant=True`` searched for the solution nearest the
        seed); ``linear_solver`` (Jacobian
        methods): "svd" (default), "angle_relaxation",
        "angle_relaxation_safeguarded". Tolerances in m and rad (default
        1e-5); ``max_restarts`` (default 200) random restarts from
        ``rng_seed``; ``num_solutions`` distinct solutions ranked by distance
        to ``seed``; ``time_budget`` in s (default: the call's deadline).
        "fabrik" and "length_relaxation" take position targets only, and
        "newton" with "angle_relaxation" does not converge (the relaxation's
        inexact solve is too coarse for Newton's step): see
        ``benches/IK_RESULTS.md`` for which combinations solve what."""
        matrix = isinstance(T, np.ndarray) and T.shape == (4, 4)
        args = (method, linear_solver, position_tolerance, orientation_tolerance, position_only, max_iterations,
                damping, max_restarts, num_solutions, rng_seed, joint_limits, time_budget, adaptive_damping,
                max_step, distinct_tolerance, rlxa_max_iterations, history, hold_configuration, nearest_turn_only,
                redundant_joint, analytic_start, search_redundant, redundant_samples, search_samples)
        if options is not None:
            args = resolve_ik_args(options, args)
        if not matrix:
            T, args = _kinematics.ik_target(T, args)
        # the request goes out as bytes built field by field: no message objects
        body = _kinematics.ik_body(T, seed, args)
        reply = self._send(_kinematics.SOLVE_IK, kinematics_pb2.SolveIkResponse, body, timeout)
        return IkResult.from_proto(reply)

    def ik_batch(
        self,
        Ts: Any,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        *,
        options: Optional[IkOptions] = None,
        timeout: Optional[float] = None,
        **shortcuts: Any,
    ) -> IkBatchResult:
        """Solves every target of ``Ts`` (n x 4 x 4 array, or a list of 4x4
        matrices / (position, quaternion) pairs) in parallel on the server,
        each from ``seed``: one joint vector for all targets, or an (n x dof)
        array with one seed per target. Options as :meth:`ik`; ``time_budget`` is per
        target, the call's deadline bounds the batch."""
        o = _kinematics.options_of(options, method, linear_solver, shortcuts)
        out: IkBatchResult = self._run(_kinematics.ik_batch(Ts, seed, o), timeout)
        return out

    def track(
        self,
        poses: Any = None,
        seed: Optional[npt.ArrayLike] = None,
        *,
        line: Optional[Mapping[str, Any]] = None,
        circle: Optional[Mapping[str, Any]] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        stop_on_failure: bool = False,
        options: Optional[IkOptions] = None,
        timeout: Optional[float] = None,
        **shortcuts: Any,
    ) -> TrackResult:
        """Follows a Cartesian path step by step, each step warm-started from
        the previous one (no restarts unless ``max_restarts`` is given).
        Give exactly one of ``poses`` (n x 4 x 4, or a list of targets),
        ``line={"end": T, "steps": 20, "start": T0}`` or ``circle={"centre":
        (x, y, z), "normal": (0, 0, 1), "angle_step": pi/50, "steps": 100,
        "start": T0}`` (``start`` defaults to the tool pose at ``seed``).
        ``seed`` defaults to the middle of the joint limits. Options as
        :meth:`ik`; ``time_budget`` bounds the whole path."""
        o = _kinematics.options_of(options, method, linear_solver, shortcuts)
        out: TrackResult = self._run(_kinematics.track(poses, seed, line, circle, o, stop_on_failure), timeout)
        return out

    def stream_ik(
        self,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        *,
        options: Optional[IkOptions] = None,
        timeout: Optional[float] = None,
        **shortcuts: Any,
    ) -> "IkStream":
        """Opens a ``StreamIk`` call (see :class:`IkStream`). The first
        target starts from ``seed`` (default: middle of the limits), every
        later one from the previous answer. Options as :meth:`ik` (default
        ``max_restarts`` 0; ``time_budget`` per target). ``timeout`` bounds
        the whole stream (default: none -- a controller's stream lasts as
        long as the controller runs)."""
        return IkStream(self, _kinematics.options_of(options, method, linear_solver, shortcuts), seed, timeout)

    # ---- PlanningService -----------------------------------------------------------------------------------------

    def plan(
        self,
        start: Any,
        goal: Any = None,
        *,
        pose: Any = None,
        algorithm: str = "rrt_connect",
        scene: Optional[Sequence[Obstacle]] = None,
        seed: int = 0,
        time_budget: Optional[float] = None,
        motion_resolution: Optional[float] = None,
        padded_motion: bool = False,
        return_cost_history: bool = True,
        stomp: Optional[Mapping[str, Any]] = None,
        cartesian: Optional[Mapping[str, Any]] = None,
        rrt_connect: Optional[Mapping[str, Any]] = None,
        timing: Optional[Mapping[str, Any]] = None,
        timeout: Optional[float] = None,
    ) -> Plan:
        """Plans from ``start`` to ``goal`` (joints) or ``pose`` (4x4 tool pose)
        among ``scene``'s obstacles. ``algorithm``: "rrt_connect", "stomp" or
        "ccstomp". ``stomp``, ``cartesian``, ``rrt_connect`` and ``timing`` take
        the fields of the proto messages of those names (e.g.
        ``stomp={"timesteps": 10}``, ``cartesian={"translation_tolerance": 1.0}``);
        unset fields take the documented defaults. ``padded_motion=True``
        checks motions conservatively (no state of an accepted motion
        collides; slower); by default states ``motion_resolution`` apart are
        checked (an obstacle thinner than one step can be grazed). The same ``seed`` gives the
        same answer."""
        call = _planning.plan(start, goal, pose, algorithm, scene, seed, time_budget, motion_resolution,
                              padded_motion, return_cost_history, stomp, cartesian, rrt_connect, timing)
        out: Plan = self._run(call, timeout)
        return out

    def plan_stream(self, start: Any, goal: Any = None, *, pose: Any = None, algorithm: str = "stomp",
                    scene: Optional[Sequence[Obstacle]] = None, seed: int = 0, timeout: Optional[float] = None,
                    **options: Any) -> Iterator[Union[np.ndarray, Plan]]:
        """Yields the trajectory (waypoints x dof) after every STOMP / CCSTOMP
        iteration, then the final :class:`Plan` (for animations). ``options``
        are those of :meth:`plan`."""
        call = _planning.plan_stream(start, goal, pose, algorithm, scene, seed, options)
        assert call.build is not None
        yield from self.client._stream(call, call.build(self._ref()), timeout)

    def check(self, qs: Any, scene: Optional[Sequence[Obstacle]] = None, *, max_distance: float = 1.0,
              timeout: Optional[float] = None) -> StateChecks:
        """Validity and clearance of each row of ``qs`` (n x dof) in ``scene``:
        collisions, joint limits, the closest pair and its witness points
        (clearances capped at ``max_distance``, m)."""
        out: StateChecks = self._run(_planning.check(qs, scene, max_distance), timeout)
        return out

    def retime(self, path: Any, *, method: str = "time_optimal", max_velocity: Optional[Sequence[float]] = None,
               max_acceleration: Optional[Sequence[float]] = None, max_jerk: Optional[Sequence[float]] = None,
               path_tolerance: Optional[float] = None, start_velocity: Optional[Sequence[float]] = None,
               sample_period: Optional[float] = None, grid_step: Optional[float] = None,
               velocity_scale: Optional[float] = None, timeout: Optional[float] = None) -> TimedTrajectory:
        """Times a joint path (n x dof, from any planner) within the joint
        limits: ``method`` "time_optimal" (circular blends at most
        ``path_tolerance`` from the waypoints, TOPP-RA; needs
        ``max_acceleration``), "jerk_limited" (straight segments joined by
        S-curve blends in time, passing each waypoint within
        ``path_tolerance`` without stopping; needs ``max_acceleration`` and
        ``max_jerk``) or "waypoint". Limits per joint in rad/s, rad/s^2,
        rad/s^3 (``max_velocity`` defaults to the model's). ``start_velocity``
        (rad/s per joint; at rest by default): along the first segment for
        "time_optimal", any within the limits for "jerk_limited". Returns a
        :class:`TimedTrajectory` sampled every ``sample_period`` s."""
        timing = dict(method=method, max_velocity=max_velocity, max_acceleration=max_acceleration,
                      max_jerk=max_jerk, path_tolerance=path_tolerance, start_velocity=start_velocity,
                      sample_period=sample_period, grid_step=grid_step, velocity_scale=velocity_scale)
        out: TimedTrajectory = self._run(_planning.retime(path, timing), timeout)
        return out

    # ---- ScoringService ------------------------------------------------------------------------------------------

    def score(
        self,
        q: Trajectory,
        timestamps: Optional[Iterable[float]] = None,
        weights: Optional[Iterable[float]] = None,
        series: bool = False,
        *,
        robot_points: Optional[str] = None,
        max_velocity: Optional[Iterable[float]] = None,
        max_acceleration: Optional[Iterable[float]] = None,
        jerk_peaks: Optional[Mapping[str, Any]] = None,
        potential_tolerance: Optional[float] = None,
        timeout: Optional[float] = None,
    ) -> Scores:
        """Scores one joint trajectory.

        ``q``: (n x joints) array, list of waypoints or a JointTrajectory
        (rad, m for prismatic joints); ``timestamps``: seconds per waypoint,
        adds the time-scaled jerk; ``weights``: CPC weight per joint;
        ``series``: also return the per-waypoint series. ``robot_points``:
        "link_origins" (default), "collision_vertices" or "none" (no RDM).
        ``max_velocity`` / ``max_acceleration``: per joint, for the cycle
        time (default: the model's speed limits, no ramps). ``jerk_peaks``:
        JerkPeakOptions fields, e.g. ``{"joint_log_gain": 3, "slowdown_floor": 0}``.
        """
        _check_trajectory_limits(self.check_limits, q)
        call = _scoring.score(q, timestamps, weights, series, robot_points, max_velocity, max_acceleration,
                              jerk_peaks, potential_tolerance)
        out: Scores = self._run(call, timeout)
        return out

    def compare(
        self,
        sets: Mapping[str, Sequence[Trajectory]],
        *,
        weights: Optional[Iterable[float]] = None,
        robot_points: Optional[str] = None,
        max_velocity: Optional[Iterable[float]] = None,
        max_acceleration: Optional[Iterable[float]] = None,
        jerk_peaks: Optional[Mapping[str, Any]] = None,
        potential_tolerance: Optional[float] = None,
        timeout: Optional[float] = None,
    ) -> Comparison:
        """Scores labelled sets of trajectories, e.g. ``{"rrt": [q1, q2],
        "ccstomp": [q3]}``, and returns per set and criterion the mean,
        variance and sum (S0 Tab. 5.3-5.5) as a :class:`kinplan.Comparison`."""
        call = _scoring.compare(sets, weights, robot_points, max_velocity, max_acceleration, jerk_peaks,
                                potential_tolerance)
        out: Comparison = self._run(call, timeout)
        return out


class IkStream:
    """A ``StreamIk`` call: send targets, read answers in order, each
    warm-started from the previous answer. Use as a context manager::

        with robot.stream_ik(time_budget=0.004) as s:
            for T in targets:
                r = s.solve(T)            # send + wait: one controller cycle
            s.send(T1); s.send(T2)        # or pipeline...
            a1, a2 = next(s), next(s)     # ...and read the answers in order

    Each answer is an :class:`IkResult` with ``sequence`` set. A bad target
    ends the stream: the next read raises :class:`KinplanError` naming the
    field and the message's sequence number.
    """

    _END = object()

    def __init__(self, robot: Any, options: kinematics_pb2.IkOptions, seed: Optional[npt.ArrayLike],
                 timeout: Optional[float]):
        self._robot = robot
        self._options = options
        self._seed = None if seed is None else joints(seed, "seed")
        self._queue: "queue.Queue[Any]" = queue.Queue()
        self._sequence = 0
        self._first = True
        self._lock = threading.Lock()
        self._closed = False
        self._call = robot.client._kinematics.StreamIk(self._requests(), timeout=timeout)

    def _requests(self) -> Iterator[kinematics_pb2.StreamIkRequest]:
        while True:
            item = self._queue.get()
            if item is IkStream._END:
                return
            yield item

    def send(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> int:
        """Queues a target; returns its sequence number."""
        if self._closed:
            raise RuntimeError("the stream is closed")
        with self._lock:
            self._sequence += 1
            first, self._first = self._first, False
            values = joints(seed, "seed") if seed is not None else (self._seed if first else None)
            self._queue.put(_kinematics.stream_request(self._robot, self._sequence, T, values, first, self._options))
            return self._sequence

    def __next__(self) -> IkResult:
        try:
            reply = next(self._call)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None
        return _kinematics.stream_answer(reply)

    def __iter__(self) -> "IkStream":
        return self

    def solve(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> IkResult:
        """Sends one target and waits for its answer."""
        self.send(T, seed)
        return next(self)

    def close(self) -> None:
        """Ends the request side; the server then ends the stream."""
        if not self._closed:
            self._closed = True
            self._queue.put(IkStream._END)

    def cancel(self) -> None:
        self.close()
        self._call.cancel()

    def __enter__(self) -> "IkStream":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
        # drain what is left so that the call ends cleanly
        try:
            for _ in self._call:
                pass
        except grpc.RpcError:
            pass


__all__ = ["IkStream", "Robot"]
