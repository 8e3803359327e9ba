//! OctoMap-compatible occupancy octree: keys, arena nodes, `.bt`/`.ot`/ROS-message IO,
//! queries, ray casting and scan integration (docs/octree.md).

mod batch;
mod counts;
mod error;
mod frame;
mod grid;
mod header;
mod io;
mod key;
mod params;
mod plan;
mod project;
mod query;
mod ray;
mod scan;
mod tree;

#[cfg(test)]
mod frame_tests;
#[cfg(test)]
mod ray_tests;
#[cfg(test)]
mod tests;

pub use counts::{CountBlock, KnownCellCounts};
pub use error::OctreeError;
pub use header::{BT_FIRST_LINE, OT_FIRST_LINE};
pub(crate) use key::morton;
pub use key::{
    OcKey, TREE_DEPTH, TREE_MAX_VAL, child_index, child_key, coord_to_key_axis, key_at_depth,
    key_to_coord_axis, key_to_coord_axis_at, logodds, probability,
};
pub use params::{LogOddsModel, OctreeLimits, SensorModel};
pub use query::{BoxVolumes, CellVisit, StateFilter};
pub use ray::{RayHit, RayParams, RayStop};
pub use scan::{
    MAX_DEPTH_PIXELS, NEAR_RAY_SPACING, PinholeIntrinsics, ScanParams, ScanStats, ScanStatus,
    depth_from_millimetres, depth_image_points,
};
pub use tree::{CellState, MAX_RESOLUTION, MIN_RESOLUTION, NodeRef, Octree, SearchCache};
