from kinplan.v1 import common_pb2 as _common_pb2
from kinplan.v1 import planning_pb2 as _planning_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class GainMethod(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    GAIN_METHOD_UNSPECIFIED: _ClassVar[GainMethod]
    GAIN_METHOD_INTERSECTION: _ClassVar[GainMethod]
    GAIN_METHOD_RAYS: _ClassVar[GainMethod]
    GAIN_METHOD_OCCLUSION_AWARE: _ClassVar[GainMethod]
    GAIN_METHOD_UNOBSERVED_VOXELS: _ClassVar[GainMethod]

class Reachability(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    REACHABILITY_UNCHECKED: _ClassVar[Reachability]
    REACHABILITY_REACHABLE: _ClassVar[Reachability]
    REACHABILITY_UNREACHABLE: _ClassVar[Reachability]

class NbvStatus(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    NBV_STATUS_UNSPECIFIED: _ClassVar[NbvStatus]
    NBV_STATUS_COMPLETE: _ClassVar[NbvStatus]
    NBV_STATUS_TIME_BUDGET: _ClassVar[NbvStatus]
    NBV_STATUS_CANCELLED: _ClassVar[NbvStatus]

class ExploreStatus(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    EXPLORE_STATUS_UNSPECIFIED: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_EXPLORED: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_ITERATION_CAP: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_CONSECUTIVE_FAILURES: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_NO_CANDIDATES: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_TIMEOUT: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_CANCELLED: _ClassVar[ExploreStatus]
    EXPLORE_STATUS_OBSERVABLE_EXHAUSTED: _ClassVar[ExploreStatus]

class ReferenceSceneName(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    REFERENCE_SCENE_NAME_UNSPECIFIED: _ClassVar[ReferenceSceneName]
    REFERENCE_SCENE_NAME_S0_OPEN_CELL: _ClassVar[ReferenceSceneName]
    REFERENCE_SCENE_NAME_S0_WALLED_CELL: _ClassVar[ReferenceSceneName]
GAIN_METHOD_UNSPECIFIED: GainMethod
GAIN_METHOD_INTERSECTION: GainMethod
GAIN_METHOD_RAYS: GainMethod
GAIN_METHOD_OCCLUSION_AWARE: GainMethod
GAIN_METHOD_UNOBSERVED_VOXELS: GainMethod
REACHABILITY_UNCHECKED: Reachability
REACHABILITY_REACHABLE: Reachability
REACHABILITY_UNREACHABLE: Reachability
NBV_STATUS_UNSPECIFIED: NbvStatus
NBV_STATUS_COMPLETE: NbvStatus
NBV_STATUS_TIME_BUDGET: NbvStatus
NBV_STATUS_CANCELLED: NbvStatus
EXPLORE_STATUS_UNSPECIFIED: ExploreStatus
EXPLORE_STATUS_EXPLORED: ExploreStatus
EXPLORE_STATUS_ITERATION_CAP: ExploreStatus
EXPLORE_STATUS_CONSECUTIVE_FAILURES: ExploreStatus
EXPLORE_STATUS_NO_CANDIDATES: ExploreStatus
EXPLORE_STATUS_TIMEOUT: ExploreStatus
EXPLORE_STATUS_CANCELLED: ExploreStatus
EXPLORE_STATUS_OBSERVABLE_EXHAUSTED: ExploreStatus
REFERENCE_SCENE_NAME_UNSPECIFIED: ReferenceSceneName
REFERENCE_SCENE_NAME_S0_OPEN_CELL: ReferenceSceneName
REFERENCE_SCENE_NAME_S0_WALLED_CELL: ReferenceSceneName

class CameraModel(_message.Message):
    __slots__ = ("horizontal_fov", "vertical_fov", "near_range", "far_range", "width", "height")
    HORIZONTAL_FOV_FIELD_NUMBER: _ClassVar[int]
    VERTICAL_FOV_FIELD_NUMBER: _ClassVar[int]
    NEAR_RANGE_FIELD_NUMBER: _ClassVar[int]
    FAR_RANGE_FIELD_NUMBER: _ClassVar[int]
    WIDTH_FIELD_NUMBER: _ClassVar[int]
    HEIGHT_FIELD_NUMBER: _ClassVar[int]
    horizontal_fov: float
    vertical_fov: float
    near_range: float
    far_range: float
    width: int
    height: int
    def __init__(self, horizontal_fov: _Optional[float] = ..., vertical_fov: _Optional[float] = ..., near_range: _Optional[float] = ..., far_range: _Optional[float] = ..., width: _Optional[int] = ..., height: _Optional[int] = ...) -> None: ...

class UtilityWeights(_message.Message):
    __slots__ = ("information_gain", "distance", "rotation")
    INFORMATION_GAIN_FIELD_NUMBER: _ClassVar[int]
    DISTANCE_FIELD_NUMBER: _ClassVar[int]
    ROTATION_FIELD_NUMBER: _ClassVar[int]
    information_gain: float
    distance: float
    rotation: float
    def __init__(self, information_gain: _Optional[float] = ..., distance: _Optional[float] = ..., rotation: _Optional[float] = ...) -> None: ...

class BoundingBox(_message.Message):
    __slots__ = ("min", "max")
    MIN_FIELD_NUMBER: _ClassVar[int]
    MAX_FIELD_NUMBER: _ClassVar[int]
    min: _common_pb2.Vec3
    max: _common_pb2.Vec3
    def __init__(self, min: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., max: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ...) -> None: ...

class ViewFailure(_message.Message):
    __slots__ = ("position", "count")
    POSITION_FIELD_NUMBER: _ClassVar[int]
    COUNT_FIELD_NUMBER: _ClassVar[int]
    position: _common_pb2.Vec3
    count: int
    def __init__(self, position: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., count: _Optional[int] = ...) -> None: ...

class NbvOptions(_message.Message):
    __slots__ = ("region", "frontier_unknown_ratio", "max_frontier_candidates", "field_radius", "standoff", "reach", "position_threshold", "orientation_threshold", "gain_threshold", "gain", "ray_fraction", "weights", "adaptive_weights", "ik_check", "count_failures", "failure_penalty", "prior_failures", "max_results", "time_budget", "seed", "free_viewpoint", "gain_in_region", "visibility")
    REGION_FIELD_NUMBER: _ClassVar[int]
    FRONTIER_UNKNOWN_RATIO_FIELD_NUMBER: _ClassVar[int]
    MAX_FRONTIER_CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    FIELD_RADIUS_FIELD_NUMBER: _ClassVar[int]
    STANDOFF_FIELD_NUMBER: _ClassVar[int]
    REACH_FIELD_NUMBER: _ClassVar[int]
    POSITION_THRESHOLD_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_THRESHOLD_FIELD_NUMBER: _ClassVar[int]
    GAIN_THRESHOLD_FIELD_NUMBER: _ClassVar[int]
    GAIN_FIELD_NUMBER: _ClassVar[int]
    RAY_FRACTION_FIELD_NUMBER: _ClassVar[int]
    WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    ADAPTIVE_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    IK_CHECK_FIELD_NUMBER: _ClassVar[int]
    COUNT_FAILURES_FIELD_NUMBER: _ClassVar[int]
    FAILURE_PENALTY_FIELD_NUMBER: _ClassVar[int]
    PRIOR_FAILURES_FIELD_NUMBER: _ClassVar[int]
    MAX_RESULTS_FIELD_NUMBER: _ClassVar[int]
    TIME_BUDGET_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    FREE_VIEWPOINT_FIELD_NUMBER: _ClassVar[int]
    GAIN_IN_REGION_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_FIELD_NUMBER: _ClassVar[int]
    region: BoundingBox
    frontier_unknown_ratio: float
    max_frontier_candidates: int
    field_radius: float
    standoff: float
    reach: float
    position_threshold: float
    orientation_threshold: float
    gain_threshold: float
    gain: GainMethod
    ray_fraction: float
    weights: UtilityWeights
    adaptive_weights: bool
    ik_check: int
    count_failures: bool
    failure_penalty: float
    prior_failures: _containers.RepeatedCompositeFieldContainer[ViewFailure]
    max_results: int
    time_budget: float
    seed: int
    free_viewpoint: bool
    gain_in_region: bool
    visibility: VisibilityCheck
    def __init__(self, region: _Optional[_Union[BoundingBox, _Mapping]] = ..., frontier_unknown_ratio: _Optional[float] = ..., max_frontier_candidates: _Optional[int] = ..., field_radius: _Optional[float] = ..., standoff: _Optional[float] = ..., reach: _Optional[float] = ..., position_threshold: _Optional[float] = ..., orientation_threshold: _Optional[float] = ..., gain_threshold: _Optional[float] = ..., gain: _Optional[_Union[GainMethod, str]] = ..., ray_fraction: _Optional[float] = ..., weights: _Optional[_Union[UtilityWeights, _Mapping]] = ..., adaptive_weights: _Optional[bool] = ..., ik_check: _Optional[int] = ..., count_failures: _Optional[bool] = ..., failure_penalty: _Optional[float] = ..., prior_failures: _Optional[_Iterable[_Union[ViewFailure, _Mapping]]] = ..., max_results: _Optional[int] = ..., time_budget: _Optional[float] = ..., seed: _Optional[int] = ..., free_viewpoint: _Optional[bool] = ..., gain_in_region: _Optional[bool] = ..., visibility: _Optional[_Union[VisibilityCheck, _Mapping]] = ...) -> None: ...

class VisibilityCheck(_message.Message):
    __slots__ = ("batch", "pixel_stride", "lookahead", "min_new_cells")
    BATCH_FIELD_NUMBER: _ClassVar[int]
    PIXEL_STRIDE_FIELD_NUMBER: _ClassVar[int]
    LOOKAHEAD_FIELD_NUMBER: _ClassVar[int]
    MIN_NEW_CELLS_FIELD_NUMBER: _ClassVar[int]
    batch: int
    pixel_stride: int
    lookahead: int
    min_new_cells: int
    def __init__(self, batch: _Optional[int] = ..., pixel_stride: _Optional[int] = ..., lookahead: _Optional[int] = ..., min_new_cells: _Optional[int] = ...) -> None: ...

class NextBestViewRequest(_message.Message):
    __slots__ = ("octree", "camera", "camera_pose", "robot", "robot_base", "camera_mount", "candidate_poses", "options")
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    CAMERA_FIELD_NUMBER: _ClassVar[int]
    CAMERA_POSE_FIELD_NUMBER: _ClassVar[int]
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    ROBOT_BASE_FIELD_NUMBER: _ClassVar[int]
    CAMERA_MOUNT_FIELD_NUMBER: _ClassVar[int]
    CANDIDATE_POSES_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    octree: _common_pb2.Octree
    camera: CameraModel
    camera_pose: _common_pb2.Pose
    robot: _common_pb2.RobotRef
    robot_base: _common_pb2.Pose
    camera_mount: _common_pb2.Pose
    candidate_poses: _containers.RepeatedCompositeFieldContainer[_common_pb2.Pose]
    options: NbvOptions
    def __init__(self, octree: _Optional[_Union[_common_pb2.Octree, _Mapping]] = ..., camera: _Optional[_Union[CameraModel, _Mapping]] = ..., camera_pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., robot_base: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., camera_mount: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., candidate_poses: _Optional[_Iterable[_Union[_common_pb2.Pose, _Mapping]]] = ..., options: _Optional[_Union[NbvOptions, _Mapping]] = ...) -> None: ...

class ViewCandidate(_message.Message):
    __slots__ = ("pose", "frontier", "distance_score", "rotation_score", "information_gain", "unknown_cells", "utility", "reachability", "joints", "failures", "predicted_cells", "predicted_reached")
    POSE_FIELD_NUMBER: _ClassVar[int]
    FRONTIER_FIELD_NUMBER: _ClassVar[int]
    DISTANCE_SCORE_FIELD_NUMBER: _ClassVar[int]
    ROTATION_SCORE_FIELD_NUMBER: _ClassVar[int]
    INFORMATION_GAIN_FIELD_NUMBER: _ClassVar[int]
    UNKNOWN_CELLS_FIELD_NUMBER: _ClassVar[int]
    UTILITY_FIELD_NUMBER: _ClassVar[int]
    REACHABILITY_FIELD_NUMBER: _ClassVar[int]
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    FAILURES_FIELD_NUMBER: _ClassVar[int]
    PREDICTED_CELLS_FIELD_NUMBER: _ClassVar[int]
    PREDICTED_REACHED_FIELD_NUMBER: _ClassVar[int]
    pose: _common_pb2.Pose
    frontier: _common_pb2.Vec3
    distance_score: float
    rotation_score: float
    information_gain: float
    unknown_cells: float
    utility: float
    reachability: Reachability
    joints: _containers.RepeatedScalarFieldContainer[float]
    failures: int
    predicted_cells: int
    predicted_reached: int
    def __init__(self, pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., frontier: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., distance_score: _Optional[float] = ..., rotation_score: _Optional[float] = ..., information_gain: _Optional[float] = ..., unknown_cells: _Optional[float] = ..., utility: _Optional[float] = ..., reachability: _Optional[_Union[Reachability, str]] = ..., joints: _Optional[_Iterable[float]] = ..., failures: _Optional[int] = ..., predicted_cells: _Optional[int] = ..., predicted_reached: _Optional[int] = ...) -> None: ...

class NbvStages(_message.Message):
    __slots__ = ("frontier_cells", "frontier_candidates", "caller_candidates", "after_orf", "after_ptf", "after_igf", "ik_checked", "ik_failed", "frontier_time", "field_time", "orf_time", "ptf_time", "igf_time", "ik_time", "ray_steps", "visibility_checked", "visibility_dropped", "after_visibility", "best_predicted_cells", "visibility_time")
    FRONTIER_CELLS_FIELD_NUMBER: _ClassVar[int]
    FRONTIER_CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    CALLER_CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    AFTER_ORF_FIELD_NUMBER: _ClassVar[int]
    AFTER_PTF_FIELD_NUMBER: _ClassVar[int]
    AFTER_IGF_FIELD_NUMBER: _ClassVar[int]
    IK_CHECKED_FIELD_NUMBER: _ClassVar[int]
    IK_FAILED_FIELD_NUMBER: _ClassVar[int]
    FRONTIER_TIME_FIELD_NUMBER: _ClassVar[int]
    FIELD_TIME_FIELD_NUMBER: _ClassVar[int]
    ORF_TIME_FIELD_NUMBER: _ClassVar[int]
    PTF_TIME_FIELD_NUMBER: _ClassVar[int]
    IGF_TIME_FIELD_NUMBER: _ClassVar[int]
    IK_TIME_FIELD_NUMBER: _ClassVar[int]
    RAY_STEPS_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_CHECKED_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_DROPPED_FIELD_NUMBER: _ClassVar[int]
    AFTER_VISIBILITY_FIELD_NUMBER: _ClassVar[int]
    BEST_PREDICTED_CELLS_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_TIME_FIELD_NUMBER: _ClassVar[int]
    frontier_cells: int
    frontier_candidates: int
    caller_candidates: int
    after_orf: int
    after_ptf: int
    after_igf: int
    ik_checked: int
    ik_failed: int
    frontier_time: float
    field_time: float
    orf_time: float
    ptf_time: float
    igf_time: float
    ik_time: float
    ray_steps: int
    visibility_checked: int
    visibility_dropped: int
    after_visibility: int
    best_predicted_cells: int
    visibility_time: float
    def __init__(self, frontier_cells: _Optional[int] = ..., frontier_candidates: _Optional[int] = ..., caller_candidates: _Optional[int] = ..., after_orf: _Optional[int] = ..., after_ptf: _Optional[int] = ..., after_igf: _Optional[int] = ..., ik_checked: _Optional[int] = ..., ik_failed: _Optional[int] = ..., frontier_time: _Optional[float] = ..., field_time: _Optional[float] = ..., orf_time: _Optional[float] = ..., ptf_time: _Optional[float] = ..., igf_time: _Optional[float] = ..., ik_time: _Optional[float] = ..., ray_steps: _Optional[int] = ..., visibility_checked: _Optional[int] = ..., visibility_dropped: _Optional[int] = ..., after_visibility: _Optional[int] = ..., best_predicted_cells: _Optional[int] = ..., visibility_time: _Optional[float] = ...) -> None: ...

class NextBestViewResponse(_message.Message):
    __slots__ = ("candidates", "stages", "status", "weights", "reach", "elapsed")
    CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    STAGES_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    REACH_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_FIELD_NUMBER: _ClassVar[int]
    candidates: _containers.RepeatedCompositeFieldContainer[ViewCandidate]
    stages: NbvStages
    status: NbvStatus
    weights: UtilityWeights
    reach: float
    elapsed: float
    def __init__(self, candidates: _Optional[_Iterable[_Union[ViewCandidate, _Mapping]]] = ..., stages: _Optional[_Union[NbvStages, _Mapping]] = ..., status: _Optional[_Union[NbvStatus, str]] = ..., weights: _Optional[_Union[UtilityWeights, _Mapping]] = ..., reach: _Optional[float] = ..., elapsed: _Optional[float] = ...) -> None: ...

class DepthImage(_message.Message):
    __slots__ = ("width", "height", "depth", "fx", "fy", "cx", "cy", "depth_mm", "camera")
    WIDTH_FIELD_NUMBER: _ClassVar[int]
    HEIGHT_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    FX_FIELD_NUMBER: _ClassVar[int]
    FY_FIELD_NUMBER: _ClassVar[int]
    CX_FIELD_NUMBER: _ClassVar[int]
    CY_FIELD_NUMBER: _ClassVar[int]
    DEPTH_MM_FIELD_NUMBER: _ClassVar[int]
    CAMERA_FIELD_NUMBER: _ClassVar[int]
    width: int
    height: int
    depth: _containers.RepeatedScalarFieldContainer[float]
    fx: float
    fy: float
    cx: float
    cy: float
    depth_mm: bytes
    camera: CameraModel
    def __init__(self, width: _Optional[int] = ..., height: _Optional[int] = ..., depth: _Optional[_Iterable[float]] = ..., fx: _Optional[float] = ..., fy: _Optional[float] = ..., cx: _Optional[float] = ..., cy: _Optional[float] = ..., depth_mm: _Optional[bytes] = ..., camera: _Optional[_Union[CameraModel, _Mapping]] = ...) -> None: ...

class InsertScanRequest(_message.Message):
    __slots__ = ("octree", "resolution", "sensor_pose", "points", "depth_image", "max_range", "discretize", "full", "near_ray_spacing")
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    SENSOR_POSE_FIELD_NUMBER: _ClassVar[int]
    POINTS_FIELD_NUMBER: _ClassVar[int]
    DEPTH_IMAGE_FIELD_NUMBER: _ClassVar[int]
    MAX_RANGE_FIELD_NUMBER: _ClassVar[int]
    DISCRETIZE_FIELD_NUMBER: _ClassVar[int]
    FULL_FIELD_NUMBER: _ClassVar[int]
    NEAR_RAY_SPACING_FIELD_NUMBER: _ClassVar[int]
    octree: _common_pb2.Octree
    resolution: float
    sensor_pose: _common_pb2.Pose
    points: PointCloud
    depth_image: DepthImage
    max_range: float
    discretize: bool
    full: bool
    near_ray_spacing: float
    def __init__(self, octree: _Optional[_Union[_common_pb2.Octree, _Mapping]] = ..., resolution: _Optional[float] = ..., sensor_pose: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., points: _Optional[_Union[PointCloud, _Mapping]] = ..., depth_image: _Optional[_Union[DepthImage, _Mapping]] = ..., max_range: _Optional[float] = ..., discretize: _Optional[bool] = ..., full: _Optional[bool] = ..., near_ray_spacing: _Optional[float] = ...) -> None: ...

class PointCloud(_message.Message):
    __slots__ = ("xyz",)
    XYZ_FIELD_NUMBER: _ClassVar[int]
    xyz: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, xyz: _Optional[_Iterable[float]] = ...) -> None: ...

class InsertScanResponse(_message.Message):
    __slots__ = ("octree", "free_cells", "occupied_cells", "skipped_points", "stats")
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    FREE_CELLS_FIELD_NUMBER: _ClassVar[int]
    OCCUPIED_CELLS_FIELD_NUMBER: _ClassVar[int]
    SKIPPED_POINTS_FIELD_NUMBER: _ClassVar[int]
    STATS_FIELD_NUMBER: _ClassVar[int]
    octree: _common_pb2.Octree
    free_cells: int
    occupied_cells: int
    skipped_points: int
    stats: OctreeStats
    def __init__(self, octree: _Optional[_Union[_common_pb2.Octree, _Mapping]] = ..., free_cells: _Optional[int] = ..., occupied_cells: _Optional[int] = ..., skipped_points: _Optional[int] = ..., stats: _Optional[_Union[OctreeStats, _Mapping]] = ...) -> None: ...

class OctreeInfoRequest(_message.Message):
    __slots__ = ("octree", "box")
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    BOX_FIELD_NUMBER: _ClassVar[int]
    octree: _common_pb2.Octree
    box: BoundingBox
    def __init__(self, octree: _Optional[_Union[_common_pb2.Octree, _Mapping]] = ..., box: _Optional[_Union[BoundingBox, _Mapping]] = ...) -> None: ...

class OctreeStats(_message.Message):
    __slots__ = ("resolution", "nodes", "leaves", "occupied_leaves", "free_leaves", "bounds")
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    NODES_FIELD_NUMBER: _ClassVar[int]
    LEAVES_FIELD_NUMBER: _ClassVar[int]
    OCCUPIED_LEAVES_FIELD_NUMBER: _ClassVar[int]
    FREE_LEAVES_FIELD_NUMBER: _ClassVar[int]
    BOUNDS_FIELD_NUMBER: _ClassVar[int]
    resolution: float
    nodes: int
    leaves: int
    occupied_leaves: int
    free_leaves: int
    bounds: BoundingBox
    def __init__(self, resolution: _Optional[float] = ..., nodes: _Optional[int] = ..., leaves: _Optional[int] = ..., occupied_leaves: _Optional[int] = ..., free_leaves: _Optional[int] = ..., bounds: _Optional[_Union[BoundingBox, _Mapping]] = ...) -> None: ...

class OctreeInfoResponse(_message.Message):
    __slots__ = ("stats", "occupied_volume", "free_volume", "unknown_volume")
    STATS_FIELD_NUMBER: _ClassVar[int]
    OCCUPIED_VOLUME_FIELD_NUMBER: _ClassVar[int]
    FREE_VOLUME_FIELD_NUMBER: _ClassVar[int]
    UNKNOWN_VOLUME_FIELD_NUMBER: _ClassVar[int]
    stats: OctreeStats
    occupied_volume: float
    free_volume: float
    unknown_volume: float
    def __init__(self, stats: _Optional[_Union[OctreeStats, _Mapping]] = ..., occupied_volume: _Optional[float] = ..., free_volume: _Optional[float] = ..., unknown_volume: _Optional[float] = ...) -> None: ...

class ExploreStopRule(_message.Message):
    __slots__ = ("known_ratio", "max_iterations", "max_consecutive_failures")
    KNOWN_RATIO_FIELD_NUMBER: _ClassVar[int]
    MAX_ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    MAX_CONSECUTIVE_FAILURES_FIELD_NUMBER: _ClassVar[int]
    known_ratio: float
    max_iterations: int
    max_consecutive_failures: int
    def __init__(self, known_ratio: _Optional[float] = ..., max_iterations: _Optional[int] = ..., max_consecutive_failures: _Optional[int] = ...) -> None: ...

class ExploreRequest(_message.Message):
    __slots__ = ("robot", "start", "scene", "region", "camera", "camera_mount", "nbv", "algorithm", "plan_options", "stop", "resolution", "pixel_stride", "noise_stddev", "near_ray_spacing", "candidates_per_iteration", "plan_time_budget", "initial_offsets", "no_initial_offsets", "extra_views", "no_extra_views", "seed", "time_budget", "visibility", "no_visibility_check", "camera_link")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    SCENE_FIELD_NUMBER: _ClassVar[int]
    REGION_FIELD_NUMBER: _ClassVar[int]
    CAMERA_FIELD_NUMBER: _ClassVar[int]
    CAMERA_MOUNT_FIELD_NUMBER: _ClassVar[int]
    NBV_FIELD_NUMBER: _ClassVar[int]
    ALGORITHM_FIELD_NUMBER: _ClassVar[int]
    PLAN_OPTIONS_FIELD_NUMBER: _ClassVar[int]
    STOP_FIELD_NUMBER: _ClassVar[int]
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    PIXEL_STRIDE_FIELD_NUMBER: _ClassVar[int]
    NOISE_STDDEV_FIELD_NUMBER: _ClassVar[int]
    NEAR_RAY_SPACING_FIELD_NUMBER: _ClassVar[int]
    CANDIDATES_PER_ITERATION_FIELD_NUMBER: _ClassVar[int]
    PLAN_TIME_BUDGET_FIELD_NUMBER: _ClassVar[int]
    INITIAL_OFFSETS_FIELD_NUMBER: _ClassVar[int]
    NO_INITIAL_OFFSETS_FIELD_NUMBER: _ClassVar[int]
    EXTRA_VIEWS_FIELD_NUMBER: _ClassVar[int]
    NO_EXTRA_VIEWS_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    TIME_BUDGET_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_FIELD_NUMBER: _ClassVar[int]
    NO_VISIBILITY_CHECK_FIELD_NUMBER: _ClassVar[int]
    CAMERA_LINK_FIELD_NUMBER: _ClassVar[int]
    robot: _common_pb2.RobotRef
    start: _containers.RepeatedScalarFieldContainer[float]
    scene: _common_pb2.Scene
    region: BoundingBox
    camera: CameraModel
    camera_mount: _common_pb2.Pose
    nbv: NbvOptions
    algorithm: _planning_pb2.PlanAlgorithm
    plan_options: _planning_pb2.PlanOptions
    stop: ExploreStopRule
    resolution: float
    pixel_stride: int
    noise_stddev: float
    near_ray_spacing: float
    candidates_per_iteration: int
    plan_time_budget: float
    initial_offsets: _common_pb2.Matrix
    no_initial_offsets: bool
    extra_views: _containers.RepeatedCompositeFieldContainer[_common_pb2.Pose]
    no_extra_views: bool
    seed: int
    time_budget: float
    visibility: VisibilityCheck
    no_visibility_check: bool
    camera_link: str
    def __init__(self, robot: _Optional[_Union[_common_pb2.RobotRef, _Mapping]] = ..., start: _Optional[_Iterable[float]] = ..., scene: _Optional[_Union[_common_pb2.Scene, _Mapping]] = ..., region: _Optional[_Union[BoundingBox, _Mapping]] = ..., camera: _Optional[_Union[CameraModel, _Mapping]] = ..., camera_mount: _Optional[_Union[_common_pb2.Pose, _Mapping]] = ..., nbv: _Optional[_Union[NbvOptions, _Mapping]] = ..., algorithm: _Optional[_Union[_planning_pb2.PlanAlgorithm, str]] = ..., plan_options: _Optional[_Union[_planning_pb2.PlanOptions, _Mapping]] = ..., stop: _Optional[_Union[ExploreStopRule, _Mapping]] = ..., resolution: _Optional[float] = ..., pixel_stride: _Optional[int] = ..., noise_stddev: _Optional[float] = ..., near_ray_spacing: _Optional[float] = ..., candidates_per_iteration: _Optional[int] = ..., plan_time_budget: _Optional[float] = ..., initial_offsets: _Optional[_Union[_common_pb2.Matrix, _Mapping]] = ..., no_initial_offsets: _Optional[bool] = ..., extra_views: _Optional[_Iterable[_Union[_common_pb2.Pose, _Mapping]]] = ..., no_extra_views: _Optional[bool] = ..., seed: _Optional[int] = ..., time_budget: _Optional[float] = ..., visibility: _Optional[_Union[VisibilityCheck, _Mapping]] = ..., no_visibility_check: _Optional[bool] = ..., camera_link: _Optional[str] = ...) -> None: ...

class FailedView(_message.Message):
    __slots__ = ("position", "reason")
    POSITION_FIELD_NUMBER: _ClassVar[int]
    REASON_FIELD_NUMBER: _ClassVar[int]
    position: _common_pb2.Vec3
    reason: str
    def __init__(self, position: _Optional[_Union[_common_pb2.Vec3, _Mapping]] = ..., reason: _Optional[str] = ...) -> None: ...

class ExploreTimes(_message.Message):
    __slots__ = ("nbv", "plan", "sense", "insert", "total")
    NBV_FIELD_NUMBER: _ClassVar[int]
    PLAN_FIELD_NUMBER: _ClassVar[int]
    SENSE_FIELD_NUMBER: _ClassVar[int]
    INSERT_FIELD_NUMBER: _ClassVar[int]
    TOTAL_FIELD_NUMBER: _ClassVar[int]
    nbv: float
    plan: float
    sense: float
    insert: float
    total: float
    def __init__(self, nbv: _Optional[float] = ..., plan: _Optional[float] = ..., sense: _Optional[float] = ..., insert: _Optional[float] = ..., total: _Optional[float] = ...) -> None: ...

class ExploreIteration(_message.Message):
    __slots__ = ("iteration", "view", "view_rank", "trajectory", "criteria", "hits_scene", "failures", "candidates", "known_ratio", "joints", "times")
    class CriteriaEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    ITERATION_FIELD_NUMBER: _ClassVar[int]
    VIEW_FIELD_NUMBER: _ClassVar[int]
    VIEW_RANK_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORY_FIELD_NUMBER: _ClassVar[int]
    CRITERIA_FIELD_NUMBER: _ClassVar[int]
    HITS_SCENE_FIELD_NUMBER: _ClassVar[int]
    FAILURES_FIELD_NUMBER: _ClassVar[int]
    CANDIDATES_FIELD_NUMBER: _ClassVar[int]
    KNOWN_RATIO_FIELD_NUMBER: _ClassVar[int]
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    TIMES_FIELD_NUMBER: _ClassVar[int]
    iteration: int
    view: ViewCandidate
    view_rank: int
    trajectory: _common_pb2.JointTrajectory
    criteria: _containers.ScalarMap[str, float]
    hits_scene: bool
    failures: _containers.RepeatedCompositeFieldContainer[FailedView]
    candidates: int
    known_ratio: float
    joints: _containers.RepeatedScalarFieldContainer[float]
    times: ExploreTimes
    def __init__(self, iteration: _Optional[int] = ..., view: _Optional[_Union[ViewCandidate, _Mapping]] = ..., view_rank: _Optional[int] = ..., trajectory: _Optional[_Union[_common_pb2.JointTrajectory, _Mapping]] = ..., criteria: _Optional[_Mapping[str, float]] = ..., hits_scene: _Optional[bool] = ..., failures: _Optional[_Iterable[_Union[FailedView, _Mapping]]] = ..., candidates: _Optional[int] = ..., known_ratio: _Optional[float] = ..., joints: _Optional[_Iterable[float]] = ..., times: _Optional[_Union[ExploreTimes, _Mapping]] = ...) -> None: ...

class ExploreTotals(_message.Message):
    __slots__ = ("jd", "cpc", "cd", "oc", "rdm", "trajectories")
    JD_FIELD_NUMBER: _ClassVar[int]
    CPC_FIELD_NUMBER: _ClassVar[int]
    CD_FIELD_NUMBER: _ClassVar[int]
    OC_FIELD_NUMBER: _ClassVar[int]
    RDM_FIELD_NUMBER: _ClassVar[int]
    TRAJECTORIES_FIELD_NUMBER: _ClassVar[int]
    jd: float
    cpc: float
    cd: float
    oc: float
    rdm: float
    trajectories: int
    def __init__(self, jd: _Optional[float] = ..., cpc: _Optional[float] = ..., cd: _Optional[float] = ..., oc: _Optional[float] = ..., rdm: _Optional[float] = ..., trajectories: _Optional[int] = ...) -> None: ...

class ExploreSummary(_message.Message):
    __slots__ = ("status", "iterations", "initial_known_ratio", "known_ratio", "observable_cells", "totals", "failures", "scene_hits", "final_joints", "octree", "scans", "elapsed", "wasted_moves", "best_predicted_cells")
    STATUS_FIELD_NUMBER: _ClassVar[int]
    ITERATIONS_FIELD_NUMBER: _ClassVar[int]
    INITIAL_KNOWN_RATIO_FIELD_NUMBER: _ClassVar[int]
    KNOWN_RATIO_FIELD_NUMBER: _ClassVar[int]
    OBSERVABLE_CELLS_FIELD_NUMBER: _ClassVar[int]
    TOTALS_FIELD_NUMBER: _ClassVar[int]
    FAILURES_FIELD_NUMBER: _ClassVar[int]
    SCENE_HITS_FIELD_NUMBER: _ClassVar[int]
    FINAL_JOINTS_FIELD_NUMBER: _ClassVar[int]
    OCTREE_FIELD_NUMBER: _ClassVar[int]
    SCANS_FIELD_NUMBER: _ClassVar[int]
    ELAPSED_FIELD_NUMBER: _ClassVar[int]
    WASTED_MOVES_FIELD_NUMBER: _ClassVar[int]
    BEST_PREDICTED_CELLS_FIELD_NUMBER: _ClassVar[int]
    status: ExploreStatus
    iterations: int
    initial_known_ratio: float
    known_ratio: float
    observable_cells: int
    totals: ExploreTotals
    failures: int
    scene_hits: int
    final_joints: _containers.RepeatedScalarFieldContainer[float]
    octree: _common_pb2.Octree
    scans: int
    elapsed: float
    wasted_moves: int
    best_predicted_cells: int
    def __init__(self, status: _Optional[_Union[ExploreStatus, str]] = ..., iterations: _Optional[int] = ..., initial_known_ratio: _Optional[float] = ..., known_ratio: _Optional[float] = ..., observable_cells: _Optional[int] = ..., totals: _Optional[_Union[ExploreTotals, _Mapping]] = ..., failures: _Optional[int] = ..., scene_hits: _Optional[int] = ..., final_joints: _Optional[_Iterable[float]] = ..., octree: _Optional[_Union[_common_pb2.Octree, _Mapping]] = ..., scans: _Optional[int] = ..., elapsed: _Optional[float] = ..., wasted_moves: _Optional[int] = ..., best_predicted_cells: _Optional[int] = ...) -> None: ...

class ExploreResponse(_message.Message):
    __slots__ = ("iteration", "summary")
    ITERATION_FIELD_NUMBER: _ClassVar[int]
    SUMMARY_FIELD_NUMBER: _ClassVar[int]
    iteration: ExploreIteration
    summary: ExploreSummary
    def __init__(self, iteration: _Optional[_Union[ExploreIteration, _Mapping]] = ..., summary: _Optional[_Union[ExploreSummary, _Mapping]] = ...) -> None: ...

class ReferenceSceneRequest(_message.Message):
    __slots__ = ("name", "seed")
    NAME_FIELD_NUMBER: _ClassVar[int]
    SEED_FIELD_NUMBER: _ClassVar[int]
    name: ReferenceSceneName
    seed: int
    def __init__(self, name: _Optional[_Union[ReferenceSceneName, str]] = ..., seed: _Optional[int] = ...) -> None: ...

class ReferenceSceneResponse(_message.Message):
    __slots__ = ("robot", "scene", "region", "start")
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    SCENE_FIELD_NUMBER: _ClassVar[int]
    REGION_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    robot: str
    scene: _common_pb2.Scene
    region: BoundingBox
    start: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, robot: _Optional[str] = ..., scene: _Optional[_Union[_common_pb2.Scene, _Mapping]] = ..., region: _Optional[_Union[BoundingBox, _Mapping]] = ..., start: _Optional[_Iterable[float]] = ...) -> None: ...
