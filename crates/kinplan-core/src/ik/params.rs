//! Parameters of an IK request, with units, defaults and validation.

use std::time::Duration;

use super::analytic::AnalyticParams;
use super::{IkError, IkParam};
use crate::linalg::{LinearSolverKind, RlxaParams};

/// IK algorithm (docs/inverse-kinematics.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum IkMethod {
    /// `J Δq = e`, `q ← q + Δq` (S2 eq. 33/35).
    JacobianInverse,
    /// Damped least squares `[J; √μ I] Δq = [e; 0]` (S2 eq. 36/37).
    #[default]
    LevenbergMarquardt,
    /// `J(q_k) q_{k+1} = J(q_k) q_k + e(q_k)` (S2 eq. 29/30, `f = −e`).
    Newton,
    /// Cyclic coordinate descent, any serial chain, position or pose.
    Ccd,
    /// FABRIK (Aristidou & Lasenby 2011), revolute chains, position targets.
    Fabrik,
    /// Length relaxation (S2 §4.1), revolute chains, position targets.
    LengthRelaxation,
    /// Closed form by subproblem decomposition ([`analytic`](super::analytic)):
    /// every solution, 6R arms of the covered families, pose targets.
    Analytic,
}

impl IkMethod {
    /// The method's name on the wire and in the Python client
    /// ("jacobian_inverse", "lm", "newton", "ccd", "fabrik", "length_relaxation", "analytic").
    pub fn name(self) -> &'static str {
        match self {
            IkMethod::JacobianInverse => "jacobian_inverse",
            IkMethod::LevenbergMarquardt => "lm",
            IkMethod::Newton => "newton",
            IkMethod::Ccd => "ccd",
            IkMethod::Fabrik => "fabrik",
            IkMethod::LengthRelaxation => "length_relaxation",
            IkMethod::Analytic => "analytic",
        }
    }

    /// True for the three methods that take a [`LinearSolverKind`].
    pub fn is_jacobian_method(self) -> bool {
        matches!(
            self,
            IkMethod::JacobianInverse | IkMethod::LevenbergMarquardt | IkMethod::Newton
        )
    }
}

/// What to do with joint limits during the iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum JointLimitMode {
    /// Clamp every iterate into `[lower, upper]` (restarts are drawn inside too).
    #[default]
    Clamp,
    /// Ignore limits while iterating (restarts are still drawn inside the limits).
    Ignore,
}

/// Options of [`solve_ik`](super::solve_ik). Tolerances are checked on the true FK of the result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkParams {
    /// Algorithm. Default Levenberg–Marquardt.
    pub method: IkMethod,
    /// Linear solver of the Jacobian methods. Default SVD pseudoinverse.
    pub linear_solver: LinearSolverKind,
    /// Converged when `‖p* − p‖ ≤ position_tolerance` (m, > 0). Default 1e-5.
    pub position_tolerance: f64,
    /// … and the rotation angle of `R* Rᵀ` ≤ `orientation_tolerance` (rad, > 0; ignored for
    /// position targets). Default 1e-5.
    pub orientation_tolerance: f64,
    /// Iterations per attempt (count ≥ 1). One iteration = one linear solve (Jacobian
    /// methods), one tip-to-root sweep (CCD) or one forward+backward pass (FABRIK, length
    /// relaxation). Default 100.
    pub max_iterations: usize,
    /// Levenberg–Marquardt damping μ (≥ 0; units of `σ²` of the Jacobian: m² and
    /// dimensionless mixed). With `adaptive_damping` it is the starting value. Default 1e-3.
    pub damping: f64,
    /// Adapt μ (×0.1 after an accepted step, ×10 and retry after a rejected one, within
    /// `[damping·1e-4, 1e8]`). When false μ is fixed and every step is taken (S2). Default true.
    pub adaptive_damping: bool,
    /// Largest `|Δq_i|` per iteration (rad or m, > 0); larger steps are scaled down
    /// uniformly. Default 1.0.
    pub max_step: f64,
    /// Singular values below this fraction of the largest are dropped by the SVD solver
    /// (dimensionless, ≥ 0). Default 1e-8.
    pub singular_value_tolerance: f64,
    /// Inner RLXA options when `linear_solver` is angle relaxation. Default: 300
    /// iterations, stop at 5 % of `‖e‖`, faithful.
    pub rlxa: RlxaParams,
    /// Joint-limit handling. Default clamp.
    pub joint_limits: JointLimitMode,
    /// Random restarts after the seeded attempt (count). Default 200.
    pub max_restarts: usize,
    /// Distinct converged solutions wanted (count ≥ 1). Default 1.
    pub num_solutions: usize,
    /// Two solutions are the same when every joint differs by less than this (rad or m, > 0). Default 1e-3.
    pub distinct_tolerance: f64,
    /// End an attempt early when the error has not made progress over this many
    /// iterations (count; 0 disables). Progress = squared error below 0.9× its value at
    /// the last reset for the Jacobian methods, 0.99× for CCD (which uses 10× this count),
    /// FABRIK and length relaxation. Default 6.
    pub stall_iterations: usize,
    /// Wall-clock budget of one solve (s), counted from its start; `None` = no
    /// limit. The solver stops at this budget or at the caller's
    /// [`Deadline`](crate::Deadline), whichever comes first. Default none.
    pub time_budget: Option<Duration>,
    /// Record each solution's error at the start of every iteration of its attempt
    /// ([`IkSolution::history`](super::IkSolution::history)). Default off (nothing is
    /// recorded, nothing allocated).
    pub record_history: bool,
    /// Options of the analytic method (tolerances, whole turns, holding the
    /// seed's configuration). Default [`AnalyticParams::default`].
    pub analytic: AnalyticParams,
    /// Iterative methods, pose targets: start the first attempt from the analytic
    /// solution nearest the seed when the chain has one (else from the seed).
    /// Default false.
    pub analytic_start: bool,
}

impl Default for IkParams {
    fn default() -> Self {
        Self {
            method: IkMethod::LevenbergMarquardt,
            linear_solver: LinearSolverKind::SvdPseudoinverse,
            position_tolerance: 1e-5,
            orientation_tolerance: 1e-5,
            max_iterations: 100,
            damping: 1e-3,
            adaptive_damping: true,
            max_step: 1.0,
            singular_value_tolerance: 1e-8,
            rlxa: RlxaParams {
                max_iterations: 300,
                tolerance: 1e-14,
                relative_tolerance: 0.05,
                ..RlxaParams::default()
            },
            joint_limits: JointLimitMode::Clamp,
            max_restarts: 200,
            num_solutions: 1,
            distinct_tolerance: 1e-3,
            stall_iterations: 6,
            time_budget: None,
            record_history: false,
            analytic: AnalyticParams::default(),
            analytic_start: false,
        }
    }
}

fn positive(field: IkParam, value: f64) -> Result<(), IkError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(IkError::InvalidParam {
            field,
            value,
            reason: "must be finite and > 0",
        })
    }
}

fn non_negative(field: IkParam, value: f64) -> Result<(), IkError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(IkError::InvalidParam {
            field,
            value,
            reason: "must be finite and >= 0",
        })
    }
}

impl IkParams {
    /// Rejects zero tolerances, NaN, zero caps, …, naming the field.
    pub fn validate(&self) -> Result<(), IkError> {
        positive(IkParam::PositionTolerance, self.position_tolerance)?;
        positive(IkParam::OrientationTolerance, self.orientation_tolerance)?;
        if self.max_iterations == 0 {
            return Err(IkError::InvalidParam {
                field: IkParam::MaxIterations,
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        non_negative(IkParam::Damping, self.damping)?;
        positive(IkParam::MaxStep, self.max_step)?;
        non_negative(IkParam::SingularValueTolerance, self.singular_value_tolerance)?;
        if self.num_solutions == 0 {
            return Err(IkError::InvalidParam {
                field: IkParam::NumSolutions,
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        positive(IkParam::DistinctTolerance, self.distinct_tolerance)?;
        if let Some(b) = self.time_budget
            && b.is_zero()
        {
            return Err(IkError::InvalidParam {
                field: IkParam::TimeBudget,
                value: 0.0,
                reason: "must be > 0 when set",
            });
        }
        if self.method == IkMethod::Analytic || self.analytic_start {
            self.analytic.validate()?;
        }
        if self.method.is_jacobian_method() && self.linear_solver == LinearSolverKind::AngleRelaxation {
            self.rlxa.validate()?;
        }
        Ok(())
    }
}
