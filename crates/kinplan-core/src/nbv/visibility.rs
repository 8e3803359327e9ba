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

use std::hint::select_unpredictable;

use nalgebra::{Isometry3, Point3, Vector3};

use super::NbvError;
use super::camera::CameraModel;
use super::gain::{dda_start, tree_state, walk_with};
use super::grid::{FREE, OCCUPIED, OUTSIDE, StateGrid, UNKNOWN};
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
    /// (pixels, in [1, 64], and at most [`MAX_VIEW_RAYS`] rays per view for the
    /// camera). Default 8 (64 × 53 rays of a Kinect v2 image).
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

    /// [`Self::validate`], and the rays one view casts with `camera` at most
    /// [`MAX_VIEW_RAYS`]: the check keeps a table of them for the request.
    pub fn validate_for(&self, camera: &CameraModel) -> Result<(), NbvError> {
        self.validate()?;
        let stride = self.pixel_stride;
        let rays = camera
            .width
            .div_ceil(stride)
            .saturating_mul(camera.height.div_ceil(stride));
        if rays > MAX_VIEW_RAYS {
            return Err(NbvError::InvalidParam {
                field: "visibility.pixel_stride",
                value: stride as f64,
                reason: "casts more than 2^20 rays per view with this camera (⌈width/stride⌉·⌈height/stride⌉); take a larger stride",
            });
        }
        Ok(())
    }
}

/// Most rays one view of the visibility check casts.
pub const MAX_VIEW_RAYS: usize = 1 << 20;

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
    /// One bit per region cell (the grid path): some ray's first unknown cell.
    first_bits: Vec<u64>,
    /// One bit per region cell (the grid path): among some ray's first unknown cells.
    reached_bits: Vec<u64>,
}

/// Largest region (cells) the grid path marks in bit sets: 2^22 cells, two bit sets of
/// 512 KiB per workspace. Larger regions take the key lists.
const MAX_BITSET_CELLS: usize = 1 << 22;

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
    let tangents = camera.half_tangents();
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
            let local = camera.ray_direction_with(tangents, u, v);
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

/// The state grid recoded for the visibility walk over one region: unknown cells
/// outside the region read as free (the walk passes them as open), and one layer of
/// [`OUTSIDE`] cells around the grid, so that the walk's inner loop meets only four
/// kinds of cell: free (go on), unknown region cells (count), occupied (stop) and
/// outside, past the grid or the key space (stop before it). Built once per request
/// and shared by every predicted view.
#[derive(Debug, Clone)]
pub(crate) struct ViewGrid {
    /// Lowest key of the state grid (the layer around it starts one cell lower).
    lo: [i64; 3],
    /// Cells of the state grid per axis (the padded grid has two more).
    inner: [usize; 3],
    /// Padded cells per axis.
    dims: [usize; 3],
    cells: Vec<u8>,
    /// The region's lowest key (its box lies inside the grid).
    rlo: OcKey,
    /// Cells of the region box per axis.
    rdims: [usize; 3],
    /// Per ray of the camera's strided pixel grid (rows, then columns): its unit
    /// direction in the optical frame and its parameter at depth `far`.
    rays: Vec<(Vector3<f64>, f64)>,
    /// The camera and stride the rays were built for (the walks take no other).
    rays_for: (CameraModel, usize),
}

impl ViewGrid {
    /// The view grid of `grid` recoded in place: its outermost layer becomes the
    /// outside layer, the rest (at least one cell of `grid` on every axis) the grid the
    /// walks read, with the rays of `camera` at `stride`. The state grid is given back
    /// when the region `[rlo, rhi]` is empty, not inside the inner grid, or has more
    /// than [`MAX_BITSET_CELLS`] cells (the caller then takes the key lists).
    pub fn from_padded(
        mut grid: StateGrid,
        (rlo, rhi): (OcKey, OcKey),
        camera: &CameraModel,
        stride: usize,
    ) -> Result<Self, StateGrid> {
        let dims = grid.dims;
        let lo = grid.lo.map(|v| v + 1);
        let mut rdims = [0usize; 3];
        for i in 0..3 {
            if dims[i] < 3
                || rlo[i] > rhi[i]
                || (rlo[i] as i64) < lo[i]
                || rhi[i] as i64 >= lo[i] + dims[i] as i64 - 2
            {
                return Err(grid);
            }
            rdims[i] = (rhi[i] - rlo[i]) as usize + 1;
        }
        if rdims[0] * rdims[1] * rdims[2] > MAX_BITSET_CELLS {
            return Err(grid);
        }
        let [nx, ny, nz] = dims;
        // region offsets in the padded grid, per axis
        let o = [0, 1, 2].map(|i| (rlo[i] as i64 - grid.lo[i]) as usize);
        let e = [0, 1, 2].map(|i| (rhi[i] as i64 - grid.lo[i]) as usize);
        for (z, plane) in grid.cells.chunks_mut(nx * ny).enumerate() {
            for (y, row) in plane.chunks_mut(nx).enumerate() {
                if z == 0 || z == nz - 1 || y == 0 || y == ny - 1 {
                    row.fill(OUTSIDE);
                    continue;
                }
                open_outside_region(row, y, z, &o, &e);
                row[0] = OUTSIDE;
                row[nx - 1] = OUTSIDE;
            }
        }
        let stride = stride.max(1);
        Ok(Self {
            lo,
            inner: dims.map(|d| d - 2),
            dims,
            cells: grid.cells,
            rlo,
            rdims,
            rays: camera_rays(camera, stride),
            rays_for: (*camera, stride),
        })
    }

    /// Whether `k` lies inside the state grid.
    #[inline]
    fn contains(&self, k: &OcKey) -> bool {
        (0..3).all(|i| k[i] as i64 >= self.lo[i] && (k[i] as i64) < self.lo[i] + self.inner[i] as i64)
    }

    /// Index in the region box of the cell at grid index `idx`, which must lie in it.
    #[inline]
    fn region_index(&self, idx: usize) -> usize {
        // grids hold at most 2^24 cells: 32-bit divisions
        let (nx, plane) = (self.dims[0] as u32, (self.dims[0] * self.dims[1]) as u32);
        let i = idx as u32;
        let (z, rest) = (i / plane, i % plane);
        let g = [rest % nx, rest / nx, z].map(|v| v as usize);
        // padded offsets are one more than the state grid's
        let r = [0, 1, 2].map(|i| (g[i] as i64 - 1 + self.lo[i] - self.rlo[i] as i64) as usize);
        debug_assert!((0..3).all(|i| r[i] < self.rdims[i]));
        r[0] + self.rdims[0] * (r[1] + self.rdims[1] * r[2])
    }
}

/// Opens the cells of grid row (`y`, `z`) that lie outside the region
/// `o..=e` (grid offsets per axis): unknown space outside the region is read
/// as free.
fn open_outside_region(row: &mut [u8], y: usize, z: usize, o: &[usize; 3], e: &[usize; 3]) {
    if (o[1]..=e[1]).contains(&y) && (o[2]..=e[2]).contains(&z) {
        let (head, rest) = row.split_at_mut(o[0]);
        open(head);
        open(&mut rest[e[0] - o[0] + 1..]);
    } else {
        open(row);
    }
}

/// Unknown cells (0) become free (1); the other states keep their codes.
fn open(row: &mut [u8]) {
    for c in row {
        *c += (*c == UNKNOWN) as u8;
    }
}

/// The rays through every `stride`-th pixel of every `stride`-th row (rows, then
/// columns), each as its unit direction in the optical frame and its parameter at
/// depth `far`, computed as [`predict_view_in`] computes them per ray.
fn camera_rays(camera: &CameraModel, stride: usize) -> Vec<(Vector3<f64>, f64)> {
    let tangents = camera.half_tangents();
    let mut rays = Vec::with_capacity(camera.height.div_ceil(stride) * camera.width.div_ceil(stride));
    for v in (0..camera.height).step_by(stride) {
        for u in (0..camera.width).step_by(stride) {
            let local = camera.ray_direction_with(tangents, u, v);
            rays.push((local, camera.far / local.z));
        }
    }
    rays
}

/// The prediction of [`predict_view_in`] on a [`ViewGrid`] of the region: the same
/// rays and the same DDA (Amanatides & Woo, as [`walk_with`]: the same floating-point
/// operations in the same order, so the same cells), with the cell states read from
/// the grid by index and the distinct region cells marked in bit sets instead of
/// sorted key lists. A ray that has been inside the grid and leaves it is stopped
/// there: the grid's box is convex and holds the region, so the straight ray cannot
/// meet a region cell again and nothing further can be counted (only the reported DDA
/// steps are fewer). Before a ray enters the grid, cells are read from the tree.
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict_on_grid(
    tree: &Octree,
    grid: &ViewGrid,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    params: &VisibilityParams,
    ws: &mut PredictWorkspace,
    deadline: Deadline<'_>,
) -> ViewPrediction {
    let (glo, pdims) = (grid.lo, grid.dims);
    let words = (grid.rdims[0] * grid.rdims[1] * grid.rdims[2]).div_ceil(64);
    for bits in [&mut ws.first_bits, &mut ws.reached_bits] {
        bits.clear();
        bits.resize(words, 0);
    }
    let (first_bits, reached_bits) = (&mut ws.first_bits[..], &mut ws.reached_bits[..]);
    let cells = &grid.cells[..];
    let mut cache = SearchCache::default();
    let res = tree.resolution();
    let stride = params.pixel_stride.max(1);
    let origin = Point3::from(pose.translation.vector);
    let mut out = ViewPrediction::default();
    let (mut first, mut reached) = (0u32, 0u32);
    let Ok(k0) = tree.key_of(&origin) else {
        // every ray starts outside the key space: the DDA takes no step
        out.rays = camera.height.div_ceil(stride) as u32 * camera.width.div_ceil(stride) as u32;
        return out;
    };
    let lookahead = params.lookahead;
    assert!(
        grid.rays_for == (*camera, stride),
        "a view grid walks the rays it was built for"
    );
    'ray: for &(local, t1) in &grid.rays {
        if out.rays % 64 == 63 && deadline.expired() {
            break 'ray;
        }
        out.rays += 1;
        let dir = pose.rotation * local;
        // the DDA set-up of `walk_with` from t0 = 0
        let mut k = k0;
        let (step, mut t_max, t_delta) = dda_start(&k, &origin, &dir, 0.0, res);
        // phase 1: outside the grid, states from the tree, until the ray enters it
        while !grid.contains(&k) {
            out.steps += 1;
            if tree_state(tree, &k, &mut cache).0 == CellState::Occupied {
                continue 'ray;
            }
            let a = next_axis(&t_max);
            if t_max[a] > t1 {
                continue 'ray;
            }
            let nk = k[a] as i32 + step[a];
            if !(0..65536).contains(&nk) {
                continue 'ray;
            }
            k[a] = nk as u16;
            t_max[a] += t_delta[a];
        }
        // phase 2: inside the grid, each step branch-free but for the cell's state
        // and the far end: the axis of `next_axis` from the comparisons x < y and
        // min(x, y) < z, applied by masks. The walk ends on an occupied cell, after
        // `lookahead` unknown region cells, past `t1`, or before an outside cell (the
        // layer around the grid, or past the key space): no region cell lies beyond
        // the grid, and the step onto the outside cell is not counted
        let g = [0, 1, 2].map(|i| k[i] as i64 - glo[i] + 1);
        let (gx, gy, gz) = (
            step[0] as isize,
            step[1] as isize * pdims[0] as isize,
            step[2] as isize * (pdims[0] * pdims[1]) as isize,
        );
        let mut idx = (g[0] + pdims[0] as i64 * (g[1] + pdims[1] as i64 * g[2])) as usize;
        let mut dda = GridDda::new(t_max, t_delta, t1, [gx, gy, gz]);
        let mut unknown = 0usize;
        let mut steps = 0u64;
        loop {
            steps += 1;
            let state = cells[idx];
            if state != FREE {
                if state != UNKNOWN {
                    steps -= (state == OUTSIDE) as u64;
                    break;
                }
                // an unknown region cell
                unknown += 1;
                let r = grid.region_index(idx);
                let (w, bit) = (r / 64, 1u64 << (r % 64));
                if unknown == 1 && first_bits[w] & bit == 0 {
                    first_bits[w] |= bit;
                    first += 1;
                }
                if reached_bits[w] & bit == 0 {
                    reached_bits[w] |= bit;
                    reached += 1;
                }
                if unknown >= lookahead {
                    break;
                }
            }
            let Some(d) = dda.advance() else {
                break;
            };
            idx = idx.wrapping_add_signed(d);
        }
        out.steps += steps;
    }
    out.first = first;
    out.reached = reached;
    out
}

/// The floating-point state of the grid walk's DDA on x86_64 (Amanatides & Woo, as
/// [`walk_with`]): per axis the ray parameter of the next cell border and the
/// parameter between borders, the far end `t1`, and the grid index step per axis.
/// [`advance`](Self::advance) picks the axis of [`next_axis`] (x when tx < ty and
/// tx < tz, y when ty ≤ tx and ty < tz, else z) without a branch: the axis is as
/// good as random from step to step, and a mispredicted branch costs more than the
/// step. The chosen t gains its delta, the other two `+0.0` (every t ≥ +0: unchanged),
/// so the sums are those of the walk, bit for bit.
#[cfg(target_arch = "x86_64")]
struct SseDda {
    t: [std::arch::x86_64::__m128d; 3],
    d: [std::arch::x86_64::__m128d; 3],
    t1: std::arch::x86_64::__m128d,
    /// Index step by the axis masks' sign bits: 0 = y, 1 = x, 2 = z.
    steps: [isize; 4],
}

#[cfg(target_arch = "x86_64")]
impl SseDda {
    #[inline(always)]
    fn new(t: [f64; 3], d: [f64; 3], t1: f64, [gx, gy, gz]: [isize; 3]) -> Self {
        use std::arch::x86_64::_mm_set_sd;
        // SAFETY: SSE2 is part of every x86_64 CPU.
        unsafe {
            Self {
                t: t.map(|v| _mm_set_sd(v)),
                d: d.map(|v| _mm_set_sd(v)),
                t1: _mm_set_sd(t1),
                steps: [gy, gx, gz, gz],
            }
        }
    }

    /// The index step to the next cell, `None` when its border lies past `t1`.
    #[inline(always)]
    fn advance(&mut self) -> Option<isize> {
        use std::arch::x86_64::{
            _mm_add_sd, _mm_and_pd, _mm_andnot_pd, _mm_cmplt_sd, _mm_cmpnlt_sd, _mm_comigt_sd, _mm_min_sd,
            _mm_movemask_pd, _mm_or_pd,
        };
        let [x, y, z] = self.t;
        // SAFETY: SSE2 is part of every x86_64 CPU. `minsd(a, b)` is `a < b ? a : b`.
        unsafe {
            let m = _mm_min_sd(x, y);
            if _mm_comigt_sd(_mm_min_sd(m, z), self.t1) != 0 {
                return None;
            }
            let mx = _mm_cmplt_sd(x, _mm_min_sd(y, z));
            let mz = _mm_cmpnlt_sd(m, z);
            // the high lanes are zero: bit 0 of each mask is its low lane's sign
            let pick = ((_mm_movemask_pd(mx) & 1) | ((_mm_movemask_pd(mz) & 1) << 1)) as usize;
            // t + (d & mask); y's mask is neither x's nor z's
            self.t[0] = _mm_add_sd(x, _mm_and_pd(mx, self.d[0]));
            self.t[1] = _mm_add_sd(y, _mm_andnot_pd(_mm_or_pd(mx, mz), self.d[1]));
            self.t[2] = _mm_add_sd(z, _mm_and_pd(mz, self.d[2]));
            Some(self.steps[pick])
        }
    }
}
/// The DDA state of the grid walk on this target.
#[cfg(target_arch = "x86_64")]
type GridDda = SseDda;
#[cfg(not(target_arch = "x86_64"))]
type GridDda = SelectDda;

/// [`SseDda`] without SSE2: the same choice by selects, the chosen t alone updated.
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
struct SelectDda {
    t: [f64; 3],
    d: [f64; 3],
    t1: f64,
    steps: [isize; 3],
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
impl SelectDda {
    #[inline(always)]
    fn new(t: [f64; 3], d: [f64; 3], t1: f64, steps: [isize; 3]) -> Self {
        Self { t, d, t1, steps }
    }

    #[inline(always)]
    fn advance(&mut self) -> Option<isize> {
        let [x, y, z] = self.t;
        let x_lt_y = x < y;
        let m = select_unpredictable(x_lt_y, x, y);
        let m_lt_z = m < z;
        if select_unpredictable(m_lt_z, m, z) > self.t1 {
            return None;
        }
        let a = select_unpredictable(m_lt_z, select_unpredictable(x_lt_y, 0, 1), 2);
        self.t[a] += self.d[a];
        Some(self.steps[a])
    }
}

/// The axis whose cell border the DDA crosses next (the smallest `t_max`; ties to the
/// later axis, as in [`walk_with`]).
#[inline(always)]
fn next_axis(t_max: &[f64; 3]) -> usize {
    if t_max[0] < t_max[1] {
        if t_max[0] < t_max[2] { 0 } else { 2 }
    } else if t_max[1] < t_max[2] {
        1
    } else {
        2
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use rand::{Rng, SeedableRng};

    use super::{SelectDda, SseDda, next_axis};

    /// Both branch-free steps against the reference step of [`walk_with`]: the
    /// axis of [`next_axis`], stopping once the smallest `t_max` passes `t1`.
    #[test]
    fn the_sse_and_the_select_dda_step_alike_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
        for ray in 0..300 {
            // t_max and deltas on a lattice of 1/8 for many ties, or random
            let tie = ray % 2 == 0;
            let v = |rng: &mut rand_chacha::ChaCha8Rng| {
                if tie {
                    rng.random_range(0..16) as f64 / 8.0
                } else {
                    rng.random_range(0.0..2.0)
                }
            };
            let t = [v(&mut rng), v(&mut rng), v(&mut rng)];
            let d = [0, 1, 2].map(|_| {
                if rng.random_bool(0.1) {
                    f64::INFINITY
                } else {
                    0.125 + v(&mut rng)
                }
            });
            let t1 = rng.random_range(1.0..6.0);
            let (mut a, mut b) = (
                SseDda::new(t, d, t1, [1, 10, 100]),
                SelectDda::new(t, d, t1, [1, 10, 100]),
            );
            let mut reference = t;
            let mut n = 0;
            loop {
                let (sa, sb) = (a.advance(), b.advance());
                assert_eq!(sa, sb, "ray {ray} step {n}");
                let axis = next_axis(&reference);
                let expected = (reference[axis] <= t1).then(|| {
                    reference[axis] += d[axis];
                    [1, 10, 100][axis]
                });
                assert_eq!(sb, expected, "ray {ray} step {n}: the reference step");
                assert_eq!(
                    b.t.map(f64::to_bits),
                    reference.map(f64::to_bits),
                    "ray {ray} step {n}"
                );
                // SAFETY: SSE2 is part of every x86_64 CPU.
                let ta =
                    a.t.map(|x| unsafe { std::arch::x86_64::_mm_cvtsd_f64(x) }.to_bits());
                assert_eq!(ta, b.t.map(f64::to_bits), "ray {ray} step {n}");
                if sa.is_none() {
                    break;
                }
                n += 1;
            }
            assert!(n < 200);
        }
    }
}
