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
    /// A mesh named by file: never read from disk; its geometry comes with the
    /// model (the client sends the file's bytes). `scale` multiplies the file's
    /// coordinates per axis (URDF `<mesh scale>`, default 1 1 1).
    MeshReference {
        filename: String,
        scale: Vector3<f64>,
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

/// The scale of a URDF `<mesh scale="x y z">` (unset: 1 1 1), or `None` when a
/// factor is not finite or is zero (a flattened or undefined mesh).
pub fn mesh_scale(scale: Option<&urdf_rs::Vec3>) -> Option<Vector3<f64>> {
    let s = match scale {
        Some(v) => Vector3::new(v[0], v[1], v[2]),
        None => Vector3::new(1.0, 1.0, 1.0),
    };
    s.iter().all(|f| f.is_finite() && *f != 0.0).then_some(s)
}
