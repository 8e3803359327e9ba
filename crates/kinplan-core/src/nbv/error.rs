//! The one error type of the `nbv` room: requests that cannot be served.

use crate::ik::IkError;
use crate::octree::OctreeError;

/// Why a next-best-view request was refused. Running out of time or being cancelled
/// are statuses in the result ([`NbvStatus`](super::NbvStatus)), not errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NbvError {
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("{field} is not finite")]
    NonFinite { field: &'static str },
    #[error(transparent)]
    Octree(#[from] OctreeError),
    #[error(transparent)]
    Ik(#[from] IkError),
}
