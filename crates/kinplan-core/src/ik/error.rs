//! The one error type of the `ik` room: requests that cannot be served.

use super::IkMethod;
use crate::linalg::LinalgError;

/// Why an IK request was refused. Not converging, running out of time or being
/// cancelled are *statuses* in the result ([`IkStatus`](super::IkStatus)), not errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    #[error("the chain has no moving joints")]
    EmptyChain,
    #[error("seed has {got} joint values, the chain has {expected}")]
    WrongSeedLength { expected: usize, got: usize },
    #[error("seed joint value {index} is not finite")]
    NonFiniteSeed { index: usize },
    #[error("target {field} is not finite")]
    NonFiniteTarget { field: &'static str },
    #[error("target quaternion has norm {norm}, expected 1 (tolerance {tolerance})")]
    NonUnitQuaternion { norm: f64, tolerance: f64 },
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("method \"{}\" cannot serve this request: {reason}", method.name())]
    MethodCannotServe { method: IkMethod, reason: String },
    #[error("path has no poses")]
    EmptyPath,
    #[error("path parameter {field} is invalid: {reason}")]
    InvalidPath {
        field: &'static str,
        reason: &'static str,
    },
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}
