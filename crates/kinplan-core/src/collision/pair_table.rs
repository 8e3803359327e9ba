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
//! The grid is filled coarse to fine: a coarse cell proved free proves its
//! fine cells without testing them. Tables are built only for pairs with a
//! shape no closed form decides (a mesh hull, a cylinder), where the exact
//! test is costly.

use nalgebra::Isometry3;

use super::model::{MAX_BODIES, RobotModel};
use super::narrow::body_body_within;
use super::sweep::SweepBound;
use crate::robot::JointKind;

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
/// shapes count 8), and pairs are given tables in order while the budget
/// lasts, so a model of many large meshes spends a bounded time here.
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
    /// Bit `i·cells[1] + k`: fine cell `(i, k)` proved free.
    free: Vec<u64>,
}

impl PairTable {
    /// The table of bodies `a < b` of `model`, when the module's conditions
    /// hold and its cost fits in `budget` (which it then spends).
    pub(crate) fn build(
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
        let mut table = PairTable {
            a,
            b,
            joints: js,
            axes: moving.len(),
            lo,
            width,
            cells,
            free: vec![0; (cells[0] * cells[1]).div_ceil(64)],
        };
        // the other joints at the middle of their ranges (any value would do)
        let mut q = model.chain().mid_limits();
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        let mut proved_apart = |centre: [f64; 2], half: [f64; 2]| {
            q[js[0]] = centre[0];
            if two {
                q[js[1]] = centre[1];
            }
            model.body_poses(&q, &mut poses);
            // grown a hair for the rounding of the cell lookup
            let reach = half[0] * lever(0) + if two { half[1] * lever(1) } else { 0.0 };
            let reach = reach * (1.0 + 1e-9) + 1e-12;
            !body_body_within(
                &bodies[a],
                &poses[a],
                &bodies[b],
                &poses[b],
                reach.max(f64::MIN_POSITIVE),
            )
        };
        let coarse_w = [width[0] * per_coarse[0] as f64, width[1] * per_coarse[1] as f64];
        for ci in 0..coarse[0] {
            for ck in 0..coarse[1] {
                let centre = [
                    lo[0] + (ci as f64 + 0.5) * coarse_w[0],
                    lo[1] + (ck as f64 + 0.5) * coarse_w[1],
                ];
                let whole = proved_apart(centre, [0.5 * coarse_w[0], 0.5 * coarse_w[1]]);
                for fi in ci * per_coarse[0]..(ci + 1) * per_coarse[0] {
                    for fk in ck * per_coarse[1]..(ck + 1) * per_coarse[1] {
                        let centre = [
                            lo[0] + (fi as f64 + 0.5) * width[0],
                            lo[1] + (fk as f64 + 0.5) * width[1],
                        ];
                        if whole || proved_apart(centre, [0.5 * width[0], 0.5 * width[1]]) {
                            let bit = fi * cells[1] + fk;
                            table.free[bit / 64] |= 1 << (bit % 64);
                        }
                    }
                }
            }
        }
        Some(table)
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
