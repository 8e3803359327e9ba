//! Whole-turn variants of closed-form solutions: each joint's `q + 2πk` inside
//! its limits, and every combination of them across the six joints.
//!
//! A configuration's flags, `singular` and `exact` do not change with whole
//! turns (each flag is the sign of a sine of a joint angle, or depends on the
//! wrist point only), so the variants of one configuration differ only in
//! their joints: the alternatives of each joint are tabled once per
//! configuration; the first variant is written, and then for each joint the
//! block of variants so far is copied once per further alternative of that
//! joint, writing only that joint in the copy. When the configurations of a
//! pose have the same number of alternatives per joint they are expanded
//! together, so that each alternative costs one block copy for the whole
//! pose. Whole rows move by block copies (wide vector moves in the C
//! library's `memcpy`), which on the benchmark host is cheaper per row than
//! writing each row's seven fields (benches/RESULTS.md, "Analytic IK").

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

/// Most configurations expanded together (the closed-form families have up
/// to 8; more, from the searched family, are expanded one by one).
const GROUP: usize = 8;

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
    /// `base`. When every configuration with variants has the same number of
    /// alternatives per joint (always, but at a limit's edge, for joints whose
    /// range is a whole number of turns such as the UR arms' ±2π), and there
    /// are at most [`GROUP`] of them, they are expanded together, so
    /// that each joint costs one block copy per further alternative for the
    /// whole pose: row `c + n(i₁ + c₁(i₂ + …))` is configuration `c` of the `n`
    /// with joint `j` at its alternative `iⱼ`. Otherwise each configuration is
    /// expanded in turn ([`Self::push_turns_of`]).
    pub(super) fn push_all_turns(&self, base: &[AnalyticSolution], out: &mut Vec<AnalyticSolution>) {
        if base.len() > GROUP {
            for s in base {
                Self::push_turns_of(&self.turn_table(s), s, out);
            }
            return;
        }
        let tables: [TurnTable; GROUP] =
            std::array::from_fn(|k| base.get(k).map_or(TurnTable::EMPTY, |s| self.turn_table(s)));
        // the configurations with variants, in order
        let mut live = [0usize; GROUP];
        let mut n = 0;
        for (k, t) in tables.iter().enumerate() {
            if t.rows() > 0 {
                live[n] = k;
                n += 1;
            }
        }
        let live = &live[..n];
        let Some(&k0) = live.first() else {
            return;
        };
        let counts = tables[k0].count;
        if live.iter().any(|&k| tables[k].count != counts) {
            for &k in live {
                Self::push_turns_of(&tables[k], &base[k], out);
            }
            return;
        }
        out.reserve(n * tables[k0].rows());
        let start = out.len();
        out.extend(live.iter().map(|&k| {
            let mut first = base[k];
            for (j, v) in first.joints.iter_mut().zip(&tables[k].values) {
                *j = v[0];
            }
            first
        }));
        for (i, &count) in counts.iter().enumerate() {
            let block = out.len() - start;
            for m in 1..count {
                // joint i's m-th alternative of each configuration, in row order
                let column: [f64; GROUP] =
                    std::array::from_fn(|c| live.get(c).map_or(0.0, |&k| tables[k].values[i][m]));
                out.extend_from_within(start..start + block);
                let end = out.len();
                for rows in out[end - block..].chunks_exact_mut(n) {
                    for (sol, &v) in rows.iter_mut().zip(&column) {
                        sol.joints[i] = v;
                    }
                }
            }
        }
    }

    /// The variants of one configuration `s` with table `t`: the first, then
    /// for each joint the block so far copied once per further alternative,
    /// writing that joint (joint 1's turn varying fastest).
    fn push_turns_of(t: &TurnTable, s: &AnalyticSolution, out: &mut Vec<AnalyticSolution>) {
        out.reserve(t.rows());
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
