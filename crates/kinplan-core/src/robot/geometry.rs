//! Collision primitives read from URDF `<collision>` elements, kept in link
//! frames for the planner.

use nalgebra::{Isometry3, Vector3};

/// A collision primitive in its own frame (URDF conventions: cylinders and
/// capsules run along z and are centred on the origin). Lengths in metres.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Half extents along x, y, z.
    Box {
        half_extents: Vector3<f64>,
    },
    /// Radius and full length along z.
    Cylinder {
        radius: f64,
        length: f64,
    },
    /// Radius and the distance between the two cap centres, along z.
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    /// A mesh named by file: never read from disk, only reported.
    MeshReference {
        filename: String,
    },
}

/// One shape placed in a link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionShape {
    /// Pose of the shape's frame in the link frame.
    pub origin: Isometry3<f64>,
    pub shape: Shape,
}

/// The collision shapes attached to one link of the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkCollision {
    pub link: String,
    pub shapes: Vec<CollisionShape>,
}
