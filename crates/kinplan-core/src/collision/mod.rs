//! Collision checking of robot states against a scene: what planners ask of a
//! robot in its world (validity, clearance, motion validity).
//!
//! Geometry runs on **parry3d-f64 0.31** (dimforge). Since 0.26 parry speaks
//! glam types (via `glamx`) instead of nalgebra; we take the newest release
//! rather than pinning a nalgebra-era 0.25, which would drag a second
//! nalgebra (0.34) into the build and freeze us on an unmaintained line.
//! The f64 flavour matches the workspace's f64 kinematics, so millimetre
//! clearances are not lost to f32 rounding at metre scale. All domain types
//! stay nalgebra 0.35; the conversion lives in one private module
//! (`convert`), called right before parry queries.
//!
//! Pieces: [`Scene`] (validated obstacles) → [`SceneGeometry`] (parry
//! shapes and a BVH, built once per scene); [`RobotModel`] (bodies from a
//! chain) and [`AllowedCollisions`] (once per model); [`SceneChecker`]
//! (the queries).

mod acm;
mod attach;
mod bvh;
mod checker;
mod convert;
mod error;
mod fast;
mod model;
mod moveit;
mod narrow;
mod scene;
mod scene_checker;
mod world;

pub use acm::{AcmParams, AllowReason, AllowedCollisions};
pub use attach::attached_bodies;
pub use checker::{MotionCheck, StateChecker, interpolate_motion_valid};
pub use error::CollisionError;
pub use model::{AttachedBody, InlineMesh, MAX_BODIES, MAX_LINKS, RobotModel};
pub use moveit::{JointRequest, MAX_YAML_BYTES, parse_joint_request, parse_planning_scene};
pub use scene::{Geometry, Obstacle, Scene, SceneLimits};
pub use scene_checker::{CheckerParams, Part, Proximity, SceneChecker, StateReport};
pub use world::SceneGeometry;

#[cfg(test)]
mod tests;
