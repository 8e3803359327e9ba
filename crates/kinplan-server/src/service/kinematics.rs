//! `KinematicsService`: inverse kinematics ([`kinplan_core::ik`]) and the linear
//! solvers behind it ([`kinplan_core::linalg`]), ALGORITHMS.md §1–2.
//!
//! Thin adapter: admit → resolve the robot → proto options, targets and
//! matrices into domain values → solve on the CPU pool, with the request's
//! deadline (less a reply reserve) as the IK time budget and
//! [`Budget::should_stop`] as the cancellation check → reply. [`IkError`]s
//! become INVALID_ARGUMENT naming the request field. Not converging is a
//! status in the reply, never an error.

use std::pin::Pin;
use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::{DVector, Isometry3, Point3};
use rand::SeedableRng;
use tokio_stream::Stream;
use tokio_stream::wrappers::ReceiverStream;
use tonic::{Request, Response, Status, Streaming};

use super::convert::{finite_slice, matrix_in, pose_in, pose_out, vec3_in};
use super::pb::{self, kinematics_service_server::KinematicsService};
use super::server::Shared;
use super::status::{invalid, robot_error, too_large};
use super::{Budget, Compute, ModelStore};
use kinplan_core::ik::{
    BatchSeeds, IkError, IkMethod, IkParams, IkResult, IkSolution, IkSolver, IkStatus, IkTarget, IkWorkspace,
    JointLimitMode, TrackParams, TrackResult, circle_path, line_path, solve_ik, solve_ik_batch, track_path,
};
use kinplan_core::linalg::{
    LinalgError, LinearSolution, LinearSolverKind, PseudoinverseParams, RlxaParams, RlxaVariant, SolveStatus,
    solve_angle_relaxation_until, solve_pseudoinverse,
};
use kinplan_core::robot::Chain;

/// Most targets in one `SolveIkBatch`.
pub const MAX_BATCH_TARGETS: usize = 10_000;
/// Most poses of a `TrackPath` (explicit poses, or line/circle steps): the reply
/// then stays under ~9 MB for a 7-joint arm (the default message limit is 16 MB).
pub const MAX_PATH_POSES: usize = 50_000;
/// Most solutions one target may ask for.
pub const MAX_SOLUTIONS: u32 = 1_000;
/// Most solutions a whole batch may ask for (targets × num_solutions).
pub const MAX_BATCH_SOLUTIONS: usize = 100_000;
/// Most entries of a `SolveLinearSystem` matrix.
pub const MAX_MATRIX_ENTRIES: usize = 10_000;
/// Most RLXA work (iteration cap × m × n) of one `SolveLinearSystem`; the
/// solve also stops at the deadline (checked every 1024 iterations).
pub const MAX_RLXA_WORK: u64 = 1_000_000_000;
/// Most iterations of a `SolveLinearSystem` that records its residual history
/// (8 bytes each in the reply, so at most 8 MB): bounded up front.
pub const MAX_LINEAR_HISTORY: usize = 1_000_000;
/// Largest magnitude of a matrix or right-hand-side entry: norms of up to
/// `MAX_MATRIX_ENTRIES` squared entries stay finite.
pub const MAX_LINEAR_ENTRY: f64 = 1e100;
/// Most RLXA iterations inside one IK iteration (`options.rlxa_max_iterations`):
/// the IK loop checks its deadline between iterations.
pub const MAX_IK_RLXA_ITERATIONS: u32 = 100_000;
/// Default random restarts of `SolveIk` and `SolveIkBatch` (the domain default).
const RESTARTS_SOLVE: usize = 200;
/// Default random restarts of `TrackPath` and `StreamIk`: stay on the seed's branch.
const RESTARTS_WARM: usize = 0;

pub struct KinematicsApi {
    shared: Shared,
}

impl KinematicsApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }
}

type ResponseStream = Pin<Box<dyn Stream<Item = Result<pb::StreamIkResponse, Status>> + Send>>;

#[tonic::async_trait]
impl KinematicsService for KinematicsApi {
    async fn solve_ik(
        &self,
        request: Request<pb::SolveIkRequest>,
    ) -> Result<Response<pb::SolveIkResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        let mut options = Options::from_proto(req.options.as_ref(), RESTARTS_SOLVE)?;
        options.params.time_budget = time_budget(options.time_budget, soft_deadline(budget.deadline()));
        let target = target_in("target", req.target.as_ref(), options.position_only)?;
        let seed = (!req.seed.is_empty()).then_some(req.seed);
        let chain = robot.chain.clone();
        let result = self
            .shared
            .compute
            .run(&budget, move |b| {
                solve_ik(
                    &chain,
                    &target,
                    seed.as_deref(),
                    &options.params,
                    options.rng_seed,
                    &|| b.should_stop(),
                )
            })
            .await?
            .map_err(|e| ik_error(e, "target", ""))?;
        let mut reply = result_out(result);
        reply.model_id = robot.model_id;
        Ok(Response::new(reply))
    }

    async fn solve_ik_batch(
        &self,
        request: Request<pb::SolveIkBatchRequest>,
    ) -> Result<Response<pb::SolveIkBatchResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        if req.targets.is_empty() {
            return Err(invalid("targets", "at least one target is required"));
        }
        if req.targets.len() > MAX_BATCH_TARGETS {
            return Err(invalid(
                "targets",
                format!(
                    "{} targets exceed the limit of {MAX_BATCH_TARGETS}",
                    req.targets.len()
                ),
            ));
        }
        let mut options = Options::from_proto(req.options.as_ref(), RESTARTS_SOLVE)?;
        if req.targets.len() * options.params.num_solutions > MAX_BATCH_SOLUTIONS {
            return Err(invalid(
                "options.num_solutions",
                format!(
                    "{} targets x {} solutions exceed the limit of {MAX_BATCH_SOLUTIONS} per batch",
                    req.targets.len(),
                    options.params.num_solutions
                ),
            ));
        }
        // the explicit budget is per target; the deadline bounds the batch (below)
        options.params.time_budget = time_budget(options.time_budget, None);
        let targets = req
            .targets
            .iter()
            .enumerate()
            .map(|(i, t)| target_in(&format!("targets[{i}]"), Some(t), options.position_only))
            .collect::<Result<Vec<_>, _>>()?;
        let dof = robot.chain.dof();
        let per_target = match &req.seeds {
            Some(m) => {
                if m.rows as usize != req.targets.len() || m.cols as usize != dof {
                    return Err(invalid(
                        "seeds",
                        format!(
                            "is {}x{}, needs one row per target and one column per joint ({}x{dof})",
                            m.rows,
                            m.cols,
                            req.targets.len()
                        ),
                    ));
                }
                if m.data.len() != req.targets.len() * dof {
                    return Err(invalid(
                        "seeds.data",
                        format!("has {} values, needs {}", m.data.len(), req.targets.len() * dof),
                    ));
                }
                for (i, row) in m.data.chunks_exact(dof).enumerate() {
                    robot
                        .chain
                        .check_joints(row)
                        .map_err(|e| robot_error(e, &format!("seeds[{i}]")))?;
                }
                Some(m.data.clone())
            }
            None => None,
        };
        let seed = (!req.seed.is_empty()).then_some(req.seed);
        let chain = robot.chain.clone();
        let soft = soft_deadline(budget.deadline());
        let reply = self
            .shared
            .compute
            .run(&budget, move |b| {
                let start = Instant::now();
                let stop = || b.should_stop() || soft.is_some_and(|d| Instant::now() >= d);
                let seeds = match &per_target {
                    Some(all) => BatchSeeds::PerTarget(all),
                    None => BatchSeeds::shared(seed.as_deref()),
                };
                let results =
                    solve_ik_batch(&chain, &targets, seeds, &options.params, options.rng_seed, &stop);
                // a cancellation seen while the caller still waits is the deadline
                let late = soft.is_some_and(|d| Instant::now() >= d);
                let results = results
                    .into_iter()
                    .enumerate()
                    .map(|(i, r)| {
                        let mut r = r.map_err(|e| ik_error(e, &format!("targets[{i}]"), ""))?;
                        if late {
                            relabel_cancelled(&mut r);
                        }
                        Ok(result_out(r))
                    })
                    .collect::<Result<Vec<_>, Status>>()?;
                Ok::<_, Status>(pb::SolveIkBatchResponse {
                    succeeded: results.iter().filter(|r| r.success).count() as u32,
                    results,
                    elapsed_us: micros(start.elapsed()),
                    model_id: Vec::new(),
                })
            })
            .await??;
        Ok(Response::new(pb::SolveIkBatchResponse {
            model_id: robot.model_id,
            ..reply
        }))
    }

    async fn track_path(
        &self,
        request: Request<pb::TrackPathRequest>,
    ) -> Result<Response<pb::TrackPathResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        let mut options = Options::from_proto(req.options.as_ref(), RESTARTS_WARM)?;
        options.params.time_budget = time_budget(options.time_budget, soft_deadline(budget.deadline()));
        let chain = robot.chain.clone();
        let seed = if req.seed.is_empty() {
            chain.mid_limits()
        } else {
            chain
                .check_joints(&req.seed)
                .map_err(|e| robot_error(e, "seed"))?;
            req.seed
        };
        let (poses, path_field) = path_in(&req.poses, req.line.as_ref(), req.circle.as_ref(), &chain, &seed)?;
        let targets: Vec<IkTarget> = poses
            .iter()
            .map(|p| target_of(p, options.position_only))
            .collect();
        let params = TrackParams {
            ik: options.params,
            stop_on_failure: req.stop_on_failure,
        };
        let result = self
            .shared
            .compute
            .run(&budget, move |b| {
                track_path(&chain, &targets, &seed, &params, options.rng_seed, &|| {
                    b.should_stop()
                })
            })
            .await?
            .map_err(|e| ik_error(e, path_field, path_field))?;
        Ok(Response::new(track_out(result, &poses, robot.model_id)))
    }

    type StreamIkStream = ResponseStream;

    async fn stream_ik(
        &self,
        request: Request<Streaming<pb::StreamIkRequest>>,
    ) -> Result<Response<Self::StreamIkStream>, Status> {
        // An open stream holds a stream slot, not an admission permit: each
        // message's work is admitted on its own (idle streams block no one).
        let permit = self.shared.compute.admit_stream()?;
        // A controller's stream lives as long as the controller runs: only a
        // deadline the client sets bounds it, not the server's default.
        let deadline =
            super::compute::grpc_timeout(request.metadata().as_ref()).and_then(super::guard::deadline_after);
        let inbound = request.into_inner();
        let (tx, rx) = tokio::sync::mpsc::channel(4);
        let models = self.shared.models.clone();
        let compute = self.shared.compute.clone();
        tokio::spawn(async move {
            let _permit = permit;
            let looped =
                super::guard::catch_unwind(stream_loop(inbound, &tx, &models, &compute, deadline)).await;
            let outcome = looped.unwrap_or_else(|_panic| {
                tracing::error!("a StreamIk stream panicked; answering INTERNAL");
                Err(Status::internal(
                    "the server failed unexpectedly while handling this stream",
                ))
            });
            if let Err(status) = outcome {
                let _ = tx.send(Err(status)).await;
            }
        });
        Ok(Response::new(Box::pin(ReceiverStream::new(rx))))
    }

    async fn solve_linear_system(
        &self,
        request: Request<pb::SolveLinearSystemRequest>,
    ) -> Result<Response<pb::SolveLinearSystemResponse>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        let a = matrix_in("a", req.a.as_ref(), MAX_MATRIX_ENTRIES)?;
        if req.b.len() != a.nrows() {
            return Err(invalid(
                "b",
                format!("has {} entries, a has {} rows", req.b.len(), a.nrows()),
            ));
        }
        finite_slice("b", &req.b)?;
        if let Some(i) = a.iter().position(|v| v.abs() > MAX_LINEAR_ENTRY) {
            return Err(invalid(
                format!("a.data[{i}]"),
                format!("magnitude above the limit of {MAX_LINEAR_ENTRY:e}"),
            ));
        }
        if let Some(i) = req.b.iter().position(|v| v.abs() > MAX_LINEAR_ENTRY) {
            return Err(invalid(
                format!("b[{i}]"),
                format!("magnitude above the limit of {MAX_LINEAR_ENTRY:e}"),
            ));
        }
        let b = DVector::from_vec(req.b);
        let solver = match linear_solver_in("method", req.method)? {
            None => {
                let params = PseudoinverseParams {
                    relative_tolerance: req
                        .singular_value_tolerance
                        .unwrap_or(PseudoinverseParams::default().relative_tolerance),
                };
                params
                    .validate()
                    .map_err(|e| invalid("singular_value_tolerance", e.to_string()))?;
                LinearSolve::Svd(params)
            }
            Some(variant) => {
                let d = RlxaParams::default();
                let params = RlxaParams {
                    max_iterations: if req.max_iterations == 0 {
                        d.max_iterations
                    } else {
                        req.max_iterations as usize
                    },
                    tolerance: req.tolerance.unwrap_or(d.tolerance),
                    relative_tolerance: req.relative_tolerance.unwrap_or(d.relative_tolerance),
                    variant,
                    record_history: req.record_history,
                    ..d
                };
                params.validate().map_err(|e| linalg_error(e, ""))?;
                if params.record_history && params.max_iterations > MAX_LINEAR_HISTORY {
                    return Err(too_large(
                        "max_iterations",
                        format!(
                            "{} iterations with record_history exceed the history limit of {MAX_LINEAR_HISTORY}",
                            params.max_iterations
                        ),
                    ));
                }
                let work = (params.max_iterations as u64).saturating_mul(a.len() as u64);
                if work > MAX_RLXA_WORK {
                    return Err(invalid(
                        "max_iterations",
                        format!(
                            "{} iterations on {} entries exceed the work limit of {MAX_RLXA_WORK} \
                             (iterations x rows x cols)",
                            params.max_iterations,
                            a.len()
                        ),
                    ));
                }
                LinearSolve::Rlxa(params, req.rng_seed)
            }
        };
        let (solution, elapsed) = self
            .shared
            .compute
            .run(&budget, move |budget| {
                let start = Instant::now();
                let s = match solver {
                    LinearSolve::Svd(p) => solve_pseudoinverse(&a, &b, &p),
                    LinearSolve::Rlxa(p, seed) => {
                        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
                        solve_angle_relaxation_until(&a, &b, &p, &mut rng, &|| budget.should_stop())
                    }
                };
                s.map(|s| (s, start.elapsed()))
            })
            .await?
            .map_err(|e| linalg_error(e, ""))?;
        Ok(Response::new(linear_out(solution, elapsed)))
    }
}

enum LinearSolve {
    Svd(PseudoinverseParams),
    Rlxa(RlxaParams, u64),
}

/// The IK options of a request in domain form.
#[derive(Debug, Clone, Copy)]
struct Options {
    params: IkParams,
    position_only: bool,
    rng_seed: u64,
    /// `options.time_budget` (validated), before the deadline is applied.
    time_budget: Option<Duration>,
}

impl Options {
    /// Unset fields take the documented defaults; ranges are checked by
    /// [`IkParams::validate`], whose field names are the proto's.
    fn from_proto(o: Option<&pb::IkOptions>, default_restarts: usize) -> Result<Self, Status> {
        let o = o.cloned().unwrap_or_default();
        let d = IkParams::default();
        let method = match pb::IkMethod::try_from(o.method) {
            Ok(pb::IkMethod::Unspecified | pb::IkMethod::LevenbergMarquardt) => IkMethod::LevenbergMarquardt,
            Ok(pb::IkMethod::JacobianInverse) => IkMethod::JacobianInverse,
            Ok(pb::IkMethod::Newton) => IkMethod::Newton,
            Ok(pb::IkMethod::Ccd) => IkMethod::Ccd,
            Ok(pb::IkMethod::Fabrik) => IkMethod::Fabrik,
            Ok(pb::IkMethod::LengthRelaxation) => IkMethod::LengthRelaxation,
            Err(_) => return Err(invalid("options.method", format!("unknown value {}", o.method))),
        };
        let mut rlxa = d.rlxa;
        let linear_solver = match linear_solver_in("options.linear_solver", o.linear_solver)? {
            None => LinearSolverKind::SvdPseudoinverse,
            Some(variant) => {
                rlxa.variant = variant;
                LinearSolverKind::AngleRelaxation
            }
        };
        if let Some(n) = o.rlxa_max_iterations {
            if n > MAX_IK_RLXA_ITERATIONS {
                return Err(invalid(
                    "options.rlxa_max_iterations",
                    format!("{n} exceeds the limit of {MAX_IK_RLXA_ITERATIONS}"),
                ));
            }
            rlxa.max_iterations = n as usize;
        }
        if o.num_solutions > MAX_SOLUTIONS {
            return Err(invalid(
                "options.num_solutions",
                format!("{} exceeds the limit of {MAX_SOLUTIONS}", o.num_solutions),
            ));
        }
        let joint_limits = match pb::JointLimitMode::try_from(o.joint_limits) {
            Ok(pb::JointLimitMode::Unspecified | pb::JointLimitMode::Clamp) => JointLimitMode::Clamp,
            Ok(pb::JointLimitMode::Ignore) => JointLimitMode::Ignore,
            Err(_) => {
                return Err(invalid(
                    "options.joint_limits",
                    format!("unknown value {}", o.joint_limits),
                ));
            }
        };
        let time_budget = match o.time_budget {
            None => None,
            Some(t) if t.is_finite() && t > 0.0 && t < 1e9 => Some(Duration::from_secs_f64(t)),
            Some(t) => {
                return Err(invalid(
                    "options.time_budget",
                    format!("must be finite, > 0 and < 1e9 seconds, got {t}"),
                ));
            }
        };
        let params = IkParams {
            method,
            linear_solver,
            position_tolerance: o.position_tolerance.unwrap_or(d.position_tolerance),
            orientation_tolerance: o.orientation_tolerance.unwrap_or(d.orientation_tolerance),
            max_iterations: if o.max_iterations == 0 {
                d.max_iterations
            } else {
                o.max_iterations as usize
            },
            damping: o.damping.unwrap_or(d.damping),
            adaptive_damping: o.adaptive_damping.unwrap_or(d.adaptive_damping),
            max_step: o.max_step.unwrap_or(d.max_step),
            rlxa,
            joint_limits,
            max_restarts: o.max_restarts.map_or(default_restarts, |n| n as usize),
            num_solutions: (o.num_solutions as usize).max(1),
            distinct_tolerance: o.distinct_tolerance.unwrap_or(d.distinct_tolerance),
            time_budget,
            record_history: o.return_history,
            ..d
        };
        params.validate().map_err(|e| ik_error(e, "target", ""))?;
        Ok(Self {
            params,
            position_only: o.position_only,
            rng_seed: o.rng_seed,
            time_budget,
        })
    }
}

/// `None` for the SVD pseudoinverse, the RLXA variant otherwise.
fn linear_solver_in(field: &str, value: i32) -> Result<Option<RlxaVariant>, Status> {
    match pb::LinearSolver::try_from(value) {
        Ok(pb::LinearSolver::Unspecified | pb::LinearSolver::SvdPseudoinverse) => Ok(None),
        Ok(pb::LinearSolver::AngleRelaxation) => Ok(Some(RlxaVariant::Faithful)),
        Ok(pb::LinearSolver::AngleRelaxationSafeguarded) => Ok(Some(RlxaVariant::Safeguarded)),
        Err(_) => Err(invalid(field, format!("unknown value {value}"))),
    }
}

/// The request's deadline less a reply reserve (a tenth of the remaining
/// time, 0.2–100 ms, at most half of it), so that an answer cut by the budget
/// still reaches the caller before its deadline.
pub(super) fn soft_deadline(deadline: Option<Instant>) -> Option<Instant> {
    let deadline = deadline?;
    let remaining = deadline.saturating_duration_since(Instant::now());
    let reserve = (remaining / 10)
        .clamp(Duration::from_micros(200), Duration::from_millis(100))
        .min(remaining / 2);
    Some(deadline - reserve)
}

/// The earlier of the explicit budget and the time left until `soft`.
fn time_budget(explicit: Option<Duration>, soft: Option<Instant>) -> Option<Duration> {
    let from_deadline = soft.map(kinplan_core::ik::budget_until);
    match (explicit, from_deadline) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Targets cut by the batch's deadline end TIME_BUDGET, not CANCELLED.
fn relabel_cancelled(r: &mut IkResult) {
    let fix = |s: &mut IkStatus| {
        if *s == IkStatus::Cancelled {
            *s = IkStatus::TimeBudget;
        }
    };
    fix(&mut r.stop_reason);
    r.solutions.iter_mut().for_each(|s| fix(&mut s.status));
    if let Some(b) = r.best_attempt.as_mut() {
        fix(&mut b.status);
    }
}

fn target_of(pose: &Isometry3<f64>, position_only: bool) -> IkTarget {
    if position_only {
        IkTarget::Position(Point3::from(pose.translation.vector))
    } else {
        IkTarget::Pose(*pose)
    }
}

fn target_in(field: &str, pose: Option<&pb::Pose>, position_only: bool) -> Result<IkTarget, Status> {
    Ok(target_of(&pose_in(field, pose)?, position_only))
}

/// The poses of a `TrackPath` and the field they came from.
fn path_in(
    poses: &[pb::Pose],
    line: Option<&pb::LinePath>,
    circle: Option<&pb::CirclePath>,
    chain: &Chain,
    seed: &[f64],
) -> Result<(Vec<Isometry3<f64>>, &'static str), Status> {
    let given = usize::from(!poses.is_empty()) + usize::from(line.is_some()) + usize::from(circle.is_some());
    if given != 1 {
        return Err(invalid(
            "poses",
            format!("exactly one of poses, line and circle is required, got {given}"),
        ));
    }
    let steps = |field: &str, steps: u32| {
        if steps == 0 || steps as usize >= MAX_PATH_POSES {
            Err(invalid(
                field,
                format!("must be between 1 and {}, got {steps}", MAX_PATH_POSES - 1),
            ))
        } else {
            Ok(steps as usize)
        }
    };
    let start = |field: &str, p: Option<&pb::Pose>| match p {
        Some(p) => pose_in(field, Some(p)),
        None => Ok(chain.fk(seed)),
    };
    if let Some(line) = line {
        let s = start("line.start", line.start.as_ref())?;
        let e = pose_in("line.end", line.end.as_ref())?;
        let n = steps("line.steps", line.steps)?;
        let path = line_path(&s, &e, n).map_err(|e| ik_error(e, "line", "line"))?;
        return Ok((path, "line"));
    }
    if let Some(c) = circle {
        let s = start("circle.start", c.start.as_ref())?;
        if c.centre.is_none() {
            return Err(invalid("circle.centre", "is required"));
        }
        let centre = Point3::from(vec3_in("circle.centre", c.centre.as_ref())?);
        let normal = vec3_in("circle.normal", c.normal.as_ref())?;
        let n = steps("circle.steps", c.steps)?;
        let path = circle_path(&s, &centre, &normal, c.angle_step, n)
            .map_err(|e| ik_error(e, "circle", "circle"))?;
        return Ok((path, "circle"));
    }
    if poses.len() > MAX_PATH_POSES {
        return Err(invalid(
            "poses",
            format!("{} poses exceed the limit of {MAX_PATH_POSES}", poses.len()),
        ));
    }
    let path = poses
        .iter()
        .enumerate()
        .map(|(i, p)| pose_in(&format!("poses[{i}]"), Some(p)))
        .collect::<Result<_, _>>()?;
    Ok((path, "poses"))
}

/// One `StreamIk` call: the first message names the robot and options; every
/// message is one target, solved on the CPU pool from the previous answer.
async fn stream_loop(
    mut inbound: Streaming<pb::StreamIkRequest>,
    tx: &tokio::sync::mpsc::Sender<Result<pb::StreamIkResponse, Status>>,
    models: &ModelStore,
    compute: &Compute,
    deadline: Option<Instant>,
) -> Result<(), Status> {
    struct Session {
        chain: Arc<Chain>,
        options: Options,
        previous: Vec<f64>,
        /// The solver's buffers, lent to each solve and handed back (`None` only if a
        /// solve never ran, e.g. its deadline passed in the queue).
        workspace: Option<IkWorkspace>,
    }
    let mut session: Option<Session> = None;
    let idle = compute.stream_idle_timeout;
    loop {
        let Ok(next) = tokio::time::timeout(idle, inbound.message()).await else {
            return Err(Status::unavailable(format!(
                "no message for {} s: the stream was ended; open a new one",
                idle.as_secs_f64()
            )));
        };
        let Some(msg) = next? else { break };
        let seq = msg.sequence;
        let at = |s: Status| with_sequence(s, seq);
        let _admitted = compute.admit_work().map_err(at)?;
        let mut model_id = Vec::new();
        let st = match session.as_mut() {
            None => {
                let robot = models
                    .resolve(msg.robot.as_ref(), compute, &Budget::new(deadline))
                    .await
                    .map_err(at)?;
                let options = Options::from_proto(msg.options.as_ref(), RESTARTS_WARM).map_err(at)?;
                model_id = robot.model_id.clone();
                session.insert(Session {
                    previous: robot.chain.mid_limits(),
                    workspace: Some(IkWorkspace::new(&robot.chain)),
                    chain: robot.chain,
                    options,
                })
            }
            Some(st) => {
                if msg.robot.is_some() {
                    return Err(at(invalid(
                        "robot",
                        "is set only in the first message of a stream",
                    )));
                }
                if msg.options.is_some() {
                    return Err(at(invalid(
                        "options",
                        "are set only in the first message of a stream",
                    )));
                }
                st
            }
        };
        let target = target_in("target", msg.target.as_ref(), st.options.position_only).map_err(at)?;
        let seed = if msg.seed.is_empty() {
            st.previous.clone()
        } else {
            msg.seed
        };
        let mut params = st.options.params;
        params.time_budget = time_budget(st.options.time_budget, soft_deadline(deadline));
        let chain = st.chain.clone();
        let rng_seed = st.options.rng_seed;
        let workspace = st.workspace.take().unwrap_or_else(|| IkWorkspace::new(&chain));
        let (result, workspace) = compute
            .run(&Budget::new(deadline), move |b| {
                let mut solver = IkSolver::with_workspace(&chain, workspace);
                let result = solver.solve(&target, Some(&seed), &params, rng_seed, &|| b.should_stop());
                (result, solver.into_workspace())
            })
            .await?;
        st.workspace = Some(workspace);
        let result = result.map_err(|e| at(ik_error(e, "target", "")))?;
        if let Some(best) = result.best() {
            st.previous.copy_from_slice(&best.joints);
        }
        let mut reply = result_out(result);
        reply.model_id = model_id;
        let answer = pb::StreamIkResponse {
            sequence: seq,
            result: Some(reply),
        };
        if tx.send(Ok(answer)).await.is_err() {
            return Ok(()); // the client went away
        }
    }
    Ok(())
}

/// Says which stream message a status is about, keeping its field details.
fn with_sequence(status: Status, sequence: u64) -> Status {
    use tonic_types::StatusExt;
    let details = status.get_error_details();
    let message = format!("{} (stream message with sequence {sequence})", status.message());
    Status::with_error_details(status.code(), message, details)
}

fn micros(d: Duration) -> u64 {
    d.as_micros().min(u64::MAX as u128) as u64
}

fn status_out(s: IkStatus) -> i32 {
    (match s {
        IkStatus::Converged => pb::IkStatus::Converged,
        IkStatus::MaxIterations => pb::IkStatus::MaxIterations,
        IkStatus::Stalled => pb::IkStatus::Stalled,
        IkStatus::TimeBudget => pb::IkStatus::TimeBudget,
        IkStatus::Cancelled => pb::IkStatus::Cancelled,
    }) as i32
}

fn solution_out(s: IkSolution) -> pb::IkSolution {
    pb::IkSolution {
        joints: s.joints,
        position_error: s.position_error,
        orientation_error: s.orientation_error,
        iterations: s.iterations as u32,
        elapsed_us: s.elapsed_us,
        status: status_out(s.status),
        attempt: s.attempt as u32,
        position_error_history: s.history.iter().map(|h| h.0).collect(),
        orientation_error_history: s.history.iter().map(|h| h.1).collect(),
    }
}

fn result_out(r: IkResult) -> pb::SolveIkResponse {
    pb::SolveIkResponse {
        success: r.success(),
        status: status_out(r.stop_reason),
        attempts: r.attempts as u32,
        total_iterations: r.total_iterations as u64,
        elapsed_us: r.elapsed_us,
        solutions: r.solutions.into_iter().map(solution_out).collect(),
        best_attempt: r.best_attempt.map(solution_out),
        model_id: Vec::new(),
    }
}

fn track_out(r: TrackResult, poses: &[Isometry3<f64>], model_id: Vec<u8>) -> pb::TrackPathResponse {
    pb::TrackPathResponse {
        steps: r
            .steps
            .into_iter()
            .zip(poses)
            .map(|(s, pose)| pb::TrackStep {
                target: Some(pose_out(pose)),
                joints: s.joints,
                position_error: s.position_error,
                orientation_error: s.orientation_error,
                iterations: s.iterations as u32,
                elapsed_us: s.elapsed_us,
                status: status_out(s.status),
                max_joint_step: s.max_joint_step,
            })
            .collect(),
        all_converged: r.all_converged,
        max_joint_step: r.max_joint_step,
        elapsed_us: r.elapsed_us,
        status: status_out(r.stop_reason),
        model_id,
    }
}

fn linear_out(s: LinearSolution, elapsed: Duration) -> pb::SolveLinearSystemResponse {
    pb::SolveLinearSystemResponse {
        x: s.x.iter().copied().collect(),
        residual_norm: s.residual_norm,
        iterations: s.iterations as u32,
        status: (match s.status {
            SolveStatus::Converged => pb::LinearSolveStatus::Converged,
            SolveStatus::IterationCap => pb::LinearSolveStatus::IterationCap,
        }) as i32,
        residual_history: s.history,
        elapsed_us: micros(elapsed),
    }
}

/// INVALID_ARGUMENT naming the request field behind an [`IkError`]; `target`
/// is the path of the target (`target`, `targets[3]`), `path` that of a
/// TrackPath's line or circle.
fn ik_error(err: IkError, target: &str, path: &str) -> Status {
    let text = err.to_string();
    match err {
        IkError::EmptyChain => invalid("robot", text),
        IkError::WrongSeedLength { .. } => invalid("seed", text),
        IkError::NonFiniteSeed { index } => invalid(format!("seed[{index}]"), text),
        IkError::NonFiniteTarget { field } => invalid(format!("{target}.{field}"), text),
        IkError::NonUnitQuaternion { .. } => invalid(format!("{target}.orientation"), text),
        IkError::InvalidParam { field, .. } => invalid(format!("options.{field}"), text),
        IkError::MethodCannotServe { .. } => invalid("options.method", text),
        IkError::EmptyPath => invalid("poses", text),
        IkError::InvalidPath { field, .. } => {
            let field = if field == "centre/normal" { "normal" } else { field };
            invalid(format!("{path}.{field}"), text)
        }
        IkError::Linalg(e) => linalg_error(e, "options.rlxa_"),
    }
}

/// INVALID_ARGUMENT for a refused linear solve; `prefix` turns the solver's
/// parameter names into request fields.
fn linalg_error(err: LinalgError, prefix: &str) -> Status {
    let text = err.to_string();
    match err {
        LinalgError::InvalidParam { field, .. } => invalid(format!("{prefix}{field}"), text),
        LinalgError::ShapeMismatch { .. } => invalid("b", text),
        LinalgError::Empty { .. } => invalid("a", text),
        LinalgError::NonFinite { what: "b" } => invalid("b", text),
        LinalgError::NonFinite { .. } => invalid("a.data", text),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_request_fields() {
        let cases = [
            (IkError::WrongSeedLength { expected: 6, got: 5 }, "seed"),
            (IkError::NonFiniteSeed { index: 2 }, "seed[2]"),
            (
                IkError::InvalidParam {
                    field: "position_tolerance",
                    value: 0.0,
                    reason: "",
                },
                "options.position_tolerance",
            ),
            (
                IkError::MethodCannotServe {
                    method: IkMethod::Fabrik,
                    reason: String::new(),
                },
                "options.method",
            ),
            (
                IkError::InvalidPath {
                    field: "normal",
                    reason: "",
                },
                "circle.normal",
            ),
            (
                IkError::Linalg(LinalgError::InvalidParam {
                    field: "max_iterations",
                    value: 0.0,
                    reason: "",
                }),
                "options.rlxa_max_iterations",
            ),
        ];
        for (err, field) in cases {
            let status = ik_error(err, "targets[1]", "circle");
            assert_eq!(status.code(), tonic::Code::InvalidArgument);
            assert!(status.message().starts_with(field), "{}", status.message());
        }
    }

    #[test]
    fn the_deadline_leaves_a_reply_reserve() {
        let now = Instant::now();
        let soft = soft_deadline(Some(now + Duration::from_millis(12))).unwrap();
        let reserve = (now + Duration::from_millis(12)) - soft;
        assert!(reserve >= Duration::from_micros(1100) && reserve <= Duration::from_micros(1200));
        let soft = soft_deadline(Some(now + Duration::from_secs(60))).unwrap();
        assert_eq!((now + Duration::from_secs(60)) - soft, Duration::from_millis(100));
        assert_eq!(
            time_budget(Some(Duration::from_millis(3)), None),
            Some(Duration::from_millis(3))
        );
        assert!(
            time_budget(
                Some(Duration::from_secs(3)),
                Some(now + Duration::from_millis(10))
            )
            .unwrap()
                <= Duration::from_millis(10)
        );
        assert_eq!(time_budget(None, None), None);
    }

    /// Short deadlines: the reserve is at most half the time left (the
    /// 200 µs floor would otherwise eat a 300 µs deadline's whole budget).
    #[test]
    fn a_short_deadline_keeps_half_for_the_work() {
        let deadline = Instant::now() + Duration::from_micros(300);
        let reserve = deadline - soft_deadline(Some(deadline)).unwrap();
        assert!(reserve <= Duration::from_micros(150), "{reserve:?}");
        assert!(reserve >= Duration::from_micros(50), "{reserve:?}");
        // A deadline already passed leaves no reserve and no overflow.
        let past = Instant::now() - Duration::from_millis(1);
        assert_eq!(soft_deadline(Some(past)), Some(past));
    }
}
