//! kinplan: kinematics, inverse kinematics, trajectory scoring and mobile-robot
//! control, as a plain library (the domain core) and a gRPC service on top.
//!
//! The domain rooms (`robot`, …) never name tonic or prost; `service` is the
//! only layer that does.

pub mod robot;
pub mod score;
pub mod service;
