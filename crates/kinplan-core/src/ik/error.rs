//! The one error type of the `ik` room: requests that cannot be served.

use std::fmt;

use super::IkMethod;
use crate::linalg::LinalgError;

/// Which part of a target is bad.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TargetPart {
    Position,
    Orientation,
}

/// An [`IkParams`](super::IkParams) field (or, for the point-chain solvers,
/// their link lengths) an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IkParam {
    PositionTolerance,
    OrientationTolerance,
    MaxIterations,
    Damping,
    MaxStep,
    SingularValueTolerance,
    NumSolutions,
    DistinctTolerance,
    TimeBudget,
    /// The link lengths handed to FABRIK or length relaxation.
    Lengths,
    /// `AnalyticParams::geometry_tolerance`.
    GeometryTolerance,
    /// `AnalyticParams::solve_tolerance`.
    SolveTolerance,
    /// `AnalyticParams::redundant_samples`.
    RedundantSamples,
    /// `AnalyticParams::search_samples`.
    SearchSamples,
}

/// A parameter of a sampled path ([`line_path`](super::line_path),
/// [`circle_path`](super::circle_path)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PathParam {
    Steps,
    AngleStep,
    Centre,
    Normal,
}

impl TargetPart {
    pub fn name(self) -> &'static str {
        match self {
            TargetPart::Position => "position",
            TargetPart::Orientation => "orientation",
        }
    }
}

impl IkParam {
    /// The field's name as [`IkParams`](super::IkParams) spells it.
    pub fn name(self) -> &'static str {
        match self {
            IkParam::PositionTolerance => "position_tolerance",
            IkParam::OrientationTolerance => "orientation_tolerance",
            IkParam::MaxIterations => "max_iterations",
            IkParam::Damping => "damping",
            IkParam::MaxStep => "max_step",
            IkParam::SingularValueTolerance => "singular_value_tolerance",
            IkParam::NumSolutions => "num_solutions",
            IkParam::DistinctTolerance => "distinct_tolerance",
            IkParam::TimeBudget => "time_budget",
            IkParam::Lengths => "lengths",
            IkParam::GeometryTolerance => "geometry_tolerance",
            IkParam::RedundantSamples => "redundant_samples",
            IkParam::SearchSamples => "search_samples",
            IkParam::SolveTolerance => "solve_tolerance",
        }
    }
}

impl PathParam {
    /// The argument's name in the path functions.
    pub fn name(self) -> &'static str {
        match self {
            PathParam::Steps => "steps",
            PathParam::AngleStep => "angle_step",
            PathParam::Centre => "centre",
            PathParam::Normal => "normal",
        }
    }
}

macro_rules! display_by_name {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
    )*};
}
display_by_name!(TargetPart, IkParam, PathParam);

/// Why an IK request was refused. Not converging, running out of time or being
/// cancelled are *statuses* in the result ([`IkStatus`](super::IkStatus)), not errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    #[error("the chain has no moving joints")]
    EmptyChain,
    #[error("seed has {got} joint values, the chain has {expected}")]
    WrongSeedLength { expected: usize, got: usize },
    #[error("seed joint value {index} is not finite")]
    NonFiniteSeed { index: usize },
    #[error("target {field} is not finite")]
    NonFiniteTarget { field: TargetPart },
    #[error("target quaternion has norm {norm}, expected 1 (tolerance {tolerance})")]
    NonUnitQuaternion { norm: f64, tolerance: f64 },
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: IkParam,
        value: f64,
        reason: &'static str,
    },
    #[error("method \"{}\" cannot serve this request: {reason}", method.name())]
    MethodCannotServe { method: IkMethod, reason: String },
    #[error("path has no poses")]
    EmptyPath,
    #[error("path parameter {field} is invalid: {reason}")]
    InvalidPath { field: PathParam, reason: &'static str },
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}
