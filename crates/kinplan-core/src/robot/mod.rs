//! Robot models: URDF text turned into immutable serial chains with forward
//! kinematics, geometric Jacobians and collision primitives.

mod builtin;
mod chain;
mod error;
mod geometry;
mod srdf;
mod urdf;
mod urdf_export;

pub use builtin::{ARM_NAMES, BUILTIN_NAMES, builtin_chain, builtin_srdf, builtin_srdf_parsed, builtin_urdf};
pub use chain::{Chain, Joint, JointKind, LinkFrame};
pub use error::RobotError;
pub use geometry::{CollisionShape, LinkCollision, Shape, mesh_scale};
pub use srdf::{EndEffector, Group, GroupState, Srdf, parse_srdf};
pub(crate) use urdf::prescan;
pub use urdf::{ChainSpec, MAX_LIMIT, MAX_ORIGIN_METRES, MAX_XML_DEPTH, UrdfLimits, parse_chain};
pub use urdf_export::expand_capsules;

#[cfg(test)]
mod tests;
