from kinplan.v1 import common_pb2 as _common_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class PlanAlgorithm(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    PLAN_ALGORITHM_UNSPECIFIED: _ClassVar[PlanAlgorithm]
    PLAN_ALGORITHM_STOMP: _ClassVar[PlanAlgorithm]
    PLAN_ALGORITHM_CCSTOMP: _ClassVar[PlanAlgorithm]
    PLAN_ALGORITHM_RRT_CONNECT: _ClassVar[PlanAlgorithm]

class PlanStatus(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    PLAN_STATUS_UNSPECIFIED: _ClassVar[PlanStatus]
    PLAN_STATUS_SUCCEEDED: _ClassVar[PlanStatus]
    PLAN_STATUS_NO_VALID_TRAJECTORY: _ClassVar[PlanStatus]
    PLAN_STATUS_INVALID_START: _ClassVar[PlanStatus]
    PLAN_STATUS_INVALID_GOAL: _ClassVar[PlanStatus]
    PLAN_STATUS_TIMEOUT: _ClassVar[PlanStatus]
    PLAN_STATUS_CANCELLED: _ClassVar[PlanStatus]
    PLAN_STATUS_GOAL_UNREACHABLE: _ClassVar[PlanStatus]

class InitialTrajectory(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    INITIAL_TRAJECTORY_UNSPECIFIED: _ClassVar[InitialTrajectory]
    INITIAL_TRAJECTORY_STRAIGHT_LINE: _ClassVar[InitialTrajectory]
    INITIAL_TRAJECTORY_RRT_CONNECT_IF_BLOCKED: _ClassVar[InitialTrajectory]
    INITIAL_TRAJECTORY_CARTESIAN_LINE: _ClassVar[InitialTrajectory]

class TimingMethod(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    TIMING_METHOD_UNSPECIFIED: _ClassVar[TimingMethod]
    TIMING_METHOD_WAYPOINT: _ClassVar[TimingMethod]
    TIMING_METHOD_TIME_OPTIMAL: _ClassVar[TimingMethod]
    TIMING_METHOD_JERK_LIMITED: _ClassVar[TimingMethod]
PLAN_ALGORITHM_UNSPECIFIED: PlanAlgorithm
PLAN_ALGORITHM_STOMP: PlanAlgorithm
PLAN_ALGORITHM_CCSTOMP: PlanAlgorithm
PLAN_ALGORITHM_RRT_CONNECT: PlanAlgorithm
PLAN_STATUS_UNSPECIFIED: PlanStatus
PLAN_STATUS_SUCCEEDED: PlanStatus
PLAN_STATUS_NO_VALID_TRAJECTORY: PlanStatus
PLAN_STATUS_INVALID_START: PlanStatus
PLAN_STATUS_INVALID_GOAL: PlanStatus
PLAN_STATUS_TIMEOUT: PlanStatus
PLAN_STATUS_CANCELLED: PlanStatus
PLAN_STATUS_GOAL_UNREACHABLE: PlanStatus
INITIAL_TRAJECTORY_UNSPECIFIED: InitialTrajectory
INITIAL_TRAJECTORY_STRAIGHT_LINE: InitialTrajectory
INITIAL_TRAJECTORY_RRT_CONNECT_IF_BLOCKED: InitialTrajectory
INITIAL_TRAJECTORY_CARTESIAN_LINE: InitialTrajectory
TIMING_METHOD_UNSPECIFIED: TimingMethod
TIMING_METHOD_WAYPOINT: TimingMethod
TIMING_METHOD_TIME_OPTIMAL: TimingMethod
TIMING_METHOD_JERK_LIMITED: TimingMethod

class StompOptions(_message.Message):
    __slots__ = ("timesteps", "rollouts", "max_rollouts", "max_iterations", "iterations_after_valid", "noise_stddev", "cost_sensitivity", "control_cost_weight", "collision_penalty", "kernel_half_width", "clearance_distance", "clearance_weight", "joint_limit_weight", "straight_line_start", "initial_trajectory")
    TIMESTEPS_FIELD_NUMBER: _ClassVar[int]
    ROLLOUTS_FIELD_NUMBER: _ClassVar[int]
    MAX_ROLLOUTS_FIELD_NUMBER: _ClassVar[int]
    MAX_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_AFTER_VALID_FIELD_NUMBER: _ClassVar[int]
    NOISE_STDDEV_FIELD_NUMBER: _ClassVar[int]
    COST_SENSITIVITY_FIELD_NUMBER: _ClassVar[int]
    CONTROL_COST_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    COLLISION_PENALTY_FIELD_NUMBER: _ClassVar[int]
    KERNEL_HALF_WIDTH_FIELD_NUMBER: _ClassVar[int]
    CLEARANCE_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    CLEARANCE_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    JOINT_LIMIT_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    STRAIGHT_LINE_START_FIELD_NUMBER: _ClassVar[int]
    INITIAL_TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    timesteps: int
    rollouts: int
    max_rollouts: int
    max_iterations: int
    iterations_after_valid: int
    noise_stddev: _containers.RepeatedScalarFieldContainer[float]
    cost_sensitivity: float
    control_cost_weight: float
    collision_penalty: float
    kernel_half_width: int
    clearance_distance: float
    clearance_weight: float
    joint_limit_weight: float
    straight_line_start: bool
    initial_trajectory: InitialTrajectory
    def __init__(self, timesteps: _Optional[int] = ..., rollouts: _Optional[int] = ..., max_rollouts: _Optional[int] = ..., max_iterations: _Optional[int] = ..., iterations_after_valid: _Optional[int] = ..., noise_stddev: _Optional[_Iterable[float]] = ..., cost_sensitivity: _Optional[float] = ..., control_cost_weight: _Optional[float] = ..., collision_penalty: _Optional[float] = ..., kernel_half_width: _Optional[int] = ..., clearance_distance: _Optional[float] = ..., clearance_weight: _Optional[float] = ..., joint_limit_weight: _Optional[float] = ..., straight_line_start: _Optional[bool] = ..., initial_trajectory: _Optional[_Union[InitialTrajectory, str]] = ...) -> None: ...

class CartesianOptions(_message.Message):
    __slots__ = ("translation_tolerance", "rotation_tolerance", "translation_weight", "rotation_weight", "translation_stddev", "rotation_stddev", "ik_iterations", "violation_penalty")
    TRANSLATION_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    ROTATION_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    TRANSLATION_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    ROTATION_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    TRANSLATION_STDDEV_FIELD_NUMBER: _ClassVar[int]
    ROTATION_STDDEV_FIELD_NUMBER: _ClassVar[int]
    IK_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    VIOLATION_PENALTY_FIELD_NUMBER: _ClassVar[int]
    translation_tolerance: float
    rotation_tolerance: float
    translation_weight: float
    rotation_weight: float
    translation_stddev: float
    rotation_stddev: float
    ik_iterations: int
    violation_penalty: float
    def __init__(self, translation_tolerance: _Optional[float] = ..., rotation_tolerance: _Optional[float] = ..., translation_weight: _Optional[float] = ..., rotation_weight: _Optional[float] = ..., translation_stddev: _Optional[float] = ..., rotation_stddev: _Optional[float] = ..., ik_iterations: _Optional[int] = ..., violation_penalty: _Optional[float] = ...) -> None: ...

class RrtConnectOptions(_message.Message):
    __slots__ = ("range", "max_samples", "shortcut_attempts")
    RANGE_FIELD_NUMBER: _ClassVar[int]
    MAX_SAMPLES_FIELD_NUMBER: _ClassVar[int]
    SHORTCUT_ATTEMPTS_FIELD_NUMBER: _ClassVar[int]
    range: float
    max_samples: int
    shortcut_attempts: int
    def __init__(self, range: _Optional[float] = ..., max_samples: _Optional[int] = ..., shortcut_attempts: _Optional[int] = ...) -> None: ...

class TimingOptions(_message.Message):
    __slots__ = ("max_velocity", "max_acceleration", "default_velocity", "velocity_scale", "method", "max_jerk", "path_tolerance", "start_velocity", "sample_period", "grid_step")
    MAX_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    MAX_ACCELERATION_FIELD_NUMBER: _ClassVar[int]
    DEFAULT_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    VELOCITY_SCALE_FIELD_NUMBER: _ClassVar[int]
    METHOD_FIELD_NUMBER: _ClassVar[int]
    MAX_JERK_FIELD_NUMBER: _ClassVar[int]
    PATH_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    START_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    SAMPLE_PERIOD_FIELD_NUMBER: _ClassVar[int]
    GRID_STEP_FIELD_NUMBER: _ClassVar[int]
    max_velocity: _containers.RepeatedScalarFieldContainer[float]
    max_acceleration: _containers.RepeatedScalarFieldContainer[float]
    default_velocity: float
    velocity_scale: float
    method: TimingMethod
    max_jerk: _containers.RepeatedScalarFieldContainer[float]
    path_tolerance: float
    start_velocity: _containers.RepeatedScalarFieldContainer[float]
    sample_period: float
    grid_step: float
    def __init__(self, max_velocity: _Optional[_Iterable[float]] = ..., max_acceleration: _Optional[_Iterable[float]] = ..., default_velocity: _Optional[float] = ..., velocity_scale: _Optional[float] = ..., method: _Optional[_Union[TimingMethod, str]] = ..., max_jerk: _Optional[_Iterable[float]] = ..., path_tolerance: _Optional[float] = ..., start_velocity: _Optional[_Iterable[float]] = ..., sample_period: _Optional[float] = ..., grid_step: _Optional[float] = ...) -> None: ...

class PlanOptions(_message.Message):
    __slots__ = ("stomp", "cartesian", "rrt_connect", "timing", "motion_resolution", "time_budget", "return_cost_history", "padded_motion")
    STOMP_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_FIELD_NUMBER: _ClassVar[int]
    RRT_CONNECT_FIELD_NUMBER: _ClassVar[int]
    TIMING_FIELD_NUMBER: _ClassVar[int]
    MOTION_RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    TIME_BUDGET_FIELD_NUMBER: _ClassVar[int]
    RETURN_COST_HISTORY_FIELD_NUMBER: _ClassVar[int]
    PADDED_MOTION_FIELD_NUMBER: _ClassVar[int]
    stomp: StompOptions
    cartesian: CartesianOptions
    rrt_connect: RrtConnectOptions
    timing: TimingOptions
    motion_resolution: float
    time_budget: float
    return_cost_history: bool
    padded_motion: bool
    def __init__(self, stomp: _Optional[_Union[StompOptions, _Mapping]] = ..., cartesian: _Optional[_Union[CartesianOptions, _Mapping]] = ..., rrt_connect: _Optional[_Union[RrtConnectOptions, _Mapping]] = ..., timing: _Optional[_Union[TimingOptions, _Mapping]] = ..., motion_resolution: _Optional[float] = ..., time_budget: _Optional[float] = ..., return_cost_history: _Optional[bool] = ..., padded_motion: _Optional[bool] = ...) -> None: ...

class JointState(_message.Message):
    __slots__ = ("positions",)
    POSITIONS_FIELD_NUMBER: _ClassVar[int]
    positions: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, positions: _Optional[_Iterable[float]] = ...) -> None: ...

class PlanRequest(_message.Message):
    __slots__ = ("robot", "start", "goal_joints", "goal_pose", "scene", "algorithm", "options", "seed")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    GOAL_JOINTS_FIELD_NUMBER: _ClassVar[int]
    GOAL_POSE_FIELD_NUMBER: _ClassVar[int]
    SCENE_FIELD_NUMBER: _ClassVar[int]
    ALGORITHM_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    start: _containers.RepeatedScalarFieldContainer[float]
    goal_joints: JointState
    goal_pose: _common_pb2.Pose
    scene: _common_pb2.Scene
    algorithm: PlanAlgorithm
    options: PlanOptions
    seed: int
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., start: _Optional[_Iterable[float]] = ..., goal_joints: _Optional[_Union[JointState, _Mapping]] = ..., goal_pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., scene: _Optional[_Union[_common_pb2.Scene, _Mapping]] = ..., algorithm: _Optional[_Union[PlanAlgorithm, str]] = ..., options: _Optional[_Union[PlanOptions, _Mapping]] = ..., seed: _Optional[int] = ...) -> None: ...

class CartesianDeviation(_message.Message):
    __slots__ = ("translation", "rotation", "violates_tolerance")
    TRANSLATION_FIELD_NUMBER: _ClassVar[int]
    ROTATION_FIELD_NUMBER: _ClassVar[int]
    VIOLATES_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    translation: _containers.RepeatedScalarFieldContainer[float]
    rotation: _containers.RepeatedScalarFieldContainer[float]
    violates_tolerance: bool
    def __init__(self, translation: _Optional[_Iterable[float]] = ..., rotation: _Optional[_Iterable[float]] = ..., violates_tolerance: _Optional[bool] = ...) -> None: ...

class PlanResponse(_message.Message):
    __slots__ = ("status", "message", "colliding", "trajectory", "valid", "cost_history", "deviation", "criteria", "iterations", "duration", "goal", "timings")
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    STATUS_FIELD_NUMBER: _ClassVar[int]
    MESSAGE_FIELD_NUMBER: _ClassVar[int]
    COLLIDING_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    VALID_FIELD_NUMBER: _ClassVar[int]
    COST_HISTORY_FIELD_NUMBER: _ClassVar[int]
    DEVIATION_FIELD_NUMBER: _ClassVar[int]
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    DURATION_FIELD_NUMBER: _ClassVar[int]
    GOAL_FIELD_NUMBER: _ClassVar[int]
    TIMINGS_FIELD_NUMBER: _ClassVar[int]
    status: PlanStatus
    message: str
    colliding: _containers.RepeatedScalarFieldContainer[str]
    trajectory: _common_pb2.JointTrajectory
    valid: bool
    cost_history: _containers.RepeatedScalarFieldContainer[float]
    deviation: CartesianDeviation
    criteria: _containers.ScalarMap[str, float]
    iterations: int
    duration: float
    goal: _containers.RepeatedScalarFieldContainer[float]
    timings: PlanTimings
    def __init__(self, status: _Optional[_Union[PlanStatus, str]] = ..., message: _Optional[str] = ..., colliding: _Optional[_Iterable[str]] = ..., trajectory: _Optional[_Union[_common_pb2.JointTrajectory, _Mapping]] = ..., valid: _Optional[bool] = ..., cost_history: _Optional[_Iterable[float]] = ..., deviation: _Optional[_Union[CartesianDeviation, _Mapping]] = ..., criteria: _Optional[_Mapping[str, float]] = ..., iterations: _Optional[int] = ..., duration: _Optional[float] = ..., goal: _Optional[_Iterable[float]] = ..., timings: _Optional[_Union[PlanTimings, _Mapping]] = ...) -> None: ...

class PlanTimings(_message.Message):
    __slots__ = ("goal_ik", "rrt_connect", "stomp", "verify", "total")
    GOAL_IK_FIELD_NUMBER: _ClassVar[int]
    RRT_CONNECT_FIELD_NUMBER: _ClassVar[int]
    STOMP_FIELD_NUMBER: _ClassVar[int]
    VERIFY_FIELD_NUMBER: _ClassVar[int]
    TOTAL_FIELD_NUMBER: _ClassVar[int]
    goal_ik: float
    rrt_connect: float
    stomp: float
    verify: float
    total: float
    def __init__(self, goal_ik: _Optional[float] = ..., rrt_connect: _Optional[float] = ..., stomp: _Optional[float] = ..., verify: _Optional[float] = ..., total: _Optional[float] = ...) -> None: ...

class PlanStreamResponse(_message.Message):
    __slots__ = ("iteration", "cost", "valid", "trajectory", "result")
    ITERATION_FIELD_NUMBER: _ClassVar[int]
    COST_FIELD_NUMBER: _ClassVar[int]
    VALID_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    RESULT_FIELD_NUMBER: _ClassVar[int]
    iteration: int
    cost: float
    valid: bool
    trajectory: _common_pb2.JointTrajectory
    result: PlanResponse
    def __init__(self, iteration: _Optional[int] = ..., cost: _Optional[float] = ..., valid: _Optional[bool] = ..., trajectory: _Optional[_Union[_common_pb2.JointTrajectory, _Mapping]] = ..., result: _Optional[_Union[PlanResponse, _Mapping]] = ...) -> None: ...

class CheckStateRequest(_message.Message):
    __slots__ = ("robot", "states", "scene", "max_distance")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    STATES_FIELD_NUMBER: _ClassVar[int]
    SCENE_FIELD_NUMBER: _ClassVar[int]
    MAX_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    states: _containers.RepeatedCompositeFieldContainer[JointState]
    scene: _common_pb2.Scene
    max_distance: float
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., states: _Optional[_Iterable[_Union[JointState, _Mapping]]] = ..., scene: _Optional[_Union[_common_pb2.Scene, _Mapping]] = ..., max_distance: _Optional[float] = ...) -> None: ...

class StateCheck(_message.Message):
    __slots__ = ("valid", "within_limits", "clearance", "colliding", "robot_point", "obstacle_point", "closest_pair", "error")
    VALID_FIELD_NUMBER: _ClassVar[int]
    WITHIN_LIMITS_FIELD_NUMBER: _ClassVar[int]
    CLEARANCE_FIELD_NUMBER: _ClassVar[int]
    COLLIDING_FIELD_NUMBER: _ClassVar[int]
    ROBOT_POINT_FIELD_NUMBER: _ClassVar[int]
    OBSTACLE_POINT_FIELD_NUMBER: _ClassVar[int]
    CLOSEST_PAIR_FIELD_NUMBER: _ClassVar[int]
    ERROR_FIELD_NUMBER: _ClassVar[int]
    valid: bool
    within_limits: bool
    clearance: float
    colliding: _containers.RepeatedScalarFieldContainer[str]
    robot_point: _common_pb2.Vec3
    obstacle_point: _common_pb2.Vec3
    closest_pair: str
    error: str
    def __init__(self, valid: _Optional[bool] = ..., within_limits: _Optional[bool] = ..., clearance: _Optional[float] = ..., colliding: _Optional[_Iterable[str]] = ..., robot_point: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., obstacle_point: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., closest_pair: _Optional[str] = ..., error: _Optional[str] = ...) -> None: ...

class CheckStateResponse(_message.Message):
    __slots__ = ("states",)
    STATES_FIELD_NUMBER: _ClassVar[int]
    states: _containers.RepeatedCompositeFieldContainer[StateCheck]
    def __init__(self, states: _Optional[_Iterable[_Union[StateCheck, _Mapping]]] = ...) -> None: ...

class RetimeRequest(_message.Message):
    __slots__ = ("robot", "waypoints", "timing")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    WAYPOINTS_FIELD_NUMBER: _ClassVar[int]
    TIMING_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    waypoints: _containers.RepeatedCompositeFieldContainer[JointState]
    timing: TimingOptions
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., waypoints: _Optional[_Iterable[_Union[JointState, _Mapping]]] = ..., timing: _Optional[_Union[TimingOptions, _Mapping]] = ...) -> None: ...

class RetimeResponse(_message.Message):
    __slots__ = ("trajectory", "duration", "criteria", "compute_time")
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    DURATION_FIELD_NUMBER: _ClassVar[int]
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    COMPUTE_TIME_FIELD_NUMBER: _ClassVar[int]
    trajectory: _common_pb2.JointTrajectory
    duration: float
    criteria: _containers.ScalarMap[str, float]
    compute_time: float
    def __init__(self, trajectory: _Optional[_Union[_common_pb2.JointTrajectory, _Mapping]] = ..., duration: _Optional[float] = ..., criteria: _Optional[_Mapping[str, float]] = ..., compute_time: _Optional[float] = ...) -> None: ...
