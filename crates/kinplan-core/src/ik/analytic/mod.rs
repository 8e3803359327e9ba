//! Closed-form inverse kinematics: Paden–Kahan subproblems, the geometric
//! family of a chain, and solvers returning every solution with its
//! configuration flags (docs/inverse-kinematics.md#analytic).

mod family;
pub(crate) mod front;
mod general;
mod params;
mod redundant;
mod search;
mod solve;
mod subproblems;
mod turned;
mod whole_turns;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_general;
#[cfg(test)]
mod tests_seven;

pub use family::{AnalyticArm, Family, NotAnalytic, ZeroAxes};
pub use front::solve_analytic;
pub use params::{AnalyticParams, Turns};
pub use redundant::{ChainModel, ReducedArm, analyse};
pub(crate) use search::{proposal_params, searched, searched_joint};
pub use solve::{AnalyticSolution, ConfigFlags, MAX_TURNS};
pub use subproblems::{Angles, DEGENERATE, Pairs, rot, sp1, sp2, sp3, sp4, wrap};
