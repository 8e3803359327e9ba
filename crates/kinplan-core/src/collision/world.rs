//! A validated [`Scene`] turned into parry shapes with a broad phase: one
//! leaf per primitive, per mesh (parry's `TriMesh` keeps its own triangle
//! tree) and per occupied cell, all under one [`Bvh`]. Built once per scene
//! and shared read-only between threads.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::SharedShape;

use super::bvh::{Aabb, Bvh};
use super::convert::{pose_to_parry, vec_to_parry};
use super::fast::LeafFast;
use super::{CollisionError, Geometry, Scene};

/// One broad-phase leaf: a parry shape at a pose (base frame).
#[derive(Clone)]
pub(crate) struct Leaf {
    /// Index of the obstacle in [`Scene::obstacles`].
    pub obstacle: u32,
    pub pose: Pose,
    pub shape: SharedShape,
    pub aabb: Aabb,
    /// The closed-form description (spheres, capsules, boxes, cells).
    pub fast: LeafFast,
    /// Its place among the scene's leaves (names it in the GJK warm
    /// start's table).
    pub key: u64,
}

/// The scene ready for queries (see the module doc).
#[derive(Clone)]
pub struct SceneGeometry {
    scene: Scene,
    pub(crate) leaves: Vec<Leaf>,
    pub(crate) bvh: Bvh,
}

impl std::fmt::Debug for SceneGeometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneGeometry")
            .field("obstacles", &self.scene.obstacles().len())
            .field("leaves", &self.leaves.len())
            .finish()
    }
}

/// The parry shape of a z-axis primitive and the correction from the URDF
/// convention (axis z) to parry's (cylinders along y): `Rx(+90°)` maps
/// parry's y axis onto z.
pub(crate) fn primitive_shape(g: &Geometry) -> Option<(SharedShape, Isometry3<f64>)> {
    let id = Isometry3::identity();
    Some(match g {
        Geometry::Box { half_extents: h } => (SharedShape::cuboid(h.x, h.y, h.z), id),
        Geometry::Sphere { radius } => (SharedShape::ball(*radius), id),
        Geometry::Capsule { radius, length } => (SharedShape::capsule_z(0.5 * length, *radius), id),
        Geometry::Cylinder { radius, length } => (
            SharedShape::cylinder(0.5 * length, *radius),
            Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
            ),
        ),
        Geometry::Mesh { .. } | Geometry::OccupiedCells { .. } => return None,
    })
}

pub(crate) fn aabb_of(shape: &SharedShape, pose: &Pose) -> Aabb {
    let a = shape.compute_aabb(pose);
    Aabb {
        min: Vector3::new(a.mins.x, a.mins.y, a.mins.z),
        max: Vector3::new(a.maxs.x, a.maxs.y, a.maxs.z),
    }
}

impl SceneGeometry {
    /// Builds the shapes and the broad phase of `scene`.
    pub fn build(scene: &Scene) -> Result<Self, CollisionError> {
        let mut leaves = Vec::new();
        for (i, o) in scene.obstacles().iter().enumerate() {
            let obstacle = i as u32;
            let mut push = |shape: SharedShape, pose: Isometry3<f64>, fast: LeafFast| {
                let pose = pose_to_parry(&pose);
                let aabb = aabb_of(&shape, &pose);
                leaves.push(Leaf {
                    obstacle,
                    pose,
                    shape,
                    aabb,
                    fast,
                    key: leaves.len() as u64,
                });
            };
            match &o.geometry {
                Geometry::Mesh { vertices, indices } => {
                    let v: Vec<Vector> = vertices.iter().map(|p| vec_to_parry(&p.coords)).collect();
                    let t: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                    let mesh = SharedShape::trimesh(v, t).map_err(|e| CollisionError::Degenerate {
                        field: format!("obstacles[{i}].mesh"),
                        reason: e.to_string(),
                    })?;
                    push(mesh, o.pose, LeafFast::None);
                }
                Geometry::OccupiedCells { size, centers } => {
                    let h = 0.5 * size;
                    let cube = SharedShape::cuboid(h, h, h);
                    for c in centers {
                        let pose = o.pose * Translation3::from(c.coords);
                        let fast = LeafFast::Box {
                            pose,
                            half: Vector3::repeat(h),
                        };
                        push(cube.clone(), pose, fast);
                    }
                }
                g => {
                    let (shape, fix) = primitive_shape(g).expect("primitives have a parry shape");
                    let fast = match g {
                        Geometry::Box { half_extents } => LeafFast::Box {
                            pose: o.pose,
                            half: *half_extents,
                        },
                        Geometry::Sphere { radius } => {
                            let c = Point3::from(o.pose.translation.vector);
                            LeafFast::Swept {
                                a: c,
                                b: c,
                                r: *radius,
                            }
                        }
                        Geometry::Capsule { radius, length } => LeafFast::Swept {
                            a: o.pose * Point3::new(0.0, 0.0, -0.5 * length),
                            b: o.pose * Point3::new(0.0, 0.0, 0.5 * length),
                            r: *radius,
                        },
                        Geometry::Cylinder { radius, length } => {
                            let h = 0.5 * length;
                            let rho = radius.min(h);
                            let at = |z: f64| o.pose * Point3::new(0.0, 0.0, z);
                            LeafFast::Cylinder {
                                outer: (at(-h), at(h), *radius),
                                inner: (at(-h + rho), at(h - rho), rho),
                            }
                        }
                        _ => LeafFast::None,
                    };
                    push(shape, o.pose * fix, fast);
                }
            }
        }
        let boxes: Vec<Aabb> = leaves.iter().map(|l| l.aabb).collect();
        let bvh = Bvh::build(&boxes);
        Ok(SceneGeometry {
            scene: scene.clone(),
            leaves,
            bvh,
        })
    }

    /// The scene this was built from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Distance along the ray `origin + t·dir` (`dir` of unit length, base
    /// frame) to the first obstacle surface with `t ≤ max_distance`, or
    /// `None`. Solid shapes: a ray starting inside an obstacle hits at 0.
    /// Broad phase by the BVH (boxes entered beyond the best hit so far are
    /// skipped), exact hits by parry's ray casts.
    pub fn cast_ray(&self, origin: &Point3<f64>, dir: &Vector3<f64>, max_distance: f64) -> Option<f64> {
        let ray = parry3d_f64::query::Ray::new(vec_to_parry(&origin.coords), vec_to_parry(dir));
        let mut hit = false;
        let end = self
            .bvh
            .ray_traverse(&origin.coords, dir, max_distance, |leaf, t_max| {
                let l = &self.leaves[leaf as usize];
                match l.shape.cast_ray(&l.pose, &ray, t_max, true) {
                    Some(t) if t <= t_max => {
                        hit = true;
                        t
                    }
                    _ => t_max,
                }
            });
        hit.then_some(end)
    }

    /// True when `p` (base frame) lies inside a solid obstacle (on its
    /// boundary counts). Meshes are surfaces here, as everywhere in this
    /// room, and contain nothing.
    pub fn contains_point(&self, p: &Point3<f64>) -> bool {
        let v = vec_to_parry(&p.coords);
        let obstacles = self.scene.obstacles();
        !self.bvh.for_each_near(&p.coords, 0.0, |leaf| {
            let l = &self.leaves[leaf as usize];
            let mesh = matches!(obstacles[l.obstacle as usize].geometry, Geometry::Mesh { .. });
            mesh || !l.shape.contains_point(&l.pose, v)
        })
    }

    /// Name of obstacle `index` (empty names become `obstacles[index]`).
    pub fn obstacle_name(&self, index: usize) -> String {
        match self.scene.obstacles().get(index) {
            Some(o) if !o.name.is_empty() => o.name.clone(),
            _ => format!("obstacles[{index}]"),
        }
    }
}
