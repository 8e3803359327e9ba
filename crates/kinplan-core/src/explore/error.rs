//! Errors of [`explore`](super::explore): bad parameters, named by field.

use thiserror::Error;

use crate::collision::CollisionError;
use crate::nbv::NbvError;
use crate::octree::OctreeError;
use crate::plan::PlanError;

/// The exploration fields a bad value can sit in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExploreField {
    Start,
    Region,
    Resolution,
    CameraMount,
    PixelStride,
    NoiseStddev,
    NearRaySpacing,
    KnownRatio,
    MaxIterations,
    ConsecutiveFailures,
    CandidatesPerIteration,
    ExtraViews,
    PlanTimeBudget,
    InitialOffsets,
}

impl ExploreField {
    /// The field's name in the parameter structs (snake case).
    pub fn name(self) -> &'static str {
        match self {
            ExploreField::Start => "start",
            ExploreField::Region => "region",
            ExploreField::Resolution => "resolution",
            ExploreField::CameraMount => "camera_mount",
            ExploreField::PixelStride => "sensor.pixel_stride",
            ExploreField::NoiseStddev => "sensor.noise_stddev",
            ExploreField::NearRaySpacing => "sensor.near_ray_spacing",
            ExploreField::KnownRatio => "stop.known_ratio",
            ExploreField::MaxIterations => "stop.max_iterations",
            ExploreField::ConsecutiveFailures => "stop.max_consecutive_failures",
            ExploreField::CandidatesPerIteration => "candidates_per_iteration",
            ExploreField::ExtraViews => "extra_views",
            ExploreField::PlanTimeBudget => "plan_time_budget",
            ExploreField::InitialOffsets => "initial_offsets",
        }
    }
}

/// Why [`explore`](super::explore) refused to start.
#[derive(Debug, Error)]
pub enum ExploreError {
    #[error("{}: {reason}", field.name())]
    InvalidParam { field: ExploreField, reason: String },
    #[error(transparent)]
    Nbv(#[from] NbvError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    #[error(transparent)]
    Collision(#[from] CollisionError),
    #[error(transparent)]
    Octree(#[from] OctreeError),
}

impl ExploreError {
    pub(crate) fn invalid(field: ExploreField, reason: impl Into<String>) -> Self {
        ExploreError::InvalidParam {
            field,
            reason: reason.into(),
        }
    }
}
