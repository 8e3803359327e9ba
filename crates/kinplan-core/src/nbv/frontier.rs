//! Candidate views from frontier cells and the potential field (docs/exploration.md#candidates,
//! S0 §4.1 eq. 4.1).

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{Isometry3, Point3, Vector3};
use rayon::prelude::*;

use super::camera::look_along;
use super::grid::{Ball, MAX_CELLS, StateGrid};
use crate::Deadline;
use crate::octree::{CellState, OcKey, Octree, SearchCache, StateFilter, TREE_DEPTH};

/// One frontier cell: a known-free depth-16 cell with enough unknown neighbours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frontier {
    pub key: OcKey,
    /// Centre (m, map frame).
    pub center: Point3<f64>,
    /// Unknown share of its 26 neighbours (0–1).
    pub unknown_ratio: f64,
}

/// Unknown neighbours (of 26) a frontier cell needs: the least `u` with
/// `u/26 ≥ min_unknown_ratio` (at least 1; 27, none, for a NaN or a ratio above 1).
pub(crate) fn unknown_needed(min_unknown_ratio: f64) -> usize {
    (1..=26usize)
        .find(|&u| u as f64 / 26.0 >= min_unknown_ratio)
        .unwrap_or(27)
}

/// Frontier cells inside the box `[min, max]` (m): free depth-16 cells (including the
/// surface cells of pruned free cubes) whose 26 neighbours are unknown in a share of at
/// least `min_unknown_ratio`. Sorted by key (x fastest) so the result is deterministic.
///
/// When the box's keys with one cell of margin hold at most `grid::MAX_CELLS` (2^24) cells, the
/// states are copied into a dense grid once and counted by 3×3×3 block sums
/// (`StateGrid::frontier`, z planes in parallel, `deadline` polled per plane);
/// otherwise free cubes are scanned in parallel chunks with neighbour lookups in the
/// tree (`deadline` polled every 256 cells of a chunk). Either way the cells found
/// so far are returned when stopped.
pub fn frontier_cells(
    tree: &Octree,
    min: &Point3<f64>,
    max: &Point3<f64>,
    min_unknown_ratio: f64,
    deadline: Deadline<'_>,
) -> Result<Vec<Frontier>, crate::octree::OctreeError> {
    let (kmin, kmax) = (tree.key_of(min)?, tree.key_of(max)?);
    if (0..3).all(|i| kmin[i] <= kmax[i]) {
        let lo = kmin.map(|k| k as i64 - 1);
        let hi = kmax.map(|k| k as i64 + 1);
        if let Some(g) = StateGrid::new(tree, lo, hi, MAX_CELLS) {
            return Ok(g.frontier(tree, &kmin, &kmax, unknown_needed(min_unknown_ratio), deadline));
        }
    }
    frontier_by_lookups(tree, min, max, min_unknown_ratio, deadline)
}

/// [`frontier_cells`] by neighbour lookups in the tree: the surface cells of every free
/// cube in the box, skipping cubes whose 26 same-size neighbour cubes are single
/// leaves (no grid, so no memory beyond the result for any box size).
pub(crate) fn frontier_by_lookups(
    tree: &Octree,
    min: &Point3<f64>,
    max: &Point3<f64>,
    min_unknown_ratio: f64,
    deadline: Deadline<'_>,
) -> Result<Vec<Frontier>, crate::octree::OctreeError> {
    let mut cubes = Vec::new();
    let free = StateFilter {
        free: true,
        occupied: false,
        unknown: false,
    };
    tree.for_each_in_box(min, max, TREE_DEPTH, free, |c| cubes.push((c.key, c.depth)))?;
    let (kmin, kmax) = (tree.key_of(min)?, tree.key_of(max)?);
    // unknown neighbours needed: the least u with u/26 ≥ the ratio (same test as below)
    let need = unknown_needed(min_unknown_ratio);
    let stopped = AtomicBool::new(false);
    // one cell of the free cube [base, base + n): neighbours inside the cube are known
    // (free) without a lookup; the lookups stop once too many are known to qualify
    // `sure`: bit `r0 + 3·r1 + 9·r2` set when the region r (0 below, 1 inside, 2 above the
    // cube along each axis) is known throughout — the cube itself, or a same-size
    // neighbour cube that is one leaf
    let region = |v: i32, b: u16, n: u32| -> usize {
        if v < b as i32 {
            0
        } else if v >= b as i32 + n as i32 {
            2
        } else {
            1
        }
    };
    let test = |k: OcKey, base: &OcKey, n: u32, sure: u32, cache: &mut SearchCache| -> Option<Frontier> {
        if (0..3).any(|i| k[i] < kmin[i] || k[i] > kmax[i]) {
            return None;
        }
        let cell = |o: [i32; 3]| {
            let nb = [0, 1, 2].map(|i| k[i] as i32 + o[i]);
            let inside = nb.iter().all(|v| (0..65536).contains(v));
            let r = region(nb[0], base[0], n) + 3 * region(nb[1], base[1], n) + 9 * region(nb[2], base[2], n);
            (nb, inside, sure & (1 << r) != 0)
        };
        // neighbours that may be unknown: too few, and the cell cannot qualify
        let mut possible = 0usize;
        for d in 0..27 {
            let o = [d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1];
            if d != 13 {
                let (_, inside, known) = cell(o);
                possible += (inside && !known) as usize;
            }
        }
        if possible < need {
            return None;
        }
        let mut unknown = 0usize;
        let mut known = 0usize;
        for dz in -1..=1i32 {
            for dy in -1..=1i32 {
                for dx in -1..=1i32 {
                    if dx == 0 && dy == 0 && dz == 0 {
                        continue;
                    }
                    let nb = [k[0] as i32 + dx, k[1] as i32 + dy, k[2] as i32 + dz];
                    if nb.iter().any(|v| !(0..65536).contains(v)) {
                        continue;
                    }
                    let (_, _, sure_known) = cell([dx, dy, dz]);
                    let nb = [nb[0] as u16, nb[1] as u16, nb[2] as u16];
                    if sure_known || tree.search_key_cached(&nb, cache).is_some() {
                        known += 1;
                        if known + need > 26 {
                            return None;
                        }
                    } else {
                        unknown += 1;
                    }
                }
            }
        }
        let ratio = unknown as f64 / 26.0;
        (unknown > 0 && ratio >= min_unknown_ratio).then(|| Frontier {
            key: k,
            center: tree.key_center(&k, TREE_DEPTH),
            unknown_ratio: ratio,
        })
    };
    // the surface cells of each free cube (only they can border anything but the cube),
    // clipped to the region's keys; cubes in parallel chunks, results in cube order
    let scan_cube = |&(base, depth): &(OcKey, u8),
                     out: &mut Vec<Frontier>,
                     cache: &mut SearchCache,
                     polled: &mut usize| {
        let n = 1u32 << (TREE_DEPTH - depth);
        let lo = [0, 1, 2].map(|i| (kmin[i] as u32).saturating_sub(base[i] as u32));
        let hi = [0, 1, 2].map(|i| (n - 1).min((kmax[i] as u32).saturating_sub(base[i] as u32)));
        if (0..3).any(|i| lo[i] > hi[i] || base[i] as u32 > kmax[i] as u32) {
            return;
        }
        let mut sure = 1u32 << 13;
        if n > 1 {
            for r in 0..27u32 {
                let o = [r % 3, r / 3 % 3, r / 9].map(|v| v as i64 - 1);
                let nb = [0, 1, 2].map(|i| base[i] as i64 + o[i] * n as i64);
                if r != 13 && nb.iter().all(|v| (0..65536).contains(v)) {
                    let key = nb.map(|v| v as u16);
                    if one_leaf(tree, &key, depth) {
                        sure |= 1 << r;
                    }
                }
            }
            if sure == (1 << 27) - 1 {
                return; // every cell around the cube is known: no frontier on it
            }
        }
        for dz in lo[2]..=hi[2] {
            for dy in lo[1]..=hi[1] {
                let surface_yz = dz == 0 || dz == n - 1 || dy == 0 || dy == n - 1;
                let mut visit = |dx: u32, out: &mut Vec<Frontier>| {
                    *polled += 1;
                    let k = [base[0] + dx as u16, base[1] + dy as u16, base[2] + dz as u16];
                    out.extend(test(k, &base, n, sure, cache));
                    if polled.is_multiple_of(256) && deadline.expired() {
                        stopped.store(true, Ordering::Relaxed);
                    }
                    stopped.load(Ordering::Relaxed)
                };
                if surface_yz {
                    for dx in lo[0]..=hi[0] {
                        if visit(dx, out) {
                            return;
                        }
                    }
                } else {
                    for dx in [0, n - 1] {
                        if (lo[0]..=hi[0]).contains(&dx) && visit(dx, out) {
                            return;
                        }
                        if n == 1 {
                            break;
                        }
                    }
                }
            }
        }
    };
    let parts: Vec<Vec<Frontier>> = cubes
        .par_chunks(64)
        .map(|chunk| {
            let mut out = Vec::new();
            let mut cache = SearchCache::default();
            let mut polled = 0usize;
            for c in chunk {
                if stopped.load(Ordering::Relaxed) {
                    break;
                }
                scan_cube(c, &mut out, &mut cache, &mut polled);
            }
            out
        })
        .collect();
    let mut out: Vec<Frontier> = parts.into_iter().flatten().collect();
    out.sort_by_key(|f| (f.key[2], f.key[1], f.key[0]));
    Ok(out)
}

/// True when the depth-`depth` cube with smallest key `key` lies inside one leaf (a
/// known node without children at that depth or above).
fn one_leaf(tree: &Octree, key: &OcKey, depth: u8) -> bool {
    let Some(mut n) = tree.root_ref() else {
        return false;
    };
    for d in 0..depth {
        if !tree.has_children(n) {
            return true;
        }
        match tree.child_ref(n, crate::octree::child_index(key, d)) {
            Some(c) => n = c,
            None => return false,
        }
    }
    !tree.has_children(n)
}

/// Potential field of the frontier cell `key` (S0 eq. 4.1, docs/exploration.md#candidates):
/// `F = Σ F_p − Σ F_o` over every depth-16 cell `k + o` within `radius` (m) of the
/// cell's centre — `0 < ‖o·res‖ ≤ radius` — where an unknown cell attracts and a known
/// (free or occupied) cell repels with `o·res/‖o·res‖²` (unit direction over distance,
/// so closer cells weigh more); cells outside the key space add nothing. Exact per
/// cell: the cells of the radius' key box are read from a dense grid filled from the
/// tree (`grid::StateGrid`).
///
/// Approximation above `grid::MAX_BALL_REACH` (32) cells of radius only: octree cubes are
/// then taken whole — each cube's part inside the radius' box counts as
/// its cell count at its centre (see [`potential_field_cubes`]).
pub fn potential_field(
    tree: &Octree,
    key: &OcKey,
    radius: f64,
) -> Result<Vector3<f64>, crate::octree::OctreeError> {
    let Some(ball) = Ball::new(tree.resolution(), radius) else {
        return potential_field_cubes(tree, &tree.key_center(key, TREE_DEPTH), radius);
    };
    let lo = key.map(|k| k as i64 - ball.reach);
    let hi = key.map(|k| k as i64 + ball.reach);
    let g = StateGrid::new(tree, lo, hi, usize::MAX).expect("a ball's box is never empty");
    Ok(g.field(key, &ball))
}

/// The field of wide radii (over `grid::MAX_BALL_REACH` cells), approximated by cubes:
/// every octree cube overlapping the radius' box around `p` is clipped to the box and
/// contributes its clipped cell count (rounded, at least one) times `(c − p)/‖c − p‖²`
/// at the clipped part's centre `c`, when `0 < ‖c − p‖ ≤ radius`. The cost follows the
/// tree, not the radius³; the direction differs from the per-cell sum by the spread of
/// each cube's cells around its centre.
pub fn potential_field_cubes(
    tree: &Octree,
    p: &Point3<f64>,
    radius: f64,
) -> Result<Vector3<f64>, crate::octree::OctreeError> {
    let r = Vector3::repeat(radius);
    let (bmin, bmax) = (p - r, p + r);
    let res = tree.resolution();
    let mut f = Vector3::zeros();
    tree.for_each_in_box(&bmin, &bmax, TREE_DEPTH, StateFilter::ALL, |c| {
        let h = c.size / 2.0;
        let lo = (c.center - Vector3::repeat(h)).coords.sup(&bmin.coords);
        let hi = (c.center + Vector3::repeat(h)).coords.inf(&bmax.coords);
        let ext = hi - lo;
        if ext.iter().any(|&e| e <= 0.0) {
            return;
        }
        let centre = (lo + hi) / 2.0;
        let d = centre - p.coords;
        let dist = d.norm();
        if dist > radius || dist < 1e-9 {
            return;
        }
        let weight =
            (ext.x / res).round().max(1.0) * (ext.y / res).round().max(1.0) * (ext.z / res).round().max(1.0);
        let term = d / (dist * dist) * weight;
        if c.state == CellState::Unknown {
            f += term;
        } else {
            f -= term;
        }
    })?;
    Ok(f)
}

/// A camera pose for a frontier cell: looking along `F̂` from `P_c − s·F̂`, with the
/// stand-off `s = max(standoff, near)` so the frontier is not closer than the sensor's
/// near range. `None` when `F` vanishes.
pub fn candidate_pose(
    frontier: &Point3<f64>,
    field: &Vector3<f64>,
    standoff: f64,
    near: f64,
) -> Option<Isometry3<f64>> {
    let dir = field.try_normalize(1e-12)?;
    let s = standoff.max(near);
    look_along(&(frontier - dir * s), &dir)
}
