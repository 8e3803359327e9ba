//! Whole-turn variants of closed-form solutions: each joint's `q + 2πk` inside
//! its limits, and every combination of them across the six joints.
//!
//! A configuration's flags, `singular` and `exact` do not change with whole
//! turns (each flag is the sign of a sine of a joint angle, or depends on the
//! wrist point only), so the variants of one configuration differ only in
//! their joints: the alternatives of each joint are tabled once per
//! configuration; the first variant is written, and then for each joint the
//! block of variants so far is copied once per further alternative of that
//! joint, writing only that joint in the copy. Whole rows move by block
//! copies (wide vector moves in the C library's `memcpy`), which on the
//! benchmark host is cheaper per row than writing each row's seven fields
//! (benches/RESULTS.md, "Analytic IK").

use std::cmp::Ordering;
use std::f64::consts::{PI, TAU};

use super::family::AnalyticArm;
use super::solve::{AnalyticSolution, MAX_TURNS};
use super::subproblems::{ceil_f, floor_f, round_f};

/// A joint value this far outside its limits (rad) still counts as inside
/// (and is clamped onto the limit).
const LIMIT_SLACK: f64 = 1e-9;

/// `1 / 2π`, so that turn counts are found by one multiplication.
const INV_TAU: f64 = 1.0 / TAU;

/// Whether the range `k_lo..=k_hi` of turn counts is not empty (false for
/// NaN, which a non-finite angle gives).
#[inline]
fn some_turn_inside(k_lo: f64, k_hi: f64) -> bool {
    matches!(k_lo.partial_cmp(&k_hi), Some(Ordering::Less | Ordering::Equal))
}

/// The whole-turn alternatives of the six joints of one configuration:
/// joint `i` takes `values[i][..count[i]]` (nearest zero first). A count of
/// zero means no turn of that joint lies inside its limits.
#[derive(Debug, Clone, Copy)]
pub(super) struct TurnTable {
    values: [[f64; MAX_TURNS]; 6],
    count: [usize; 6],
}

impl TurnTable {
    const EMPTY: Self = Self {
        values: [[0.0; MAX_TURNS]; 6],
        count: [0; 6],
    };

    /// How many solutions the table expands to: the product of the counts.
    pub(super) fn rows(&self) -> usize {
        self.count.iter().product()
    }
}

impl AnalyticArm {
    /// Joint `i`'s alternatives for angle `q` into `values`: every `q + 2πk`
    /// inside its limits (with [`LIMIT_SLACK`], then clamped onto them), the
    /// one nearest zero first and then alternately below and above it, at
    /// most [`MAX_TURNS`]; returns how many (0: outside the limits at every
    /// turn). A continuous joint has the one value `q`.
    #[inline]
    fn alternatives(&self, i: usize, q: f64, values: &mut [f64; MAX_TURNS]) -> usize {
        if self.continuous[i] {
            values[0] = q;
            return 1;
        }
        let (lo, hi) = self.limits[i];
        let (a, b) = (lo - LIMIT_SLACK, hi + LIMIT_SLACK);
        // the turn nearest zero, k₀ = ⌊−q/2π + ½⌋ taken into the range of k
        // whose turns lie inside; k₀ = 0 when q is inside and |q| < π
        let v0 = if q >= lo && q <= hi && q.abs() < PI {
            q
        } else {
            let k_lo = ceil_f((a - q) * INV_TAU);
            let k_hi = floor_f((b - q) * INV_TAU);
            if !some_turn_inside(k_lo, k_hi) {
                return 0;
            }
            q + TAU * round_f(-q * INV_TAU).max(k_lo).min(k_hi)
        };
        values[0] = v0.max(lo).min(hi);
        let mut n = 1;
        let mut step = TAU;
        while n < MAX_TURNS {
            // two turns never clamp onto the same value: they are 2π apart
            // and each lies within LIMIT_SLACK of the limits
            let (down, up) = (v0 - step, v0 + step);
            let (down_in, up_in) = (down >= a, up <= b);
            if !(down_in || up_in) {
                break;
            }
            if down_in {
                values[n] = down.max(lo);
                n += 1;
            }
            if up_in && n < MAX_TURNS {
                values[n] = up.min(hi);
                n += 1;
            }
            step += TAU;
        }
        n
    }

    /// The table of `s`'s whole-turn alternatives; all counts zero when some
    /// joint has none inside its limits.
    fn turn_table(&self, s: &AnalyticSolution) -> TurnTable {
        let mut t = TurnTable::EMPTY;
        for i in 0..6 {
            t.count[i] = self.alternatives(i, s.joints[i], &mut t.values[i]);
            if t.count[i] == 0 {
                return TurnTable::EMPTY;
            }
        }
        t
    }

    /// The variant of `s` whose every joint is the turn nearest `seed`'s
    /// (nearest zero without a seed; a continuous joint without a seed keeps
    /// its angle), or `None` when a joint is outside its limits at every turn.
    pub(super) fn nearest_turn(
        &self,
        s: &AnalyticSolution,
        seed: Option<&[f64]>,
    ) -> Option<AnalyticSolution> {
        let mut r = *s;
        for (i, q) in r.joints.iter_mut().enumerate() {
            let target = seed.map_or(0.0, |sd| sd[i]);
            let (lo, hi) = self.limits[i];
            // k = ⌊(target − q)/2π + ½⌋ is 0 when |target − q| < π
            if (target - *q).abs() < PI && ((*q >= lo && *q <= hi) || self.continuous[i]) {
                continue;
            }
            if self.continuous[i] {
                if seed.is_some() {
                    *q += TAU * round_f((target - *q) * INV_TAU);
                }
                continue;
            }
            let k_lo = ceil_f((lo - LIMIT_SLACK - *q) * INV_TAU);
            let k_hi = floor_f((hi + LIMIT_SLACK - *q) * INV_TAU);
            if !some_turn_inside(k_lo, k_hi) {
                return None;
            }
            let k = round_f((target - *q) * INV_TAU).max(k_lo).min(k_hi);
            *q = (*q + TAU * k).max(lo).min(hi);
        }
        Some(r)
    }

    /// Appends every whole-turn variant inside the limits of each solution of
    /// `base` (configurations in order; within one, joint 1's turn varying
    /// fastest, so that row `i₁ + c₁(i₂ + c₂(i₃ + …))` has joint `j` at its
    /// alternative `iⱼ`).
    pub(super) fn push_all_turns(&self, base: &[AnalyticSolution], out: &mut Vec<AnalyticSolution>) {
        for s in base {
            let t = self.turn_table(s);
            let rows = t.rows();
            if rows == 0 {
                continue;
            }
            out.reserve(rows);
            let start = out.len();
            let mut first = *s;
            for (j, v) in first.joints.iter_mut().zip(&t.values) {
                *j = v[0];
            }
            out.push(first);
            for (i, values) in t.values.iter().enumerate() {
                let block = out.len() - start;
                for &v in &values[1..t.count[i]] {
                    out.extend_from_within(start..start + block);
                    let end = out.len();
                    for sol in &mut out[end - block..] {
                        sol.joints[i] = v;
                    }
                }
            }
        }
    }
}
