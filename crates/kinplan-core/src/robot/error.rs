//! Errors raised while building or evaluating a robot model.

/// Everything that can be wrong with a robot model or a joint vector.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    #[error("URDF could not be parsed: {0}")]
    MalformedUrdf(String),
    #[error("SRDF could not be read: {0}")]
    MalformedSrdf(String),
    #[error("URDF is {size} bytes, more than the limit of {limit} bytes")]
    UrdfTooLarge { size: usize, limit: usize },
    #[error("URDF has {count} {what}, more than the limit of {limit}")]
    TooManyElements {
        what: &'static str,
        count: usize,
        limit: usize,
    },
    #[error("URDF value {field} is not finite")]
    NonFiniteValue { field: String },
    #[error("URDF value {field} is out of range: {reason}")]
    ValueOutOfRange { field: String, reason: &'static str },
    #[error("unknown link `{link}`")]
    UnknownLink { link: String },
    #[error("unknown robot `{name}`; built-in robots: {known}")]
    UnknownRobot { name: String, known: String },
    #[error("the URDF has no single root link (roots: {roots})")]
    NoSingleRoot { roots: String },
    #[error("tip link is ambiguous: the tree has several end links ({leaves}); name one")]
    AmbiguousTip { leaves: String },
    #[error("no serial chain leads from `{base}` to `{tip}`")]
    NotSerialChain { base: String, tip: String },
    #[error("joint `{joint}` has type {kind}, which a serial chain cannot use")]
    UnsupportedJoint { joint: String, kind: String },
    #[error("joint `{joint}` has a zero-length axis")]
    ZeroAxis { joint: String },
    #[error("joint `{joint}` has lower limit {lower} above upper limit {upper}")]
    InvertedLimits { joint: String, lower: f64, upper: f64 },
    #[error("expected {expected} joint values, got {got}")]
    WrongJointCount { expected: usize, got: usize },
    #[error("joint value {index} is not finite")]
    NonFiniteJoint { index: usize },
    #[error("joint value {index} is {value}, beyond the accepted magnitude {limit}")]
    JointOutOfRange { index: usize, value: f64, limit: f64 },
}
