//! Small dense linear solvers for Jacobian systems: SVD pseudoinverse and angle relaxation (RLXA).
//!
//! Both solve `A x = b` for any m×n `A` (any rank) and report a [`LinearSolution`];
//! "did not reach the tolerance" is a [`SolveStatus`], not an error. Spec: docs/linear-solvers.md.

mod angle_relaxation;
mod error;
mod pseudoinverse;
mod solution;

pub use angle_relaxation::{
    RlxaParams, RlxaReport, RlxaVariant, RlxaWorkspace, STOP_CHECK_WORK, solve_angle_relaxation,
    solve_angle_relaxation_until,
};
pub use error::{LinalgError, LinalgParam, Operand};
pub use pseudoinverse::{PseudoinverseParams, SvdWorkspace, solve_pseudoinverse};
pub use solution::{LinearSolution, LinearSolverKind, SolveStatus};
