//! Inverse kinematics: Jacobian methods (with SVD or RLXA), CCD, FABRIK, length
//! relaxation, closed-form (analytic) solvers, restarts and time budgets, batches
//! and Cartesian path tracking.

pub mod analytic;
mod attempt;
mod ccd;
mod error;
mod fabrik;
mod jacobian_methods;
mod length_relaxation;
mod params;
mod point_chain;
mod solve;
mod target;
mod track;
mod workspace;

#[cfg(test)]
mod tests;

pub use error::{IkError, IkParam, PathParam, TargetPart};
pub use fabrik::{PointChainReport, fabrik_points};
pub use length_relaxation::{RelaxationGraph, length_relaxation_points, relax_length};
pub use params::{IkMethod, IkParams, JointLimitMode};
pub use point_chain::PointWorkspace;
pub use solve::{IkResult, IkSolution, IkSolver, IkStatus, solve_ik};
pub use target::{IkTarget, PoseError, pose_error};
pub use track::{
    BatchSeeds, PathStep, TrackParams, TrackResult, circle_path, line_path, solve_ik_batch, track_path,
};
pub use workspace::IkWorkspace;
