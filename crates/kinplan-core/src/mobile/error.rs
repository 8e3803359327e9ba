//! The one error type of the `mobile` room: invalid input, reported with the offending field.

use thiserror::Error;

/// Invalid input to a mobile-robot function. Outcomes such as "no path" or
/// "collision" are not errors: they are statuses inside a run result.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MobileError {
    /// A number that must be finite is NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NotFinite {
        /// Name of the field, e.g. `"state.x"`.
        field: String,
        /// The value received.
        value: f64,
    },
    /// A number that must be strictly positive is not.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// Name of the field.
        field: String,
        /// The value received.
        value: f64,
    },
    /// A number lies outside its allowed closed interval.
    #[error("{field} = {value} is outside [{min}, {max}]")]
    OutOfRange {
        /// Name of the field.
        field: String,
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
        /// Name of the field.
        field: String,
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

pub(crate) fn check_finite(field: &str, value: f64) -> Result<(), MobileError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(MobileError::NotFinite {
            field: field.to_owned(),
            value,
        })
    }
}

pub(crate) fn check_positive(field: &str, value: f64) -> Result<(), MobileError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(MobileError::NotPositive {
            field: field.to_owned(),
            value,
        })
    }
}

pub(crate) fn check_range(field: &str, value: f64, min: f64, max: f64) -> Result<(), MobileError> {
    check_finite(field, value)?;
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(MobileError::OutOfRange {
            field: field.to_owned(),
            value,
            min,
            max,
        })
    }
}

pub(crate) fn check_count(field: &str, got: usize, min: usize) -> Result<(), MobileError> {
    if got >= min {
        Ok(())
    } else {
        Err(MobileError::TooFew {
            field: field.to_owned(),
            min,
            got,
        })
    }
}
