"""RobotService: robot references, descriptions, forward kinematics and
Jacobians — requests built and replies read for both clients."""
from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

from .. import _codec
from .._codec import joints, length_delimited
from .._convert import matrix_from_proto, matrix_to_proto
from .._rotation import poses_to_matrices
from ..description import RobotDescription
from ..errors import invalid_argument
from ..v1 import common_pb2, robot_pb2
from . import Call

#: The hand-encoded forward-kinematics call of the blocking client.
FORWARD_KINEMATICS = "/kinplan.v1.RobotService/ForwardKinematics"


def check_robot_args(name: Optional[str], urdf: Optional[Any]) -> None:
    """``Client.robot``'s checks: one of a name or a URDF (text or an
    existing file's path: :func:`kinplan._model_files.load_model` reads it)."""
    if (name is None) == (urdf is None):
        raise invalid_argument("name", "give exactly one of name or urdf=")


class RobotRefs:
    """How a robot names itself in requests (shared by :class:`kinplan.Robot`
    and :class:`kinplan.aio.AsyncRobot`): by name, by model id once the
    server has given one, else (or when resending) the URDF text."""

    name: Optional[str]
    urdf_text: Optional[str]
    mesh_files: Dict[str, bytes]
    srdf_text: Optional[str]
    group: str
    held_joints: Dict[str, float]
    base_link: str
    tip_link: str
    model_id: bytes

    def _ref(self, inline: bool = False) -> common_pb2.RobotRef:
        """The RobotRef of this robot's next request. Cached while the model
        id stays the same; callers copy it, never change it."""
        key = (inline, self.model_id)
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[0] == key:
            ref: common_pb2.RobotRef = cached[1]
            return ref
        ref = self._new_ref(inline)
        self.__dict__["_ref_cache"] = (key, ref, length_delimited(_codec.ROBOT_REF, ref.SerializeToString()))
        return ref

    def _ref_field(self, ref: common_pb2.RobotRef) -> bytes:
        """`ref` (from :meth:`_ref`) encoded as the robot field of a
        hand-encoded request, cached with it."""
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[1] is ref:
            encoded: bytes = cached[2]
            return encoded
        return length_delimited(_codec.ROBOT_REF, ref.SerializeToString())

    def _new_ref(self, inline: bool) -> common_pb2.RobotRef:
        ref = common_pb2.RobotRef(base_link=self.base_link, tip_link=self.tip_link, group=self.group)
        ref.held_joints.update(self.held_joints)
        if self.name is not None:
            ref.name = self.name
        elif self.model_id and not inline:
            ref.model_id = self.model_id
        else:
            ref.urdf = self.urdf_text or ""
            for uri, data in sorted(self.mesh_files.items()):
                ref.meshes.add(uri=uri, data=data)
            ref.srdf = self.srdf_text or ""
        return ref

    def limits_key(self) -> Any:
        """What identifies this robot's chain in a client's cache."""
        return (self.name, None if self.urdf_text is None else hash(self.urdf_text), self.base_link, self.tip_link,
                self.group)

    def _learn(self, reply: Any) -> None:
        """Keeps the model id a reply gives an inline model."""
        model_id = getattr(reply, "model_id", b"")
        if model_id and self.urdf_text is not None:
            self.model_id = model_id


def _robots(reply: robot_pb2.ListRobotsResponse) -> List[Dict[str, Any]]:
    return [
        {"name": r.name, "dof": r.dof, "description": r.description, "base_link": r.base_link,
         "tip_link": r.tip_link}
        for r in reply.robots
    ]


def list_robots() -> Call[List[Dict[str, Any]]]:
    """The built-in robots: name, dof, description, base and tip links."""
    return Call("robot", "ListRobots", _robots, request=robot_pb2.ListRobotsRequest())


def describe() -> Call[RobotDescription]:
    return Call("robot", "DescribeRobot", RobotDescription.from_proto,
                build=lambda ref: robot_pb2.DescribeRobotRequest(robot=ref))


def urdf(keep_capsules: bool) -> Call[str]:
    return Call("robot", "DescribeRobot", lambda r: str(r.urdf),
                build=lambda ref: robot_pb2.DescribeRobotRequest(robot=ref, include_urdf=True,
                                                                 keep_capsules=keep_capsules))


def _fk_reply(links: bool) -> Any:
    def read(r: robot_pb2.ForwardKinematicsResponse) -> Any:
        tool = _codec.pose_to_matrix(r.tool_pose)
        if links:
            return tool, {link.name: _codec.pose_to_matrix(link.pose) for link in r.links}
        return tool

    return read


def fk(positions: List[float], links: bool) -> Call[Any]:
    """ForwardKinematics through the generated classes (``positions`` from
    :func:`kinplan._codec.joints`, already checked against the limits)."""
    return Call("robot", "ForwardKinematics", _fk_reply(links),
                build=lambda ref: robot_pb2.ForwardKinematicsRequest(robot=ref, joint_positions=positions,
                                                                     include_links=links))


def fk_body(q: npt.ArrayLike) -> Tuple[List[float], bytes]:
    """The joint values of a hand-encoded ForwardKinematicsRequest and its
    fields after the robot (:func:`kinplan._codec.read_fk_reply` reads the answer)."""
    return _codec.joints_and_field(_codec.FK_JOINTS, q, "q")


def batch_states(qs: Any) -> np.ndarray:
    """`qs` as a contiguous n x dof float array, n >= 1 (one state: one row)."""
    arr = np.ascontiguousarray(qs, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[0] == 0:
        raise invalid_argument("qs", f"must be n x dof with n >= 1, got shape {arr.shape}")
    return arr


def fk_batch(arr: np.ndarray, jacobians: bool) -> Call[Any]:
    """ForwardKinematicsBatch of the states of :func:`batch_states`: (n, 4,
    4) poses, and with `jacobians` the (n, 6, dof) Jacobians."""
    matrix = matrix_to_proto(arr)
    dof = arr.shape[1]

    def read(r: robot_pb2.ForwardKinematicsBatchResponse) -> Any:
        T = poses_to_matrices(np.asarray(r.tool_poses.data, dtype=np.float64))
        if jacobians:
            return T, np.asarray(r.jacobians.data, dtype=np.float64).reshape(len(T), 6, dof)
        return T

    return Call("robot", "ForwardKinematicsBatch", read,
                build=lambda ref: robot_pb2.ForwardKinematicsBatchRequest(robot=ref, joint_positions=matrix,
                                                                          include_jacobians=jacobians))


def jacobian(positions: List[float]) -> Call[np.ndarray]:
    return Call("robot", "Jacobian", lambda r: matrix_from_proto(r.jacobian),
                build=lambda ref: robot_pb2.JacobianRequest(robot=ref, joint_positions=positions))


__all__ = ["RobotRefs", "batch_states", "check_robot_args", "describe", "fk", "fk_batch", "fk_body", "jacobian",
           "joints", "list_robots", "urdf"]
