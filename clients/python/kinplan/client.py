"""The blocking client: :class:`Client` holds the channel and the calls that
are not about one robot; ``client.robot(name)`` gives the :class:`Robot`
handle of every call about one (:mod:`kinplan.robot`)."""
from __future__ import annotations

import os
import time
import warnings
from typing import Any, Callable, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import grpc
import numpy as np
import numpy.typing as npt

from ._channel import (DEFAULT_PORT, DEFAULT_TIMEOUT, _BearerToken, _channel_options, _no_server, _pem,
                       normalize_target)
from ._services import Call, Stubs
from ._services import exploration as _exploration
from ._services import kinematics as _kinematics
from ._services import mobile as _mobile
from ._services import robot as _robot
from ._services.robot import RobotRefs, check_robot_args
from .description import JointLimits, RobotDescription
from ._model_files import load_model, load_text
from .errors import KinplanError, invalid_argument
from .exploration_loop import ExploreStep, ExploreSummary, ReferenceScene
from .kinematics import LinearSolution
from .mobile import MobileRun, Obstacle as MobileObstacle, StepResult, WheelKinematics
from .octree import Octree, OctreeSource, Views
from .planning import Obstacle, Plan, StateChecks
from .robot import Robot
from .scoring import Comparison, Scores, Trajectory

#: The old private names of the request helpers, for code that imported them from here.
_check_robot_args = check_robot_args


class Client:
    """A connection to a kinplan server.

    `timeout` (seconds) is the default deadline of every call; each method
    also takes its own `timeout=`. Use as a context manager, or call close().
    """

    def __init__(
        self,
        target: Union[str, Sequence[str]] = "127.0.0.1:50051",
        *,
        timeout: Optional[float] = DEFAULT_TIMEOUT,
        max_message_bytes: int = 16 * 1024 * 1024,
        channel: Optional[grpc.Channel] = None,
        wait_for_ready: bool = False,
        token: Optional[str] = None,
        tls_ca: Union[None, str, bytes] = None,
        tls_cert: Union[None, str, bytes] = None,
        tls_key: Union[None, str, bytes] = None,
    ):
        """`target`: "host", "host:port" (port 50051 when left out),
        "dns:///name:port" (every address the name resolves to, round robin),
        or several "host:port" (a list or one comma-separated string; calls
        spread round robin over identical replicas). With `wait_for_ready`,
        the constructor waits up to `timeout` for the server and raises
        :class:`kinplan.errors.Unavailable` if none answers.

        Security (both off by default, as on the server): `token` is sent as
        ``authorization: Bearer <token>`` on every call; `tls_ca` (a PEM
        file path or bytes) turns on TLS, trusting that CA; `tls_cert` and
        `tls_key` add a client certificate for mutual TLS."""
        self.target = normalize_target(target)
        self.timeout = timeout
        options = _channel_options(self.target, max_message_bytes)
        if channel is None:
            if tls_ca is not None:
                creds = grpc.ssl_channel_credentials(
                    root_certificates=_pem(tls_ca),
                    private_key=_pem(tls_key) if tls_key is not None else None,
                    certificate_chain=_pem(tls_cert) if tls_cert is not None else None,
                )
                channel = grpc.secure_channel(self.target, creds, options=options)
            elif tls_cert is not None or tls_key is not None:
                raise invalid_argument("tls_ca", "a client certificate needs TLS: give tls_ca too")
            else:
                channel = grpc.insecure_channel(self.target, options=options)
            if token is not None:
                channel = grpc.intercept_channel(channel, _BearerToken(token))
        self._channel = channel
        self._stubs = Stubs(channel)
        if wait_for_ready:
            self.wait_for_ready(timeout)

    @classmethod
    def local(cls, *, timeout: Optional[float] = DEFAULT_TIMEOUT, cpu_threads: int = 0,
              acm_samples: int = 10_000) -> "Client":
        """A client whose calls run in this process: kinplan's services through
        the native extension (``pip install kinplan-native``), with the same
        API, validation and errors as a server, and no network hop — for
        latency-critical loops. `cpu_threads` sizes its CPU pool (0: one per
        core); `acm_samples` is the random states sampled per robot for its
        allowed-collision matrix (planning)."""
        from .inprocess import LocalChannel

        client = cls(timeout=timeout, channel=LocalChannel(cpu_threads, acm_samples))
        client.target = "in-process"
        return client

    def wait_for_ready(self, timeout: Optional[float] = None) -> None:
        """Blocks until the channel connects (at most `timeout` s, default the
        client's); raises :class:`kinplan.errors.Unavailable` otherwise."""
        if self.target == "in-process":
            return
        t = self.timeout if timeout is None else timeout
        try:
            grpc.channel_ready_future(self._channel).result(timeout=t)
        except grpc.FutureTimeoutError:
            raise _no_server(self.target, t) from None

    def ping(self, *, timeout: Optional[float] = None) -> float:
        """Round-trip time (s) of the cheapest call (ListRobots); raises
        :class:`kinplan.errors.Unavailable` when no server answers."""
        t0 = time.perf_counter()
        self._run(_robot.list_robots(), timeout)
        return time.perf_counter() - t0

    def __repr__(self) -> str:
        return f"kinplan.Client({self.target!r}, timeout={self.timeout})"

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        self._channel.close()

    def _raw_unary(self, path: str, response: Any) -> Any:
        """A unary method that sends an already-encoded request (bytes) and
        decodes the answer as `response` (``None``: the answer's bytes): the
        fast path of hot calls."""
        try:
            return self.__dict__["_raw_methods"][(path, response)]
        except KeyError:
            cache = self.__dict__.setdefault("_raw_methods", {})
            # registered as the generated stubs register theirs (the core
            # interns the method's path once, not per call)
            method = cache[(path, response)] = self._channel.unary_unary(
                path, request_serializer=None, response_deserializer=None if response is None else response.FromString,
                _registered_method=True,
            )
            return method

    def _call(self, method: Callable[..., Any], request: Any, timeout: Optional[float]) -> Any:
        try:
            return method(request, timeout=self.timeout if timeout is None else timeout)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None

    def _run(self, call: Call[Any], timeout: Optional[float]) -> Any:
        """Runs a unary :class:`kinplan._services.Call` that is not about a robot."""
        return call.read(self._call(self._stubs.method(call), call.request, timeout))

    def _stream(self, call: Call[Any], request: Any, timeout: Optional[float]) -> Iterator[Any]:
        """The messages of a server-streaming `call`, each read; its errors as :class:`KinplanError`."""
        t = self.timeout if timeout is None else timeout
        try:
            for message in self._stubs.method(call)(request, timeout=t):
                yield call.read(message)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None

    # the generated stubs, for code that calls them directly
    @property
    def _robots(self) -> Any:
        return self._stubs["robot"]

    @property
    def _kinematics(self) -> Any:
        return self._stubs["kinematics"]

    @property
    def _planning(self) -> Any:
        return self._stubs["planning"]

    @property
    def _scoring(self) -> Any:
        return self._stubs["scoring"]

    @property
    def _exploration(self) -> Any:
        return self._stubs["exploration"]

    def list_robots(self, *, timeout: Optional[float] = None) -> List[Dict[str, Any]]:
        """The built-in robots: name, dof, description, base and tip links."""
        out: List[Dict[str, Any]] = self._run(_robot.list_robots(), timeout)
        return out

    def robot(
        self,
        name: Optional[str] = None,
        *,
        urdf: Optional[Union[str, "os.PathLike[str]"]] = None,
        base_link: str = "",
        tip_link: str = "",
        strict: bool = False,
        package_dirs: Optional[Sequence[Union[str, "os.PathLike[str]"]]] = None,
        meshes: Optional[Mapping[str, bytes]] = None,
        srdf: Optional[Union[str, "os.PathLike[str]"]] = None,
        group: str = "",
        held_joints: Optional[Mapping[str, float]] = None,
    ) -> Robot:
        """A built-in robot by `name`, or a model sent as `urdf` (its text,
        or the path of a URDF file): the handle of every call about it
        (``fk``, ``ik``, ``plan``, ``check``, ``score``, ...).

        The collision meshes a URDF names travel with it (the server opens
        no file): given as `meshes` (``{uri: bytes}``, the URI as the URDF
        writes it), or read from disk when the URDF is a file or
        `package_dirs` are given — ``package://pkg/...`` under each package
        dir, relative paths next to the URDF, as pinocchio resolves them. A
        mesh that cannot be found raises :class:`FileNotFoundError` naming it
        and every place looked. STL, OBJ and COLLADA are read by the server.

        `srdf` (MoveIt's SRDF, text or path) comes with the model: its
        ``disable_collisions`` pairs are never checked, `group` names one of
        its groups as the chain (instead of `base_link`/`tip_link`), and
        ``robot.describe().named_state("ready")`` gives a group state as a
        joint vector in chain order.

        `held_joints` (``{joint: value}``, rad or m) holds joints off the
        chain — a gripper's fingers, another arm — where the collision model
        puts their links; unnamed ones sit at 0 clamped into their limits.

        Joint values outside the robot's limits (usually degrees given where
        radians are meant) raise a :class:`kinplan.JointLimitWarning` in
        ``fk``, ``fk_batch``, ``jacobian`` and ``score``; with
        `strict=True` they raise :class:`kinplan.InvalidArgument` instead."""
        check_robot_args(name, urdf)
        text, files = (None, {}) if urdf is None else load_model(urdf, package_dirs, meshes)
        robot = Robot(self, name=name, urdf=text, base_link=base_link, tip_link=tip_link, strict=strict)
        robot.mesh_files, robot.srdf_text, robot.group = files, load_text(srdf, "srdf"), group
        robot.held_joints = {k: float(v) for k, v in (held_joints or {}).items()}
        return robot

    def _robot_of(self, robot: Any) -> Robot:
        """A robot, or a built-in's name made into one."""
        if robot is None:
            raise ValueError("robot= is required (a name or client.robot(...))")
        return self.robot(robot) if isinstance(robot, str) else robot

    @property
    def mobile(self) -> Mobile:
        """The MobileService calls: wheel kinematics, controller steps and simulated runs."""
        m = self.__dict__.get("_mobile")
        if m is None:
            m = self.__dict__["_mobile"] = Mobile(self)
        return m

    # ---- calls not about one robot -------------------------------------------------------------------------------

    def solve_linear(
        self,
        A: Any,
        b: Any,
        method: Optional[str] = "svd",
        *,
        max_iterations: Optional[int] = None,
        tolerance: Optional[float] = None,
        relative_tolerance: Optional[float] = None,
        rng_seed: int = 0,
        history: bool = False,
        singular_value_tolerance: Optional[float] = None,
        timeout: Optional[float] = None,
    ) -> LinearSolution:
        """Solves ``A x = b`` for any m x n ``A``: ``method="svd"`` (least
        squares, minimum norm) or ``"angle_relaxation"`` /
        ``"angle_relaxation_safeguarded"`` (RLXA: ``max_iterations``, default
        20,000; ``tolerance`` on |b - A x|, default 0.01; ``rng_seed``;
        ``history=True`` returns the residual after every iteration)."""
        call = _kinematics.solve_linear(A, b, method, max_iterations, tolerance, relative_tolerance, rng_seed,
                                        history, singular_value_tolerance)
        out: LinearSolution = self._run(call, timeout)
        return out

    def next_best_view(
        self,
        octree: Any,
        *,
        camera_pose: Any = None,
        robot: Any = None,
        camera_mount: Any = None,
        candidate_poses: Sequence[Any] = (),
        weights: Optional[Sequence[float]] = None,
        gain: str = "intersection",
        ray_fraction: Optional[float] = None,
        max_results: int = 10,
        camera: Optional[Dict[str, Any]] = None,
        region: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> Views:
        """Ranked next views of the unknown space in ``octree`` (an
        :class:`Octree`, a ``.bt``/``.ot`` file's bytes, a binary file object
        or a path: see :meth:`Octree.read`). ``region`` = (min xyz, max xyz),
        metres, world frame: where frontiers are sought. ``weights`` = (w_i,
        w_d, w_r); ``gain`` one of "intersection", "rays", "occlusion_aware",
        "unobserved_voxels"; ``robot`` (optional, a robot or a built-in's name) adds the reach filter and IK
        checks of the best candidates; further ``options`` are fields of
        ``NbvOptions`` (e.g. ``frontier_unknown_ratio=0.3``; an unknown name is a
        TypeError listing them)."""
        if region is not None:
            options["region"] = region
        call = _exploration.next_best_view(octree, camera_pose, camera_mount, candidate_poses, weights, gain,
                                           ray_fraction, max_results, camera, options, robot is not None)
        if robot is not None:
            out: Views = self._robot_of(robot)._run(call, timeout)
            return out
        views: Views = self._run(call, timeout)
        return views

    def insert_scan(
        self,
        octree: Optional[OctreeSource],
        points: Any = None,
        origin: Any = None,
        *,
        depth: Any = None,
        intrinsics: Optional[Sequence[float]] = None,
        camera: Optional[Dict[str, Any]] = None,
        resolution: float = 0.05,
        max_range: Optional[float] = None,
        discretize: bool = False,
        near_ray_spacing: float = 0.0,
        timeout: Optional[float] = None,
    ) -> Octree:
        """Inserts ``points`` (n x 3, world frame, metres) seen from ``origin``
        (3-vector or 4x4 sensor pose) with OctoMap's sensor model into
        ``octree`` (any form :meth:`Octree.read` takes); a new tree at
        ``resolution`` when ``octree`` is None. Returns the updated tree.

        Or a ``depth`` image (height x width; uint16 millimetres or float
        metres, 0 / NaN = no return) taken from ``origin``, the camera's
        optical frame (4x4: x right, y down, z forward), with
        ``intrinsics=(fx, fy, cx, cy)`` in pixels or ``camera=`` a camera
        model dict (its width and height those of the image).
        ``near_ray_spacing`` (cells, in [0, 1]; depth images only): trace
        only a pixel lattice this dense close to the camera, 0.7 being the
        suggested value; 0 (default) gives OctoMap's tree exactly."""
        out: Octree = self._run(_exploration.insert_scan(octree, points, origin, resolution, max_range, discretize,
                                                         depth, intrinsics, camera, near_ray_spacing),
                                timeout)
        return out

    def octree_info(self, octree: Any, *, box: Any = None, timeout: Optional[float] = None) -> Dict[str, Any]:
        """Resolution, node and leaf counts, bounds, and free / occupied /
        unknown volume (m^3) inside ``box`` = (min xyz, max xyz) or the bounds."""
        out: Dict[str, Any] = self._run(_exploration.octree_info(octree, box), timeout)
        return out

    def reference_scene(self, name: str = "s0_open_cell", *, seed: int = 1,
                        timeout: Optional[float] = None) -> ReferenceScene:
        """The reference cell ``name`` ("s0_open_cell" or "s0_walled_cell")
        built with ``seed``."""
        out: ReferenceScene = self._run(_exploration.reference_scene(name, seed), timeout)
        return out

    def explore(
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
    ) -> Iterator[Union[ExploreStep, ExploreSummary]]:
        """Explores ``region`` = (min xyz, max xyz) of the simulated ``scene``
        with a depth camera on ``robot`` from joints ``start`` (all three
        taken from ``scene`` when it is a :class:`ReferenceScene`; ``robot``
        may be a built-in's name): yields an
        :class:`ExploreStep` per iteration, then the :class:`ExploreSummary`.
        ``planner``: "rrt_connect", "stomp" or "ccstomp"; ``weights`` =
        (w_i, w_d, w_r) of the NBV utility (S0's IG1_T025_R01 = (1, 0.25, 0.1)
        by default). ``nbv`` takes ``NbvOptions`` fields, ``plan_options``
        ``PlanOptions`` fields (e.g. ``{"stomp": {"timesteps": 20}}``), and
        further ``options`` the remaining ``ExploreRequest`` fields
        (``noise_stddev``, ``near_ray_spacing`` — cells in [0, 1], each scan
        inserted as its depth image with the beams' near field shared, 0 by
        default —, ``candidates_per_iteration``, ``plan_time_budget``,
        ``time_budget``)."""
        call = _exploration.explore(
            self.robot, robot, scene, start, region, planner, weights, seed, resolution, pixel_stride, known_ratio,
            max_iterations, max_consecutive_failures, camera, camera_mount, nbv, plan_options, options,
        )
        yield from self._stream(call, call.request, timeout)

    # ---- the per-robot calls of earlier releases -----------------------------------------------------------------

    def plan(
        self,
        robot: Any,
        *,
        start: Any,
        goal: Any = None,
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
        """Deprecated alias of :meth:`kinplan.Robot.plan`, kept for one
        release: ``client.plan(robot, start=...)`` is
        ``robot.plan(start, ...)`` (``robot`` may be a built-in's name)."""
        _deprecated("plan", "robot.plan(start, goal, ...)")
        return self._robot_of(robot).plan(
            start, goal, pose=pose, algorithm=algorithm, scene=scene, seed=seed, time_budget=time_budget,
            motion_resolution=motion_resolution, padded_motion=padded_motion,
            return_cost_history=return_cost_history, stomp=stomp, cartesian=cartesian, rrt_connect=rrt_connect,
            timing=timing, timeout=timeout)

    def plan_stream(self, robot: Any, *, start: Any, goal: Any = None, pose: Any = None,
                    algorithm: str = "stomp", scene: Optional[Sequence[Obstacle]] = None, seed: int = 0,
                    timeout: Optional[float] = None, **options: Any) -> Iterator[Union[np.ndarray, Plan]]:
        """Deprecated alias of :meth:`kinplan.Robot.plan_stream`, kept for one release."""
        _deprecated("plan_stream", "robot.plan_stream(start, goal, ...)")
        yield from self._robot_of(robot).plan_stream(start, goal, pose=pose, algorithm=algorithm, scene=scene,
                                                 seed=seed, timeout=timeout, **options)

    def check_states(
        self,
        robot: Any,
        qs: Any,
        scene: Optional[Sequence[Obstacle]] = None,
        *,
        max_distance: float = 1.0,
        timeout: Optional[float] = None,
    ) -> StateChecks:
        """Deprecated alias of :meth:`kinplan.Robot.check`, kept for one
        release: ``client.check_states(robot, qs, scene)`` is ``robot.check(qs, scene)``."""
        _deprecated("check_states", "robot.check(qs, scene)")
        return self._robot_of(robot).check(qs, scene, max_distance=max_distance, timeout=timeout)

    def score(
        self,
        robot: Any,
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
        """Deprecated alias of :meth:`kinplan.Robot.score`, kept for one
        release: ``client.score(robot, q)`` is ``robot.score(q)``."""
        _deprecated("score", "robot.score(q)")
        return self._robot_of(robot).score(
            q, timestamps, weights, series, robot_points=robot_points, max_velocity=max_velocity,
            max_acceleration=max_acceleration, jerk_peaks=jerk_peaks, potential_tolerance=potential_tolerance,
            timeout=timeout)

    def compare(
        self,
        sets: Mapping[str, Sequence[Trajectory]],
        robot: Any = None,
        *,
        weights: Optional[Iterable[float]] = None,
        robot_points: Optional[str] = None,
        max_velocity: Optional[Iterable[float]] = None,
        max_acceleration: Optional[Iterable[float]] = None,
        jerk_peaks: Optional[Mapping[str, Any]] = None,
        potential_tolerance: Optional[float] = None,
        timeout: Optional[float] = None,
    ) -> Comparison:
        """Deprecated alias of :meth:`kinplan.Robot.compare`, kept for one
        release: ``client.compare(sets, robot=r)`` is ``r.compare(sets)``."""
        _deprecated("compare", "robot.compare(sets)")
        return self._robot_of(robot).compare(
            sets, weights=weights, robot_points=robot_points, max_velocity=max_velocity,
            max_acceleration=max_acceleration, jerk_peaks=jerk_peaks, potential_tolerance=potential_tolerance,
            timeout=timeout)


class Mobile:
    """The MobileService calls; reach it as ``client.mobile``."""

    def __init__(self, client: Any):
        self._client = client

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
        out: WheelKinematics = self._client._run(_mobile.wheels(chassis, twist, wheels, chassis_params), timeout)
        return out

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
        world: Optional[Iterable[MobileObstacle]] = None,
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
        call = _mobile.step(state, chassis, controller, path, goal, gains, params, sensors, readings, world,
                            robot_radius, seed, dt, token, chassis_params)
        out: StepResult = self._client._run(call, timeout)
        return out

    def follow(
        self,
        chassis: str = "differential",
        start: Sequence[float] = (0.0, 0.0, 0.0),
        path: Iterable[Sequence[float]] = (),
        controller: str = "lyapunov",
        gains: Optional[Mapping[str, Any]] = None,
        *,
        world: Optional[Iterable[MobileObstacle]] = None,
        robot_radius: Optional[float] = None,
        dt: Optional[float] = None,
        max_time: Optional[float] = None,
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> MobileRun:
        """Simulates ``controller`` along ``path`` ([(x, y[, θ]), ...]; a
        heading is honoured on the last node) from ``start`` = (x, y, θ),
        optionally among obstacles (collisions end the run)."""
        call = _mobile.follow(chassis, start, path, controller, gains, world, robot_radius, dt, max_time,
                              chassis_params)
        out: MobileRun = self._client._run(call, timeout)
        return out

    def navigate(
        self,
        chassis: str = "differential",
        start: Sequence[float] = (0.0, 0.0, 0.0),
        goal: Sequence[float] = (0.0, 0.0),
        world: Optional[Iterable[MobileObstacle]] = None,
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
        call = _mobile.navigate(chassis, start, goal, world, robot_radius, navigator, params, sensors, seed,
                                controller, gains, astar, dt, max_time, chassis_params)
        out: MobileRun = self._client._run(call, timeout)
        return out


def _deprecated(old: str, new: str) -> None:
    """The DeprecationWarning of a per-robot call made on the client (the aliases of one release)."""
    warnings.warn(f"Client.{old}(robot, ...) is deprecated and goes in the next release: use {new}",
                  DeprecationWarning, stacklevel=3)


__all__ = ["DEFAULT_PORT", "DEFAULT_TIMEOUT", "Client", "JointLimits", "Mobile", "Robot", "RobotDescription", "RobotRefs",
           "normalize_target"]
