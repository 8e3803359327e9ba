//! Turns URDF text into a [`Chain`] between a base link and a tip link.
//!
//! Only the text given is read: mesh files are recorded by name, never opened.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::chain::LinkFrame;
use super::{Chain, CollisionShape, Joint, JointKind, LinkCollision, RobotError, Shape};

/// Which part of a URDF tree to use. `None` picks the tree's single root as
/// base, and its single end link as tip.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct ChainSpec {
    pub base_link: Option<String>,
    pub tip_link: Option<String>,
}

/// Size limits applied before and after parsing a URDF.
#[derive(Debug, Clone, Copy)]
pub struct UrdfLimits {
    /// Largest accepted document, bytes.
    pub max_bytes: usize,
    /// Largest number of links (and of joints).
    pub max_elements: usize,
}

impl Default for UrdfLimits {
    fn default() -> Self {
        Self {
            max_bytes: 2 * 1024 * 1024,
            max_elements: 1000,
        }
    }
}

/// Parses `text` and extracts the serial chain named by `spec`.
pub fn parse_chain(text: &str, spec: &ChainSpec, limits: UrdfLimits) -> Result<Chain, RobotError> {
    if text.len() > limits.max_bytes {
        return Err(RobotError::UrdfTooLarge {
            size: text.len(),
            limit: limits.max_bytes,
        });
    }
    if text.trim().is_empty() {
        return Err(RobotError::MalformedUrdf("the document is empty".into()));
    }
    let robot = std::panic::catch_unwind(|| urdf_rs::read_from_string(text))
        .map_err(|_| RobotError::MalformedUrdf("the XML parser failed".into()))?
        .map_err(|e| RobotError::MalformedUrdf(e.to_string()))?;
    for (what, count) in [("links", robot.links.len()), ("joints", robot.joints.len())] {
        if count > limits.max_elements {
            return Err(RobotError::TooManyElements {
                what,
                count,
                limit: limits.max_elements,
            });
        }
    }
    if robot.links.is_empty() {
        return Err(RobotError::MalformedUrdf("the robot has no links".into()));
    }
    Tree::new(&robot)?.chain(spec)
}

/// The URDF's links and joints, indexed for walking the tree.
struct Tree<'a> {
    robot: &'a urdf_rs::Robot,
    links: HashMap<&'a str, &'a urdf_rs::Link>,
    /// Joint whose child is the key.
    parent_joint: HashMap<&'a str, &'a urdf_rs::Joint>,
}

impl<'a> Tree<'a> {
    fn new(robot: &'a urdf_rs::Robot) -> Result<Self, RobotError> {
        let links: HashMap<_, _> = robot.links.iter().map(|l| (l.name.as_str(), l)).collect();
        if links.len() != robot.links.len() {
            return Err(RobotError::MalformedUrdf("two links share a name".into()));
        }
        let mut parent_joint = HashMap::new();
        for joint in &robot.joints {
            for end in [&joint.parent.link, &joint.child.link] {
                if !links.contains_key(end.as_str()) {
                    return Err(RobotError::MalformedUrdf(format!(
                        "joint `{}` names link `{end}`, which does not exist",
                        joint.name
                    )));
                }
            }
            if parent_joint.insert(joint.child.link.as_str(), joint).is_some() {
                return Err(RobotError::MalformedUrdf(format!(
                    "link `{}` is the child of two joints",
                    joint.child.link
                )));
            }
        }
        Ok(Self {
            robot,
            links,
            parent_joint,
        })
    }

    fn root(&self) -> Result<&'a str, RobotError> {
        let roots: Vec<&str> = self
            .robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|name| !self.parent_joint.contains_key(name))
            .collect();
        match roots.as_slice() {
            [one] => Ok(one),
            _ => Err(RobotError::NoSingleRoot {
                roots: roots.join(", "),
            }),
        }
    }

    fn leaf(&self) -> Result<&'a str, RobotError> {
        let parents: HashSet<&str> = self.robot.joints.iter().map(|j| j.parent.link.as_str()).collect();
        let leaves: Vec<&str> = self
            .robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|name| !parents.contains(name))
            .collect();
        match leaves.as_slice() {
            [one] => Ok(one),
            _ => Err(RobotError::AmbiguousTip {
                leaves: leaves.join(", "),
            }),
        }
    }

    fn named_link(&self, name: &str) -> Result<&'a str, RobotError> {
        self.links
            .get_key_value(name)
            .map(|(k, _)| *k)
            .ok_or_else(|| RobotError::UnknownLink { link: name.into() })
    }

    /// Joints from `base` down to `tip`, in order from the base.
    fn path(&self, base: &str, tip: &'a str) -> Result<Vec<&'a urdf_rs::Joint>, RobotError> {
        let mut path = Vec::new();
        let mut link = tip;
        while link != base {
            let Some(joint) = self.parent_joint.get(link) else {
                return Err(RobotError::NotSerialChain {
                    base: base.into(),
                    tip: tip.into(),
                });
            };
            path.push(*joint);
            link = joint.parent.link.as_str();
            if path.len() > self.robot.joints.len() {
                return Err(RobotError::MalformedUrdf("the joints form a cycle".into()));
            }
        }
        path.reverse();
        Ok(path)
    }

    fn chain(&self, spec: &ChainSpec) -> Result<Chain, RobotError> {
        let base = match &spec.base_link {
            Some(name) if !name.is_empty() => self.named_link(name)?,
            _ => self.root()?,
        };
        let tip = match &spec.tip_link {
            Some(name) if !name.is_empty() => self.named_link(name)?,
            _ => self.leaf()?,
        };
        let path = self.path(base, tip)?;

        let mut joints = Vec::new();
        let mut links = vec![LinkFrame {
            name: base.to_string(),
            after_joint: None,
            offset: Isometry3::identity(),
        }];
        // Transform from the last moving joint's frame (or the base) to the
        // current link, accumulating fixed joints.
        let mut pending = Isometry3::identity();
        for joint in &path {
            let origin = pose(&joint.origin, &joint.name)?;
            let kind = match joint.joint_type {
                urdf_rs::JointType::Fixed => None,
                urdf_rs::JointType::Revolute => Some(JointKind::Revolute),
                urdf_rs::JointType::Continuous => Some(JointKind::Continuous),
                urdf_rs::JointType::Prismatic => Some(JointKind::Prismatic),
                ref other => {
                    return Err(RobotError::UnsupportedJoint {
                        joint: joint.name.clone(),
                        kind: format!("{other:?}").to_lowercase(),
                    });
                }
            };
            match kind {
                None => pending *= origin,
                Some(kind) => {
                    if joint.mimic.is_some() {
                        return Err(RobotError::UnsupportedJoint {
                            joint: joint.name.clone(),
                            kind: "mimic".into(),
                        });
                    }
                    joints.push(moving_joint(joint, kind, pending * origin)?);
                    pending = Isometry3::identity();
                }
            }
            links.push(LinkFrame {
                name: joint.child.link.clone(),
                after_joint: joints.len().checked_sub(1),
                offset: pending,
            });
        }
        let collision = links
            .iter()
            .map(|frame| link_collision(self.links[frame.name.as_str()]))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Chain {
            name: self.robot.name.clone(),
            base_link: base.to_string(),
            tip_link: tip.to_string(),
            joints,
            tip_offset: pending,
            links,
            collision,
        })
    }
}

fn finite(values: &[f64], field: impl Fn() -> String) -> Result<(), RobotError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(RobotError::NonFiniteValue { field: field() })
    }
}

/// URDF origin: translation `xyz`, then rotation `Rz(yaw) Ry(pitch) Rx(roll)`.
fn pose(p: &urdf_rs::Pose, owner: &str) -> Result<Isometry3<f64>, RobotError> {
    finite(&p.xyz[..], || format!("{owner}.origin.xyz"))?;
    finite(&p.rpy[..], || format!("{owner}.origin.rpy"))?;
    Ok(Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    ))
}

fn moving_joint(
    joint: &urdf_rs::Joint,
    kind: JointKind,
    origin: Isometry3<f64>,
) -> Result<Joint, RobotError> {
    let name = &joint.name;
    finite(&joint.axis.xyz[..], || format!("{name}.axis"))?;
    let axis = Vector3::new(joint.axis.xyz[0], joint.axis.xyz[1], joint.axis.xyz[2]);
    let axis = Unit::try_new(axis, 1e-12).ok_or_else(|| RobotError::ZeroAxis { joint: name.clone() })?;
    let limit = &joint.limit;
    let (lower, upper) = match kind {
        JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
        _ => {
            if limit.lower.is_nan() || limit.upper.is_nan() {
                return Err(RobotError::NonFiniteValue {
                    field: format!("{name}.limit"),
                });
            }
            (limit.lower, limit.upper)
        }
    };
    if lower > upper {
        return Err(RobotError::InvertedLimits {
            joint: name.clone(),
            lower,
            upper,
        });
    }
    let max_velocity = (limit.velocity.is_finite() && limit.velocity > 0.0).then_some(limit.velocity);
    Ok(Joint {
        name: name.clone(),
        kind,
        origin,
        axis,
        lower,
        upper,
        max_velocity,
    })
}

fn link_collision(link: &urdf_rs::Link) -> Result<LinkCollision, RobotError> {
    let mut shapes = Vec::with_capacity(link.collision.len());
    for (i, c) in link.collision.iter().enumerate() {
        let owner = format!("{}.collision[{i}]", link.name);
        let origin = pose(&c.origin, &owner)?;
        let positive = |values: &[f64]| -> Result<(), RobotError> {
            finite(values, || owner.clone())?;
            if values.iter().any(|v| *v < 0.0) {
                return Err(RobotError::MalformedUrdf(format!("{owner} has a negative size")));
            }
            Ok(())
        };
        let shape = match &c.geometry {
            urdf_rs::Geometry::Box { size } => {
                positive(&size[..])?;
                Shape::Box {
                    half_extents: Vector3::new(size[0], size[1], size[2]) * 0.5,
                }
            }
            urdf_rs::Geometry::Cylinder { radius, length } => {
                positive(&[*radius, *length])?;
                Shape::Cylinder {
                    radius: *radius,
                    length: *length,
                }
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                positive(&[*radius, *length])?;
                Shape::Capsule {
                    radius: *radius,
                    length: *length,
                }
            }
            urdf_rs::Geometry::Sphere { radius } => {
                positive(&[*radius])?;
                Shape::Sphere { radius: *radius }
            }
            urdf_rs::Geometry::Mesh { filename, .. } => Shape::MeshReference {
                filename: filename.clone(),
            },
        };
        shapes.push(CollisionShape { origin, shape });
    }
    Ok(LinkCollision {
        link: link.name.clone(),
        shapes,
    })
}
