//! Every domain error turned into `tonic::Status`, with `google.rpc.BadRequest`
//! details naming the offending field: the generic constructors here, one
//! submodule per domain room. Only this module turns domain field identifiers
//! into proto field paths.

use tonic::{Code, Status};
use tonic_types::{ErrorDetails, StatusExt};

use kinplan_core::robot::RobotError;

pub mod collision;
pub mod explore;
pub mod ik;
pub mod linalg;
pub mod nbv;
pub mod octree;
pub mod plan;
pub mod score;

/// INVALID_ARGUMENT naming `field`, with a BadRequest field violation.
pub fn invalid(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::InvalidArgument, field, description)
}

/// RESOURCE_EXHAUSTED naming `field`: a request that cannot fit the server's
/// limits, refused before any work.
pub fn too_large(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::ResourceExhausted, field, description)
}

/// NOT_FOUND naming `field`, with a BadRequest field violation.
pub fn not_found(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::NotFound, field, description)
}

/// Longest description a status carries: values echoed from a request are
/// clipped so a reply never outgrows the client's metadata limit.
pub const MAX_DESCRIPTION_CHARS: usize = 256;

/// At most `max` characters of `text`, with `…` when clipped.
pub fn clip(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

fn field_status(code: Code, field: impl Into<String>, description: impl Into<String>) -> Status {
    let field = clip(&field.into(), 64);
    let description = clip(&description.into(), MAX_DESCRIPTION_CHARS);
    let message = format!("{field}: {description}");
    Status::with_error_details(
        code,
        message,
        ErrorDetails::with_bad_request_violation(field, description),
    )
}

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
    }
}

/// The canonical upper-case name of a gRPC status code, as metrics label it.
pub fn code_name(code: i32) -> &'static str {
    const NAMES: [&str; 17] = [
        "OK",
        "CANCELLED",
        "UNKNOWN",
        "INVALID_ARGUMENT",
        "DEADLINE_EXCEEDED",
        "NOT_FOUND",
        "ALREADY_EXISTS",
        "PERMISSION_DENIED",
        "RESOURCE_EXHAUSTED",
        "FAILED_PRECONDITION",
        "ABORTED",
        "OUT_OF_RANGE",
        "UNIMPLEMENTED",
        "INTERNAL",
        "UNAVAILABLE",
        "DATA_LOSS",
        "UNAUTHENTICATED",
    ];
    usize::try_from(code)
        .ok()
        .and_then(|i| NAMES.get(i))
        .copied()
        .unwrap_or("UNKNOWN")
}
