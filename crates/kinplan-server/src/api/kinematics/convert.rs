//! `KinematicsService` messages ↔ the ik and linalg rooms: IkOptions and
//! targets in (method, solver, tolerances, restarts, the explicit time
//! budget), TrackPath's poses (explicit, or a line or circle sampled into
//! steps), domain answers out as replies.

use std::time::Duration;

use nalgebra::{Isometry3, Point3};
use tonic::Status;

use crate::api::convert::{pose_in, pose_out, vec3_in};
use crate::pb;
use crate::status::ik::{IkAt, PathAt, ik_error};
use crate::status::linalg::{SolveAt, linalg_error};
use crate::status::{invalid, too_large};
use kinplan_core::ik::analytic::{AnalyticParams, ConfigFlags, Turns};
use kinplan_core::ik::{
    IkMethod, IkParams, IkResult, IkSolution, IkStatus, IkTarget, JointLimitMode, TrackResult, circle_path,
    line_path,
};
use kinplan_core::linalg::{
    LinearSolution, LinearSolverKind, PseudoinverseParams, RlxaParams, RlxaVariant, SolveStatus,
};
use kinplan_core::robot::Chain;

/// Most poses of a `TrackPath` (explicit poses, or line/circle steps): the reply
/// then stays under ~9 MB for a 7-joint arm (the default message limit is 16 MB).
pub const MAX_PATH_POSES: usize = 50_000;
/// Most solutions one target may ask for.
pub const MAX_SOLUTIONS: u32 = 1_000;
/// Most RLXA work (iteration cap × m × n) of one `SolveLinearSystem`; the
/// solve also stops at the deadline (checked every 1024 iterations).
pub const MAX_RLXA_WORK: u64 = 1_000_000_000;
/// Most iterations of a `SolveLinearSystem` that records its residual history
/// (8 bytes each in the reply, so at most 8 MB): bounded up front.
pub const MAX_LINEAR_HISTORY: usize = 1_000_000;
/// Most RLXA iterations inside one IK iteration (`options.rlxa_max_iterations`):
/// the IK loop checks its deadline between iterations.
pub const MAX_IK_RLXA_ITERATIONS: u32 = 100_000;

/// The solver of a `SolveLinearSystem`, with its options (and the RLXA seed).
pub(super) enum LinearSolve {
    Svd(PseudoinverseParams),
    Rlxa(RlxaParams, u64),
}

/// The IK options of a request in domain form.
#[derive(Debug, Clone, Copy)]
pub(super) struct Options {
    pub(super) params: IkParams,
    pub(super) position_only: bool,
    pub(super) rng_seed: u64,
}

impl Options {
    /// Unset fields take the documented defaults; ranges are checked by
    /// [`IkParams::validate`], whose field names are the proto's.
    /// `default_restarts` replaces the domain's default restart count when set.
    pub(super) fn from_proto(
        o: Option<&pb::IkOptions>,
        default_restarts: Option<usize>,
    ) -> Result<Self, Status> {
        let o = o.cloned().unwrap_or_default();
        let d = IkParams::default();
        let method = match pb::IkMethod::try_from(o.method) {
            Ok(pb::IkMethod::Unspecified | pb::IkMethod::LevenbergMarquardt) => IkMethod::LevenbergMarquardt,
            Ok(pb::IkMethod::JacobianInverse) => IkMethod::JacobianInverse,
            Ok(pb::IkMethod::Newton) => IkMethod::Newton,
            Ok(pb::IkMethod::Ccd) => IkMethod::Ccd,
            Ok(pb::IkMethod::Fabrik) => IkMethod::Fabrik,
            Ok(pb::IkMethod::LengthRelaxation) => IkMethod::LengthRelaxation,
            Ok(pb::IkMethod::Analytic) => IkMethod::Analytic,
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
            max_restarts: o
                .max_restarts
                .map_or(default_restarts.unwrap_or(d.max_restarts), |n| n as usize),
            num_solutions: (o.num_solutions as usize).max(1),
            distinct_tolerance: o.distinct_tolerance.unwrap_or(d.distinct_tolerance),
            time_budget,
            record_history: o.return_history,
            analytic_start: o.analytic_start,
            analytic: AnalyticParams {
                // warm calls (TrackPath, StreamIk) pass their restart default and
                // hold the previous answer's configuration unless told otherwise
                hold_configuration: o.hold_configuration.unwrap_or(default_restarts.is_some()),
                turns: if o.nearest_turn_only {
                    Turns::NearestSeed
                } else {
                    Turns::All
                },
                redundant_joint: o.redundant_joint.map(|j| j as usize),
                search_redundant: o.search_redundant,
                redundant_samples: match o.redundant_samples {
                    None | Some(0) => d.analytic.redundant_samples,
                    Some(n) => n as usize,
                },
                search_samples: match o.search_samples {
                    None | Some(0) => d.analytic.search_samples,
                    Some(n) => n as usize,
                },
                ..d.analytic
            },
            ..d
        };
        params.validate().map_err(|e| ik_error(e, IkAt::Target))?;
        Ok(Self {
            params,
            position_only: o.position_only,
            rng_seed: o.rng_seed,
        })
    }
}

/// The solver a `SolveLinearSystem` asks for, with its options (unset fields
/// take the documented defaults), checked against the work limits for a
/// matrix of `entries` entries.
pub(super) fn linear_solve_in(
    req: &pb::SolveLinearSystemRequest,
    entries: usize,
) -> Result<LinearSolve, Status> {
    Ok(match linear_solver_in("method", req.method)? {
        None => {
            let params = PseudoinverseParams {
                relative_tolerance: req
                    .singular_value_tolerance
                    .unwrap_or(PseudoinverseParams::default().relative_tolerance),
            };
            params
                .validate()
                .map_err(|e| linalg_error(e, SolveAt::LinearSystem))?;
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
            params
                .validate()
                .map_err(|e| linalg_error(e, SolveAt::LinearSystem))?;
            if params.record_history && params.max_iterations > MAX_LINEAR_HISTORY {
                return Err(too_large(
                    "max_iterations",
                    format!(
                        "{} iterations with record_history exceed the history limit of {MAX_LINEAR_HISTORY}",
                        params.max_iterations
                    ),
                ));
            }
            let work = (params.max_iterations as u64).saturating_mul(entries as u64);
            if work > MAX_RLXA_WORK {
                return Err(invalid(
                    "max_iterations",
                    format!(
                        "{} iterations on {} entries exceed the work limit of {MAX_RLXA_WORK} \
                         (iterations x rows x cols)",
                        params.max_iterations, entries
                    ),
                ));
            }
            LinearSolve::Rlxa(params, req.rng_seed)
        }
    })
}

/// `None` for the SVD pseudoinverse, the RLXA variant otherwise.
pub(super) fn linear_solver_in(field: &str, value: i32) -> Result<Option<RlxaVariant>, Status> {
    match pb::LinearSolver::try_from(value) {
        Ok(pb::LinearSolver::Unspecified | pb::LinearSolver::SvdPseudoinverse) => Ok(None),
        Ok(pb::LinearSolver::AngleRelaxation) => Ok(Some(RlxaVariant::Faithful)),
        Ok(pb::LinearSolver::AngleRelaxationSafeguarded) => Ok(Some(RlxaVariant::Safeguarded)),
        Err(_) => Err(invalid(field, format!("unknown value {value}"))),
    }
}

pub(super) fn target_of(pose: &Isometry3<f64>, position_only: bool) -> IkTarget {
    if position_only {
        IkTarget::Position(Point3::from(pose.translation.vector))
    } else {
        IkTarget::Pose(*pose)
    }
}

pub(super) fn target_in(
    field: &str,
    pose: Option<&pb::Pose>,
    position_only: bool,
) -> Result<IkTarget, Status> {
    Ok(target_of(&pose_in(field, pose)?, position_only))
}

pub(super) fn micros(d: Duration) -> u64 {
    d.as_micros().min(u64::MAX as u128) as u64
}

pub(super) fn status_out(s: IkStatus) -> i32 {
    (match s {
        IkStatus::Converged => pb::IkStatus::Converged,
        IkStatus::MaxIterations => pb::IkStatus::MaxIterations,
        IkStatus::Stalled => pb::IkStatus::Stalled,
        IkStatus::TimeBudget => pb::IkStatus::TimeBudget,
        IkStatus::Cancelled => pb::IkStatus::Cancelled,
    }) as i32
}

pub(super) fn solution_out(s: IkSolution) -> pb::IkSolution {
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
        config: s.config.map(config_out),
        singular: s.singular,
    }
}

pub(super) fn config_out(c: ConfigFlags) -> pb::ConfigFlags {
    pb::ConfigFlags {
        shoulder_back: c.shoulder_back,
        elbow_down: c.elbow_down,
        wrist_flipped: c.wrist_flipped,
    }
}

pub(super) fn result_out(r: IkResult) -> pb::SolveIkResponse {
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

pub(super) fn track_out(
    r: TrackResult,
    poses: &[Isometry3<f64>],
    model_id: Vec<u8>,
) -> pb::TrackPathResponse {
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

pub(super) fn linear_out(s: LinearSolution, elapsed: Duration) -> pb::SolveLinearSystemResponse {
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

/// The poses of a `TrackPath` and the field they came from.
pub(super) fn path_in(
    poses: &[pb::Pose],
    line: Option<&pb::LinePath>,
    circle: Option<&pb::CirclePath>,
    chain: &Chain,
    seed: &[f64],
) -> Result<(Vec<Isometry3<f64>>, PathAt), Status> {
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
        let path = line_path(&s, &e, n).map_err(|e| ik_error(e, IkAt::Path(PathAt::Line)))?;
        return Ok((path, PathAt::Line));
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
            .map_err(|e| ik_error(e, IkAt::Path(PathAt::Circle)))?;
        return Ok((path, PathAt::Circle));
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
    Ok((path, PathAt::Poses))
}
