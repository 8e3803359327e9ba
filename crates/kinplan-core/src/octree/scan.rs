//! Scan integration with OctoMap's `insertPointCloud` model: free cells along each
//! beam, occupied at the end points, each cell updated once per scan, occupied
//! preferred over free (docs/octree.md#rays-and-scans).

use std::time::Instant;

use nalgebra::{Isometry3, Point3};
use rayon::prelude::*;

use super::key::OcKey;
use super::{Octree, OctreeError};

/// Options of [`Octree::insert_scan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanParams {
    /// Beams longer than this (m) are cut there and leave no occupied end point; ≤ 0
    /// means no limit. Default −1 (OctoMap's default).
    pub max_range: f64,
    /// Merge end points falling into the same cell first and cast from its centre
    /// (OctoMap's `discretize`). Default false.
    pub discretize: bool,
    /// Largest key box (cells) traced into dense bitsets (one bit per cell and set,
    /// per worker); larger scans fall back to sorted key vectors. Default 2^27
    /// (16 MiB per bitset).
    pub dense_limit_cells: usize,
    /// Above `dense_limit_cells` the beams' keys are collected in vectors; a scan whose
    /// beams could cross more cells than this (upper bound `Σ (‖Δkey‖₁ + 1)`) is refused
    /// with [`OctreeError::ScanTooLarge`] instead of allocating without bound.
    /// Default 2^26 (512 MiB of keys at most).
    pub max_sorted_keys: usize,
}

impl Default for ScanParams {
    fn default() -> Self {
        Self {
            max_range: -1.0,
            discretize: false,
            dense_limit_cells: 1 << 27,
            max_sorted_keys: 1 << 26,
        }
    }
}

impl ScanParams {
    /// Checks `max_range` is not NaN.
    pub fn validate(&self) -> Result<(), OctreeError> {
        if self.max_range.is_nan() {
            return Err(OctreeError::NonFinite { field: "max_range" });
        }
        Ok(())
    }
}

/// Whether the scan went in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScanStatus {
    /// Every beam was integrated.
    Inserted,
    /// `should_stop` returned true while the beams were traced; the tree is unchanged.
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
    /// Wall time of tracing the beams (µs) and of updating the tree (µs).
    pub trace_us: u64,
    pub update_us: u64,
}

/// Pinhole intrinsics of a depth camera (pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeIntrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

/// Free cells, end-point cells (Morton codes) and skipped points of one chunk of beams.
type ChunkKeys = (Vec<u64>, Vec<u64>, usize);

/// Morton code of a key (x in bit 0): sorting by it makes successive updates share
/// their path from the root.
#[inline]
fn morton(k: &OcKey) -> u64 {
    #[inline]
    fn spread(v: u16) -> u64 {
        let mut x = v as u64;
        x = (x | (x << 32)) & 0x001F_0000_0000_FFFF;
        x = (x | (x << 16)) & 0x001F_0000_FF00_00FF;
        x = (x | (x << 8)) & 0x100F_00F0_0F00_F00F;
        x = (x | (x << 4)) & 0x10C3_0C30_C30C_30C3;
        x = (x | (x << 2)) & 0x1249_2492_4924_9249;
        x
    }
    spread(k[0]) | (spread(k[1]) << 1) | (spread(k[2]) << 2)
}

#[inline]
fn unmorton(m: u64) -> OcKey {
    #[inline]
    fn squeeze(mut x: u64) -> u16 {
        x &= 0x1249_2492_4924_9249;
        x = (x ^ (x >> 2)) & 0x10C3_0C30_C30C_30C3;
        x = (x ^ (x >> 4)) & 0x100F_00F0_0F00_F00F;
        x = (x ^ (x >> 8)) & 0x001F_0000_FF00_00FF;
        x = (x ^ (x >> 16)) & 0x001F_0000_0000_FFFF;
        x = (x ^ (x >> 32)) & 0x001F_FFFF;
        x as u16
    }
    [squeeze(m), squeeze(m >> 1), squeeze(m >> 2)]
}

impl Octree {
    /// Integrates a point cloud measured from `origin` (m, map frame; coordinates are
    /// rounded to f32 as OctoMap's `point3d`). For each point p: if `max_range ≤ 0` or
    /// `‖p − o‖ ≤ max_range`, the cells of `compute_ray_keys(o, p)` are free and the cell
    /// of p is occupied; otherwise the beam is cut at `o + max_range·(p − o)/‖p − o‖` and
    /// only its free cells count. Cells are collected into two sets, cells in both are
    /// occupied only, and each set element gets one update (`+hit` or `+miss` log-odds,
    /// clamped) — the same tree as OctoMap's `insertPointCloud(…, lazy_eval = false)`.
    ///
    /// Beams are traced in parallel (rayon) into dense bitsets over the scan's key box\n    /// (or, beyond `dense_limit_cells`, sorted Morton-code vectors).
    /// `should_stop` is polled per chunk of 4,096 beams (1,024 on the sorted path); when
    /// it fires the tree is left unchanged.
    ///
    /// ```
    /// use kinplan_core::octree::{CellState, Octree, ScanParams};
    /// let mut t = Octree::new(0.1).unwrap();
    /// // one beam along +x from the centre of cell 32768 to x = 0.45 (cell 32772)
    /// let s = t.insert_scan(&[[0.45, 0.05, 0.05]], &[0.05, 0.05, 0.05], &ScanParams::default(), &|| false).unwrap();
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
        should_stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<ScanStats, OctreeError> {
        params.validate()?;
        if origin.iter().any(|v| !v.is_finite()) {
            return Err(OctreeError::NonFinite { field: "origin" });
        }
        self.key_of_f32(origin)
            .ok_or(OctreeError::OutOfBounds { field: "origin" })?;
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
        let max_range = params.max_range;
        // key box of the origin and every usable point: all beams lie inside it
        let ko = self.key_of_f32(origin).expect("checked above");
        let (mut lo, mut hi) = (ko, ko);
        for p in pts {
            if let Some(k) = p
                .iter()
                .all(|v| v.is_finite())
                .then(|| self.key_of_f32(p))
                .flatten()
            {
                for i in 0..3 {
                    lo[i] = lo[i].min(k[i]);
                    hi[i] = hi[i].max(k[i]);
                }
            }
        }
        let dims = [0, 1, 2].map(|i| (hi[i] - lo[i]) as usize + 1);
        let cells = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
        if cells <= params.dense_limit_cells {
            return Ok(self.insert_dense(pts, origin, max_range, lo, dims, points.len(), t0, should_stop));
        }
        // bound the keys the sorted path could collect before allocating for them
        let cut_bound = if max_range > 0.0 {
            3 * (max_range * self.resolution_factor) as u64 + 4
        } else {
            u64::MAX
        };
        let mut bound = 0u64;
        for p in pts {
            if let Some(k) = p
                .iter()
                .all(|v| v.is_finite())
                .then(|| self.key_of_f32(p))
                .flatten()
            {
                let l1: u64 = (0..3).map(|i| (k[i] as i64 - ko[i] as i64).unsigned_abs()).sum();
                bound = bound.saturating_add((l1 + 1).min(cut_bound));
            } else if max_range > 0.0 && p.iter().all(|v| v.is_finite()) {
                bound = bound.saturating_add(cut_bound);
            }
        }
        if bound > params.max_sorted_keys as u64 {
            return Err(OctreeError::ScanTooLarge {
                cells: bound,
                limit: params.max_sorted_keys,
            });
        }
        let chunks: Vec<Option<ChunkKeys>> = pts
            .par_chunks(1024)
            .map(|chunk| {
                if should_stop() {
                    return None;
                }
                let mut ray = Vec::with_capacity(512);
                let (mut free, mut occ, mut skipped) = (Vec::new(), Vec::with_capacity(chunk.len()), 0usize);
                for p in chunk {
                    if p.iter().any(|v| !v.is_finite()) {
                        skipped += 1;
                        continue;
                    }
                    let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
                    let norm = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
                    if max_range < 0.0 || norm <= max_range {
                        if self.compute_ray_keys(origin, p, &mut ray) {
                            free.extend(ray.iter().map(morton));
                        }
                        match self.key_of_f32(p) {
                            Some(k) => occ.push(morton(&k)),
                            None => skipped += 1,
                        }
                    } else {
                        let n = norm as f32;
                        let m = max_range as f32;
                        let e = [0, 1, 2].map(|i| origin[i] + d[i] / n * m);
                        if self.compute_ray_keys(origin, &e, &mut ray) {
                            free.extend(ray.iter().map(morton));
                        }
                    }
                }
                free.sort_unstable();
                free.dedup();
                Some((free, occ, skipped))
            })
            .collect();
        let mut stats = ScanStats {
            status: ScanStatus::Cancelled,
            points: points.len(),
            skipped_points: 0,
            free_cells: 0,
            occupied_cells: 0,
            nodes: self.num_nodes,
            trace_us: 0,
            update_us: 0,
        };
        if chunks.iter().any(Option::is_none) {
            stats.trace_us = t0.elapsed().as_micros() as u64;
            return Ok(stats);
        }
        let (mut free, mut occ) = (Vec::new(), Vec::new());
        for (f, o, s) in chunks.into_iter().flatten() {
            free.extend_from_slice(&f);
            occ.extend_from_slice(&o);
            stats.skipped_points += s;
        }
        free.par_sort_unstable();
        free.dedup();
        occ.par_sort_unstable();
        occ.dedup();
        // occupied wins: drop free cells that are also end points (both sorted)
        let mut j = 0;
        free.retain(|m| {
            while j < occ.len() && occ[j] < *m {
                j += 1;
            }
            !(j < occ.len() && occ[j] == *m)
        });
        stats.trace_us = t0.elapsed().as_micros() as u64;
        let t1 = Instant::now();
        let (hit, miss) = (self.model.hit, self.model.miss);
        for m in &free {
            self.update_key(&unmorton(*m), miss);
        }
        for m in &occ {
            self.update_key(&unmorton(*m), hit);
        }
        stats.update_us = t1.elapsed().as_micros() as u64;
        stats.free_cells = free.len();
        stats.occupied_cells = occ.len();
        stats.nodes = self.num_nodes;
        stats.status = ScanStatus::Inserted;
        Ok(stats)
    }

    /// Traces every beam into two bitsets over the key box (free, end points), merges
    /// the workers' sets by OR, clears free bits that are end points, and updates the
    /// cells in x-fastest order — the same sets, so the same tree, as the sorted path.
    #[allow(clippy::too_many_arguments)]
    fn insert_dense(
        &mut self,
        pts: &[[f32; 3]],
        origin: &[f32; 3],
        max_range: f64,
        lo: OcKey,
        dims: [usize; 3],
        given: usize,
        t0: Instant,
        should_stop: &(dyn Fn() -> bool + Sync),
    ) -> ScanStats {
        let words = (dims[0] * dims[1] * dims[2]).div_ceil(64);
        let index = |k: &OcKey| {
            ((k[2] - lo[2]) as usize * dims[1] + (k[1] - lo[1]) as usize) * dims[0] + (k[0] - lo[0]) as usize
        };
        let strides = [1, dims[0], dims[0] * dims[1]];
        let this = &*self;
        type Acc = (Vec<u64>, Vec<u64>, usize, bool);
        let empty = || -> Acc { (vec![0u64; words], vec![0u64; words], 0, false) };
        let (mut free, occ, skipped, stopped) = pts
            .par_chunks(4096)
            .fold(empty, |mut acc, chunk| {
                if acc.3 || should_stop() {
                    acc.3 = true;
                    return acc;
                }
                for p in chunk {
                    if p.iter().any(|v| !v.is_finite()) {
                        acc.2 += 1;
                        continue;
                    }
                    let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
                    let norm = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
                    let free = &mut acc.0;
                    let mut mark = |_: &OcKey, i: usize| {
                        free[i >> 6] |= 1 << (i & 63);
                    };
                    if max_range < 0.0 || norm <= max_range {
                        this.visit_ray_cells(origin, p, &lo, strides, &mut mark);
                        match this.key_of_f32(p) {
                            Some(k) => {
                                let i = index(&k);
                                acc.1[i >> 6] |= 1 << (i & 63);
                            }
                            None => acc.2 += 1,
                        }
                    } else {
                        let (n, m) = (norm as f32, max_range as f32);
                        let e = [0, 1, 2].map(|i| origin[i] + d[i] / n * m);
                        this.visit_ray_cells(origin, &e, &lo, strides, &mut mark);
                    }
                }
                acc
            })
            .reduce(empty, |mut a, b| {
                for (x, y) in a.0.iter_mut().zip(&b.0) {
                    *x |= y;
                }
                for (x, y) in a.1.iter_mut().zip(&b.1) {
                    *x |= y;
                }
                (a.0, a.1, a.2 + b.2, a.3 || b.3)
            });
        let mut stats = ScanStats {
            status: ScanStatus::Cancelled,
            points: given,
            skipped_points: skipped,
            free_cells: 0,
            occupied_cells: 0,
            nodes: self.num_nodes,
            trace_us: 0,
            update_us: 0,
        };
        if stopped {
            stats.trace_us = t0.elapsed().as_micros() as u64;
            return stats;
        }
        for (f, o) in free.iter_mut().zip(&occ) {
            *f &= !o;
        }
        stats.trace_us = t0.elapsed().as_micros() as u64;
        let t1 = Instant::now();
        let key_of = |i: usize| {
            let x = i % dims[0];
            let y = (i / dims[0]) % dims[1];
            let z = i / (dims[0] * dims[1]);
            [lo[0] + x as u16, lo[1] + y as u16, lo[2] + z as u16]
        };
        let (hit, miss) = (self.model.hit, self.model.miss);
        for (bits, delta, count) in [
            (&free, miss, &mut stats.free_cells),
            (&occ, hit, &mut stats.occupied_cells),
        ] {
            for (w, &word) in bits.iter().enumerate() {
                let mut b = word;
                while b != 0 {
                    let i = w * 64 + b.trailing_zeros() as usize;
                    b &= b - 1;
                    self.update_key(&key_of(i), delta);
                    *count += 1;
                }
            }
        }
        stats.update_us = t1.elapsed().as_micros() as u64;
        stats.nodes = self.num_nodes;
        stats.status = ScanStatus::Inserted;
        stats
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
        should_stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<ScanStats, OctreeError> {
        let pts = depth_image_points(depth, width, height, intrinsics, camera_pose)?;
        let o = camera_pose.translation.vector;
        self.insert_scan(&pts, &[o.x as f32, o.y as f32, o.z as f32], params, should_stop)
    }
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
    let expected = width.checked_mul(height).ok_or(OctreeError::InvalidParam {
        field: "width",
        value: width as f64,
        reason: "width · height overflows",
    })?;
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
    let mut out = Vec::with_capacity(expected);
    for v in 0..height {
        for u in 0..width {
            let z = depth[v * width + u] as f64;
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let pc = Point3::new((u as f64 - k.cx) * z / k.fx, (v as f64 - k.cy) * z / k.fy, z);
            let pm = camera_pose * pc;
            out.push([pm.x as f32, pm.y as f32, pm.z as f32]);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_round_trips() {
        for k in [[0u16, 0, 0], [65535, 1, 32768], [12345, 54321, 7]] {
            assert_eq!(unmorton(morton(&k)), k);
        }
        assert_eq!(morton(&[1, 0, 0]), 1);
        assert_eq!(morton(&[0, 1, 0]), 2);
        assert_eq!(morton(&[0, 0, 1]), 4);
        assert_eq!(morton(&[2, 0, 0]), 8);
        assert_eq!(
            morton(&[0xffff, 0, 0]),
            0x1249_2492_4924_9249 & ((1u64 << 48) - 1)
        );
    }
}
