//! Closed-form inverse kinematics: Paden–Kahan subproblems, the geometric
//! family of a chain, and solvers returning every solution with its
//! configuration flags (docs/inverse-kinematics.md#analytic).

mod family;
pub(crate) mod front;
mod params;
mod redundant;
mod solve;
mod subproblems;

#[cfg(test)]
mod tests;

pub use family::{AnalyticArm, Family, NotAnalytic, ZeroAxes};
pub use front::solve_analytic;
pub use params::{AnalyticParams, Turns};
pub use redundant::{ReducedArm, analyse};
pub use solve::{AnalyticSolution, ConfigFlags, MAX_TURNS};
pub use subproblems::{Angles, DEGENERATE, Pairs, rot, sp1, sp2, sp3, sp4, wrap};
