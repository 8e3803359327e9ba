//! Result of a linear solve, shared by both solvers.

use nalgebra::DVector;

/// Which linear solver a Jacobian method uses for its per-iteration system.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum LinearSolverKind {
    /// Moore–Penrose pseudoinverse through an SVD (direct).
    #[default]
    SvdPseudoinverse,
    /// Angle relaxation, RLXA (iterative, randomised; S2 §2).
    AngleRelaxation,
}

/// Whether an iterative solve met its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SolveStatus {
    /// `‖b − A x‖ < tolerance` (always the case for the direct SVD solve).
    Converged,
    /// The iteration cap was reached first; `x` is the last iterate.
    IterationCap,
}

/// `x` with its residual norm `‖b − A x‖₂`, iteration count, status and
/// (when asked for) the residual norm after every iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearSolution {
    pub x: DVector<f64>,
    pub residual_norm: f64,
    pub iterations: usize,
    pub status: SolveStatus,
    /// `history[k]` = `‖r‖` after iteration `k+1`; empty unless requested.
    pub history: Vec<f64>,
}
