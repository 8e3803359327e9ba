"""``kinplan.aio.Client.mobile``: the MobileService calls for asyncio, with
the arguments, results and errors of :class:`kinplan.client.Mobile`.
Requests and replies are built and read by :mod:`kinplan._services.mobile`;
each method only awaits its call."""
from __future__ import annotations

from typing import Any, Iterable, Mapping, Optional, Sequence, Union

from .._services import mobile as _mobile
from ..mobile import MobileRun, Obstacle, StepResult, WheelKinematics


class AsyncMobile:
    """The MobileService calls for asyncio; reach it as ``client.mobile``
    of a :class:`kinplan.aio.Client`."""

    def __init__(self, client: Any):
        self._client = client

    async def wheels(
        self,
        chassis: str = "differential",
        twist: Optional[Sequence[float]] = None,
        *,
        wheels: Optional[Mapping[str, Any]] = None,
        chassis_params: Optional[Mapping[str, float]] = None,
        timeout: Optional[float] = None,
    ) -> WheelKinematics:
        """As :meth:`kinplan.mobile.Mobile.wheels`."""
        out: WheelKinematics = await self._client._run(_mobile.wheels(chassis, twist, wheels, chassis_params), timeout)
        return out

    async def step(
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
        """As :meth:`kinplan.mobile.Mobile.step` (pass the previous result or
        its ``token`` to continue)."""
        call = _mobile.step(state, chassis, controller, path, goal, gains, params, sensors, readings, world,
                            robot_radius, seed, dt, token, chassis_params)
        out: StepResult = await self._client._run(call, timeout)
        return out

    async def follow(
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
        """As :meth:`kinplan.mobile.Mobile.follow`."""
        call = _mobile.follow(chassis, start, path, controller, gains, world, robot_radius, dt, max_time,
                              chassis_params)
        out: MobileRun = await self._client._run(call, timeout)
        return out

    async def navigate(
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
        """As :meth:`kinplan.mobile.Mobile.navigate`."""
        call = _mobile.navigate(chassis, start, goal, world, robot_radius, navigator, params, sensors, seed,
                                controller, gains, astar, dt, max_time, chassis_params)
        out: MobileRun = await self._client._run(call, timeout)
        return out
