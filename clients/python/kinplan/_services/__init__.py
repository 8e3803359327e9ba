"""The layer the blocking and the asyncio clients share, one module per
gRPC service (:mod:`.robot`, :mod:`.kinematics`, :mod:`.planning`,
:mod:`.scoring`, :mod:`.exploration`, :mod:`.mobile`).

Each function there takes a call's Python arguments, checks them, and
returns a :class:`Call`: the stub method to call, the request (for a call
about one robot, a function of the robot's reference that builds it, so the
robot can send its URDF again when a replica does not hold it) and the
function that reads the reply. A client only runs it — ``kinplan.Client``
and ``kinplan.Robot`` block on it, ``kinplan.aio`` awaits it — so both give
the same answers and raise the same errors before anything is sent.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Dict, Generic, Optional, TypeVar

from ..v1 import (
    exploration_pb2_grpc,
    kinematics_pb2_grpc,
    mobile_pb2_grpc,
    planning_pb2_grpc,
    robot_pb2_grpc,
    scoring_pb2_grpc,
)

R = TypeVar("R")

#: The generated stub class of each service, by the name a :class:`Call` gives.
STUBS: Dict[str, Callable[[Any], Any]] = {
    "robot": robot_pb2_grpc.RobotServiceStub,
    "kinematics": kinematics_pb2_grpc.KinematicsServiceStub,
    "planning": planning_pb2_grpc.PlanningServiceStub,
    "scoring": scoring_pb2_grpc.ScoringServiceStub,
    "exploration": exploration_pb2_grpc.ExplorationServiceStub,
    "mobile": mobile_pb2_grpc.MobileServiceStub,
}


@dataclass(frozen=True)
class Call(Generic[R]):
    """One call: ``service`` (a key of :data:`STUBS`) and ``method`` name the
    stub method; ``request`` is the request message, or ``build`` makes it
    from a robot reference (a call about a robot); ``read`` turns the reply
    — each message of a server stream when ``streaming`` — into the result."""

    service: str
    method: str
    read: Callable[[Any], R]
    request: Any = None
    build: Optional[Callable[[Any], Any]] = None
    streaming: bool = False


class Stubs:
    """The generated stubs of a channel, made on first use."""

    def __init__(self, channel: Any):
        self._channel = channel
        self._made: Dict[str, Any] = {}

    def __getitem__(self, service: str) -> Any:
        stub = self._made.get(service)
        if stub is None:
            stub = self._made[service] = STUBS[service](self._channel)
        return stub

    def method(self, call: "Call[Any]") -> Any:
        """The stub method `call` names."""
        return getattr(self[call.service], call.method)
