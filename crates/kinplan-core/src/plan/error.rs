//! The one error type of the `plan` room: requests that cannot be served.
//! No path, a colliding start, running out of time: statuses in the result
//! ([`PlanStatus`](super::PlanStatus)), never errors.

use std::fmt;

/// Which request field or parameter an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PlanField {
    Start,
    GoalJoints,
    GoalPose,
    Timesteps,
    Rollouts,
    MaxRollouts,
    MaxIterations,
    IterationsAfterValid,
    NoiseStddev,
    CostSensitivity,
    ControlCostWeight,
    CollisionPenalty,
    KernelHalfWidth,
    ClearanceDistance,
    ClearanceWeight,
    JointLimitWeight,
    TranslationTolerance,
    RotationTolerance,
    TranslationWeight,
    RotationWeight,
    TranslationStddev,
    RotationStddev,
    ViolationPenalty,
    IkIterations,
    RrtRange,
    RrtMaxSamples,
    ShortcutAttempts,
    ShortcutResolution,
    VelocityLimits,
    AccelerationLimits,
    VelocityScale,
    JerkLimits,
    PathTolerance,
    StartVelocity,
    SamplePeriod,
    GridStep,
    /// The waypoints of a path to time.
    Waypoints,
}

impl PlanField {
    /// The field's name as a request would spell it.
    pub fn name(self) -> &'static str {
        match self {
            PlanField::Start => "start",
            PlanField::GoalJoints => "goal.joints",
            PlanField::GoalPose => "goal.pose",
            PlanField::Timesteps => "stomp.timesteps",
            PlanField::Rollouts => "stomp.rollouts",
            PlanField::MaxRollouts => "stomp.max_rollouts",
            PlanField::MaxIterations => "stomp.max_iterations",
            PlanField::IterationsAfterValid => "stomp.iterations_after_valid",
            PlanField::NoiseStddev => "stomp.noise_stddev",
            PlanField::CostSensitivity => "stomp.cost_sensitivity",
            PlanField::ControlCostWeight => "stomp.control_cost_weight",
            PlanField::CollisionPenalty => "stomp.collision_penalty",
            PlanField::KernelHalfWidth => "stomp.kernel_half_width",
            PlanField::ClearanceDistance => "stomp.clearance_distance",
            PlanField::ClearanceWeight => "stomp.clearance_weight",
            PlanField::JointLimitWeight => "stomp.joint_limit_weight",
            PlanField::TranslationTolerance => "cartesian.translation_tolerance",
            PlanField::RotationTolerance => "cartesian.rotation_tolerance",
            PlanField::TranslationWeight => "cartesian.translation_weight",
            PlanField::RotationWeight => "cartesian.rotation_weight",
            PlanField::TranslationStddev => "cartesian.translation_stddev",
            PlanField::RotationStddev => "cartesian.rotation_stddev",
            PlanField::ViolationPenalty => "cartesian.violation_penalty",
            PlanField::IkIterations => "cartesian.ik_iterations",
            PlanField::RrtRange => "rrt.range",
            PlanField::RrtMaxSamples => "rrt.max_samples",
            PlanField::ShortcutAttempts => "rrt.shortcut_attempts",
            PlanField::ShortcutResolution => "rrt.shortcut_resolution",
            PlanField::VelocityLimits => "timing.velocity_limits",
            PlanField::AccelerationLimits => "timing.acceleration_limits",
            PlanField::VelocityScale => "timing.velocity_scale",
            PlanField::JerkLimits => "timing.jerk_limits",
            PlanField::PathTolerance => "timing.path_tolerance",
            PlanField::StartVelocity => "timing.start_velocity",
            PlanField::SamplePeriod => "timing.sample_period",
            PlanField::GridStep => "timing.grid_step",
            PlanField::Waypoints => "waypoints",
        }
    }
}

impl fmt::Display for PlanField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a planning request was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("the chain has no moving joints")]
    EmptyChain,
    #[error("the checker has {checker} joints, the chain has {chain}")]
    CheckerDof { chain: usize, checker: usize },
    #[error("{field} has {got} values, expected {expected}")]
    WrongLength {
        field: PlanField,
        expected: usize,
        got: usize,
    },
    #[error("{field}[{index}] is not finite")]
    NonFinite { field: PlanField, index: usize },
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: PlanField,
        value: f64,
        reason: &'static str,
    },
    #[error("the deadline passed or the caller cancelled while timing the path")]
    Interrupted,
    #[error("goal IK parameters: {0}")]
    GoalIk(#[from] crate::ik::IkError),
}

/// `Err(InvalidParam)` unless `ok`.
pub(crate) fn require(ok: bool, field: PlanField, value: f64, reason: &'static str) -> Result<(), PlanError> {
    if ok {
        Ok(())
    } else {
        Err(PlanError::InvalidParam { field, value, reason })
    }
}

/// Checks that `values` has `expected` finite entries.
pub(crate) fn check_vector(field: PlanField, values: &[f64], expected: usize) -> Result<(), PlanError> {
    if values.len() != expected {
        return Err(PlanError::WrongLength {
            field,
            expected,
            got: values.len(),
        });
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(PlanError::NonFinite { field, index }),
        None => Ok(()),
    }
}
