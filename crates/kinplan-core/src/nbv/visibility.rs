//! Occlusion-aware prediction of what a view will reveal before the robot moves there
//! (docs/exploration.md#visibility-check).
//!
//! The intersection gain counts unknown cells in the frustum whether or not a ray can
//! reach them; cells behind an occupied surface lure views that then add nothing. The
//! prediction casts the camera's rays through the octree instead, as a depth sensor
//! would: a ray ends at its first occupied cell, and every unknown cell it enters is a
//! cell the scan may reveal. Two counts come out of one walk:
//!
//! - `first`: distinct region cells that are the **first** unknown region cell of some
//!   ray before any occupied cell. The real ray reaches that cell (every region cell
//!   before it is known free) and either passes it (free) or ends in it (occupied):
//!   either way it becomes known. It is a lower bound of what the scan adds (up to the
//!   sensor's range, the pixel grid, and unknown space outside the region, which is
//!   passed as open: the views stand in it and the planner treats it so), and the
//!   "not executed" rule uses it.
//! - `reached`: distinct region cells among the first `lookahead` unknown cells of each
//!   ray (an unknown cell is as likely to stop the ray as not; beyond a few of them the
//!   ray has probably ended). It ranks the views.
//!
//! This is the occlusion-aware ray gain of Delmerico et al., "A comparison of
//! volumetric information gain metrics for active 3D object reconstruction",
//! Autonomous Robots 42 (2018), with the visibility product cut to a fixed number of
//! unknown cells.

use nalgebra::{Isometry3, Point3};

use super::NbvError;
use super::camera::CameraModel;
use super::gain::{tree_state, walk_with};
use super::grid::{FREE, OCCUPIED, StateGrid, UNKNOWN};
use crate::Deadline;
use crate::octree::{CellState, OcKey, Octree, SearchCache, morton};

/// Options of the visibility check of [`next_best_view`](super::next_best_view).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisibilityParams {
    /// Best candidates (by the first-stage utility) predicted per batch; further
    /// batches follow until `max_results` views pass or every candidate was checked
    /// (count ≥ 1). Default 24.
    pub batch: usize,
    /// Every `pixel_stride`-th pixel of every `pixel_stride`-th row casts a ray
    /// (pixels, in [1, 64]). Default 8 (64 × 53 rays of a Kinect v2 image).
    pub pixel_stride: usize,
    /// Unknown cells a ray enters before the prediction stops following it (count ≥ 1).
    /// Default 3.
    pub lookahead: usize,
    /// Views whose lower bound `first` is below this many cells are dropped: the scan
    /// would add (almost) nothing (count ≥ 1). Default 8.
    pub min_new_cells: usize,
}

impl Default for VisibilityParams {
    fn default() -> Self {
        VisibilityParams {
            batch: 24,
            pixel_stride: 8,
            lookahead: 3,
            min_new_cells: 8,
        }
    }
}

impl VisibilityParams {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), NbvError> {
        let bad = |field, value: usize, reason| {
            Err(NbvError::InvalidParam {
                field,
                value: value as f64,
                reason,
            })
        };
        if self.batch == 0 || self.batch > 10_000 {
            return bad("visibility.batch", self.batch, "must lie in [1, 10000]");
        }
        if self.pixel_stride == 0 || self.pixel_stride > 64 {
            return bad(
                "visibility.pixel_stride",
                self.pixel_stride,
                "must lie in [1, 64]",
            );
        }
        if self.lookahead == 0 || self.lookahead > 64 {
            return bad("visibility.lookahead", self.lookahead, "must lie in [1, 64]");
        }
        if self.min_new_cells == 0 {
            return bad("visibility.min_new_cells", 0, "must be at least 1");
        }
        Ok(())
    }
}

/// What one view is predicted to reveal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ViewPrediction {
    /// Distinct region cells that are some ray's first unknown cell (lower bound).
    pub first: u32,
    /// Distinct region cells among the first `lookahead` unknown cells of the rays.
    pub reached: u32,
    /// Rays cast.
    pub rays: u32,
    /// DDA steps taken.
    pub steps: u64,
}

/// Reusable buffers of [`predict_view`].
#[derive(Debug, Default, Clone)]
pub struct PredictWorkspace {
    first: Vec<u64>,
    reached: Vec<u64>,
}

#[inline]
fn in_keys(k: &OcKey, keys: &Option<(OcKey, OcKey)>) -> bool {
    keys.as_ref()
        .is_none_or(|(a, b)| (0..3).all(|i| k[i] >= a[i] && k[i] <= b[i]))
}

/// Length at which a key list is first compacted.
const COMPACT_MIN: usize = 1 << 16;

/// Predicts what `camera` at `pose` (optical frame → map) reveals of `tree` (module
/// docs): the rays through every `pixel_stride`-th pixel (the pixel grid of the
/// simulated sensor at the same stride) are walked by a 3-D DDA from the camera centre
/// to depth `far`, each stopping at its first occupied cell or after `lookahead`
/// unknown cells with keys in `region_keys` (inclusive; `None` = all); unknown cells
/// outside it are passed as open and not counted. Cost: at most `rays · (far / res) · √3`
/// lookups. `deadline` is polled every 64 rays; a stopped view returns what it found so far.
pub fn predict_view(
    tree: &Octree,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    params: &VisibilityParams,
    region_keys: Option<(OcKey, OcKey)>,
    ws: &mut PredictWorkspace,
    deadline: Deadline<'_>,
) -> ViewPrediction {
    predict_view_in(tree, None, camera, pose, params, region_keys, ws, deadline)
}

/// [`predict_view`] reading cell states from `grid` (the tree's states over a key box,
/// one byte per cell) where it covers the key, from the tree elsewhere.
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict_view_in(
    tree: &Octree,
    grid: Option<&StateGrid>,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    params: &VisibilityParams,
    region_keys: Option<(OcKey, OcKey)>,
    ws: &mut PredictWorkspace,
    deadline: Deadline<'_>,
) -> ViewPrediction {
    let mut cache = SearchCache::default();
    let mut lookup = |k: &OcKey| match grid.and_then(|g| g.index_of(k).map(|i| g.cells[i])) {
        Some(UNKNOWN) => (CellState::Unknown, None),
        Some(FREE) => (CellState::Free, None),
        Some(OCCUPIED) => (CellState::Occupied, None),
        _ => tree_state(tree, k, &mut cache),
    };
    let stride = params.pixel_stride.max(1);
    let origin = Point3::from(pose.translation.vector);
    ws.first.clear();
    ws.reached.clear();
    let mut out = ViewPrediction::default();
    // The key lists are compacted (sorted, deduplicated) whenever they have
    // doubled since the last compaction: memory stays within twice the
    // distinct cells, not rays × lookahead.
    let mut compact_at = [COMPACT_MIN; 2];
    'rows: for v in (0..camera.height).step_by(stride) {
        for u in (0..camera.width).step_by(stride) {
            if out.rays % 64 == 63 && deadline.expired() {
                break 'rows;
            }
            out.rays += 1;
            let local = camera.ray_direction(u, v);
            let dir = pose.rotation * local;
            let mut unknown = 0usize;
            out.steps += walk_with(
                tree,
                &origin,
                &dir,
                0.0,
                camera.far / local.z,
                &mut lookup,
                |k, state, _| match state {
                    CellState::Occupied => false,
                    CellState::Free => true,
                    // unknown space outside the region is passed as open (the
                    // views stand in it; the planner treats it so too)
                    CellState::Unknown if !in_keys(k, &region_keys) => true,
                    CellState::Unknown => {
                        unknown += 1;
                        let m = morton(k);
                        if unknown == 1 {
                            ws.first.push(m);
                        }
                        ws.reached.push(m);
                        unknown < params.lookahead
                    }
                },
            );
            for (list, at) in [&mut ws.first, &mut ws.reached].into_iter().zip(&mut compact_at) {
                if list.len() >= *at {
                    list.sort_unstable();
                    list.dedup();
                    *at = (2 * list.len()).max(COMPACT_MIN);
                }
            }
        }
    }
    for v in [&mut ws.first, &mut ws.reached] {
        v.sort_unstable();
        v.dedup();
    }
    out.first = ws.first.len() as u32;
    out.reached = ws.reached.len() as u32;
    out
}
