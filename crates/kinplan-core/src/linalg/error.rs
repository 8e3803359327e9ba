//! The one error type of the `linalg` room, naming operands and parameters by
//! typed identifiers ([`Operand`], [`LinalgParam`]).

use std::fmt;

/// An operand of the system `A x = b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Operand {
    /// The matrix `A`.
    A,
    /// The right-hand side `b`.
    B,
}

impl fmt::Display for Operand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Operand::A => "A",
            Operand::B => "b",
        })
    }
}

/// A solver parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LinalgParam {
    /// `RlxaParams::max_iterations`.
    MaxIterations,
    /// `RlxaParams::tolerance`.
    Tolerance,
    /// `RlxaParams::relative_tolerance`.
    RelativeTolerance,
    /// `RlxaParams::zero_column_tolerance`.
    ZeroColumnTolerance,
    /// `PseudoinverseParams::relative_tolerance`: the singular-value cut-off.
    SingularValueTolerance,
    /// The damping of a damped least-squares solve.
    Damping,
}

impl LinalgParam {
    /// The parameter's name as its struct (or argument) spells it.
    pub fn name(self) -> &'static str {
        match self {
            LinalgParam::MaxIterations => "max_iterations",
            LinalgParam::Tolerance => "tolerance",
            LinalgParam::RelativeTolerance | LinalgParam::SingularValueTolerance => "relative_tolerance",
            LinalgParam::ZeroColumnTolerance => "zero_column_tolerance",
            LinalgParam::Damping => "damping",
        }
    }
}

impl fmt::Display for LinalgParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

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
    NonFinite { what: Operand },
    /// A parameter is out of its allowed range.
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: LinalgParam,
        value: f64,
        reason: &'static str,
    },
}
