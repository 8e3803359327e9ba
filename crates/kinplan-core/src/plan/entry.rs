//! [`plan`]: the one entry point — validation, goal IK, the chosen planner,
//! an independent re-check, time parameterisation and the S0 criteria.

use std::time::Instant;

use nalgebra::Isometry3;

use super::cartesian::{CartesianLine, Deviation, deviation, violates};
use super::clock::{Clock, Interrupt};
use super::costs::{path_valid, resolution_of};
use super::error::{PlanError, PlanField, check_vector, require};
use super::initial::initial_trajectory;
use super::rrt_connect::{RrtStop, rrt_connect_path};
use super::stomp::{IterationReport, StompStop, stomp_optimize};
use super::timing::{TimedTrajectory, TimingMethod, TimingParams, retime, time_parameterize};
use super::{CartesianParams, RrtParams, StompParams};
use crate::Deadline;
use crate::collision::StateChecker;
use crate::ik::{IkParams, IkTarget, solve_ik};
use crate::robot::Chain;
use crate::score::{Rows, ScoreInput, ScoreParams, Scores, TrajectoryData, score};

/// Mixed into the seed of CCSTOMP's second pass, so that its rollouts
/// differ from the first pass's.
const RESTART_SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// CCSTOMP's second pass, when the first ends without a valid trajectory:
/// S0's noise generator at a tenth of the translation and half the rotation
/// standard deviation (m, rad). S0's σ = 0.5 m suits its 2.7 m arm and a
/// 1 m tube; near an obstacle or on a smaller arm most such samples leave
/// the tube or collide, and the update learns nothing from them.
fn finer_noise(c: &CartesianParams) -> CartesianParams {
    CartesianParams {
        translation_stddev: c.translation_stddev * 0.1,
        rotation_stddev: c.rotation_stddev * 0.5,
        ..*c
    }
}

/// Which planner [`plan`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Algorithm {
    /// STOMP with joint-space noise (docs/planning.md#stomp).
    #[default]
    Stomp,
    /// STOMP with S0's Cartesian noise generator and Cartesian distance cost.
    Ccstomp,
    /// RRT-Connect with shortcutting.
    RrtConnect,
}

/// Where the robot should end.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// A joint state (rad or m, chain order).
    Joints(Vec<f64>),
    /// A tool pose in the base frame (m); solved by IK inside [`plan`].
    Pose(Isometry3<f64>),
}

/// A planning request.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRequest {
    /// Start joints (rad or m).
    pub start: Vec<f64>,
    pub goal: Goal,
    pub algorithm: Algorithm,
    pub stomp: StompParams,
    /// CCSTOMP's extensions; also the tolerances deviations are judged by.
    pub cartesian: CartesianParams,
    pub rrt: RrtParams,
    pub timing: TimingParams,
    /// IK for a pose goal (solutions sought: `num_solutions`). Default:
    /// [`IkParams::default`] with 8 solutions and 50 restarts.
    pub goal_ik: IkParams,
    /// Seeds every random choice: the same request gives the same answer.
    pub seed: u64,
}

impl Default for PlanRequest {
    fn default() -> Self {
        Self {
            start: Vec::new(),
            goal: Goal::Joints(Vec::new()),
            algorithm: Algorithm::default(),
            stomp: StompParams::default(),
            cartesian: CartesianParams::default(),
            rrt: RrtParams::default(),
            timing: TimingParams::default(),
            goal_ik: IkParams {
                num_solutions: 8,
                max_restarts: 50,
                ..IkParams::default()
            },
            seed: 0,
        }
    }
}

/// How a request ended. Statuses, not errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanStatus {
    /// A valid trajectory (collision-free; CCSTOMP: within the tolerances).
    Succeeded,
    /// The planner finished without a valid trajectory (the best is returned).
    NoValidTrajectory,
    /// The start state is in collision or outside the limits.
    InvalidStart,
    /// The goal state is in collision or outside the limits (for a pose:
    /// every IK solution is).
    InvalidGoal,
    /// IK found no joint state for the goal pose.
    GoalUnreachable,
    /// The deadline passed first (the best trajectory so far is returned).
    Timeout,
    /// The caller's cancellation was raised (the best trajectory so far is
    /// returned).
    Cancelled,
}

/// Wall time per phase, µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Timings {
    pub goal_ik_us: u64,
    /// RRT-Connect (as planner or as STOMP's initial trajectory).
    pub rrt_us: u64,
    pub stomp_us: u64,
    /// Re-check of the result, every state and motion.
    pub verify_us: u64,
    pub total_us: u64,
}

/// What [`plan`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanResult {
    pub status: PlanStatus,
    /// Waypoints, `n × dof` row-major (empty for invalid start/goal).
    pub q: Vec<f64>,
    /// Time of each waypoint from the start (s) by the waypoint method
    /// ([`time_parameterize`]), within the velocity and acceleration limits
    /// of [`TimingParams`], whatever `timing.method` is.
    pub time_from_start: Vec<f64>,
    /// The trajectory to execute, timed by `timing.method`: for the waypoint
    /// method one sample per waypoint, otherwise samples every
    /// `sample_period` along the path blended at the waypoints (circular
    /// arcs for the time-optimal method, blends in time for the jerk-limited
    /// one). Empty without waypoints, or when the deadline
    /// or a cancellation cut the timing short.
    pub trajectory: TimedTrajectory,
    pub dof: usize,
    /// Every state and motion valid per the checker (re-checked here) and,
    /// for CCSTOMP, every waypoint within the Cartesian tolerances: true
    /// exactly when the status is `Succeeded`.
    pub valid: bool,
    /// Some waypoint lies beyond t_t or t_r of the straight Cartesian line.
    pub violates_tolerance: bool,
    /// STOMP's total cost before the first iteration and after each one
    /// (empty for RRT-Connect).
    pub cost_history: Vec<f64>,
    /// Per-waypoint deviation from the straight Cartesian line (waypoint i
    /// against the line at i/(n−1)), for every algorithm.
    pub deviation: Vec<Deviation>,
    /// The S0 criteria of the result; `None` without waypoints.
    pub criteria: Option<Scores>,
    /// The goal joints used (the chosen IK solution for a pose goal).
    pub goal: Option<Vec<f64>>,
    /// STOMP iterations run.
    pub iterations: usize,
    pub timings: Timings,
}

/// The caller's side channel: the request's [`Deadline`] (instant and
/// cancellation, checked by every planner loop, the goal IK included) and
/// per-iteration progress (STOMP/CCSTOMP call it once per iteration, from
/// the calling thread).
#[derive(Default)]
pub struct PlanControl<'a> {
    pub deadline: Deadline<'a>,
    pub progress: Option<&'a mut dyn FnMut(&IterationReport<'_>)>,
}

fn validate(chain: &Chain, checker_dof: usize, req: &PlanRequest) -> Result<(), PlanError> {
    let dof = chain.dof();
    if dof == 0 {
        return Err(PlanError::EmptyChain);
    }
    if checker_dof != dof {
        return Err(PlanError::CheckerDof {
            chain: dof,
            checker: checker_dof,
        });
    }
    check_vector(PlanField::Start, &req.start, dof)?;
    match &req.goal {
        Goal::Joints(g) => check_vector(PlanField::GoalJoints, g, dof)?,
        Goal::Pose(p) => {
            IkTarget::Pose(*p).validate().map_err(|_| PlanError::NonFinite {
                field: PlanField::GoalPose,
                index: 0,
            })?;
            req.goal_ik.validate()?;
        }
    }
    req.stomp.validate(dof)?;
    req.cartesian.validate()?;
    req.rrt.validate()?;
    req.timing.validate(dof)?;
    // a start velocity must point along the path's first segment, which a
    // client cannot know before the plan: only Retime takes one
    let moving = req
        .timing
        .start_velocity
        .as_deref()
        .and_then(|v| v.iter().copied().find(|x| *x != 0.0));
    match moving {
        Some(v) => require(
            false,
            PlanField::StartVelocity,
            v,
            "a plan starts at rest; time a path from a moving start with Retime",
        ),
        None => Ok(()),
    }
}

/// Plans a trajectory for `chain` from `req.start` to `req.goal` in the world
/// of `checker` (docs/planning.md).
///
/// 1. Invalid parameters → `Err`; everything else is a [`PlanStatus`].
/// 2. Start (and a joint goal) checked with `checker.is_valid`. A pose goal is
///    solved by IK (`goal_ik.num_solutions` distinct solutions seeded at the
///    start); the valid one nearest the start (Euclidean) is used.
/// 3. RRT-Connect: the path, shortcut. STOMP/CCSTOMP: the initial trajectory
///    chosen by [`InitialTrajectory`](super::InitialTrajectory) (straight
///    joint line; Cartesian line by IK; RRT-Connect when the line is blocked)
///    optimised by STOMP.
/// 4. The result is re-checked state by state and motion by motion at the
///    checker's resolution (skipped after an interruption), timed by
///    [`retime`] with `timing.method` (a time-optimal or jerk-limited
///    trajectory, whose blends leave the checked polyline, is checked again
///    sample to sample)
///    and scored on the timed points (S0 criteria, unit joint weights, jerk
///    on the real time axis).
///
/// ```
/// use kinplan_core::collision::StateChecker;
/// use kinplan_core::plan::{plan, Goal, PlanControl, PlanRequest, PlanStatus};
/// struct Free;
/// impl StateChecker for Free {
///     fn dof(&self) -> usize { 2 }
///     fn is_valid(&self, q: &[f64]) -> bool { q.iter().all(|v| v.abs() <= 3.0) }
///     fn clearance(&self, _: &[f64], d: f64) -> f64 { d }
/// }
/// let chain = kinplan_core::robot::builtin_chain("planar_2").unwrap();
/// let req = PlanRequest { start: vec![0.0, 0.0], goal: Goal::Joints(vec![1.0, -0.5]), ..Default::default() };
/// let r = plan(&chain, &Free, &req, PlanControl::default()).unwrap();
/// assert_eq!(r.status, PlanStatus::Succeeded);
/// assert_eq!(&r.q[..2], &[0.0, 0.0]);
/// assert!(r.time_from_start.windows(2).all(|w| w[1] > w[0]));
/// ```
pub fn plan<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    req: &PlanRequest,
    ctl: PlanControl<'_>,
) -> Result<PlanResult, PlanError> {
    validate(chain, checker.dof(), req)?;
    let clock = Clock {
        start: Instant::now(),
        deadline: ctl.deadline,
    };
    let mut noop = |_: &IterationReport<'_>| {};
    let progress: &mut dyn FnMut(&IterationReport<'_>) = match ctl.progress {
        Some(p) => p,
        None => &mut noop,
    };
    let dof = chain.dof();
    let mut timings = Timings::default();
    let mut result = PlanResult {
        status: PlanStatus::NoValidTrajectory,
        q: Vec::new(),
        time_from_start: Vec::new(),
        trajectory: TimedTrajectory::default(),
        dof,
        valid: false,
        violates_tolerance: false,
        cost_history: Vec::new(),
        deviation: Vec::new(),
        criteria: None,
        goal: None,
        iterations: 0,
        timings,
    };
    let finish = |mut r: PlanResult, mut timings: Timings| {
        timings.total_us = clock.elapsed_us();
        r.timings = timings;
        Ok(r)
    };
    let start = &req.start;
    if !checker.is_valid(start) {
        result.status = PlanStatus::InvalidStart;
        return finish(result, timings);
    }
    let goal = match &req.goal {
        Goal::Joints(g) => {
            if !checker.is_valid(g) {
                result.status = PlanStatus::InvalidGoal;
                return finish(result, timings);
            }
            g.clone()
        }
        Goal::Pose(p) => {
            let t0 = Instant::now();
            let ik = solve_ik(
                chain,
                &IkTarget::Pose(*p),
                Some(start),
                &req.goal_ik,
                req.seed,
                clock.deadline,
            )?;
            timings.goal_ik_us = t0.elapsed().as_micros() as u64;
            // solutions come nearest the seed (the start) first
            match ik.solutions.iter().find(|s| checker.is_valid(&s.joints)) {
                Some(s) => s.joints.clone(),
                None => {
                    result.status = match clock.interrupted() {
                        Some(Interrupt::Deadline) => PlanStatus::Timeout,
                        Some(Interrupt::Cancelled) => PlanStatus::Cancelled,
                        None if ik.success() => PlanStatus::InvalidGoal,
                        None => PlanStatus::GoalUnreachable,
                    };
                    return finish(result, timings);
                }
            }
        }
    };
    result.goal = Some(goal.clone());
    let mut interrupted: Option<Interrupt> = None;
    // a verdict that stands without the re-check below: the planner's after
    // an interruption, or a path every edge of which the padded check proved
    let mut settled_valid: Option<bool> = None;
    let mut planner_valid = false;
    match req.algorithm {
        Algorithm::RrtConnect => {
            let t0 = Instant::now();
            let out = rrt_connect_path(chain, checker, start, &goal, &req.rrt, req.seed, &clock);
            timings.rrt_us = t0.elapsed().as_micros() as u64;
            match out.stop {
                RrtStop::Connected => {
                    result.q = out.path;
                    planner_valid = true;
                    // every edge was proved by the padded check, or lies on
                    // an edge that was (a shortcut keeps pieces of proved
                    // edges); proving a piece again could only refuse more
                    if checker.motion_check().is_padded() {
                        settled_valid = Some(true);
                    }
                }
                RrtStop::SampleBudget => {}
                RrtStop::Deadline => interrupted = Some(Interrupt::Deadline),
                RrtStop::Cancelled => interrupted = Some(Interrupt::Cancelled),
            }
        }
        Algorithm::Stomp | Algorithm::Ccstomp => {
            let n = req.stomp.timesteps;
            let (initial, rrt_us) = initial_trajectory(
                chain,
                checker,
                start,
                &goal,
                n,
                req.stomp.initial.for_algorithm(req.algorithm),
                (req.algorithm == Algorithm::Ccstomp).then_some(&req.cartesian),
                &req.rrt,
                req.seed,
                &clock,
            );
            timings.rrt_us = rrt_us;
            let t0 = Instant::now();
            let cart = (req.algorithm == Algorithm::Ccstomp).then_some(&req.cartesian);
            let mut out = stomp_optimize(
                chain, checker, &req.stomp, cart, &initial, req.seed, &clock, progress,
            );
            if let Some(c) = cart
                && !out.valid
                && out.stop == StompStop::MaxIterations
            {
                // CCSTOMP's restart: a second pass from the best trajectory
                // with finer Cartesian noise (docs/planning.md#ccstomp)
                let finer = finer_noise(c);
                let offset = out.iterations;
                let mut shifted = |r: &IterationReport<'_>| {
                    progress(&IterationReport {
                        iteration: r.iteration + offset,
                        ..*r
                    })
                };
                let seed = req.seed ^ RESTART_SEED;
                let again = stomp_optimize(
                    chain,
                    checker,
                    &req.stomp,
                    Some(&finer),
                    &out.trajectory,
                    seed,
                    &clock,
                    &mut shifted,
                );
                out.cost_history
                    .extend_from_slice(again.cost_history.get(1..).unwrap_or(&[]));
                out.iterations += again.iterations;
                out.trajectory = again.trajectory;
                out.valid = again.valid;
                out.stop = again.stop;
            }
            timings.stomp_us = t0.elapsed().as_micros() as u64;
            if matches!(out.stop, StompStop::Deadline | StompStop::Cancelled) {
                settled_valid = Some(out.valid);
            }
            interrupted = match out.stop {
                StompStop::Deadline if !out.valid => Some(Interrupt::Deadline),
                StompStop::Cancelled if !out.valid => Some(Interrupt::Cancelled),
                _ => None,
            };
            planner_valid = out.valid;
            result.q = out.trajectory;
            result.cost_history = out.cost_history;
            result.iterations = out.iterations;
        }
    }
    let n = result.q.len() / dof;
    let t0 = Instant::now();
    // The re-check costs about one trajectory evaluation; after an
    // interruption (before or during it), or for a path the padded check
    // proved edge by edge, the planner's own verdict stands.
    result.valid = n >= 2
        && match settled_valid {
            Some(v) => v,
            None => {
                path_valid(checker, &result.q, dof, resolution_of(checker), &clock).unwrap_or(planner_valid)
            }
        };
    timings.verify_us = t0.elapsed().as_micros() as u64;
    if n >= 1 {
        let line = CartesianLine::between(chain, start, &goal);
        result.deviation = result
            .q
            .chunks_exact(dof)
            .enumerate()
            .map(|(i, q)| deviation(&line.pose_at_waypoint(i, n), &chain.fk(q)))
            .collect();
        result.violates_tolerance = result.deviation.iter().any(|d| violates(d, &req.cartesian));
        let v = req.timing.velocities(chain);
        match retime(&result.q, dof, &v, &req.timing, clock.deadline) {
            Ok(t) => {
                // the waypoint method's samples are the waypoints at these
                // very times: computed once
                result.time_from_start = if req.timing.method == TimingMethod::Waypoint {
                    t.t.clone()
                } else {
                    time_parameterize(&result.q, dof, &v, req.timing.acceleration_limits.as_deref())
                };
                // the blends cut the corners the re-check above proved: the
                // timed trajectory itself is checked, sample to sample
                if req.timing.method != TimingMethod::Waypoint && result.valid {
                    let t0 = Instant::now();
                    result.valid =
                        path_valid(checker, &t.q, dof, resolution_of(checker), &clock) == Some(true);
                    timings.verify_us += t0.elapsed().as_micros() as u64;
                }
                result.trajectory = t;
            }
            Err(PlanError::Interrupted) => {
                result.time_from_start =
                    time_parameterize(&result.q, dof, &v, req.timing.acceleration_limits.as_deref());
                // no executable timed trajectory: reported as the interruption
                result.valid = false;
                interrupted = clock.interrupted().or(Some(Interrupt::Deadline));
            }
            Err(e) => return Err(e),
        }
        let traj = &result.trajectory;
        let poses: Vec<Isometry3<f64>> = traj.q.chunks_exact(dof).map(|q| chain.fk(q)).collect();
        let mut data = TrajectoryData::new(
            Rows::Flat {
                values: &traj.q,
                width: dof,
            },
            &poses,
        );
        data.timestamps = Some(&traj.t);
        let mut input = ScoreInput::new(data);
        input.dof = Some(dof);
        result.criteria = score(&input, &ScoreParams::default()).ok().map(|r| r.scores);
    }
    let ok = result.valid && !(req.algorithm == Algorithm::Ccstomp && result.violates_tolerance);
    // `valid` is what a client may execute: for CCSTOMP a collision-free
    // trajectory outside its tolerances is not (`violates_tolerance` says why).
    result.valid = ok;
    result.status = match (ok, interrupted) {
        (true, _) => PlanStatus::Succeeded,
        (false, Some(Interrupt::Deadline)) => PlanStatus::Timeout,
        (false, Some(Interrupt::Cancelled)) => PlanStatus::Cancelled,
        (false, None) => PlanStatus::NoValidTrajectory,
    };
    finish(result, timings)
}
