//! `plan` room errors into statuses: each [`PlanField`] becomes the
//! `PlanRequest` field it comes from.

use tonic::Status;

use super::invalid;
use kinplan_core::plan::{PlanError, PlanField};

/// The request field a plan-room parameter comes from.
pub fn plan_field(field: PlanField) -> &'static str {
    match field {
        PlanField::Start => "start",
        PlanField::GoalJoints => "goal_joints.positions",
        PlanField::GoalPose => "goal_pose",
        PlanField::Timesteps => "options.stomp.timesteps",
        PlanField::Rollouts => "options.stomp.rollouts",
        PlanField::MaxRollouts => "options.stomp.max_rollouts",
        PlanField::MaxIterations => "options.stomp.max_iterations",
        PlanField::IterationsAfterValid => "options.stomp.iterations_after_valid",
        PlanField::NoiseStddev => "options.stomp.noise_stddev",
        PlanField::CostSensitivity => "options.stomp.cost_sensitivity",
        PlanField::ControlCostWeight => "options.stomp.control_cost_weight",
        PlanField::CollisionPenalty => "options.stomp.collision_penalty",
        PlanField::KernelHalfWidth => "options.stomp.kernel_half_width",
        PlanField::ClearanceDistance => "options.stomp.clearance_distance",
        PlanField::ClearanceWeight => "options.stomp.clearance_weight",
        PlanField::JointLimitWeight => "options.stomp.joint_limit_weight",
        PlanField::TranslationTolerance => "options.cartesian.translation_tolerance",
        PlanField::RotationTolerance => "options.cartesian.rotation_tolerance",
        PlanField::TranslationWeight => "options.cartesian.translation_weight",
        PlanField::RotationWeight => "options.cartesian.rotation_weight",
        PlanField::TranslationStddev => "options.cartesian.translation_stddev",
        PlanField::RotationStddev => "options.cartesian.rotation_stddev",
        PlanField::ViolationPenalty => "options.cartesian.violation_penalty",
        PlanField::IkIterations => "options.cartesian.ik_iterations",
        PlanField::RrtRange => "options.rrt_connect.range",
        PlanField::RrtMaxSamples => "options.rrt_connect.max_samples",
        PlanField::ShortcutAttempts => "options.rrt_connect.shortcut_attempts",
        // not exposed in the proto; named as the core names it
        PlanField::ShortcutResolution => "rrt.shortcut_resolution",
        PlanField::VelocityLimits => "options.timing.max_velocity",
        PlanField::AccelerationLimits => "options.timing.max_acceleration",
        PlanField::VelocityScale => "options.timing.velocity_scale",
        PlanField::JerkLimits => "options.timing.max_jerk",
        PlanField::PathTolerance => "options.timing.path_tolerance",
        PlanField::StartVelocity => "options.timing.start_velocity",
        PlanField::SamplePeriod => "options.timing.sample_period",
        PlanField::GridStep => "options.timing.grid_step",
        PlanField::Waypoints => "waypoints",
    }
}

/// INVALID_ARGUMENT naming the request field behind a refused plan; INTERNAL
/// for what the service itself built wrong; DEADLINE_EXCEEDED when the
/// timing was cut short.
pub fn plan_error(err: PlanError) -> Status {
    error_at(err, |f| plan_field(f).to_owned())
}

/// As [`plan_error`] for a `RetimeRequest`, whose timing options sit at
/// `timing` instead of `options.timing`.
pub fn retime_error(err: PlanError) -> Status {
    error_at(err, |f| {
        let name = plan_field(f);
        name.strip_prefix("options.").unwrap_or(name).to_owned()
    })
}

fn error_at(err: PlanError, name: impl Fn(PlanField) -> String) -> Status {
    let text = err.to_string();
    match err {
        PlanError::EmptyChain => invalid("robot", text),
        PlanError::WrongLength { field, .. } | PlanError::InvalidParam { field, .. } => {
            invalid(name(field), text)
        }
        PlanError::NonFinite { field, index } => match field {
            PlanField::GoalPose => invalid(name(field), text),
            _ => invalid(format!("{}[{index}]", name(field)), text),
        },
        PlanError::Interrupted => Status::deadline_exceeded(text),
        PlanError::CheckerDof { .. } | PlanError::GoalIk(_) => {
            tracing::error!(error = %text, "planning rejected service-built input");
            Status::internal(format!("planning failed on service-built input: {text}"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(err: PlanError) -> String {
        let status = plan_error(err);
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
        assert_eq!(field_of(PlanError::EmptyChain), "robot");
        assert_eq!(
            field_of(PlanError::NonFinite {
                field: PlanField::Start,
                index: 2
            }),
            "start[2]"
        );
        assert_eq!(
            field_of(PlanError::NonFinite {
                field: PlanField::GoalPose,
                index: 4
            }),
            "goal_pose"
        );
        assert_eq!(
            field_of(PlanError::WrongLength {
                field: PlanField::GoalJoints,
                expected: 6,
                got: 5
            }),
            "goal_joints.positions"
        );
        assert_eq!(
            field_of(PlanError::InvalidParam {
                field: PlanField::RrtRange,
                value: 0.0,
                reason: ""
            }),
            "options.rrt_connect.range"
        );
        assert_eq!(
            field_of(PlanError::InvalidParam {
                field: PlanField::VelocityLimits,
                value: 0.0,
                reason: ""
            }),
            "options.timing.max_velocity"
        );
    }

    #[test]
    fn service_built_input_is_internal() {
        let err = PlanError::CheckerDof { chain: 6, checker: 7 };
        assert_eq!(plan_error(err).code(), tonic::Code::Internal);
    }

    #[test]
    fn option_fields_keep_the_domain_names_below_their_group() {
        // stomp.* / cartesian.* / timing.velocity_scale keep the domain's leaf name
        for f in [
            PlanField::Timesteps,
            PlanField::NoiseStddev,
            PlanField::IkIterations,
            PlanField::VelocityScale,
        ] {
            assert_eq!(plan_field(f), format!("options.{}", f.name()));
        }
    }
}
