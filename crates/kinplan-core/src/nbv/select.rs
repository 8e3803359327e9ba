//! The NBV pipeline: candidates, ORF → PTF → IGF, utility, IK reachability
//! (docs/exploration.md, S0 §4).

use std::time::Instant;

use kiddo::{KdTree, SquaredEuclidean};
use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::camera::{CameraModel, Frustum};
use super::count::FrustumCounter;
use super::frontier::{candidate_pose, frontier_cells, potential_field, unknown_needed};
use super::gain::{GainMethod, GainWorkspace, ray_gain};
use super::grid::{Ball, FIELD_LANES, MAX_CELLS, StateGrid};
use super::visibility::{PredictWorkspace, ViewGrid, ViewPrediction, predict_on_grid, predict_view_in};
use super::{NbvError, NbvParams, Weights};
use crate::ik::{IkTarget, solve_ik};
use crate::octree::{CellState, Octree};
use crate::robot::Chain;
use crate::{Deadline, Stop};

/// How the request ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NbvStatus {
    /// Every stage ran to the end.
    Complete,
    /// The time budget ran out; the result ranks what was evaluated by then.
    TimeBudget,
    /// The caller's cancellation was raised; likewise partial.
    Cancelled,
}

/// One ranked view.
#[derive(Debug, Clone, PartialEq)]
pub struct NbvCandidate {
    /// Camera pose (optical frame → map; +z is the view direction).
    pub pose: Isometry3<f64>,
    /// The frontier cell it looks at (None for caller-given poses).
    pub frontier: Option<Point3<f64>>,
    /// D = 1 − ‖p_c − p'‖ / (2·d_max).
    pub distance_term: f64,
    /// R = 1 − Δr/π.
    pub rotation_term: f64,
    /// Ig = c / c_max.
    pub ig: f64,
    /// c, the unknown cells counted (weighted sum for occlusion-aware gain).
    pub unknown_cells: f64,
    /// f = w_d·D + w_r·R + w_i·Ig (minus the failure penalty when counting failures).
    pub utility: f64,
    /// Some(true/false) once checked by IK, None when not checked.
    pub reachable: Option<bool>,
    /// IK joints (rad/m, chain order) reaching the camera pose, when reachable.
    pub joints: Option<Vec<f64>>,
    /// Planning failures: prior ones matched by position plus this call's.
    pub failures: u32,
    /// What the view is predicted to reveal, when the visibility check ran on it.
    pub predicted: Option<ViewPrediction>,
}

/// Per-stage counts and times (µs) of one request.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageStats {
    pub frontier_cells: usize,
    pub frontier_candidates: usize,
    pub caller_candidates: usize,
    pub after_orf: usize,
    pub after_ptf: usize,
    pub after_igf: usize,
    pub ik_checked: usize,
    pub ik_failed: usize,
    pub frontier_us: u64,
    pub field_us: u64,
    pub orf_us: u64,
    pub ptf_us: u64,
    pub igf_us: u64,
    pub ik_us: u64,
    /// DDA steps of ray gains.
    pub ray_steps: u64,
    /// Visibility check: candidates predicted, dropped (lower bound below
    /// `min_new_cells`), kept.
    pub visibility_checked: usize,
    pub visibility_dropped: usize,
    pub after_visibility: usize,
    /// Largest lower bound `first` among the predicted views (cells).
    pub best_predicted_cells: u32,
    pub visibility_us: u64,
}

/// Result of [`next_best_view`].
#[derive(Debug, Clone, PartialEq)]
pub struct NbvResult {
    /// Best first, at most `max_results`.
    pub candidates: Vec<NbvCandidate>,
    pub stages: StageStats,
    pub status: NbvStatus,
    /// Weights used (after adaptation).
    pub weights: Weights,
    /// Reach used by ORF (m), if any.
    pub reach: Option<f64>,
    pub elapsed_us: u64,
}

/// The request's deadline (already combined with `NbvParams::time_budget`).
struct Clock<'a> {
    deadline: Deadline<'a>,
}

impl Clock<'_> {
    fn interrupted(&self) -> Option<NbvStatus> {
        self.deadline.stop().map(|s| match s {
            Stop::Deadline => NbvStatus::TimeBudget,
            Stop::Cancelled => NbvStatus::Cancelled,
        })
    }
}

fn us(t: Instant) -> u64 {
    t.elapsed().as_micros() as u64
}

/// S0's utility `f = w_d·D + w_r·R + w_i·Ig − penalty·failures` of a scored candidate
/// (`failures` is 0 unless failures are counted).
fn utility(w: &Weights, c: &NbvCandidate, failure_penalty: f64) -> f64 {
    w.w_d * c.distance_term + w.w_r * c.rotation_term + w.w_i * c.ig - failure_penalty * c.failures as f64
}

/// Largest tool distance from the base over 2,000 seeded joint samples inside the
/// limits (unlimited revolute joints in [−π, π]), plus 5 % (m).
pub fn estimate_reach(chain: &Chain) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let lim: Vec<(f64, f64)> = chain
        .limits()
        .map(|(lo, hi)| {
            if lo.is_finite() && hi.is_finite() && hi > lo {
                (lo, hi)
            } else {
                (-3.2, 3.2)
            }
        })
        .collect();
    let mut q = vec![0.0; lim.len()];
    let mut best: f64 = 0.0;
    for _ in 0..2000 {
        for (v, &(lo, hi)) in q.iter_mut().zip(&lim) {
            *v = rng.random_range(lo..=hi);
        }
        best = best.max(chain.fk(&q).translation.vector.norm());
    }
    best * 1.05
}

/// Ranks candidate views of `tree` for `camera` now at `current_pose` (optical frame →
/// map) — docs/exploration.md / S0 §4:
/// 1. candidates: frontier cells (free, ≥ `frontier_unknown_ratio` unknown
///    neighbours), each looking along its potential field `F = ΣF_p − ΣF_o` from a
///    stand-off, plus `extra_candidates`;
/// 2. ORF: `‖p' − base‖ > reach` dropped (with `free_viewpoint`, also a
///    camera position in an occupied cell, in an unknown cell inside the
///    region, or below the region); PTF: dropped when a kept candidate is within
///    `position_threshold` (k-d tree) and `orientation_threshold`; IGF: `Ig <
///    gain_threshold` dropped (gains computed in parallel);
/// 3. `f = w_d·D + w_r·R + w_i·Ig`, `D = 1 − ‖p_c − p'‖/(2·d_max)` (d_max the largest
///    distance among the survivors), `R = 1 − Δr/π` (Δr the rotation angle between the
///    current and the candidate orientation);
/// 4. with `visibility`, the best candidates are checked in batches by
///    [`predict_view`](super::predict_view): views whose lower bound is below
///    `min_new_cells` are dropped, the rest get `Ig = reached / max reached` and are
///    ranked again by the same `f` (unchecked candidates are not returned);
/// 5. the best `ik_check` are checked by IK on `robot` for the tip pose
///    `base⁻¹ · pose · mount⁻¹`; unreachable ones are dropped (or, with
///    `count_failures`, kept with `f − failure_penalty · failures`).
///
/// `deadline` (its instant or `params.time_budget` from the start, whichever comes first, and its
/// cancellation) is polled per candidate in every stage, the IK included; on either the result ranks
/// what was evaluated (a candidate whose IK was cut is kept, its reachability unknown).
pub fn next_best_view(
    tree: &Octree,
    params: &NbvParams,
    camera: &CameraModel,
    current_pose: &Isometry3<f64>,
    robot: Option<&Chain>,
    deadline: Deadline<'_>,
) -> Result<NbvResult, NbvError> {
    params.validate()?;
    camera.validate()?;
    if let Some(v) = &params.visibility {
        v.validate_for(camera)?;
    }
    let start = Instant::now();
    let clock = Clock {
        deadline: deadline.min_with_budget(params.time_budget),
    };
    let mut st = StageStats::default();
    let mut status = NbvStatus::Complete;
    // default region: the known leaves' bounds, moved in by half a cell to the centres of
    // the outermost cells (the upper bound may be the tree cube's exclusive edge)
    let half = tree.resolution() / 2.0;
    let region = params.region.or_else(|| {
        tree.known_bounds().map(|(a, b)| {
            (
                a + nalgebra::Vector3::repeat(half),
                b - nalgebra::Vector3::repeat(half),
            )
        })
    });

    // 1. candidates: one dense state grid of the region plus the field's radius serves
    // the frontier test and every potential field when it fits (else tree lookups)
    let t = Instant::now();
    let ball = Ball::new(tree.resolution(), params.field_radius);
    let mut grid = None;
    let mut frontier = match &region {
        Some((a, b)) if params.max_frontier_candidates > 0 => {
            let (ka, kb) = (tree.key_of(a)?, tree.key_of(b)?);
            // the field's reach, and one more layer that the visibility walk recodes
            // as the grid's end (`ViewGrid::from_padded`)
            let pad = ball.as_ref().map_or(1, |b| b.reach.max(1)) + 1;
            if (0..3).all(|i| ka[i] <= kb[i]) {
                grid = StateGrid::new(
                    tree,
                    ka.map(|k| k as i64 - pad),
                    kb.map(|k| k as i64 + pad),
                    MAX_CELLS,
                );
            }
            match &grid {
                Some(g) => g.frontier(
                    tree,
                    &ka,
                    &kb,
                    unknown_needed(params.frontier_unknown_ratio),
                    clock.deadline,
                ),
                None => frontier_cells(tree, a, b, params.frontier_unknown_ratio, clock.deadline)?,
            }
        }
        _ => Vec::new(),
    };
    if let Some(s) = clock.interrupted() {
        status = s; // the frontier scan was cut short
    }
    st.frontier_cells = frontier.len();
    if frontier.len() > params.max_frontier_candidates {
        let n = frontier.len();
        let m = params.max_frontier_candidates;
        frontier = (0..m).map(|i| frontier[i * n / m]).collect();
    }
    st.frontier_us = us(t);
    let t = Instant::now();
    // potential fields in parallel, FIELD_LANES cells per pass on the grid (the last
    // group padded with its last cell); the clock is polled per group
    let steps = match (&grid, &ball) {
        (Some(g), Some(b)) => b.index_steps(g),
        _ => Vec::new(),
    };
    let fields_stage = || {
        frontier
            .par_chunks(FIELD_LANES)
            .map(|group| {
                let mut out = [None; FIELD_LANES];
                if clock.interrupted().is_some() {
                    return Ok(out);
                }
                let poses = |fs: &[Vector3<f64>], out: &mut [Option<Option<Isometry3<f64>>>; FIELD_LANES]| {
                    for ((o, f), field) in out.iter_mut().zip(group).zip(fs) {
                        *o = Some(candidate_pose(&f.center, field, params.standoff, camera.near));
                    }
                };
                match (&grid, &ball) {
                    (Some(g), Some(b)) => {
                        let keys = std::array::from_fn(|l| group[l.min(group.len() - 1)].key);
                        poses(&g.fields(&keys, b, &steps), &mut out);
                    }
                    _ => {
                        let mut fs = [Vector3::zeros(); FIELD_LANES];
                        for (v, f) in fs.iter_mut().zip(group) {
                            *v = potential_field(tree, &f.key, params.field_radius)?;
                        }
                        poses(&fs, &mut out);
                    }
                }
                Ok(out)
            })
            .collect::<Result<Vec<_>, crate::octree::OctreeError>>()
    };
    // beside the fields, on whichever thread is free: the tree's known-cell counts for
    // the intersection gain and the robot's reach for ORF (neither reads the fields)
    let side_work = || {
        let counter = matches!(params.gain, GainMethod::Intersection).then(|| FrustumCounter::new(tree));
        (counter, params.reach.or_else(|| robot.map(estimate_reach)))
    };
    let (fields, (counter, reach)) = rayon::join(fields_stage, side_work);
    let fields: Vec<Option<Option<Isometry3<f64>>>> =
        fields?.into_iter().flatten().take(frontier.len()).collect();
    if fields.iter().any(Option::is_none)
        && let Some(s) = clock.interrupted()
    {
        status = s;
    }
    let mut cands: Vec<(Isometry3<f64>, Option<Point3<f64>>)> = fields
        .into_iter()
        .zip(&frontier)
        .filter_map(|(p, f)| p.flatten().map(|p| (p, Some(f.center))))
        .collect();
    st.frontier_candidates = cands.len();
    st.caller_candidates = params.extra_candidates.len();
    cands.extend(params.extra_candidates.iter().map(|p| (*p, None)));
    st.field_us = us(t);

    // 2a. ORF
    let t = Instant::now();
    if let Some(r) = reach {
        let base = params.robot_base.translation.vector;
        cands.retain(|(p, _)| (p.translation.vector - base).norm() <= r);
    }
    if params.free_viewpoint {
        cands.retain(|(p, _)| {
            let at = Point3::from(p.translation.vector);
            let inside = region
                .as_ref()
                .map(|(a, b)| (0..3).all(|i| at[i] >= a[i] && at[i] <= b[i]));
            let below = region.as_ref().is_some_and(|(a, _)| at.z < a.z);
            match tree.state_at(&at, crate::octree::TREE_DEPTH) {
                Ok((CellState::Free, _)) => true,
                Ok((CellState::Unknown, _)) => inside == Some(false) && !below,
                _ => false,
            }
        });
    }
    st.after_orf = cands.len();
    st.orf_us = us(t);

    // 2b. PTF
    let t = Instant::now();
    let mut kd: KdTree<f64, 3> = KdTree::with_capacity(cands.len().max(1));
    let mut kept: Vec<(Isometry3<f64>, Option<Point3<f64>>)> = Vec::with_capacity(cands.len());
    let r2 = params.position_threshold * params.position_threshold;
    for c in cands {
        let p = c.0.translation.vector;
        let dir = c.0.rotation * nalgebra::Vector3::z();
        let near = kd.within_unsorted::<SquaredEuclidean>(&[p.x, p.y, p.z], r2);
        let clash = near.iter().any(|nb| {
            let other = kept[nb.item as usize].0.rotation * nalgebra::Vector3::z();
            dir.angle(&other) < params.orientation_threshold
        });
        if !clash {
            kd.add(&[p.x, p.y, p.z], kept.len() as u64);
            kept.push(c);
        }
    }
    st.after_ptf = kept.len();
    st.ptf_us = us(t);

    // 2c. IGF
    let t = Instant::now();
    let gain_keys = match (&region, params.gain_in_region) {
        (Some((a, b)), true) => Some((tree.key_of(a)?, tree.key_of(b)?)),
        _ => None,
    };
    let c_max = camera.frustum_volume() / tree.resolution().powi(3);
    // the state grid recoded for the visibility walks, built beside the gains (the
    // visibility stage checks the region's keys again); it takes the state grid over
    // and gives it back when it cannot
    let state_grid = if params.visibility.is_some() {
        grid.take()
    } else {
        None
    };
    let clock_ref = &clock;
    let view_grid_work = move || match (&params.visibility, state_grid, &region) {
        // not recoded once the request is interrupted: the visibility stage will not run
        (_, g, _) if clock_ref.interrupted().is_some() => (None, g),
        (Some(vp), Some(g), Some((a, b))) => match (tree.key_of(a), tree.key_of(b)) {
            (Ok(ka), Ok(kb)) => match ViewGrid::from_padded(g, (ka, kb), camera, vp.pixel_stride) {
                Ok(vg) => (Some(vg), None),
                Err(g) => (None, Some(g)),
            },
            _ => (None, Some(g)),
        },
        (_, g, _) => (None, g),
    };
    // the counter (the tree's known-cell counts) is shared by every candidate's count
    let gains_stage = || {
        kept.par_iter()
            .map_init(GainWorkspace::default, |ws, (pose, _)| {
                if clock.interrupted().is_some() {
                    return None;
                }
                Some(match params.gain {
                    GainMethod::Intersection => {
                        let counter = counter.as_ref().expect("built for the intersection gain");
                        let c = counter.count_in(&Frustum::new(camera, pose), gain_keys) as f64;
                        (c, c / c_max, 0)
                    }
                    m => {
                        let g = ray_gain(tree, camera, pose, m, ws, clock.deadline);
                        (g.cells, g.ig, g.ray_steps)
                    }
                })
            })
            .collect::<Vec<Option<(f64, f64, u64)>>>()
    };
    let (gains, (view_grid, back)) = rayon::join(gains_stage, view_grid_work);
    if back.is_some() {
        grid = back;
    }
    if gains.iter().any(Option::is_none)
        && let Some(s) = clock.interrupted()
    {
        status = s;
    }
    let mut scored: Vec<NbvCandidate> = Vec::with_capacity(kept.len());
    for ((pose, frontier), g) in kept.into_iter().zip(gains) {
        let Some((cells, ig, steps)) = g else { continue };
        st.ray_steps += steps;
        if ig < params.gain_threshold {
            continue;
        }
        scored.push(NbvCandidate {
            pose,
            frontier,
            distance_term: 0.0,
            rotation_term: 0.0,
            ig,
            unknown_cells: cells,
            utility: 0.0,
            reachable: None,
            joints: None,
            failures: 0,
            predicted: None,
        });
    }
    st.after_igf = scored.len();
    st.igf_us = us(t);

    // 3. utility
    let mut w = params.weights;
    if params.adaptive_weights
        && let Some((a, b)) = &region
    {
        let v = tree.volumes_in_box(a, b)?;
        let total = v.free + v.occupied + v.unknown;
        let u = if total > 0.0 { v.unknown / total } else { 0.0 };
        w = Weights {
            w_i: w.w_i * (0.5 + u),
            w_d: w.w_d * (1.5 - u),
            w_r: w.w_r * (1.5 - u),
        };
    }
    let pc = current_pose.translation.vector;
    let d_max = scored
        .iter()
        .map(|c| (c.pose.translation.vector - pc).norm())
        .fold(0.0f64, f64::max)
        .max(1e-12);
    for c in scored.iter_mut() {
        c.distance_term = 1.0 - (c.pose.translation.vector - pc).norm() / (2.0 * d_max);
        c.rotation_term = 1.0 - current_pose.rotation.angle_to(&c.pose.rotation) / std::f64::consts::PI;
        if params.count_failures {
            let pos = Point3::from(c.pose.translation.vector);
            c.failures = params
                .prior_failures
                .iter()
                .filter(|(p, _)| (p - pos).norm() <= params.position_threshold)
                .map(|(_, n)| *n)
                .sum();
        }
        c.utility = utility(&w, c, params.failure_penalty);
    }
    let rank = |v: &mut Vec<NbvCandidate>| v.sort_by(|a, b| b.utility.total_cmp(&a.utility));
    rank(&mut scored);

    // 3b. visibility (step 4 of the doc): predict the best views' yield by ray casting, drop the ones that
    // would add nothing, rank the rest again on the predicted gain
    if let Some(vp) = &params.visibility
        && status == NbvStatus::Complete
    {
        let t = Instant::now();
        let region_keys = match &region {
            Some((a, b)) => Some((tree.key_of(a)?, tree.key_of(b)?)),
            None => None,
        };
        let mut kept: Vec<NbvCandidate> = Vec::with_capacity(params.max_results);
        let mut rest = scored.into_iter();
        let pool = std::sync::Mutex::new(Vec::new());
        loop {
            let batch: Vec<NbvCandidate> = rest.by_ref().take(vp.batch).collect();
            if batch.is_empty() {
                break;
            }
            if let Some(s) = clock.interrupted() {
                status = s;
                break;
            }
            // a workspace per share of the batch (its bit sets span the region), taken from
            // the pool and given back, so the bit sets are allocated once per thread
            let preds: Vec<Option<ViewPrediction>> = batch
                .par_iter()
                .map_init(
                    || Pooled::take(&pool),
                    |pooled, c| {
                        let ws = &mut pooled.ws;
                        if clock.interrupted().is_some() {
                            return None;
                        }
                        Some(match &view_grid {
                            Some(vg) => predict_on_grid(tree, vg, camera, &c.pose, vp, ws, clock.deadline),
                            None => predict_view_in(
                                tree,
                                grid.as_ref(),
                                camera,
                                &c.pose,
                                vp,
                                region_keys,
                                ws,
                                clock.deadline,
                            ),
                        })
                    },
                )
                .collect();
            for (mut c, p) in batch.into_iter().zip(preds) {
                let Some(p) = p else { continue };
                st.visibility_checked += 1;
                st.ray_steps += p.steps;
                st.best_predicted_cells = st.best_predicted_cells.max(p.first);
                if (p.first as usize) < vp.min_new_cells {
                    st.visibility_dropped += 1;
                    continue;
                }
                c.predicted = Some(p);
                kept.push(c);
            }
            if let Some(s) = clock.interrupted() {
                status = s;
                break;
            }
            // enough views for the results and for the IK check that follows
            let wanted = match robot {
                Some(_) => params.max_results.max(params.ik_check),
                None => params.max_results,
            };
            if kept.len() >= wanted {
                break;
            }
        }
        // Ig = reached / the most reached among the kept views, in [0, 1]
        let best = kept
            .iter()
            .filter_map(|c| c.predicted.map(|p| p.reached))
            .max()
            .unwrap_or(1)
            .max(1) as f64;
        for c in kept.iter_mut() {
            let reached = c.predicted.map_or(0, |p| p.reached) as f64;
            c.ig = reached / best;
            c.unknown_cells = reached;
            c.utility = utility(&w, c, params.failure_penalty);
        }
        st.after_visibility = kept.len();
        scored = kept;
        rank(&mut scored);
        st.visibility_us = us(t);
    }

    // 4. reachability
    let t = Instant::now();
    if let Some(chain) = robot
        && params.ik_check > 0
    {
        let base_inv = params.robot_base.inverse();
        let mount_inv = params.camera_mount.inverse();
        let mut out = Vec::with_capacity(scored.len());
        let mut checked = 0;
        for (i, mut c) in scored.into_iter().enumerate() {
            if checked >= params.ik_check || status != NbvStatus::Complete {
                out.push(c);
                continue;
            }
            if let Some(s) = clock.interrupted() {
                status = s;
                out.push(c);
                continue;
            }
            checked += 1;
            let target = IkTarget::Pose(base_inv * c.pose * mount_inv);
            let r = solve_ik(
                chain,
                &target,
                None,
                &params.ik,
                params.seed.wrapping_add(i as u64),
                clock.deadline,
            )?;
            if r.solutions.is_empty()
                && let Some(s) = clock.interrupted()
            {
                // cut by the deadline, not found unreachable
                status = s;
                out.push(c);
                continue;
            }
            if let Some(s) = r.solutions.first() {
                c.reachable = Some(true);
                c.joints = Some(s.joints.clone());
                out.push(c);
            } else {
                st.ik_failed += 1;
                c.reachable = Some(false);
                if params.count_failures {
                    c.failures += 1;
                    c.utility = utility(&w, &c, params.failure_penalty);
                    out.push(c);
                }
            }
        }
        st.ik_checked = checked;
        scored = out;
        rank(&mut scored);
    }
    st.ik_us = us(t);
    scored.truncate(params.max_results);
    Ok(NbvResult {
        candidates: scored,
        stages: st,
        status,
        weights: w,
        reach,
        elapsed_us: us(start),
    })
}

/// A visibility workspace lent by a pool for one share of a batch and given
/// back when the share is done, so its bit sets outlive the batch.
struct Pooled<'a> {
    ws: PredictWorkspace,
    pool: &'a std::sync::Mutex<Vec<PredictWorkspace>>,
}

impl<'a> Pooled<'a> {
    fn take(pool: &'a std::sync::Mutex<Vec<PredictWorkspace>>) -> Self {
        let ws = pool
            .lock()
            .map(|mut p| p.pop())
            .ok()
            .flatten()
            .unwrap_or_default();
        Pooled { ws, pool }
    }
}

impl Drop for Pooled<'_> {
    fn drop(&mut self) {
        if let Ok(mut p) = self.pool.lock() {
            p.push(std::mem::take(&mut self.ws));
        }
    }
}
