//! STOMP's per-timestep costs (docs/planning.md#stomp): collision (penalty smoothed
//! over a window, plus the distance cost), joint limits, control
//! (acceleration) and, for CCSTOMP, the Cartesian distance to the straight
//! line.

use super::cartesian::{CartesianLine, Deviation, cartesian_cost, deviation, violates};
use super::clock::Clock;
use super::stomp_matrices::ACCELERATION_STENCIL;
use super::{CartesianParams, StompParams};
use crate::collision::{StateChecker, bisection_order, padded_motion_valid};
use crate::robot::Chain;

/// Everything that stays fixed while one trajectory is optimised.
pub(crate) struct CostModel<'a, C: ?Sized> {
    pub chain: &'a Chain,
    pub checker: &'a C,
    pub params: &'a StompParams,
    pub limits: Vec<(f64, f64)>,
    pub resolution: f64,
    pub cartesian: Option<(&'a CartesianParams, CartesianLine)>,
    pub n: usize,
    pub dof: usize,
}

/// The costs of one trajectory, per timestep (buffers reused across iterations).
#[derive(Debug, Clone, Default)]
pub(crate) struct Evaluation {
    /// Collision + distance + limits + Cartesian cost per timestep.
    pub state: Vec<f64>,
    /// ½·w·Σ_d q̈_d(t)² per timestep.
    pub control: Vec<f64>,
    /// Unsmoothed collision indicator per timestep.
    raw: Vec<f64>,
    state_ok: Vec<bool>,
    /// Clearance per timestep (m), when the distance cost is on.
    clearance: Vec<f64>,
    segment_ok: Vec<bool>,
    /// Per-waypoint Cartesian deviation (CCSTOMP only; empty otherwise).
    pub deviation: Vec<Deviation>,
    /// Σ state + Σ control.
    pub total: f64,
    /// Every state and motion free of collisions and within limits.
    pub collision_free: bool,
    /// No waypoint beyond a Cartesian tolerance (true without CCSTOMP).
    pub within_tolerance: bool,
    scratch: Vec<f64>,
}

impl Evaluation {
    pub fn new(n: usize, dof: usize) -> Self {
        Self {
            state: vec![0.0; n],
            control: vec![0.0; n],
            raw: vec![0.0; n],
            state_ok: vec![false; n],
            clearance: vec![0.0; n],
            segment_ok: vec![false; n.saturating_sub(1)],
            deviation: Vec::with_capacity(n),
            total: f64::INFINITY,
            collision_free: false,
            within_tolerance: false,
            scratch: vec![0.0; dof],
        }
    }

    /// Collision-free and within the tolerances.
    pub fn valid(&self) -> bool {
        self.collision_free && self.within_tolerance
    }

    /// Cost of timestep `t` as the probabilities see it.
    #[inline]
    pub fn at(&self, t: usize) -> f64 {
        self.state[t] + self.control[t]
    }
}

/// True when every state strictly between `a` and `b`, at most `resolution`
/// apart per joint (max-norm), is valid — the ends are not checked; states
/// visited in bisection order (`2^k ≥ span/resolution` equal steps). Under a
/// padded motion check ([`crate::collision::MotionCheck::Padded`]) the whole motion is proved
/// free by [`padded_motion_valid`] instead.
/// `None` when `clock` was interrupted (checked every 32 states).
pub(crate) fn interior_valid<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    buf: &mut [f64],
    clock: &Clock<'_>,
) -> Option<bool> {
    let padded = checker.motion_check().is_padded();
    interior_valid_as(checker, a, b, resolution, padded, buf, clock)
}

/// [`interior_valid`] with the kind of check chosen by the caller: padded
/// (conservative) or interpolated states, whatever the checker's own.
pub(crate) fn interior_valid_as<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    padded: bool,
    buf: &mut [f64],
    clock: &Clock<'_>,
) -> Option<bool> {
    motion_valid_as(checker, a, b, resolution, padded, false, buf, clock)
}

/// `b` valid and [`interior_valid_as`]: a tree edge from `a`, a node, to
/// `b`, a new state. Interpolated, `b` is checked with the first interior
/// states, in one batch ([`StateChecker::states_valid`]).
pub(crate) fn edge_valid_as<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    padded: bool,
    buf: &mut [f64],
    clock: &Clock<'_>,
) -> Option<bool> {
    motion_valid_as(checker, a, b, resolution, padded, true, buf, clock)
}

/// The interior of `a → b`, and `b` too when `with_end`, padded or by
/// interpolated states.
#[allow(clippy::too_many_arguments)]
fn motion_valid_as<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    padded: bool,
    with_end: bool,
    buf: &mut [f64],
    clock: &Clock<'_>,
) -> Option<bool> {
    if !padded {
        return states_between_valid(checker, a, b, resolution, with_end, buf, clock);
    }
    if with_end && !checker.is_valid(b) {
        return Some(false);
    }
    padded_motion_valid(checker, a, b, resolution, clock.deadline)
}

/// States handed to [`StateChecker::states_valid`] at once: the lanes of
/// the batched check (a state-by-state check stops at the first collision
/// of a batch all the same).
const BATCH: usize = 8;
/// Most joints batched here (stack buffer); longer chains go state by state.
const BATCH_DOF: usize = 32;

/// The interior states of `a → b` (and `b` first when `with_end`), in
/// bisection order, [`BATCH`] at a time; `None` when `clock` was
/// interrupted (asked every 32 states).
#[allow(clippy::too_many_arguments)]
fn states_between_valid<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    with_end: bool,
    buf: &mut [f64],
    clock: &Clock<'_>,
) -> Option<bool> {
    let span = a
        .iter()
        .zip(b)
        .map(|(x, y)| (y - x).abs())
        .fold(0.0_f64, f64::max);
    if !span.is_finite() {
        return Some(false);
    }
    let steps = (span / resolution).ceil();
    if steps > 1e7 {
        return Some(false);
    }
    let steps = (steps.max(1.0) as usize).next_power_of_two();
    let dof = a.len();
    // the end first and alone when asked: an extension that collides mostly
    // does so at its new end, which one state check settles; then the
    // interior states, every index but 0, in bisection order
    if with_end && !checker.is_valid(b) {
        return Some(false);
    }
    let mut order = bisection_order(steps).skip(1);
    if dof > BATCH_DOF || dof == 0 {
        for (visited, i) in order.enumerate() {
            if (visited + 1).is_multiple_of(32) && clock.interrupted().is_some() {
                return None;
            }
            let s = i as f64 / steps as f64;
            for ((v, x), y) in buf.iter_mut().zip(a).zip(b) {
                *v = x + s * (y - x);
            }
            if !checker.is_valid(buf) {
                return Some(false);
            }
        }
        return Some(true);
    }
    let mut rows = [0.0; BATCH * BATCH_DOF];
    let mut visited = 0usize;
    loop {
        let mut n = 0;
        for i in order.by_ref().take(BATCH) {
            let row = &mut rows[n * dof..(n + 1) * dof];
            let s = i as f64 / steps as f64;
            for ((v, x), y) in row.iter_mut().zip(a).zip(b) {
                *v = x + s * (y - x);
            }
            n += 1;
        }
        if n == 0 {
            return Some(true);
        }
        if (visited + n) / 32 != visited / 32 && clock.interrupted().is_some() {
            return None;
        }
        visited += n;
        if !checker.states_valid(&rows[..n * dof]) {
            return Some(false);
        }
    }
}

/// A whole path (`n × dof`, row-major) checked state by state and motion by
/// motion at `resolution`; `None` when `clock` was interrupted.
pub(crate) fn path_valid<C: StateChecker + ?Sized>(
    checker: &C,
    q: &[f64],
    dof: usize,
    resolution: f64,
    clock: &Clock<'_>,
) -> Option<bool> {
    let mut buf = vec![0.0; dof];
    let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
    if !rows.iter().all(|r| checker.is_valid(r)) {
        return Some(false);
    }
    for w in rows.windows(2) {
        if !interior_valid(checker, w[0], w[1], resolution, &mut buf, clock)? {
            return Some(false);
        }
    }
    Some(true)
}

/// The check resolution of `checker` (rad or m).
pub(crate) fn resolution_of<C: StateChecker + ?Sized>(checker: &C) -> f64 {
    checker.motion_check().resolution()
}

impl<C: StateChecker + ?Sized> CostModel<'_, C> {
    /// Evaluates trajectory `q` (`n × dof`, row-major) into `e`.
    ///
    /// Per timestep `t`:
    /// - collision: `c(t) = penalty · Σ_{|j|≤W} (1 − (j/(W+1))²) · x(t+j)`,
    ///   `x = 1` where the state or a motion to a neighbour is invalid
    ///   (Epanechnikov window of half-width W); plus
    ///   `w_d · max(0, (d_max − d)/d_max)` with `d` the clearance (m);
    /// - joint limits: `w_l · Σ_d` (distance beyond the limit);
    /// - control: `½ w_c Σ_d q̈_d(t)²` with `q̈` the stencil of
    ///   [`ACCELERATION_STENCIL`]/12 per timestep² on the trajectory padded
    ///   with copies of the start and the goal — the quadratic form
    ///   `½ w_c θ_dᵀRθ_d` plus the fixed ends' terms (rows just outside the
    ///   trajectory are added to its first and last timestep);
    /// - CCSTOMP: S0 eq. 3.3's term against the straight Cartesian line.
    ///
    /// Returns false, with `e` incomplete, when `clock` is interrupted
    /// (checked before every waypoint and every motion).
    pub fn evaluate(&self, q: &[f64], e: &mut Evaluation, clock: &Clock<'_>) -> bool {
        let (n, dof, p) = (self.n, self.dof, self.params);
        let row = |t: usize| &q[t * dof..(t + 1) * dof];
        e.total = f64::INFINITY;
        e.collision_free = false;
        for t in 0..n {
            if clock.interrupted().is_some() {
                return false;
            }
            if p.clearance_weight > 0.0 {
                let (ok, d) = self.checker.valid_and_clearance(row(t), p.clearance_distance);
                (e.state_ok[t], e.clearance[t]) = (ok, d);
            } else {
                e.state_ok[t] = self.checker.is_valid(row(t));
            }
        }
        for s in 0..n - 1 {
            if clock.interrupted().is_some() {
                return false;
            }
            e.segment_ok[s] = e.state_ok[s]
                && e.state_ok[s + 1]
                && match interior_valid(
                    self.checker,
                    row(s),
                    row(s + 1),
                    self.resolution,
                    &mut e.scratch,
                    clock,
                ) {
                    Some(ok) => ok,
                    None => return false,
                };
        }
        for t in 0..n {
            let bad = !e.state_ok[t] || (t > 0 && !e.segment_ok[t - 1]) || (t + 1 < n && !e.segment_ok[t]);
            e.raw[t] = if bad { 1.0 } else { 0.0 };
        }
        e.collision_free = e.raw.iter().all(|&x| x == 0.0);
        let w = p.kernel_half_width as isize;
        let mut total = 0.0;
        for t in 0..n {
            let mut c = 0.0;
            if !e.collision_free {
                for j in -w..=w {
                    let k = t as isize + j;
                    if k >= 0 && (k as usize) < n && e.raw[k as usize] > 0.0 {
                        let u = j as f64 / (w + 1) as f64;
                        c += 1.0 - u * u;
                    }
                }
            }
            c *= p.collision_penalty;
            let qt = row(t);
            if p.clearance_weight > 0.0 {
                let d = e.clearance[t];
                c += p.clearance_weight * ((p.clearance_distance - d) / p.clearance_distance).max(0.0);
            }
            if p.joint_limit_weight > 0.0 {
                let excess: f64 = qt
                    .iter()
                    .zip(&self.limits)
                    .map(|(&v, &(lo, hi))| (lo - v).max(0.0) + (v - hi).max(0.0))
                    .sum();
                c += p.joint_limit_weight * excess;
            }
            e.state[t] = c;
            total += c;
        }
        e.deviation.clear();
        e.within_tolerance = true;
        if let Some((cp, line)) = &self.cartesian {
            for t in 0..n {
                let d = deviation(&line.pose_at_waypoint(t, n), &self.chain.fk(row(t)));
                e.within_tolerance &= !violates(&d, cp);
                let c = cartesian_cost(&d, cp);
                e.state[t] += c;
                total += c;
                e.deviation.push(d);
            }
        }
        e.control.iter_mut().for_each(|c| *c = 0.0);
        if p.control_cost_weight > 0.0 {
            let padded = |t: isize, d: usize| q[(t.clamp(0, n as isize - 1) as usize) * dof + d];
            for r in -1..=n as isize {
                let mut sq = 0.0;
                for d in 0..dof {
                    let acc: f64 = (0..5)
                        .map(|k| ACCELERATION_STENCIL[k] * padded(r + k as isize - 2, d))
                        .sum::<f64>()
                        / 12.0;
                    sq += acc * acc;
                }
                let c = 0.5 * p.control_cost_weight * sq;
                e.control[r.clamp(0, n as isize - 1) as usize] += c;
                total += c;
            }
        }
        e.total = total;
        true
    }
}
