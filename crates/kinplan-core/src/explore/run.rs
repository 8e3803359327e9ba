//! The exploration loop of S0 §4–5: initial scans, then NBV → IK → plan →
//! execute → scan → insert until the region is known.

use std::sync::Arc;
use std::time::Instant;

use nalgebra::{Isometry3, Point3};

use super::depth_camera::{depth_to_points, render_depth_until, strided_intrinsics};
use super::world_model::{ObservableCells, occupied_obstacles};
use super::{ExploreError, ExploreField, ExploreParams};
use crate::collision::{
    AllowedCollisions, CheckerParams, MotionCheck, RobotModel, Scene, SceneChecker, SceneGeometry,
    SceneLimits, StateChecker, interpolate_motion_valid,
};
use crate::nbv::{NbvCandidate, NbvParams, next_best_view};
use crate::octree::{Octree, ScanParams, ScanStatus};
use crate::plan::{Goal, PlanControl, PlanStatus, plan};
use crate::robot::Chain;
use crate::score::{PointSet, Rows, ScoreInput, ScoreParams, Scores, TrajectoryData, sample_chain, score};
use crate::{Deadline, Stop};

/// The robot and the world it explores.
pub struct ExploreWorld<'a> {
    pub chain: &'a Arc<Chain>,
    /// The chain's collision bodies and their allowed pairs.
    pub model: &'a Arc<RobotModel>,
    pub acm: &'a AllowedCollisions,
    /// The true scene: what the camera sees and what the robot really hits.
    /// The planner never sees it, only the octree built from scans.
    pub truth: &'a Arc<SceneGeometry>,
}

/// The caller's side channel: the run's [`Deadline`] (instant and
/// cancellation, checked between stages and inside NBV, sensing and
/// planning) and a callback per finished iteration (from the calling thread).
#[derive(Default)]
pub struct ExploreControl<'a> {
    pub deadline: Deadline<'a>,
    pub on_step: Option<&'a mut dyn FnMut(&ExploreStep)>,
}

/// Why the loop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExploreStatus {
    /// The known ratio reached `stop.known_ratio`.
    Explored,
    /// `stop.max_iterations` iterations ran.
    IterationCap,
    /// `stop.max_consecutive_failures` iterations in a row moved nowhere.
    ConsecutiveFailures,
    /// NBV found no candidate view (no frontier left that passes the filters).
    NoCandidates,
    /// The visibility check predicted every candidate view to reveal fewer
    /// than `visibility.min_new_cells` cells: what the views can still
    /// observe is exhausted (the estimate is the largest lower bound over
    /// the candidates, [`ExploreOutcome::best_predicted_cells`]).
    ObservableExhausted,
    /// The deadline passed.
    Timeout,
    /// The caller's cancellation was raised.
    Cancelled,
}

/// Why a tried view was not reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewFailure {
    /// NBV's IK check found no joints for the view.
    Unreachable,
    /// The planner ended with this status.
    Plan(PlanStatus),
    /// The view was reached and scanned but added no known cell (the
    /// occlusion-blind gain saw unknown cells hidden behind obstacles).
    NoGain,
}

/// The view an iteration moved to, with its utility terms (S0 §4.4).
#[derive(Debug, Clone, PartialEq)]
pub struct ChosenView {
    /// Camera optical frame in the world (base) frame.
    pub pose: Isometry3<f64>,
    /// D, R, Ig and f = w_d·D + w_r·R + w_i·Ig (minus the failure penalty).
    pub distance_term: f64,
    pub rotation_term: f64,
    pub ig: f64,
    pub utility: f64,
    /// Rank among this iteration's candidates (0 = best).
    pub rank: usize,
    /// Cells the visibility check predicted the view to reveal at least
    /// (None without the check).
    pub predicted_cells: Option<u32>,
}

/// The motion of one iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Waypoints `n × dof`, row-major (rad or m).
    pub q: Vec<f64>,
    pub time_from_start: Vec<f64>,
    pub dof: usize,
    /// S0 criteria (CD, JD, OC, CPC; RDM over the link origins).
    pub criteria: Scores,
    /// Some state or motion of the executed trajectory overlaps the true
    /// scene (the planner knew only the octree).
    pub hits_truth: bool,
}

/// Wall time per stage of one iteration, µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StageTimes {
    pub nbv_us: u64,
    /// Planning, goal IK included, over every tried view.
    pub plan_us: u64,
    /// Rendering the depth image.
    pub sense_us: u64,
    /// Inserting the scan into the octree.
    pub insert_us: u64,
    pub total_us: u64,
}

/// One finished iteration (streamed by `on_step`).
#[derive(Debug, Clone, PartialEq)]
pub struct ExploreStep {
    /// 1-based.
    pub iteration: usize,
    /// The view moved to; `None` when every tried view failed.
    pub view: Option<ChosenView>,
    pub motion: Option<Motion>,
    /// Views tried and failed this iteration: position and reason.
    pub failures: Vec<(Point3<f64>, ViewFailure)>,
    /// NBV candidates ranked this iteration.
    pub candidates: usize,
    /// Known share of the observable cells after this iteration's scan.
    pub known_ratio: f64,
    /// Joints at the end of the iteration.
    pub joints: Vec<f64>,
    pub times: StageTimes,
}

/// Sums of the S0 criteria over every executed motion (S0 Tab. 5.3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CriteriaTotals {
    pub jd: f64,
    pub cpc: f64,
    pub cd: f64,
    pub oc: f64,
    pub rdm: f64,
    /// Motions summed.
    pub motions: usize,
}

/// What [`explore`] returns.
#[derive(Debug, Clone)]
pub struct ExploreOutcome {
    pub status: ExploreStatus,
    pub iterations: usize,
    /// Known ratio after the initial scans and at the end.
    pub initial_known_ratio: f64,
    pub known_ratio: f64,
    /// Cells the ratio counts (region cells outside the true obstacles).
    pub observable_cells: usize,
    pub totals: CriteriaTotals,
    /// Views that failed IK or planning, or were reached and added nothing,
    /// over the whole run.
    pub failures: usize,
    /// Executed motions whose scan added no known cell (wasted moves).
    pub wasted_moves: usize,
    /// The last NBV call's largest predicted lower bound over the views it
    /// checked (cells; None without the visibility check): the estimate of
    /// the observable unknown still within the candidates' reach.
    pub best_predicted_cells: Option<u32>,
    /// Executed motions that overlapped the true scene.
    pub truth_hits: usize,
    pub final_joints: Vec<f64>,
    pub tree: Octree,
    /// Scans integrated (initial ones included).
    pub scans: usize,
    pub elapsed_us: u64,
}

fn us(t: Instant) -> u64 {
    t.elapsed().as_micros() as u64
}

/// Cells of the known world the planner may see, at most.
const MAX_PLANNER_CELLS: usize = 2_000_000;

struct Explorer<'a> {
    world: &'a ExploreWorld<'a>,
    params: &'a ExploreParams,
    truth_checker: SceneChecker,
    tree: Octree,
    scans: usize,
    deadline: Deadline<'a>,
}

impl Explorer<'_> {
    fn interrupted(&self) -> Option<ExploreStatus> {
        self.deadline.stop().map(|s| match s {
            Stop::Deadline => ExploreStatus::Timeout,
            Stop::Cancelled => ExploreStatus::Cancelled,
        })
    }

    fn camera_pose(&self, q: &[f64]) -> Isometry3<f64> {
        self.world.chain.fk(q) * self.params.camera_mount
    }

    /// Renders the view at `q` and inserts it; returns (sense µs, insert µs).
    fn scan(&mut self, q: &[f64]) -> Result<(u64, u64), ExploreError> {
        let pose = self.camera_pose(q);
        let t0 = Instant::now();
        let seed = self.params.seed ^ (self.scans as u64).wrapping_mul(0xA24B_AED4_963E_E407);
        let Some(image) = render_depth_until(
            self.world.truth,
            &self.params.camera,
            &pose,
            &self.params.sensor,
            seed,
            self.deadline,
        ) else {
            return Ok((us(t0), 0)); // stopped: nothing inserted
        };
        let sensor = self.params.sensor;
        // with the near field shared the image itself goes in, else its points
        let points = (sensor.near_ray_spacing <= 0.0)
            .then(|| depth_to_points(&image, &self.params.camera, &pose, sensor.pixel_stride));
        let sense = us(t0);
        let t1 = Instant::now();
        // a view rendered in time is inserted whole: only a cancellation stops it
        let deadline = self.deadline.without_instant();
        let stats = match points {
            Some(points) => {
                let o = pose.translation.vector;
                let origin = [o.x as f32, o.y as f32, o.z as f32];
                self.tree
                    .insert_scan(&points, &origin, &ScanParams::default(), deadline)?
            }
            None => {
                let k = strided_intrinsics(&self.params.camera, sensor.pixel_stride);
                let scan = ScanParams {
                    near_ray_spacing: sensor.near_ray_spacing,
                    ..ScanParams::default()
                };
                self.tree.insert_depth_image(
                    &image.depth,
                    image.width,
                    image.height,
                    &k,
                    &pose,
                    &scan,
                    deadline,
                )?
            }
        };
        if stats.status == ScanStatus::Inserted {
            self.scans += 1;
        }
        Ok((sense, us(t1)))
    }

    /// A checker for what the robot knows: the occupied cells in the region.
    fn known_checker(&self) -> Result<SceneChecker, ExploreError> {
        let (min, max) = &self.params.region;
        let obstacles = occupied_obstacles(&self.tree, min, max, MAX_PLANNER_CELLS)?.ok_or_else(|| {
            ExploreError::invalid(
                ExploreField::Resolution,
                "the known world exceeds 2 million cells",
            )
        })?;
        let scene = Scene::new(obstacles, &SceneLimits::default())?;
        let geometry = Arc::new(SceneGeometry::build(&scene)?);
        Ok(SceneChecker::new(
            self.world.model.clone(),
            self.world.acm,
            geometry,
            CheckerParams::default(),
        )?)
    }

    fn motion_hits_truth(&self, q: &[f64], dof: usize) -> bool {
        let check = MotionCheck::Interpolated { resolution: 0.05 };
        let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
        rows.windows(2)
            .any(|w| !interpolate_motion_valid(&self.truth_checker, w[0], w[1], check))
    }
}

/// Scores a trajectory with RDM over the link origins.
fn criteria(chain: &Chain, q: &[f64]) -> Option<Scores> {
    let dof = chain.dof();
    let rows = Rows::Flat {
        values: q,
        width: dof,
    };
    let samples = sample_chain(chain, rows, Some(PointSet::LinkOrigins)).ok()?;
    let mut input = ScoreInput::new(TrajectoryData {
        robot_points: samples.point_rows(),
        ..TrajectoryData::new(
            Rows::Flat {
                values: q,
                width: dof,
            },
            &samples.poses,
        )
    });
    input.dof = Some(dof);
    score(&input, &ScoreParams::default()).ok().map(|r| r.scores)
}

/// Adds one failure at `p` to `record` (matched within `radius`).
fn record_failure(record: &mut Vec<(Point3<f64>, u32)>, p: Point3<f64>, radius: f64) {
    match record.iter_mut().find(|(q, _)| (q - p).norm() <= radius) {
        Some((_, n)) => *n = n.saturating_add(1),
        None => record.push((p, 1)),
    }
}

/// Explores `params.region` with a depth camera on `world.chain`, starting
/// at joints `start` (docs/exploration.md#the-exploration-loop, S0 §4–5):
///
/// 1. Scan at the start and at each of `initial_offsets` (S0's initial
///    motion of the last joints), then return to the start.
/// 2. Per iteration: [`next_best_view`] ranks views (frontier candidates,
///    ORF → PTF → IGF, `f = w_d·D + w_r·R + w_i·Ig`, IK check); the best
///    `candidates_per_iteration` are tried in order: the planner plans from
///    the current joints to the view's tip pose in the world the robot knows
///    (the octree's occupied cells in the region). A view that fails IK or
///    planning is recorded at its position, and NBV lowers its utility by
///    `failure_penalty` per failure afterwards (S0's future work). The first
///    success is executed (the joints become the trajectory's end), scanned
///    and inserted.
/// 3. Stop at `stop.known_ratio` of the observable cells (the region's cells
///    outside the true obstacles), at `stop.max_iterations`, after
///    `stop.max_consecutive_failures` iterations without a motion, when NBV
///    has no candidate, or when `ctl.deadline` passes or is cancelled.
///
/// Every random choice derives from `params.seed`: the same inputs give the
/// same run.
pub fn explore(
    world: &ExploreWorld<'_>,
    start: &[f64],
    params: &ExploreParams,
    ctl: ExploreControl<'_>,
) -> Result<ExploreOutcome, ExploreError> {
    let t_run = Instant::now();
    let chain = world.chain;
    let dof = chain.dof();
    params.validate(dof)?;
    if start.len() != dof || start.iter().any(|v| !v.is_finite()) {
        return Err(ExploreError::invalid(
            ExploreField::Start,
            format!("needs {dof} finite joint values, got {}", start.len()),
        ));
    }
    let truth_checker = SceneChecker::new(
        world.model.clone(),
        world.acm,
        world.truth.clone(),
        CheckerParams::default(),
    )?;
    if !truth_checker.is_valid(start) {
        return Err(ExploreError::invalid(
            ExploreField::Start,
            "the start state collides with the scene or lies outside the joint limits",
        ));
    }
    let tree = Octree::new(params.resolution)?;
    let (min, max) = params.region;
    let observable = ObservableCells::new(&tree, &min, &max, world.truth)?;
    if observable.is_empty() {
        return Err(ExploreError::invalid(
            ExploreField::Region,
            "holds no cell outside the scene's obstacles",
        ));
    }
    let mut ex = Explorer {
        world,
        params,
        truth_checker,
        tree,
        scans: 0,
        deadline: ctl.deadline,
    };
    let mut on_step = ctl.on_step;
    let mut q = start.to_vec();
    ex.scan(&q)?;
    let check = MotionCheck::Interpolated { resolution: 0.05 };
    for offset in &params.initial_offsets {
        if ex.interrupted().is_some() {
            break;
        }
        let target: Vec<f64> = start.iter().zip(offset).map(|(a, b)| a + b).collect();
        if interpolate_motion_valid(&ex.truth_checker, start, &target, check) {
            ex.scan(&target)?;
        }
    }
    let initial_known_ratio = observable.known_ratio(&ex.tree);
    let mut known_ratio = initial_known_ratio;
    let mut totals = CriteriaTotals::default();
    let mut failure_record: Vec<(Point3<f64>, u32)> = Vec::new();
    let (mut failures, mut truth_hits, mut consecutive, mut iterations) = (0usize, 0usize, 0usize, 0usize);
    let mut wasted_moves = 0usize;
    let mut best_predicted_cells = None;
    let status = loop {
        if known_ratio >= params.stop.known_ratio {
            break ExploreStatus::Explored;
        }
        if iterations >= params.stop.max_iterations {
            break ExploreStatus::IterationCap;
        }
        if consecutive >= params.stop.max_consecutive_failures {
            break ExploreStatus::ConsecutiveFailures;
        }
        if let Some(s) = ex.interrupted() {
            break s;
        }
        iterations += 1;
        let t_iter = Instant::now();
        let mut times = StageTimes::default();
        let t0 = Instant::now();
        let ik_check = params.nbv.ik_check.max(params.candidates_per_iteration);
        let nbv_params = NbvParams {
            region: Some(params.region),
            robot_base: Isometry3::identity(),
            camera_mount: params.camera_mount,
            count_failures: true,
            free_viewpoint: true,
            gain_in_region: true,
            extra_candidates: params.extra_views.clone(),
            visibility: params.visibility,
            prior_failures: failure_record.clone(),
            // with the visibility check every returned view is predicted to
            // add cells, but the best predicted ones are often out of reach:
            // NBV returns and IK-checks four times as many, and the loop
            // skips the unreachable ones without spending a try on them
            max_results: match params.visibility {
                Some(_) => 4 * ik_check,
                None => params.candidates_per_iteration,
            },
            ik_check: match params.visibility {
                Some(_) => 4 * ik_check,
                None => ik_check,
            },
            // bounded by the run's deadline (passed below), not a budget of its own
            time_budget: None,
            seed: params.seed.wrapping_add(iterations as u64),
            ..params.nbv.clone()
        };
        let current = ex.camera_pose(&q);
        let ranked = next_best_view(
            &ex.tree,
            &nbv_params,
            &params.camera,
            &current,
            Some(chain),
            ex.deadline,
        )?;
        times.nbv_us = us(t0);
        if params.visibility.is_some() && ranked.stages.visibility_checked > 0 {
            best_predicted_cells = Some(ranked.stages.best_predicted_cells);
        }
        if ranked.candidates.is_empty() {
            iterations -= 1;
            let exhausted = ranked.status == crate::nbv::NbvStatus::Complete
                && ranked.stages.visibility_checked > 0
                && ranked.stages.after_visibility == 0;
            break match ex.interrupted() {
                Some(s) => s,
                None if exhausted => ExploreStatus::ObservableExhausted,
                None => ExploreStatus::NoCandidates,
            };
        }
        let mut step = ExploreStep {
            iteration: iterations,
            view: None,
            motion: None,
            failures: Vec::new(),
            candidates: ranked.candidates.len(),
            known_ratio,
            joints: Vec::new(),
            times,
        };
        let known = ex.known_checker()?;
        let t_plan = Instant::now();
        let mut tries = 0usize;
        for (rank, c) in ranked.candidates.iter().enumerate() {
            if ex.interrupted().is_some() || tries >= params.candidates_per_iteration {
                break;
            }
            let position = Point3::from(c.pose.translation.vector);
            // unchecked views (beyond NBV's ik_check) go to the planner,
            // whose goal IK decides
            if c.reachable == Some(false) {
                step.failures.push((position, ViewFailure::Unreachable));
                record_failure(&mut failure_record, position, params.nbv.position_threshold);
                continue;
            }
            tries += 1;
            match plan_to(&ex, &known, &q, c, iterations, rank)? {
                Ok(motion) => {
                    step.view = Some(ChosenView {
                        pose: c.pose,
                        distance_term: c.distance_term,
                        rotation_term: c.rotation_term,
                        ig: c.ig,
                        utility: c.utility,
                        rank,
                        predicted_cells: c.predicted.map(|p| p.first),
                    });
                    step.motion = Some(motion);
                    break;
                }
                Err(status) => {
                    step.failures.push((position, ViewFailure::Plan(status)));
                    record_failure(&mut failure_record, position, params.nbv.position_threshold);
                }
            }
        }
        step.times.plan_us = us(t_plan);
        failures += step.failures.len();
        if let Some(m) = &step.motion {
            q = m.q[m.q.len() - dof..].to_vec();
            truth_hits += m.hits_truth as usize;
            totals.jd += m.criteria.jd;
            totals.cpc += m.criteria.cpc;
            totals.cd += m.criteria.cd;
            totals.oc += m.criteria.oc;
            totals.rdm += m.criteria.rdm.unwrap_or(0.0);
            totals.motions += 1;
            let (sense, insert) = ex.scan(&q)?;
            step.times.sense_us = sense;
            step.times.insert_us = insert;
            let before = known_ratio;
            known_ratio = observable.known_ratio(&ex.tree);
            if known_ratio <= before
                && let Some(v) = &step.view
            {
                let position = Point3::from(v.pose.translation.vector);
                step.failures.push((position, ViewFailure::NoGain));
                record_failure(&mut failure_record, position, params.nbv.position_threshold);
                failures += 1;
                wasted_moves += 1;
                consecutive += 1;
            } else {
                consecutive = 0;
            }
        } else {
            consecutive += 1;
        }
        step.known_ratio = known_ratio;
        step.joints = q.clone();
        step.times.total_us = us(t_iter);
        if let Some(cb) = on_step.as_deref_mut() {
            cb(&step);
        }
    };
    Ok(ExploreOutcome {
        status,
        iterations,
        initial_known_ratio,
        known_ratio,
        observable_cells: observable.len(),
        totals,
        failures,
        wasted_moves,
        best_predicted_cells,
        truth_hits,
        final_joints: q,
        tree: ex.tree,
        scans: ex.scans,
        elapsed_us: us(t_run),
    })
}

/// Plans from `q` to the tip pose that puts the camera at `c.pose`; the
/// motion on success, the planner's status otherwise.
fn plan_to(
    ex: &Explorer<'_>,
    known: &SceneChecker,
    q: &[f64],
    c: &NbvCandidate,
    iteration: usize,
    rank: usize,
) -> Result<Result<Motion, PlanStatus>, ExploreError> {
    let params = ex.params;
    let chain = ex.world.chain;
    let dof = chain.dof();
    let mut req = params.plan.clone();
    req.start = q.to_vec();
    req.goal = Goal::Pose(c.pose * params.camera_mount.inverse());
    req.seed = params
        .seed
        .wrapping_mul(1_000_003)
        .wrapping_add((iteration * 131 + rank) as u64);
    let r = plan(
        chain,
        known,
        &req,
        PlanControl {
            deadline: ex.deadline.min_with_budget(Some(params.plan_time_budget)),
            progress: None,
        },
    )?;
    if r.status != PlanStatus::Succeeded || r.q.len() < 2 * dof {
        return Ok(Err(r.status));
    }
    let Some(criteria) = criteria(chain, &r.q) else {
        return Ok(Err(PlanStatus::NoValidTrajectory));
    };
    let hits_truth = ex.motion_hits_truth(&r.q, dof);
    Ok(Ok(Motion {
        time_from_start: r.time_from_start,
        dof,
        criteria,
        hits_truth,
        q: r.q,
    }))
}
