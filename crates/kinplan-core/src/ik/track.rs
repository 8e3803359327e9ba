//! Many targets at once (rayon) and Cartesian path tracking, warm-started step to step.

use std::time::Instant;

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use rayon::prelude::*;

use super::attempt::Clock;
use super::solve::validate_request;
use super::{IkError, IkParams, IkResult, IkSolver, IkStatus, IkTarget, PathParam};
use crate::robot::Chain;
use crate::{Deadline, Stop};

/// Per-target RNG seed of a batch: a SplitMix64 step of `rng_seed + index`.
fn batch_seed(rng_seed: u64, index: usize) -> u64 {
    let mut z = rng_seed.wrapping_add((index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Where the targets of a batch start from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BatchSeeds<'a> {
    /// The middle of the joint limits (and random restarts).
    None,
    /// One seed (`dof` values) for every target.
    Shared(&'a [f64]),
    /// Target `i` starts from `seeds[i·dof .. (i+1)·dof]`; the length must be
    /// `targets.len() · dof` (else every target answers `WrongSeedLength`).
    PerTarget(&'a [f64]),
}

impl<'a> BatchSeeds<'a> {
    /// `None` / `Shared` from an optional single seed.
    pub fn shared(seed: Option<&'a [f64]>) -> Self {
        seed.map_or(BatchSeeds::None, BatchSeeds::Shared)
    }
}

/// Solves every target independently and in parallel (rayon, one workspace per worker),
/// each from its seed (see [`BatchSeeds`]) with its own deterministic RNG seed, so the
/// answers do not depend on the thread count. `params.time_budget` applies to each
/// target; `deadline` to all.
pub fn solve_ik_batch(
    chain: &Chain,
    targets: &[IkTarget],
    seeds: BatchSeeds<'_>,
    params: &IkParams,
    rng_seed: u64,
    deadline: Deadline<'_>,
) -> Vec<Result<IkResult, IkError>> {
    let dof = chain.dof();
    if let BatchSeeds::PerTarget(all) = seeds
        && all.len() != targets.len() * dof
    {
        return targets
            .iter()
            .map(|_| {
                Err(IkError::WrongSeedLength {
                    expected: targets.len() * dof,
                    got: all.len(),
                })
            })
            .collect();
    }
    let seed_of = |i: usize| match seeds {
        BatchSeeds::None => None,
        BatchSeeds::Shared(s) => Some(s),
        BatchSeeds::PerTarget(all) => Some(&all[i * dof..(i + 1) * dof]),
    };
    targets
        .par_iter()
        .enumerate()
        .map_init(
            || IkSolver::new(chain),
            |solver, (i, t)| {
                // Once stopped, the remaining targets are answered at once
                // (TIME_BUDGET at the deadline, CANCELLED on cancellation, no
                // attempt) instead of each starting a solve.
                if let Some(stop) = deadline.stop() {
                    return Ok(IkResult {
                        solutions: Vec::new(),
                        best_attempt: None,
                        stop_reason: match stop {
                            Stop::Deadline => IkStatus::TimeBudget,
                            Stop::Cancelled => IkStatus::Cancelled,
                        },
                        attempts: 0,
                        total_iterations: 0,
                        elapsed_us: 0,
                    });
                }
                solver.solve(t, seed_of(i), params, batch_seed(rng_seed, i), deadline)
            },
        )
        .collect()
}

/// Options of [`track_path`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackParams {
    /// IK options of every step. Default: [`IkParams::default`] with no restarts
    /// (`max_restarts = 0`), so each step stays on the branch of the previous one.
    pub ik: IkParams,
    /// Stop the whole path at the first step that does not converge. Default false.
    pub stop_on_failure: bool,
}

impl Default for TrackParams {
    fn default() -> Self {
        Self {
            ik: IkParams {
                max_restarts: 0,
                ..IkParams::default()
            },
            stop_on_failure: false,
        }
    }
}

impl TrackParams {
    /// Validates the per-step IK options (see [`IkParams::validate`]).
    pub fn validate(&self) -> Result<(), IkError> {
        self.ik.validate()
    }
}

/// One step of a tracked path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathStep {
    /// Joints (the best attempt when the step did not converge).
    pub joints: Vec<f64>,
    /// m
    pub position_error: f64,
    /// rad
    pub orientation_error: f64,
    pub iterations: usize,
    /// Time of this step (µs).
    pub elapsed_us: u64,
    pub status: IkStatus,
    /// `max_i |q_i − q_i(previous step)|` (rad or m) — joint-space continuity (S2 Fig. 15–16).
    pub max_joint_step: f64,
}

/// A tracked path.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackResult {
    pub steps: Vec<PathStep>,
    /// Every step converged.
    pub all_converged: bool,
    /// Largest joint step over the path (rad or m).
    pub max_joint_step: f64,
    /// Whole path (µs).
    pub elapsed_us: u64,
    /// `Converged` when the whole path was solved, otherwise why it stopped early
    /// (`TimeBudget`, `Cancelled`, or `MaxIterations`/`Stalled` with `stop_on_failure`).
    pub stop_reason: IkStatus,
}

/// Tracks a Cartesian path: step `k` is solved from the joints of step `k − 1` (the
/// first from `seed`), with the same IK options each step (docs/inverse-kinematics.md#path-tracking,
/// S2 §3.2 Tab. 5/6). `params.ik.time_budget` bounds the whole path, as does `deadline`
/// (whichever comes first); both are checked every iteration.
///
/// ```
/// use kinplan_core::Deadline;
/// use kinplan_core::ik::{circle_path, track_path, IkTarget, TrackParams};
/// use nalgebra::{Point3, Vector3};
/// let chain = kinplan_core::robot::builtin_chain("planar_4").unwrap();
/// let q0 = [0.3, 0.4, 0.5, 0.2];
/// let start = chain.fk(&q0);
/// let centre = Point3::from(start.translation.vector - Vector3::new(0.1, 0.0, 0.0));
/// let path = circle_path(&start, &centre, &Vector3::z(), std::f64::consts::PI / 50.0, 100).unwrap();
/// let targets: Vec<_> = path.iter().map(|p| IkTarget::Position(Point3::from(p.translation.vector))).collect();
/// let r = track_path(&chain, &targets, &q0, &TrackParams::default(), 1, Deadline::none()).unwrap();
/// assert!(r.all_converged && r.max_joint_step < 0.5);
/// ```
pub fn track_path(
    chain: &Chain,
    targets: &[IkTarget],
    seed: &[f64],
    params: &TrackParams,
    rng_seed: u64,
    deadline: Deadline<'_>,
) -> Result<TrackResult, IkError> {
    params.validate()?;
    if targets.is_empty() {
        return Err(IkError::EmptyPath);
    }
    for t in targets {
        validate_request(chain, t, Some(seed), &params.ik)?;
    }
    let start = Instant::now();
    let clock = Clock {
        start,
        deadline: deadline.min_with_budget(params.ik.time_budget),
    };
    let mut solver = IkSolver::new(chain);
    let mut prev = seed.to_vec();
    let mut steps = Vec::with_capacity(targets.len());
    let mut stop_reason = IkStatus::Converged;
    let mut max_step: f64 = 0.0;
    for (k, t) in targets.iter().enumerate() {
        let step_start = Instant::now();
        let r = solver.solve_validated(
            t,
            Some(&prev),
            &params.ik,
            rng_seed.wrapping_add(k as u64),
            &clock,
        );
        let s = match r.best() {
            Some(s) => s.clone(),
            None => break,
        };
        let jump = s
            .joints
            .iter()
            .zip(&prev)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        max_step = max_step.max(jump);
        prev.copy_from_slice(&s.joints);
        let status = if r.success() {
            IkStatus::Converged
        } else {
            s.status
        };
        steps.push(PathStep {
            joints: s.joints,
            position_error: s.position_error,
            orientation_error: s.orientation_error,
            iterations: s.iterations,
            elapsed_us: step_start.elapsed().as_micros() as u64,
            status,
            max_joint_step: jump,
        });
        if matches!(status, IkStatus::TimeBudget | IkStatus::Cancelled) {
            stop_reason = status;
            break;
        }
        if status != IkStatus::Converged && params.stop_on_failure {
            stop_reason = status;
            break;
        }
    }
    let all_converged = steps.len() == targets.len() && steps.iter().all(|s| s.status == IkStatus::Converged);
    if !all_converged && stop_reason == IkStatus::Converged {
        stop_reason = IkStatus::MaxIterations;
    }
    Ok(TrackResult {
        steps,
        all_converged,
        max_joint_step: max_step,
        elapsed_us: start.elapsed().as_micros() as u64,
        stop_reason,
    })
}

fn check_steps(steps: usize) -> Result<(), IkError> {
    if steps == 0 {
        return Err(IkError::InvalidPath {
            field: PathParam::Steps,
            reason: "must be >= 1",
        });
    }
    Ok(())
}

/// `steps + 1` poses from `start` to `end`: position interpolated linearly, orientation
/// by slerp (m, base frame).
pub fn line_path(
    start: &Isometry3<f64>,
    end: &Isometry3<f64>,
    steps: usize,
) -> Result<Vec<Isometry3<f64>>, IkError> {
    check_steps(steps)?;
    for p in [start, end] {
        IkTarget::Pose(*p).validate()?;
    }
    Ok((0..=steps)
        .map(|k| {
            let s = k as f64 / steps as f64;
            let p = start.translation.vector.lerp(&end.translation.vector, s);
            let r = start
                .rotation
                .try_slerp(&end.rotation, s, 1e-9)
                .unwrap_or(start.rotation);
            Isometry3::from_parts(Translation3::from(p), r)
        })
        .collect())
}

/// `steps + 1` poses on the circle through `start`'s position about the axis
/// (`centre`, `normal`), turning by `angle_step` (rad) each step; the orientation stays
/// that of `start` (S2 Fig. 12/13: circles with steps π/50 and π/100).
pub fn circle_path(
    start: &Isometry3<f64>,
    centre: &Point3<f64>,
    normal: &Vector3<f64>,
    angle_step: f64,
    steps: usize,
) -> Result<Vec<Isometry3<f64>>, IkError> {
    check_steps(steps)?;
    if !angle_step.is_finite() {
        return Err(IkError::InvalidPath {
            field: PathParam::AngleStep,
            reason: "must be finite",
        });
    }
    IkTarget::Pose(*start).validate()?;
    for (field, v) in [(PathParam::Centre, &centre.coords), (PathParam::Normal, normal)] {
        if v.iter().any(|v| !v.is_finite()) {
            return Err(IkError::InvalidPath {
                field,
                reason: "must be finite",
            });
        }
    }
    let axis = Unit::try_new(*normal, 1e-12).ok_or(IkError::InvalidPath {
        field: PathParam::Normal,
        reason: "must be non-zero",
    })?;
    let r0 = start.translation.vector - centre.coords;
    Ok((0..=steps)
        .map(|k| {
            let rot = UnitQuaternion::from_axis_angle(&axis, angle_step * k as f64);
            Isometry3::from_parts(Translation3::from(centre.coords + rot * r0), start.rotation)
        })
        .collect())
}
