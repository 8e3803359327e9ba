from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Vec3(_message.Message):
    __slots__ = ("x", "y", "z")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class Quaternion(_message.Message):
    __slots__ = ("x", "y", "z", "w")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    W_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    w: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ..., w: _Optional[float] = ...) -> None: ...

class Pose(_message.Message):
    __slots__ = ("position", "orientation")
    POSITION_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_FIELD_NUMBER: _ClassVar[int]
    position: Vec3
    orientation: Quaternion
    def __init__(self, position: _Optional[_Union[Vec3, _Mapping]] = ..., orientation: _Optional[_Union[Quaternion, _Mapping]] = ...) -> None: ...

class RobotRef(_message.Message):
    __slots__ = ("name", "urdf", "model_id", "base_link", "tip_link", "meshes", "srdf", "group", "held_joints")
    class HeldJointsEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    NAME_FIELD_NUMBER: _ClassVar[int]
    URDF_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    BASE_LINK_FIELD_NUMBER: _ClassVar[int]
    TIP_LINK_FIELD_NUMBER: _ClassVar[int]
    MESHES_FIELD_NUMBER: _ClassVar[int]
    SRDF_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    HELD_JOINTS_FIELD_NUMBER: _ClassVar[int]
    name: str
    urdf: str
    model_id: bytes
    base_link: str
    tip_link: str
    meshes: _containers.RepeatedCompositeFieldContainer[MeshFile]
    srdf: str
    group: str
    held_joints: _containers.ScalarMap[str, float]
    def __init__(self, name: _Optional[str] = ..., urdf: _Optional[str] = ..., model_id: _Optional[bytes] = ..., base_link: _Optional[str] = ..., tip_link: _Optional[str] = ..., meshes: _Optional[_Iterable[_Union[MeshFile, _Mapping]]] = ..., srdf: _Optional[str] = ..., group: _Optional[str] = ..., held_joints: _Optional[_Mapping[str, float]] = ...) -> None: ...

class MeshFile(_message.Message):
    __slots__ = ("uri", "data")
    URI_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    uri: str
    data: bytes
    def __init__(self, uri: _Optional[str] = ..., data: _Optional[bytes] = ...) -> None: ...

class JointPoint(_message.Message):
    __slots__ = ("positions", "time_from_start", "velocities", "accelerations")
    POSITIONS_FIELD_NUMBER: _ClassVar[int]
    TIME_FROM_START_FIELD_NUMBER: _ClassVar[int]
    VELOCITIES_FIELD_NUMBER: _ClassVar[int]
    ACCELERATIONS_FIELD_NUMBER: _ClassVar[int]
    positions: _containers.RepeatedScalarFieldContainer[float]
    time_from_start: float
    velocities: _containers.RepeatedScalarFieldContainer[float]
    accelerations: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, positions: _Optional[_Iterable[float]] = ..., time_from_start: _Optional[float] = ..., velocities: _Optional[_Iterable[float]] = ..., accelerations: _Optional[_Iterable[float]] = ...) -> None: ...

class JointTrajectory(_message.Message):
    __slots__ = ("joint_names", "points")
    JOINT_NAMES_FIELD_NUMBER: _ClassVar[int]
    POINTS_FIELD_NUMBER: _ClassVar[int]
    joint_names: _containers.RepeatedScalarFieldContainer[str]
    points: _containers.RepeatedCompositeFieldContainer[JointPoint]
    def __init__(self, joint_names: _Optional[_Iterable[str]] = ..., points: _Optional[_Iterable[_Union[JointPoint, _Mapping]]] = ...) -> None: ...

class Matrix(_message.Message):
    __slots__ = ("rows", "cols", "data")
    ROWS_FIELD_NUMBER: _ClassVar[int]
    COLS_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    rows: int
    cols: int
    data: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, rows: _Optional[int] = ..., cols: _Optional[int] = ..., data: _Optional[_Iterable[float]] = ...) -> None: ...

class Box(_message.Message):
    __slots__ = ("size",)
    SIZE_FIELD_NUMBER: _ClassVar[int]
    size: Vec3
    def __init__(self, size: _Optional[_Union[Vec3, _Mapping]] = ...) -> None: ...

class Sphere(_message.Message):
    __slots__ = ("radius",)
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    radius: float
    def __init__(self, radius: _Optional[float] = ...) -> None: ...

class Cylinder(_message.Message):
    __slots__ = ("radius", "length")
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    LENGTH_FIELD_NUMBER: _ClassVar[int]
    radius: float
    length: float
    def __init__(self, radius: _Optional[float] = ..., length: _Optional[float] = ...) -> None: ...

class Capsule(_message.Message):
    __slots__ = ("radius", "length")
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    LENGTH_FIELD_NUMBER: _ClassVar[int]
    radius: float
    length: float
    def __init__(self, radius: _Optional[float] = ..., length: _Optional[float] = ...) -> None: ...

class TriangleMesh(_message.Message):
    __slots__ = ("vertices", "indices")
    VERTICES_FIELD_NUMBER: _ClassVar[int]
    INDICES_FIELD_NUMBER: _ClassVar[int]
    vertices: _containers.RepeatedCompositeFieldContainer[Vec3]
    indices: _containers.RepeatedScalarFieldContainer[int]
    def __init__(self, vertices: _Optional[_Iterable[_Union[Vec3, _Mapping]]] = ..., indices: _Optional[_Iterable[int]] = ...) -> None: ...

class Octree(_message.Message):
    __slots__ = ("id", "resolution", "binary", "data")
    ID_FIELD_NUMBER: _ClassVar[int]
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    BINARY_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    id: str
    resolution: float
    binary: bool
    data: bytes
    def __init__(self, id: _Optional[str] = ..., resolution: _Optional[float] = ..., binary: _Optional[bool] = ..., data: _Optional[bytes] = ...) -> None: ...

class CollisionObject(_message.Message):
    __slots__ = ("id", "pose", "box", "sphere", "cylinder", "capsule", "mesh", "octree", "unknown_as_obstacle")
    ID_FIELD_NUMBER: _ClassVar[int]
    POSE_FIELD_NUMBER: _ClassVar[int]
    BOX_FIELD_NUMBER: _ClassVar[int]
    SPHERE_FIELD_NUMBER: _ClassVar[int]
    CYLINDER_FIELD_NUMBER: _ClassVar[int]
    CAPSULE_FIELD_NUMBER: _ClassVar[int]
    MESH_FIELD_NUMBER: _ClassVar[int]
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    UNKNOWN_AS_OBSTACLE_FIELD_NUMBER: _ClassVar[int]
    id: str
    pose: Pose
    box: Box
    sphere: Sphere
    cylinder: Cylinder
    capsule: Capsule
    mesh: TriangleMesh
    octree: Octree
    unknown_as_obstacle: bool
    def __init__(self, id: _Optional[str] = ..., pose: _Optional[_Union[Pose, _Mapping]] = ..., box: _Optional[_Union[Box, _Mapping]] = ..., sphere: _Optional[_Union[Sphere, _Mapping]] = ..., cylinder: _Optional[_Union[Cylinder, _Mapping]] = ..., capsule: _Optional[_Union[Capsule, _Mapping]] = ..., mesh: _Optional[_Union[TriangleMesh, _Mapping]] = ..., octree: _Optional[_Union[Octree, _Mapping]] = ..., unknown_as_obstacle: _Optional[bool] = ...) -> None: ...

class Scene(_message.Message):
    __slots__ = ("objects",)
    OBJECTS_FIELD_NUMBER: _ClassVar[int]
    objects: _containers.RepeatedCompositeFieldContainer[CollisionObject]
    def __init__(self, objects: _Optional[_Iterable[_Union[CollisionObject, _Mapping]]] = ...) -> None: ...
