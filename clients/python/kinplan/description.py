"""What a robot is, as the server describes it: :class:`RobotDescription`,
and the joint limits the clients check joint values against."""
from __future__ import annotations

import operator
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, List

import numpy as np

from .errors import JointLimitWarning, invalid_argument
from .v1 import robot_pb2


@dataclass
class RobotDescription:
    """A robot's chain as the server sees it. Limits in rad (m for prismatic
    joints); infinite for unlimited joints; max_velocity 0 when unknown."""

    name: str
    base_link: str
    tip_link: str
    joint_names: List[str]
    joint_types: List[str]
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    link_names: List[str]
    model_id: bytes = b""
    raw: Any = field(default=None, repr=False)

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @property
    def named_states(self) -> Dict[str, Dict[str, float]]:
        """The SRDF's group states: ``{name: {joint: value}}`` (empty without an SRDF)."""
        if self.raw is None:
            return {}
        return {s.name: dict(zip(s.joint_names, s.positions)) for s in self.raw.named_states}

    @property
    def analytic_family(self) -> str:
        """The chain's analytic IK family ("spherical_wrist",
        "three_parallel", "spherical_two_intersecting", or "searched_6r" for a 6-joint offset wrist
        solved by a 1-D search), or "" when ``method="analytic"`` does not apply
        (then :attr:`analytic_reason` says why)."""
        return "" if self.raw is None else str(self.raw.analytic_family)

    @property
    def analytic_held_joint(self) -> int:
        """7-joint arms: the joint (0-based) the analytic method holds at the
        seed's value by default; -1 otherwise."""
        return -1 if self.raw is None else int(self.raw.analytic_held_joint)

    @property
    def analytic_reversed(self) -> bool:
        """The analytic family holds for the chain read from the tool end
        (the Panda with joint 7 held): the solver inverts the pose and reverses
        the joints, and the solutions' ``config`` flags name the reversed
        chain's shoulder, elbow and wrist."""
        return False if self.raw is None else bool(self.raw.analytic_reversed)

    @property
    def analytic_reason(self) -> str:
        """Why the analytic IK method does not apply ("" when it does)."""
        return "" if self.raw is None else str(self.raw.analytic_reason)

    def named_state(self, name: str) -> np.ndarray:
        """The SRDF group state `name` as a joint vector in chain order. A
        chain joint the state does not set is an error naming it."""
        states = self.named_states
        if name not in states:
            raise KeyError(f"no named state {name!r}; the SRDF has {sorted(states) or 'none'}")
        values = states[name]
        missing = [j for j in self.joint_names if j not in values]
        if missing:
            raise ValueError(f"named state {name!r} does not set the chain joints {missing}")
        return np.array([values[j] for j in self.joint_names])

    @classmethod
    def from_proto(cls, r: robot_pb2.DescribeRobotResponse) -> "RobotDescription":
        return cls(
            name=r.name,
            base_link=r.base_link,
            tip_link=r.tip_link,
            joint_names=[j.name for j in r.joints],
            joint_types=[robot_pb2.JointType.Name(j.type).removeprefix("JOINT_TYPE_").lower() for j in r.joints],
            lower=np.array([j.lower for j in r.joints]),
            upper=np.array([j.upper for j in r.joints]),
            max_velocity=np.array([j.max_velocity for j in r.joints]),
            link_names=[link.name for link in r.links],
            model_id=r.model_id,
            raw=r,
        )


class JointLimits:
    """A chain's joint limits for the client-side guard against degrees: a
    value outside [lower, upper] (1e-9 of slack) warns, or raises when strict."""

    def __init__(self, d: RobotDescription):
        self.lower = d.lower - 1e-9
        self.upper = d.upper + 1e-9
        self.names = d.joint_names
        self._lower_list: List[float] = self.lower.tolist()
        self._upper_list: List[float] = self.upper.tolist()

    def check(self, q: Any, field_name: str, strict: bool) -> None:
        if isinstance(q, list) and len(q) == len(self._lower_list):
            # one state as floats (fk, jacobian): comparisons mapped in C are the cheapest test
            if all(map(operator.le, self._lower_list, q)) and all(map(operator.le, q, self._upper_list)):
                return
        arr = np.asarray(q, dtype=float)
        if arr.ndim == 0 or arr.shape[-1] != len(self.lower):
            return  # the server names a wrong length
        outside = (arr < self.lower) | (arr > self.upper)
        if not outside.any():
            return
        where = np.argwhere(outside)[0]
        j = int(where[-1])
        value = float(arr[tuple(where)])
        message = (
            f"{int(outside.sum())} joint value(s) outside the limits, e.g. {self.names[j]} = {value:.6g} not in "
            f"[{self.lower[j] + 1e-9:.6g}, {self.upper[j] - 1e-9:.6g}]; kinplan takes radians (m for prismatic "
            "joints): degrees? use np.radians(...)"
        )
        if strict:
            raise invalid_argument(field_name, message)
        warnings.warn(f"{field_name}: {message}", JointLimitWarning, stacklevel=4)
