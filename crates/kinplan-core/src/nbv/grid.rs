//! A dense grid of depth-16 cell states over one key box, filled from the tree in one
//! pass, so that the frontier test (26 neighbours per cell) and the potential field
//! (every cell within the radius) read bytes instead of descending the tree per cell
//! (docs/exploration.md#candidates, S0 §4.1).

use nalgebra::Vector3;
use rayon::prelude::*;

use super::frontier::Frontier;
use crate::Deadline;
use crate::octree::{NodeRef, OcKey, Octree, TREE_DEPTH, child_key};

/// No node covers the cell.
pub(crate) const UNKNOWN: u8 = 0;
/// A leaf at or below the occupancy threshold covers it.
pub(crate) const FREE: u8 = 1;
/// A leaf above the threshold covers it.
pub(crate) const OCCUPIED: u8 = 2;
/// The cell lies outside the tree's key space `[0, 65536)³` (no cell there).
pub(crate) const OUTSIDE: u8 = 3;

/// Largest grid built for a region (cells, one byte each, plus one byte each for the
/// frontier's row sums): 2^24, at most 32 MiB per request together (a 20 × 20 × 5 m
/// region at 5 cm fits). Larger boxes take the tree-lookup paths instead.
pub(crate) const MAX_CELLS: usize = 1 << 24;

/// Cell states of the inclusive key box `[lo, hi]` (keys as i64, so the box may reach
/// one cell or more past the key space: those cells are [`OUTSIDE`]). x fastest.
#[derive(Debug, Clone)]
pub(crate) struct StateGrid {
    pub lo: [i64; 3],
    pub dims: [usize; 3],
    pub cells: Vec<u8>,
}

impl StateGrid {
    /// Fills the grid from `tree`: every leaf overlapping the box writes its state into
    /// the cells it covers (clipped to the box); the rest stays unknown. `None` when the
    /// box is empty or holds more than `max_cells` cells.
    pub fn new(tree: &Octree, lo: [i64; 3], hi: [i64; 3], max_cells: usize) -> Option<Self> {
        let mut dims = [0usize; 3];
        for i in 0..3 {
            if hi[i] < lo[i] {
                return None;
            }
            dims[i] = usize::try_from(hi[i] - lo[i] + 1).ok()?;
        }
        let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d))?;
        if n > max_cells {
            return None;
        }
        let mut g = Self {
            lo,
            dims,
            cells: vec![UNKNOWN; n],
        };
        let max_key = (1i64 << TREE_DEPTH) - 1;
        if (0..3).any(|i| lo[i] < 0 || hi[i] > max_key) {
            for z in 0..dims[2] {
                for y in 0..dims[1] {
                    for x in 0..dims[0] {
                        let k = [x, y, z].map(|v| v as i64);
                        if (0..3).any(|i| !(0..=max_key).contains(&(lo[i] + k[i]))) {
                            let j = g.index(k);
                            g.cells[j] = OUTSIDE;
                        }
                    }
                }
            }
        }
        // two slabs along z, filled side by side (each cell lies in one leaf at most,
        // so the slabs' walks write disjoint cells)
        let plane = dims[0] * dims[1];
        let mid = dims[2] / 2;
        if mid == 0 || n < 1 << 16 {
            fill_from_tree(tree, &mut g.cells, lo, hi, dims[0], dims[1]);
        } else {
            let (near, far) = g.cells.split_at_mut(mid * plane);
            let z_mid = lo[2] + mid as i64;
            rayon::join(
                || fill_from_tree(tree, near, lo, [hi[0], hi[1], z_mid - 1], dims[0], dims[1]),
                || fill_from_tree(tree, far, [lo[0], lo[1], z_mid], hi, dims[0], dims[1]),
            );
        }
        Some(g)
    }

    /// Linear index of the grid cell at offsets `k` from `lo`.
    #[inline]
    pub fn index(&self, k: [i64; 3]) -> usize {
        (k[0] as usize) + self.dims[0] * ((k[1] as usize) + self.dims[1] * (k[2] as usize))
    }

    /// Index of the key `key`, `None` outside the grid.
    #[inline]
    pub fn index_of(&self, key: &OcKey) -> Option<usize> {
        let k = [0, 1, 2].map(|i| key[i] as i64 - self.lo[i]);
        (0..3)
            .all(|i| k[i] >= 0 && (k[i] as usize) < self.dims[i])
            .then(|| self.index(k))
    }

    /// Frontier cells of the key box `[kmin, kmax]`, which must lie inside the grid with
    /// at least one cell of margin on every side: free cells with at least `need` (≥ 1)
    /// unknown cells among their 26 neighbours. The unknown neighbours are `27 − S`,
    /// `S` the known (free, occupied or outside) cells of the 3×3×3 block, summed as
    /// three-cell row sums along x added over the nine rows. Same cells and ratios as
    /// [`frontier_cells`](super::frontier_cells)' neighbour lookups, in key order (z,
    /// y, x). `deadline` is polled per z plane; the planes done by then are returned.
    pub fn frontier(
        &self,
        tree: &Octree,
        kmin: &OcKey,
        kmax: &OcKey,
        need: usize,
        deadline: Deadline<'_>,
    ) -> Vec<Frontier> {
        let [nx, ny, _] = self.dims;
        let plane = nx * ny;
        let o = [0, 1, 2].map(|i| (kmin[i] as i64 - self.lo[i]) as usize);
        let e = [0, 1, 2].map(|i| (kmax[i] as i64 - self.lo[i]) as usize);
        debug_assert!((0..3).all(|i| o[i] >= 1 && e[i] + 1 < self.dims[i]));
        // row sums of the known flags along x over the planes o[2] − 1 ..= e[2] + 1
        let z0 = o[2] - 1;
        let nz = e[2] - o[2] + 3;
        let mut rows = vec![0u8; nz * plane];
        rows.par_chunks_mut(plane).enumerate().for_each(|(dz, out)| {
            let src = &self.cells[(z0 + dz) * plane..(z0 + dz + 1) * plane];
            for y in o[1] - 1..=e[1] + 1 {
                let r = &src[y * nx..(y + 1) * nx];
                let w = &mut out[y * nx..(y + 1) * nx];
                for x in o[0]..=e[0] {
                    w[x] =
                        (r[x - 1] != UNKNOWN) as u8 + (r[x] != UNKNOWN) as u8 + (r[x + 1] != UNKNOWN) as u8;
                }
            }
        });
        let parts: Vec<Vec<Frontier>> = (o[2]..=e[2])
            .into_par_iter()
            .map(|z| {
                let mut out = Vec::new();
                if deadline.expired() {
                    return out;
                }
                let rz = z - z0;
                for y in o[1]..=e[1] {
                    let cells = &self.cells[z * plane + y * nx..z * plane + (y + 1) * nx];
                    let rr = |dy: usize, dz: usize| {
                        let s = (rz + dz - 1) * plane + (y + dy - 1) * nx;
                        &rows[s..s + nx]
                    };
                    let r = [
                        rr(0, 0),
                        rr(1, 0),
                        rr(2, 0),
                        rr(0, 1),
                        rr(1, 1),
                        rr(2, 1),
                        rr(0, 2),
                        rr(1, 2),
                        rr(2, 2),
                    ];
                    for x in o[0]..=e[0] {
                        if cells[x] != FREE {
                            continue;
                        }
                        let s: usize = r.iter().map(|row| row[x] as usize).sum();
                        let unknown = 27 - s;
                        if unknown >= need {
                            let k = [0, 1, 2].map(|i| (self.lo[i] + [x, y, z][i] as i64) as u16);
                            out.push(Frontier {
                                key: k,
                                center: tree.key_center(&k, TREE_DEPTH),
                                unknown_ratio: unknown as f64 / 26.0,
                            });
                        }
                    }
                }
                out
            })
            .collect();
        parts.into_iter().flatten().collect()
    }

    /// The potential field of the cell `key` (which must lie inside the grid with the
    /// ball's margin on every side) over the cells of `ball`:
    /// `F = Σ s(k + o)·o·res/‖o·res‖²`, `s` = +1 unknown, −1 free or occupied, 0 outside
    /// the key space.
    pub fn field(&self, key: &OcKey, ball: &Ball) -> Vector3<f64> {
        const SIGN: [f64; 4] = [1.0, -1.0, -1.0, 0.0];
        let c = self.index_of(key).expect("field cell inside the grid") as isize;
        let (sy, sz) = (self.dims[0] as isize, (self.dims[0] * self.dims[1]) as isize);
        let mut f = [0.0f64; 3];
        for (o, v) in ball.offsets.iter().zip(&ball.terms) {
            let j = (c + o[0] as isize + sy * o[1] as isize + sz * o[2] as isize) as usize;
            let s = SIGN[self.cells[j] as usize & 3];
            f[0] += s * v[0];
            f[1] += s * v[1];
            f[2] += s * v[2];
        }
        Vector3::from(f)
    }
}

/// Writes every leaf of `tree` overlapping the key box `[lo, hi]` into `cells`, the
/// box's cells (x fastest, rows of `nx`, planes of `nx · ny`), clipped to the box.
fn fill_from_tree(tree: &Octree, cells: &mut [u8], lo: [i64; 3], hi: [i64; 3], nx: usize, ny: usize) {
    let Some(root) = tree.root_ref() else {
        return;
    };
    let thr = tree.threshold_log_odds();
    let mut stack: Vec<(NodeRef, OcKey, u8)> = Vec::with_capacity(8 * (TREE_DEPTH as usize + 1));
    stack.push((root, [0; 3], 0));
    while let Some((node, key, depth)) = stack.pop() {
        let side = 1i64 << (TREE_DEPTH - depth);
        let a = [0, 1, 2].map(|i| (key[i] as i64).max(lo[i]));
        let b = [0, 1, 2].map(|i| (key[i] as i64 + side - 1).min(hi[i]));
        if (0..3).any(|i| a[i] > b[i]) {
            continue;
        }
        if !tree.has_children(node) {
            let s = if tree.log_odds_of(node) > thr {
                OCCUPIED
            } else {
                FREE
            };
            let (x0, x1) = ((a[0] - lo[0]) as usize, (b[0] - lo[0]) as usize);
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    let row = ((y - lo[1]) as usize + ny * (z - lo[2]) as usize) * nx;
                    cells[row + x0..=row + x1].fill(s);
                }
            }
            continue;
        }
        for i in 0..8 {
            if let Some(c) = tree.child_ref(node, i) {
                stack.push((c, child_key(&key, depth, i), depth + 1));
            }
        }
    }
}

/// Cells whose potential fields [`StateGrid::fields`] sums in one pass.
pub(crate) const FIELD_LANES: usize = 4;

impl StateGrid {
    /// The potential fields of [`field`](Self::field) for `FIELD_LANES` cells at once
    /// (each inside the grid with the ball's margin), bit for bit the same: per cell
    /// the same terms are added in the same order, but the cells' sums are independent
    /// chains of additions, which the processor overlaps (one cell's sum waits on each
    /// addition's latency). `lin` holds the ball's offsets as index steps of this grid
    /// ([`Ball::index_steps`]).
    pub fn fields(
        &self,
        keys: &[OcKey; FIELD_LANES],
        ball: &Ball,
        lin: &[isize],
    ) -> [Vector3<f64>; FIELD_LANES] {
        const SIGN: [f64; 4] = [1.0, -1.0, -1.0, 0.0];
        let [c0, c1, c2, c3] = keys.map(|k| self.index_of(&k).expect("field cell inside the grid") as isize);
        let sign = |i: isize| SIGN[self.cells[i as usize] as usize & 3];
        // twelve accumulators in registers: (cell, axis)
        let (mut x0, mut y0, mut z0) = (0.0f64, 0.0f64, 0.0f64);
        let (mut x1, mut y1, mut z1) = (0.0f64, 0.0f64, 0.0f64);
        let (mut x2, mut y2, mut z2) = (0.0f64, 0.0f64, 0.0f64);
        let (mut x3, mut y3, mut z3) = (0.0f64, 0.0f64, 0.0f64);
        for (&o, &[vx, vy, vz]) in lin.iter().zip(&ball.terms) {
            let (s0, s1, s2, s3) = (sign(c0 + o), sign(c1 + o), sign(c2 + o), sign(c3 + o));
            x0 += s0 * vx;
            y0 += s0 * vy;
            z0 += s0 * vz;
            x1 += s1 * vx;
            y1 += s1 * vy;
            z1 += s1 * vz;
            x2 += s2 * vx;
            y2 += s2 * vy;
            z2 += s2 * vz;
            x3 += s3 * vx;
            y3 += s3 * vy;
            z3 += s3 * vz;
        }
        [
            Vector3::new(x0, y0, z0),
            Vector3::new(x1, y1, z1),
            Vector3::new(x2, y2, z2),
            Vector3::new(x3, y3, z3),
        ]
    }
}

/// The key offsets `o ≠ 0` of the cells within `radius` of a cell centre —
/// `‖o·res‖ ≤ radius`, with `o·res` computed per axis as `o_i · res` in f64 — and each
/// one's term `o·res / ‖o·res‖²` (unit direction over distance).
#[derive(Debug, Clone)]
pub(crate) struct Ball {
    /// Largest |o_i|.
    pub reach: i64,
    pub offsets: Vec<[i32; 3]>,
    pub terms: Vec<[f64; 3]>,
}

/// Balls are built only up to a radius of this many cells (137,000 offsets, 5 MB);
/// wider radii take the cube approximation of [`potential_field`](super::potential_field).
pub(crate) const MAX_BALL_REACH: i64 = 32;

impl Ball {
    /// `None` when `radius / res` exceeds [`MAX_BALL_REACH`] cells.
    pub fn new(res: f64, radius: f64) -> Option<Self> {
        let q = (radius / res).floor();
        if !(q.is_finite() && q <= MAX_BALL_REACH as f64) {
            return None;
        }
        let reach = q.max(0.0) as i64 + 1;
        let mut offsets = Vec::new();
        let mut terms = Vec::new();
        for z in -reach..=reach {
            for y in -reach..=reach {
                for x in -reach..=reach {
                    if let Some(t) = ball_term([x, y, z], res, radius) {
                        offsets.push([x as i32, y as i32, z as i32]);
                        terms.push(t);
                    }
                }
            }
        }
        Some(Self {
            reach,
            offsets,
            terms,
        })
    }
}

impl Ball {
    /// The offsets as steps of the linear index of `grid` (x fastest).
    pub fn index_steps(&self, grid: &StateGrid) -> Vec<isize> {
        let (sy, sz) = (grid.dims[0] as isize, (grid.dims[0] * grid.dims[1]) as isize);
        self.offsets
            .iter()
            .map(|o| o[0] as isize + sy * o[1] as isize + sz * o[2] as isize)
            .collect()
    }
}

/// The field term of the key offset `o`: `o·res/‖o·res‖²` when `0 < ‖o·res‖ ≤ radius`.
#[inline]
pub(crate) fn ball_term(o: [i64; 3], res: f64, radius: f64) -> Option<[f64; 3]> {
    let d = Vector3::new(o[0] as f64 * res, o[1] as f64 * res, o[2] as f64 * res);
    let dist = d.norm();
    (o != [0; 3] && dist <= radius).then(|| {
        let t = d / (dist * dist);
        [t.x, t.y, t.z]
    })
}
