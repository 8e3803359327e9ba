//! The exact frustum count of unknown cells (docs/exploration.md#information-gain, S0 eq. 4.2's c):
//! octree culling against the frustum's planes with per-node known-cell counts, and
//! boundary cubes of unknown space counted row by row.

use nalgebra::Vector3;

use super::camera::Frustum;
use crate::octree::{CountBlock, KnownCellCounts, OcKey, Octree, TREE_DEPTH, child_key, key_to_coord_axis};

/// Unknown cubes of at most `2^ROW_LOG` cells a side that a plane cuts are counted row
/// by row instead of being split further.
const ROW_LOG: u8 = 4;
/// Plane-test margin (m): a cube counts as inside (outside) a plane only when all its
/// cell centres clear it by more than this, far above the rounding of the test, so the
/// culled answer equals the per-cell test; cubes in the band are counted exactly.
const EPS: f64 = 1e-9;
/// DFS stack bound: eight children pushed per level below the root.
const STACK: usize = 8 * TREE_DEPTH as usize + 1;

#[derive(Clone, Copy)]
struct Entry {
    key: OcKey,
    depth: u8,
    /// Planes (bits 0–5) that may still cut this cube.
    mask: u8,
    /// The cube's node: [`CountBlock::ABSENT`] (unknown space) or the block of its children in
    /// [`KnownCellCounts`] (known leaves and wholly known subtrees are never pushed).
    block: u32,
    /// Known depth-16 cells below the cube's node (0 when absent).
    known: u64,
}

impl Entry {
    /// A walk's stack with the root (block `root`, `known` known cells) on it,
    /// every plane still to test.
    fn stack_at_root(root: u32, known: u64) -> [Entry; STACK] {
        let mut stack = [Entry {
            key: [0; 3],
            depth: 0,
            mask: 0,
            block: CountBlock::ABSENT,
            known: 0,
        }; STACK];
        stack[0] = Entry {
            mask: 0b11_1111,
            block: root,
            known,
            ..stack[0]
        };
        stack
    }

    /// Its child `i`, planes `mask` still to test, in `block` with `known` known cells.
    #[inline(always)]
    fn child(&self, i: usize, mask: u8, block: u32, known: u64) -> Entry {
        Entry {
            key: child_key(&self.key, self.depth, i),
            depth: self.depth + 1,
            mask,
            block,
            known,
        }
    }

    /// Whether the cube of `side` keys at this entry overlaps the key box
    /// `lo..=hi`, and whether it lies wholly inside it.
    #[inline(always)]
    fn against_key_box(&self, side: u32, lo: &[u16; 3], hi: &[u16; 3]) -> (bool, bool) {
        let (mut overlaps, mut within) = (true, true);
        for i in 0..3 {
            let (a, b) = (self.key[i] as u32, self.key[i] as u32 + side - 1);
            overlaps &= a <= hi[i] as u32 && b >= lo[i] as u32;
            within &= a >= lo[i] as u32 && b <= hi[i] as u32;
        }
        (overlaps, within)
    }
}

/// Counts unknown depth-16 cells inside view frusta for one tree: the tree's per-node
/// known-cell counts ([`KnownCellCounts`]) are built once in [`FrustumCounter::new`]
/// (one pass over the nodes) and shared by every view (and thread) after that.
///
/// Per view (fixed-size stacks, no allocation), `unknown = all − known` over the cells
/// whose centres lie in the frustum and whose keys lie in the view's key box:
/// - `all`: columns of cells along the axis the view direction is steepest in, in
///   tiles of 16 × 16 columns spanning the key box; a tile whose cell centres all pass
///   every plane adds its volume, one whose centres all fail a plane nothing, and the
///   others are counted row by row: along the row axis each cutting plane
///   `n·c + d ≥ 0` bounds the cells to one interval, found from the crossing
///   `x* = −(n_b·c_b + n_c·c_c + d)/n_a` and confirmed with the per-cell test itself
///   wherever the crossing lies within rounding of a cell centre (the test is monotone
///   along a row), so the count equals the count of every cell centre. A cutting plane
///   that another on the same side of the rows bounds at least two keys more tightly
///   over the whole tile (the near plane in the tiles the side planes bound) is left
///   out of its rows;
/// - `known`: a depth-first walk over the known nodes only: a node inside every plane
///   (planes already cleared by an ancestor are not tested again) and inside the key
///   box adds `known(node)`, one outside a plane or the key box nothing, a known leaf
///   or wholly known subtree of at most `2^ROW_LOG` cells a side cut by planes its
///   cells inside them row by row (larger ones are split virtually first), an inner
///   node its children that hold known cells.
///
/// A view whose corners leave the key space (its key box is the whole key space) is
/// counted by one walk over known and unknown space alike instead: known leaves and
/// wholly known subtrees skipped, a cube inside every plane adding
/// `8^(16−d) − known(node)`, unknown cubes of at most `2^ROW_LOG` cells a side cut by
/// planes counted row by row, anything else split.
///
/// The cube test uses the centre `c` of the cube's cell centres and their half span
/// `h = (size − res)/2`: all inside plane j when `n·c + d − h·‖n‖₁ ≥ ε`, all outside when
/// `n·c + d + h·‖n‖₁ < −ε` (per axis half spans `h_i` for tiles: `Σ|n_i|·h_i`).
#[derive(Debug, Clone)]
pub struct FrustumCounter<'a> {
    tree: &'a Octree,
    known: KnownCellCounts,
}

impl<'a> FrustumCounter<'a> {
    /// Builds the per-node known-cell counts of `tree` (one pass over its nodes).
    pub fn new(tree: &'a Octree) -> Self {
        Self {
            tree,
            known: KnownCellCounts::new(tree),
        }
    }

    /// Unknown depth-16 cells whose centres lie inside `frustum` (see
    /// [`frustum_unknown_count`](super::frustum_unknown_count)).
    pub fn count(&self, frustum: &Frustum) -> u64 {
        self.count_in(frustum, None)
    }

    /// [`count`](Self::count) restricted to the cells whose keys lie in the inclusive
    /// key box `keys` (`None`: no restriction besides the frustum corners' key box).
    pub fn count_in(&self, frustum: &Frustum, keys: Option<(OcKey, OcKey)>) -> u64 {
        let tree = self.tree;
        let res = tree.resolution();
        let planes = &frustum.planes;
        let norm1: [f64; 6] = planes.map(|(n, _)| n.x.abs() + n.y.abs() + n.z.abs());
        // box of keys covering the frustum corners (the whole key space when one is out)
        let mut lo = [u16::MAX; 3];
        let mut hi = [0u16; 3];
        for c in &frustum.corners {
            match tree.key_of(c) {
                Ok(k) => {
                    for i in 0..3 {
                        lo[i] = lo[i].min(k[i]);
                        hi[i] = hi[i].max(k[i]);
                    }
                }
                Err(_) => {
                    lo = [0; 3];
                    hi = [u16::MAX; 3];
                }
            }
        }
        if let Some((a, b)) = keys {
            for i in 0..3 {
                lo[i] = lo[i].max(a[i]);
                hi[i] = hi[i].min(b[i]);
                if lo[i] > hi[i] {
                    return 0;
                }
            }
        }
        let rows = RowCounter::new(planes, res, lo, hi);
        // columns along the axis the view direction (the near plane's normal) is
        // steepest in
        let a = rows.axis[0];
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let columns = (hi[b] - lo[b]) as u64 * (hi[c] - lo[c]) as u64;
        if columns > MAX_COLUMNS {
            return self.walk_unknown(&rows, &norm1);
        }
        let all = frustum_cells(&rows, a);
        all - self.known_cells(&rows, &norm1)
    }

    /// The unknown cells of the view by one walk over the tree, known and unknown
    /// space alike (the fallback for a key box of more than [`MAX_COLUMNS`] columns).
    fn walk_unknown(&self, rows: &RowCounter<'_>, norm1: &[f64; 6]) -> u64 {
        let (res, planes, lo, hi) = (rows.res, rows.planes, rows.lo, rows.hi);
        let known = &self.known;
        let root = known.root_child();
        if root == CountBlock::LEAF || known.root() == 1u64 << (3 * TREE_DEPTH as u32) {
            return 0;
        }
        let mut stack = Entry::stack_at_root(root, known.root());
        let mut len = 1usize;
        let mut count = 0u64;
        while len > 0 {
            len -= 1;
            let e = stack[len];
            let side = 1u32 << (TREE_DEPTH - e.depth);
            let (overlaps, within) = e.against_key_box(side, &lo, &hi);
            if !overlaps {
                continue;
            }
            // plane tests for the planes an ancestor has not cleared
            let mut mask = 0u8;
            if e.mask != 0 {
                let size = res * side as f64;
                let half_span = (size - res) / 2.0;
                let c = Vector3::from(e.key.map(|k| (k as f64 - 32768.0) * res + size / 2.0));
                let mut out = false;
                for (j, (n, d)) in planes.iter().enumerate() {
                    if e.mask & (1 << j) == 0 {
                        continue;
                    }
                    let s = n.dot(&c) + d;
                    let r = half_span * norm1[j];
                    if s + r < -EPS {
                        out = true;
                        break;
                    }
                    if s - r < EPS {
                        mask |= 1 << j;
                    }
                }
                if out {
                    continue;
                }
            }
            if mask == 0 && within {
                count += (1u64 << (3 * (TREE_DEPTH - e.depth) as u32)) - e.known;
                continue;
            }
            if e.block == CountBlock::ABSENT {
                if e.depth >= TREE_DEPTH - ROW_LOG {
                    count += rows.count(&e.key, side, mask);
                    continue;
                }
                for i in 0..8 {
                    stack[len] = e.child(i, mask, CountBlock::ABSENT, 0);
                    len += 1;
                }
                continue;
            }
            let b = known.block(e.block);
            // a child of this many cells with as many known holds no unknown one
            let full = 1u64 << (3 * (TREE_DEPTH - e.depth - 1) as u32);
            for i in 0..8 {
                if b.child[i] == CountBlock::LEAF || b.known[i] == full {
                    continue;
                }
                stack[len] = e.child(i, mask, b.child[i], b.known[i]);
                len += 1;
            }
        }
        count
    }

    /// Known cells of the view: a walk over the known nodes only (absent space is
    /// never entered). A node inside every plane and the key box adds `known(node)`,
    /// a known leaf cut by planes or the key box its cells inside them (row by row,
    /// all known; a leaf of more than `2^ROW_LOG` cells a side split virtually first),
    /// an inner node cut by them its children that hold known cells.
    fn known_cells(&self, rows: &RowCounter<'_>, norm1: &[f64; 6]) -> u64 {
        let (res, planes, lo, hi) = (rows.res, rows.planes, rows.lo, rows.hi);
        let known = &self.known;
        let root = known.root_child();
        if root == CountBlock::ABSENT {
            return 0;
        }
        let mut stack = Entry::stack_at_root(root, known.root());
        let mut len = 1usize;
        let mut count = 0u64;
        while len > 0 {
            len -= 1;
            let e = stack[len];
            let side = 1u32 << (TREE_DEPTH - e.depth);
            let (overlaps, within) = e.against_key_box(side, &lo, &hi);
            if !overlaps {
                continue;
            }
            let Some(mask) = cube_planes(planes, norm1, res, &e.key, side, e.mask) else {
                continue;
            };
            if mask == 0 && within {
                count += e.known;
                continue;
            }
            // a leaf, or a subtree whose cells are all known: its cells inside the planes
            if e.block == CountBlock::LEAF || e.known == 1u64 << (3 * (TREE_DEPTH - e.depth) as u32) {
                if e.depth >= TREE_DEPTH - ROW_LOG {
                    count += rows.count(&e.key, side, mask);
                } else {
                    for i in 0..8 {
                        stack[len] = e.child(i, mask, CountBlock::LEAF, e.known / 8);
                        len += 1;
                    }
                }
                continue;
            }
            let b = known.block(e.block);
            for i in 0..8 {
                if b.known[i] == 0 {
                    continue;
                }
                stack[len] = e.child(i, mask, b.child[i], b.known[i]);
                len += 1;
            }
        }
        count
    }
}

/// Columns of the view's key box above which [`FrustumCounter`] walks the tree once
/// instead of counting the frustum's cells column by column (a view whose corners
/// leave the key space has the whole key space as its box).
const MAX_COLUMNS: u64 = 1 << 22;

/// Side (cells) of the tiles of columns [`frustum_cells`] classifies against the planes.
const TILE: i64 = 16;

/// Cells of the view's key box whose centres lie inside the frustum, in columns along
/// axis `a`: tiles of `TILE × TILE` columns spanning the key box along `a` are tested
/// against the planes like the cubes of the walk (half spans per axis); a tile inside
/// every plane adds its volume, one outside a plane nothing, and the rest are counted
/// row by row ([`RowCounter::count_box`]), each row bounded by the crossings of the
/// planes that cut its tile.
fn frustum_cells(rows: &RowCounter<'_>, a: usize) -> u64 {
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let (res, lo, hi) = (rows.res, rows.lo, rows.hi);
    let span = |i: usize| (lo[i] as i64, hi[i] as i64);
    let mut total = 0u64;
    let mut r = [span(0), span(1), span(2)];
    let mut tc = lo[c] as i64;
    while tc <= hi[c] as i64 {
        r[c] = (tc, (tc + TILE - 1).min(hi[c] as i64));
        let mut tb = lo[b] as i64;
        while tb <= hi[b] as i64 {
            r[b] = (tb, (tb + TILE - 1).min(hi[b] as i64));
            tb += TILE;
            // centre of the tile's cell centres and their half span per axis
            let centre = Vector3::from([0, 1, 2].map(|i| ((r[i].0 + r[i].1) as f64 / 2.0 - 32767.5) * res));
            let half = [0, 1, 2].map(|i| (r[i].1 - r[i].0) as f64 / 2.0 * res);
            let mut mask = 0u8;
            let mut out = false;
            for (j, (n, d)) in rows.planes.iter().enumerate() {
                let s = n.dot(&centre) + d;
                let reach = n.x.abs() * half[0] + n.y.abs() * half[1] + n.z.abs() * half[2];
                if s + reach < -EPS {
                    out = true;
                    break;
                }
                if s - reach < EPS {
                    mask |= 1 << j;
                }
            }
            if out {
                continue;
            }
            total += if mask == 0 {
                r.iter().map(|(x, y)| (y - x + 1) as u64).product()
            } else {
                rows.count_box(&r, mask, a)
            };
        }
        tc += TILE;
    }
    total
}

/// The planes of `parent_mask` that may cut the cube `[key, key + side)³` (bit j: plane
/// j), or `None` when its cell centres all lie outside one of them; see
/// [`FrustumCounter`] for the test.
#[inline]
fn cube_planes(
    planes: &[(Vector3<f64>, f64); 6],
    norm1: &[f64; 6],
    res: f64,
    key: &OcKey,
    side: u32,
    parent_mask: u8,
) -> Option<u8> {
    if parent_mask == 0 {
        return Some(0);
    }
    let mut mask = 0u8;
    let size = res * side as f64;
    let half_span = (size - res) / 2.0;
    let c = Vector3::from(key.map(|k| (k as f64 - 32768.0) * res + size / 2.0));
    for (j, (n, d)) in planes.iter().enumerate() {
        if parent_mask & (1 << j) == 0 {
            continue;
        }
        let s = n.dot(&c) + d;
        let r = half_span * norm1[j];
        if s + r < -EPS {
            return None;
        }
        if s - r < EPS {
            mask |= 1 << j;
        }
    }
    Some(mask)
}

/// One cutting plane's crossing along a row: plane index, `κ0`, `κ_b`, `κ_c` (the
/// crossing `κ = κ0 + κ_b·k_b + κ_c·k_c`), its tolerance, and whether `n_a > 0`.
type Lin = (usize, f64, f64, f64, f64, bool);

/// Row-by-row count of the cells of an unknown cube inside the key box and the planes.
struct RowCounter<'f> {
    planes: &'f [(Vector3<f64>, f64); 6],
    res: f64,
    lo: [u16; 3],
    hi: [u16; 3],
    /// Per plane j: the row axis when j is a cube's first cutting plane (the axis
    /// its normal is steepest in).
    axis: [usize; 6],
    /// Per plane j and row axis a: the crossing coefficients and tolerance, `None` when
    /// the plane needs the per-cell tests along that axis. They depend on the plane and
    /// the axis only, so they are computed once per view instead of once per cube.
    coef: [[Option<Lin>; 3]; 6],
}

impl<'f> RowCounter<'f> {
    fn new(planes: &'f [(Vector3<f64>, f64); 6], res: f64, lo: [u16; 3], hi: [u16; 3]) -> Self {
        let axis = planes.map(|(n, _)| {
            (0..3)
                .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
                .unwrap_or(0)
        });
        let mut coef = [[None; 3]; 6];
        for (j, (n, d)) in planes.iter().enumerate() {
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                let scale = (n[0].abs() + n[1].abs() + n[2].abs()) / n[a].abs();
                // key-unit error bound of κ and of the per-cell test near the crossing,
                // with a safety factor of about 10^6 over f64 rounding
                let tol = 1e-9 * scale * (32768.0 + (32768.0 * res + d.abs()) / res);
                if n[a] == 0.0 || tol.is_nan() || tol >= 0.25 {
                    continue;
                }
                // κ = −(n_b·c_b + n_c·c_c + d)/(n_a·res) + 32767.5, c_i = (k_i − 32767.5)·res
                let kb = -n[b] / n[a];
                let kc = -n[c] / n[a];
                let k0 = -d / (n[a] * res) - (kb + kc) * 32767.5 + 32767.5;
                coef[j][a] = Some((j, k0, kb, kc, tol, n[a] > 0.0));
            }
        }
        Self {
            planes,
            res,
            lo,
            hi,
            axis,
            coef,
        }
    }

    /// The per-cell test, written exactly as [`Frustum::contains`] evaluates it at the
    /// cell centre `key_center(k, 16)`.
    #[inline]
    fn inside(&self, j: usize, k: [i64; 3]) -> bool {
        let (n, d) = &self.planes[j];
        let p = Vector3::new(
            key_to_coord_axis(k[0] as u16, self.res),
            key_to_coord_axis(k[1] as u16, self.res),
            key_to_coord_axis(k[2] as u16, self.res),
        );
        n.dot(&p) + d >= 0.0
    }

    /// Cells of the cube `[key, key + side)³` inside the key box whose centres pass
    /// every plane in `mask`. Along a row (axis a, the others fixed) plane j is crossed
    /// at the real key `κ = K0 + Kb·k_b + Kc·k_c` (`n·c + d = 0` solved for the key with
    /// `c = (k − 32768 + ½)·res`); when `κ` is more than `tol` away from an integer its
    /// floor settles the row without any per-cell test (`κ` clamped to the row's range
    /// ± 1), else the per-cell tests decide the row.
    fn count(&self, key: &OcKey, side: u32, mask: u8) -> u64 {
        let r: [(i64, i64); 3] = [0, 1, 2].map(|i| {
            (
                (key[i] as i64).max(self.lo[i] as i64),
                (key[i] as i64 + side as i64 - 1).min(self.hi[i] as i64),
            )
        });
        if r.iter().any(|(a, b)| a > b) {
            return 0;
        }
        if mask == 0 {
            return r.iter().map(|(a, b)| (b - a + 1) as u64).product();
        }
        // rows along the axis the first cutting plane is steepest in
        self.count_box(&r, mask, self.axis[mask.trailing_zeros() as usize])
    }

    /// Cells of the non-empty key box `r` (inclusive ranges, inside the key box of
    /// the view) whose centres pass every plane in `mask` (not 0), counted in rows
    /// along axis `a`, as [`count`](Self::count) describes.
    fn count_box(&self, r: &[(i64, i64); 3], mask: u8, a: usize) -> u64 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let (alo, ahi) = r[a];
        // per cutting plane: crossing coefficients and tolerance (or in `exact`: per-cell tests)
        let mut lin: [Lin; 6] = [(0, 0.0, 0.0, 0.0, 0.0, false); 6];
        let mut exact = [usize::MAX; 6];
        let (mut nl, mut ne) = (0, 0);
        for j in 0..6 {
            if mask & (1 << j) == 0 {
                continue;
            }
            match self.coef[j][a] {
                Some(l) => {
                    lin[nl] = l;
                    nl += 1;
                }
                None => {
                    exact[ne] = j;
                    ne += 1;
                }
            }
        }
        // planes another one of the same side dominates over the whole box bound no
        // row (see `dominated`); the rest ordered lower bounds first
        let mut kept: [Lin; 6] = [(0, 0.0, 0.0, 0.0, 0.0, false); 6];
        let mut n = 0;
        for up in [true, false] {
            for p in 0..nl {
                if lin[p].5 == up && !(0..nl).any(|q| q != p && dominated(&lin[p], &lin[q], r, b, c)) {
                    kept[n] = lin[p];
                    n += 1;
                }
            }
        }
        let (lin, nl) = (kept, n);
        let nu = lin[..nl].iter().filter(|p| p.5).count();
        // the crossings of the cutting planes in 32.32 fixed point when every plane's
        // |cb| ≤ 2^20 and fewer than 32 rows are stepped along b (cubes of at most
        // 2^ROW_LOG cells a side, tiles of TILE)
        let max_cb = lin[..nl].iter().fold(0.0f64, |m, p| m.max(p.2.abs()));
        if ne == 0 && max_cb <= 1_048_576.0 && r[b].1 - r[b].0 < 32 {
            let axes = [a, b, c];
            macro_rules! rows {
                ($($u:literal $d:literal),*) => {
                    match (nu, nl - nu) {
                        $(($u, $d) => return self.fixed_rows::<$u, $d>(&lin, r, axes, max_cb),)*
                        _ => {}
                    }
                };
            }
            rows!(1 0, 0 1, 2 0, 1 1, 0 2, 3 0, 2 1, 1 2, 0 3, 4 0, 3 1, 2 2, 1 3, 0 4,
                5 0, 4 1, 3 2, 2 3, 1 4, 0 5, 6 0, 5 1, 4 2, 3 3, 2 4, 1 5, 0 6);
        }
        let mut total = 0u64;
        let mut k = [0i64; 3];
        for kc in r[c].0..=r[c].1 {
            k[c] = kc;
            for kb in r[b].0..=r[b].1 {
                k[b] = kb;
                // fast path: the floors of the crossings; a crossing within `tol` of an
                // integer (rare) sends the row to the per-cell tests instead
                let (mut first_in, mut last_in) = (alo, ahi);
                let mut near = false;
                let (lo_f, hi_f) = (alo as f64 - 1.0, ahi as f64 + 1.0);
                let mut fls = [0i64; 6];
                for (p, &(_, k0, cb, cc, tol, up)) in lin[..nl].iter().enumerate() {
                    let kr = k0 + cb * kb as f64 + cc * kc as f64;
                    let fl = floor_i64(kr.clamp(lo_f, hi_f));
                    fls[p] = fl;
                    let frac = kr - fl as f64;
                    near |= kr > lo_f && kr < hi_f && (frac <= tol || frac >= 1.0 - tol);
                    if up {
                        first_in = first_in.max(fl + 1);
                    } else {
                        last_in = last_in.min(fl);
                    }
                }
                if near {
                    // the per-cell tests, searched from the floors
                    (first_in, last_in) = (alo, ahi);
                    for (p, &(j, _, _, _, _, up)) in lin[..nl].iter().enumerate() {
                        if first_in > last_in {
                            break;
                        }
                        if up {
                            let guess = (fls[p] + 1).clamp(alo, ahi + 1);
                            first_in = first_in.max(self.first_inside(j, k, a, guess, alo, ahi));
                        } else {
                            let guess = fls[p].clamp(alo - 1, ahi);
                            last_in = last_in.min(self.last_inside(j, k, a, guess, alo, ahi));
                        }
                    }
                }
                for &j in &exact[..ne] {
                    if first_in > last_in {
                        break;
                    }
                    let (n, _) = &self.planes[j];
                    if n[a] == 0.0 {
                        k[a] = alo;
                        if !self.inside(j, k) {
                            last_in = first_in - 1;
                        }
                    } else if n[a] > 0.0 {
                        first_in = first_in.max(self.first_inside(j, k, a, alo, alo, ahi));
                    } else {
                        last_in = last_in.min(self.last_inside(j, k, a, ahi, alo, ahi));
                    }
                }
                if last_in >= first_in {
                    total += (last_in - first_in + 1) as u64;
                }
            }
        }
        total
    }

    /// The rows of [`count`](Self::count) for `U` lower-bound planes (`lin[..U]`, `n_a >
    /// 0`) and `D` upper-bound ones after them (1–6 together), all with a crossing, in
    /// 32.32 fixed point relative to `alo`: per c-row each crossing is evaluated once in
    /// f64 at the first b, then stepped by `cb` as an integer (at most 31 steps;
    /// truncating `cb` and the start to 2^−32 adds under 2^−26 keys of error, covered by
    /// the 2^−20 added to each `tol`). Starting crossings are clamped to `[−m, len + m]`
    /// with `m = 4 + 32·⌈max|cb|⌉`: 31 steps cannot bring a clamped one back into
    /// `[−1, len + 1]`, so its rows count the same (all or none of the row). A row with a
    /// crossing within `tol` of an integer is decided by the per-cell tests, as in the
    /// f64 path.
    #[inline(always)]
    fn fixed_rows<const U: usize, const D: usize>(
        &self,
        lin: &[Lin; 6],
        r: &[(i64, i64); 3],
        [a, b, c]: [usize; 3],
        max_cb: f64,
    ) -> u64 {
        const ONE: i64 = 1 << 32;
        let (alo, ahi) = r[a];
        let len = ahi - alo + 1;
        let margin = 4.0 + 32.0 * max_cb.ceil();
        // per plane (lower bounds first): step per b-row and tolerance, fixed point
        let (mut us, mut ut) = ([0i64; U], [0i64; U]);
        let (mut ds, mut dt) = ([0i64; D], [0i64; D]);
        let fixed = |p: usize| {
            (
                (lin[p].2 * ONE as f64) as i64,
                ((lin[p].4 + 1.0 / 1_048_576.0) * ONE as f64) as i64,
            )
        };
        for p in 0..U {
            (us[p], ut[p]) = fixed(p);
        }
        for p in 0..D {
            (ds[p], dt[p]) = fixed(U + p);
        }
        // `v ∈ (−1, len)` (keys, fixed point) as one unsigned compare
        let span = ((len + 1) * ONE - 1) as u64;
        // within tol of an integer: `frac(v) ≤ tol` or `frac(v) ≥ 1 − tol`, i.e.
        // `(v + tol) mod 1 ≤ 2·tol` (tol < ¼), and inside the row; no branches
        let near = |v: i64, tol: i64| (((v + ONE - 1) as u64) < span) & (((v + tol) & (ONE - 1)) <= 2 * tol);
        let start = |p: usize, kc: i64| {
            let (_, k0, cb, cc, _, _) = lin[p];
            let rel =
                (k0 + cb * r[b].0 as f64 + cc * kc as f64 - alo as f64).clamp(-margin, len as f64 + margin);
            (rel * ONE as f64) as i64
        };
        let mut total = 0u64;
        let mut k = [0i64; 3];
        for kc in r[c].0..=r[c].1 {
            k[c] = kc;
            let mut uv: [i64; U] = std::array::from_fn(|p| start(p, kc));
            let mut dv: [i64; D] = std::array::from_fn(|p| start(U + p, kc));
            for kb in r[b].0..=r[b].1 {
                // relative first and last keys inside every plane
                let (mut first, mut last) = (0i64, len - 1);
                let mut any_near = false;
                for p in 0..U {
                    let v = uv[p];
                    uv[p] += us[p];
                    any_near |= near(v, ut[p]);
                    first = first.max((v >> 32) + 1);
                }
                for p in 0..D {
                    let v = dv[p];
                    dv[p] += ds[p];
                    any_near |= near(v, dt[p]);
                    last = last.min(v >> 32);
                }
                if any_near {
                    // the per-cell tests, searched from the floors (of the crossings
                    // just stepped past)
                    k[b] = kb;
                    let (mut f, mut l) = (alo, ahi);
                    for p in 0..U {
                        if f > l {
                            break;
                        }
                        let fl = (uv[p] - us[p]) >> 32;
                        let guess = (alo + fl + 1).clamp(alo, ahi + 1);
                        f = f.max(self.first_inside(lin[p].0, k, a, guess, alo, ahi));
                    }
                    for p in 0..D {
                        if f > l {
                            break;
                        }
                        let fl = (dv[p] - ds[p]) >> 32;
                        let guess = (alo + fl).clamp(alo - 1, ahi);
                        l = l.min(self.last_inside(lin[U + p].0, k, a, guess, alo, ahi));
                    }
                    total += (l - f + 1).max(0) as u64;
                } else {
                    total += (last - first + 1).max(0) as u64;
                }
            }
        }
        total
    }

    /// The first key in `[alo, ahi]` (or `ahi + 1`) along axis `a` inside plane `j`
    /// (with `n_a > 0` the test is monotone along the row), searched from `guess`.
    fn first_inside(&self, j: usize, mut k: [i64; 3], a: usize, guess: i64, alo: i64, ahi: i64) -> i64 {
        let mut f = guess;
        while f > alo && {
            k[a] = f - 1;
            self.inside(j, k)
        } {
            f -= 1;
        }
        while f <= ahi && {
            k[a] = f;
            !self.inside(j, k)
        } {
            f += 1;
        }
        f
    }

    /// The last key in `[alo, ahi]` (or `alo − 1`) along axis `a` inside plane `j`
    /// (`n_a < 0`), searched from `guess`.
    fn last_inside(&self, j: usize, mut k: [i64; 3], a: usize, guess: i64, alo: i64, ahi: i64) -> i64 {
        let mut l = guess;
        while l < ahi && {
            k[a] = l + 1;
            self.inside(j, k)
        } {
            l += 1;
        }
        while l >= alo && {
            k[a] = l;
            !self.inside(j, k)
        } {
            l -= 1;
        }
        l
    }
}

/// Whether the cutting plane `p` bounds no row of the box `r` that plane `q`, on the
/// same side (both lower or both upper bounds along the rows), does not bound more
/// tightly: the crossings `κ_p`, `κ_q` (keys) differ by at least 2 in `q`'s favour
/// over the whole box — checked at its four (b, c) corners, the difference being
/// linear in b and c. Then every cell that `p`'s per-cell test refuses, `q`'s refuses
/// too (each crossing is within `tol` < ¼ key of its test's switch), and the row
/// counts without `p` are the same.
#[inline]
fn dominated(p: &Lin, q: &Lin, r: &[(i64, i64); 3], b: usize, c: usize) -> bool {
    if p.5 != q.5 {
        return false;
    }
    // κ_q − κ_p for lower bounds (q's crossing later), κ_p − κ_q for upper ones
    let s = if p.5 { 1.0 } else { -1.0 };
    let (d0, db, dc) = (s * (q.1 - p.1), s * (q.2 - p.2), s * (q.3 - p.3));
    let lowest =
        d0 + (db * r[b].0 as f64).min(db * r[b].1 as f64) + (dc * r[c].0 as f64).min(dc * r[c].1 as f64);
    lowest >= 2.0
}

/// `⌊x⌋` for |x| well inside the i64 range, without a libm call.
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

#[cfg(test)]
mod tests {
    use super::dominated;

    #[test]
    fn a_plane_is_dominated_only_by_one_on_its_side_two_keys_tighter_over_the_box() {
        // rows along x (a = 0), the box b = y ∈ [0, 15], c = z ∈ [0, 15]
        let r = [(0, 40), (0, 15), (0, 15)];
        // lower bounds: κ = 10 everywhere, and κ = 12 + 0.01·y (≥ 2 keys later)
        let p = (0, 10.0, 0.0, 0.0, 1e-4, true);
        let q = (1, 12.0, 0.01, 0.0, 1e-4, true);
        assert!(dominated(&p, &q, &r, 1, 2));
        assert!(!dominated(&q, &p, &r, 1, 2));
        // 1.9 keys apart at y = 0: not enough
        let q2 = (1, 11.9, 0.01, 0.0, 1e-4, true);
        assert!(!dominated(&p, &q2, &r, 1, 2));
        // κ_q = 13 − 0.1·z: 11.5 at z = 15, 1.5 keys later only
        let q3 = (1, 13.0, 0.0, -0.1, 1e-4, true);
        assert!(!dominated(&p, &q3, &r, 1, 2));
        // upper bounds: the smaller crossing binds
        let (pu, qu) = ((2, 14.0, 0.0, 0.0, 1e-4, false), (3, 12.0, 0.0, 0.0, 1e-4, false));
        assert!(dominated(&pu, &qu, &r, 1, 2));
        assert!(!dominated(&qu, &pu, &r, 1, 2));
        // a lower and an upper bound never dominate each other
        assert!(!dominated(&p, &qu, &r, 1, 2));
        assert!(!dominated(&qu, &p, &r, 1, 2));
    }
}
