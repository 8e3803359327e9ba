//! Next-best-view selection on occupancy octrees: frontier candidates with a potential
//! field, ORF → PTF → IGF filters, information gain by frustum intersection or ray
//! casting, utility and IK reachability (docs/exploration.md, S0 §4).

mod camera;
mod count;
mod error;
mod frontier;
mod gain;
mod grid;
mod params;
mod select;
mod visibility;

#[cfg(test)]
mod count_tests;
#[cfg(test)]
mod tests;

pub use camera::{CameraModel, Frustum, look_along};
pub use count::FrustumCounter;
pub use error::NbvError;
pub use frontier::{Frontier, candidate_pose, frontier_cells, potential_field, potential_field_cubes};
pub use gain::{
    GainMethod, GainWorkspace, ViewGain, frustum_unknown_count, frustum_unknown_count_in, ray_gain, walk,
};
pub use params::{NbvParams, Weights};
pub use select::{NbvCandidate, NbvResult, NbvStatus, StageStats, estimate_reach, next_best_view};
pub use visibility::{PredictWorkspace, ViewPrediction, VisibilityParams, predict_view};
