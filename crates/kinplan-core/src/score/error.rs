//! The one error type of the `score` room: bad input and bad parameters,
//! naming the offending input field or parameter by a typed identifier
//! ([`ScoreField`], [`ScoreParam`]) the service layer turns into its own names.

use std::fmt;

/// An input field of [`ScoreInput`](super::ScoreInput) /
/// [`TrajectoryData`](super::TrajectoryData) an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScoreField {
    /// `TrajectoryData::joints`.
    Joints,
    /// `TrajectoryData::poses`.
    Poses,
    /// `TrajectoryData::robot_points`.
    RobotPoints,
    /// `TrajectoryData::timestamps`.
    Timestamps,
    /// `ScoreInput::joint_weights`.
    JointWeights,
    /// `JointLimits::v_max`.
    VMax,
    /// `JointLimits::a_max`.
    AMax,
}

impl ScoreField {
    /// The field's name as the input structs spell it.
    pub fn name(self) -> &'static str {
        match self {
            ScoreField::Joints => "joints",
            ScoreField::Poses => "poses",
            ScoreField::RobotPoints => "robot_points",
            ScoreField::Timestamps => "timestamps",
            ScoreField::JointWeights => "joint_weights",
            ScoreField::VMax => "v_max",
            ScoreField::AMax => "a_max",
        }
    }
}

impl fmt::Display for ScoreField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A parameter of [`JerkPeakParams`](super::JerkPeakParams) or
/// [`CycleTimeParams`](super::CycleTimeParams) an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScoreParam {
    JointLogGain,
    JointOffset,
    CartesianSqrtGain,
    CartesianOffset,
    JointMinHeight,
    CartesianMinHeight,
    SlowdownFloor,
    PotentialTolerance,
}

impl ScoreParam {
    /// The parameter's name as the parameter structs spell it.
    pub fn name(self) -> &'static str {
        match self {
            ScoreParam::JointLogGain => "joint_log_gain",
            ScoreParam::JointOffset => "joint_offset",
            ScoreParam::CartesianSqrtGain => "cartesian_sqrt_gain",
            ScoreParam::CartesianOffset => "cartesian_offset",
            ScoreParam::JointMinHeight => "joint_min_height",
            ScoreParam::CartesianMinHeight => "cartesian_min_height",
            ScoreParam::SlowdownFloor => "slowdown_floor",
            ScoreParam::PotentialTolerance => "potential_tolerance",
        }
    }
}

impl fmt::Display for ScoreParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything that makes a scoring request unanswerable.
///
/// Each variant names the offending field (as the input struct spells it) and,
/// where it applies, the waypoint index and joint/point component, so the service
/// layer can turn it into a field violation without guessing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScoreError {
    /// A row has a different length from the first row of the same field.
    #[error("{field}[{index}] has {found} entries, expected {expected} like row 0")]
    RaggedRow {
        /// Input field, e.g. joints or robot points.
        field: ScoreField,
        /// Waypoint index of the bad row.
        index: usize,
        /// Length of row 0.
        expected: usize,
        /// Length of this row.
        found: usize,
    },
    /// A joint row does not have the robot's number of joints.
    #[error("joints[{index}] has {found} joints, the robot has {expected}")]
    WrongJointCount {
        /// Waypoint index of the bad row.
        index: usize,
        /// The robot's joint count (`ScoreInput::dof`).
        expected: usize,
        /// Length of this row.
        found: usize,
    },
    /// Waypoints with zero joints.
    #[error("joints: rows have no joints")]
    NoJoints,
    /// A flat row-major buffer whose length is not a multiple of its row width,
    /// or a zero width with data.
    #[error("{field}: flat buffer of {len} values does not split into rows of {width}")]
    FlatShape {
        /// Input field.
        field: ScoreField,
        /// Number of values in the buffer.
        len: usize,
        /// Declared row width.
        width: usize,
    },
    /// A per-waypoint or per-joint field has the wrong number of entries.
    #[error("{field} has {found} entries, expected {expected}")]
    LengthMismatch {
        /// Input field, e.g. poses, timestamps, joint weights, `v_max`.
        field: ScoreField,
        /// Required count (waypoints or joints).
        expected: usize,
        /// Given count.
        found: usize,
    },
    /// NaN or infinity where a finite number is needed.
    #[error("{field}[{index}][{component}] is not finite ({value})")]
    NonFinite {
        /// Input field.
        field: ScoreField,
        /// Waypoint (or joint) index.
        index: usize,
        /// Component inside the row: joint index, point index × 3 + axis, or for
        /// poses 0–2 translation x,y,z and 3–6 quaternion i,j,k,w.
        component: usize,
        /// The offending value.
        value: f64,
    },
    /// A pose whose rotation quaternion is not of unit norm.
    #[error("poses[{index}] rotation quaternion has norm {norm}, expected 1")]
    NonUnitQuaternion {
        /// Waypoint index.
        index: usize,
        /// Its Euclidean norm.
        norm: f64,
    },
    /// Timestamps must increase strictly.
    #[error("timestamps[{index}] = {value} s does not exceed timestamps[{}] = {previous} s", .index.saturating_sub(1))]
    NonIncreasingTimestamp {
        /// Index of the first timestamp not greater than its predecessor (≥ 1).
        index: usize,
        /// The predecessor's value, seconds.
        previous: f64,
        /// This value, seconds.
        value: f64,
    },
    /// A per-joint value outside its allowed range (e.g. a negative weight,
    /// a zero velocity limit).
    #[error("{field}[{index}] = {value}: {reason}")]
    InvalidValue {
        /// Input field.
        field: ScoreField,
        /// Joint index.
        index: usize,
        /// The offending value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A parameter outside its allowed range.
    #[error("parameter {name} = {value}: {reason}")]
    InvalidParam {
        /// The parameter.
        name: ScoreParam,
        /// The offending value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A comparison set without trajectories.
    #[error("comparison set {label:?} has no trajectories")]
    EmptySet {
        /// The set's label.
        label: String,
    },
    /// Two comparison sets with the same label.
    #[error("comparison label {label:?} is used twice")]
    DuplicateLabel {
        /// The repeated label.
        label: String,
    },
}
