"""``kinplan.aio``: the client for asyncio programs, on ``grpc.aio``.

    async with kinplan.aio.Client("127.0.0.1:50051") as c:
        robot = c.robot("kuka_kr210_r2700_extra")
        T = await robot.fk(q)
        sols = await asyncio.gather(*(robot.ik(T_k) for T_k in targets))  # concurrent calls
        async with robot.stream_ik(seed=q) as s:
            answer = await s.solve(T)
        async for frame in c.robot("ur5").plan_stream(q0, q1):          # server streams: async iterators
            ...

Same names, arguments, results and errors as the blocking client
(:class:`kinplan.Client`, :class:`kinplan.Robot`, ``client.mobile``), method
for method; each method awaits its call, and many calls can be in flight on
one channel. Server streams (``plan_stream``, ``explore``) are async
iterators. Requests are built and replies read by :mod:`kinplan._services`,
the layer both clients share, so both give the same answers.
"""
from __future__ import annotations

import asyncio
import os
import warnings
from typing import Any, AsyncIterator, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import grpc
import grpc.aio
import numpy as np
import numpy.typing as npt

from .._channel import DEFAULT_TIMEOUT, _channel_options, _no_server, _pem, normalize_target
from .._services import Call, Stubs
from .._services import exploration as _exploration
from .._services import kinematics as _kinematics
from .._services import robot as _robot
from .._services.robot import check_robot_args
from .._model_files import load_model, load_text
from ..errors import KinplanError, invalid_argument
from ..exploration_loop import ExploreStep, ExploreSummary, ReferenceScene
from ..kinematics import LinearSolution
from ..octree import Octree, OctreeSource, Views
from ..planning import Obstacle, Plan, StateChecks
from ..scoring import Comparison, Scores, Trajectory
from ._mobile import AsyncMobile
from ._async_robot import AsyncIkStream, AsyncRobot

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
        from ..inprocess import AioLocalChannel

        client = cls.__new__(cls)
        client.target, client.timeout, client._metadata = "in-process", timeout, None
        client._channel = AioLocalChannel(cpu_threads, acm_samples)
        client._attach_stubs()
        return client

    def _attach_stubs(self) -> None:
        self._stubs = Stubs(self._channel)
        self.mobile = AsyncMobile(self)
        """The MobileService calls (as :attr:`kinplan.Client.mobile`)."""

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

    async def _run(self, call: Call[Any], timeout: Optional[float]) -> Any:
        """Awaits a unary :class:`kinplan._services.Call` that is not about a robot."""
        return call.read(await self._call(self._stubs.method(call), call.request, timeout))

    async def _stream(self, spec: Call[Any], request: Any, timeout: Optional[float]) -> AsyncIterator[Any]:
        """The messages of a server-streaming call, each read; its errors as
        :class:`KinplanError`. Leaving the loop early cancels the call."""
        method = self._stubs.method(spec)
        call = method(request, timeout=self.timeout if timeout is None else timeout, metadata=self._metadata)
        try:
            async for message in call:
                yield spec.read(message)
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
        await self._run(_robot.list_robots(), timeout)
        return asyncio.get_running_loop().time() - t0

    async def list_robots(self, *, timeout: Optional[float] = None) -> List[Dict[str, Any]]:
        """As :meth:`kinplan.Client.list_robots`."""
        out: List[Dict[str, Any]] = await self._run(_robot.list_robots(), timeout)
        return out

    def robot(self, name: Optional[str] = None, *, urdf: Optional[Union[str, "os.PathLike[str]"]] = None,
              base_link: str = "", tip_link: str = "", strict: bool = False,
              package_dirs: Optional[Sequence[Union[str, "os.PathLike[str]"]]] = None,
              meshes: Optional[Mapping[str, bytes]] = None,
              srdf: Optional[Union[str, "os.PathLike[str]"]] = None, group: str = "",
              held_joints: Optional[Mapping[str, float]] = None) -> AsyncRobot:
        """As :meth:`kinplan.Client.robot`."""
        check_robot_args(name, urdf)
        text, files = (None, {}) if urdf is None else load_model(urdf, package_dirs, meshes)
        robot = AsyncRobot(self, name=name, urdf=text, base_link=base_link, tip_link=tip_link, strict=strict)
        robot.mesh_files, robot.srdf_text, robot.group = files, load_text(srdf, "srdf"), group
        robot.held_joints = {k: float(v) for k, v in (held_joints or {}).items()}
        return robot

    def _robot_of(self, robot: Any) -> AsyncRobot:
        if robot is None:
            raise ValueError("robot= is required (a name or client.robot(...))")
        return self.robot(robot) if isinstance(robot, str) else robot

    async def solve_linear(self, A: Any, b: Any, method: Optional[str] = "svd", *,
                           max_iterations: Optional[int] = None, tolerance: Optional[float] = None,
                           relative_tolerance: Optional[float] = None, rng_seed: int = 0, history: bool = False,
                           singular_value_tolerance: Optional[float] = None,
                           timeout: Optional[float] = None) -> LinearSolution:
        """As :meth:`kinplan.Client.solve_linear`."""
        call = _kinematics.solve_linear(A, b, method, max_iterations, tolerance, relative_tolerance, rng_seed,
                                        history, singular_value_tolerance)
        out: LinearSolution = await self._run(call, timeout)
        return out

    async def next_best_view(self, octree: Any, *, camera_pose: Any = None, robot: Any = None,
                             camera_mount: Any = None, candidate_poses: Sequence[Any] = (),
                             weights: Optional[Sequence[float]] = None, gain: str = "intersection",
                             ray_fraction: Optional[float] = None, max_results: int = 10,
                             camera: Optional[Dict[str, Any]] = None,
                             region: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None,
                             timeout: Optional[float] = None, **options: Any) -> Views:
        """As :meth:`kinplan.Client.next_best_view`."""
        if region is not None:
            options["region"] = region
        call = _exploration.next_best_view(octree, camera_pose, camera_mount, candidate_poses, weights, gain,
                                           ray_fraction, max_results, camera, options, robot is not None)
        if robot is not None:
            out: Views = await self._robot_of(robot)._run(call, timeout)
            return out
        views: Views = await self._run(call, timeout)
        return views

    async def insert_scan(self, octree: Optional[OctreeSource], points: Any = None, origin: Any = None, *,
                          depth: Any = None, intrinsics: Optional[Sequence[float]] = None,
                          camera: Optional[Dict[str, Any]] = None,
                          resolution: float = 0.05, max_range: Optional[float] = None, discretize: bool = False,
                          near_ray_spacing: float = 0.0,
                          timeout: Optional[float] = None) -> Octree:
        """As :meth:`kinplan.Client.insert_scan`."""
        call = _exploration.insert_scan(octree, points, origin, resolution, max_range, discretize,
                                        depth, intrinsics, camera, near_ray_spacing)
        out: Octree = await self._run(call, timeout)
        return out

    async def octree_info(self, octree: Any, *, box: Any = None, timeout: Optional[float] = None) -> Dict[str, Any]:
        """As :meth:`kinplan.Client.octree_info`."""
        out: Dict[str, Any] = await self._run(_exploration.octree_info(octree, box), timeout)
        return out

    async def reference_scene(self, name: str = "s0_open_cell", *, seed: int = 1,
                              timeout: Optional[float] = None) -> ReferenceScene:
        """As :meth:`kinplan.Client.reference_scene`."""
        out: ReferenceScene = await self._run(_exploration.reference_scene(name, seed), timeout)
        return out

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
        call = _exploration.explore(
            self.robot, robot, scene, start, region, planner, weights, seed, resolution, pixel_stride, known_ratio,
            max_iterations, max_consecutive_failures, camera, camera_mount, nbv, plan_options, options,
        )
        async for message in self._stream(call, call.request, timeout):
            yield message

    # ---- the per-robot calls of earlier releases (deprecated aliases, as the blocking client's) ------------------

    async def plan(self, robot: Any, *, start: Any, goal: Any = None, pose: Any = None,
                   algorithm: str = "rrt_connect", scene: Optional[Sequence[Obstacle]] = None, seed: int = 0,
                   time_budget: Optional[float] = None, motion_resolution: Optional[float] = None,
                   padded_motion: bool = False, return_cost_history: bool = True,
                   stomp: Optional[Mapping[str, Any]] = None, cartesian: Optional[Mapping[str, Any]] = None,
                   rrt_connect: Optional[Mapping[str, Any]] = None, timing: Optional[Mapping[str, Any]] = None,
                   timeout: Optional[float] = None) -> Plan:
        """Deprecated alias of :meth:`AsyncRobot.plan`, kept for one release."""
        _deprecated("plan", "robot.plan(start, goal, ...)")
        return await self._robot_of(robot).plan(
            start, goal, pose=pose, algorithm=algorithm, scene=scene, seed=seed, time_budget=time_budget,
            motion_resolution=motion_resolution, padded_motion=padded_motion,
            return_cost_history=return_cost_history, stomp=stomp, cartesian=cartesian, rrt_connect=rrt_connect,
            timing=timing, timeout=timeout)

    async def plan_stream(self, robot: Any, *, start: Any, goal: Any = None, pose: Any = None,
                          algorithm: str = "stomp", scene: Optional[Sequence[Obstacle]] = None, seed: int = 0,
                          timeout: Optional[float] = None, **options: Any) -> AsyncIterator[Union[np.ndarray, Plan]]:
        """Deprecated alias of :meth:`AsyncRobot.plan_stream`, kept for one release."""
        _deprecated("plan_stream", "robot.plan_stream(start, goal, ...)")
        async for message in self._robot_of(robot).plan_stream(start, goal, pose=pose, algorithm=algorithm,
                                                               scene=scene, seed=seed, timeout=timeout, **options):
            yield message

    async def check_states(self, robot: Any, qs: Any, scene: Optional[Sequence[Obstacle]] = None, *,
                           max_distance: float = 1.0, timeout: Optional[float] = None) -> StateChecks:
        """Deprecated alias of :meth:`AsyncRobot.check`, kept for one release."""
        _deprecated("check_states", "robot.check(qs, scene)")
        return await self._robot_of(robot).check(qs, scene, max_distance=max_distance, timeout=timeout)

    async def score(self, robot: Any, q: Trajectory, timestamps: Optional[Iterable[float]] = None,
                    weights: Optional[Iterable[float]] = None, series: bool = False, *,
                    robot_points: Optional[str] = None, max_velocity: Optional[Iterable[float]] = None,
                    max_acceleration: Optional[Iterable[float]] = None, jerk_peaks: Optional[Mapping[str, Any]] = None,
                    potential_tolerance: Optional[float] = None, timeout: Optional[float] = None) -> Scores:
        """Deprecated alias of :meth:`AsyncRobot.score`, kept for one release."""
        _deprecated("score", "robot.score(q)")
        return await self._robot_of(robot).score(
            q, timestamps, weights, series, robot_points=robot_points, max_velocity=max_velocity,
            max_acceleration=max_acceleration, jerk_peaks=jerk_peaks, potential_tolerance=potential_tolerance,
            timeout=timeout)

    async def compare(self, sets: Mapping[str, Sequence[Trajectory]], robot: Any = None, *,
                      weights: Optional[Iterable[float]] = None, robot_points: Optional[str] = None,
                      max_velocity: Optional[Iterable[float]] = None, max_acceleration: Optional[Iterable[float]] = None,
                      jerk_peaks: Optional[Mapping[str, Any]] = None, potential_tolerance: Optional[float] = None,
                      timeout: Optional[float] = None) -> Comparison:
        """Deprecated alias of :meth:`AsyncRobot.compare`, kept for one release."""
        _deprecated("compare", "robot.compare(sets)")
        return await self._robot_of(robot).compare(
            sets, weights=weights, robot_points=robot_points, max_velocity=max_velocity,
            max_acceleration=max_acceleration, jerk_peaks=jerk_peaks, potential_tolerance=potential_tolerance,
            timeout=timeout)


def _deprecated(old: str, new: str) -> None:
    warnings.warn(f"kinplan.aio.Client.{old}(robot, ...) is deprecated and goes in the next release: use {new}",
                  DeprecationWarning, stacklevel=3)
