//! The `solve_ik` front: validation, seeded random restarts, distinct solutions,
//! time budget and cancellation around the per-attempt algorithms.

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::analytic::analyse;
use super::attempt::{Attempt, Clock};
use super::workspace::IkWorkspace;
use super::{IkError, IkMethod, IkParams, IkTarget};
use crate::Deadline;
use crate::robot::{Chain, JointKind};

/// How an attempt (or the whole request) ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IkStatus {
    /// Within both tolerances.
    Converged,
    /// The per-attempt iteration cap (or, for the request, every restart) was used up.
    MaxIterations,
    /// The error stopped decreasing (the attempt was abandoned for a restart).
    Stalled,
    /// The time budget ran out.
    TimeBudget,
    /// The caller's cancellation closure returned true.
    Cancelled,
}

/// One IK answer.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// Joint values (rad or m), chain order.
    pub joints: Vec<f64>,
    /// `‖p* − p‖` of `fk(joints)` (m).
    pub position_error: f64,
    /// Rotation angle of `R* Rᵀ` (rad); 0 for position targets.
    pub orientation_error: f64,
    /// Iterations of the attempt that produced it.
    pub iterations: usize,
    /// Time from the start of the request until this attempt ended (µs).
    pub elapsed_us: u64,
    /// How its attempt ended.
    pub status: IkStatus,
    /// 0 = from the seed, k = k-th random restart.
    pub attempt: usize,
    /// With [`IkParams::record_history`]: `(position error m, orientation error rad)` at
    /// the start of every iteration of the attempt, ending with the error returned;
    /// empty otherwise.
    pub history: Vec<(f64, f64)>,
    /// Analytic method: the solution's configuration flags; `None` otherwise.
    pub config: Option<super::analytic::ConfigFlags>,
    /// Analytic method: a singular pose, where a joint was free and took the
    /// seed's value (the solutions form a continuous family); false otherwise.
    pub singular: bool,
}

/// Everything a request produced.
#[derive(Debug, Clone, PartialEq)]
pub struct IkResult {
    /// Distinct converged solutions, nearest to the seed first (≤ `num_solutions`).
    pub solutions: Vec<IkSolution>,
    /// When nothing converged: the attempt with the lowest error, **not a solution**.
    pub best_attempt: Option<IkSolution>,
    /// Why the search stopped: `Converged` when `num_solutions` were found, otherwise
    /// `MaxIterations` (restarts exhausted), `TimeBudget` or `Cancelled`.
    pub stop_reason: IkStatus,
    /// Attempts run (1 + restarts used).
    pub attempts: usize,
    /// Iterations summed over all attempts.
    pub total_iterations: usize,
    /// Wall time of the request (µs).
    pub elapsed_us: u64,
}

impl IkResult {
    /// True when at least one converged solution was found.
    pub fn success(&self) -> bool {
        !self.solutions.is_empty()
    }
    /// First solution, or the flagged best attempt.
    pub fn best(&self) -> Option<&IkSolution> {
        self.solutions.first().or(self.best_attempt.as_ref())
    }
}

/// Validates a request shared by every front.
pub(crate) fn validate_request(
    chain: &Chain,
    target: &IkTarget,
    seed: Option<&[f64]>,
    params: &IkParams,
) -> Result<(), IkError> {
    if chain.dof() == 0 {
        return Err(IkError::EmptyChain);
    }
    params.validate()?;
    target.validate()?;
    if let Some(s) = seed {
        if s.len() != chain.dof() {
            return Err(IkError::WrongSeedLength {
                expected: chain.dof(),
                got: s.len(),
            });
        }
        if let Some(index) = s.iter().position(|v| !v.is_finite()) {
            return Err(IkError::NonFiniteSeed { index });
        }
    }
    match params.method {
        IkMethod::Fabrik | IkMethod::LengthRelaxation => {
            super::point_chain::check_servable(chain, target, params.method)?
        }
        IkMethod::Analytic => {
            if matches!(target, IkTarget::Position(_)) {
                return Err(IkError::MethodCannotServe {
                    method: params.method,
                    reason: "it needs a full pose target (position and orientation)".into(),
                });
            }
            analyse(chain, &params.analytic, seed).map_err(|e| IkError::MethodCannotServe {
                method: params.method,
                reason: e.to_string(),
            })?;
        }
        _ => {}
    }
    Ok(())
}

/// Uniform sample inside the limits (unlimited — or astronomically wide — revolute
/// joints: [−π, π]; prismatic: [−1, 1] m).
pub(crate) fn random_in_limits(chain: &Chain, rng: &mut ChaCha8Rng, out: &mut [f64]) {
    for (v, j) in out.iter_mut().zip(chain.joints()) {
        let (lo, hi) = if j.lower.is_finite() && j.upper.is_finite() && (j.upper - j.lower).is_finite() {
            (j.lower, j.upper)
        } else if j.kind == JointKind::Prismatic {
            (-1.0, 1.0)
        } else {
            (-std::f64::consts::PI, std::f64::consts::PI)
        };
        *v = if hi > lo { rng.random_range(lo..=hi) } else { lo };
    }
}

/// A reusable IK solver for one chain: owns the workspace so repeated requests
/// (batches, path steps, streams) do not allocate in their iterations.
#[derive(Debug, Clone)]
pub struct IkSolver<'c> {
    chain: &'c Chain,
    ws: IkWorkspace,
}

impl<'c> IkSolver<'c> {
    pub fn new(chain: &'c Chain) -> Self {
        Self {
            chain,
            ws: IkWorkspace::new(chain),
        }
    }

    /// A solver reusing `workspace` (from [`into_workspace`](Self::into_workspace) of an
    /// earlier solver), so a long-lived caller — a `StreamIk` session — allocates its
    /// buffers once. A workspace sized for another chain is replaced.
    pub fn with_workspace(chain: &'c Chain, workspace: IkWorkspace) -> Self {
        let fits = workspace.q.len() == chain.dof() && workspace.limits.iter().copied().eq(chain.limits());
        Self {
            chain,
            ws: if fits { workspace } else { IkWorkspace::new(chain) },
        }
    }

    /// Gives the buffers back for [`with_workspace`](Self::with_workspace).
    pub fn into_workspace(self) -> IkWorkspace {
        self.ws
    }

    pub fn chain(&self) -> &'c Chain {
        self.chain
    }

    /// See [`solve_ik`].
    pub fn solve(
        &mut self,
        target: &IkTarget,
        seed: Option<&[f64]>,
        params: &IkParams,
        rng_seed: u64,
        deadline: Deadline<'_>,
    ) -> Result<IkResult, IkError> {
        validate_request(self.chain, target, seed, params)?;
        let clock = Clock {
            start: Instant::now(),
            deadline: deadline.min_with_budget(params.time_budget),
        };
        Ok(self.solve_validated(target, seed, params, rng_seed, &clock))
    }

    pub(crate) fn solve_validated(
        &mut self,
        target: &IkTarget,
        seed: Option<&[f64]>,
        params: &IkParams,
        rng_seed: u64,
        clock: &Clock<'_>,
    ) -> IkResult {
        let chain = self.chain;
        if params.method == IkMethod::Analytic {
            // validated: the chain is analytic
            if let Ok(arm) = analyse(chain, &params.analytic, seed) {
                // Levenberg–Marquardt from the seed (one attempt) lands on a
                // solution near it; its held value is one more start for the
                // search. It runs on this solver's workspace.
                let proposal =
                    super::analytic::searched_joint(&arm, target, &params.analytic).and_then(|j| {
                        let seed_q = seed.map_or_else(|| chain.mid_limits(), <[f64]>::to_vec);
                        let lm = super::analytic::proposal_params();
                        self.solve_validated(target, Some(&seed_q), &lm, 0, clock)
                            .solutions
                            .first()
                            .map(|s| s.joints[j])
                    });
                let arm =
                    super::analytic::searched(chain, arm, target, seed, proposal, &params.analytic, clock);
                return super::analytic::front::solve_with(chain, &arm, target, seed, params, clock);
            }
        }
        let mut seed_q: Vec<f64> = match seed {
            Some(s) => s.to_vec(),
            None => chain.mid_limits(),
        };
        if params.analytic_start {
            analytic_start(chain, target, params, &mut seed_q);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(rng_seed);
        // same request ⇒ same floating-point path, whatever was solved before
        self.ws.svd.reset();
        let mut solutions: Vec<IkSolution> = Vec::new();
        let mut best: Option<IkSolution> = None;
        let mut best_sq = f64::INFINITY;
        let mut stop_reason = IkStatus::MaxIterations;
        let mut attempts = 0;
        let mut total_iterations = 0;
        for attempt in 0..=params.max_restarts {
            if attempt == 0 {
                self.ws.q.copy_from_slice(&seed_q);
            } else {
                let mut q = std::mem::take(&mut self.ws.q);
                random_in_limits(chain, &mut rng, &mut q);
                self.ws.q = q;
            }
            if attempt > 0
                && let Some(s) = clock.interrupted()
            {
                stop_reason = s;
                break;
            }
            attempts += 1;
            self.ws.history.clear();
            let out = run_attempt(chain, target, params, &mut self.ws, &mut rng, clock);
            self.ws.finish_history(params, &out.error);
            total_iterations += out.iterations;
            let make = |ws: &IkWorkspace| IkSolution {
                joints: ws.q.clone(),
                position_error: out.error.position,
                orientation_error: out.error.orientation,
                iterations: out.iterations,
                elapsed_us: clock.elapsed_us(),
                status: out.status,
                attempt,
                history: ws.history.clone(),
                config: None,
                singular: false,
            };
            if out.status == IkStatus::Converged {
                let distinct = solutions.iter().all(|s| {
                    s.joints
                        .iter()
                        .zip(&self.ws.q)
                        .any(|(a, b)| (a - b).abs() >= params.distinct_tolerance)
                });
                if distinct {
                    solutions.push(make(&self.ws));
                }
                if solutions.len() >= params.num_solutions {
                    stop_reason = IkStatus::Converged;
                    break;
                }
            } else {
                // only a new best attempt is copied out (no allocation per failed attempt)
                let sq = out.error.squared();
                if sq < best_sq || best.is_none() {
                    best_sq = sq;
                    best = Some(make(&self.ws));
                }
                if matches!(out.status, IkStatus::TimeBudget | IkStatus::Cancelled) {
                    stop_reason = out.status;
                    break;
                }
            }
        }
        let dist = |q: &[f64]| q.iter().zip(&seed_q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
        solutions.sort_by(|a, b| dist(&a.joints).total_cmp(&dist(&b.joints)));
        IkResult {
            best_attempt: if solutions.is_empty() { best } else { None },
            solutions,
            stop_reason,
            attempts,
            total_iterations,
            elapsed_us: clock.elapsed_us(),
        }
    }
}

/// Replaces `seed_q` by the analytic solution nearest it (Euclidean joint
/// distance) when the chain has a closed form and the target is a pose.
fn analytic_start(chain: &Chain, target: &IkTarget, params: &IkParams, seed_q: &mut Vec<f64>) {
    let IkTarget::Pose(pose) = target else { return };
    let Ok(reduced) = analyse(chain, &params.analytic, Some(seed_q)) else {
        return;
    };
    let seed6 = reduced.reduce(seed_q);
    let mut out = Vec::new();
    let near = super::analytic::AnalyticParams {
        turns: super::analytic::Turns::NearestSeed,
        ..params.analytic
    };
    reduced.arm.solve_into(pose, Some(&seed6), &near, &mut out);
    let dist = |q: &[f64; 6]| q.iter().zip(&seed6).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    if let Some(best) = out
        .iter()
        .min_by(|a, b| dist(&a.joints).total_cmp(&dist(&b.joints)))
    {
        *seed_q = reduced.expand(&best.joints);
    }
}

pub(crate) fn run_attempt(
    chain: &Chain,
    target: &IkTarget,
    params: &IkParams,
    ws: &mut IkWorkspace,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) -> Attempt {
    match params.method {
        IkMethod::JacobianInverse | IkMethod::LevenbergMarquardt | IkMethod::Newton => {
            super::jacobian_methods::run(chain, target, params, ws, rng, clock)
        }
        IkMethod::Ccd => super::ccd::run(chain, target, params, ws, clock),
        IkMethod::Fabrik | IkMethod::LengthRelaxation => {
            super::point_chain::run(chain, target, params, ws, clock)
        }
        // served whole by `analytic::front` before any attempt; as a fallback the
        // attempt is a Levenberg–Marquardt one
        IkMethod::Analytic => super::jacobian_methods::run(chain, target, params, ws, rng, clock),
    }
}

/// Solves inverse kinematics for `chain` (docs/inverse-kinematics.md).
///
/// The first attempt starts at `seed` (default: middle of the limits); further attempts
/// start at joints drawn uniformly inside the limits from a ChaCha8 RNG seeded with
/// `rng_seed`, so the same input gives the same answer. The search stops when
/// `params.num_solutions` distinct converged solutions are found, the restarts are used
/// up, or `deadline` stops it: its instant or `params.time_budget` from the start,
/// whichever comes first (`TimeBudget`), or its cancellation (`Cancelled`), both checked
/// every iteration. Solutions are ranked by Euclidean joint distance to the seed; when
/// none converged, [`IkResult::best_attempt`] holds the lowest-error attempt, flagged.
///
/// ```
/// use kinplan_core::Deadline;
/// use kinplan_core::ik::{solve_ik, IkParams, IkTarget};
/// let chain = kinplan_core::robot::builtin_chain("ur5").unwrap();
/// let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
/// let target = IkTarget::Pose(chain.fk(&q));
/// let r = solve_ik(&chain, &target, None, &IkParams::default(), 7, Deadline::none()).unwrap();
/// assert!(r.success());
/// let s = &r.solutions[0];
/// assert!(s.position_error <= 1e-5 && s.orientation_error <= 1e-5);
/// let fk = chain.fk(&s.joints);
/// assert!((fk.translation.vector - target.position()).norm() <= 1e-5);
/// ```
pub fn solve_ik(
    chain: &Chain,
    target: &IkTarget,
    seed: Option<&[f64]>,
    params: &IkParams,
    rng_seed: u64,
    deadline: Deadline<'_>,
) -> Result<IkResult, IkError> {
    IkSolver::new(chain).solve(target, seed, params, rng_seed, deadline)
}
