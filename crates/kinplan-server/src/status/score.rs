//! `score` room errors into statuses: [`ScoreField`] and [`ScoreParam`] become
//! the proto field paths of `ScoreTrajectory` / `CompareTrajectories`.

use std::fmt;

use tonic::Status;

use super::invalid;
use kinplan_core::score::{ScoreError, ScoreField, ScoreParam};

/// Where the trajectory being scored sits in its request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryAt {
    /// `ScoreTrajectoryRequest.trajectory`.
    Single,
    /// `CompareTrajectoriesRequest.sets[set].trajectories[index]`.
    InSet { set: usize, index: usize },
}

impl fmt::Display for TrajectoryAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TrajectoryAt::Single => f.write_str("trajectory"),
            TrajectoryAt::InSet { set, index } => write!(f, "sets[{set}].trajectories[{index}]"),
        }
    }
}

/// The `ScoreOptions` field a per-joint input comes from; `None` for inputs
/// the service derives from the trajectory (joints, poses, points, times).
pub fn option_field(field: ScoreField) -> Option<&'static str> {
    match field {
        ScoreField::JointWeights => Some("options.joint_weights"),
        ScoreField::VMax => Some("options.max_velocity"),
        ScoreField::AMax => Some("options.max_acceleration"),
        ScoreField::Joints | ScoreField::Poses | ScoreField::RobotPoints | ScoreField::Timestamps => None,
    }
}

/// The `ScoreOptions` field of a parameter.
pub fn param_field(param: ScoreParam) -> &'static str {
    match param {
        ScoreParam::PotentialTolerance => "options.potential_tolerance",
        ScoreParam::JointLogGain => "options.jerk_peaks.joint_log_gain",
        ScoreParam::JointOffset => "options.jerk_peaks.joint_offset",
        ScoreParam::CartesianSqrtGain => "options.jerk_peaks.cartesian_sqrt_gain",
        ScoreParam::CartesianOffset => "options.jerk_peaks.cartesian_offset",
        ScoreParam::JointMinHeight => "options.jerk_peaks.joint_min_height",
        ScoreParam::CartesianMinHeight => "options.jerk_peaks.cartesian_min_height",
        ScoreParam::SlowdownFloor => "options.jerk_peaks.slowdown_floor",
    }
}

/// INVALID_ARGUMENT naming the request field behind a [`ScoreError`] met while
/// scoring the trajectory `at`; INTERNAL for errors in data the service
/// derived itself (FK poses and robot points of validated joints).
pub fn score_error(err: ScoreError, at: TrajectoryAt) -> Status {
    let text = err.to_string();
    let field = match &err {
        ScoreError::RaggedRow {
            field: ScoreField::Joints,
            index,
            ..
        }
        | ScoreError::WrongJointCount { index, .. } => format!("{at}.points[{index}].positions"),
        ScoreError::NoJoints => format!("{at}.points"),
        ScoreError::NonFinite {
            field: ScoreField::Joints,
            index,
            component,
            ..
        } => format!("{at}.points[{index}].positions[{component}]"),
        ScoreError::NonFinite {
            field: ScoreField::Timestamps,
            index,
            ..
        }
        | ScoreError::NonIncreasingTimestamp { index, .. } => format!("{at}.points[{index}].time_from_start"),
        ScoreError::LengthMismatch { field, .. } if option_field(*field).is_some() => {
            option_field(*field).unwrap_or_default().to_string()
        }
        ScoreError::InvalidValue { field, index, .. } if option_field(*field).is_some() => {
            format!("{}[{index}]", option_field(*field).unwrap_or_default())
        }
        ScoreError::InvalidParam { name, .. } => param_field(*name).to_string(),
        ScoreError::EmptySet { .. } | ScoreError::DuplicateLabel { .. } => "sets".to_string(),
        // Poses and robot points come from FK of validated joints.
        _ => {
            tracing::error!(error = %text, "scoring rejected derived data");
            return Status::internal(format!("scoring failed on derived data: {text}"));
        }
    };
    invalid(field, text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(err: ScoreError, at: TrajectoryAt) -> String {
        let status = score_error(err, at);
        assert_eq!(
            status.code(),
            tonic::Code::InvalidArgument,
            "{}",
            status.message()
        );
        status.message().split(':').next().unwrap().to_string()
    }

    #[test]
    fn errors_name_request_fields() {
        let set = TrajectoryAt::InSet { set: 1, index: 4 };
        let cases = [
            (
                ScoreError::WrongJointCount {
                    index: 12,
                    expected: 6,
                    found: 5,
                },
                TrajectoryAt::Single,
                "trajectory.points[12].positions",
            ),
            (
                ScoreError::RaggedRow {
                    field: ScoreField::Joints,
                    index: 2,
                    expected: 6,
                    found: 5,
                },
                set,
                "sets[1].trajectories[4].points[2].positions",
            ),
            (ScoreError::NoJoints, set, "sets[1].trajectories[4].points"),
            (
                ScoreError::NonFinite {
                    field: ScoreField::Joints,
                    index: 3,
                    component: 1,
                    value: f64::NAN,
                },
                TrajectoryAt::Single,
                "trajectory.points[3].positions[1]",
            ),
            (
                ScoreError::NonFinite {
                    field: ScoreField::Timestamps,
                    index: 5,
                    component: 0,
                    value: f64::NAN,
                },
                set,
                "sets[1].trajectories[4].points[5].time_from_start",
            ),
            (
                ScoreError::NonIncreasingTimestamp {
                    index: 2,
                    previous: 1.0,
                    value: 1.0,
                },
                TrajectoryAt::Single,
                "trajectory.points[2].time_from_start",
            ),
            (
                ScoreError::InvalidValue {
                    field: ScoreField::JointWeights,
                    index: 1,
                    value: -1.0,
                    reason: "",
                },
                TrajectoryAt::Single,
                "options.joint_weights[1]",
            ),
            (
                ScoreError::InvalidValue {
                    field: ScoreField::AMax,
                    index: 0,
                    value: -1.0,
                    reason: "",
                },
                set,
                "options.max_acceleration[0]",
            ),
            (
                ScoreError::LengthMismatch {
                    field: ScoreField::VMax,
                    expected: 6,
                    found: 2,
                },
                TrajectoryAt::Single,
                "options.max_velocity",
            ),
            (
                ScoreError::InvalidParam {
                    name: ScoreParam::JointLogGain,
                    value: f64::NAN,
                    reason: "",
                },
                TrajectoryAt::Single,
                "options.jerk_peaks.joint_log_gain",
            ),
            (
                ScoreError::InvalidParam {
                    name: ScoreParam::PotentialTolerance,
                    value: -1.0,
                    reason: "",
                },
                TrajectoryAt::Single,
                "options.potential_tolerance",
            ),
            (
                ScoreError::DuplicateLabel { label: "a".into() },
                TrajectoryAt::Single,
                "sets",
            ),
        ];
        for (err, at, field) in cases {
            assert_eq!(field_of(err, at), field);
        }
    }

    #[test]
    fn every_parameter_is_named_after_its_struct_field() {
        use ScoreParam::*;
        for p in [
            JointLogGain,
            JointOffset,
            CartesianSqrtGain,
            CartesianOffset,
            JointMinHeight,
            CartesianMinHeight,
            SlowdownFloor,
            PotentialTolerance,
        ] {
            assert!(param_field(p).ends_with(&format!(".{}", p.name())), "{p}");
        }
    }

    #[test]
    fn errors_in_derived_data_are_internal() {
        let derived = [
            ScoreError::NonUnitQuaternion { index: 0, norm: 2.0 },
            ScoreError::NonFinite {
                field: ScoreField::Poses,
                index: 0,
                component: 0,
                value: f64::NAN,
            },
            ScoreError::LengthMismatch {
                field: ScoreField::RobotPoints,
                expected: 3,
                found: 2,
            },
        ];
        for err in derived {
            assert_eq!(
                score_error(err, TrajectoryAt::Single).code(),
                tonic::Code::Internal
            );
        }
    }
}
