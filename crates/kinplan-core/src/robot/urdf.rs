//! Turns URDF text into a [`Chain`] between a base link and a tip link.
//!
//! Only the text given is read: mesh files are recorded by name, never opened.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::chain::LinkFrame;
use super::{Chain, CollisionShape, Joint, JointKind, LinkCollision, RobotError, Shape, mesh_scale};

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
    /// Deepest element nesting, checked by a linear scan before the XML parser
    /// (which recurses, and is quadratic on deep unclosed input) sees the text.
    pub max_depth: usize,
    /// Most XML elements of any kind in the document (checked before parsing).
    pub max_xml_elements: usize,
    /// Most collision shapes over all links of the model.
    pub max_collision_shapes: usize,
}

impl Default for UrdfLimits {
    fn default() -> Self {
        Self {
            max_bytes: 2 * 1024 * 1024,
            max_elements: 1000,
            max_depth: MAX_XML_DEPTH,
            max_xml_elements: 20_000,
            max_collision_shapes: 1000,
        }
    }
}

/// Default deepest XML nesting: a URDF needs 5 (`robot/link/collision/geometry/box`).
pub const MAX_XML_DEPTH: usize = 64;
/// Largest magnitude of an origin coordinate, metres: a robot larger than 10 km
/// is a mistake, and bounded origins keep forward kinematics finite.
pub const MAX_ORIGIN_METRES: f64 = 1e4;
/// Largest magnitude of a joint limit (rad or m) and of a velocity or effort limit.
pub const MAX_LIMIT: f64 = 1e6;

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
    prescan(text, &limits)?;
    let robot = std::panic::catch_unwind(|| urdf_rs::read_from_string(text))
        .map_err(|_| RobotError::MalformedUrdf("the XML parser failed".into()))?
        .map_err(|e| RobotError::MalformedUrdf(clip(&e.to_string())))?;
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
    let shapes: usize = robot.links.iter().map(|l| l.collision.len()).sum();
    if shapes > limits.max_collision_shapes {
        return Err(RobotError::TooManyElements {
            what: "collision shapes",
            count: shapes,
            limit: limits.max_collision_shapes,
        });
    }
    Tree::new(&robot)?.chain(spec)
}

/// A linear scan of the XML structure before the real parser runs: rejects
/// nesting deeper than `limits.max_depth`, more than `limits.max_xml_elements`
/// elements, and document type declarations (entity expansion). The parsers
/// behind urdf-rs (RustyXML, then xml-rs) recurse per level and cost time
/// quadratic in the depth of unclosed elements, so both are kept bounded here.
/// The scan follows XML's lexical rules (comments, CDATA, processing
/// instructions, quoted attribute values); it only counts, the parser still
/// decides what is well formed.
pub(crate) fn prescan(text: &str, limits: &UrdfLimits) -> Result<(), RobotError> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut elements = 0usize;
    let mut i = 0;
    let find = |from: usize, pat: &[u8]| -> Option<usize> {
        bytes[from.min(bytes.len())..]
            .windows(pat.len())
            .position(|w| w == pat)
            .map(|p| from + p + pat.len())
    };
    let unterminated = |what: &str| RobotError::MalformedUrdf(format!("unterminated {what}"));
    while let Some(off) = bytes[i..].iter().position(|&b| b == b'<') {
        i += off;
        let rest = &bytes[i..];
        if rest.starts_with(b"<!--") {
            i = find(i + 4, b"-->").ok_or_else(|| unterminated("comment"))?;
        } else if rest.starts_with(b"<![CDATA[") {
            i = find(i + 9, b"]]>").ok_or_else(|| unterminated("CDATA section"))?;
        } else if rest.starts_with(b"<?") {
            i = find(i + 2, b"?>").ok_or_else(|| unterminated("processing instruction"))?;
        } else if rest.starts_with(b"<!") {
            return Err(RobotError::MalformedUrdf(
                "document type declarations are not accepted".into(),
            ));
        } else {
            // A tag: skip to its `>`, honouring quoted attribute values.
            let closing = rest.get(1) == Some(&b'/');
            let mut j = i + 1;
            let mut quote = None;
            let end = loop {
                let Some(&b) = bytes.get(j) else {
                    return Err(unterminated("tag"));
                };
                match (quote, b) {
                    (Some(q), b) if b == q => quote = None,
                    (Some(_), _) => {}
                    (None, b'"' | b'\'') => quote = Some(b),
                    (None, b'>') => break j,
                    _ => {}
                }
                j += 1;
            };
            let self_closing = bytes[end - 1] == b'/';
            if closing {
                depth = depth.saturating_sub(1);
            } else {
                elements += 1;
                if elements > limits.max_xml_elements {
                    return Err(RobotError::TooManyElements {
                        what: "XML elements",
                        count: elements,
                        limit: limits.max_xml_elements,
                    });
                }
                if !self_closing {
                    depth += 1;
                    if depth > limits.max_depth {
                        return Err(RobotError::MalformedUrdf(format!(
                            "elements are nested more than {} deep",
                            limits.max_depth
                        )));
                    }
                }
            }
            i = end + 1;
        }
    }
    Ok(())
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
        let mut joint_names = HashSet::new();
        for joint in &robot.joints {
            if !joint_names.insert(joint.name.as_str()) {
                return Err(RobotError::MalformedUrdf(format!(
                    "two joints share the name `{}`",
                    clip(&joint.name)
                )));
            }
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
        let tree = Self {
            robot,
            links,
            parent_joint,
        };
        tree.check_connected()?;
        Ok(tree)
    }

    /// With one root, every link must hang from it: a cycle of joints detached
    /// from the root leaves links that no walk from the root reaches.
    fn check_connected(&self) -> Result<(), RobotError> {
        let Ok(root) = self.root() else {
            return Ok(()); // reported when a chain needs the root
        };
        let mut children: HashMap<&str, Vec<&str>> = HashMap::new();
        for joint in &self.robot.joints {
            children
                .entry(joint.parent.link.as_str())
                .or_default()
                .push(joint.child.link.as_str());
        }
        let mut seen = HashSet::from([root]);
        let mut stack = vec![root];
        while let Some(link) = stack.pop() {
            for child in children.get(link).into_iter().flatten() {
                if seen.insert(child) {
                    stack.push(child);
                }
            }
        }
        match self.robot.links.iter().find(|l| !seen.contains(l.name.as_str())) {
            Some(l) => Err(RobotError::MalformedUrdf(format!(
                "link `{}` is on a cycle of joints detached from the root `{}`",
                clip(&l.name),
                clip(root)
            ))),
            None => Ok(()),
        }
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
            .ok_or_else(|| RobotError::UnknownLink { link: clip(name) })
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
                        joint: clip(&joint.name),
                        kind: format!("{other:?}").to_lowercase(),
                    });
                }
            };
            match kind {
                None => pending *= origin,
                Some(kind) => {
                    if joint.mimic.is_some() {
                        return Err(RobotError::UnsupportedJoint {
                            joint: clip(&joint.name),
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
            analytic: Default::default(),
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

/// At most 64 characters of a name from the document, for messages.
pub(crate) fn clip(text: &str) -> String {
    match text.char_indices().nth(64) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

fn bounded(
    values: &[f64],
    bound: f64,
    field: impl Fn() -> String,
    reason: &'static str,
) -> Result<(), RobotError> {
    finite(values, &field)?;
    if values.iter().all(|v| v.abs() <= bound) {
        Ok(())
    } else {
        Err(RobotError::ValueOutOfRange {
            field: field(),
            reason,
        })
    }
}

/// URDF origin: translation `xyz`, then rotation `Rz(yaw) Ry(pitch) Rx(roll)`.
/// Coordinates are bounded by [`MAX_ORIGIN_METRES`], angles by [`MAX_LIMIT`].
fn pose(p: &urdf_rs::Pose, owner: &str) -> Result<Isometry3<f64>, RobotError> {
    let owner = clip(owner);
    bounded(
        &p.xyz[..],
        MAX_ORIGIN_METRES,
        || format!("{owner}.origin.xyz"),
        "coordinates must be within ±1e4 m",
    )?;
    bounded(
        &p.rpy[..],
        MAX_LIMIT,
        || format!("{owner}.origin.rpy"),
        "angles must be within ±1e6 rad",
    )?;
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
    let name = &clip(&joint.name);
    finite(&joint.axis.xyz[..], || format!("{name}.axis"))?;
    let axis = Vector3::new(joint.axis.xyz[0], joint.axis.xyz[1], joint.axis.xyz[2]);
    // Scaled by its largest component first, so that huge axes normalise
    // without overflow and tiny ones without underflow.
    let scale = axis.amax();
    if scale * (axis / scale.max(f64::MIN_POSITIVE)).norm() < 1e-12 {
        return Err(RobotError::ZeroAxis { joint: name.clone() });
    }
    let axis = Unit::new_normalize(axis / scale);
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
    // A velocity limit of 0 or +inf means none (URDF 1.2 writes omitted limits
    // as infinity); anything else must be a usable speed.
    let velocity = limit.velocity;
    if velocity.is_nan()
        || velocity < 0.0
        || (velocity > 0.0 && velocity.is_finite() && !(1e-6..=MAX_LIMIT).contains(&velocity))
    {
        return Err(RobotError::ValueOutOfRange {
            field: format!("{name}.limit.velocity"),
            reason: "must be 0 (none), +inf (none) or within [1e-6, 1e6]",
        });
    }
    if limit.effort.is_nan() || limit.effort < 0.0 {
        return Err(RobotError::ValueOutOfRange {
            field: format!("{name}.limit.effort"),
            reason: "must be >= 0",
        });
    }
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
        let owner = format!("{}.collision[{i}]", clip(&link.name));
        let origin = pose(&c.origin, &owner)?;
        let positive = |values: &[f64]| -> Result<(), RobotError> {
            bounded(
                values,
                MAX_ORIGIN_METRES,
                || owner.clone(),
                "sizes must be within 1e4 m",
            )?;
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
            urdf_rs::Geometry::Mesh { filename, scale } => Shape::MeshReference {
                filename: filename.clone(),
                scale: mesh_scale(scale.as_ref()).ok_or_else(|| {
                    RobotError::MalformedUrdf(format!(
                        "link `{}`: mesh `{filename}` has a scale that is not finite and non-zero",
                        link.name
                    ))
                })?,
            },
        };
        shapes.push(CollisionShape { origin, shape });
    }
    Ok(LinkCollision {
        link: link.name.clone(),
        shapes,
    })
}
