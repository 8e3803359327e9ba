//! `explore` room errors into statuses: each [`ExploreField`] becomes the
//! `ExploreRequest` field it comes from; errors of the rooms the loop drives
//! name the request message that configures them.

use tonic::Status;

use super::invalid;
use kinplan_core::explore::{ExploreError, ExploreField};

/// The `ExploreRequest` field of an exploration parameter.
pub fn explore_field(field: ExploreField) -> &'static str {
    match field {
        ExploreField::Start => "start",
        ExploreField::Region => "region",
        ExploreField::Resolution => "resolution",
        ExploreField::CameraMount => "camera_mount",
        ExploreField::PixelStride => "pixel_stride",
        ExploreField::NoiseStddev => "noise_stddev",
        ExploreField::NearRaySpacing => "near_ray_spacing",
        ExploreField::KnownRatio => "stop.known_ratio",
        ExploreField::MaxIterations => "stop.max_iterations",
        ExploreField::ConsecutiveFailures => "stop.max_consecutive_failures",
        ExploreField::CandidatesPerIteration => "candidates_per_iteration",
        ExploreField::ExtraViews => "extra_views",
        ExploreField::PlanTimeBudget => "plan_time_budget",
        ExploreField::InitialOffsets => "initial_offsets",
    }
}

/// INVALID_ARGUMENT naming the request field behind an [`ExploreError`].
pub fn explore_error(e: ExploreError) -> Status {
    match e {
        ExploreError::InvalidParam { field, reason } => invalid(explore_field(field), reason),
        ExploreError::Nbv(e) => invalid("nbv", e.to_string()),
        ExploreError::Plan(e) => invalid("plan_options", e.to_string()),
        ExploreError::Collision(e) => invalid("scene", e.to_string()),
        ExploreError::Octree(e) => invalid("resolution", e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_name_request_fields() {
        for (field, path) in [
            (ExploreField::Start, "start"),
            (ExploreField::PixelStride, "pixel_stride"),
            (ExploreField::NoiseStddev, "noise_stddev"),
            (ExploreField::NearRaySpacing, "near_ray_spacing"),
            (ExploreField::KnownRatio, "stop.known_ratio"),
            (ExploreField::ConsecutiveFailures, "stop.max_consecutive_failures"),
        ] {
            let status = explore_error(ExploreError::InvalidParam {
                field,
                reason: "bad".into(),
            });
            assert_eq!(status.code(), tonic::Code::InvalidArgument);
            assert_eq!(status.message(), format!("{path}: bad"));
        }
    }
}
