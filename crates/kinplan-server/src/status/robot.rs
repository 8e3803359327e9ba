//! `robot` room errors into statuses: unknown robots and links are NOT_FOUND,
//! bad joint values name the request's joint vector, URDF problems `robot.urdf`.

use tonic::Status;

use super::{invalid, not_found};
use kinplan_core::robot::RobotError;

/// Maps a robot-model error; `joints_field` names the joint vector in the
/// request, for errors about joint values.
pub fn robot_error(err: RobotError, joints_field: &str) -> Status {
    let text = err.to_string();
    match err {
        RobotError::UnknownRobot { .. } => not_found("robot.name", text),
        RobotError::UnknownLink { .. } => not_found("robot.base_link/tip_link", text),
        RobotError::AmbiguousTip { .. } | RobotError::NotSerialChain { .. } => {
            invalid("robot.tip_link", text)
        }
        RobotError::WrongJointCount { .. } => invalid(joints_field, text),
        RobotError::NonFiniteJoint { index } | RobotError::JointOutOfRange { index, .. } => {
            invalid(format!("{joints_field}[{index}]"), text)
        }
        RobotError::MalformedUrdf(_)
        | RobotError::UrdfTooLarge { .. }
        | RobotError::TooManyElements { .. }
        | RobotError::NonFiniteValue { .. }
        | RobotError::ValueOutOfRange { .. }
        | RobotError::NoSingleRoot { .. }
        | RobotError::UnsupportedJoint { .. }
        | RobotError::ZeroAxis { .. }
        | RobotError::InvertedLimits { .. } => invalid("robot.urdf", text),
        RobotError::MalformedSrdf(_) => invalid("robot.srdf", text),
    }
}
