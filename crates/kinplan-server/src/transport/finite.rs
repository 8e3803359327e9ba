//! The one place that asserts no OK reply carries a non-finite number.
//!
//! Every kinplan reply is checked as encoded, against the proto schema (the
//! descriptor set the server already serves for reflection): each `double`
//! and `float` field, packed or not, at any depth. A reply that fails is a
//! server bug; the guard layer turns it into INTERNAL with a log line. Inputs
//! are validated where they could overflow, so no request should reach this.

use std::collections::HashMap;
use std::sync::OnceLock;

use prost_types::field_descriptor_proto::Type;

use crate::runtime::wire::{descriptor_set, each_message, varint};

#[derive(Debug, Clone)]
enum Kind {
    Double,
    /// A double whose documentation gives ±inf a meaning (unlimited joints).
    DoubleOrInfinite,
    Float,
    Message(String),
    Other,
}

/// Field kinds of every message, by full name (`.kinplan.v1.Pose`), and the
/// reply type of every method, by path (`/kinplan.v1.RobotService/Jacobian`).
struct Schema {
    messages: HashMap<String, HashMap<u64, Kind>>,
    replies: HashMap<String, String>,
}

/// `(message, field)` pairs whose proto documentation gives ±inf a meaning;
/// NaN is refused everywhere.
const INFINITE_ALLOWED: &[(&str, &str)] = &[("JointInfo", "lower"), ("JointInfo", "upper")];

/// Builds the schema now, so that a server does it before it reports
/// serving rather than on its first call.
pub(crate) fn prepare() {
    schema();
}

fn schema() -> &'static Schema {
    static SCHEMA: OnceLock<Schema> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let set = descriptor_set();
        let mut messages = HashMap::new();
        let mut replies = HashMap::new();
        each_message(&set, &mut |name, m| {
            let fields = m
                .field
                .iter()
                .map(|f| {
                    let kind = match f.r#type() {
                        Type::Double if INFINITE_ALLOWED.contains(&(m.name(), f.name())) => {
                            Kind::DoubleOrInfinite
                        }
                        Type::Double => Kind::Double,
                        Type::Float => Kind::Float,
                        Type::Message => Kind::Message(f.type_name().to_string()),
                        _ => Kind::Other,
                    };
                    (f.number() as u64, kind)
                })
                .collect();
            messages.insert(name.to_string(), fields);
        });
        for file in &set.file {
            for service in &file.service {
                for method in &service.method {
                    replies.insert(
                        format!("/{}.{}/{}", file.package(), service.name(), method.name()),
                        method.output_type().to_string(),
                    );
                }
            }
        }
        Schema { messages, replies }
    })
}

/// The reply type of the method at `path`, if it is a kinplan method.
pub fn reply_type(path: &str) -> Option<&'static str> {
    schema().replies.get(path).map(String::as_str)
}

/// Where a non-finite number sits in a reply: the field numbers from the top.
#[derive(Debug, PartialEq)]
pub struct NonFinite(pub Vec<u64>);

/// Checks an encoded message of type `type_name`. Bytes that do not parse
/// are left to the client (this check only looks for non-finite numbers).
pub fn check(type_name: &str, bytes: &[u8]) -> Result<(), NonFinite> {
    let mut path = Vec::new();
    walk(schema(), type_name, bytes, &mut path, 0)
}

fn double_ok(kind: &Kind, v: f64) -> bool {
    match kind {
        Kind::Double => v.is_finite(),
        Kind::DoubleOrInfinite => !v.is_nan(),
        _ => true,
    }
}

fn walk(
    schema: &Schema,
    type_name: &str,
    bytes: &[u8],
    path: &mut Vec<u64>,
    depth: usize,
) -> Result<(), NonFinite> {
    let Some(fields) = schema.messages.get(type_name) else {
        return Ok(());
    };
    if depth > 64 {
        return Ok(());
    }
    let mut at = 0;
    while at < bytes.len() {
        let Some(tag) = varint(bytes, &mut at) else {
            return Ok(());
        };
        let (number, wire) = (tag >> 3, tag & 7);
        let kind = fields.get(&number).unwrap_or(&Kind::Other);
        let bad = |path: &mut Vec<u64>| {
            path.push(number);
            Err(NonFinite(std::mem::take(path)))
        };
        match wire {
            0 => {
                if varint(bytes, &mut at).is_none() {
                    return Ok(());
                }
            }
            1 => {
                let Some(b) = bytes.get(at..at + 8) else {
                    return Ok(());
                };
                at += 8;
                if !double_ok(kind, f64::from_le_bytes(b.try_into().expect("8 bytes"))) {
                    return bad(path);
                }
            }
            5 => {
                let Some(b) = bytes.get(at..at + 4) else {
                    return Ok(());
                };
                at += 4;
                if matches!(kind, Kind::Float)
                    && !f32::from_le_bytes(b.try_into().expect("4 bytes")).is_finite()
                {
                    return bad(path);
                }
            }
            2 => {
                let Some(len) = varint(bytes, &mut at) else {
                    return Ok(());
                };
                let Some(body) = usize::try_from(len)
                    .ok()
                    .and_then(|len| bytes.get(at..at.checked_add(len)?))
                else {
                    return Ok(());
                };
                at += body.len();
                match kind {
                    Kind::Double | Kind::DoubleOrInfinite => {
                        if body
                            .chunks_exact(8)
                            .any(|c| !double_ok(kind, f64::from_le_bytes(c.try_into().expect("8 bytes"))))
                        {
                            return bad(path);
                        }
                    }
                    Kind::Float => {
                        if body
                            .chunks_exact(4)
                            .any(|c| !f32::from_le_bytes(c.try_into().expect("4 bytes")).is_finite())
                        {
                            return bad(path);
                        }
                    }
                    Kind::Message(inner) => {
                        path.push(number);
                        walk(schema, inner, body, path, depth + 1)?;
                        path.pop();
                    }
                    Kind::Other => {}
                }
            }
            _ => return Ok(()),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pb;
    use prost::Message;

    #[test]
    fn non_finite_numbers_are_found_at_any_depth() {
        let ok = pb::ForwardKinematicsResponse {
            tool_pose: Some(pb::Pose {
                position: Some(pb::Vec3 {
                    x: 1.0,
                    y: 2.0,
                    z: 3.0,
                }),
                orientation: None,
            }),
            ..Default::default()
        };
        let name = reply_type("/kinplan.v1.RobotService/ForwardKinematics").unwrap();
        assert_eq!(name, ".kinplan.v1.ForwardKinematicsResponse");
        assert_eq!(check(name, &ok.encode_to_vec()), Ok(()));
        let mut bad = ok.clone();
        bad.tool_pose.as_mut().unwrap().position.as_mut().unwrap().y = f64::NAN;
        let found = check(name, &bad.encode_to_vec()).unwrap_err();
        assert_eq!(found.0.len(), 3, "{found:?}");
        // Packed repeated doubles.
        let lin = pb::SolveLinearSystemResponse {
            x: vec![1.0, f64::INFINITY],
            ..Default::default()
        };
        let name = reply_type("/kinplan.v1.KinematicsService/SolveLinearSystem").unwrap();
        assert!(check(name, &lin.encode_to_vec()).is_err());
        let lin = pb::SolveLinearSystemResponse {
            x: vec![1.0, 2.0],
            ..Default::default()
        };
        assert!(check(name, &lin.encode_to_vec()).is_ok());
        assert_eq!(reply_type("/grpc.health.v1.Health/Check"), None);
        // Documented infinities pass; NaN never does.
        let mut joint = pb::DescribeRobotResponse {
            joints: vec![pb::JointInfo {
                lower: f64::NEG_INFINITY,
                upper: f64::INFINITY,
                ..Default::default()
            }],
            ..Default::default()
        };
        let name = reply_type("/kinplan.v1.RobotService/DescribeRobot").unwrap();
        assert!(check(name, &joint.encode_to_vec()).is_ok());
        joint.joints[0].lower = f64::NAN;
        assert!(check(name, &joint.encode_to_vec()).is_err());
    }
}
