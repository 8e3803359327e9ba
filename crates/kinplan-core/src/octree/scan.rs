//! Scan integration with OctoMap's `insertPointCloud` model: free cells along each
//! beam, occupied at the end points, each cell updated once per scan, occupied
//! preferred over free (docs/octree.md#rays-and-scans).

use std::time::Instant;

use nalgebra::Isometry3;
use rayon::prelude::*;

use std::ops::ControlFlow;

use super::batch::BatchUpdate;
use super::frame::{PixelBeam, near_field_starts};
use super::grid::{BLOCK_WORDS, BlockGrid};
use super::key::{OcKey, morton, unmorton};
use super::plan::{Beam, EndPoint, PlanBuilder, ScanPlan};
use super::project::RowProjector;
use super::ray::{CellAddress, NoAddress, Walk, WalkStart};
use super::{Octree, OctreeError, OctreeLimits};
use crate::Deadline;

/// Options of [`Octree::insert_scan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanParams {
    /// Beams longer than this (m) are cut there and leave no occupied end point; ≤ 0
    /// means no limit. Default −1 (OctoMap's default).
    pub max_range: f64,
    /// Merge end points falling into the same cell first and cast from its centre
    /// (OctoMap's `discretize`). Default false.
    pub discretize: bool,
    /// Largest key box (cells, once widened to whole blocks of 32³ cells aligned to
    /// multiples of 32 keys) traced into dense bitsets (one bit per cell and set, per
    /// worker); larger scans collect sorted key vectors. Default 2^27 (16 MiB per
    /// bitset); values above 2^32 act as 2^32.
    pub dense_limit_cells: usize,
    /// Most cells the beams may cross in all, counted before any is traced as
    /// `Σ_beams min(‖key(p) − key(o)‖₁ + 1, 3·max_range/resolution + 4)` — the
    /// scan's work. A scan over it is refused with [`OctreeError::ScanTooLarge`].
    /// Default 2^28.
    pub max_traced_cells: u64,
    /// Most nodes the tree may hold. A scan that updates more distinct cells than
    /// this (every updated cell is a leaf until pruned) is refused with
    /// [`OctreeError::ScanTooManyCells`] while its beams are traced, and the update
    /// stops with [`OctreeError::TreeGrewTooLarge`] once the tree grows past it.
    /// Default [`OctreeLimits::default`]'s `max_nodes`.
    pub max_nodes: usize,
    /// Depth images only: the near field of the image's beams is shared
    /// (docs/octree.md#whole-frame-insertion): close to the camera only a pixel
    /// lattice whose neighbouring beams are at most this far apart is traced, in cells
    /// (multiples of the resolution), in [0, 1]; 0 traces every beam from the camera
    /// (the exact `insertPointCloud` result). [`NEAR_RAY_SPACING`] is the suggested
    /// value. Not with `discretize`. Default 0.
    pub near_ray_spacing: f64,
}

/// Suggested [`ScanParams::near_ray_spacing`] (cells): a lattice of this spacing
/// crosses the inscribed ball of every cell in its fan (`s/√2 < ½`).
pub const NEAR_RAY_SPACING: f64 = 0.7;

impl Default for ScanParams {
    fn default() -> Self {
        Self {
            max_range: -1.0,
            discretize: false,
            dense_limit_cells: 1 << 27,
            max_traced_cells: 1 << 28,
            max_nodes: OctreeLimits::default().max_nodes,
            near_ray_spacing: 0.0,
        }
    }
}

impl ScanParams {
    /// Checks `max_range` is not NaN and `near_ray_spacing` lies in [0, 1] without
    /// `discretize`.
    pub fn validate(&self) -> Result<(), OctreeError> {
        if self.max_range.is_nan() {
            return Err(OctreeError::NonFinite { field: "max_range" });
        }
        let s = self.near_ray_spacing;
        if !(0.0..=1.0).contains(&s) {
            return Err(OctreeError::InvalidParam {
                field: "near_ray_spacing",
                value: s,
                reason: "must lie in [0, 1] cells",
            });
        }
        if s > 0.0 && self.discretize {
            return Err(OctreeError::InvalidParam {
                field: "near_ray_spacing",
                value: s,
                reason: "cannot be combined with discretize",
            });
        }
        Ok(())
    }
}

/// Whether the scan went in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScanStatus {
    /// Every beam was integrated.
    Inserted,
    /// `deadline` expired (passed or cancelled). Seen while the beams were traced, the tree is
    /// unchanged; seen while the cells were updated, the cells updated so far keep
    /// their update (each cell's update is whole): discard the tree when the scan
    /// must go in all or not at all.
    Cancelled,
}

/// Counts and times of one insert.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanStats {
    pub status: ScanStatus,
    /// Points given.
    pub points: usize,
    /// Points outside the tree's cube or non-finite, skipped (OctoMap skips them too).
    pub skipped_points: usize,
    /// Distinct cells updated as free.
    pub free_cells: usize,
    /// Distinct cells updated as occupied.
    pub occupied_cells: usize,
    /// Tree nodes after the insert.
    pub nodes: usize,
    /// Free-cell visits of the beams' walks, repeats included: the trace's work.
    pub traced_cells: u64,
    /// Wall time of tracing the beams (µs) and of updating the tree (µs).
    pub trace_us: u64,
    pub update_us: u64,
}

/// Most pixels a depth image or a camera model may have (`width · height`): 2^24.
pub const MAX_DEPTH_PIXELS: usize = 1 << 24;

/// Pinhole intrinsics of a depth camera (pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeIntrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

/// Free cells, end-point cells (Morton codes), skipped points and free-cell visits
/// of one chunk of beams.
type ChunkKeys = (Vec<u64>, Vec<u64>, usize, u64);

/// The cells one scan updates, free (end points removed) and occupied (end points):
/// two bitsets over a [`BlockGrid`], or two sorted, disjoint vectors of Morton codes.
enum CellSets {
    Dense {
        grid: BlockGrid,
        free: Vec<u64>,
        occupied: Vec<u64>,
    },
    Sorted {
        free: Vec<u64>,
        occupied: Vec<u64>,
    },
}

/// The cells one scan updates, the points it skipped and the free-cell visits of
/// its walks.
struct ScanCells {
    sets: CellSets,
    skipped: usize,
    traced: u64,
}

impl CellSets {
    /// Hands the cells to `each` grouped by their depth-15 parent, as the key of the
    /// parent's child 0 and two disjoint masks of its children (bit `x + 2y + 4z`),
    /// free and occupied: in ascending Morton order inside each 32³ block (dense) or
    /// in ascending Morton order (sorted), until `each` breaks. In both layouts a
    /// parent's eight children are eight consecutive bits, so a dense group is one
    /// byte of each bitset.
    fn for_each_group<B>(&self, mut each: impl FnMut(&OcKey, u8, u8) -> ControlFlow<B>) -> ControlFlow<B> {
        match self {
            CellSets::Dense { grid, free, occupied } => {
                let blocks = free
                    .chunks_exact(BLOCK_WORDS)
                    .zip(occupied.chunks_exact(BLOCK_WORDS));
                for (b, (f, o)) in blocks.enumerate() {
                    if f.iter().chain(o).all(|&w| w == 0) {
                        continue;
                    }
                    let base = grid.block_base(b);
                    for (w, (&f, &o)) in f.iter().zip(o).enumerate() {
                        let mut bits = f | o;
                        while bits != 0 {
                            let shift = bits.trailing_zeros() & !7;
                            bits &= !(0xff << shift);
                            let first = grid.key_in_block(&base, w * 64 + shift as usize);
                            each(&first, (f >> shift) as u8, (o >> shift) as u8)?;
                        }
                    }
                }
            }
            CellSets::Sorted { free, occupied } => {
                let (mut i, mut j) = (0, 0);
                let mut group: Option<(u64, u8, u8)> = None;
                while i < free.len() || j < occupied.len() {
                    let (m, is_free) = if j == occupied.len() || (i < free.len() && free[i] < occupied[j]) {
                        i += 1;
                        (free[i - 1], true)
                    } else {
                        j += 1;
                        (occupied[j - 1], false)
                    };
                    let bit = 1u8 << (m & 7);
                    match &mut group {
                        Some((parent, f, o)) if *parent == m >> 3 => {
                            *(if is_free { f } else { o }) |= bit;
                        }
                        _ => {
                            if let Some((parent, f, o)) = group {
                                each(&unmorton(parent << 3), f, o)?;
                            }
                            group = Some(if is_free {
                                (m >> 3, bit, 0)
                            } else {
                                (m >> 3, 0, bit)
                            });
                        }
                    }
                }
                if let Some((parent, f, o)) = group {
                    each(&unmorton(parent << 3), f, o)?;
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// The union of two sorted, deduplicated vectors, sorted and deduplicated.
fn merge_sorted(a: &[u64], b: &[u64]) -> Vec<u64> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// Cells traced per batch on the sorted path before the batch's keys are
/// merged into the scan's sets and their size is checked against the node
/// limit: bounds the keys held at once.
const BATCH_CELLS: u64 = 1 << 22;

/// Beams whose walks are started in a row before they are walked (dense path).
const WALK_GROUP: usize = 64;

/// Most cells of a dense key box (its bit addresses are u32).
const MAX_DENSE_CELLS: usize = 1 << 32;

/// Cell updates between two looks at the stop flag and the node count.
const UPDATES_PER_CHECK: usize = 4096;

/// Memory the dense path's per-worker bitsets may take in all (bytes); fewer
/// workers trace a large key box.
const DENSE_BUDGET_BYTES: usize = 256 << 20;

impl Octree {
    /// Integrates a point cloud measured from `origin` (m, map frame; coordinates are
    /// rounded to f32 as OctoMap's `point3d`). For each point p: if `max_range ≤ 0` or
    /// `‖p − o‖ ≤ max_range`, the cells of `compute_ray_keys(o, p)` are free and the cell
    /// of p is occupied; otherwise the beam is cut at `o + max_range·(p − o)/‖p − o‖` and
    /// only its free cells count. Cells are collected into two sets, cells in both are
    /// occupied only, and each set element gets one update (`+hit` or `+miss` log-odds,
    /// clamped) — the same tree as OctoMap's `insertPointCloud(…, lazy_eval = false)`.
    ///
    /// Cost, bounded before the work starts: the cells the beams can cross are counted
    /// first (`ScanParams::max_traced_cells`); beams are traced in parallel (rayon) in
    /// chunks of about 65,536 cells into dense bitsets over the scan's key box (workers
    /// limited so their bitsets stay within 256 MiB) or, beyond `dense_limit_cells`, into
    /// sorted Morton-code vectors merged batch by batch, refused once they hold more
    /// distinct cells than `max_nodes`; the update stops once the tree holds more than
    /// `max_nodes` nodes. `deadline` is polled per chunk and every 4,096 updates.
    ///
    /// ```
    /// use kinplan_core::Deadline;
    /// use kinplan_core::octree::{CellState, Octree, ScanParams};
    /// let mut t = Octree::new(0.1).unwrap();
    /// // one beam along +x from the centre of cell 32768 to x = 0.45 (cell 32772)
    /// let s = t.insert_scan(&[[0.45, 0.05, 0.05]], &[0.05, 0.05, 0.05], &ScanParams::default(), Deadline::none()).unwrap();
    /// assert_eq!((s.free_cells, s.occupied_cells), (4, 1));
    /// assert_eq!(t.state_of_key(&[32771, 32768, 32768]), CellState::Free);
    /// assert_eq!(t.state_of_key(&[32772, 32768, 32768]), CellState::Occupied);
    /// assert_eq!(t.state_of_key(&[32773, 32768, 32768]), CellState::Unknown);
    /// ```
    pub fn insert_scan(
        &mut self,
        points: &[[f32; 3]],
        origin: &[f32; 3],
        params: &ScanParams,
        deadline: Deadline<'_>,
    ) -> Result<ScanStats, OctreeError> {
        params.validate()?;
        if origin.iter().any(|v| !v.is_finite()) {
            return Err(OctreeError::NonFinite { field: "origin" });
        }
        let t0 = Instant::now();
        let discrete: Vec<[f32; 3]>;
        let pts: &[[f32; 3]] = if params.discretize {
            let mut seen: Vec<u64> = points
                .iter()
                .filter_map(|p| self.key_of_f32(p))
                .map(|k| morton(&k))
                .collect();
            // keep first occurrence order irrelevant: the update sets are order-free
            seen.sort_unstable();
            seen.dedup();
            let r = self.resolution;
            discrete = seen
                .iter()
                .map(|&m| unmorton(m).map(|k| super::key::key_to_coord_axis(k, r) as f32))
                .collect();
            &discrete
        } else {
            points
        };
        let mut builder = PlanBuilder::new(self, origin, params, pts.len())?;
        for p in pts {
            builder.push(p);
        }
        let plan = builder.finish(params)?;
        self.insert_planned(&plan, origin, None, points.len(), params, t0, deadline)
    }

    /// Traces the beams of `plan` from `origin` and updates their cells, optionally
    /// with the ray parameter (m) at which each beam's free cells start (one per
    /// beam; the end point is always occupied). `points` is the count reported in
    /// the stats, `t0` when the scan's work started.
    #[allow(clippy::too_many_arguments)]
    fn insert_planned(
        &mut self,
        plan: &ScanPlan,
        origin: &[f32; 3],
        starts: Option<&[f32]>,
        points: usize,
        params: &ScanParams,
        t0: Instant,
        deadline: Deadline<'_>,
    ) -> Result<ScanStats, OctreeError> {
        debug_assert!(starts.is_none_or(|s| s.len() == plan.beams.len() && !params.discretize));
        let mut stats = ScanStats {
            status: ScanStatus::Cancelled,
            points,
            skipped_points: 0,
            free_cells: 0,
            occupied_cells: 0,
            nodes: self.num_nodes,
            traced_cells: 0,
            trace_us: 0,
            update_us: 0,
        };
        let dense_limit = params.dense_limit_cells.min(MAX_DENSE_CELLS);
        let dense = BlockGrid::cells_for(&plan.lo, &plan.hi).is_some_and(|c| c <= dense_limit);
        let traced = if dense {
            self.trace_dense(origin, starts, params.max_range, plan, deadline)
        } else {
            self.trace_sorted(origin, starts, params, plan, deadline)?
        };
        stats.trace_us = t0.elapsed().as_micros() as u64;
        let Some(cells) = traced else {
            return Ok(stats);
        };
        stats.skipped_points = cells.skipped;
        stats.traced_cells = cells.traced;
        let t1 = Instant::now();
        let (hit, miss) = (self.model.hit, self.model.miss);
        let (mut updates, mut next_check) = (0usize, 0usize);
        let mut batch = BatchUpdate::new();
        let stopped = cells.sets.for_each_group(|first, free, occupied| {
            if updates >= next_check {
                if self.num_nodes > params.max_nodes {
                    return ControlFlow::Break(true);
                }
                if deadline.expired() {
                    return ControlFlow::Break(false);
                }
                next_check = updates + UPDATES_PER_CHECK;
            }
            batch.update_siblings(self, first, free, occupied, hit, miss);
            let (f, o) = (free.count_ones() as usize, occupied.count_ones() as usize);
            stats.free_cells += f;
            stats.occupied_cells += o;
            updates += f + o;
            ControlFlow::Continue(())
        });
        batch.finish(self);
        if matches!(stopped, ControlFlow::Break(true)) || self.num_nodes > params.max_nodes {
            return Err(OctreeError::TreeGrewTooLarge {
                limit: params.max_nodes,
            });
        }
        if stopped.is_break() {
            stats.update_us = t1.elapsed().as_micros() as u64;
            stats.nodes = self.num_nodes;
            return Ok(stats);
        }
        stats.update_us = t1.elapsed().as_micros() as u64;
        stats.nodes = self.num_nodes;
        stats.status = ScanStatus::Inserted;
        Ok(stats)
    }

    /// Traces one beam from `origin` (free cells from the ray parameter `t0` on to
    /// `free` with their address, its end cell to `end`) with `insertPointCloud`'s
    /// rule: a beam longer than `max_range > 0` is cut there and has no end cell.
    /// False when the point is skipped (not finite, or outside the tree's cube and not
    /// cut).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn trace_beam(
        &self,
        beam: &Beam,
        origin: &[f32; 3],
        t0: f64,
        max_range: f64,
        addr: &impl CellAddress,
        free: impl FnMut(&OcKey, usize),
        end: impl FnOnce(&OcKey),
    ) -> bool {
        let (kept, start) = self.beam_start(beam, origin, t0, max_range, end);
        self.walk_from(start, addr, free);
        kept
    }

    /// [`trace_beam`](Self::trace_beam) up to the start of its walk: the end cell
    /// (if any) goes to `end` and the walk, not yet taken, is returned with false
    /// when the point is skipped.
    #[inline]
    fn beam_start(
        &self,
        beam: &Beam,
        origin: &[f32; 3],
        t0: f64,
        max_range: f64,
        end: impl FnOnce(&OcKey),
    ) -> (bool, WalkStart) {
        if beam.kind == EndPoint::NonFinite {
            return (false, WalkStart::Empty);
        }
        let norm = beam.norm;
        if max_range <= 0.0 || norm <= max_range {
            if beam.kind != EndPoint::InTree {
                return (false, WalkStart::Empty);
            }
            end(&beam.end);
            if t0 < norm {
                return (true, self.walk_start(origin, &beam.diff, norm, &beam.end, t0));
            }
        } else if t0 < max_range {
            let (n, m) = (norm as f32, max_range as f32);
            let e = [0, 1, 2].map(|i| origin[i] + beam.diff[i] / n * m);
            return (true, self.ray_walk_start(origin, &e, t0));
        }
        (true, WalkStart::Empty)
    }

    /// Traces every beam into two bitsets over the key box (free, end points), one
    /// pair per worker, merges them by OR and clears free bits that are end points.
    /// `None` when `deadline` fired.
    fn trace_dense(
        &self,
        origin: &[f32; 3],
        starts: Option<&[f32]>,
        max_range: f64,
        plan: &ScanPlan,
        deadline: Deadline<'_>,
    ) -> Option<ScanCells> {
        let grid = BlockGrid::new(&plan.lo, &plan.hi);
        let words = grid.cells() / 64;
        let workers = rayon::current_num_threads()
            .min((DENSE_BUDGET_BYTES / (16 * words)).max(1))
            .min(plan.chunks.len())
            .max(1);
        type Acc = (Vec<u64>, Vec<u64>, usize, u64);
        let traced: Vec<Option<Acc>> = (0..workers)
            .into_par_iter()
            .map(|w| {
                let (mut free, mut occ, mut skipped) = (vec![0u64; words], vec![0u64; words], 0usize);
                let mut traced = 0u64;
                // The starts of a group of beams are worked out first, then the
                // group is walked: each start is a chain of dependent float
                // operations (norm, direction, start key, border parameters), and
                // worked out in a row they overlap instead of each waiting for the
                // previous walk's last, mispredicted step.
                let mut walks: Vec<Walk> = Vec::with_capacity(WALK_GROUP);
                for (range, _) in plan.chunks.iter().skip(w).step_by(workers) {
                    if deadline.expired() {
                        return None;
                    }
                    for first in range.clone().step_by(WALK_GROUP) {
                        walks.clear();
                        for i in first..(first + WALK_GROUP).min(range.end) {
                            let t0 = starts.map_or(0.0, |s| s[i] as f64);
                            let end = |k: &OcKey| {
                                let i = grid.index(k);
                                occ[i >> 6] |= 1 << (i & 63);
                            };
                            let (counted, start) =
                                self.beam_start(&plan.beams[i], origin, t0, max_range, end);
                            if !counted {
                                skipped += 1;
                            }
                            if let WalkStart::From(walk) = start {
                                walks.push(walk);
                            }
                        }
                        for walk in &walks {
                            self.walk(walk, &grid, |_, i| {
                                traced += 1;
                                free[i >> 6] |= 1 << (i & 63);
                            });
                        }
                    }
                }
                Some((free, occ, skipped, traced))
            })
            .collect();
        let mut traced = traced.into_iter();
        let (mut free, mut occ, mut skipped, mut visits) = traced.next()??;
        for acc in traced {
            let (f, o, s, v) = acc?;
            visits += v;
            free.iter_mut().zip(&f).for_each(|(x, y)| *x |= y);
            occ.iter_mut().zip(&o).for_each(|(x, y)| *x |= y);
            skipped += s;
        }
        for (f, o) in free.iter_mut().zip(&occ) {
            *f &= !o;
        }
        Some(ScanCells {
            sets: CellSets::Dense {
                grid,
                free,
                occupied: occ,
            },
            skipped,
            traced: visits,
        })
    }

    /// Traces the beams batch by batch into sorted, deduplicated Morton-code vectors,
    /// merging each batch into the scan's sets; refuses the scan once the sets hold
    /// more than `max_nodes` cells. `Ok(None)` when `deadline` fired.
    fn trace_sorted(
        &self,
        origin: &[f32; 3],
        starts: Option<&[f32]>,
        params: &ScanParams,
        plan: &ScanPlan,
        deadline: Deadline<'_>,
    ) -> Result<Option<ScanCells>, OctreeError> {
        let max_range = params.max_range;
        let (mut free, mut occ, mut skipped) = (Vec::<u64>::new(), Vec::<u64>::new(), 0usize);
        let (mut traced, mut next) = (0u64, 0);
        while next < plan.chunks.len() {
            let mut end = next;
            let mut batch_cells = 0u64;
            while end < plan.chunks.len() && (end == next || batch_cells + plan.chunks[end].1 <= BATCH_CELLS)
            {
                batch_cells += plan.chunks[end].1;
                end += 1;
            }
            let chunks: Vec<Option<ChunkKeys>> = plan.chunks[next..end]
                .par_iter()
                .map(|(range, cells)| {
                    if deadline.expired() {
                        return None;
                    }
                    let mut chunk_free = Vec::with_capacity(*cells as usize);
                    let (mut chunk_occ, mut chunk_skipped) = (Vec::with_capacity(range.len()), 0usize);
                    for i in range.clone() {
                        let t0 = starts.map_or(0.0, |s| s[i] as f64);
                        let mark = |k: &OcKey, _: usize| chunk_free.push(morton(k));
                        let end = |k: &OcKey| chunk_occ.push(morton(k));
                        if !self.trace_beam(&plan.beams[i], origin, t0, max_range, &NoAddress, mark, end) {
                            chunk_skipped += 1;
                        }
                    }
                    let visits = chunk_free.len() as u64;
                    chunk_free.sort_unstable();
                    chunk_free.dedup();
                    chunk_occ.sort_unstable();
                    chunk_occ.dedup();
                    Some((chunk_free, chunk_occ, chunk_skipped, visits))
                })
                .collect();
            let (mut batch_free, mut batch_occ) = (Vec::new(), Vec::new());
            for chunk in chunks {
                let Some((f, o, s, v)) = chunk else {
                    return Ok(None);
                };
                batch_free.extend_from_slice(&f);
                batch_occ.extend_from_slice(&o);
                skipped += s;
                traced += v;
            }
            for (set, batch) in [(&mut free, &mut batch_free), (&mut occ, &mut batch_occ)] {
                batch.par_sort_unstable();
                batch.dedup();
                *set = merge_sorted(set, batch);
            }
            if free.len() + occ.len() > params.max_nodes {
                return Err(OctreeError::ScanTooManyCells {
                    cells: (free.len() + occ.len()) as u64,
                    limit: params.max_nodes,
                });
            }
            next = end;
        }
        // occupied wins: drop free cells that are also end points (both sorted)
        let mut j = 0;
        free.retain(|m| {
            while j < occ.len() && occ[j] < *m {
                j += 1;
            }
            !(j < occ.len() && occ[j] == *m)
        });
        Ok(Some(ScanCells {
            sets: CellSets::Sorted { free, occupied: occ },
            skipped,
            traced,
        }))
    }

    /// Inserts a depth image: pixel `(u, v)` (row-major, `width` per row) with depth
    /// `z > 0` (m along the optical axis; 0, negative or non-finite = no return) becomes
    /// the camera-frame point `((u − cx)·z/fx, (v − cy)·z/fy, z)` (optical frame: x
    /// right, y down, z forward), mapped by `camera_pose` (camera → map) and inserted
    /// with [`insert_scan`](Self::insert_scan) from the camera origin.
    #[allow(clippy::too_many_arguments)]
    pub fn insert_depth_image(
        &mut self,
        depth: &[f32],
        width: usize,
        height: usize,
        intrinsics: &PinholeIntrinsics,
        camera_pose: &Isometry3<f64>,
        params: &ScanParams,
        deadline: Deadline<'_>,
    ) -> Result<ScanStats, OctreeError> {
        params.validate()?;
        let o = camera_pose.translation.vector;
        let origin = [o.x as f32, o.y as f32, o.z as f32];
        if params.near_ray_spacing <= 0.0 || origin.iter().any(|v| !v.is_finite()) {
            let pts = depth_image_points(depth, width, height, intrinsics, camera_pose)?;
            return self.insert_scan(&pts, &origin, params, deadline);
        }
        let t0 = Instant::now();
        check_image(depth, width, height, intrinsics)?;
        let mut builder = PlanBuilder::new(self, &origin, params, depth.len())?;
        let mut pixels = vec![
            PixelBeam {
                covered: 0.0,
                point: u32::MAX,
            };
            depth.len()
        ];
        let mut points = 0u32;
        let k = intrinsics;
        let mut rows = RowProjector::new(
            width,
            k.fx,
            k.cx,
            camera_pose,
            &origin,
            self.resolution_factor,
            params.max_range,
        );
        for v in 0..height {
            let row = v * width..(v + 1) * width;
            rows.beams(&depth[row.clone()], (v as f64 - k.cy) / k.fy);
            let n = width;
            let r = &rows;
            let (dx, dy, dz) = (&r.diff[0][..n], &r.diff[1][..n], &r.diff[2][..n]);
            let (kx, ky, kz) = (&r.key[0][..n], &r.key[1][..n], &r.key[2][..n]);
            let (valid, finite, in_tree) = (&r.valid[..n], &r.finite[..n], &r.in_tree[..n]);
            let (norm, covered) = (&r.norm[..n], &r.covered[..n]);
            let row_pixels = &mut pixels[row];
            for u in 0..n {
                if !valid[u] {
                    continue;
                }
                let key = in_tree[u].then_some([kx[u], ky[u], kz[u]]);
                builder.push_parts([dx[u], dy[u], dz[u]], norm[u], key, finite[u]);
                row_pixels[u] = PixelBeam {
                    covered: covered[u],
                    point: points,
                };
                points += 1;
            }
        }
        let starts = near_field_starts(
            &pixels,
            width,
            height,
            points as usize,
            intrinsics.fx.min(intrinsics.fy),
            params.near_ray_spacing * self.resolution,
            self.near_field_margin(),
        );
        let plan = builder.finish_in_box(params, &rows.lo, &rows.hi)?;
        self.insert_planned(
            &plan,
            &origin,
            Some(&starts),
            points as usize,
            params,
            t0,
            deadline,
        )
    }
}

/// Depths in metres from a little-endian uint16 image in millimetres (2 bytes per
/// pixel, a ROS `16UC1` image): `z = mm / 1000`, 0 stays 0 (no return). An odd byte
/// count is refused naming `field`.
pub fn depth_from_millimetres(bytes: &[u8], field: &'static str) -> Result<Vec<f32>, OctreeError> {
    if !bytes.len().is_multiple_of(2) {
        return Err(OctreeError::WrongLength {
            field,
            expected: bytes.len() + 1,
            got: bytes.len(),
        });
    }
    Ok(bytes
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]) as f32 / 1000.0)
        .collect())
}

/// Back-projects a depth image to map-frame points (see
/// [`Octree::insert_depth_image`]); pixels without a return are left out.
pub fn depth_image_points(
    depth: &[f32],
    width: usize,
    height: usize,
    k: &PinholeIntrinsics,
    camera_pose: &Isometry3<f64>,
) -> Result<Vec<[f32; 3]>, OctreeError> {
    let mut out = Vec::with_capacity(depth.len());
    back_project(depth, width, height, k, camera_pose, |_, p| out.push(p))?;
    Ok(out)
}

/// Checks the image and hands each pixel with a return to `each` as
/// `(row-major pixel index, map-frame point)`, in pixel order: `z > 0` finite,
/// `p_c = (a_u·z, b_v·z, z)` with `a_u = (u − cx)/fx`, `b_v = (v − cy)/fy`, and
/// `p = R·p_c + t` for the pose's rotation matrix `R` and translation `t`
/// ([`RowProjector`]).
pub(crate) fn back_project(
    depth: &[f32],
    width: usize,
    height: usize,
    k: &PinholeIntrinsics,
    camera_pose: &Isometry3<f64>,
    mut each: impl FnMut(usize, [f32; 3]),
) -> Result<(), OctreeError> {
    check_image(depth, width, height, k)?;
    let mut rows = RowProjector::new(width, k.fx, k.cx, camera_pose, &[0.0; 3], 1.0, -1.0);
    for v in 0..height {
        rows.points(&depth[v * width..(v + 1) * width], (v as f64 - k.cy) / k.fy);
        let [px, py, pz] = &rows.p;
        for u in (0..width).filter(|&u| rows.valid[u]) {
            each(v * width + u, [px[u], py[u], pz[u]]);
        }
    }
    Ok(())
}

/// Checks a depth image's size (`depth` holds `width · height` pixels) and
/// intrinsics (finite focal lengths > 0, finite principal point).
fn check_image(depth: &[f32], width: usize, height: usize, k: &PinholeIntrinsics) -> Result<(), OctreeError> {
    let expected = width.checked_mul(height).ok_or(OctreeError::InvalidParam {
        field: "width",
        value: width as f64,
        reason: "width · height overflows",
    })?;
    if expected > MAX_DEPTH_PIXELS {
        return Err(OctreeError::InvalidParam {
            field: "width",
            value: width as f64,
            reason: "width · height must be at most 2^24",
        });
    }
    if depth.len() != expected {
        return Err(OctreeError::WrongLength {
            field: "depth",
            expected,
            got: depth.len(),
        });
    }
    for (field, v) in [("fx", k.fx), ("fy", k.fy)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(OctreeError::InvalidParam {
                field,
                value: v,
                reason: "focal length must be finite and > 0",
            });
        }
    }
    if !(k.cx.is_finite() && k.cy.is_finite()) {
        return Err(OctreeError::NonFinite {
            field: "principal point",
        });
    }
    Ok(())
}
