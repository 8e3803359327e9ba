//! Inverse kinematics: typed options, the answer, and the unary calls.

use std::time::Duration;

use nalgebra::{DVector, Isometry3};

use crate::convert::pose_to_proto;
use crate::error::{Error, Result};
use crate::pb::{self, kinematics_service_client::KinematicsServiceClient};
use crate::robot::Robot;

/// IK algorithm (docs/inverse-kinematics.md). CCD, FABRIK and length relaxation need
/// [`IkOptions::position_only`] except CCD, which also takes poses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IkMethod {
    JacobianInverse,
    #[default]
    LevenbergMarquardt,
    Newton,
    Ccd,
    Fabrik,
    LengthRelaxation,
    /// Closed form: every solution of a pose (6-joint arms of the families
    /// `DescribeRobot.analytic_family` names), ranked by distance to the seed.
    Analytic,
}

/// Linear solver of the Jacobian methods (docs/linear-solvers.md). S2 predicts, and
/// the server's benchmarks confirm, that Newton with angle relaxation
/// practically never converges; LM or the Jacobian inverse with either solver do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolver {
    #[default]
    SvdPseudoinverse,
    AngleRelaxation,
    AngleRelaxationSafeguarded,
}

/// IK options; `None` and `Default` take the server's documented defaults
/// (tolerances 1e-5 m / rad, 100 iterations, 200 restarts for a unary call and
/// 0 in a stream, one solution, clamp to the limits).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IkOptions {
    pub method: IkMethod,
    pub solver: LinearSolver,
    /// Metres.
    pub position_tolerance: Option<f64>,
    /// Radians.
    pub orientation_tolerance: Option<f64>,
    /// Match the tool position only (the target's rotation is not used).
    pub position_only: bool,
    pub max_iterations: Option<u32>,
    pub max_restarts: Option<u32>,
    /// Distinct solutions wanted (at most 1,000).
    pub num_solutions: Option<u32>,
    /// Seed of the restart RNG: the same request gives the same answer.
    pub rng_seed: u64,
    /// Wall-clock budget per request (per target in a stream); unset: the
    /// call's deadline less a reply margin, so a short deadline still returns
    /// the best attempt.
    pub time_budget: Option<Duration>,
}

impl IkOptions {
    pub(crate) fn to_proto(&self) -> pb::IkOptions {
        let method = match self.method {
            IkMethod::JacobianInverse => pb::IkMethod::JacobianInverse,
            IkMethod::LevenbergMarquardt => pb::IkMethod::LevenbergMarquardt,
            IkMethod::Newton => pb::IkMethod::Newton,
            IkMethod::Ccd => pb::IkMethod::Ccd,
            IkMethod::Fabrik => pb::IkMethod::Fabrik,
            IkMethod::LengthRelaxation => pb::IkMethod::LengthRelaxation,
            IkMethod::Analytic => pb::IkMethod::Analytic,
        };
        let solver = match self.solver {
            LinearSolver::SvdPseudoinverse => pb::LinearSolver::SvdPseudoinverse,
            LinearSolver::AngleRelaxation => pb::LinearSolver::AngleRelaxation,
            LinearSolver::AngleRelaxationSafeguarded => pb::LinearSolver::AngleRelaxationSafeguarded,
        };
        pb::IkOptions {
            method: method as i32,
            linear_solver: solver as i32,
            position_tolerance: self.position_tolerance,
            orientation_tolerance: self.orientation_tolerance,
            position_only: self.position_only,
            max_iterations: self.max_iterations.unwrap_or(0),
            max_restarts: self.max_restarts,
            num_solutions: self.num_solutions.unwrap_or(0),
            rng_seed: self.rng_seed,
            time_budget: self.time_budget.map(|d| d.as_secs_f64()),
            ..Default::default()
        }
    }
}

/// How an IK request ended.
pub use pb::IkStatus;

/// The answer of one IK request.
#[derive(Clone, Debug, PartialEq)]
pub struct IkAnswer {
    /// At least one solution is within the tolerances.
    pub success: bool,
    /// The solution nearest the seed, or the best attempt (not a solution)
    /// when `success` is false. Chain order, rad (m for prismatic joints).
    pub joints: DVector<f64>,
    /// |p* − p| of `joints`, metres.
    pub position_error: f64,
    /// Rotation angle between the wanted and reached orientation, radians.
    pub orientation_error: f64,
    /// Every distinct converged solution, nearest to the seed first.
    pub solutions: Vec<DVector<f64>>,
    pub status: IkStatus,
    /// Attempts run (1 + restarts used).
    pub attempts: u32,
    /// Server-side solve time.
    pub elapsed: Duration,
}

impl IkAnswer {
    pub(crate) fn from_proto(r: pb::SolveIkResponse) -> Result<IkAnswer> {
        let best = if r.success {
            r.solutions.first().cloned().ok_or(Error::Reply("solutions"))?
        } else {
            r.best_attempt.clone().unwrap_or_default()
        };
        Ok(IkAnswer {
            success: r.success,
            status: r.status(),
            joints: DVector::from_vec(best.joints),
            position_error: best.position_error,
            orientation_error: best.orientation_error,
            solutions: r
                .solutions
                .into_iter()
                .map(|s| DVector::from_vec(s.joints))
                .collect(),
            attempts: r.attempts,
            elapsed: Duration::from_micros(r.elapsed_us),
        })
    }
}

impl Robot {
    /// Joints that put the tool at `target` (base frame), starting from
    /// `seed` (empty: the middle of the limits). Not converging is an answer
    /// with `success == false`, not an error.
    pub async fn ik(&self, target: &Isometry3<f64>, seed: &[f64], options: &IkOptions) -> Result<IkAnswer> {
        let (target, options) = (pose_to_proto(target), options.to_proto());
        let r = self
            .call(
                |robot| pb::SolveIkRequest {
                    robot: Some(robot),
                    target: Some(target),
                    seed: seed.to_vec(),
                    options: Some(options),
                },
                |ch, req| async move { KinematicsServiceClient::new(ch).solve_ik(req).await },
                |r| &r.model_id,
            )
            .await?;
        IkAnswer::from_proto(r)
    }

    /// One IK answer per target in one call (the server solves them in
    /// parallel); each target starts from `seed` (empty: mid-limits).
    pub async fn ik_batch(
        &self,
        targets: &[Isometry3<f64>],
        seed: &[f64],
        options: &IkOptions,
    ) -> Result<Vec<IkAnswer>> {
        let targets: Vec<pb::Pose> = targets.iter().map(pose_to_proto).collect();
        let options = options.to_proto();
        let r = self
            .call(
                |robot| pb::SolveIkBatchRequest {
                    robot: Some(robot),
                    targets: targets.clone(),
                    seed: seed.to_vec(),
                    options: Some(options),
                    seeds: None,
                },
                |ch, req| async move { KinematicsServiceClient::new(ch).solve_ik_batch(req).await },
                |r| &r.model_id,
            )
            .await?;
        r.results.into_iter().map(IkAnswer::from_proto).collect()
    }
}
