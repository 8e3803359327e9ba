//! RRT-Connect (Kuffner & LaValle 2000) in joint space, with shortcutting
//! and resampling for STOMP's initial trajectory.

use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::RrtParams;
use super::clock::{Clock, Interrupt};
use super::costs::{interior_valid, interior_valid_as, resolution_of};
use super::error::{PlanError, PlanField, check_vector};
use super::noise::{standard_normal, stream};
use super::rrt_tree::{Grown, grow};
use crate::Deadline;
use crate::collision::{PaddedMotion, StateChecker, WarmChecks, padded_motion, padded_motion_valid};
use crate::robot::{Chain, JointKind};

/// How RRT-Connect ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RrtStop {
    /// The trees met.
    Connected,
    /// `max_samples` samples without a connection.
    SampleBudget,
    /// The deadline passed.
    Deadline,
    /// The caller's cancellation was raised.
    Cancelled,
}

/// What [`rrt_connect`](super::rrt_connect) returns.
#[derive(Debug, Clone, PartialEq)]
pub struct RrtOutcome {
    /// Waypoints from start to goal (row-major, `dof` per row), shortcut;
    /// empty unless `stop` is `Connected`.
    pub path: Vec<f64>,
    pub stop: RrtStop,
    /// Random samples drawn.
    pub samples: usize,
    /// Nodes in both trees.
    pub nodes: usize,
    /// Wall time of the search (straight-line test and tree growth), ns.
    pub search_ns: u64,
    /// Wall time of the shortcutting after a connection, ns (0 otherwise).
    pub shortcut_ns: u64,
}

/// Sampling box per joint: the limits, or ±π (rotational) / ±1 m
/// (prismatic) for unlimited joints.
pub(crate) fn sampling_bounds(chain: &Chain) -> Vec<(f64, f64)> {
    chain
        .joints()
        .iter()
        .map(|j| {
            if j.lower.is_finite() && j.upper.is_finite() && j.upper - j.lower < 1e6 {
                (j.lower, j.upper)
            } else if j.kind == JointKind::Prismatic {
                (-1.0, 1.0)
            } else {
                (-std::f64::consts::PI, std::f64::consts::PI)
            }
        })
        .collect()
}

/// RRT-Connect alone, as [`plan`](super::plan) runs it for
/// `Algorithm::RrtConnect` but without the start/goal validity test, the
/// re-check, the time parameterisation and the scoring — for benchmarks that
/// time the search ([`RrtOutcome::search_ns`]) and the shortcutting
/// ([`RrtOutcome::shortcut_ns`]) apart. `start` and `goal` should be valid
/// states (the search assumes it); lengths and parameters are validated.
pub fn rrt_connect<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    params: &RrtParams,
    seed: u64,
    deadline: Deadline<'_>,
) -> Result<RrtOutcome, PlanError> {
    let dof = chain.dof();
    if dof == 0 {
        return Err(PlanError::EmptyChain);
    }
    if checker.dof() != dof {
        return Err(PlanError::CheckerDof {
            chain: dof,
            checker: checker.dof(),
        });
    }
    check_vector(PlanField::Start, start, dof)?;
    check_vector(PlanField::GoalJoints, goal, dof)?;
    params.validate()?;
    let clock = Clock {
        start: Instant::now(),
        deadline,
    };
    // the search runs on this thread alone, one check after another (the
    // checker's pair tables, built in parallel, exist before it starts)
    let _warm = WarmChecks::begin();
    Ok(rrt_connect_path(
        chain, checker, start, goal, params, seed, &clock,
    ))
}

/// RRT-Connect between two valid states ([`grow`]), then shortcut.
///
/// Under a padded (conservative) motion check the trees grow with the
/// cheaper interpolated check and the path they find is then proved edge by
/// edge with the padded check ([`prove_lazily`]), so the returned path is as
/// conservative as if every tree edge had been padded, while the many edges
/// the search tries and drops are never padded. Shortcutting uses the
/// checker's own check. The deadline (and its cancellation) is checked every sample
/// and every connect step. Parameters must be valid.
pub(crate) fn rrt_connect_path<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    params: &RrtParams,
    seed: u64,
    clock: &Clock<'_>,
) -> RrtOutcome {
    let dof = start.len();
    let bounds = sampling_bounds(chain);
    let mut rng = stream(seed, u64::MAX, 0);
    let t0 = Instant::now();
    let grown = if checker.motion_check().is_padded() {
        prove_lazily(checker, &bounds, start, goal, params, &mut rng, clock)
    } else {
        let (budget, resolution) = (params.max_samples, resolution_of(checker));
        grow(
            checker, &bounds, start, goal, params, false, true, resolution, budget, &mut rng, clock,
        )
    };
    let search_ns = t0.elapsed().as_nanos() as u64;
    let outcome = |stop, path, shortcut_ns| RrtOutcome {
        path,
        stop,
        samples: grown.samples,
        nodes: grown.nodes,
        search_ns,
        shortcut_ns,
    };
    let mut path = match grown.path {
        Ok(path) => path,
        Err(stop) => return outcome(stop, Vec::new(), 0),
    };
    if path.len() == 2 * dof {
        return outcome(RrtStop::Connected, path, 0);
    }
    let resolution = resolution_of(checker);
    let res = params
        .shortcut_resolution
        .map_or(resolution, |r| r.min(resolution));
    let t1 = Instant::now();
    let attempts = params.shortcut_attempts;
    shortcut(checker, &mut path, dof, res, attempts, &mut rng, clock);
    outcome(RrtStop::Connected, path, t1.elapsed().as_nanos() as u64)
}

/// How much coarser than the checker's resolution the lazy search
/// interpolates: its states only guide the search (the proof is the check).
/// Coarser searches faster until the proofs start failing more often; four
/// was the best of two to eight on the MotionBenchMaker Panda problems.
const LAZY_COARSENING: f64 = 4.0;

/// The padded search, lazily: trees grown with interpolated edge checks
/// ([`LAZY_COARSENING`] times the checker's resolution apart), then every
/// edge of the path they find proved with the padded check
/// ([`padded_motion_valid`]); an edge that cannot be proved is replaced by
/// two through a nudged waypoint ([`nudged_waypoint`]), else by a path grown
/// between its ends with padded edges, and if that fails too the whole
/// problem is grown with padded edges. Samples count against one budget,
/// `params.max_samples`. (A grown detour is the costly part of a proof, so
/// the nudges come first, spread around where the edge was refused rather
/// than around its midpoint.)
#[inline(never)] // one call per search; a named frame for profilers
fn prove_lazily<C: StateChecker + ?Sized>(
    checker: &C,
    bounds: &[(f64, f64)],
    start: &[f64],
    goal: &[f64],
    params: &RrtParams,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) -> Grown {
    let dof = start.len();
    let resolution = resolution_of(checker);
    let coarse = resolution * LAZY_COARSENING;
    let mut grown = grow(
        checker,
        bounds,
        start,
        goal,
        params,
        false,
        true,
        coarse,
        params.max_samples,
        rng,
        clock,
    );
    let Ok(found) = grown.path else {
        return grown;
    };
    let mut proved = start.to_vec();
    for (x, y) in found.chunks_exact(dof).zip(found.chunks_exact(dof).skip(1)) {
        let at = match padded_motion(checker, x, y, resolution, clock.deadline) {
            PaddedMotion::Free => {
                proved.extend_from_slice(y);
                continue;
            }
            PaddedMotion::Interrupted => {
                grown.path = Err(clock.interrupted().map_or(RrtStop::Deadline, stop_of));
                return grown;
            }
            PaddedMotion::Refused { at } => at,
        };
        // x → y itself was just refused: first through a waypoint nudged
        // from where it was refused
        if let Some(m) = nudged_waypoint(checker, bounds, x, y, at, resolution, rng, clock) {
            proved.extend_from_slice(&m);
            proved.extend_from_slice(y);
            continue;
        }
        let budget = params.max_samples.saturating_sub(grown.samples);
        let detour = grow(
            checker, bounds, x, y, params, true, false, resolution, budget, rng, clock,
        );
        grown.samples += detour.samples;
        grown.nodes += detour.nodes;
        match detour.path {
            Ok(piece) => proved.extend_from_slice(&piece[dof..]),
            Err(RrtStop::SampleBudget) => {
                let budget = params.max_samples.saturating_sub(grown.samples);
                // the straight start → goal either failed the interpolated
                // check, so cannot be proved, or was the edge refused
                let whole = grow(
                    checker, bounds, start, goal, params, true, false, resolution, budget, rng, clock,
                );
                grown.samples += whole.samples;
                grown.nodes += whole.nodes;
                grown.path = whole.path;
                return grown;
            }
            Err(stop) => {
                grown.path = Err(stop);
                return grown;
            }
        }
    }
    grown.path = Ok(proved);
    grown
}

/// Nudges tried before a padded detour (more nudges, spreading slower, were
/// no better overall on the MotionBenchMaker problems).
const NUDGES: usize = 12;

/// A state `m` near `x + at·(y − x)`, where the motion `x → y` was refused,
/// with both `x → m` and `m → y` proved free: that state moved by Gaussian
/// offsets whose spread doubles every three tries (0.05, 0.1, 0.2, 0.4 rad
/// or m), within `bounds`; `None` after [`NUDGES`] tries or when `clock`
/// says stop. Each candidate is first checked as the lazy search checks its
/// edges (states [`LAZY_COARSENING`] resolutions apart), so most blocked
/// ones cost a few states instead of a proof.
#[allow(clippy::too_many_arguments)]
pub(super) fn nudged_waypoint<C: StateChecker + ?Sized>(
    checker: &C,
    bounds: &[(f64, f64)],
    x: &[f64],
    y: &[f64],
    at: f64,
    resolution: f64,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) -> Option<Vec<f64>> {
    if x.len() != y.len() || bounds.len() != x.len() {
        return None;
    }
    let coarse = resolution * LAZY_COARSENING;
    let mut buf = vec![0.0; x.len()];
    let mut m = vec![0.0; x.len()];
    for k in 0..NUDGES {
        if clock.interrupted().is_some() {
            return None;
        }
        let sigma = 0.05 * f64::powi(2.0, (k / 3) as i32);
        for (j, v) in m.iter_mut().enumerate() {
            let normal = standard_normal(rng);
            let (lo, hi) = bounds[j];
            *v = (x[j] + at * (y[j] - x[j]) + sigma * normal).clamp(lo, hi);
        }
        let guided = |a: &[f64], b: &[f64], buf: &mut [f64]| {
            interior_valid_as(checker, a, b, coarse, false, buf, clock) == Some(true)
        };
        if checker.is_valid(&m)
            && guided(x, &m, &mut buf)
            && guided(&m, y, &mut buf)
            && padded_motion_valid(checker, x, &m, resolution, clock.deadline) == Some(true)
            && padded_motion_valid(checker, &m, y, resolution, clock.deadline) == Some(true)
        {
            return Some(m);
        }
    }
    None
}

/// The stop an interrupt means.
pub(super) fn stop_of(interrupt: Interrupt) -> RrtStop {
    match interrupt {
        Interrupt::Deadline => RrtStop::Deadline,
        Interrupt::Cancelled => RrtStop::Cancelled,
    }
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Least shortening (joint-space path length: rad, or m for prismatic
/// joints) a random shortcut must bring to be checked at all. A shortcut's
/// cost is the proof of its chord whatever it gains, and converged paths draw
/// many chords that gain almost nothing. On the MotionBenchMaker Panda
/// problems the shortcuts below this gain took a large share of the
/// checking time for little of the total shortening (`benches/RESULTS.md`,
/// shortcutting under a Plan call).
const MIN_SHORTCUT_GAIN: f64 = 0.01;

/// Longest stretch of path, as a fraction of its length, a random shortcut
/// may replace: the second point is drawn within this arc length of the
/// first (OMPL's shortcutting bounds its chords by a range ratio of the path
/// in a similar way). Chords across most of a path are mostly blocked and
/// cost a check each; shorter ones are accepted more often, and several of
/// them straighten a path as far.
const SHORTCUT_SPAN: f64 = 1.0 / 3.0;

/// Greedy vertex shortcut: from each kept vertex, jump to the farthest
/// later vertex reachable by a valid straight motion.
fn greedy_pass<C: StateChecker + ?Sized>(
    checker: &C,
    path: &mut Vec<f64>,
    dof: usize,
    resolution: f64,
    clock: &Clock<'_>,
) {
    let n = path.len() / dof;
    let mut buf = vec![0.0; dof];
    let mut out = path[..dof].to_vec();
    let mut i = 0;
    while i + 1 < n {
        let mut j = n - 1;
        while j > i + 1 {
            match interior_valid(
                checker,
                &path[i * dof..(i + 1) * dof],
                &path[j * dof..(j + 1) * dof],
                resolution,
                &mut buf,
                clock,
            ) {
                None => return,
                Some(true) => break,
                Some(false) => j -= 1,
            }
        }
        out.extend_from_slice(&path[j * dof..(j + 1) * dof]);
        i = j;
    }
    *path = out;
}

/// Shortens a valid path in place: a greedy vertex pass, then `attempts`
/// random partial shortcuts. An attempt draws a point `u1` uniformly by arc
/// length on the path (length `L`) and a second `u2` uniformly within
/// [`SHORTCUT_SPAN`]` · L` of it (clamped to the path); when they fall on
/// different segments `s1 < s2`, the points `p1`, `p2` there replace the
/// path between them if the motions `v_{s1} → p1 → p2 → v_{s2+1}` are valid.
///
/// Under interpolated checks the pieces of old segments (`v_{s1} → p1`,
/// `p2 → v_{s2+1}`) are re-checked, since an interpolated check of a piece
/// visits other states. Under padded checks they are not: every state of a
/// proved motion is free, so its pieces are too, and only the chord
/// `p1 → p2` needs a proof. An attempt whose chord would shorten the path
/// (`(u2 − u1) − |p2 − p1|`) by at most [`MIN_SHORTCUT_GAIN`] is skipped
/// without a check. The ends are kept exactly; every edge of the result is
/// checked at `resolution` (or lies on an edge that was). Stops early when
/// `clock` is interrupted (the path stays valid).
///
/// No greedy pass follows the random ones: on the MotionBenchMaker Panda
/// problems it only ever removed single vertices, shortening the paths
/// little for a large share of the shortcutting time (`benches/RESULTS.md`).
pub(crate) fn shortcut<C: StateChecker + ?Sized>(
    checker: &C,
    path: &mut Vec<f64>,
    dof: usize,
    resolution: f64,
    attempts: usize,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) {
    greedy_pass(checker, path, dof, resolution, clock);
    let mut buf = vec![0.0; dof];
    let mut cum = Vec::new();
    let mut p1 = vec![0.0; dof];
    let mut p2 = vec![0.0; dof];
    let padded = checker.motion_check().is_padded();
    for _ in 0..attempts {
        if clock.interrupted().is_some() {
            return;
        }
        let n = path.len() / dof;
        if n < 3 {
            break;
        }
        cum.clear();
        cum.push(0.0);
        for s in 0..n - 1 {
            let l = dist(&path[s * dof..(s + 1) * dof], &path[(s + 1) * dof..(s + 2) * dof]);
            cum.push(cum[s] + l);
        }
        let total = cum[n - 1];
        if total <= 0.0 {
            break;
        }
        let mut u1 = rng.random::<f64>() * total;
        let reach = SHORTCUT_SPAN * total;
        let mut u2 = (u1 + (2.0 * rng.random::<f64>() - 1.0) * reach).clamp(0.0, total);
        if u1 > u2 {
            std::mem::swap(&mut u1, &mut u2);
        }
        let seg = |u: f64| cum.partition_point(|&c| c <= u).clamp(1, n - 1) - 1;
        let (s1, s2) = (seg(u1), seg(u2));
        if s1 == s2 {
            continue;
        }
        let point = |s: usize, u: f64, out: &mut [f64]| {
            let l = cum[s + 1] - cum[s];
            let f = if l > 0.0 { (u - cum[s]) / l } else { 0.0 };
            for (j, v) in out.iter_mut().enumerate() {
                *v = path[s * dof + j] + f * (path[(s + 1) * dof + j] - path[s * dof + j]);
            }
        };
        point(s1, u1, &mut p1);
        point(s2, u2, &mut p2);
        // the path between p1 and p2 is u2 - u1 long; the chord replaces it
        if u2 - u1 - dist(&p1, &p2) <= MIN_SHORTCUT_GAIN {
            continue;
        }
        let v1 = &path[s1 * dof..(s1 + 1) * dof];
        let v2 = &path[(s2 + 1) * dof..(s2 + 2) * dof];
        let mut ok = padded || (checker.is_valid(&p1) && checker.is_valid(&p2));
        let motions = [(&p1[..], &p2[..]), (v1, &p1[..]), (&p2[..], v2)];
        for (x, y) in &motions[..if padded { 1 } else { 3 }] {
            if !ok {
                break;
            }
            match interior_valid(checker, x, y, resolution, &mut buf, clock) {
                None => return,
                Some(v) => ok = v,
            }
        }
        if ok {
            let mut out = Vec::with_capacity(path.len());
            out.extend_from_slice(&path[..(s1 + 1) * dof]);
            out.extend_from_slice(&p1);
            out.extend_from_slice(&p2);
            out.extend_from_slice(&path[(s2 + 1) * dof..]);
            *path = out;
        }
    }
}

/// `n ≥ 2` waypoints on a piecewise-linear path (row-major): every vertex is
/// kept (so no chord cuts a corner) and the remaining `n − vertices` points
/// are spread over the segments in proportion to their length. With more
/// vertices than `n`, points are placed uniformly by arc length instead.
pub(crate) fn resample(path: &[f64], dof: usize, n: usize) -> Vec<f64> {
    let v = path.len() / dof;
    let row = |i: usize| &path[i * dof..(i + 1) * dof];
    let lens: Vec<f64> = (0..v - 1).map(|s| dist(row(s), row(s + 1))).collect();
    let total: f64 = lens.iter().sum();
    let mut out = Vec::with_capacity(n * dof);
    if v <= n && total > 0.0 {
        // extra points per segment by largest remainders
        let extra = n - v;
        let ideal: Vec<f64> = lens.iter().map(|l| l / total * extra as f64).collect();
        let mut count: Vec<usize> = ideal.iter().map(|x| x.floor() as usize).collect();
        let left = extra - count.iter().sum::<usize>();
        let mut order: Vec<usize> = (0..lens.len()).collect();
        order.sort_by(|&a, &b| (ideal[b] - ideal[b].floor()).total_cmp(&(ideal[a] - ideal[a].floor())));
        for &s in order.iter().cycle().take(left) {
            count[s] += 1;
        }
        for (s, &k) in count.iter().enumerate() {
            out.extend_from_slice(row(s));
            for i in 1..=k {
                let f = i as f64 / (k + 1) as f64;
                out.extend(row(s).iter().zip(row(s + 1)).map(|(a, b)| a + f * (b - a)));
            }
        }
        out.extend_from_slice(row(v - 1));
        return out;
    }
    let mut s = 0;
    let mut acc = 0.0;
    for i in 0..n {
        let u = if total > 0.0 {
            total * i as f64 / (n - 1) as f64
        } else {
            0.0
        };
        while s + 1 < v - 1 && acc + lens[s] < u {
            acc += lens[s];
            s += 1;
        }
        let f = if lens[s] > 0.0 {
            ((u - acc) / lens[s]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.extend(row(s).iter().zip(row(s + 1)).map(|(a, b)| a + f * (b - a)));
    }
    out[..dof].copy_from_slice(row(0));
    out[(n - 1) * dof..].copy_from_slice(row(v - 1));
    out
}
