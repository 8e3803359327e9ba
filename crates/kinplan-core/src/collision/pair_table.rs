//! Regions of joint space where two bodies of a robot are proved apart, for
//! the self pairs whose relative pose only one or two joints change (an
//! arm's wrist: link 5 against link 7 and the hand turns with joints 6 and
//! 7 alone). Such a pair is often within centimetres in every state, so its
//! closed-form bounds always meet and the exact test runs on every check;
//! the table answers most of those checks with a lookup.
//!
//! For a pair whose distal body `d` moves relative to the proximal one
//! only through joints `j ∈ J` (`|J| ≤ 2`, revolute, limited), the joint
//! ranges are cut into a grid of cells; with `c` a cell's centre and `h_j`
//! its half widths, every point of `d` stays within `Σ_{j∈J} h_j L_{j,d}`
//! of where it is at `c`, in the proximal body's frame (`L` the lever arms
//! of [`SweepBound`]: turning joint `j` by `θ` moves a point at most `θ`
//! times its distance from the axis, and the joints of `J` turned one after
//! the other reach every state of the cell). So a cell is proved free when
//! the bodies at `c` are farther apart than that sum
//! (`body_body_within`, conservative), and then the pair is apart at every
//! state whose joints of `J` lie in the cell, whatever the other joints.
//! A cell not proved says nothing; the exact test decides there.
//!
//! The grid is filled coarse to fine: each coarse cell is tested whole,
//! and where that fails, its halves along the joint that moves the distal
//! body farther across it, down to single fine cells; a block proved free
//! proves its fine cells without testing them. The rows of coarse cells
//! are proved side by side (rayon), each on its own. Tables are built only for pairs with a
//! shape no closed form decides (a mesh hull, a cylinder), where the exact
//! test is costly.

use nalgebra::Isometry3;

use super::gjk::WarmChecks;
use super::model::{MAX_BODIES, RobotModel};
use super::narrow::body_body_within;
use super::sweep::SweepBound;
use crate::robot::JointKind;
use crate::{Deadline, Stop};

/// How far (m) a distal body may move within a fine cell.
const FINE_REACH: f64 = 0.006;
/// How far (m) a distal body may move within a fine cell of a table over
/// one joint.
const FINE_REACH_ONE: f64 = 0.0005;
/// Coarse cells per joint.
const COARSE: usize = 12;
/// Most fine cells per table.
const MAX_FINE_CELLS: usize = 1 << 14;
/// The work a model's tables may take, in cell × vertex tests: a table
/// costs its fine cells times the vertices of both bodies (boxes and round
/// shapes count 8; its block tests are at most twice its fine cells), and
/// pairs are given tables in order while the budget lasts, so a model of
/// many large meshes spends a bounded time here.
pub(crate) const TABLE_BUDGET: usize = 1 << 24;

/// The proved-free cells of one self pair (module doc).
#[derive(Debug, Clone)]
pub(crate) struct PairTable {
    /// The pair's bodies, `a < b`.
    pub a: usize,
    pub b: usize,
    /// The joints that move one body relative to the other: the first
    /// `axes` (one or two) of these; with one, the second axis of the grid
    /// has a single cell.
    joints: [usize; 2],
    axes: usize,
    lo: [f64; 2],
    /// Fine cell widths (rad).
    width: [f64; 2],
    /// Fine cells per joint.
    cells: [usize; 2],
    /// How far (m) the distal body may move within one fine cell along
    /// each axis (`width · L`; 0 for a missing second axis).
    reach_per_cell: [f64; 2],
    /// Bit `i·cells[1] + k`: fine cell `(i, k)` proved free.
    free: Vec<u64>,
}

/// A block of fine cells: `n[k]` cells from index `i[k]` along each axis.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Region {
    i: [usize; 2],
    n: [usize; 2],
}

impl Region {
    /// The block's centre along axis `k`, in fine cells from the table's start.
    fn mid(&self, k: usize) -> f64 {
        self.i[k] as f64 + 0.5 * self.n[k] as f64
    }

    /// `Σ_k h_k L_k`: how far the distal body may move from where it is at
    /// the block's centre, given the reach of one fine cell per axis.
    fn reach(&self, reach_per_cell: &[f64; 2]) -> f64 {
        0.5 * (self.n[0] as f64 * reach_per_cell[0] + self.n[1] as f64 * reach_per_cell[1])
    }

    /// The two halves across the axis along which the block reaches
    /// farther (of those more than one cell wide); `None` for a single cell.
    fn halves(&self, reach_per_cell: &[f64; 2]) -> Option<(Region, Region)> {
        let splittable = |k: usize| self.n[k] > 1;
        let k = match (splittable(0), splittable(1)) {
            (false, false) => return None,
            (true, false) => 0,
            (false, true) => 1,
            (true, true) => {
                usize::from(self.n[1] as f64 * reach_per_cell[1] > self.n[0] as f64 * reach_per_cell[0])
            }
        };
        let (mut low, mut high) = (*self, *self);
        low.n[k] = self.n[k] / 2;
        high.i[k] = self.i[k] + low.n[k];
        high.n[k] = self.n[k] - low.n[k];
        Some((low, high))
    }
}

/// Collects in `proved` the blocks of `region` that `apart` proves: the
/// whole region first, then, where that fails, its halves along its longer
/// reach, down to single fine cells (so a region of `n` fine cells costs at
/// most `2n − 1` tests).
fn prove(
    region: Region,
    reach_per_cell: &[f64; 2],
    apart: &mut impl FnMut(Region) -> bool,
    proved: &mut Vec<Region>,
) {
    if apart(region) {
        proved.push(region);
    } else if let Some((low, high)) = region.halves(reach_per_cell) {
        prove(low, reach_per_cell, apart, proved);
        prove(high, reach_per_cell, apart, proved);
    }
}

impl PairTable {
    /// The table of bodies `a < b` of `model`, when the module's conditions
    /// hold and its cost fits in `budget` (which it then spends): laid out,
    /// with no cell proved yet ([`PairTable::proved_row`] proves them).
    pub(crate) fn planned(
        model: &RobotModel,
        sweep: &SweepBound,
        a: usize,
        b: usize,
        budget: &mut usize,
    ) -> Option<PairTable> {
        let bodies = &model.bodies;
        let joints = model.chain().joints();
        let costly = |x: usize| {
            bodies[x]
                .shapes
                .iter()
                .any(|s| matches!(s.fast, super::fast::RobotFast::None))
        };
        if model.adjacent(a, b) || !(costly(a) || costly(b)) || bodies.len() > MAX_BODIES {
            return None;
        }
        let (la, lb) = (sweep.last(a), sweep.last(b));
        let (proximal, distal) = if la.map_or(-1, |k| k as i64) <= lb.map_or(-1, |k| k as i64) {
            (la, b)
        } else {
            (lb, a)
        };
        let last = sweep.last(distal)?;
        let first = proximal.map_or(0, |k| k + 1);
        if last < first || last - first > 1 {
            return None;
        }
        let moving: Vec<usize> = (first..=last).collect();
        for &j in &moving {
            let joint = &joints[j];
            if joint.kind != JointKind::Revolute || !(joint.lower.is_finite() && joint.upper.is_finite()) {
                return None;
            }
        }
        let js = [moving[0], *moving.last().unwrap()];
        let two = moving.len() == 2;
        let span = |k: usize| joints[js[k]].upper - joints[js[k]].lower;
        let lever = |k: usize| sweep.lever(distal, js[k]);
        // fine cells so that each joint moves the distal body at most
        // FINE_REACH / |J| within a cell (a table over one joint, which costs
        // little, down to FINE_REACH_ONE), in whole coarse cells
        let share = if two { FINE_REACH / 2.0 } else { FINE_REACH_ONE };
        let mut per_coarse = [1usize; 2];
        for (k, cells) in per_coarse.iter_mut().enumerate().take(moving.len()) {
            // at most MAX_FINE_CELLS per joint, so the products below stay small
            let needed = (span(k) * lever(k) / (2.0 * share))
                .ceil()
                .clamp(1.0, MAX_FINE_CELLS as f64) as usize;
            *cells = needed.div_ceil(COARSE).max(1);
        }
        let coarse = [COARSE, if two { COARSE } else { 1 }];
        let count = |p: &[usize; 2]| (coarse[0] * p[0]).saturating_mul(coarse[1] * p[1]);
        while count(&per_coarse) > MAX_FINE_CELLS {
            let k = if per_coarse[0] >= per_coarse[1] { 0 } else { 1 };
            per_coarse[k] = (per_coarse[k] / 2).max(1);
        }
        let cells = [coarse[0] * per_coarse[0], coarse[1] * per_coarse[1]];
        let vertices = |x: usize| -> usize {
            let shape =
                |s: &super::model::BodyShape| s.shape.as_convex_polyhedron().map_or(8, |c| c.points().len());
            bodies[x].shapes.iter().map(shape).sum()
        };
        let cost = (cells[0] * cells[1]).saturating_mul(vertices(a) + vertices(b));
        if cost > *budget {
            return None;
        }
        *budget -= cost;
        let lo = [joints[js[0]].lower, joints[js[1]].lower];
        let width = [
            span(0) / cells[0] as f64,
            if two { span(1) / cells[1] as f64 } else { 0.0 },
        ];
        Some(PairTable {
            a,
            b,
            joints: js,
            axes: moving.len(),
            lo,
            width,
            cells,
            reach_per_cell: [width[0] * lever(0), if two { width[1] * lever(1) } else { 0.0 }],
            free: vec![0; (cells[0] * cells[1]).div_ceil(64)],
        })
    }

    /// Coarse cells along the grid's first axis: the rows of
    /// [`PairTable::proved_row`].
    pub(crate) const ROWS: usize = COARSE;

    /// The blocks of fine cells proved free in row `row` of coarse cells of
    /// a [`planned`](PairTable::planned) table, for [`PairTable::mark`];
    /// rows are proved on their own, so side by side. Stops once `deadline`
    /// says so, polled before every coarse cell.
    pub(crate) fn proved_row(
        &self,
        model: &RobotModel,
        row: usize,
        deadline: Deadline<'_>,
    ) -> Result<Vec<Region>, Stop> {
        // the row's blocks are tested one after another on this thread
        let _warm = WarmChecks::begin();
        let mut apart = self.apart_test(model);
        self.proved_row_with(row, &mut apart, deadline)
    }

    /// [`PairTable::proved_row`] with the block test `apart`.
    fn proved_row_with(
        &self,
        row: usize,
        apart: &mut impl FnMut(Region) -> bool,
        deadline: Deadline<'_>,
    ) -> Result<Vec<Region>, Stop> {
        let coarse = [COARSE, if self.axes == 2 { COARSE } else { 1 }];
        let per_coarse = [self.cells[0] / coarse[0], self.cells[1] / coarse[1]];
        let mut proved = Vec::new();
        for ck in 0..coarse[1] {
            if let Some(stop) = deadline.stop() {
                return Err(stop);
            }
            let cell = Region {
                i: [row * per_coarse[0], ck * per_coarse[1]],
                n: per_coarse,
            };
            prove(cell, &self.reach_per_cell, apart, &mut proved);
        }
        Ok(proved)
    }

    /// Marks the fine cells of `block` free.
    pub(crate) fn mark(&mut self, block: Region) {
        for i in block.i[0]..block.i[0] + block.n[0] {
            for k in block.i[1]..block.i[1] + block.n[1] {
                let bit = i * self.cells[1] + k;
                self.free[bit / 64] |= 1 << (bit % 64);
            }
        }
    }

    /// True when every cell of the table is proved free: the pair is apart
    /// in every state within the joints' limits.
    pub(crate) fn all_free(&self) -> bool {
        let cells = self.cells[0] * self.cells[1];
        self.free.iter().map(|w| w.count_ones() as usize).sum::<usize>() == cells
    }

    /// The test of a block of cells: true when the bodies, posed at the
    /// block's centre with the other joints at the middle of their ranges
    /// (any value would do), are farther apart than the block's reach.
    fn apart_test<'m>(&self, model: &'m RobotModel) -> impl FnMut(Region) -> bool + use<'m> {
        let bodies = &model.bodies;
        let (a, b, js, lo, width, reach_per_cell) = (
            self.a,
            self.b,
            self.joints,
            self.lo,
            self.width,
            self.reach_per_cell,
        );
        let two = self.axes == 2;
        let mut q = model.chain().mid_limits();
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        move |r: Region| {
            let centre = [lo[0] + r.mid(0) * width[0], lo[1] + r.mid(1) * width[1]];
            q[js[0]] = centre[0];
            if two {
                q[js[1]] = centre[1];
            }
            model.body_poses(&q, &mut poses);
            // grown a hair for the rounding of the cell lookup
            let reach = r.reach(&reach_per_cell) * (1.0 + 1e-9) + 1e-12;
            !body_body_within(
                &bodies[a],
                &poses[a],
                &bodies[b],
                &poses[b],
                reach.max(f64::MIN_POSITIVE),
            )
        }
    }

    /// True when the pair is proved apart at every state whose joints lie
    /// within `half` of `q` (`half` empty: at `q` alone).
    pub(crate) fn proves_apart(&self, q: &[f64], half: &[f64]) -> bool {
        let mut range = [(0usize, 0usize); 2];
        for (k, cells) in range.iter_mut().enumerate().take(self.axes) {
            let j = self.joints[k];
            let (Some(&v), h) = (q.get(j), half.get(j).map_or(0.0, |h| h.abs())) else {
                return false;
            };
            let lo = (v - h - self.lo[k]) / self.width[k];
            let hi = (v + h - self.lo[k]) / self.width[k];
            // NaN and anything outside the table fail here
            if !(lo >= 0.0 && hi <= self.cells[k] as f64) {
                return false;
            }
            *cells = (
                (lo as usize).min(self.cells[k] - 1),
                (hi as usize).min(self.cells[k] - 1),
            );
        }
        (range[0].0..=range[0].1).all(|i| {
            (range[1].0..=range[1].1).all(|k| {
                let bit = i * self.cells[1] + k;
                self.free[bit / 64] & (1 << (bit % 64)) != 0
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::SweepBound;

    /// Halving blocks down to single cells loses no cell that a test of that
    /// cell alone proves, and spends fewer tests than one per cell.
    #[test]
    fn halving_proves_every_cell_its_own_test_proves() {
        let model = crate::collision::tests::panda_hand_open();
        let sweep = SweepBound::new(&model).unwrap();
        let n = model.body_count();
        let mut budget = TABLE_BUDGET;
        let planned: Vec<_> = (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .filter_map(|(a, b)| PairTable::planned(&model, &sweep, a, b, &mut budget))
            .collect();
        assert!(planned.len() >= 2, "{}", planned.len());
        for mut table in planned {
            let mut alone = table.apart_test(&model);
            let mut tests = 0;
            let mut counted = |r: Region| {
                tests += 1;
                alone(r)
            };
            let proved: Vec<Region> = (0..PairTable::ROWS)
                .flat_map(|row| {
                    table
                        .proved_row_with(row, &mut counted, Deadline::none())
                        .unwrap()
                })
                .collect();
            proved.into_iter().for_each(|r| table.mark(r));
            let mut alone = table.apart_test(&model);
            let (mut free_alone, mut free) = (0, 0);
            for i in 0..table.cells[0] {
                for k in 0..table.cells[1] {
                    let bit = i * table.cells[1] + k;
                    let set = table.free[bit / 64] & (1 << (bit % 64)) != 0;
                    free += usize::from(set);
                    if alone(Region { i: [i, k], n: [1, 1] }) {
                        free_alone += 1;
                        assert!(set, "pair {}-{}: cell ({i}, {k}) lost", table.a, table.b);
                    }
                }
            }
            let cells = table.cells[0] * table.cells[1];
            assert!(free >= free_alone && free > 0, "{free} {free_alone}");
            assert!(
                tests < cells,
                "pair {}-{}: {tests} tests for {cells} cells",
                table.a,
                table.b
            );
        }
    }
}
