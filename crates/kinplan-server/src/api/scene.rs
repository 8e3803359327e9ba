//! `Scene` (common.proto) → the collision room's validated [`Scene`]: one
//! obstacle per object, an octree object becoming its occupied (and, on
//! request, unknown) cells grouped by cell size.

use nalgebra::Point3;
use tonic::Status;

use crate::api::convert::{finite, pose_at, vec3_at};
use crate::pb::{self, collision_object::Shape};
use crate::status::invalid;
use kinplan_core::collision::{self, Geometry, Obstacle, Scene, SceneLimits};
use kinplan_core::octree::{Octree, OctreeLimits};

/// Largest octree a scene object may carry, in nodes.
const MAX_SCENE_OCTREE_NODES: usize = 2_000_000;

/// The scene of a request (`field` is its path, e.g. "scene"); unset is empty.
/// Shapes are checked here field by field; what only the whole scene can
/// tell (element counts, degenerate triangles) is checked by [`Scene::new`],
/// whose message names the object as `obstacles[i]` (= `objects[i]`).
pub fn scene_in(field: &str, scene: Option<&pb::Scene>, limits: &SceneLimits) -> Result<Scene, Status> {
    let Some(scene) = scene else {
        return Ok(Scene::empty());
    };
    if scene.objects.len() > limits.max_obstacles {
        return Err(invalid(
            format!("{field}.objects"),
            format!(
                "{} objects exceed the limit of {}",
                scene.objects.len(),
                limits.max_obstacles
            ),
        ));
    }
    let mut obstacles = Vec::with_capacity(scene.objects.len());
    for (i, object) in scene.objects.iter().enumerate() {
        // field names are formatted only for an error
        let path = || format!("{field}.objects[{i}]");
        let name = if object.id.is_empty() {
            format!("object {i}")
        } else {
            object.id.chars().take(64).collect()
        };
        let pose = pose_at(
            &|| format!("{}.pose", path()),
            object.pose.as_ref().or(Some(&pb::Pose::default())),
        )?;
        let Some(shape) = &object.shape else {
            return Err(invalid(
                path(),
                "one of box, sphere, cylinder, capsule, mesh or octree is required",
            ));
        };
        match shape {
            Shape::Octree(tree) => {
                for geometry in octree_cells(
                    &format!("{}.octree", path()),
                    tree,
                    object.unknown_as_obstacle,
                    limits,
                )? {
                    obstacles.push(Obstacle::new(name.clone(), pose, geometry));
                }
            }
            other => obstacles.push(Obstacle::new(name, pose, primitive_in(&path, other)?)),
        }
    }
    Scene::new(obstacles, limits).map_err(|e| invalid(field, e.to_string()))
}

/// `value` when finite and > 0; the error names `field()`, made only then.
fn positive(field: impl FnOnce() -> String, value: f64) -> Result<f64, Status> {
    if value.is_finite() && value > 0.0 {
        return Ok(value);
    }
    let field = field();
    let v = finite(&field, value)?;
    Err(invalid(field, format!("must be > 0, got {v}")))
}

fn primitive_in(path: &dyn Fn() -> String, shape: &Shape) -> Result<Geometry, Status> {
    Ok(match shape {
        Shape::Box(b) => {
            let size = vec3_at(&|| format!("{}.box.size", path()), b.size.as_ref())?;
            for (axis, v) in ["x", "y", "z"].iter().zip(size.iter()) {
                positive(|| format!("{}.box.size.{axis}", path()), *v)?;
            }
            Geometry::Box {
                half_extents: size / 2.0,
            }
        }
        Shape::Sphere(s) => Geometry::Sphere {
            radius: positive(|| format!("{}.sphere.radius", path()), s.radius)?,
        },
        Shape::Cylinder(c) => Geometry::Cylinder {
            radius: positive(|| format!("{}.cylinder.radius", path()), c.radius)?,
            length: positive(|| format!("{}.cylinder.length", path()), c.length)?,
        },
        Shape::Capsule(c) => Geometry::Capsule {
            radius: positive(|| format!("{}.capsule.radius", path()), c.radius)?,
            length: if c.length.is_finite() {
                c.length.max(0.0)
            } else {
                finite(&format!("{}.capsule.length", path()), c.length)?
            },
        },
        Shape::Mesh(m) => {
            if m.indices.len() % 3 != 0 {
                return Err(invalid(
                    format!("{}.mesh.indices", path()),
                    format!("{} indices is not a multiple of 3", m.indices.len()),
                ));
            }
            let vertices = m
                .vertices
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    vec3_at(&|| format!("{}.mesh.vertices[{k}]", path()), Some(v)).map(Point3::from)
                })
                .collect::<Result<Vec<_>, _>>()?;
            if let Some(k) = m.indices.iter().position(|&i| i as usize >= vertices.len()) {
                return Err(invalid(
                    format!("{}.mesh.indices[{k}]", path()),
                    format!(
                        "{} is out of range: the mesh has {} vertices",
                        m.indices[k],
                        vertices.len()
                    ),
                ));
            }
            Geometry::Mesh {
                vertices,
                indices: m.indices.clone(),
            }
        }
        Shape::Octree(_) => unreachable!("octrees are converted by octree_cells"),
    })
}

/// The occupied leaves of an OctoMap tree (and, with `unknown`, the unknown
/// cubes inside its known bounds) as cubes, one geometry per cube size.
fn octree_cells(
    path: &str,
    tree: &pb::Octree,
    unknown: bool,
    limits: &SceneLimits,
) -> Result<Vec<Geometry>, Status> {
    let octree_limits = OctreeLimits {
        max_nodes: MAX_SCENE_OCTREE_NODES,
    };
    let octree =
        Octree::from_message_data(tree.binary, &tree.id, tree.resolution, &tree.data, &octree_limits)
            .map_err(|e| invalid(path, e.to_string()))?;
    let Some((min, max)) = octree.known_bounds() else {
        return Ok(Vec::new());
    };
    collision::octree_cells(&octree, &min, &max, unknown, limits.max_total_elements)
        .map_err(|e| invalid(path, e.to_string()))?
        .ok_or_else(|| {
            invalid(
                path,
                format!(
                    "more than {} obstacle cells; send a coarser tree",
                    limits.max_total_elements
                ),
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(shape: Shape, pose: Option<pb::Pose>) -> pb::CollisionObject {
        pb::CollisionObject {
            id: "o".into(),
            pose,
            shape: Some(shape),
            unknown_as_obstacle: false,
        }
    }

    fn pose(p: [f64; 3], q: [f64; 4]) -> Option<pb::Pose> {
        Some(pb::Pose {
            position: Some(pb::Vec3 {
                x: p[0],
                y: p[1],
                z: p[2],
            }),
            orientation: Some(pb::Quaternion {
                x: q[0],
                y: q[1],
                z: q[2],
                w: q[3],
            }),
        })
    }

    fn box_of(x: f64, y: f64, z: f64) -> Shape {
        Shape::Box(pb::Box {
            size: Some(pb::Vec3 { x, y, z }),
        })
    }

    fn unit_box() -> Shape {
        box_of(1.0, 1.0, 1.0)
    }

    /// The message of converting `objects`, which must be refused.
    fn refusal(objects: Vec<pb::CollisionObject>) -> String {
        let scene = pb::Scene { objects };
        let e = scene_in("scene", Some(&scene), &SceneLimits::default()).expect_err("refused");
        assert_eq!(e.code(), tonic::Code::InvalidArgument);
        e.message().to_string()
    }

    #[test]
    fn a_refused_value_is_named_by_its_full_path() {
        let fine = object(unit_box(), None);
        let cases = [
            (
                object(box_of(1.0, 0.0, 1.0), None),
                "scene.objects[1].box.size.y: must be > 0, got 0",
            ),
            (
                object(unit_box(), pose([0.0, 0.0, f64::NAN], [0.0, 0.0, 0.0, 1.0])),
                "scene.objects[1].pose.position.z: must be finite, got NaN",
            ),
            (
                object(unit_box(), pose([0.0; 3], [0.0, 0.0, 0.0, 2.0])),
                "scene.objects[1].pose.orientation: quaternion must have norm 1",
            ),
            (
                object(
                    Shape::Cylinder(pb::Cylinder {
                        radius: 0.1,
                        length: -1.0,
                    }),
                    None,
                ),
                "scene.objects[1].cylinder.length: must be > 0, got -1",
            ),
            (
                object(
                    Shape::Capsule(pb::Capsule {
                        radius: f64::INFINITY,
                        length: 1.0,
                    }),
                    None,
                ),
                "scene.objects[1].capsule.radius: must be finite, got inf",
            ),
            (
                object(
                    Shape::Capsule(pb::Capsule {
                        radius: 0.1,
                        length: f64::NAN,
                    }),
                    None,
                ),
                "scene.objects[1].capsule.length: must be finite, got NaN",
            ),
        ];
        for (bad, expected) in cases {
            let message = refusal(vec![fine.clone(), bad]);
            assert!(
                message.starts_with(expected),
                "{message:?} should start with {expected:?}"
            );
        }
    }

    #[test]
    fn accepted_objects_keep_their_values() {
        let (s, c) = (0.5f64.sqrt(), 0.5f64.sqrt());
        let scene = pb::Scene {
            objects: vec![
                object(box_of(0.2, 0.4, 0.6), pose([1.0, -2.0, 3.0], [0.0, 0.0, s, c])),
                object(
                    Shape::Cylinder(pb::Cylinder {
                        radius: 0.1,
                        length: 0.3,
                    }),
                    None,
                ),
            ],
        };
        let out = scene_in("scene", Some(&scene), &SceneLimits::default()).unwrap();
        let o = out.obstacles();
        assert_eq!(o.len(), 2);
        match &o[0].geometry {
            Geometry::Box { half_extents } => assert_eq!(half_extents.as_slice(), &[0.1, 0.2, 0.3]),
            g => panic!("a box, got {g:?}"),
        }
        assert_eq!(o[0].pose.translation.vector.as_slice(), &[1.0, -2.0, 3.0]);
        // a quarter turn about z: x goes to y
        let x = o[0].pose.rotation * nalgebra::Vector3::x();
        assert!((x - nalgebra::Vector3::y()).norm() < 1e-12, "{x}");
        assert_eq!(
            o[1].geometry,
            Geometry::Cylinder {
                radius: 0.1,
                length: 0.3
            }
        );
        assert_eq!(o[1].pose, nalgebra::Isometry3::identity());
    }
}
