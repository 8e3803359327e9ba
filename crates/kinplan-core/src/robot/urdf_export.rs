//! Built-in models as standard URDF. The built-ins describe links with
//! `<capsule>` collision elements (a ROS extension that urdfdom, pinocchio
//! and most URDF tools refuse); [`expand_capsules`] writes each as the
//! shapes every tool reads: a cylinder of the capsule's length and a sphere
//! at each end, the union of which is the capsule.

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::RobotError;

/// The value of `name="…"` inside one XML tag's text.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

fn numbers(text: &str, field: &'static str) -> Result<Vec<f64>, RobotError> {
    text.split_whitespace()
        .map(|v| v.parse::<f64>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| RobotError::MalformedUrdf(format!("{field}: {text:?} is not a list of numbers")))
}

/// The first `<tag …/>` or `<tag …>` in `text`: (start, end) byte range.
fn find_tag(text: &str, tag: &str) -> Option<(usize, usize)> {
    let start = text.find(&format!("<{tag}"))?;
    let end = text[start..].find('>')? + start + 1;
    Some((start, end))
}

/// Rewrites every `<collision>` element holding a `<capsule radius="r"
/// length="l"/>` (l = distance between the cap centres, along the
/// element's z axis) as three: a `<cylinder radius="r" length="l"/>` at the
/// same origin, and `<sphere radius="r"/>` elements at origin · (0, 0, ±l/2)
/// with the same rotation. Everything else is copied unchanged.
///
/// ```
/// let text = kinplan_core::robot::builtin_urdf("ur5").unwrap();
/// let standard = kinplan_core::robot::expand_capsules(text).unwrap();
/// assert!(text.contains("<capsule") && !standard.contains("<capsule"));
/// ```
pub fn expand_capsules(urdf: &str) -> Result<String, RobotError> {
    let mut out = String::with_capacity(urdf.len() * 2);
    let mut rest = urdf;
    while let Some(open) = rest.find("<collision") {
        let close = rest[open..]
            .find("</collision>")
            .ok_or_else(|| RobotError::MalformedUrdf("a <collision> element is not closed".into()))?
            + open
            + "</collision>".len();
        out.push_str(&rest[..open]);
        let block = &rest[open..close];
        match find_tag(block, "capsule") {
            None => out.push_str(block),
            Some((cs, ce)) => {
                let capsule = &block[cs..ce];
                let radius = attr(capsule, "radius")
                    .ok_or_else(|| RobotError::MalformedUrdf("a <capsule> has no radius".into()))?;
                let length: f64 = attr(capsule, "length")
                    .ok_or_else(|| RobotError::MalformedUrdf("a <capsule> has no length".into()))?
                    .parse()
                    .map_err(|_| RobotError::MalformedUrdf("a <capsule> length is not a number".into()))?;
                let (xyz, rpy) = match find_tag(block, "origin") {
                    Some((os, oe)) => {
                        let o = &block[os..oe];
                        (
                            numbers(attr(o, "xyz").unwrap_or("0 0 0"), "origin.xyz")?,
                            numbers(attr(o, "rpy").unwrap_or("0 0 0"), "origin.rpy")?,
                        )
                    }
                    None => (vec![0.0; 3], vec![0.0; 3]),
                };
                if xyz.len() != 3 || rpy.len() != 3 {
                    return Err(RobotError::MalformedUrdf(
                        "an <origin> needs 3 xyz and 3 rpy values".into(),
                    ));
                }
                let rotation = UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
                let centre = Translation3::new(xyz[0], xyz[1], xyz[2]);
                let rpy_text = format!("{} {} {}", rpy[0], rpy[1], rpy[2]);
                let element = |x: Vector3<f64>, geometry: &str| {
                    format!(
                        "<collision>\n      <origin xyz=\"{} {} {}\" rpy=\"{rpy_text}\"/>\n      <geometry>{geometry}</geometry>\n    </collision>",
                        x.x, x.y, x.z
                    )
                };
                out.push_str(&element(
                    centre.vector,
                    &format!("<cylinder radius=\"{radius}\" length=\"{length}\"/>"),
                ));
                for sign in [1.0, -1.0] {
                    let end = centre.vector + rotation * Vector3::new(0.0, 0.0, sign * length / 2.0);
                    out.push_str("\n    ");
                    out.push_str(&element(end, &format!("<sphere radius=\"{radius}\"/>")));
                }
            }
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::{ARM_NAMES, ChainSpec, Shape, UrdfLimits, builtin_urdf, parse_chain};
    use nalgebra::Point3;

    #[test]
    fn every_capsule_becomes_a_cylinder_and_two_end_spheres_and_the_chain_is_unchanged() {
        for name in ARM_NAMES {
            let text = builtin_urdf(name).unwrap();
            let standard = expand_capsules(text).unwrap();
            assert!(!standard.contains("capsule"), "{name}");
            let a = parse_chain(text, &ChainSpec::default(), UrdfLimits::default()).unwrap();
            let b = parse_chain(&standard, &ChainSpec::default(), UrdfLimits::default()).unwrap();
            let q: Vec<f64> = (0..a.dof()).map(|i| 0.3 * i as f64 - 0.7).collect();
            assert!(
                (a.fk(&q).to_homogeneous() - b.fk(&q).to_homogeneous()).norm() < 1e-12,
                "{name}"
            );
            for (la, lb) in a.collision().iter().zip(b.collision()) {
                let capsules: Vec<_> = la
                    .shapes
                    .iter()
                    .filter_map(|s| match s.shape {
                        Shape::Capsule { radius, length } => Some((s.origin, radius, length)),
                        _ => None,
                    })
                    .collect();
                let others = la.shapes.len() - capsules.len();
                assert_eq!(lb.shapes.len(), others + 3 * capsules.len(), "{name}");
                for (origin, radius, length) in capsules {
                    // the capsule's cap centres, from the original model's pose
                    for z in [length / 2.0, -length / 2.0] {
                        let want = origin * Point3::new(0.0, 0.0, z);
                        assert!(
                            lb.shapes
                                .iter()
                                .any(|s| matches!(s.shape, Shape::Sphere { radius: r } if r == radius)
                                    && (s.origin * Point3::origin() - want).norm() < 1e-9),
                            "{name}: no sphere at {want:?}"
                        );
                    }
                    assert!(lb.shapes.iter().any(|s| matches!(
                        s.shape,
                        Shape::Cylinder { radius: r, length: l } if r == radius && l == length
                    )));
                }
            }
        }
    }

    #[test]
    fn a_document_without_capsules_is_copied_unchanged() {
        let text = "<robot name=\"a\"><link name=\"l\"><collision><geometry><sphere radius=\"1\"/></geometry></collision></link></robot>";
        assert_eq!(expand_capsules(text).unwrap(), text);
        assert!(expand_capsules("<collision><capsule radius=\"1\"/>").is_err());
    }
}
