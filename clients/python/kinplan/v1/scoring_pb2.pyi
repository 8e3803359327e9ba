from kinplan.v1 import common_pb2 as _common_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class RobotPoints(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    ROBOT_POINTS_UNSPECIFIED: _ClassVar[RobotPoints]
    ROBOT_POINTS_LINK_ORIGINS: _ClassVar[RobotPoints]
    ROBOT_POINTS_COLLISION_VERTICES: _ClassVar[RobotPoints]
    ROBOT_POINTS_NONE: _ClassVar[RobotPoints]
ROBOT_POINTS_UNSPECIFIED: RobotPoints
ROBOT_POINTS_LINK_ORIGINS: RobotPoints
ROBOT_POINTS_COLLISION_VERTICES: RobotPoints
ROBOT_POINTS_NONE: RobotPoints

class JerkPeakOptions(_message.Message):
    __slots__ = ("joint_log_gain", "joint_offset", "cartesian_sqrt_gain", "cartesian_offset", "joint_min_height", "cartesian_min_height", "edge_peaks", "slowdown_floor")
    JOINT_LOG_GAIN_FIELD_NUMBER: _ClassVar[int]
    JOINT_OFFSET_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_SQRT_GAIN_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_OFFSET_FIELD_NUMBER: _ClassVar[int]
    JOINT_MIN_HEIGHT_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_MIN_HEIGHT_FIELD_NUMBER: _ClassVar[int]
    EDGE_PEAKS_FIELD_NUMBER: _ClassVar[int]
    SLOWDOWN_FLOOR_FIELD_NUMBER: _ClassVar[int]
    joint_log_gain: float
    joint_offset: float
    cartesian_sqrt_gain: float
    cartesian_offset: float
    joint_min_height: float
    cartesian_min_height: float
    edge_peaks: bool
    slowdown_floor: float
    def __init__(self, joint_log_gain: _Optional[float] = ..., joint_offset: _Optional[float] = ..., cartesian_sqrt_gain: _Optional[float] = ..., cartesian_offset: _Optional[float] = ..., joint_min_height: _Optional[float] = ..., cartesian_min_height: _Optional[float] = ..., edge_peaks: _Optional[bool] = ..., slowdown_floor: _Optional[float] = ...) -> None: ...

class ScoreOptions(_message.Message):
    __slots__ = ("joint_weights", "series", "robot_points", "max_velocity", "max_acceleration", "jerk_peaks", "potential_tolerance")
    JOINT_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    SERIES_FIELD_NUMBER: _ClassVar[int]
    ROBOT_POINTS_FIELD_NUMBER: _ClassVar[int]
    MAX_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    MAX_ACCELERATION_FIELD_NUMBER: _ClassVar[int]
    JERK_PEAKS_FIELD_NUMBER: _ClassVar[int]
    POTENTIAL_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    joint_weights: _containers.RepeatedScalarFieldContainer[float]
    series: bool
    robot_points: RobotPoints
    max_velocity: _containers.RepeatedScalarFieldContainer[float]
    max_acceleration: _containers.RepeatedScalarFieldContainer[float]
    jerk_peaks: JerkPeakOptions
    potential_tolerance: float
    def __init__(self, joint_weights: _Optional[_Iterable[float]] = ..., series: _Optional[bool] = ..., robot_points: _Optional[_Union[RobotPoints, str]] = ..., max_velocity: _Optional[_Iterable[float]] = ..., max_acceleration: _Optional[_Iterable[float]] = ..., jerk_peaks: _Optional[_Union[JerkPeakOptions, _Mapping]] = ..., potential_tolerance: _Optional[float] = ...) -> None: ...

class ScoreTrajectoryRequest(_message.Message):
    __slots__ = ("robot", "trajectory", "options")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    trajectory: _common_pb2.JointTrajectory
    options: ScoreOptions
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., trajectory: _Optional[_Union[_common_pb2.JointTrajectory, _Mapping]] = ..., options: _Optional[_Union[ScoreOptions, _Mapping]] = ...) -> None: ...

class SegmentTime(_message.Message):
    __slots__ = ("duration", "limiting_joint")
    DURATION_FIELD_NUMBER: _ClassVar[int]
    LIMITING_JOINT_FIELD_NUMBER: _ClassVar[int]
    duration: float
    limiting_joint: int
    def __init__(self, duration: _Optional[float] = ..., limiting_joint: _Optional[int] = ...) -> None: ...

class TimePotential(_message.Message):
    __slots__ = ("index", "via", "direct", "gain", "has_potential")
    INDEX_FIELD_NUMBER: _ClassVar[int]
    VIA_FIELD_NUMBER: _ClassVar[int]
    DIRECT_FIELD_NUMBER: _ClassVar[int]
    GAIN_FIELD_NUMBER: _ClassVar[int]
    HAS_POTENTIAL_FIELD_NUMBER: _ClassVar[int]
    index: int
    via: float
    direct: float
    gain: float
    has_potential: bool
    def __init__(self, index: _Optional[int] = ..., via: _Optional[float] = ..., direct: _Optional[float] = ..., gain: _Optional[float] = ..., has_potential: _Optional[bool] = ...) -> None: ...

class CycleTime(_message.Message):
    __slots__ = ("total", "segments", "potentials")
    TOTAL_FIELD_NUMBER: _ClassVar[int]
    SEGMENTS_FIELD_NUMBER: _ClassVar[int]
    POTENTIALS_FIELD_NUMBER: _ClassVar[int]
    total: float
    segments: _containers.RepeatedCompositeFieldContainer[SegmentTime]
    potentials: _containers.RepeatedCompositeFieldContainer[TimePotential]
    def __init__(self, total: _Optional[float] = ..., segments: _Optional[_Iterable[_Union[SegmentTime, _Mapping]]] = ..., potentials: _Optional[_Iterable[_Union[TimePotential, _Mapping]]] = ...) -> None: ...

class JerkPeak(_message.Message):
    __slots__ = ("index", "height", "slowdown")
    INDEX_FIELD_NUMBER: _ClassVar[int]
    HEIGHT_FIELD_NUMBER: _ClassVar[int]
    SLOWDOWN_FIELD_NUMBER: _ClassVar[int]
    index: int
    height: float
    slowdown: float
    def __init__(self, index: _Optional[int] = ..., height: _Optional[float] = ..., slowdown: _Optional[float] = ...) -> None: ...

class TimeScaledJerk(_message.Message):
    __slots__ = ("jj", "cj", "jmj", "cmj")
    JJ_FIELD_NUMBER: _ClassVar[int]
    CJ_FIELD_NUMBER: _ClassVar[int]
    JMJ_FIELD_NUMBER: _ClassVar[int]
    CMJ_FIELD_NUMBER: _ClassVar[int]
    jj: float
    cj: float
    jmj: float
    cmj: float
    def __init__(self, jj: _Optional[float] = ..., cj: _Optional[float] = ..., jmj: _Optional[float] = ..., cmj: _Optional[float] = ...) -> None: ...

class ScoreSeries(_message.Message):
    __slots__ = ("cd", "jd", "oc", "cpc", "rdm", "joint_jerk", "cartesian_jerk", "joint_peaks", "cartesian_peaks", "joint_jerk_rate", "cartesian_jerk_rate")
    CD_FIELD_NUMBER: _ClassVar[int]
    JD_FIELD_NUMBER: _ClassVar[int]
    OC_FIELD_NUMBER: _ClassVar[int]
    CPC_FIELD_NUMBER: _ClassVar[int]
    RDM_FIELD_NUMBER: _ClassVar[int]
    JOINT_JERK_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_JERK_FIELD_NUMBER: _ClassVar[int]
    JOINT_PEAKS_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_PEAKS_FIELD_NUMBER: _ClassVar[int]
    JOINT_JERK_RATE_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_JERK_RATE_FIELD_NUMBER: _ClassVar[int]
    cd: _containers.RepeatedScalarFieldContainer[float]
    jd: _containers.RepeatedScalarFieldContainer[float]
    oc: _containers.RepeatedScalarFieldContainer[float]
    cpc: _containers.RepeatedScalarFieldContainer[float]
    rdm: _containers.RepeatedScalarFieldContainer[float]
    joint_jerk: _containers.RepeatedScalarFieldContainer[float]
    cartesian_jerk: _containers.RepeatedScalarFieldContainer[float]
    joint_peaks: _containers.RepeatedCompositeFieldContainer[JerkPeak]
    cartesian_peaks: _containers.RepeatedCompositeFieldContainer[JerkPeak]
    joint_jerk_rate: _containers.RepeatedScalarFieldContainer[float]
    cartesian_jerk_rate: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, cd: _Optional[_Iterable[float]] = ..., jd: _Optional[_Iterable[float]] = ..., oc: _Optional[_Iterable[float]] = ..., cpc: _Optional[_Iterable[float]] = ..., rdm: _Optional[_Iterable[float]] = ..., joint_jerk: _Optional[_Iterable[float]] = ..., cartesian_jerk: _Optional[_Iterable[float]] = ..., joint_peaks: _Optional[_Iterable[_Union[JerkPeak, _Mapping]]] = ..., cartesian_peaks: _Optional[_Iterable[_Union[JerkPeak, _Mapping]]] = ..., joint_jerk_rate: _Optional[_Iterable[float]] = ..., cartesian_jerk_rate: _Optional[_Iterable[float]] = ...) -> None: ...

class ScoreTrajectoryResponse(_message.Message):
    __slots__ = ("criteria", "waypoints", "joint_peak_count", "cartesian_peak_count", "robot_points", "cycle_time", "cycle_time_unavailable", "time_scaled", "series", "model_id")
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    WAYPOINTS_FIELD_NUMBER: _ClassVar[int]
    JOINT_PEAK_COUNT_FIELD_NUMBER: _ClassVar[int]
    CARTESIAN_PEAK_COUNT_FIELD_NUMBER: _ClassVar[int]
    ROBOT_POINTS_FIELD_NUMBER: _ClassVar[int]
    CYCLE_TIME_FIELD_NUMBER: _ClassVar[int]
    CYCLE_TIME_UNAVAILABLE_FIELD_NUMBER: _ClassVar[int]
    TIME_SCALED_FIELD_NUMBER: _ClassVar[int]
    SERIES_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    criteria: _containers.ScalarMap[str, float]
    waypoints: int
    joint_peak_count: int
    cartesian_peak_count: int
    robot_points: int
    cycle_time: CycleTime
    cycle_time_unavailable: str
    time_scaled: TimeScaledJerk
    series: ScoreSeries
    model_id: bytes
    def __init__(self, criteria: _Optional[_Mapping[str, float]] = ..., waypoints: _Optional[int] = ..., joint_peak_count: _Optional[int] = ..., cartesian_peak_count: _Optional[int] = ..., robot_points: _Optional[int] = ..., cycle_time: _Optional[_Union[CycleTime, _Mapping]] = ..., cycle_time_unavailable: _Optional[str] = ..., time_scaled: _Optional[_Union[TimeScaledJerk, _Mapping]] = ..., series: _Optional[_Union[ScoreSeries, _Mapping]] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class TrajectorySet(_message.Message):
    __slots__ = ("label", "trajectories")
    LABEL_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORIES_FIELD_NUMBER: _ClassVar[int]
    label: str
    trajectories: _containers.RepeatedCompositeFieldContainer[_common_pb2.JointTrajectory]
    def __init__(self, label: _Optional[str] = ..., trajectories: _Optional[_Iterable[_Union[_common_pb2.JointTrajectory, _Mapping]]] = ...) -> None: ...

class CompareTrajectoriesRequest(_message.Message):
    __slots__ = ("robot", "sets", "options")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    SETS_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    sets: _containers.RepeatedCompositeFieldContainer[TrajectorySet]
    options: ScoreOptions
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., sets: _Optional[_Iterable[_Union[TrajectorySet, _Mapping]]] = ..., options: _Optional[_Union[ScoreOptions, _Mapping]] = ...) -> None: ...

class CriterionStats(_message.Message):
    __slots__ = ("count", "mean", "variance", "population_variance", "sum", "min", "max")
    COUNT_FIELD_NUMBER: _ClassVar[int]
    MEAN_FIELD_NUMBER: _ClassVar[int]
    VARIANCE_FIELD_NUMBER: _ClassVar[int]
    POPULATION_VARIANCE_FIELD_NUMBER: _ClassVar[int]
    SUM_FIELD_NUMBER: _ClassVar[int]
    MIN_FIELD_NUMBER: _ClassVar[int]
    MAX_FIELD_NUMBER: _ClassVar[int]
    count: int
    mean: float
    variance: float
    population_variance: float
    sum: float
    min: float
    max: float
    def __init__(self, count: _Optional[int] = ..., mean: _Optional[float] = ..., variance: _Optional[float] = ..., population_variance: _Optional[float] = ..., sum: _Optional[float] = ..., min: _Optional[float] = ..., max: _Optional[float] = ...) -> None: ...

class TrajectoryCriteria(_message.Message):
    __slots__ = ("criteria",)
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    criteria: _containers.ScalarMap[str, float]
    def __init__(self, criteria: _Optional[_Mapping[str, float]] = ...) -> None: ...

class SetSummary(_message.Message):
    __slots__ = ("label", "trajectories", "criteria", "scores")
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: CriterionStats
        def __init__(self, key: _Optional[str] = ..., value: _Optional[_Union[CriterionStats, _Mapping]] = ...) -> None: ...
    LABEL_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORIES_FIELD_NUMBER: _ClassVar[int]
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    SCORES_FIELD_NUMBER: _ClassVar[int]
    label: str
    trajectories: int
    criteria: _containers.MessageMap[str, CriterionStats]
    scores: _containers.RepeatedCompositeFieldContainer[TrajectoryCriteria]
    def __init__(self, label: _Optional[str] = ..., trajectories: _Optional[int] = ..., criteria: _Optional[_Mapping[str, CriterionStats]] = ..., scores: _Optional[_Iterable[_Union[TrajectoryCriteria, _Mapping]]] = ...) -> None: ...

class CompareTrajectoriesResponse(_message.Message):
    __slots__ = ("sets", "criteria", "cycle_time_unavailable", "model_id")
    SETS_FIELD_NUMBER: _ClassVar[int]
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    CYCLE_TIME_UNAVAILABLE_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    sets: _containers.RepeatedCompositeFieldContainer[SetSummary]
    criteria: _containers.RepeatedScalarFieldContainer[str]
    cycle_time_unavailable: str
    model_id: bytes
    def __init__(self, sets: _Optional[_Iterable[_Union[SetSummary, _Mapping]]] = ..., criteria: _Optional[_Iterable[str]] = ..., cycle_time_unavailable: _Optional[str] = ..., model_id: _Optional[bytes] = ...) -> None: ...
