//! The one error type of the `mobile` room: invalid input, reported with the offending field.

use thiserror::Error;

use super::field::MobileField;

/// Invalid input to a mobile-robot function. Outcomes such as "no path" or
/// "collision" are not errors: they are statuses inside a run result.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MobileError {
    /// A number that must be finite is NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NotFinite {
        /// The offending input, e.g. `MobileField::State(Component::X)`.
        field: MobileField,
        /// The value received.
        value: f64,
    },
    /// A number that must be strictly positive is not.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// The offending input.
        field: MobileField,
        /// The value received.
        value: f64,
    },
    /// A number lies outside its allowed closed interval.
    #[error("{field} = {value} is outside [{min}, {max}]")]
    OutOfRange {
        /// The offending input.
        field: MobileField,
        /// The value received.
        value: f64,
        /// Lower bound (inclusive).
        min: f64,
        /// Upper bound (inclusive).
        max: f64,
    },
    /// A list or count is too short.
    #[error("{field} needs at least {min} entries, got {got}")]
    TooFew {
        /// The offending input.
        field: MobileField,
        /// Minimum length.
        min: usize,
        /// Length received.
        got: usize,
    },
    /// A path with no nodes.
    #[error("path is empty")]
    EmptyPath,
    /// An opaque controller token that does not decode to a valid state.
    #[error("controller token is invalid: {reason}")]
    BadToken {
        /// Why decoding failed.
        reason: String,
    },
    /// A controller state that a token may not carry (a bug, not bad input): encoding refuses
    /// it rather than hand out an empty token.
    #[error("the controller state could not be encoded: {reason}")]
    TokenEncoding {
        /// Why encoding failed.
        reason: String,
    },
    /// The start pose already overlaps an obstacle.
    #[error("start pose collides with obstacle {obstacle} (clearance {clearance} m)")]
    StartInCollision {
        /// Index of the obstacle in the world.
        obstacle: usize,
        /// Signed clearance (negative: penetration depth), m.
        clearance: f64,
    },
    /// A wheel state of another chassis kind was given.
    #[error("wheel state does not match the chassis: expected {expected}")]
    WheelMismatch {
        /// The kind of wheel state the chassis expects.
        expected: &'static str,
    },
}

impl MobileError {
    /// The input a field-specific error names (`None` for the errors that are about a whole
    /// input: the path, the token, the start pose, the wheel state).
    pub fn field(&self) -> Option<MobileField> {
        match self {
            MobileError::NotFinite { field, .. }
            | MobileError::NotPositive { field, .. }
            | MobileError::OutOfRange { field, .. }
            | MobileError::TooFew { field, .. } => Some(*field),
            MobileError::EmptyPath
            | MobileError::BadToken { .. }
            | MobileError::TokenEncoding { .. }
            | MobileError::StartInCollision { .. }
            | MobileError::WheelMismatch { .. } => None,
        }
    }
}

pub(crate) fn check_finite(field: MobileField, value: f64) -> Result<(), MobileError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(MobileError::NotFinite { field, value })
    }
}

pub(crate) fn check_positive(field: MobileField, value: f64) -> Result<(), MobileError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(MobileError::NotPositive { field, value })
    }
}

/// Smallest chassis length accepted (m): a wheel of a micrometre is no wheel,
/// and dividing by a smaller one overflows.
pub const MIN_DIMENSION: f64 = 1e-6;
/// Largest chassis length accepted (m).
pub const MAX_DIMENSION: f64 = 1e3;

/// A chassis length: finite and within [`MIN_DIMENSION`], [`MAX_DIMENSION`] m.
pub(crate) fn check_dimension(field: MobileField, value: f64) -> Result<(), MobileError> {
    check_range(field, value, MIN_DIMENSION, MAX_DIMENSION)
}

pub(crate) fn check_range(field: MobileField, value: f64, min: f64, max: f64) -> Result<(), MobileError> {
    check_finite(field, value)?;
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(MobileError::OutOfRange {
            field,
            value,
            min,
            max,
        })
    }
}

pub(crate) fn check_count(field: MobileField, got: usize, min: usize) -> Result<(), MobileError> {
    if got >= min {
        Ok(())
    } else {
        Err(MobileError::TooFew { field, min, got })
    }
}
