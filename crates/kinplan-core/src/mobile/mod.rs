//! Mobile robots (docs/mobile.md, source S1): chassis kinematics, pose controllers, vector-distance
//! local navigation, a grid A* global planner and a simulator with collision detection.

mod angle;
mod chassis;
mod control_step;
mod error;
mod field;
mod goal_seeking;
mod grid_astar;
mod lyapunov;
mod path_follow;
mod pose;
mod pure_pursuit;
mod sensors;
mod shortest_path;
mod simulate;
mod token;
mod vector_distance;
mod wheel_kinematics;
mod world;

pub use angle::{sinc, wrap_angle};
pub use chassis::{
    CarParams, Chassis, ChassisStep, DifferentialParams, OmniParams, Saturation, TricycleParams,
};
pub use control_step::{ControlStep, StepController, StepOptions, StepReport, control_step};
pub use error::{MAX_DIMENSION, MIN_DIMENSION, MobileError};
pub use field::{
    AstarField, ChassisKind, ChassisParam, Component, FollowField, FollowParam, LyapunovParam, MobileField,
    ObstaclePart, PurePursuitParam, SensorField, SimField, SteeringParam, VdfField, WheelField,
};
pub use goal_seeking::{SteeringCommand, SteeringParams, goal_seeking_finished, goal_seeking_step};
pub use grid_astar::{GridAstarParams, plan_grid_astar, plan_grid_astar_until};
pub use lyapunov::{LyapunovCommand, LyapunovParams, lyapunov_step, lyapunov_value};
pub use path_follow::{
    ControllerKind, PathFollowParams, PathFollowState, PathFollowStep, PathNode, path_follow_step,
    validate_path,
};
pub use pose::{MAX_COORDINATE, MAX_RATE, Point2, Pose, Twist, integrate_twist};
pub use pure_pursuit::{PurePursuitCommand, PurePursuitParams, pure_pursuit_step};
pub use sensors::{RangeSensorParams, RangeSensors};
pub use shortest_path::shortest_path_step;
pub use simulate::{
    GRID_PATH_CONTROLLER, NavigateParams, Outcome, RunMetrics, SimParams, SimRun, follow_path, navigate,
    navigate_astar,
};
pub use token::{ControllerMemory, decode_token, encode_token};
pub use vector_distance::{
    MAX_TOKEN_STEPS, NavMode, NoPathReason, TurnPreference, TurnSide, VdfEvent, VdfOutput, VdfParams,
    VdfState, vdf_step,
};
pub use wheel_kinematics::WheelState;
pub use world::{Obstacle, World};
