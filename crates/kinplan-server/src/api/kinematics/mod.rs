//! `KinematicsService`: inverse kinematics ([`kinplan_core::ik`]) and the linear
//! solvers behind it ([`kinplan_core::linalg`]); docs/inverse-kinematics.md and docs/linear-solvers.md.
//!
//! Thin adapter: admit → resolve the robot → proto options, targets and
//! matrices into domain values → solve on the CPU pool until the request's
//! [`Budget::deadline`] (the call's deadline less a reply reserve, and the
//! caller's cancellation) or `options.time_budget`, whichever ends first →
//! reply. [`IkError`](kinplan_core::ik::IkError)s
//! become INVALID_ARGUMENT naming the request field. Not converging is a
//! status in the reply, never an error.

use std::pin::Pin;
use std::sync::Arc;
use std::time::Instant;

use nalgebra::DVector;
use rand::SeedableRng;
use tokio_stream::Stream;
use tokio_stream::wrappers::ReceiverStream;
use tonic::{Request, Response, Status, Streaming};

use crate::api::convert::{finite_slice, matrix_in};
use crate::pb::{self, kinematics_service_server::KinematicsService};
use crate::runtime::Shared;
use crate::runtime::deadline::{call_deadline, grpc_timeout};
use crate::runtime::{Budget, Compute, ModelStore, catch_unwind};
use crate::status::ik::{IkAt, ik_error};
use crate::status::linalg::{SolveAt, linalg_error};
use crate::status::{invalid, robot_error};
use kinplan_core::ik::{
    BatchSeeds, IkSolver, IkTarget, IkWorkspace, TrackParams, solve_ik, solve_ik_batch, track_path,
};
use kinplan_core::linalg::{solve_angle_relaxation_until, solve_pseudoinverse};
use kinplan_core::robot::Chain;

mod convert;
mod stream;

use convert::*;
pub use convert::{MAX_IK_RLXA_ITERATIONS, MAX_LINEAR_HISTORY, MAX_PATH_POSES, MAX_RLXA_WORK, MAX_SOLUTIONS};
use stream::*;

/// Most targets in one `SolveIkBatch`.
pub const MAX_BATCH_TARGETS: usize = 10_000;
/// Most solutions a whole batch may ask for (targets × num_solutions).
pub const MAX_BATCH_SOLUTIONS: usize = 100_000;
/// Most entries of a `SolveLinearSystem` matrix.
pub const MAX_MATRIX_ENTRIES: usize = 10_000;
/// Largest magnitude of a matrix or right-hand-side entry: norms of up to
/// `MAX_MATRIX_ENTRIES` squared entries stay finite.
pub const MAX_LINEAR_ENTRY: f64 = 1e100;
/// Default random restarts of `SolveIk` and `SolveIkBatch`: the domain's
/// (`IkParams::default().max_restarts`).
const RESTARTS_SOLVE: Option<usize> = None;
/// Default random restarts of `TrackPath` and `StreamIk`: none, to stay on the
/// seed's branch.
const RESTARTS_WARM: Option<usize> = Some(0);

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
        let options = Options::from_proto(req.options.as_ref(), RESTARTS_SOLVE)?;
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
                    b.deadline(),
                )
            })
            .await?
            .map_err(|e| ik_error(e, IkAt::Target))?;
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
        let options = Options::from_proto(req.options.as_ref(), RESTARTS_SOLVE)?;
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
        // the explicit budget is per target; the deadline bounds the batch
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
        let reply = self
            .shared
            .compute
            .run(&budget, move |b| {
                let start = Instant::now();
                let seeds = match &per_target {
                    Some(all) => BatchSeeds::PerTarget(all),
                    None => BatchSeeds::shared(seed.as_deref()),
                };
                // targets cut by the batch's deadline end TIME_BUDGET
                let results = solve_ik_batch(
                    &chain,
                    &targets,
                    seeds,
                    &options.params,
                    options.rng_seed,
                    b.deadline(),
                );
                let results = results
                    .into_iter()
                    .enumerate()
                    .map(|(i, r)| Ok(result_out(r.map_err(|e| ik_error(e, IkAt::Batch(i)))?)))
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
        let options = Options::from_proto(req.options.as_ref(), RESTARTS_WARM)?;
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
                track_path(&chain, &targets, &seed, &params, options.rng_seed, b.deadline())
            })
            .await?
            .map_err(|e| ik_error(e, IkAt::Path(path_field)))?;
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
        let deadline = call_deadline(grpc_timeout(request.metadata().as_ref()), None);
        let inbound = request.into_inner();
        let (tx, rx) = tokio::sync::mpsc::channel(4);
        let models = self.shared.models.clone();
        let compute = self.shared.compute.clone();
        tokio::spawn(async move {
            let _permit = permit;
            let looped = catch_unwind(stream_loop(inbound, &tx, &models, &compute, deadline)).await;
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
        let solver = linear_solve_in(&req, a.len())?;
        let b = DVector::from_vec(req.b);
        let (solution, elapsed) = self
            .shared
            .compute
            .run(&budget, move |budget| {
                let start = Instant::now();
                let s = match solver {
                    LinearSolve::Svd(p) => solve_pseudoinverse(&a, &b, &p),
                    LinearSolve::Rlxa(p, seed) => {
                        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
                        solve_angle_relaxation_until(&a, &b, &p, &mut rng, budget.deadline())
                    }
                };
                s.map(|s| (s, start.elapsed()))
            })
            .await?
            .map_err(|e| linalg_error(e, SolveAt::LinearSystem))?;
        Ok(Response::new(linear_out(solution, elapsed)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinplan_core::ik::{IkMethod, JointLimitMode};
    use kinplan_core::linalg::{LinearSolverKind, RlxaVariant};

    /// Unset options take the defaults `proto/kinplan/v1/kinematics.proto`
    /// documents beside each `IkOptions` field, written out here so that a change
    /// of a default in the domain shows up as a contract change.
    #[test]
    fn unset_options_take_the_documented_defaults() {
        let solve = Options::from_proto(None, RESTARTS_SOLVE).unwrap();
        let p = solve.params;
        assert_eq!(p.method, IkMethod::LevenbergMarquardt);
        assert_eq!(p.linear_solver, LinearSolverKind::SvdPseudoinverse);
        assert_eq!(p.position_tolerance, 1e-5);
        assert_eq!(p.orientation_tolerance, 1e-5);
        assert!(!solve.position_only);
        assert_eq!(p.max_iterations, 100);
        assert_eq!(p.damping, 1e-3);
        assert_eq!(p.max_restarts, 200);
        assert_eq!(p.num_solutions, 1);
        assert_eq!(solve.rng_seed, 0);
        assert_eq!(p.joint_limits, JointLimitMode::Clamp);
        assert_eq!(p.time_budget, None);
        assert!(p.adaptive_damping);
        assert_eq!(p.max_step, 1.0);
        assert_eq!(p.distinct_tolerance, 1e-3);
        assert_eq!(p.rlxa.max_iterations, 300);
        assert!(!p.record_history);
        // "0: default": the zero of a plain field means its default too.
        let zeros = pb::IkOptions {
            max_iterations: 0,
            num_solutions: 0,
            ..Default::default()
        };
        let p = Options::from_proto(Some(&zeros), RESTARTS_SOLVE).unwrap().params;
        assert_eq!((p.max_iterations, p.num_solutions), (100, 1));
        // TrackPath and StreamIk: no restarts unless asked for.
        let warm = Options::from_proto(None, RESTARTS_WARM).unwrap().params;
        assert_eq!(warm.max_restarts, 0);
        let explicit = pb::IkOptions {
            max_restarts: Some(7),
            ..Default::default()
        };
        let p = Options::from_proto(Some(&explicit), RESTARTS_WARM)
            .unwrap()
            .params;
        assert_eq!(p.max_restarts, 7);
    }

    /// Unset `SolveLinearSystemRequest` options take the documented defaults:
    /// SVD with singular values below 1e-10 of the largest as zero; angle
    /// relaxation with 20,000 iterations, tolerance 0.01, no relative tolerance,
    /// seed 0, no history.
    #[test]
    fn unset_linear_system_options_take_the_documented_defaults() {
        let svd = pb::SolveLinearSystemRequest::default();
        match linear_solve_in(&svd, 4).unwrap() {
            LinearSolve::Svd(p) => assert_eq!(p.relative_tolerance, 1e-10),
            LinearSolve::Rlxa(..) => panic!("the default method is the SVD pseudoinverse"),
        }
        let rlxa = pb::SolveLinearSystemRequest {
            method: pb::LinearSolver::AngleRelaxation as i32,
            ..Default::default()
        };
        match linear_solve_in(&rlxa, 4).unwrap() {
            LinearSolve::Rlxa(p, seed) => {
                assert_eq!(p.max_iterations, 20_000);
                assert_eq!(p.tolerance, 0.01);
                assert_eq!(p.relative_tolerance, 0.0);
                assert_eq!(p.variant, RlxaVariant::Faithful);
                assert!(!p.record_history);
                assert_eq!(seed, 0);
            }
            LinearSolve::Svd(_) => panic!("angle relaxation was asked for"),
        }
    }
}
