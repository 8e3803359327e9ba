"""kinplan: Python client for the kinplan motion-planning service.

>>> import kinplan
>>> with kinplan.Client("127.0.0.1:50051") as c:          # doctest: +SKIP
...     T = c.robot("ur5").fk([0, -1.57, 1.57, 0, 0, 0])
"""
from ._convert import matrix_to_pose, pose_to_matrix
from .client import Client
from .description import RobotDescription
from .errors import (
    Cancelled,
    DeadlineExceeded,
    Internal,
    InvalidArgument,
    JointLimitWarning,
    KinplanError,
    NotFound,
    ResourceExhausted,
    Unavailable,
)
from .local_server import LocalServer
from .octree import Octree, Views
from . import scenes
from .exploration_loop import ExploreStep, ExploreSummary, ReferenceScene
from .kinematics import ConfigFlags, IkBatchResult, IkOptions, IkResult, IkSolution, LinearSolution, TrackResult
from .robot import IkStream, Robot
from .mobile import Mobile, MobileRun, StepResult, WheelKinematics
from .planning import Box, Capsule, Cylinder, Mesh, OctreeObstacle, Plan, Sphere, StateChecks, TimedTrajectory
from .scoring import Comparison, Scores

__all__ = [
    "Box",
    "Capsule",
    "Client",
    "Cylinder",
    "JointLimitWarning",
    "Mesh",
    "ExploreStep",
    "ExploreSummary",
    "Octree",
    "ReferenceScene",
    "OctreeObstacle",
    "Plan",
    "Sphere",
    "StateChecks",
    "TimedTrajectory",
    "Comparison",
    "IkBatchResult",
    "IkOptions",
    "IkResult",
    "ConfigFlags",
    "IkSolution",
    "IkStream",
    "Cancelled",
    "DeadlineExceeded",
    "Internal",
    "InvalidArgument",
    "KinplanError",
    "LocalServer",
    "NotFound",
    "ResourceExhausted",
    "Unavailable",
    "LinearSolution",
    "Mobile",
    "MobileRun",
    "Robot",
    "RobotDescription",
    "Scores",
    "StepResult",
    "TrackResult",
    "Views",
    "WheelKinematics",
    "matrix_to_pose",
    "pose_to_matrix",
]
__version__ = "0.1.0"
