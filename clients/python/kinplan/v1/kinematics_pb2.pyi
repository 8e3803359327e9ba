from kinplan.v1 import common_pb2 as _common_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class IkMethod(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    IK_METHOD_UNSPECIFIED: _ClassVar[IkMethod]
    IK_METHOD_JACOBIAN_INVERSE: _ClassVar[IkMethod]
    IK_METHOD_LEVENBERG_MARQUARDT: _ClassVar[IkMethod]
    IK_METHOD_NEWTON: _ClassVar[IkMethod]
    IK_METHOD_CCD: _ClassVar[IkMethod]
    IK_METHOD_FABRIK: _ClassVar[IkMethod]
    IK_METHOD_LENGTH_RELAXATION: _ClassVar[IkMethod]
    IK_METHOD_ANALYTIC: _ClassVar[IkMethod]

class LinearSolver(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    LINEAR_SOLVER_UNSPECIFIED: _ClassVar[LinearSolver]
    LINEAR_SOLVER_SVD_PSEUDOINVERSE: _ClassVar[LinearSolver]
    LINEAR_SOLVER_ANGLE_RELAXATION: _ClassVar[LinearSolver]
    LINEAR_SOLVER_ANGLE_RELAXATION_SAFEGUARDED: _ClassVar[LinearSolver]

class JointLimitMode(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    JOINT_LIMIT_MODE_UNSPECIFIED: _ClassVar[JointLimitMode]
    JOINT_LIMIT_MODE_CLAMP: _ClassVar[JointLimitMode]
    JOINT_LIMIT_MODE_IGNORE: _ClassVar[JointLimitMode]

class IkStatus(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    IK_STATUS_UNSPECIFIED: _ClassVar[IkStatus]
    IK_STATUS_CONVERGED: _ClassVar[IkStatus]
    IK_STATUS_MAX_ITERATIONS: _ClassVar[IkStatus]
    IK_STATUS_STALLED: _ClassVar[IkStatus]
    IK_STATUS_TIME_BUDGET: _ClassVar[IkStatus]
    IK_STATUS_CANCELLED: _ClassVar[IkStatus]

class LinearSolveStatus(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    LINEAR_SOLVE_STATUS_UNSPECIFIED: _ClassVar[LinearSolveStatus]
    LINEAR_SOLVE_STATUS_CONVERGED: _ClassVar[LinearSolveStatus]
    LINEAR_SOLVE_STATUS_ITERATION_CAP: _ClassVar[LinearSolveStatus]
IK_METHOD_UNSPECIFIED: IkMethod
IK_METHOD_JACOBIAN_INVERSE: IkMethod
IK_METHOD_LEVENBERG_MARQUARDT: IkMethod
IK_METHOD_NEWTON: IkMethod
IK_METHOD_CCD: IkMethod
IK_METHOD_FABRIK: IkMethod
IK_METHOD_LENGTH_RELAXATION: IkMethod
IK_METHOD_ANALYTIC: IkMethod
LINEAR_SOLVER_UNSPECIFIED: LinearSolver
LINEAR_SOLVER_SVD_PSEUDOINVERSE: LinearSolver
LINEAR_SOLVER_ANGLE_RELAXATION: LinearSolver
LINEAR_SOLVER_ANGLE_RELAXATION_SAFEGUARDED: LinearSolver
JOINT_LIMIT_MODE_UNSPECIFIED: JointLimitMode
JOINT_LIMIT_MODE_CLAMP: JointLimitMode
JOINT_LIMIT_MODE_IGNORE: JointLimitMode
IK_STATUS_UNSPECIFIED: IkStatus
IK_STATUS_CONVERGED: IkStatus
IK_STATUS_MAX_ITERATIONS: IkStatus
IK_STATUS_STALLED: IkStatus
IK_STATUS_TIME_BUDGET: IkStatus
IK_STATUS_CANCELLED: IkStatus
LINEAR_SOLVE_STATUS_UNSPECIFIED: LinearSolveStatus
LINEAR_SOLVE_STATUS_CONVERGED: LinearSolveStatus
LINEAR_SOLVE_STATUS_ITERATION_CAP: LinearSolveStatus

class IkOptions(_message.Message):
    __slots__ = ("method", "linear_solver", "position_tolerance", "orientation_tolerance", "position_only", "max_iterations", "damping", "max_restarts", "num_solutions", "rng_seed", "joint_limits", "time_budget", "adaptive_damping", "max_step", "distinct_tolerance", "rlxa_max_iterations", "return_history", "hold_configuration", "nearest_turn_only", "redundant_joint", "analytic_start", "search_redundant", "redundant_samples", "search_samples")
    METHOD_FIELD_NUMBER: _ClassVar[int]
    LINEAR_SOLVER_FIELD_NUMBER: _ClassVar[int]
    POSITION_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    POSITION_ONLY_FIELD_NUMBER: _ClassVar[int]
    MAX_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    DAMPING_FIELD_NUMBER: _ClassVar[int]
    MAX_RESTARTS_FIELD_NUMBER: _ClassVar[int]
    NUM_SOLUTIONS_FIELD_NUMBER: _ClassVar[int]
    RNG_SEED_FIELD_NUMBER: _ClassVar[int]
    JOINT_LIMITS_FIELD_NUMBER: _ClassVar[int]
    TIME_BUDGET_FIELD_NUMBER: _ClassVar[int]
    ADAPTIVE_DAMPING_FIELD_NUMBER: _ClassVar[int]
    MAX_STEP_FIELD_NUMBER: _ClassVar[int]
    DISTINCT_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    RLXA_MAX_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    RETURN_HISTORY_FIELD_NUMBER: _ClassVar[int]
    HOLD_CONFIGURATION_FIELD_NUMBER: _ClassVar[int]
    NEAREST_TURN_ONLY_FIELD_NUMBER: _ClassVar[int]
    REDUNDANT_JOINT_FIELD_NUMBER: _ClassVar[int]
    ANALYTIC_START_FIELD_NUMBER: _ClassVar[int]
    SEARCH_REDUNDANT_FIELD_NUMBER: _ClassVar[int]
    REDUNDANT_SAMPLES_FIELD_NUMBER: _ClassVar[int]
    SEARCH_SAMPLES_FIELD_NUMBER: _ClassVar[int]
    method: IkMethod
    linear_solver: LinearSolver
    position_tolerance: float
    orientation_tolerance: float
    position_only: bool
    max_iterations: int
    damping: float
    max_restarts: int
    num_solutions: int
    rng_seed: int
    joint_limits: JointLimitMode
    time_budget: float
    adaptive_damping: bool
    max_step: float
    distinct_tolerance: float
    rlxa_max_iterations: int
    return_history: bool
    hold_configuration: bool
    nearest_turn_only: bool
    redundant_joint: int
    analytic_start: bool
    search_redundant: bool
    redundant_samples: int
    search_samples: int
    def __init__(self, method: _Optional[_Union[IkMethod, str]] = ..., linear_solver: _Optional[_Union[LinearSolver, str]] = ..., position_tolerance: _Optional[float] = ..., orientation_tolerance: _Optional[float] = ..., position_only: _Optional[bool] = ..., max_iterations: _Optional[int] = ..., damping: _Optional[float] = ..., max_restarts: _Optional[int] = ..., num_solutions: _Optional[int] = ..., rng_seed: _Optional[int] = ..., joint_limits: _Optional[_Union[JointLimitMode, str]] = ..., time_budget: _Optional[float] = ..., adaptive_damping: _Optional[bool] = ..., max_step: _Optional[float] = ..., distinct_tolerance: _Optional[float] = ..., rlxa_max_iterations: _Optional[int] = ..., return_history: _Optional[bool] = ..., hold_configuration: _Optional[bool] = ..., nearest_turn_only: _Optional[bool] = ..., redundant_joint: _Optional[int] = ..., analytic_start: _Optional[bool] = ..., search_redundant: _Optional[bool] = ..., redundant_samples: _Optional[int] = ..., search_samples: _Optional[int] = ...) -> None: ...

class ConfigFlags(_message.Message):
    __slots__ = ("shoulder_back", "elbow_down", "wrist_flipped")
    SHOULDER_BACK_FIELD_NUMBER: _ClassVar[int]
    ELBOW_DOWN_FIELD_NUMBER: _ClassVar[int]
    WRIST_FLIPPED_FIELD_NUMBER: _ClassVar[int]
    shoulder_back: bool
    elbow_down: bool
    wrist_flipped: bool
    def __init__(self, shoulder_back: _Optional[bool] = ..., elbow_down: _Optional[bool] = ..., wrist_flipped: _Optional[bool] = ...) -> None: ...

class SolveIkRequest(_message.Message):
    __slots__ = ("robot", "target", "seed", "options")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    TARGET_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    target: _common_pb2.Pose
    seed: _containers.RepeatedScalarFieldContainer[float]
    options: IkOptions
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., target: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., seed: _Optional[_Iterable[float]] = ..., options: _Optional[_Union[IkOptions, _Mapping]] = ...) -> None: ...

class IkSolution(_message.Message):
    __slots__ = ("joints", "position_error", "orientation_error", "iterations", "elapsed_us", "status", "attempt", "position_error_history", "orientation_error_history", "config", "singular")
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    POSITION_ERROR_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_ERROR_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    ATTEMPT_FIELD_NUMBER: _ClassVar[int]
    POSITION_ERROR_HISTORY_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_ERROR_HISTORY_FIELD_NUMBER: _ClassVar[int]
    CONFIG_FIELD_NUMBER: _ClassVar[int]
    SINGULAR_FIELD_NUMBER: _ClassVar[int]
    joints: _containers.RepeatedScalarFieldContainer[float]
    position_error: float
    orientation_error: float
    iterations: int
    elapsed_us: int
    status: IkStatus
    attempt: int
    position_error_history: _containers.RepeatedScalarFieldContainer[float]
    orientation_error_history: _containers.RepeatedScalarFieldContainer[float]
    config: ConfigFlags
    singular: bool
    def __init__(self, joints: _Optional[_Iterable[float]] = ..., position_error: _Optional[float] = ..., orientation_error: _Optional[float] = ..., iterations: _Optional[int] = ..., elapsed_us: _Optional[int] = ..., status: _Optional[_Union[IkStatus, str]] = ..., attempt: _Optional[int] = ..., position_error_history: _Optional[_Iterable[float]] = ..., orientation_error_history: _Optional[_Iterable[float]] = ..., config: _Optional[_Union[ConfigFlags, _Mapping]] = ..., singular: _Optional[bool] = ...) -> None: ...

class SolveIkResponse(_message.Message):
    __slots__ = ("solutions", "best_attempt", "success", "status", "attempts", "total_iterations", "elapsed_us", "model_id")
    SOLUTIONS_FIELD_NUMBER: _ClassVar[int]
    BEST_ATTEMPT_FIELD_NUMBER: _ClassVar[int]
    SUCCESS_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    ATTEMPTS_FIELD_NUMBER: _ClassVar[int]
    TOTAL_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    solutions: _containers.RepeatedCompositeFieldContainer[IkSolution]
    best_attempt: IkSolution
    success: bool
    status: IkStatus
    attempts: int
    total_iterations: int
    elapsed_us: int
    model_id: bytes
    def __init__(self, solutions: _Optional[_Iterable[_Union[IkSolution, _Mapping]]] = ..., best_attempt: _Optional[_Union[IkSolution, _Mapping]] = ..., success: _Optional[bool] = ..., status: _Optional[_Union[IkStatus, str]] = ..., attempts: _Optional[int] = ..., total_iterations: _Optional[int] = ..., elapsed_us: _Optional[int] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class SolveIkBatchRequest(_message.Message):
    __slots__ = ("robot", "targets", "seed", "options", "seeds")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    TARGETS_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    SEEDS_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    targets: _containers.RepeatedCompositeFieldContainer[_common_pb2.Pose]
    seed: _containers.RepeatedScalarFieldContainer[float]
    options: IkOptions
    seeds: _common_pb2.Matrix
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., targets: _Optional[_Iterable[_Union[_common_pb2.Pose, _Mapping]]] = ..., seed: _Optional[_Iterable[float]] = ..., options: _Optional[_Union[IkOptions, _Mapping]] = ..., seeds: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ...) -> None: ...

class SolveIkBatchResponse(_message.Message):
    __slots__ = ("results", "succeeded", "elapsed_us", "model_id")
    RESULTS_FIELD_NUMBER: _ClassVar[int]
    SUCCEEDED_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    results: _containers.RepeatedCompositeFieldContainer[SolveIkResponse]
    succeeded: int
    elapsed_us: int
    model_id: bytes
    def __init__(self, results: _Optional[_Iterable[_Union[SolveIkResponse, _Mapping]]] = ..., succeeded: _Optional[int] = ..., elapsed_us: _Optional[int] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class LinePath(_message.Message):
    __slots__ = ("start", "end", "steps")
    START_FIELD_NUMBER: _ClassVar[int]
    END_FIELD_NUMBER: _ClassVar[int]
    STEPS_FIELD_NUMBER: _ClassVar[int]
    start: _common_pb2.Pose
    end: _common_pb2.Pose
    steps: int
    def __init__(self, start: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., end: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., steps: _Optional[int] = ...) -> None: ...

class CirclePath(_message.Message):
    __slots__ = ("start", "centre", "normal", "angle_step", "steps")
    START_FIELD_NUMBER: _ClassVar[int]
    CENTRE_FIELD_NUMBER: _ClassVar[int]
    NORMAL_FIELD_NUMBER: _ClassVar[int]
    ANGLE_STEP_FIELD_NUMBER: _ClassVar[int]
    STEPS_FIELD_NUMBER: _ClassVar[int]
    start: _common_pb2.Pose
    centre: _common_pb2.Vec3
    normal: _common_pb2.Vec3
    angle_step: float
    steps: int
    def __init__(self, start: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., centre: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., normal: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., angle_step: _Optional[float] = ..., steps: _Optional[int] = ...) -> None: ...

class TrackPathRequest(_message.Message):
    __slots__ = ("robot", "poses", "line", "circle", "seed", "options", "stop_on_failure")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    POSES_FIELD_NUMBER: _ClassVar[int]
    LINE_FIELD_NUMBER: _ClassVar[int]
    CIRCLE_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    STOP_ON_FAILURE_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    poses: _containers.RepeatedCompositeFieldContainer[_common_pb2.Pose]
    line: LinePath
    circle: CirclePath
    seed: _containers.RepeatedScalarFieldContainer[float]
    options: IkOptions
    stop_on_failure: bool
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., poses: _Optional[_Iterable[_Union[_common_pb2.Pose, _Mapping]]] = ..., line: _Optional[_Union[LinePath, _Mapping]] = ..., circle: _Optional[_Union[CirclePath, _Mapping]] = ..., seed: _Optional[_Iterable[float]] = ..., options: _Optional[_Union[IkOptions, _Mapping]] = ..., stop_on_failure: _Optional[bool] = ...) -> None: ...

class TrackStep(_message.Message):
    __slots__ = ("target", "joints", "position_error", "orientation_error", "iterations", "elapsed_us", "status", "max_joint_step")
    TARGET_FIELD_NUMBER: _ClassVar[int]
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    POSITION_ERROR_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_ERROR_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    MAX_JOINT_STEP_FIELD_NUMBER: _ClassVar[int]
    target: _common_pb2.Pose
    joints: _containers.RepeatedScalarFieldContainer[float]
    position_error: float
    orientation_error: float
    iterations: int
    elapsed_us: int
    status: IkStatus
    max_joint_step: float
    def __init__(self, target: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., joints: _Optional[_Iterable[float]] = ..., position_error: _Optional[float] = ..., orientation_error: _Optional[float] = ..., iterations: _Optional[int] = ..., elapsed_us: _Optional[int] = ..., status: _Optional[_Union[IkStatus, str]] = ..., max_joint_step: _Optional[float] = ...) -> None: ...

class TrackPathResponse(_message.Message):
    __slots__ = ("steps", "all_converged", "max_joint_step", "elapsed_us", "status", "model_id")
    STEPS_FIELD_NUMBER: _ClassVar[int]
    ALL_CONVERGED_FIELD_NUMBER: _ClassVar[int]
    MAX_JOINT_STEP_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    MODEL_ID_FIELD_NUMBER: _ClassVar[int]
    steps: _containers.RepeatedCompositeFieldContainer[TrackStep]
    all_converged: bool
    max_joint_step: float
    elapsed_us: int
    status: IkStatus
    model_id: bytes
    def __init__(self, steps: _Optional[_Iterable[_Union[TrackStep, _Mapping]]] = ..., all_converged: _Optional[bool] = ..., max_joint_step: _Optional[float] = ..., elapsed_us: _Optional[int] = ..., status: _Optional[_Union[IkStatus, str]] = ..., model_id: _Optional[bytes] = ...) -> None: ...

class StreamIkRequest(_message.Message):
    __slots__ = ("sequence", "robot", "options", "seed", "target")
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    TARGET_FIELD_NUMBER: _ClassVar[int]
    sequence: int
    robot: _common_pb2.RobotRef
    options: IkOptions
    seed: _containers.RepeatedScalarFieldContainer[float]
    target: _common_pb2.Pose
    def __init__(self, sequence: _Optional[int] = ..., robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., options: _Optional[_Union[IkOptions, _Mapping]] = ..., seed: _Optional[_Iterable[float]] = ..., target: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ...) -> None: ...

class StreamIkResponse(_message.Message):
    __slots__ = ("sequence", "result")
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    RESULT_FIELD_NUMBER: _ClassVar[int]
    sequence: int
    result: SolveIkResponse
    def __init__(self, sequence: _Optional[int] = ..., result: _Optional[_Union[SolveIkResponse, _Mapping]] = ...) -> None: ...

class SolveLinearSystemRequest(_message.Message):
    __slots__ = ("a", "b", "method", "max_iterations", "tolerance", "relative_tolerance", "rng_seed", "record_history", "singular_value_tolerance")
    A_FIELD_NUMBER: _ClassVar[int]
    B_FIELD_NUMBER: _ClassVar[int]
    METHOD_FIELD_NUMBER: _ClassVar[int]
    MAX_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    RELATIVE_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    RNG_SEED_FIELD_NUMBER: _ClassVar[int]
    RECORD_HISTORY_FIELD_NUMBER: _ClassVar[int]
    SINGULAR_VALUE_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    a: _common_pb2.Matrix
    b: _containers.RepeatedScalarFieldContainer[float]
    method: LinearSolver
    max_iterations: int
    tolerance: float
    relative_tolerance: float
    rng_seed: int
    record_history: bool
    singular_value_tolerance: float
    def __init__(self, a: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., b: _Optional[_Iterable[float]] = ..., method: _Optional[_Union[LinearSolver, str]] = ..., max_iterations: _Optional[int] = ..., tolerance: _Optional[float] = ..., relative_tolerance: _Optional[float] = ..., rng_seed: _Optional[int] = ..., record_history: _Optional[bool] = ..., singular_value_tolerance: _Optional[float] = ...) -> None: ...

class SolveLinearSystemResponse(_message.Message):
    __slots__ = ("x", "residual_norm", "iterations", "status", "residual_history", "elapsed_us")
    X_FIELD_NUMBER: _ClassVar[int]
    RESIDUAL_NORM_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    RESIDUAL_HISTORY_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_US_FIELD_NUMBER: _ClassVar[int]
    x: _containers.RepeatedScalarFieldContainer[float]
    residual_norm: float
    iterations: int
    status: LinearSolveStatus
    residual_history: _containers.RepeatedScalarFieldContainer[float]
    elapsed_us: int
    def __init__(self, x: _Optional[_Iterable[float]] = ..., residual_norm: _Optional[float] = ..., iterations: _Optional[int] = ..., status: _Optional[_Union[LinearSolveStatus, str]] = ..., residual_history: _Optional[_Iterable[float]] = ..., elapsed_us: _Optional[int] = ...) -> None: ...
