//! Bodies hanging off a chain: every link of a URDF tree that is not on the
//! base → tip path — a tool or gripper beyond the tip, a camera bracket on a
//! wrist, a pedestal above the base, another branch of the tree — carried by
//! the chain through fixed joints, or through moving joints held at a locked
//! value (a gripper's fingers during arm motion). Each becomes an
//! [`AttachedBody`] of its nearest chain link, so the whole robot collides,
//! not only the chain from base to tip.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::CollisionError;
use super::model::AttachedBody;
use crate::robot::{Chain, CollisionShape, Shape};

/// Largest URDF accepted here (bytes), as for robot models.
const MAX_URDF_BYTES: usize = 4 << 20;

/// The attached bodies of `chain` in the URDF `urdf` (the text the chain
/// was parsed from): the tree is walked from the chain's links through every
/// joint not on the chain, down to children and up to parents (links above
/// the base ride on the base link). Off-chain moving joints take their value
/// from `locked` (by joint name, rad or m), used as given even outside the
/// joint's limits (a recorded state is reproduced as it was), else 0
/// clamped into the limits. Joint transform: `J = origin · motion(value)`,
/// composed from the chain link down to a child (`T · J`) or up to a parent
/// (`T · J⁻¹`).
pub fn attached_bodies(
    urdf: &str,
    chain: &Chain,
    locked: &[(&str, f64)],
) -> Result<Vec<AttachedBody>, CollisionError> {
    if urdf.len() > MAX_URDF_BYTES {
        return Err(CollisionError::TooLarge {
            field: "urdf".into(),
            value: urdf.len() as f64,
            limit: MAX_URDF_BYTES as f64,
        });
    }
    let robot = urdf_rs::read_from_string(urdf).map_err(|e| CollisionError::Parse {
        field: "urdf".into(),
        reason: e.to_string(),
    })?;
    let on_chain: HashSet<&str> = chain.links().iter().map(|l| l.name.as_str()).collect();
    let links: HashMap<&str, &urdf_rs::Link> = robot.links.iter().map(|l| (l.name.as_str(), l)).collect();
    for (name, value) in locked {
        if !value.is_finite() {
            return Err(CollisionError::NonFinite {
                field: format!("locked[{name}]"),
            });
        }
    }
    // (link name, chain link it rides on, pose in that chain link's frame)
    let mut frontier: Vec<(String, String, Isometry3<f64>)> = chain
        .links()
        .iter()
        .map(|l| (l.name.clone(), l.name.clone(), Isometry3::identity()))
        .collect();
    let mut out = Vec::new();
    let mut seen: HashSet<String> = HashSet::new();
    while let Some((from, root, offset)) = frontier.pop() {
        // joints to a child of `from`, and the joint from its parent
        let steps = robot.joints.iter().filter_map(|j| {
            if j.parent.link == from {
                Some((j, j.child.link.as_str(), false))
            } else if j.child.link == from {
                Some((j, j.parent.link.as_str(), true))
            } else {
                None
            }
        });
        for (joint, child, upward) in steps {
            if on_chain.contains(child) || !seen.insert(child.to_string()) {
                continue;
            }
            let field = format!("joints[{}]", joint.name);
            let origin = pose(&joint.origin, &field)?;
            let motion = match joint.joint_type {
                urdf_rs::JointType::Fixed => Isometry3::identity(),
                urdf_rs::JointType::Revolute
                | urdf_rs::JointType::Continuous
                | urdf_rs::JointType::Prismatic => {
                    let axis = Vector3::from_row_slice(&joint.axis.xyz[..]);
                    let axis = Unit::try_new(axis, 1e-12).ok_or_else(|| CollisionError::Degenerate {
                        field: format!("{field}.axis"),
                        reason: "zero-length axis".into(),
                    })?;
                    let value = match locked.iter().find(|(n, _)| *n == joint.name) {
                        Some((_, v)) => *v,
                        None if matches!(joint.joint_type, urdf_rs::JointType::Continuous) => 0.0,
                        None => 0.0_f64.clamp(
                            joint.limit.lower.min(joint.limit.upper),
                            joint.limit.upper.max(joint.limit.lower),
                        ),
                    };
                    if matches!(joint.joint_type, urdf_rs::JointType::Prismatic) {
                        Isometry3::from_parts(
                            Translation3::from(axis.into_inner() * value),
                            UnitQuaternion::identity(),
                        )
                    } else {
                        Isometry3::from_parts(
                            Translation3::identity(),
                            UnitQuaternion::from_axis_angle(&axis, value),
                        )
                    }
                }
                ref other => {
                    return Err(CollisionError::Parse {
                        field,
                        reason: format!("joint type {other:?} cannot carry an attached body"),
                    });
                }
            };
            let pose_in_root = if upward {
                offset * (origin * motion).inverse()
            } else {
                offset * origin * motion
            };
            let end = if upward { "parent" } else { "child" };
            let link = links.get(child).ok_or_else(|| CollisionError::UnknownName {
                field: format!("{field}.{end}"),
                name: child.to_string(),
            })?;
            let shapes = link_shapes(link)?;
            if !shapes.is_empty() {
                out.push(AttachedBody {
                    name: child.to_string(),
                    parent_link: root.clone(),
                    offset: pose_in_root,
                    shapes,
                });
            }
            frontier.push((child.to_string(), root.clone(), pose_in_root));
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(out)
}

fn pose(p: &urdf_rs::Pose, field: &str) -> Result<Isometry3<f64>, CollisionError> {
    if p.xyz.iter().chain(p.rpy.iter()).any(|v| !v.is_finite()) {
        return Err(CollisionError::NonFinite {
            field: format!("{field}.origin"),
        });
    }
    Ok(Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    ))
}

/// URDF `<collision>` elements of one link as robot shapes.
fn link_shapes(link: &urdf_rs::Link) -> Result<Vec<CollisionShape>, CollisionError> {
    let mut out = Vec::new();
    for (k, c) in link.collision.iter().enumerate() {
        let field = format!("links[{}].collision[{k}]", link.name);
        let origin = pose(&c.origin, &field)?;
        let sizes: Vec<f64> = match &c.geometry {
            urdf_rs::Geometry::Box { size } => size.to_vec(),
            urdf_rs::Geometry::Cylinder { radius, length }
            | urdf_rs::Geometry::Capsule { radius, length } => {
                vec![*radius, *length]
            }
            urdf_rs::Geometry::Sphere { radius } => vec![*radius],
            urdf_rs::Geometry::Mesh { .. } => vec![],
        };
        if let Some(&value) = sizes.iter().find(|v| !v.is_finite() || **v < 0.0) {
            return Err(CollisionError::NotPositive { field, value });
        }
        let shape = match &c.geometry {
            urdf_rs::Geometry::Box { size } => Shape::Box {
                half_extents: Vector3::new(size[0], size[1], size[2]) * 0.5,
            },
            urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Capsule { radius, length } => Shape::Capsule {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
            urdf_rs::Geometry::Mesh { filename, scale } => Shape::MeshReference {
                filename: filename.clone(),
                scale: crate::robot::mesh_scale(scale.as_ref()).ok_or_else(|| {
                    CollisionError::Degenerate {
                        field: field.clone(),
                        reason: format!("mesh `{filename}` has a scale that is not finite and non-zero"),
                    }
                })?,
            },
        };
        out.push(CollisionShape { origin, shape });
    }
    Ok(out)
}
