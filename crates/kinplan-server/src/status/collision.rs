//! `collision` room errors into statuses. A [`CollisionError`] carries the path
//! of the bad value inside the scene or model it was handed (in its message);
//! the request field holding that scene or model is named by the caller.

use tonic::Status;

use super::invalid;
use kinplan_core::collision::CollisionError;

/// INVALID_ARGUMENT naming `field`, the request field the scene or robot
/// model came from.
pub fn collision_error(field: &str, e: CollisionError) -> Status {
    invalid(field, e.to_string())
}

/// INTERNAL for a collision error on input the service built itself (a
/// checker's state from validated joints), with a log line.
pub fn collision_internal(e: CollisionError) -> Status {
    tracing::error!(error = %e, "collision checking rejected service-built input");
    Status::internal(e.to_string())
}

/// A checker that could not be built from service-validated parts: a robot
/// whose motions cannot be padded names `options.padded_motion`; anything
/// else is INTERNAL (see [`collision_internal`]).
pub fn checker_error(e: CollisionError) -> Status {
    match e {
        CollisionError::CannotPad => invalid("options.padded_motion", e.to_string()),
        e => collision_internal(e),
    }
}
