from kinplan.v1 import common_pb2 as _common_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class JointType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    JOINT_TYPE_UNSPECIFIED: _ClassVar[JointType]
    JOINT_TYPE_REVOLUTE: _ClassVar[JointType]
    JOINT_TYPE_CONTINUOUS: _ClassVar[JointType]
    JOINT_TYPE_PRISMATIC: _ClassVar[JointType]
JOINT_TYPE_UNSPECIFIED: JointType
JOINT_TYPE_REVOLUTE: JointType
JOINT_TYPE_CONTINUOUS: JointType
JOINT_TYPE_PRISMATIC: JointType

class ListRobotsRequest(_message.Message):
    __slots__ = ()
    def __init__(self) -> None: ...

class RobotSummary(_message.Message):
    __slots__ = ("name", "dof", "description", "base_link", "tip_link")
    NAME_FIELD_NUMBER: _ClassVar[int]
    DOF_FIELD_NUMBER: _ClassVar[int]
    DESCRIPTION_FIELD_NUMBER: _ClassVar[int]
    BASE_LINK_FIELD_NUMBER: _ClassVar[int]
    TIP_LINK_FIELD_NUMBER: _ClassVar[int]
    name: str
    dof: int
    description: str
    base_link: str
    tip_link: str
    def __init__(self, name: _Optional[str] = ..., dof: _Optional[int] = ..., description: _Optional[str] = ..., base_link: _Optional[str] = ..., tip_link: _Optional[str] = ...) -> None: ...

class ListRobotsResponse(_message.Message):
    __slots__ = ("robots",)
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    robots: _containers.RepeatedCompositeFieldContainer[RobotSummary]
    def __init__(self, robots: _Optional[_Iterable[_Union[RobotSummary, _Mapping]]] = ...) -> None: ...

class DescribeRobotRequest(_message.Message):
    __slots__ = ("robot", "include_urdf", "keep_capsules", "include_collision_bodies")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    INCLUDE_URDF_FIELD_NUMBER: _ClassVar[int]
    KEEP_CAPSULES_FIELD_NUMBER: _ClassVar[int]
    INCLUDE_COLLISION_BODIES_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    include_urdf: bool
    keep_capsules: bool
    include_collision_bodies: bool
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., include_urdf: _Optional[bool] = ..., keep_capsules: _Optional[bool] = ..., include_collision_bodies: _Optional[bool] = ...) -> None: ...

class JointInfo(_message.Message):
    __slots__ = ("name", "type", "origin", "axis", "lower", "upper", "max_velocity")
    NAME_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    ORIGIN_FIELD_NUMBER: _ClassVar[int]
    AXIS_FIELD_NUMBER: _ClassVar[int]
    LOWER_FIELD_NUMBER: _ClassVar[int]
    UPPER_FIELD_NUMBER: _ClassVar[int]
    MAX_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    name: str
    type: JointType
    origin: _common_pb2.Pose
    axis: _common_pb2.Vec3
    lower: float
    upper: float
    max_velocity: float
    def __init__(self, name: _Optional[str] = ..., type: _Optional[_Union[JointType, str]] = ..., origin: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., axis: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., lower: _Optional[float] = ..., upper: _Optional[float] = ..., max_velocity: _Optional[float] = ...) -> None: ...

class CollisionGeometry(_message.Message):
    __slots__ = ("origin", "box", "sphere", "cylinder", "capsule", "mesh_reference", "mesh")
    ORIGIN_FIELD_NUMBER: _ClassVar[int]
    BOX_FIELD_NUMBER: _ClassVar[int]
    SPHERE_FIELD_NUMBER: _ClassVar[int]
    CYLINDER_FIELD_NUMBER: _ClassVar[int]
    CAPSULE_FIELD_NUMBER: _ClassVar[int]
    MESH_REFERENCE_FIELD_NUMBER: _ClassVar[int]
    MESH_FIELD_NUMBER: _ClassVar[int]
    origin: _common_pb2.Pose
    box: _common_pb2.Box
    sphere: _common_pb2.Sphere
    cylinder: _common_pb2.Cylinder
    capsule: _common_pb2.Capsule
    mesh_reference: str
    mesh: _common_pb2.TriangleMesh
    def __init__(self, origin: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., box: _Optional[_Union[_common_pb2.Box, _Mapping]] = ..., sphere: _Optional[_Union[_common_pb2.Sphere, _Mapping]] = ..., cylinder: _Optional[_Union[_common_pb2.Cylinder, _Mapping]] = ..., capsule: _Optional[_Union[_common_pb2.Capsule, _Mapping]] = ..., mesh_reference: _Optional[str] = ..., mesh: _Optional[_Union[_common_pb2.TriangleMesh, _Mapping]] = ...) -> None: ...

class LinkInfo(_message.Message):
    __slots__ = ("name", "parent_joint", "offset", "collision")
    NAME_FIELD_NUMBER: _ClassVar[int]
    PARENT_JOINT_FIELD_NUMBER: _ClassVar[int]
    OFFSET_FIELD_NUMBER: _ClassVar[int]
    COLLISION_FIELD_NUMBER: _ClassVar[int]
    name: str
    parent_joint: int
    offset: _common_pb2.Pose
    collision: _containers.RepeatedCompositeFieldContainer[CollisionGeometry]
    def __init__(self, name: _Optional[str] = ..., parent_joint: _Optional[int] = ..., offset: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., collision: _Optional[_Iterable[_Union[CollisionGeometry, _Mapping]]] = ...) -> None: ...

class DescribeRobotResponse(_message.Message):
    __slots__ = ("name", "model_id", "base_link", "tip_link", "joints", "links", "tip_offset", "urdf", "collision_bodies", "named_states", "analytic_family", "analytic_reason", "analytic_held_joint", "analytic_reversed")
    NAME_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    BASE_LINK_FIELD_NUMBER: _ClassVar[int]
    TIP_LINK_FIELD_NUMBER: _ClassVar[int]
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    LINKS_FIELD_NUMBER: _ClassVar[int]
    TIP_OFFSET_FIELD_NUMBER: _ClassVar[int]
    URDF_FIELD_NUMBER: _ClassVar[int]
    COLLISION_BODIES_FIELD_NUMBER: _ClassVar[int]
    NAMED_STATES_FIELD_NUMBER: _ClassVar[int]
    ANALYTIC_FAMILY_FIELD_NUMBER: _ClassVar[int]
    ANALYTIC_REASON_FIELD_NUMBER: _ClassVar[int]
    ANALYTIC_HELD_JOINT_FIELD_NUMBER: _ClassVar[int]
    ANALYTIC_REVERSED_FIELD_NUMBER: _ClassVar[int]
    name: str
    model_id: bytes
    base_link: str
    tip_link: str
    joints: _containers.RepeatedCompositeFieldContainer[JointInfo]
    links: _containers.RepeatedCompositeFieldContainer[LinkInfo]
    tip_offset: _common_pb2.Pose
    urdf: str
    collision_bodies: _containers.RepeatedCompositeFieldContainer[CollisionBodyInfo]
    named_states: _containers.RepeatedCompositeFieldContainer[NamedState]
    analytic_family: str
    analytic_reason: str
    analytic_held_joint: int
    analytic_reversed: bool
    def __init__(self, name: _Optional[str] = ..., model_id: _Optional[bytes] = ..., base_link: _Optional[str] = ..., tip_link: _Optional[str] = ..., joints: _Optional[_Iterable[_Union[JointInfo, _Mapping]]] = ..., links: _Optional[_Iterable[_Union[LinkInfo, _Mapping]]] = ..., tip_offset: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., urdf: _Optional[str] = ..., collision_bodies: _Optional[_Iterable[_Union[CollisionBodyInfo, _Mapping]]] = ..., named_states: _Optional[_Iterable[_Union[NamedState, _Mapping]]] = ..., analytic_family: _Optional[str] = ..., analytic_reason: _Optional[str] = ..., analytic_held_joint: _Optional[int] = ..., analytic_reversed: _Optional[bool] = ...) -> None: ...

class NamedState(_message.Message):
    __slots__ = ("name", "group", "joint_names", "positions")
    NAME_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    JOINT_NAMES_FIELD_NUMBER: _ClassVar[int]
    POSITIONS_FIELD_NUMBER: _ClassVar[int]
    name: str
    group: str
    joint_names: _containers.RepeatedScalarFieldContainer[str]
    positions: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, name: _Optional[str] = ..., group: _Optional[str] = ..., joint_names: _Optional[_Iterable[str]] = ..., positions: _Optional[_Iterable[float]] = ...) -> None: ...

class CollisionBodyInfo(_message.Message):
    __slots__ = ("name", "carried_by", "shapes")
    NAME_FIELD_NUMBER: _ClassVar[int]
    CARRIED_BY_FIELD_NUMBER: _ClassVar[int]
    SHAPES_FIELD_NUMBER: _ClassVar[int]
    name: str
    carried_by: str
    shapes: int
    def __init__(self, name: _Optional[str] = ..., carried_by: _Optional[str] = ..., shapes: _Optional[int] = ...) -> None: ...

class ForwardKinematicsRequest(_message.Message):
    __slots__ = ("robot", "joint_positions", "include_links")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    JOINT_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    INCLUDE_LINKS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    joint_positions: _containers.RepeatedScalarFieldContainer[float]
    include_links: bool
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., joint_positions: _Optional[_Iterable[float]] = ..., include_links: _Optional[bool] = ...) -> None: ...

class LinkPose(_message.Message):
    __slots__ = ("name", "pose")
    NAME_FIELD_NUMBER: _ClassVar[int]
    POSE_FIELD_NUMBER: _ClassVar[int]
    name: str
    pose: _common_pb2.Pose
    def __init__(self, name: _Optional[str] = ..., pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ...) -> None: ...

class ForwardKinematicsResponse(_message.Message):
    __slots__ = ("tool_pose", "links", "model_id")
    TOOL_POSE_FIELD_NUMBER: _ClassVar[int]
    LINKS_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    tool_pose: _common_pb2.Pose
    links: _containers.RepeatedCompositeFieldContainer[LinkPose]
    model_id: bytes
    def __init__(self, tool_pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., links: _Optional[_Iterable[_Union[LinkPose, _Mapping]]] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class JacobianRequest(_message.Message):
    __slots__ = ("robot", "joint_positions")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    JOINT_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    joint_positions: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., joint_positions: _Optional[_Iterable[float]] = ...) -> None: ...

class JacobianResponse(_message.Message):
    __slots__ = ("jacobian", "tool_pose", "model_id")
    JACOBIAN_FIELD_NUMBER: _ClassVar[int]
    TOOL_POSE_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    jacobian: _common_pb2.Matrix
    tool_pose: _common_pb2.Pose
    model_id: bytes
    def __init__(self, jacobian: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., tool_pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class ForwardKinematicsBatchRequest(_message.Message):
    __slots__ = ("robot", "joint_positions", "include_jacobians")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    JOINT_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    INCLUDE_JACOBIANS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    joint_positions: _common_pb2.Matrix
    include_jacobians: bool
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., joint_positions: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., include_jacobians: _Optional[bool] = ...) -> None: ...

class ForwardKinematicsBatchResponse(_message.Message):
    __slots__ = ("tool_poses", "jacobians", "model_id")
    TOOL_POSES_FIELD_NUMBER: _ClassVar[int]
    JACOBIANS_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    tool_poses: _common_pb2.Matrix
    jacobians: _common_pb2.Matrix
    model_id: bytes
    def __init__(self, tool_poses: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., jacobians: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., model_id: _Optional[bytes] = ...) -> None: ...
