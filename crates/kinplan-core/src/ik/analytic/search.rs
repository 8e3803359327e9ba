//! 7-joint arms: the held joint's value searched for the closed-form solution
//! nearest the seed.

use nalgebra::Isometry3;

use super::family::AnalyticArm;
use super::params::{AnalyticParams, Turns};
use super::redundant::{ChainAxes, ChainModel, ReducedArm, hold_at};
use super::solve::AnalyticSolution;
use super::turned::TurnedArm;
use crate::ik::attempt::Clock;
use crate::ik::{IkMethod, IkParams, IkTarget};
use crate::robot::Chain;

/// Brent's minimiser stops when the bracket is this narrow (rad).
const X_TOLERANCE: f64 = 1e-6;
/// The relaxed objective is refined only this far (rad): it only points
/// at a valley, which the exact objective then refines.
const G_TOLERANCE: f64 = 1e-4;
/// … or after this many evaluations (the compass search too).
const MAX_REFINE: usize = 80;
/// First step (rad) of the compass search around a proposed held value.
const PROPOSAL_STEP: f64 = 0.01;
/// The deadline and cancellation are looked at every this many evaluations.
const POLL_EVERY: usize = 8;

/// Weight (1/rad²) of the squared limit violation in the relaxed objective.
const LIMIT_WEIGHT: f64 = 1.0;

/// `f(v)`: the squared joint distance to the seed of the nearest closed-form
/// solution with joint `j` held at `v` (`+∞` when none is inside the limits);
/// with `relaxed`, `g(v)`: the same over every branch with the limits replaced
/// by a penalty, `min (distance² + LIMIT_WEIGHT · violation²)`, finite wherever
/// the pose is reachable, so that a branch the limits allow only on a short
/// stretch of `v` still shows as a valley between samples. A middle held
/// joint of a spherical-shoulder arm moves one once-analysed arm
/// ([`TurnedArm`]); other middle joints are analysed afresh at each value.
struct Objective<'a> {
    axes: &'a ChainAxes,
    j: usize,
    tol: f64,
    params: AnalyticParams,
    target: Isometry3<f64>,
    seed: [f64; 7],
    seed6: [f64; 6],
    /// Limits of the six solved joints (rad) and whether each is continuous.
    limits: [(f64, f64); 6],
    continuous: [bool; 6],
    /// End joints: the arm at `v = 0` and how `v` moves the target instead.
    fixed: Option<AnalyticArm>,
    /// Middle joints: the arm analysed once, turned to each held value.
    turned: Option<TurnedArm>,
    /// `M⁻¹` of the 7-joint chain (last joint held).
    m_inv: Isometry3<f64>,
    buf: Vec<AnalyticSolution>,
    relaxed: bool,
    /// Values of `f` at or above this (rad²) need not be exact: they are
    /// reported as some value at least as high (and `g` likewise), which
    /// spares the wrists of far branches while the samples are scanned.
    bound: f64,
}

impl Objective<'_> {
    fn eval(&mut self, v: f64) -> f64 {
        let (f, g) = self.both(v);
        if self.relaxed { g } else { f }
    }

    /// `(f(v), g(v))`.
    fn both(&mut self, v: f64) -> (f64, f64) {
        use std::f64::consts::TAU;
        let built;
        let (arm, target) = match (&self.fixed, &self.turned) {
            // T = E₁(v) E₂⋯E₇ M: arm(v) reaches T where arm(0) reaches E₁(−v) T
            (Some(arm), _) if self.j == 0 => (arm, self.axes.motion(0, -v) * self.target),
            // T = E₁⋯E₆ E₇(v) M: arm(v) reaches T where arm(0) reaches T M⁻¹ E₇(−v) M
            (Some(arm), _) => (
                arm,
                self.target * self.m_inv * self.axes.motion(self.j, -v) * self.axes.m,
            ),
            (None, Some(turned)) => {
                built = turned.at(v);
                (&built, self.target)
            }
            (None, None) => match AnalyticArm::from_axes(&self.axes.held(self.j, v), self.tol) {
                Ok(a) => {
                    built = a;
                    (&built, self.target)
                }
                Err(_) => return (f64::INFINITY, f64::INFINITY),
            },
        };
        // every branch in (−π, π], without limits
        let dv = (v - self.seed[self.j]).powi(2);
        let tol = self.params.solve_tolerance;
        arm.exact_near(&target, &self.seed6, tol, self.bound - dv, &mut self.buf);
        let (mut f, mut g) = (f64::INFINITY, f64::INFINITY);
        for s in self.buf.iter().filter(|s| s.exact) {
            let (mut d, mut viol) = (dv, 0.0);
            for i in 0..6 {
                let (q, sd) = (s.joints[i], self.seed6[i]);
                let near = q + TAU * ((sd - q) / TAU).round();
                let (lo, hi) = self.limits[i];
                let x = if self.continuous[i] || (lo..=hi).contains(&near) {
                    near
                } else {
                    // the turn inside the limits nearest the seed, if any
                    let k_lo = ((lo - q) / TAU).ceil();
                    let k_hi = ((hi - q) / TAU).floor();
                    if k_lo <= k_hi {
                        let k = ((sd - q) / TAU).round().clamp(k_lo, k_hi);
                        q + TAU * k
                    } else {
                        viol += (lo - near).max(near - hi).powi(2);
                        near
                    }
                };
                d += (x - sd) * (x - sd);
            }
            if viol == 0.0 {
                f = f.min(d);
            }
            g = g.min(d + LIMIT_WEIGHT * viol);
        }
        (f, g)
    }
}

/// The value of held joint `j` (rad) whose closed-form solution for `target`
/// lies nearest `seed` (7 values; Euclidean joint distance, the held joint
/// included). The arm must be covered with `j` held (see
/// [`analyse`](super::analyse)).
///
/// Method: `f(v)`, the squared distance of the nearest solution (every
/// configuration, each joint's whole turn nearest the seed, inside the
/// limits) at held value `v`, and its relaxed form `g(v)` (limits as a
/// penalty, see `Objective`) are evaluated at `params.redundant_samples`
/// evenly spaced values across joint `j`'s limits (`seed ± π` when unlimited)
/// and at the seed's own value. The best sample of `f` is refined within its
/// neighbouring samples, to 1e-6 rad, by Brent's minimiser (parabolic
/// interpolation with golden-section steps; R. P. Brent, *Algorithms for
/// Minimization without Derivatives*, 1973, ch. 5) when the neighbours
/// bracket it, else by walking downhill with growing steps until `f` rises
/// and then Brent's minimiser (see `downhill`; a compass search, step halved
/// on failure, takes over where the limits leave no solution, `f = ∞`) — unless a
/// proposal is given (the caller's Levenberg–Marquardt solve from the seed: a
/// local answer, usually on the seed's own branch) and `f` refined next to
/// its held value is already below the best sample's value. When the best sample of `g` lies elsewhere and is lower
/// than the best `f` so far (a branch the limits allow on a stretch shorter
/// than the sample spacing), `g` is refined there to 1e-4 rad and then `f`
/// next to it. The nearest answer wins. Each configuration's
/// solution moves continuously with `v` away from singular poses, so both
/// refinements converge to local minima.
///
/// Guarantee: the answer is at least as near the seed as the solution at the
/// seed's own value and at every sample. The global nearest can be missed when
/// it lies in a dip of `f` (and of `g`) narrower than the sample spacing
/// `(upper − lower)/(samples − 1)` that no sample falls in; more samples narrow
/// that gap, at one closed-form solve each (the proposal closes it for the
/// branch the seed's local answer lies on). Cost: `samples + 1` solves, one LM
/// attempt, and at most four refinements of at most 170 solves each. The
/// deadline and cancellation end the search early with the best value so far.
pub(crate) fn search_held(
    axes: &ChainAxes,
    j: usize,
    target: &Isometry3<f64>,
    seed: &[f64],
    proposal: Option<f64>,
    params: &AnalyticParams,
    clock: &Clock<'_>,
) -> f64 {
    let tol = params.geometry_tolerance;
    let seed7: [f64; 7] = std::array::from_fn(|i| seed.get(i).copied().unwrap_or(0.0));
    let idx = |k: usize| if k < j { k } else { k + 1 };
    let fixed = if j == 0 || j + 1 == axes.n {
        AnalyticArm::from_axes(&axes.held(j, 0.0), tol).ok()
    } else {
        None
    };
    let mut f = Objective {
        axes,
        j,
        tol,
        params: AnalyticParams {
            turns: Turns::NearestSeed,
            ..*params
        },
        target: *target,
        seed: seed7,
        seed6: std::array::from_fn(|k| seed7[idx(k)]),
        limits: std::array::from_fn(|k| axes.limits[idx(k)]),
        continuous: std::array::from_fn(|k| axes.continuous[idx(k)]),
        fixed,
        turned: TurnedArm::new(axes, j, axes.generic(j), tol),
        m_inv: axes.m.inverse(),
        buf: Vec::with_capacity(8),
        relaxed: false,
        bound: f64::INFINITY,
    };
    let (lo, hi) = match axes.limits[j] {
        (lo, hi) if lo.is_finite() && hi.is_finite() && hi - lo <= 4.0 * std::f64::consts::TAU => (lo, hi),
        _ => (seed7[j] - std::f64::consts::PI, seed7[j] + std::f64::consts::PI),
    };
    let v_seed = seed7[j].clamp(lo, hi);
    let (f0, g0) = f.both(v_seed);
    let (mut best_f, mut best_g) = ((v_seed, f0, None), (v_seed, g0, None));
    let n = params.redundant_samples.max(2);
    let step = (hi - lo) / (n - 1) as f64;
    let grid = Grid { lo, hi, step, v_seed };
    for k in 0..n {
        if k % POLL_EVERY == POLL_EVERY - 1 && clock.interrupted().is_some() {
            return best_f.0;
        }
        let v = lo + step * k as f64;
        // a sample matters only when below the best f so far (and then g ≤ f)
        f.bound = best_f.1;
        let (fv, gv) = f.both(v);
        if fv < best_f.1 {
            best_f = (v, fv, Some(k));
        }
        if gv < best_g.1 {
            best_g = (v, gv, Some(k));
        }
    }
    f.bound = f64::INFINITY;
    // the held value of a local numerical answer from the seed, when given
    let mut best = (best_f.0, best_f.1);
    if let Some(v) = proposal.filter(|v| (lo..=hi).contains(v)) {
        let r = local(&mut f, (lo, hi), v, PROPOSAL_STEP, clock);
        if r.1 < best.1 {
            best = r;
        }
    }
    // the best sample's valley, unless the proposal's answer is nearer than
    // that sample already
    if best_f.1.is_finite() && best_f.1 <= best.1 {
        let r = refine(&mut f, &grid, (best_f.0, best_f.1), best_f.2, X_TOLERANCE, clock);
        if r.1 < best.1 {
            best = r;
        }
    }
    // the relaxed valley, when it lies elsewhere and promises a nearer
    // solution: its bottom, then the nearest values the limits allow there
    // (its bottom may lie a little outside them)
    if best_g.1 < best.1 && best_g.2 != best_f.2 {
        f.relaxed = true;
        let (x, _) = refine(&mut f, &grid, (best_g.0, best_g.1), best_g.2, G_TOLERANCE, clock);
        f.relaxed = false;
        let r = local(&mut f, (lo, hi), x, (0.25 * step).min(0.05), clock);
        if r.1 < best.1 {
            best = r;
        }
    }
    if best.1.is_finite() { best.0 } else { v_seed }
}

/// The held values searched: `[lo, hi]` (rad), the sample spacing, and the
/// seed's value.
#[derive(Clone, Copy)]
struct Grid {
    lo: f64,
    hi: f64,
    step: f64,
    v_seed: f64,
}

/// Refines the sample `best` (index `k`, or the seed's value `v_seed` when
/// `None`) between its neighbouring samples: Brent's minimiser when they
/// bracket it (both finite and higher), else (a neighbour without a solution
/// inside the limits, or the best at an end of the range) [`downhill`], which
/// never steps where the objective is infinite.
fn refine(
    f: &mut Objective<'_>,
    grid: &Grid,
    best: (f64, f64),
    k: Option<usize>,
    xtol: f64,
    clock: &Clock<'_>,
) -> (f64, f64) {
    let Grid { lo, hi, step, v_seed } = *grid;
    let (a, b) = match k {
        Some(k) => (
            lo + step * k.saturating_sub(1) as f64,
            (lo + step * (k + 1) as f64).min(hi),
        ),
        None => ((v_seed - step).max(lo), (v_seed + step).min(hi)),
    };
    let (fa, fb) = (f.eval(a), f.eval(b));
    let bracketed =
        a < best.0 && best.0 < b && fa.is_finite() && fb.is_finite() && fa >= best.1 && fb >= best.1;
    if bracketed {
        brent(f, a, b, best, xtol, clock)
    } else if best.1.is_finite() {
        downhill(f, (lo, hi), best, 0.5 * step, xtol, clock)
    } else {
        compass(f, (lo, hi), best, 0.5 * step, xtol, clock)
    }
}

/// `f`'s local minimum next to `v`: Brent's minimiser on `[v − h, v + h]`
/// when that brackets one, else a compass search from the best of the three.
fn local(f: &mut Objective<'_>, (lo, hi): (f64, f64), v: f64, h: f64, clock: &Clock<'_>) -> (f64, f64) {
    let (a, b) = ((v - h).max(lo), (v + h).min(hi));
    let (fa, fv, fb) = (f.eval(a), f.eval(v), f.eval(b));
    if a < v && v < b && fv.is_finite() && fa >= fv && fb >= fv && fa.is_finite() && fb.is_finite() {
        return brent(f, a, b, (v, fv), X_TOLERANCE, clock);
    }
    let start = [(a, fa), (v, fv), (b, fb)]
        .into_iter()
        .fold((v, fv), |m, x| if x.1 < m.1 { x } else { m });
    if !start.1.is_finite() {
        return start;
    }
    downhill(f, (lo, hi), start, h, X_TOLERANCE, clock)
}

/// `f`'s local minimum downhill of `start` on `[lo, hi]`: steps growing by the
/// golden ratio from `h` in the direction `f` falls until it rises again
/// (W. H. Press et al., *Numerical Recipes*, 3rd ed., 2007, §10.1, bracketing
/// a minimum), then Brent's minimiser on that bracket. Where a step meets an
/// end of the range or a held value without a solution inside the limits
/// (`f = ∞`), a compass search from the lowest point so far takes over.
fn downhill(
    f: &mut Objective<'_>,
    (lo, hi): (f64, f64),
    start: (f64, f64),
    h: f64,
    xtol: f64,
    clock: &Clock<'_>,
) -> (f64, f64) {
    const GROW: f64 = 1.618_033_988_749_895;
    let (x0, f0) = start;
    let up = (x0 + h).min(hi);
    let f_up = if up > x0 { f.eval(up) } else { f64::INFINITY };
    let (dir, mut b) = if f_up < f0 {
        (1.0, (up, f_up))
    } else {
        let down = (x0 - h).max(lo);
        let f_down = if down < x0 { f.eval(down) } else { f64::INFINITY };
        if f_down < f0 {
            (-1.0, (down, f_down))
        } else if f_up.is_finite() && f_down.is_finite() {
            return brent(f, down, up, start, xtol, clock);
        } else {
            return compass(f, (lo, hi), start, 0.5 * h, xtol, clock);
        }
    };
    let mut a = x0;
    let mut step = (b.0 - x0).abs();
    for _ in 0..MAX_REFINE {
        if clock.interrupted().is_some() {
            break;
        }
        step *= GROW;
        let c = (b.0 + dir * step).clamp(lo, hi);
        let fc = if c == b.0 { f64::INFINITY } else { f.eval(c) };
        if !fc.is_finite() {
            return compass(f, (lo, hi), b, 0.5 * (c - b.0).abs().max(h), xtol, clock);
        }
        if fc >= b.1 {
            let (l, r) = if dir > 0.0 { (a, c) } else { (c, a) };
            return brent(f, l, r, b, xtol, clock);
        }
        (a, b) = (b.0, (c, fc));
    }
    b
}

/// Compass search on `[lo, hi]` from `start`: try `x ± h`, move to the first
/// that lowers `f`, else halve `h`, until `h` is below the tolerance.
fn compass(
    f: &mut Objective<'_>,
    (lo, hi): (f64, f64),
    start: (f64, f64),
    step: f64,
    xtol: f64,
    clock: &Clock<'_>,
) -> (f64, f64) {
    let (mut x, mut fx) = start;
    let mut h = step;
    let mut evaluations = 0;
    while h > xtol && evaluations < MAX_REFINE {
        if clock.interrupted().is_some() {
            break;
        }
        let mut moved = false;
        for u in [x - h, x + h] {
            if u < lo || u > hi {
                continue;
            }
            evaluations += 1;
            let fu = f.eval(u);
            if fu < fx {
                (x, fx) = (u, fu);
                moved = true;
                break;
            }
        }
        if !moved {
            h *= 0.5;
        }
    }
    (x, fx)
}

/// Brent's localmin on `[a, b]` starting from the known point `start` inside
/// it (its golden-section point is used when `start` lies outside).
fn brent(
    f: &mut Objective<'_>,
    mut a: f64,
    mut b: f64,
    start: (f64, f64),
    xtol: f64,
    clock: &Clock<'_>,
) -> (f64, f64) {
    const GOLD: f64 = 0.381_966_011_250_105_1; // (3 − √5)/2
    let (mut x, mut fx) = if start.0 > a && start.0 < b {
        start
    } else {
        let x = a + GOLD * (b - a);
        (x, f.eval(x))
    };
    let (mut w, mut fw, mut v, mut fv) = (x, fx, x, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for it in 0..MAX_REFINE {
        if it % POLL_EVERY == POLL_EVERY - 1 && clock.interrupted().is_some() {
            break;
        }
        let m = 0.5 * (a + b);
        let tol1 = 1e-12 * x.abs() + xtol / 3.0;
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // parabola through (v, fv), (w, fw), (x, fx)
            let r = (x - w) * (fx - fv);
            let q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            let mut q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let e_prev = e;
            e = d;
            // finite, inside the bracket, and less than half the step before last
            if p.abs() < (0.5 * q * e_prev).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x < m { b - x } else { a - x };
            d = GOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f.eval(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

/// The joint whose value [`searched`] searches for `target`: the held joint
/// of a 7-joint chain with [`AnalyticParams::search_redundant`] and a pose
/// target; `None` otherwise.
pub(crate) fn searched_joint(
    reduced: &ReducedArm,
    target: &IkTarget,
    params: &AnalyticParams,
) -> Option<usize> {
    match (reduced.held, params.search_redundant, target) {
        (Some((j, _)), true, IkTarget::Pose(_)) => Some(j),
        _ => None,
    }
}

/// The Levenberg–Marquardt options of the search's proposal: one attempt
/// from the seed, no restarts, one solution.
pub(crate) fn proposal_params() -> IkParams {
    IkParams {
        method: IkMethod::LevenbergMarquardt,
        max_restarts: 0,
        num_solutions: 1,
        analytic_start: false,
        ..IkParams::default()
    }
}

/// With [`AnalyticParams::search_redundant`] and a 7-joint chain: `reduced`
/// with its held joint moved to the value [`search_held`] finds for `target`,
/// `proposal` being the held value of a Levenberg–Marquardt solve from the
/// seed ([`proposal_params`], run by the caller on its own solver workspace);
/// otherwise `reduced` unchanged.
pub(crate) fn searched(
    chain: &Chain,
    reduced: ReducedArm,
    target: &IkTarget,
    seed: Option<&[f64]>,
    proposal: Option<f64>,
    params: &AnalyticParams,
    clock: &Clock<'_>,
) -> ReducedArm {
    let (Some(j), IkTarget::Pose(pose)) = (searched_joint(&reduced, target, params), target) else {
        return reduced;
    };
    let Ok(axes) = ChainModel::of_chain(chain).axes() else {
        return reduced;
    };
    let seed_q = seed.map_or_else(|| chain.mid_limits(), <[f64]>::to_vec);
    let v = search_held(axes, j, pose, &seed_q, proposal, params, clock);
    hold_at(axes, j, v, params.geometry_tolerance).unwrap_or(reduced)
}
