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
//! Semantics: touching counts as collision; scene meshes are surfaces
//! (a robot part wholly inside a closed mesh does not touch it); robot
//! meshes are used as convex hulls, or as a polytope of at most 20 faces
//! around the hull when the hull has more (`outer_polytope`); motions are checked at interpolated
//! states at most 0.05 rad apart — by default each state as it is (not
//! conservative between states), or piece by piece with every body padded
//! by how far it can move within the piece ([`MotionCheck::Padded`],
//! conservative: no state of an accepted motion collides; see
//! [`padded_motion_valid`] and [`SweepBound`]).
//! Narrow phase: closed forms for robot spheres/capsules against spheres,
//! capsules, boxes and cells (cylinders bracketed by capsules), parry for
//! the rest and for every distance query.
//!
//! Pieces: [`Scene`] (validated obstacles) → [`SceneGeometry`] (parry
//! shapes and a BVH, built once per scene); [`RobotModel`] (bodies from a
//! chain) and [`AllowedCollisions`] (once per model); [`SceneChecker`]
//! (the queries).

mod acm;
mod attach;
mod bound;
mod builtin_meshes;
mod bvh;
mod checker;
mod convert;
mod error;
mod face_axes;
mod fast;
mod fast_box;
mod fixed_frame;
mod gjk;
mod lanes8;
mod lanes8_bound;
mod mesh_dae;
mod mesh_file;
mod model;
mod moveit;
mod narrow;
mod octree_cells;
mod outer_polytope;
mod padded;
mod pair_table;
mod scene;
mod scene_checker;
mod spheres;
mod sweep;
mod trig;
mod trig32;
mod world;

pub use acm::{AcmParams, AllowReason, AllowedCollisions, MAX_ACM_PAIR_TESTS};
pub use attach::attached_bodies;
pub use builtin_meshes::{BUILTIN_MESH_SCHEME, builtin_mesh};
pub use checker::{MotionCheck, PadVerdict, StateChecker, interpolate_motion_valid};
pub use error::CollisionError;
pub(crate) use gjk::WarmChecks;
pub use mesh_file::{MeshFileLimits, read_mesh_file};
pub use model::{AttachedBody, InlineMesh, MAX_BODIES, MAX_LINKS, MAX_MESH_VERTICES, RobotModel};
pub use moveit::{JointRequest, MAX_YAML_BYTES, parse_joint_request, parse_planning_scene};
pub use octree_cells::octree_cells;
pub(crate) use padded::bisection_order;

pub use padded::{MAX_CHECKS_PER_PIECE, MIN_PIECE, PaddedMotion, padded_motion, padded_motion_valid};
pub use scene::{Geometry, Obstacle, Scene, SceneLimits};
pub use scene_checker::{CheckerParams, Part, Proximity, SceneChecker, StateReport};
pub use spheres::{Sphere, SphereModel, SphereParams};
pub use sweep::SweepBound;
pub use world::SceneGeometry;

#[cfg(test)]
mod tests;
