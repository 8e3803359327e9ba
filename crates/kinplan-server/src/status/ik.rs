//! `ik` room errors into statuses: [`TargetPart`], [`IkParam`] and
//! [`PathParam`] become the fields of `SolveIk`, `SolveIkBatch`, `TrackPath`
//! and `StreamIk` requests.

use std::fmt;

use tonic::Status;

use super::invalid;
use super::linalg::{SolveAt, linalg_error};
use kinplan_core::ik::{IkError, IkParam, PathParam, TargetPart};

/// How a `TrackPath` request gives its path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathAt {
    /// `poses`.
    Poses,
    /// `line`.
    Line,
    /// `circle`.
    Circle,
}

impl fmt::Display for PathAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PathAt::Poses => "poses",
            PathAt::Line => "line",
            PathAt::Circle => "circle",
        })
    }
}

/// Where the IK target of a failed request sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkAt {
    /// `target` (SolveIk, StreamIk).
    Target,
    /// `targets[i]` (SolveIkBatch).
    Batch(usize),
    /// A TrackPath's path.
    Path(PathAt),
}

impl fmt::Display for IkAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IkAt::Target => f.write_str("target"),
            IkAt::Batch(i) => write!(f, "targets[{i}]"),
            IkAt::Path(p) => p.fmt(f),
        }
    }
}

/// The `IkOptions` field of a parameter (`lengths` is not a request field:
/// the point-chain solvers derive it from the robot).
pub fn param_field(param: IkParam) -> &'static str {
    match param {
        IkParam::PositionTolerance => "options.position_tolerance",
        IkParam::OrientationTolerance => "options.orientation_tolerance",
        IkParam::MaxIterations => "options.max_iterations",
        IkParam::Damping => "options.damping",
        IkParam::MaxStep => "options.max_step",
        IkParam::SingularValueTolerance => "options.singular_value_tolerance",
        IkParam::NumSolutions => "options.num_solutions",
        IkParam::DistinctTolerance => "options.distinct_tolerance",
        IkParam::TimeBudget => "options.time_budget",
        IkParam::Lengths => "robot",
        IkParam::RedundantSamples => "options.redundant_samples",
        IkParam::SearchSamples => "options.search_samples",
        // not settable on the wire (the service uses the domain defaults)
        IkParam::GeometryTolerance | IkParam::SolveTolerance => "options.method",
    }
}

/// The field of a path parameter within `line` / `circle`.
fn path_field(param: PathParam) -> &'static str {
    match param {
        PathParam::Steps => "steps",
        PathParam::AngleStep => "angle_step",
        PathParam::Centre => "centre",
        PathParam::Normal => "normal",
    }
}

fn target_field(part: TargetPart) -> &'static str {
    match part {
        TargetPart::Position => "position",
        TargetPart::Orientation => "orientation",
    }
}

/// INVALID_ARGUMENT naming the request field behind an [`IkError`] of the
/// request whose target (or path) is `at`.
pub fn ik_error(err: IkError, at: IkAt) -> Status {
    let text = err.to_string();
    match err {
        IkError::EmptyChain => invalid("robot", text),
        IkError::WrongSeedLength { .. } => invalid("seed", text),
        IkError::NonFiniteSeed { index } => invalid(format!("seed[{index}]"), text),
        IkError::NonFiniteTarget { field } => invalid(format!("{at}.{}", target_field(field)), text),
        IkError::NonUnitQuaternion { .. } => invalid(format!("{at}.orientation"), text),
        IkError::InvalidParam { field, .. } => invalid(param_field(field), text),
        IkError::MethodCannotServe { .. } => invalid("options.method", text),
        IkError::EmptyPath => invalid("poses", text),
        IkError::InvalidPath { field, .. } => match at {
            IkAt::Path(path) => invalid(format!("{path}.{}", path_field(field)), text),
            // Only the path builders raise it, and only TrackPath calls them.
            IkAt::Target | IkAt::Batch(_) => invalid(path_field(field), text),
        },
        IkError::Linalg(e) => linalg_error(e, SolveAt::IkOptions),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinplan_core::ik::IkMethod;
    use kinplan_core::linalg::{LinalgError, LinalgParam};

    fn field_of(err: IkError, at: IkAt) -> String {
        let status = ik_error(err, at);
        assert_eq!(status.code(), tonic::Code::InvalidArgument);
        status.message().split(':').next().unwrap().to_string()
    }

    #[test]
    fn errors_name_request_fields() {
        let circle = IkAt::Path(PathAt::Circle);
        let cases = [
            (IkError::EmptyChain, IkAt::Target, "robot"),
            (
                IkError::WrongSeedLength { expected: 6, got: 5 },
                IkAt::Target,
                "seed",
            ),
            (IkError::NonFiniteSeed { index: 2 }, IkAt::Target, "seed[2]"),
            (
                IkError::NonFiniteTarget {
                    field: TargetPart::Position,
                },
                IkAt::Batch(3),
                "targets[3].position",
            ),
            (
                IkError::NonFiniteTarget {
                    field: TargetPart::Orientation,
                },
                IkAt::Target,
                "target.orientation",
            ),
            (
                IkError::NonUnitQuaternion {
                    norm: 2.0,
                    tolerance: 1e-6,
                },
                IkAt::Path(PathAt::Line),
                "line.orientation",
            ),
            (
                IkError::InvalidParam {
                    field: IkParam::PositionTolerance,
                    value: 0.0,
                    reason: "",
                },
                IkAt::Batch(1),
                "options.position_tolerance",
            ),
            (
                IkError::MethodCannotServe {
                    method: IkMethod::Fabrik,
                    reason: String::new(),
                },
                IkAt::Target,
                "options.method",
            ),
            (IkError::EmptyPath, IkAt::Path(PathAt::Poses), "poses"),
            (
                IkError::InvalidPath {
                    field: PathParam::Normal,
                    reason: "",
                },
                circle,
                "circle.normal",
            ),
            (
                IkError::InvalidPath {
                    field: PathParam::Centre,
                    reason: "",
                },
                circle,
                "circle.centre",
            ),
            (
                IkError::InvalidPath {
                    field: PathParam::Steps,
                    reason: "",
                },
                IkAt::Path(PathAt::Line),
                "line.steps",
            ),
            (
                IkError::Linalg(LinalgError::InvalidParam {
                    field: LinalgParam::MaxIterations,
                    value: 0.0,
                    reason: "",
                }),
                IkAt::Target,
                "options.rlxa_max_iterations",
            ),
        ];
        for (err, at, field) in cases {
            assert_eq!(field_of(err, at), field);
        }
    }

    #[test]
    fn every_option_is_named_after_its_params_field() {
        use IkParam::*;
        for p in [
            PositionTolerance,
            OrientationTolerance,
            MaxIterations,
            Damping,
            MaxStep,
            SingularValueTolerance,
            NumSolutions,
            DistinctTolerance,
            TimeBudget,
        ] {
            assert_eq!(param_field(p), format!("options.{}", p.name()));
        }
    }
}
