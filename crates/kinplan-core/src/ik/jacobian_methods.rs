//! Jacobian inverse, Levenberg–Marquardt and Newton iterations (S2 §3.1,
//! docs/inverse-kinematics.md#jacobian-methods), each with the SVD pseudoinverse or angle relaxation as the
//! linear solver. One attempt from the joints in the workspace.
//!
//! With the geometric Jacobian `J(q)` (rows: linear, angular velocity, base frame; only
//! the 3 linear rows for position targets) and the pose error `e(q)`:
//! - Jacobian inverse (S2 eq. 33/35): solve `J Δq = e`, `q ← q + Δq`.
//! - Levenberg–Marquardt (S2 eq. 36/37): solve `[J; √μ I] Δq = [e; 0]`. With SVD this is
//!   `Δq = Σ σᵢ/(σᵢ² + μ) vᵢ uᵢᵀ e`, the same least-squares solution without forming
//!   `JᵀJ`; with RLXA the augmented system itself is relaxed.
//! - Newton (S2 eq. 29/30 with `f = −e`): solve `J q_{k+1} = J q_k + e` for `q_{k+1}`
//!   (a fresh solve from zero; for redundant chains the pseudoinverse drops the null-space
//!   part of `q_k` — faithful to the source, which found it poor with RLXA).
//!
//! Every step is scaled so `max|Δqᵢ| ≤ max_step`, then clamped into the limits.
//!
//! Joint limits (`JointLimitMode::Clamp`, not Newton): the step is solved over the free
//! joints, as in a projected Newton method (Bertsekas 1982). Before the solve, a joint on
//! a limit whose descent direction `(Jᵀe)ₖ` points outward is bound (its column of `J`
//! zeroed); after it, a joint on a limit whose step still points outward is bound too
//! and the step re-solved. Binding by the gradient first saves most of the re-solves on
//! arms that often meet a limit, such as the Panda (`benches/IK_RESULTS.md`).

use nalgebra::Isometry3;
use rand_chacha::ChaCha8Rng;

use super::attempt::{Attempt, Clock, Progress, stop_before_iteration};
use super::workspace::IkWorkspace;
use super::{IkMethod, IkParams, IkStatus, IkTarget, JointLimitMode, PoseError, pose_error};
use crate::linalg::{LinearSolverKind, RlxaParams, SvdWorkspace};
use crate::robot::Chain;

const MU_MAX: f64 = 1e8;
/// Progress that resets the stall counter: the squared error must fall below this
/// fraction of its value at the last reset (≈ 5 % on the error norm). Was 0.99; 0.9 ends
/// failed attempts (typically creeping along a joint limit) sooner, which cuts
/// iterations per target on the benchmark arms at equal success
/// (`benches/IK_RESULTS.md` §0).
const STALL_PROGRESS: f64 = 0.9;
/// Orthogonality tolerance of the Jacobi SVD behind each Jacobian-inverse and LM step
/// (see [`SvdWorkspace::with_orthogonality`]): a step accurate to ~1e-4 relative
/// converges as fast as an exact one (identical iteration counts on every benchmark arm
/// at 1e-4 and 1e-3; 1e-2 costs more) and needs fewer sweeps than the
/// default 1e-10. Newton keeps the default.
pub(crate) const STEP_ORTHOGONALITY: f64 = 1e-4;

pub(crate) fn run(
    chain: &Chain,
    target: &IkTarget,
    params: &IkParams,
    ws: &mut IkWorkspace,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) -> Attempt {
    let n = chain.dof();
    let task = target.task_dim();
    let lm = params.method == IkMethod::LevenbergMarquardt;
    let rlxa = params.linear_solver == LinearSolverKind::AngleRelaxation;
    let rows = if lm && rlxa { task + n } else { task };
    ws.ensure_system(rows, n);
    // Inexact steps are fine when the unknown is the step (JI, LM), not when it is the
    // new iterate (Newton): see SvdWorkspace::with_orthogonality.
    ws.svd.set_orthogonality(if params.method == IkMethod::Newton {
        SvdWorkspace::DEFAULT_ORTHOGONALITY
    } else {
        STEP_ORTHOGONALITY
    });
    IkWorkspace::apply_limits(&ws.limits, params.joint_limits, &mut ws.q);

    let mut tip: Isometry3<f64> = chain.jacobian_into(&ws.q, &mut ws.jac);
    let mut err = pose_error(&tip, target);
    let mut best = err;
    ws.q_best.copy_from_slice(&ws.q);
    let mut progress = Progress::new(STALL_PROGRESS, params.stall_iterations, err.squared());
    let mu_min = params.damping * 1e-4;
    let mut mu = params.damping;
    // true while ws.svd holds the decomposition of the current J (LM retries reuse it)
    let mut decomposed = false;
    let inner: RlxaParams = params.rlxa;

    let mut it = 0;
    let status = loop {
        ws.record(params, &err);
        if let Some(s) = stop_before_iteration(&err, target, params, it, clock) {
            break s;
        }
        it += 1;

        // Assemble and solve the linear system for the step ws.x (Δq).
        match (params.method, rlxa) {
            (IkMethod::JacobianInverse | IkMethod::LevenbergMarquardt, false) => {
                if !decomposed {
                    copy_task_rows(ws, task, n);
                    if params.joint_limits == JointLimitMode::Clamp {
                        bind_by_gradient(ws, &err, task, n);
                    }
                    // Warm start from the last right singular vectors (any orthogonal
                    // start is valid for one-sided Jacobi; the solver resets V per request).
                    ws.svd.decompose_warm(&ws.a);
                    decomposed = true;
                }
                for r in 0..task {
                    ws.b[r] = err.e[r];
                }
                let damping = if lm { mu } else { 0.0 };
                ws.svd
                    .solve_decomposed(&ws.b, damping, params.singular_value_tolerance, &mut ws.x);
            }
            (IkMethod::Newton, false) => {
                copy_task_rows(ws, task, n);
                fill_newton_rhs(ws, &err, task, n);
                ws.svd.decompose_warm(&ws.a);
                ws.svd
                    .solve_decomposed(&ws.b, 0.0, params.singular_value_tolerance, &mut ws.x);
                for k in 0..n {
                    ws.x[k] -= ws.q[k];
                }
            }
            (IkMethod::JacobianInverse | IkMethod::LevenbergMarquardt, true) => {
                copy_task_rows(ws, task, n);
                if params.joint_limits == JointLimitMode::Clamp {
                    bind_by_gradient(ws, &err, task, n);
                }
                for r in 0..task {
                    ws.b[r] = err.e[r];
                }
                if lm {
                    let s = mu.sqrt();
                    for r in 0..n {
                        for c in 0..n {
                            ws.a[(task + r, c)] = if r == c { s } else { 0.0 };
                        }
                        ws.b[task + r] = 0.0;
                    }
                }
                ws.x.fill(0.0);
                let _ = ws.rlxa.solve_into(&ws.a, &ws.b, &mut ws.x, &inner, rng, None);
            }
            (IkMethod::Newton, true) => {
                copy_task_rows(ws, task, n);
                fill_newton_rhs(ws, &err, task, n);
                ws.x.fill(0.0);
                let _ = ws.rlxa.solve_into(&ws.a, &ws.b, &mut ws.x, &inner, rng, None);
                for k in 0..n {
                    ws.x[k] -= ws.q[k];
                }
            }
            _ => unreachable_method(),
        }

        // Active set: a joint sitting on a limit whose step points further out is locked
        // (its column zeroed) and the step re-solved, so clamping does not stall LM.
        if params.joint_limits == JointLimitMode::Clamp
            && params.method != IkMethod::Newton
            && lock_limited_columns(ws, task, n)
        {
            if rlxa {
                ws.x.fill(0.0);
                let _ = ws.rlxa.solve_into(&ws.a, &ws.b, &mut ws.x, &inner, rng, None);
            } else {
                ws.svd.decompose_warm(&ws.a);
                let damping = if lm { mu } else { 0.0 };
                ws.svd
                    .solve_decomposed(&ws.b, damping, params.singular_value_tolerance, &mut ws.x);
            }
        }

        // Step limit, trial point, limits.
        let largest = ws.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale = if largest.is_finite() && largest > params.max_step {
            params.max_step / largest
        } else {
            1.0
        };
        if !largest.is_finite() {
            ws.x.fill(0.0);
        }
        for k in 0..n {
            ws.q_trial[k] = ws.q[k] + scale * ws.x[k];
        }
        IkWorkspace::apply_limits_wrapping(&ws.limits, &ws.wraps, params.joint_limits, &mut ws.q_trial);

        if lm && params.adaptive_damping {
            let trial_tip = chain.jacobian_into(&ws.q_trial, &mut ws.jac_trial);
            let trial_err = pose_error(&trial_tip, target);
            if trial_err.squared() < err.squared() {
                std::mem::swap(&mut ws.q, &mut ws.q_trial);
                std::mem::swap(&mut ws.jac, &mut ws.jac_trial);
                mu = (mu * 0.1).max(mu_min);
                tip = trial_tip;
                err = trial_err;
                decomposed = false;
            } else {
                mu *= 10.0;
                if mu > MU_MAX {
                    break IkStatus::Stalled;
                }
            }
        } else {
            std::mem::swap(&mut ws.q, &mut ws.q_trial);
            tip = chain.jacobian_into(&ws.q, &mut ws.jac);
            err = pose_error(&tip, target);
            decomposed = false;
        }

        if err.squared() < best.squared() {
            best = err;
            ws.q_best.copy_from_slice(&ws.q);
        }
        if progress.stalled(err.squared()) {
            break IkStatus::Stalled;
        }
    };
    let _ = tip;
    if status != IkStatus::Converged && best.squared() < err.squared() {
        ws.q.copy_from_slice(&ws.q_best);
        err = best;
    }
    Attempt {
        status,
        iterations: it,
        error: err,
    }
}

/// Binding set before the solve: a joint on a limit whose descent direction of `½‖e‖²`,
/// `gₖ = (Jᵀe)ₖ`, points outward (projected Newton).
fn bind_by_gradient(ws: &mut IkWorkspace, err: &PoseError, task: usize, n: usize) {
    bind_outward(ws, task, n, |ws, k| {
        (0..task).map(|r| ws.a[(r, k)] * err.e[r]).sum()
    });
}

/// Binding set after the solve: a joint on a limit whose step `Δqₖ` points outward.
/// Returns whether any column was bound.
fn lock_limited_columns(ws: &mut IkWorkspace, task: usize, n: usize) -> bool {
    bind_outward(ws, task, n, |ws, k| ws.x[k])
}

/// Zeroes the task rows of column `k` for every joint `k` on a limit whose
/// `direction(ws, k)` points out of its range; true when any column was zeroed.
fn bind_outward(
    ws: &mut IkWorkspace,
    task: usize,
    n: usize,
    direction: impl Fn(&IkWorkspace, usize) -> f64,
) -> bool {
    let mut any = false;
    for k in 0..n {
        let (lo, hi) = ws.limits[k];
        let (at_lo, at_hi) = (ws.q[k] <= lo, ws.q[k] >= hi);
        if !(at_lo || at_hi) {
            continue;
        }
        let d = direction(ws, k);
        if (at_lo && d < 0.0) || (at_hi && d > 0.0) {
            for r in 0..task {
                ws.a[(r, k)] = 0.0;
            }
            any = true;
        }
    }
    any
}

#[inline]
fn copy_task_rows(ws: &mut IkWorkspace, task: usize, n: usize) {
    for c in 0..n {
        for r in 0..task {
            ws.a[(r, c)] = ws.jac[(r, c)];
        }
    }
}

/// `b = J q + e` (S2 eq. 30 with `f(q) = −e(q)`).
#[inline]
fn fill_newton_rhs(ws: &mut IkWorkspace, err: &PoseError, task: usize, n: usize) {
    for r in 0..task {
        let mut s = err.e[r];
        for c in 0..n {
            s += ws.jac[(r, c)] * ws.q[c];
        }
        ws.b[r] = s;
    }
}

#[cold]
fn unreachable_method() {}
