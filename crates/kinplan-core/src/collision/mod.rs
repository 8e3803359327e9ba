//! Collision checking of robot states against a scene: what planners ask of a
//! robot in its world (validity, clearance, motion validity).

mod checker;

pub use checker::{MotionCheck, StateChecker, interpolate_motion_valid};
