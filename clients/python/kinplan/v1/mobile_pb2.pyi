from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Controller(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    CONTROLLER_UNSPECIFIED: _ClassVar[Controller]
    CONTROLLER_LYAPUNOV: _ClassVar[Controller]
    CONTROLLER_PURE_PURSUIT: _ClassVar[Controller]
    CONTROLLER_GOAL_SEEKING: _ClassVar[Controller]
    CONTROLLER_SHORTEST_PATH: _ClassVar[Controller]
    CONTROLLER_VECTOR_DISTANCE: _ClassVar[Controller]

class TurnPreference(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    TURN_PREFERENCE_UNSPECIFIED: _ClassVar[TurnPreference]
    TURN_PREFERENCE_AUTO: _ClassVar[TurnPreference]
    TURN_PREFERENCE_LEFT: _ClassVar[TurnPreference]
    TURN_PREFERENCE_RIGHT: _ClassVar[TurnPreference]

class NavMode(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    NAV_MODE_UNSPECIFIED: _ClassVar[NavMode]
    NAV_MODE_ROTATE: _ClassVar[NavMode]
    NAV_MODE_LOCK: _ClassVar[NavMode]
    NAV_MODE_TRACK: _ClassVar[NavMode]

class Navigator(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    NAVIGATOR_UNSPECIFIED: _ClassVar[Navigator]
    NAVIGATOR_VECTOR_DISTANCE: _ClassVar[Navigator]
    NAVIGATOR_GRID_ASTAR: _ClassVar[Navigator]

class Outcome(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    OUTCOME_UNSPECIFIED: _ClassVar[Outcome]
    OUTCOME_REACHED: _ClassVar[Outcome]
    OUTCOME_NO_PATH: _ClassVar[Outcome]
    OUTCOME_TIMEOUT: _ClassVar[Outcome]
    OUTCOME_COLLISION: _ClassVar[Outcome]
    OUTCOME_CANCELLED: _ClassVar[Outcome]

class NoPathReason(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    NO_PATH_REASON_UNSPECIFIED: _ClassVar[NoPathReason]
    NO_PATH_REASON_RETURNED_TO_HIT: _ClassVar[NoPathReason]
    NO_PATH_REASON_NO_PROGRESS: _ClassVar[NoPathReason]
    NO_PATH_REASON_NO_GRID_PATH: _ClassVar[NoPathReason]
CONTROLLER_UNSPECIFIED: Controller
CONTROLLER_LYAPUNOV: Controller
CONTROLLER_PURE_PURSUIT: Controller
CONTROLLER_GOAL_SEEKING: Controller
CONTROLLER_SHORTEST_PATH: Controller
CONTROLLER_VECTOR_DISTANCE: Controller
TURN_PREFERENCE_UNSPECIFIED: TurnPreference
TURN_PREFERENCE_AUTO: TurnPreference
TURN_PREFERENCE_LEFT: TurnPreference
TURN_PREFERENCE_RIGHT: TurnPreference
NAV_MODE_UNSPECIFIED: NavMode
NAV_MODE_ROTATE: NavMode
NAV_MODE_LOCK: NavMode
NAV_MODE_TRACK: NavMode
NAVIGATOR_UNSPECIFIED: Navigator
NAVIGATOR_VECTOR_DISTANCE: Navigator
NAVIGATOR_GRID_ASTAR: Navigator
OUTCOME_UNSPECIFIED: Outcome
OUTCOME_REACHED: Outcome
OUTCOME_NO_PATH: Outcome
OUTCOME_TIMEOUT: Outcome
OUTCOME_COLLISION: Outcome
OUTCOME_CANCELLED: Outcome
NO_PATH_REASON_UNSPECIFIED: NoPathReason
NO_PATH_REASON_RETURNED_TO_HIT: NoPathReason
NO_PATH_REASON_NO_PROGRESS: NoPathReason
NO_PATH_REASON_NO_GRID_PATH: NoPathReason

class Pose2D(_message.Message):
    __slots__ = ("x", "y", "theta")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    THETA_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    theta: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., theta: _Optional[float] = ...) -> None: ...

class Point2D(_message.Message):
    __slots__ = ("x", "y")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ...) -> None: ...

class Twist2D(_message.Message):
    __slots__ = ("vx", "vy", "omega")
    VX_FIELD_NUMBER: _ClassVar[int]
    VY_FIELD_NUMBER: _ClassVar[int]
    OMEGA_FIELD_NUMBER: _ClassVar[int]
    vx: float
    vy: float
    omega: float
    def __init__(self, vx: _Optional[float] = ..., vy: _Optional[float] = ..., omega: _Optional[float] = ...) -> None: ...

class TricycleChassis(_message.Message):
    __slots__ = ("wheelbase", "wheel_radius", "max_steer", "max_speed")
    WHEELBASE_FIELD_NUMBER: _ClassVar[int]
    WHEEL_RADIUS_FIELD_NUMBER: _ClassVar[int]
    MAX_STEER_FIELD_NUMBER: _ClassVar[int]
    MAX_SPEED_FIELD_NUMBER: _ClassVar[int]
    wheelbase: float
    wheel_radius: float
    max_steer: float
    max_speed: float
    def __init__(self, wheelbase: _Optional[float] = ..., wheel_radius: _Optional[float] = ..., max_steer: _Optional[float] = ..., max_speed: _Optional[float] = ...) -> None: ...

class CarChassis(_message.Message):
    __slots__ = ("wheelbase", "track", "wheel_radius", "max_steer", "max_speed")
    WHEELBASE_FIELD_NUMBER: _ClassVar[int]
    TRACK_FIELD_NUMBER: _ClassVar[int]
    WHEEL_RADIUS_FIELD_NUMBER: _ClassVar[int]
    MAX_STEER_FIELD_NUMBER: _ClassVar[int]
    MAX_SPEED_FIELD_NUMBER: _ClassVar[int]
    wheelbase: float
    track: float
    wheel_radius: float
    max_steer: float
    max_speed: float
    def __init__(self, wheelbase: _Optional[float] = ..., track: _Optional[float] = ..., wheel_radius: _Optional[float] = ..., max_steer: _Optional[float] = ..., max_speed: _Optional[float] = ...) -> None: ...

class OmniChassis(_message.Message):
    __slots__ = ("wheel_radius", "center_distance", "first_wheel_angle", "max_wheel_speed")
    WHEEL_RADIUS_FIELD_NUMBER: _ClassVar[int]
    CENTER_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    FIRST_WHEEL_ANGLE_FIELD_NUMBER: _ClassVar[int]
    MAX_WHEEL_SPEED_FIELD_NUMBER: _ClassVar[int]
    wheel_radius: float
    center_distance: float
    first_wheel_angle: float
    max_wheel_speed: float
    def __init__(self, wheel_radius: _Optional[float] = ..., center_distance: _Optional[float] = ..., first_wheel_angle: _Optional[float] = ..., max_wheel_speed: _Optional[float] = ...) -> None: ...

class DifferentialChassis(_message.Message):
    __slots__ = ("wheel_radius", "track", "max_wheel_speed")
    WHEEL_RADIUS_FIELD_NUMBER: _ClassVar[int]
    TRACK_FIELD_NUMBER: _ClassVar[int]
    MAX_WHEEL_SPEED_FIELD_NUMBER: _ClassVar[int]
    wheel_radius: float
    track: float
    max_wheel_speed: float
    def __init__(self, wheel_radius: _Optional[float] = ..., track: _Optional[float] = ..., max_wheel_speed: _Optional[float] = ...) -> None: ...

class Chassis(_message.Message):
    __slots__ = ("tricycle", "car", "omni", "differential")
    TRICYCLE_FIELD_NUMBER: _ClassVar[int]
    CAR_FIELD_NUMBER: _ClassVar[int]
    OMNI_FIELD_NUMBER: _ClassVar[int]
    DIFFERENTIAL_FIELD_NUMBER: _ClassVar[int]
    tricycle: TricycleChassis
    car: CarChassis
    omni: OmniChassis
    differential: DifferentialChassis
    def __init__(self, tricycle: _Optional[_Union[TricycleChassis, _Mapping]] = ..., car: _Optional[_Union[CarChassis, _Mapping]] = ..., omni: _Optional[_Union[OmniChassis, _Mapping]] = ..., differential: _Optional[_Union[DifferentialChassis, _Mapping]] = ...) -> None: ...

class TricycleWheels(_message.Message):
    __slots__ = ("speed", "steer")
    SPEED_FIELD_NUMBER: _ClassVar[int]
    STEER_FIELD_NUMBER: _ClassVar[int]
    speed: float
    steer: float
    def __init__(self, speed: _Optional[float] = ..., steer: _Optional[float] = ...) -> None: ...

class CarWheels(_message.Message):
    __slots__ = ("rear_left", "rear_right", "steer_left", "steer_right")
    REAR_LEFT_FIELD_NUMBER: _ClassVar[int]
    REAR_RIGHT_FIELD_NUMBER: _ClassVar[int]
    STEER_LEFT_FIELD_NUMBER: _ClassVar[int]
    STEER_RIGHT_FIELD_NUMBER: _ClassVar[int]
    rear_left: float
    rear_right: float
    steer_left: float
    steer_right: float
    def __init__(self, rear_left: _Optional[float] = ..., rear_right: _Optional[float] = ..., steer_left: _Optional[float] = ..., steer_right: _Optional[float] = ...) -> None: ...

class OmniWheels(_message.Message):
    __slots__ = ("speeds",)
    SPEEDS_FIELD_NUMBER: _ClassVar[int]
    speeds: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, speeds: _Optional[_Iterable[float]] = ...) -> None: ...

class DifferentialWheels(_message.Message):
    __slots__ = ("left", "right")
    LEFT_FIELD_NUMBER: _ClassVar[int]
    RIGHT_FIELD_NUMBER: _ClassVar[int]
    left: float
    right: float
    def __init__(self, left: _Optional[float] = ..., right: _Optional[float] = ...) -> None: ...

class WheelState(_message.Message):
    __slots__ = ("tricycle", "car", "omni", "differential")
    TRICYCLE_FIELD_NUMBER: _ClassVar[int]
    CAR_FIELD_NUMBER: _ClassVar[int]
    OMNI_FIELD_NUMBER: _ClassVar[int]
    DIFFERENTIAL_FIELD_NUMBER: _ClassVar[int]
    tricycle: TricycleWheels
    car: CarWheels
    omni: OmniWheels
    differential: DifferentialWheels
    def __init__(self, tricycle: _Optional[_Union[TricycleWheels, _Mapping]] = ..., car: _Optional[_Union[CarWheels, _Mapping]] = ..., omni: _Optional[_Union[OmniWheels, _Mapping]] = ..., differential: _Optional[_Union[DifferentialWheels, _Mapping]] = ...) -> None: ...

class Saturation(_message.Message):
    __slots__ = ("speed_scale", "steering_clamped", "lateral_dropped")
    SPEED_SCALE_FIELD_NUMBER: _ClassVar[int]
    STEERING_CLAMPED_FIELD_NUMBER: _ClassVar[int]
    LATERAL_DROPPED_FIELD_NUMBER: _ClassVar[int]
    speed_scale: float
    steering_clamped: bool
    lateral_dropped: bool
    def __init__(self, speed_scale: _Optional[float] = ..., steering_clamped: _Optional[bool] = ..., lateral_dropped: _Optional[bool] = ...) -> None: ...

class WheelKinematicsRequest(_message.Message):
    __slots__ = ("chassis", "twist", "wheels")
    CHASSIS_FIELD_NUMBER: _ClassVar[int]
    TWIST_FIELD_NUMBER: _ClassVar[int]
    WHEELS_FIELD_NUMBER: _ClassVar[int]
    chassis: Chassis
    twist: Twist2D
    wheels: WheelState
    def __init__(self, chassis: _Optional[_Union[Chassis, _Mapping]] = ..., twist: _Optional[_Union[Twist2D, _Mapping]] = ..., wheels: _Optional[_Union[WheelState, _Mapping]] = ...) -> None: ...

class WheelKinematicsResponse(_message.Message):
    __slots__ = ("twist", "wheels", "saturation")
    TWIST_FIELD_NUMBER: _ClassVar[int]
    WHEELS_FIELD_NUMBER: _ClassVar[int]
    SATURATION_FIELD_NUMBER: _ClassVar[int]
    twist: Twist2D
    wheels: WheelState
    saturation: Saturation
    def __init__(self, twist: _Optional[_Union[Twist2D, _Mapping]] = ..., wheels: _Optional[_Union[WheelState, _Mapping]] = ..., saturation: _Optional[_Union[Saturation, _Mapping]] = ...) -> None: ...

class LyapunovGains(_message.Message):
    __slots__ = ("gamma", "k", "h", "max_speed", "max_yaw_rate")
    GAMMA_FIELD_NUMBER: _ClassVar[int]
    K_FIELD_NUMBER: _ClassVar[int]
    H_FIELD_NUMBER: _ClassVar[int]
    LAMBDA_FIELD_NUMBER: _ClassVar[int]
    MAX_SPEED_FIELD_NUMBER: _ClassVar[int]
    MAX_YAW_RATE_FIELD_NUMBER: _ClassVar[int]
    gamma: float
    k: float
    h: float
    max_speed: float
    max_yaw_rate: float
    def __init__(self, gamma: _Optional[float] = ..., k: _Optional[float] = ..., h: _Optional[float] = ..., max_speed: _Optional[float] = ..., max_yaw_rate: _Optional[float] = ..., **kwargs) -> None: ...

class PurePursuitGains(_message.Message):
    __slots__ = ("lookahead", "desired_speed", "approach_distance", "min_approach_speed", "rotate_to_heading", "rotate_min_angle", "rotate_yaw_rate")
    LOOKAHEAD_FIELD_NUMBER: _ClassVar[int]
    DESIRED_SPEED_FIELD_NUMBER: _ClassVar[int]
    APPROACH_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    MIN_APPROACH_SPEED_FIELD_NUMBER: _ClassVar[int]
    ROTATE_TO_HEADING_FIELD_NUMBER: _ClassVar[int]
    ROTATE_MIN_ANGLE_FIELD_NUMBER: _ClassVar[int]
    ROTATE_YAW_RATE_FIELD_NUMBER: _ClassVar[int]
    lookahead: float
    desired_speed: float
    approach_distance: float
    min_approach_speed: float
    rotate_to_heading: bool
    rotate_min_angle: float
    rotate_yaw_rate: float
    def __init__(self, lookahead: _Optional[float] = ..., desired_speed: _Optional[float] = ..., approach_distance: _Optional[float] = ..., min_approach_speed: _Optional[float] = ..., rotate_to_heading: _Optional[bool] = ..., rotate_min_angle: _Optional[float] = ..., rotate_yaw_rate: _Optional[float] = ...) -> None: ...

class SteeringGains(_message.Message):
    __slots__ = ("speed", "wheelbase", "max_steer", "epsilon", "candidates")
    SPEED_FIELD_NUMBER: _ClassVar[int]
    WHEELBASE_FIELD_NUMBER: _ClassVar[int]
    MAX_STEER_FIELD_NUMBER: _ClassVar[int]
    EPSILON_FIELD_NUMBER: _ClassVar[int]
    CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    speed: float
    wheelbase: float
    max_steer: float
    epsilon: float
    candidates: int
    def __init__(self, speed: _Optional[float] = ..., wheelbase: _Optional[float] = ..., max_steer: _Optional[float] = ..., epsilon: _Optional[float] = ..., candidates: _Optional[int] = ...) -> None: ...

class FollowOptions(_message.Message):
    __slots__ = ("switching_distance", "goal_tolerance", "heading_tolerance", "lyapunov", "pure_pursuit", "steering")
    SWITCHING_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    GOAL_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    HEADING_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    LYAPUNOV_FIELD_NUMBER: _ClassVar[int]
    PURE_PURSUIT_FIELD_NUMBER: _ClassVar[int]
    STEERING_FIELD_NUMBER: _ClassVar[int]
    switching_distance: float
    goal_tolerance: float
    heading_tolerance: float
    lyapunov: LyapunovGains
    pure_pursuit: PurePursuitGains
    steering: SteeringGains
    def __init__(self, switching_distance: _Optional[float] = ..., goal_tolerance: _Optional[float] = ..., heading_tolerance: _Optional[float] = ..., lyapunov: _Optional[_Union[LyapunovGains, _Mapping]] = ..., pure_pursuit: _Optional[_Union[PurePursuitGains, _Mapping]] = ..., steering: _Optional[_Union[SteeringGains, _Mapping]] = ...) -> None: ...

class PathNode(_message.Message):
    __slots__ = ("x", "y", "heading")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    heading: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., heading: _Optional[float] = ...) -> None: ...

class VectorDistanceParams(_message.Message):
    __slots__ = ("safe_distance", "magnitude", "weight_decay", "turn_gain", "release_distance", "turn", "max_speed", "max_yaw_rate", "heading_gain", "slow_distance", "allow_reverse", "avoid_blocked_heading", "progress_steps", "progress_min", "no_path_steps", "no_path_min", "leave_tolerance", "hit_radius", "wall_gain", "goal_tolerance", "retry_other_side")
    SAFE_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    MAGNITUDE_FIELD_NUMBER: _ClassVar[int]
    WEIGHT_DECAY_FIELD_NUMBER: _ClassVar[int]
    TURN_GAIN_FIELD_NUMBER: _ClassVar[int]
    RELEASE_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    TURN_FIELD_NUMBER: _ClassVar[int]
    MAX_SPEED_FIELD_NUMBER: _ClassVar[int]
    MAX_YAW_RATE_FIELD_NUMBER: _ClassVar[int]
    HEADING_GAIN_FIELD_NUMBER: _ClassVar[int]
    SLOW_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    ALLOW_REVERSE_FIELD_NUMBER: _ClassVar[int]
    AVOID_BLOCKED_HEADING_FIELD_NUMBER: _ClassVar[int]
    PROGRESS_STEPS_FIELD_NUMBER: _ClassVar[int]
    PROGRESS_MIN_FIELD_NUMBER: _ClassVar[int]
    NO_PATH_STEPS_FIELD_NUMBER: _ClassVar[int]
    NO_PATH_MIN_FIELD_NUMBER: _ClassVar[int]
    LEAVE_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    HIT_RADIUS_FIELD_NUMBER: _ClassVar[int]
    WALL_GAIN_FIELD_NUMBER: _ClassVar[int]
    GOAL_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    RETRY_OTHER_SIDE_FIELD_NUMBER: _ClassVar[int]
    safe_distance: float
    magnitude: float
    weight_decay: float
    turn_gain: float
    release_distance: float
    turn: TurnPreference
    max_speed: float
    max_yaw_rate: float
    heading_gain: float
    slow_distance: float
    allow_reverse: bool
    avoid_blocked_heading: bool
    progress_steps: int
    progress_min: float
    no_path_steps: int
    no_path_min: float
    leave_tolerance: float
    hit_radius: float
    wall_gain: float
    goal_tolerance: float
    retry_other_side: bool
    def __init__(self, safe_distance: _Optional[float] = ..., magnitude: _Optional[float] = ..., weight_decay: _Optional[float] = ..., turn_gain: _Optional[float] = ..., release_distance: _Optional[float] = ..., turn: _Optional[_Union[TurnPreference, str]] = ..., max_speed: _Optional[float] = ..., max_yaw_rate: _Optional[float] = ..., heading_gain: _Optional[float] = ..., slow_distance: _Optional[float] = ..., allow_reverse: _Optional[bool] = ..., avoid_blocked_heading: _Optional[bool] = ..., progress_steps: _Optional[int] = ..., progress_min: _Optional[float] = ..., no_path_steps: _Optional[int] = ..., no_path_min: _Optional[float] = ..., leave_tolerance: _Optional[float] = ..., hit_radius: _Optional[float] = ..., wall_gain: _Optional[float] = ..., goal_tolerance: _Optional[float] = ..., retry_other_side: _Optional[bool] = ...) -> None: ...

class RangeSensorParams(_message.Message):
    __slots__ = ("count", "max_range", "beam_width", "rays_per_beam", "noise_sigma")
    COUNT_FIELD_NUMBER: _ClassVar[int]
    MAX_RANGE_FIELD_NUMBER: _ClassVar[int]
    BEAM_WIDTH_FIELD_NUMBER: _ClassVar[int]
    RAYS_PER_BEAM_FIELD_NUMBER: _ClassVar[int]
    NOISE_SIGMA_FIELD_NUMBER: _ClassVar[int]
    count: int
    max_range: float
    beam_width: float
    rays_per_beam: int
    noise_sigma: float
    def __init__(self, count: _Optional[int] = ..., max_range: _Optional[float] = ..., beam_width: _Optional[float] = ..., rays_per_beam: _Optional[int] = ..., noise_sigma: _Optional[float] = ...) -> None: ...

class Circle(_message.Message):
    __slots__ = ("center", "radius")
    CENTER_FIELD_NUMBER: _ClassVar[int]
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    center: Point2D
    radius: float
    def __init__(self, center: _Optional[_Union[Point2D, _Mapping]] = ..., radius: _Optional[float] = ...) -> None: ...

class Polygon(_message.Message):
    __slots__ = ("vertices",)
    VERTICES_FIELD_NUMBER: _ClassVar[int]
    vertices: _containers.RepeatedCompositeFieldContainer[Point2D]
    def __init__(self, vertices: _Optional[_Iterable[_Union[Point2D, _Mapping]]] = ...) -> None: ...

class Obstacle(_message.Message):
    __slots__ = ("circle", "polygon")
    CIRCLE_FIELD_NUMBER: _ClassVar[int]
    POLYGON_FIELD_NUMBER: _ClassVar[int]
    circle: Circle
    polygon: Polygon
    def __init__(self, circle: _Optional[_Union[Circle, _Mapping]] = ..., polygon: _Optional[_Union[Polygon, _Mapping]] = ...) -> None: ...

class SimOptions(_message.Message):
    __slots__ = ("robot_radius", "dt", "max_time")
    ROBOT_RADIUS_FIELD_NUMBER: _ClassVar[int]
    DT_FIELD_NUMBER: _ClassVar[int]
    MAX_TIME_FIELD_NUMBER: _ClassVar[int]
    robot_radius: float
    dt: float
    max_time: float
    def __init__(self, robot_radius: _Optional[float] = ..., dt: _Optional[float] = ..., max_time: _Optional[float] = ...) -> None: ...

class ControlStepRequest(_message.Message):
    __slots__ = ("chassis", "state", "controller", "path", "goal", "follow", "vdf", "sensors", "readings", "world", "robot_radius", "seed", "dt", "state_token")
    CHASSIS_FIELD_NUMBER: _ClassVar[int]
    STATE_FIELD_NUMBER: _ClassVar[int]
    CONTROLLER_FIELD_NUMBER: _ClassVar[int]
    PATH_FIELD_NUMBER: _ClassVar[int]
    GOAL_FIELD_NUMBER: _ClassVar[int]
    FOLLOW_FIELD_NUMBER: _ClassVar[int]
    VDF_FIELD_NUMBER: _ClassVar[int]
    SENSORS_FIELD_NUMBER: _ClassVar[int]
    READINGS_FIELD_NUMBER: _ClassVar[int]
    WORLD_FIELD_NUMBER: _ClassVar[int]
    ROBOT_RADIUS_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    DT_FIELD_NUMBER: _ClassVar[int]
    STATE_TOKEN_FIELD_NUMBER: _ClassVar[int]
    chassis: Chassis
    state: Pose2D
    controller: Controller
    path: _containers.RepeatedCompositeFieldContainer[PathNode]
    goal: Point2D
    follow: FollowOptions
    vdf: VectorDistanceParams
    sensors: RangeSensorParams
    readings: _containers.RepeatedScalarFieldContainer[float]
    world: _containers.RepeatedCompositeFieldContainer[Obstacle]
    robot_radius: float
    seed: int
    dt: float
    state_token: bytes
    def __init__(self, chassis: _Optional[_Union[Chassis, _Mapping]] = ..., state: _Optional[_Union[Pose2D, _Mapping]] = ..., controller: _Optional[_Union[Controller, str]] = ..., path: _Optional[_Iterable[_Union[PathNode, _Mapping]]] = ..., goal: _Optional[_Union[Point2D, _Mapping]] = ..., follow: _Optional[_Union[FollowOptions, _Mapping]] = ..., vdf: _Optional[_Union[VectorDistanceParams, _Mapping]] = ..., sensors: _Optional[_Union[RangeSensorParams, _Mapping]] = ..., readings: _Optional[_Iterable[float]] = ..., world: _Optional[_Iterable[_Union[Obstacle, _Mapping]]] = ..., robot_radius: _Optional[float] = ..., seed: _Optional[int] = ..., dt: _Optional[float] = ..., state_token: _Optional[bytes] = ...) -> None: ...

class ControlStepResponse(_message.Message):
    __slots__ = ("command", "applied", "saturation", "reached", "state_token", "target_node", "mode", "readings", "force", "hit_point", "leave_point", "no_path")
    COMMAND_FIELD_NUMBER: _ClassVar[int]
    APPLIED_FIELD_NUMBER: _ClassVar[int]
    SATURATION_FIELD_NUMBER: _ClassVar[int]
    REACHED_FIELD_NUMBER: _ClassVar[int]
    STATE_TOKEN_FIELD_NUMBER: _ClassVar[int]
    TARGET_NODE_FIELD_NUMBER: _ClassVar[int]
    MODE_FIELD_NUMBER: _ClassVar[int]
    READINGS_FIELD_NUMBER: _ClassVar[int]
    FORCE_FIELD_NUMBER: _ClassVar[int]
    HIT_POINT_FIELD_NUMBER: _ClassVar[int]
    LEAVE_POINT_FIELD_NUMBER: _ClassVar[int]
    NO_PATH_FIELD_NUMBER: _ClassVar[int]
    command: Twist2D
    applied: Twist2D
    saturation: Saturation
    reached: bool
    state_token: bytes
    target_node: int
    mode: NavMode
    readings: _containers.RepeatedScalarFieldContainer[float]
    force: Point2D
    hit_point: Point2D
    leave_point: Point2D
    no_path: bool
    def __init__(self, command: _Optional[_Union[Twist2D, _Mapping]] = ..., applied: _Optional[_Union[Twist2D, _Mapping]] = ..., saturation: _Optional[_Union[Saturation, _Mapping]] = ..., reached: _Optional[bool] = ..., state_token: _Optional[bytes] = ..., target_node: _Optional[int] = ..., mode: _Optional[_Union[NavMode, str]] = ..., readings: _Optional[_Iterable[float]] = ..., force: _Optional[_Union[Point2D, _Mapping]] = ..., hit_point: _Optional[_Union[Point2D, _Mapping]] = ..., leave_point: _Optional[_Union[Point2D, _Mapping]] = ..., no_path: _Optional[bool] = ...) -> None: ...

class FollowPathRequest(_message.Message):
    __slots__ = ("chassis", "start", "path", "controller", "follow", "world", "sim")
    CHASSIS_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    PATH_FIELD_NUMBER: _ClassVar[int]
    CONTROLLER_FIELD_NUMBER: _ClassVar[int]
    FOLLOW_FIELD_NUMBER: _ClassVar[int]
    WORLD_FIELD_NUMBER: _ClassVar[int]
    SIM_FIELD_NUMBER: _ClassVar[int]
    chassis: Chassis
    start: Pose2D
    path: _containers.RepeatedCompositeFieldContainer[PathNode]
    controller: Controller
    follow: FollowOptions
    world: _containers.RepeatedCompositeFieldContainer[Obstacle]
    sim: SimOptions
    def __init__(self, chassis: _Optional[_Union[Chassis, _Mapping]] = ..., start: _Optional[_Union[Pose2D, _Mapping]] = ..., path: _Optional[_Iterable[_Union[PathNode, _Mapping]]] = ..., controller: _Optional[_Union[Controller, str]] = ..., follow: _Optional[_Union[FollowOptions, _Mapping]] = ..., world: _Optional[_Iterable[_Union[Obstacle, _Mapping]]] = ..., sim: _Optional[_Union[SimOptions, _Mapping]] = ...) -> None: ...

class GridAstarOptions(_message.Message):
    __slots__ = ("resolution", "inflation", "padding", "max_cells")
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    INFLATION_FIELD_NUMBER: _ClassVar[int]
    PADDING_FIELD_NUMBER: _ClassVar[int]
    MAX_CELLS_FIELD_NUMBER: _ClassVar[int]
    resolution: float
    inflation: float
    padding: float
    max_cells: int
    def __init__(self, resolution: _Optional[float] = ..., inflation: _Optional[float] = ..., padding: _Optional[float] = ..., max_cells: _Optional[int] = ...) -> None: ...

class NavigateRequest(_message.Message):
    __slots__ = ("chassis", "start", "goal", "world", "sim", "navigator", "sensors", "vdf", "seed", "astar", "follow", "controller")
    CHASSIS_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    GOAL_FIELD_NUMBER: _ClassVar[int]
    WORLD_FIELD_NUMBER: _ClassVar[int]
    SIM_FIELD_NUMBER: _ClassVar[int]
    NAVIGATOR_FIELD_NUMBER: _ClassVar[int]
    SENSORS_FIELD_NUMBER: _ClassVar[int]
    VDF_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    ASTAR_FIELD_NUMBER: _ClassVar[int]
    FOLLOW_FIELD_NUMBER: _ClassVar[int]
    CONTROLLER_FIELD_NUMBER: _ClassVar[int]
    chassis: Chassis
    start: Pose2D
    goal: Point2D
    world: _containers.RepeatedCompositeFieldContainer[Obstacle]
    sim: SimOptions
    navigator: Navigator
    sensors: RangeSensorParams
    vdf: VectorDistanceParams
    seed: int
    astar: GridAstarOptions
    follow: FollowOptions
    controller: Controller
    def __init__(self, chassis: _Optional[_Union[Chassis, _Mapping]] = ..., start: _Optional[_Union[Pose2D, _Mapping]] = ..., goal: _Optional[_Union[Point2D, _Mapping]] = ..., world: _Optional[_Iterable[_Union[Obstacle, _Mapping]]] = ..., sim: _Optional[_Union[SimOptions, _Mapping]] = ..., navigator: _Optional[_Union[Navigator, str]] = ..., sensors: _Optional[_Union[RangeSensorParams, _Mapping]] = ..., vdf: _Optional[_Union[VectorDistanceParams, _Mapping]] = ..., seed: _Optional[int] = ..., astar: _Optional[_Union[GridAstarOptions, _Mapping]] = ..., follow: _Optional[_Union[FollowOptions, _Mapping]] = ..., controller: _Optional[_Union[Controller, str]] = ...) -> None: ...

class RunMetrics(_message.Message):
    __slots__ = ("path_length", "time", "min_clearance", "steps")
    PATH_LENGTH_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    MIN_CLEARANCE_FIELD_NUMBER: _ClassVar[int]
    STEPS_FIELD_NUMBER: _ClassVar[int]
    path_length: float
    time: float
    min_clearance: float
    steps: int
    def __init__(self, path_length: _Optional[float] = ..., time: _Optional[float] = ..., min_clearance: _Optional[float] = ..., steps: _Optional[int] = ...) -> None: ...

class MobileRun(_message.Message):
    __slots__ = ("outcome", "states", "commands", "modes", "hit_points", "leave_points", "no_path_reason", "collided_with", "metrics")
    OUTCOME_FIELD_NUMBER: _ClassVar[int]
    STATES_FIELD_NUMBER: _ClassVar[int]
    COMMANDS_FIELD_NUMBER: _ClassVar[int]
    MODES_FIELD_NUMBER: _ClassVar[int]
    HIT_POINTS_FIELD_NUMBER: _ClassVar[int]
    LEAVE_POINTS_FIELD_NUMBER: _ClassVar[int]
    NO_PATH_REASON_FIELD_NUMBER: _ClassVar[int]
    COLLIDED_WITH_FIELD_NUMBER: _ClassVar[int]
    METRICS_FIELD_NUMBER: _ClassVar[int]
    outcome: Outcome
    states: _containers.RepeatedCompositeFieldContainer[Pose2D]
    commands: _containers.RepeatedCompositeFieldContainer[Twist2D]
    modes: _containers.RepeatedScalarFieldContainer[NavMode]
    hit_points: _containers.RepeatedCompositeFieldContainer[Point2D]
    leave_points: _containers.RepeatedCompositeFieldContainer[Point2D]
    no_path_reason: NoPathReason
    collided_with: int
    metrics: RunMetrics
    def __init__(self, outcome: _Optional[_Union[Outcome, str]] = ..., states: _Optional[_Iterable[_Union[Pose2D, _Mapping]]] = ..., commands: _Optional[_Iterable[_Union[Twist2D, _Mapping]]] = ..., modes: _Optional[_Iterable[_Union[NavMode, str]]] = ..., hit_points: _Optional[_Iterable[_Union[Point2D, _Mapping]]] = ..., leave_points: _Optional[_Iterable[_Union[Point2D, _Mapping]]] = ..., no_path_reason: _Optional[_Union[NoPathReason, str]] = ..., collided_with: _Optional[int] = ..., metrics: _Optional[_Union[RunMetrics, _Mapping]] = ...) -> None: ...
