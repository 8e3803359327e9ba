//! Errors raised while building a robot collision model or a scene.

/// Everything that can be wrong with the input of the collision room.
///
/// Variants name the offending field as a path (`obstacles[3].indices[5]`)
/// and carry the numbers a caller needs to fix the input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CollisionError {
    #[error("{field} is not finite")]
    NonFinite { field: String },
    #[error("{field} must be positive, got {value}")]
    NotPositive { field: String, value: f64 },
    #[error("{field} is {value}, outside the limit {limit}")]
    TooLarge { field: String, value: f64, limit: f64 },
    #[error("{field} = {index} is out of range: the mesh has {vertex_count} vertices")]
    IndexOutOfRange {
        field: String,
        index: u32,
        vertex_count: usize,
    },
    #[error("{field} is degenerate: {reason}")]
    Degenerate { field: String, reason: String },
    #[error("{field} has {count} elements, more than the limit of {limit}")]
    TooMany {
        field: String,
        count: usize,
        limit: usize,
    },
    #[error("{field} must not be empty")]
    Empty { field: String },
    #[error("{field}: the robot has {count} collision bodies, more than the limit of {limit}")]
    TooManyBodies {
        field: String,
        count: usize,
        limit: usize,
    },
    #[error(
        "{field}: mesh file `{filename}` was not sent with the model; send its bytes keyed by that URI (RobotRef.meshes)"
    )]
    MeshNotInline { field: String, filename: String },
    #[error("{field}: unknown name `{name}`")]
    UnknownName { field: String, name: String },
    #[error("{field}: could not parse: {reason}")]
    Parse { field: String, reason: String },
    #[error(
        "motions of this robot cannot be padded: a prismatic joint without limits after a revolute one \
         can move its links arbitrarily far"
    )]
    CannotPad,
    #[error("{what} stopped before it finished: {}", match stop {
        crate::Stop::Deadline => "the deadline passed",
        crate::Stop::Cancelled => "the call was cancelled",
    })]
    Stopped { what: String, stop: crate::Stop },
    #[error("{field} = {value} is outside [{lower}, {upper}]")]
    OutOfRange {
        field: String,
        value: f64,
        lower: f64,
        upper: f64,
    },
}
