//! The one error type of the `linalg` room.

/// Why a linear solve was refused. Not converging is *not* an error (see
/// [`SolveStatus`](super::SolveStatus)).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinalgError {
    /// `b` does not have as many rows as `A`.
    #[error("shape mismatch: A is {rows}x{cols} but b has {rhs_len} entries")]
    ShapeMismatch {
        rows: usize,
        cols: usize,
        rhs_len: usize,
    },
    /// `A` has no rows or no columns.
    #[error("empty system: A is {rows}x{cols}")]
    Empty { rows: usize, cols: usize },
    /// `A` or `b` holds NaN or an infinity.
    #[error("non-finite value in {what}")]
    NonFinite { what: &'static str },
    /// A parameter is out of its allowed range.
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
}
