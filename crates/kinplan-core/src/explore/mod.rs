//! Exploration of an unknown cell end to end (docs/exploration.md#the-exploration-loop, S0 §4–5): a
//! simulated depth camera, reference scenes, and the loop NBV → IK → plan →
//! execute → scan → insert.

mod depth_camera;
mod error;
mod params;
mod run;
mod scenes;
mod world_model;

#[cfg(test)]
mod tests;

pub use depth_camera::{
    DepthImage, SensorParams, depth_to_points, render_depth, render_depth_until, strided_intrinsics,
};
pub use error::{ExploreError, ExploreField};
pub use params::{ExploreParams, MAX_RAYS_PER_IMAGE, MAX_REGION_CELLS, StopRule};
pub use run::{
    ChosenView, CriteriaTotals, ExploreControl, ExploreOutcome, ExploreStatus, ExploreStep, ExploreWorld,
    Motion, StageTimes, ViewFailure, explore,
};
pub use scenes::{ReferenceScene, s0_open_cell, s0_walled_cell};
pub use world_model::{ObservableCells, occupied_obstacles};
