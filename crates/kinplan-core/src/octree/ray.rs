//! Ray casting over keys: the 3-D DDA of Amanatides & Woo with OctoMap's
//! `computeRayKeys` and `castRay` semantics, in OctoMap's f32/f64 arithmetic so the same
//! cells come out (docs/octree.md#rays-and-scans).

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::key::{OcKey, TREE_DEPTH, TREE_MAX_VAL, coord_to_key_axis, floor_to_i32, key_to_coord_axis};
use super::{Octree, OctreeError, SearchCache};

/// Options of [`Octree::cast_ray`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayParams {
    /// Treat unknown cells as free and go on (`true`) or stop there (`false`, OctoMap's
    /// default: a ray ends at the first unknown cell, reported as not hitting).
    pub ignore_unknown: bool,
    /// Stop once the centre of the current cell is farther than this from the origin
    /// (m); ≤ 0 means no limit. Default −1.
    pub max_range: f64,
}

impl Default for RayParams {
    fn default() -> Self {
        Self {
            ignore_unknown: false,
            max_range: -1.0,
        }
    }
}

/// Why a cast ray stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RayStop {
    /// An occupied cell (the only outcome OctoMap reports as `true`).
    Occupied,
    /// An unknown cell while `ignore_unknown` is false.
    Unknown,
    /// The next cell lies beyond `max_range`.
    MaxRange,
    /// The ray reached the border of the tree's cube.
    Bounds,
}

/// Result of one cast.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// True when an occupied cell stopped the ray (OctoMap's return value).
    pub hit: bool,
    pub stop: RayStop,
    /// Centre of the cell where the ray stopped (m), as OctoMap's `end`.
    pub end: Point3<f64>,
    /// Its key.
    pub key: OcKey,
    /// Cells stepped through (DDA steps).
    pub steps: u32,
}

/// The per-axis DDA state of OctoMap: step sign, parameter of the next border,
/// parameter increment per cell.
#[derive(Clone, Copy)]
struct Dda {
    step: [i32; 3],
    t_max: [f64; 3],
    t_delta: [f64; 3],
}

impl Dda {
    /// `float_border`: `computeRayKeys` rounds the half cell to f32, `castRay` does not.
    #[inline]
    fn new(key: &OcKey, origin: &[f32; 3], dir: &[f32; 3], res: f64, float_border: bool) -> Self {
        let mut d = Dda {
            step: [0; 3],
            t_max: [f64::MAX; 3],
            t_delta: [f64::MAX; 3],
        };
        for i in 0..3 {
            d.step[i] = if dir[i] > 0.0 {
                1
            } else if dir[i] < 0.0 {
                -1
            } else {
                0
            };
            if d.step[i] != 0 {
                let half = d.step[i] as f64 * res * 0.5;
                let border =
                    key_to_coord_axis(key[i], res) + if float_border { half as f32 as f64 } else { half };
                d.t_max[i] = (border - origin[i] as f64) / dir[i] as f64;
                d.t_delta[i] = res / (dir[i].abs() as f64);
            }
        }
        d
    }

    /// Axis of the smallest `t_max`, ties resolved as OctoMap does.
    #[inline]
    fn axis(&self) -> usize {
        let t = &self.t_max;
        if t[0] < t[1] {
            if t[0] < t[2] { 0 } else { 2 }
        } else if t[1] < t[2] {
            1
        } else {
            2
        }
    }
}

/// Where a walk starts (see [`Octree::walk_start`]).
pub(crate) enum WalkStart {
    /// A point lies outside the tree's cube (the walk reports false).
    Outside,
    /// No cell to visit.
    Empty,
    From(Walk),
}

/// A started walk: its first cell `ks`, end cell `ke`, DDA state there and the
/// segment's length (m).
#[derive(Clone, Copy)]
pub(crate) struct Walk {
    ks: OcKey,
    ke: OcKey,
    dda: Dda,
    length: f64,
}

/// Addresses of the cells a walk visits: a cell's address is `Σ_a term(a, k_a)`.
pub(crate) trait CellAddress {
    fn term(&self, axis: usize, k: u16) -> usize;
}

/// Every cell at address 0 (walks that need keys only).
pub(crate) struct NoAddress;

impl CellAddress for NoAddress {
    #[inline]
    fn term(&self, _: usize, _: u16) -> usize {
        0
    }
}

/// `‖v‖` as OctoMap's `norm()`: the squares summed in f32, the root in f64.
#[inline]
pub(crate) fn f32_norm(v: &[f32; 3]) -> f64 {
    ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64).sqrt()
}

impl Octree {
    /// Key of an f32 point (OctoMap's `coordToKeyChecked(point3d)`).
    #[inline]
    pub(crate) fn key_of_f32(&self, p: &[f32; 3]) -> Option<OcKey> {
        let f = self.resolution_factor;
        Some([
            coord_to_key_axis(p[0] as f64, f)?,
            coord_to_key_axis(p[1] as f64, f)?,
            coord_to_key_axis(p[2] as f64, f)?,
        ])
    }

    /// The cells a beam from `origin` to `end` (m, map frame, rounded to f32 as OctoMap's
    /// `point3d`) passes through, end cell excluded, origin cell first — OctoMap's
    /// `computeRayKeys`: DDA with `t_max_i = (border_i − o_i)/d_i`,
    /// `t_delta_i = res/|d_i|`, stopping at the end key or once `min t_max > ‖end − o‖`.
    /// `out` is cleared and filled (no other allocation). Returns false (and leaves
    /// `out` empty) when either point is outside the tree's cube.
    pub fn compute_ray_keys(&self, origin: &[f32; 3], end: &[f32; 3], out: &mut Vec<OcKey>) -> bool {
        out.clear();
        self.visit_ray_keys(origin, end, |k| out.push(*k))
    }

    /// [`compute_ray_keys`](Self::compute_ray_keys) handing each key to `visit` in order
    /// instead of collecting them.
    #[inline]
    pub(crate) fn visit_ray_keys(
        &self,
        origin: &[f32; 3],
        end: &[f32; 3],
        mut visit: impl FnMut(&OcKey),
    ) -> bool {
        self.visit_ray_cells(origin, end, &NoAddress, |k, _| visit(k))
    }

    /// [`visit_ray_keys`](Self::visit_ray_keys) handing each key with its address
    /// `Σ_a addr.term(a, k_a)`, kept up to date by one term per step (the beam must lie
    /// where `addr` is defined).
    #[inline]
    pub(crate) fn visit_ray_cells(
        &self,
        origin: &[f32; 3],
        end: &[f32; 3],
        addr: &impl CellAddress,
        visit: impl FnMut(&OcKey, usize),
    ) -> bool {
        self.visit_ray_cells_from(origin, end, 0.0, addr, visit)
    }

    /// [`visit_ray_cells`](Self::visit_ray_cells) from the ray parameter `t_start`
    /// (m from `origin`) on: the cells before it are left out. The walk starts in the
    /// cell holding `o + t_start·d̂` with the DDA state in closed form,
    /// `t_max_i = (border_i − o_i)/d̂_i` — the value the walk from the origin reaches
    /// by summing `t_delta_i`, up to rounding — so the cells after `t_start` are those
    /// of the whole walk (a cell can differ only where two borders lie within rounding
    /// of each other). `t_start ≤ 0` is the whole walk; with `t_start > 0` the origin's
    /// cell is not looked up (the caller has checked it lies in the tree).
    #[inline]
    pub(crate) fn visit_ray_cells_from(
        &self,
        origin: &[f32; 3],
        end: &[f32; 3],
        t_start: f64,
        addr: &impl CellAddress,
        visit: impl FnMut(&OcKey, usize),
    ) -> bool {
        self.walk_from(self.ray_walk_start(origin, end, t_start), addr, visit)
    }

    /// Walks from `start`: false when the beam lies outside the tree's cube.
    #[inline]
    pub(crate) fn walk_from(
        &self,
        start: WalkStart,
        addr: &impl CellAddress,
        visit: impl FnMut(&OcKey, usize),
    ) -> bool {
        match start {
            WalkStart::Outside => false,
            WalkStart::Empty => true,
            WalkStart::From(w) => {
                self.walk(&w, addr, visit);
                true
            }
        }
    }

    /// Where the walk of [`visit_ray_cells_from`](Self::visit_ray_cells_from) starts.
    #[inline]
    pub(crate) fn ray_walk_start(&self, origin: &[f32; 3], end: &[f32; 3], t_start: f64) -> WalkStart {
        let diff = [end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]];
        let norm = f32_norm(&diff);
        if t_start > 0.0 && t_start >= norm as f32 as f64 {
            return WalkStart::Empty;
        }
        let Some(ke) = self.key_of_f32(end) else {
            return WalkStart::Outside;
        };
        self.walk_start(origin, &diff, norm, &ke, t_start)
    }

    /// The start of a beam's walk given its difference `end − origin` (f32), its
    /// norm `f32_norm(diff)` and the end point's key (in the tree): its first cell
    /// and DDA state, or why it visits nothing. Apart from the walk itself, so that a scan can work out
    /// the starts of many beams in a row (independent of each other) before it walks
    /// them.
    #[inline]
    pub(crate) fn walk_start(
        &self,
        origin: &[f32; 3],
        diff: &[f32; 3],
        norm: f64,
        ke: &OcKey,
        t_start: f64,
    ) -> WalkStart {
        let ke = *ke;
        let length = norm as f32;
        if t_start > 0.0 && t_start >= length as f64 {
            return WalkStart::Empty;
        }
        let dir = diff.map(|v| v / length);
        let length = length as f64;
        let (ks, dda) = if t_start > 0.0 {
            let f = self.resolution_factor;
            // `coord_to_key_axis` with the range test on the key: the point lies
            // between two points of the cube, so |c·f| < 2^51 and the floor is exact
            let at = |i: usize| {
                let s = (origin[i] as f64 + t_start * dir[i] as f64) * f;
                floor_to_i32(s).wrapping_add(TREE_MAX_VAL) as u32
            };
            let k = [at(0), at(1), at(2)];
            if (k[0] | k[1] | k[2]) > u16::MAX as u32 {
                return WalkStart::Empty;
            }
            let ks = k.map(|k| k as u16);
            if ks == ke {
                return WalkStart::Empty;
            }
            let dda = Dda::new(&ks, origin, &dir, self.resolution, true);
            // the whole walk visits this cell only when it leaves it before the end
            let exit = dda.t_max[0].min(dda.t_max[1]).min(dda.t_max[2]);
            if exit > length {
                return WalkStart::Empty;
            }
            (ks, dda)
        } else {
            // a start inside the segment lies in the end cell when the origin does
            // (cells are convex), so only the whole walk checks the origin's cell
            let Some(ko) = self.key_of_f32(origin) else {
                return WalkStart::Outside;
            };
            if ko == ke {
                return WalkStart::Empty;
            }
            (ko, Dda::new(&ko, origin, &dir, self.resolution, true))
        };
        WalkStart::From(Walk { ks, ke, dda, length })
    }

    /// Visits the cells of a started walk (see [`walk_start`](Self::walk_start)).
    #[inline]
    pub(crate) fn walk(&self, w: &Walk, addr: &impl CellAddress, mut visit: impl FnMut(&OcKey, usize)) {
        let Walk {
            ks,
            ke,
            ref dda,
            length,
        } = *w;
        visit(
            &ks,
            addr.term(0, ks[0]) + addr.term(1, ks[1]) + addr.term(2, ks[2]),
        );
        // Steps until the key can equal the end key: the walk moves each axis by its
        // sign only, so it meets `ke` exactly after Σ_a (ke_a − ks_a)·step_a steps if
        // every term is ≥ 0 (and 0 on a still axis), or never (−1: the count only
        // falls and never meets 0).
        let to_end = (0..3)
            .try_fold(0i64, |n, a| {
                let r = (ke[a] as i64 - ks[a] as i64) * dda.step[a] as i64;
                (r >= 0 && (dda.step[a] != 0 || r == 0)).then_some(n + r)
            })
            .unwrap_or(-1);
        // the DDA state in scalar locals (registers): an array indexed by the axis made
        // each step wait on a partial store-to-load forward of the key
        let [mut kx, mut ky, mut kz] = ks;
        let [mut tx, mut ty, mut tz] = dda.t_max;
        let [dx, dy, dz] = dda.t_delta;
        let [sx, sy, sz] = dda.step.map(|s| s as u16); // ±1 as a wrapping u16 step
        let [mut ax, mut ay, mut az] = [0, 1, 2].map(|a| addr.term(a, ks[a]));
        // The walk visits the cell it enters unless it is the end cell or the segment
        // ends before leaving it (`min t_max > length`). That minimum is the `t_max`
        // the next step picks, so the test waits for the next axis choice: each
        // branch first checks its own `t_max` (not for the first step, out of the
        // start cell, visited above), then visits the cell, then steps.
        macro_rules! step {
            ($walk:lifetime, $t:ident, $d:ident, $k:ident, $s:ident, $a:ident, $axis:expr, $first:expr) => {{
                if !$first {
                    if $t > length {
                        break $walk;
                    }
                    visit(&[kx, ky, kz], ax + ay + az);
                }
                $k = $k.wrapping_add($s);
                $t += $d;
                $a = addr.term($axis, $k);
            }};
        }
        // axis of the smallest t_max, ties as in `Dda::axis`
        macro_rules! choose_and_step {
            ($walk:lifetime, $first:expr) => {{
                if tx < ty {
                    if tx < tz {
                        step!($walk, tx, dx, kx, sx, ax, 0, $first)
                    } else {
                        step!($walk, tz, dz, kz, sz, az, 2, $first)
                    }
                } else if ty < tz {
                    step!($walk, ty, dy, ky, sy, ay, 1, $first)
                } else {
                    step!($walk, tz, dz, kz, sz, az, 2, $first)
                }
            }};
        }
        // The key can equal the end key only after exactly `to_end` steps, so the
        // first `to_end` steps run without looking at it, then it is compared once;
        // a walk that missed it (or never meets it, `to_end` = −1) goes on until
        // the length stops it. A beam between two keys in the cube crosses at most
        // 3 · 65536 borders.
        'walk: {
            choose_and_step!('walk, true);
            for _ in 1..to_end {
                choose_and_step!('walk, false);
            }
            if to_end >= 1 && kx == ke[0] && ky == ke[1] && kz == ke[2] {
                break 'walk;
            }
            for _ in 0..3 * 65536 {
                choose_and_step!('walk, false);
            }
        }
    }

    /// Casts a ray from `origin` along `direction` (m, map frame; both rounded to f32)
    /// and stops at the first occupied cell — OctoMap's `castRay`: an occupied origin
    /// cell is a hit at once; an unknown origin (unless `ignore_unknown`) stops with
    /// `Unknown`; the cube's border stops with `Bounds`; with `max_range > 0` a cell whose
    /// centre is farther stops with `MaxRange`. Errors: origin outside the cube, zero or
    /// non-finite direction.
    pub fn cast_ray(
        &self,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        params: &RayParams,
    ) -> Result<RayHit, OctreeError> {
        let o = [origin.x as f32, origin.y as f32, origin.z as f32];
        let d = [direction.x as f32, direction.y as f32, direction.z as f32];
        if o.iter().any(|v| !v.is_finite()) {
            return Err(OctreeError::NonFinite { field: "origin" });
        }
        if d.iter().any(|v| !v.is_finite()) {
            return Err(OctreeError::NonFinite { field: "direction" });
        }
        let ko = self
            .key_of_f32(&o)
            .ok_or(OctreeError::OutOfBounds { field: "origin" })?;
        self.cast_ray_f32(&o, &d, &ko, params)
    }

    pub(crate) fn cast_ray_f32(
        &self,
        o: &[f32; 3],
        d: &[f32; 3],
        ko: &OcKey,
        params: &RayParams,
    ) -> Result<RayHit, OctreeError> {
        let res = self.resolution;
        let center = |k: &OcKey| [0, 1, 2].map(|i| key_to_coord_axis(k[i], res) as f32);
        let finish = |k: OcKey, hit, stop, steps| RayHit {
            hit,
            stop,
            end: Point3::from(center(&k).map(|v| v as f64)),
            key: k,
            steps,
        };
        match self.search_key(ko, TREE_DEPTH) {
            Some((v, _)) if self.is_occupied_value(v) => return Ok(finish(*ko, true, RayStop::Occupied, 0)),
            None if !params.ignore_unknown => return Ok(finish(*ko, false, RayStop::Unknown, 0)),
            _ => {}
        }
        let len = f32_norm(d);
        if len <= 0.0 {
            return Err(OctreeError::InvalidParam {
                field: "direction",
                value: 0.0,
                reason: "must not be zero",
            });
        }
        let lenf = len as f32;
        let dir = [d[0] / lenf, d[1] / lenf, d[2] / lenf];
        let mut dda = Dda::new(ko, o, &dir, res, false);
        let limit = params.max_range > 0.0;
        let range_sq = params.max_range * params.max_range;
        let mut k = *ko;
        let mut steps = 0u32;
        let mut cache = SearchCache::default();
        loop {
            let a = dda.axis();
            if (dda.step[a] < 0 && k[a] == 0) || (dda.step[a] > 0 && k[a] == u16::MAX) {
                return Ok(finish(k, false, RayStop::Bounds, steps));
            }
            k[a] = (k[a] as i32 + dda.step[a]) as u16;
            dda.t_max[a] += dda.t_delta[a];
            steps += 1;
            if limit {
                let c = center(&k);
                let mut sq = 0.0f64;
                for j in 0..3 {
                    let e = c[j] - o[j];
                    sq += (e * e) as f64;
                }
                if sq > range_sq {
                    return Ok(finish(k, false, RayStop::MaxRange, steps));
                }
            }
            match self.search_key_cached(&k, &mut cache) {
                Some((v, _)) if self.is_occupied_value(v) => {
                    return Ok(finish(k, true, RayStop::Occupied, steps));
                }
                None if !params.ignore_unknown => return Ok(finish(k, false, RayStop::Unknown, steps)),
                _ => {}
            }
        }
    }

    /// Casts many rays `(origin, direction)` in parallel on the rayon pool; one result
    /// per ray, in order.
    pub fn cast_rays(
        &self,
        rays: &[(Point3<f64>, Vector3<f64>)],
        params: &RayParams,
    ) -> Vec<Result<RayHit, OctreeError>> {
        rays.par_iter()
            .with_min_len(256)
            .map(|(o, d)| self.cast_ray(o, d, params))
            .collect()
    }
}
