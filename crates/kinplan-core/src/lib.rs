//! kinplan-core: the domain core of kinplan — robot models, kinematics,
//! linear solvers, inverse kinematics, trajectory scoring and mobile-robot
//! control — as a plain library of pure functions over nalgebra types.
//!
//! Every long computation takes its time limit as one [`Deadline`] (an
//! optional instant and an optional cancellation) and polls it; see
//! [`deadline`].
//!
//! This crate knows nothing of gRPC: it does not depend on tonic, prost or
//! tokio (the server crate `kinplan-server` adapts it to the wire), so Rust
//! users can depend on the algorithms alone.

pub mod collision;
pub mod deadline;
pub mod explore;
pub mod ik;
pub mod linalg;
#[doc(hidden)]
pub mod mbm_data;
pub mod mobile;
pub mod nbv;
pub mod octree;
pub mod plan;
pub mod robot;
pub mod score;

pub use deadline::{Cancel, Deadline, Stop};
