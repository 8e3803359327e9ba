//! The range of every number a request carries, checked once at admission.
//!
//! Every `double` and `float` field of every kinplan request, packed or not,
//! at any depth, is walked against the proto schema (the descriptor set the
//! server serves for reflection). Unless its field is listed in
//! [`WIDER_FIELDS`], a number must be finite, within ±[`MAX_MAGNITUDE`] and
//! not subnormal: physical quantities (metres, radians, seconds, weights)
//! never need more, and an absurd magnitude would otherwise overflow deep in
//! the computation. The refusal names the field by its path in the request
//! (`states[3].positions[2]`), so the client sees which value was wrong before
//! any work starts. Fields with a narrower documented range are checked again
//! by their own converters.

use std::collections::HashMap;
use std::sync::OnceLock;

use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use tonic::Status;

use super::wire::{descriptor_set, each_message, varint};
use crate::status::invalid;

/// Largest magnitude of a request number (metres, radians, seconds, …)
/// unless its field says otherwise.
pub const MAX_MAGNITUDE: f64 = 1e6;

/// What a field accepts beyond the default range.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Range {
    /// Finite, |v| ≤ [`MAX_MAGNITUDE`], not subnormal.
    Physical,
    /// Finite and |v| ≤ the bound (subnormals allowed): plain numbers of a
    /// linear system, whose squares must stay finite.
    Finite(f64),
    /// Finite, or the infinity of the given sign (a documented "no limit").
    OrInfinite { positive: bool },
    /// Anything: sensor data whose non-finite or far values mean "no return"
    /// and are skipped by the algorithm, as OctoMap does.
    Any,
}

/// `(message, field, range)`: fields whose documentation allows more than the
/// default range; on a message field, every number inside it.
const WIDER_FIELDS: &[(&str, &str, Range)] = &[
    ("PointCloud", "xyz", Range::Any),
    ("DepthImage", "depth", Range::Any),
    ("SolveLinearSystemRequest", "a", Range::Finite(1e150)),
    ("SolveLinearSystemRequest", "b", Range::Finite(1e150)),
    (
        "JerkPeakOptions",
        "slowdown_floor",
        Range::OrInfinite { positive: false },
    ),
    (
        "ScoreOptions",
        "max_acceleration",
        Range::OrInfinite { positive: true },
    ),
];

#[derive(Debug, Clone)]
enum Kind {
    Number {
        float: bool,
        range: Range,
    },
    /// A nested message, with the range its numbers take when the field
    /// widens it.
    Message(String, Option<Range>),
    Other,
}

#[derive(Debug, Clone)]
struct Field {
    name: String,
    repeated: bool,
    kind: Kind,
}

/// Builds the schema now, so that a server does it before it reports
/// serving rather than on its first call.
pub fn prepare() {
    schema();
}

/// Fields of every kinplan message by full name (`.kinplan.v1.Pose`).
fn schema() -> &'static HashMap<String, HashMap<u64, Field>> {
    static SCHEMA: OnceLock<HashMap<String, HashMap<u64, Field>>> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let mut messages = HashMap::new();
        each_message(&descriptor_set(), &mut |name, m| {
            let range = |field: &str| {
                WIDER_FIELDS
                    .iter()
                    .find(|(msg, f, _)| *msg == m.name() && *f == field)
                    .map_or(Range::Physical, |(_, _, r)| *r)
            };
            let fields = m
                .field
                .iter()
                .map(|f| {
                    let kind = match f.r#type() {
                        Type::Double => Kind::Number {
                            float: false,
                            range: range(f.name()),
                        },
                        Type::Float => Kind::Number {
                            float: true,
                            range: range(f.name()),
                        },
                        Type::Message => Kind::Message(
                            f.type_name().to_string(),
                            Some(range(f.name())).filter(|r| *r != Range::Physical),
                        ),
                        _ => Kind::Other,
                    };
                    let field = Field {
                        name: f.name().to_string(),
                        repeated: f.label() == Label::Repeated,
                        kind,
                    };
                    (f.number() as u64, field)
                })
                .collect();
            messages.insert(name.to_string(), fields);
        });
        messages
    })
}

/// The schema name of a generated request type: every kinplan request is a
/// top-level message of `kinplan.v1`, and its Rust type has the same name.
fn schema_name<T>() -> String {
    let rust = std::any::type_name::<T>();
    format!(".kinplan.v1.{}", rust.rsplit("::").next().unwrap_or(rust))
}

/// Checks every number of `request` (a generated kinplan message) against
/// its field's range; the error names the first number out of range.
pub fn check_request<T: Message>(request: &T) -> Result<(), Status> {
    let name = schema_name::<T>();
    if !schema().contains_key(&name) {
        return Ok(());
    }
    let bytes = request.encode_to_vec();
    let mut path = Vec::new();
    walk(&name, &bytes, &mut path, None, 0)
}

/// One step of a field path: the field's name and, for repeated fields, the
/// element's index.
type Step = (&'static str, Option<usize>);

fn path_text(path: &[Step]) -> String {
    let mut out = String::new();
    for (i, (name, index)) in path.iter().enumerate() {
        if i > 0 {
            out.push('.');
        }
        out.push_str(name);
        if let Some(k) = index {
            out.push_str(&format!("[{k}]"));
        }
    }
    out
}

/// Full name of the matrix message, whose data entries are also named by row
/// and column (`joint_positions[1][2]`) in the description.
const MATRIX: &str = ".kinplan.v1.Matrix";

/// Why `v` is out of `range`, if it is.
fn out_of_range(v: f64, float: bool, range: Range) -> Option<String> {
    let subnormal_limit = if float {
        f32::MIN_POSITIVE as f64
    } else {
        f64::MIN_POSITIVE
    };
    match range {
        Range::Any => None,
        _ if v.is_nan() => Some("must be finite, got NaN".into()),
        Range::OrInfinite { positive } if v.is_infinite() && (v > 0.0) == positive => None,
        _ if v.is_infinite() => Some(format!("must be finite, got {v}")),
        Range::Finite(bound) if v.abs() > bound => Some(format!("must be within ±{bound:e}, got {v:e}")),
        Range::Finite(_) => None,
        _ if v.abs() > MAX_MAGNITUDE => Some(format!(
            "must be within ±{MAX_MAGNITUDE:e} (the range of a request number unless its field says otherwise), got {v:e}"
        )),
        _ if v != 0.0 && v.abs() < subnormal_limit => Some(format!(
            "is subnormal ({v:e}): give 0 or a number of normal magnitude"
        )),
        _ => None,
    }
}

fn walk(
    type_name: &str,
    bytes: &[u8],
    path: &mut Vec<Step>,
    inherited: Option<Range>,
    depth: usize,
) -> Result<(), Status> {
    let Some(fields) = schema().get(type_name) else {
        return Ok(());
    };
    if depth > 64 {
        return Ok(());
    }
    // occurrences of each repeated field so far (their indices): a few
    // fields per message, so a small list, allocated only when one repeats
    let mut seen: Vec<(u64, usize)> = Vec::new();
    let is_matrix = type_name == MATRIX;
    let mut columns = 0usize;
    let mut at = 0;
    while at < bytes.len() {
        let Some(tag) = varint(bytes, &mut at) else {
            return Ok(());
        };
        let (number, wire) = (tag >> 3, tag & 7);
        let field: Option<&'static Field> = fields.get(&number);
        let mut next_index = |field: &Field| {
            field
                .repeated
                .then(|| match seen.iter_mut().find(|(n, _)| *n == number) {
                    Some((_, k)) => {
                        *k += 1;
                        *k - 1
                    }
                    None => {
                        seen.push((number, 1));
                        0
                    }
                })
        };
        let refuse = |path: &mut Vec<Step>, field: &'static Field, index: Option<usize>, why: String| {
            let why = match index {
                Some(k) if is_matrix && columns > 0 => {
                    format!(
                        "{why} (that is {}[{}][{}])",
                        path_text(path),
                        k / columns,
                        k % columns
                    )
                }
                _ => why,
            };
            path.push((&field.name, index));
            Err(invalid(path_text(path), why))
        };
        match wire {
            0 => {
                let Some(v) = varint(bytes, &mut at) else {
                    return Ok(());
                };
                if is_matrix && field.is_some_and(|f| f.name == "cols") {
                    columns = v as usize;
                }
            }
            1 | 5 => {
                let width = if wire == 1 { 8 } else { 4 };
                let Some(b) = bytes.get(at..at + width) else {
                    return Ok(());
                };
                at += width;
                if let Some(f) = field
                    && let Kind::Number { float, range } = f.kind
                {
                    let v = number_at(b, float);
                    let index = next_index(f);
                    if let Some(why) = out_of_range(v, float, inherited.unwrap_or(range)) {
                        return refuse(path, f, index, why);
                    }
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
                let Some(f) = field else { continue };
                match &f.kind {
                    Kind::Number { float, range } => {
                        let width = if *float { 4 } else { 8 };
                        for c in body.chunks_exact(width) {
                            let index = next_index(f);
                            if let Some(why) =
                                out_of_range(number_at(c, *float), *float, inherited.unwrap_or(*range))
                            {
                                return refuse(path, f, index, why);
                            }
                        }
                    }
                    Kind::Message(inner, widened) => {
                        let index = next_index(f);
                        path.push((&f.name, index));
                        walk(inner, body, path, widened.or(inherited), depth + 1)?;
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

fn number_at(b: &[u8], float: bool) -> f64 {
    if float {
        f32::from_le_bytes(b.try_into().expect("4 bytes")) as f64
    } else {
        f64::from_le_bytes(b.try_into().expect("8 bytes"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pb;

    fn message(status: Status) -> String {
        status.message().to_string()
    }

    #[test]
    fn every_request_type_is_found_in_the_schema() {
        let set = descriptor_set();
        let inputs: Vec<String> = set
            .file
            .iter()
            .flat_map(|f| f.service.iter())
            .flat_map(|s| s.method.iter())
            .map(|m| m.input_type().to_string())
            .collect();
        assert!(inputs.len() > 20);
        for input in &inputs {
            assert!(
                input.starts_with(".kinplan.v1.") && input.matches('.').count() == 3,
                "{input} is not a top-level kinplan.v1 message"
            );
            assert!(schema().contains_key(input), "{input}");
        }
        assert_eq!(schema_name::<pb::PlanRequest>(), ".kinplan.v1.PlanRequest");
        assert_eq!(
            schema_name::<pb::CheckStateRequest>(),
            ".kinplan.v1.CheckStateRequest"
        );
    }

    #[test]
    fn absurd_numbers_are_refused_naming_their_path() {
        let state = |positions: Vec<f64>| pb::JointState { positions };
        let req = pb::CheckStateRequest {
            states: vec![state(vec![0.0; 6]), state(vec![0.0, 1e308, 0.0])],
            ..Default::default()
        };
        let m = message(check_request(&req).unwrap_err());
        assert!(
            m.starts_with("states[1].positions[1]: must be within ±1e6"),
            "{m}"
        );
        // the bound itself passes; subnormals and NaN do not
        let ok = pb::CheckStateRequest {
            states: vec![state(vec![-1e6, 1e6, 0.0, -0.0, 1e-300])],
            ..Default::default()
        };
        assert!(check_request(&ok).is_ok());
        let tiny = pb::CheckStateRequest {
            states: vec![state(vec![5e-324])],
            ..Default::default()
        };
        let m = message(check_request(&tiny).unwrap_err());
        assert!(m.starts_with("states[0].positions[0]: is subnormal"), "{m}");
        let nan = pb::CheckStateRequest {
            max_distance: Some(f64::NAN),
            ..Default::default()
        };
        assert!(
            message(check_request(&nan).unwrap_err()).starts_with("max_distance: must be finite, got NaN")
        );
    }

    #[test]
    fn matrix_numbers_are_named_by_their_path_row_and_column() {
        let req = pb::ForwardKinematicsBatchRequest {
            joint_positions: Some(pb::Matrix {
                rows: 2,
                cols: 3,
                data: vec![0.0, 0.0, 0.0, 0.0, 0.0, f64::NAN],
            }),
            ..Default::default()
        };
        let m = message(check_request(&req).unwrap_err());
        assert!(
            m.starts_with("joint_positions.data[5]: must be finite, got NaN (that is joint_positions[1][2])"),
            "{m}"
        );
    }

    #[test]
    fn nested_messages_and_unpacked_floats_are_walked() {
        let req = pb::InsertScanRequest {
            sensor_pose: Some(pb::Pose {
                position: Some(pb::Vec3 {
                    x: 0.0,
                    y: -2e6,
                    z: 0.0,
                }),
                orientation: None,
            }),
            ..Default::default()
        };
        let m = message(check_request(&req).unwrap_err());
        assert!(m.starts_with("sensor_pose.position.y: must be within"), "{m}");
    }

    #[test]
    fn documented_wider_fields_keep_their_range() {
        // points: non-finite and far points are skipped by the scan, as OctoMap does
        let scan = pb::InsertScanRequest {
            scan: Some(pb::insert_scan_request::Scan::Points(pb::PointCloud {
                xyz: vec![f32::NAN, 1e30, f32::INFINITY],
            })),
            ..Default::default()
        };
        assert!(check_request(&scan).is_ok());
        // a linear system's numbers may be large, not infinite
        let lin = pb::SolveLinearSystemRequest {
            a: Some(pb::Matrix {
                rows: 1,
                cols: 1,
                data: vec![1e100],
            }),
            b: vec![f64::INFINITY],
            ..Default::default()
        };
        let m = message(check_request(&lin).unwrap_err());
        assert!(m.starts_with("b[0]: must be finite"), "{m}");
        // acceleration limits may be +inf (no ramp), never -inf
        let score = |a: f64| pb::ScoreTrajectoryRequest {
            options: Some(pb::ScoreOptions {
                max_acceleration: vec![1.0, a],
                ..Default::default()
            }),
            ..Default::default()
        };
        assert!(check_request(&score(f64::INFINITY)).is_ok());
        let m = message(check_request(&score(f64::NEG_INFINITY)).unwrap_err());
        assert!(
            m.starts_with("options.max_acceleration[1]: must be finite"),
            "{m}"
        );
    }
}
