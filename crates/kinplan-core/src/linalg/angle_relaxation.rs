//! Angle relaxation (RLXA), the randomised iterative solver of S2 §2
//! (docs/linear-solvers.md#angle-relaxation-rlxa).

use nalgebra::{DMatrix, DVector};
use rand::Rng;

use super::pseudoinverse::check_system;
use super::{LinalgError, LinalgParam, LinearSolution, SolveStatus};
use crate::Deadline;

/// Faithful RLXA, or the safeguarded variant (reported separately).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum RlxaVariant {
    /// Exactly S2 §2: every random step is taken.
    #[default]
    Faithful,
    /// Not in S2: when a step would increase `‖r‖`, `λ` is halved (up to 30 times;
    /// if the residual still grows the step is skipped).
    Safeguarded,
}

/// Options of [`solve_angle_relaxation`] / [`RlxaWorkspace`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RlxaParams {
    /// Iteration cap (count ≥ 1). Default 20 000 (S2 Tab. 2/3).
    pub max_iterations: usize,
    /// Stop when `‖b − A x‖₂ < tolerance` (units of `b`, > 0). Default 0.01 (S2).
    pub tolerance: f64,
    /// Also stop when `‖b − A x‖₂ < relative_tolerance · ‖b‖₂` (dimensionless, ≥ 0;
    /// 0 disables it). Default 0.
    pub relative_tolerance: f64,
    /// Faithful or safeguarded. Default faithful.
    pub variant: RlxaVariant,
    /// Columns with `‖aⱼ‖ ≤ zero_column_tolerance` are skipped (`xⱼ` untouched). Default 1e-12.
    pub zero_column_tolerance: f64,
    /// Record `‖r‖` after every iteration in [`LinearSolution::history`]. Default false.
    pub record_history: bool,
}

impl Default for RlxaParams {
    fn default() -> Self {
        Self {
            max_iterations: 20_000,
            tolerance: 0.01,
            relative_tolerance: 0.0,
            variant: RlxaVariant::Faithful,
            zero_column_tolerance: 1e-12,
            record_history: false,
        }
    }
}

impl RlxaParams {
    /// Rejects a zero iteration cap, a non-positive or non-finite tolerance, …
    pub fn validate(&self) -> Result<(), LinalgError> {
        if self.max_iterations == 0 {
            return Err(LinalgError::InvalidParam {
                field: LinalgParam::MaxIterations,
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(LinalgError::InvalidParam {
                field: LinalgParam::Tolerance,
                value: self.tolerance,
                reason: "must be finite and > 0",
            });
        }
        if !(self.relative_tolerance.is_finite() && self.relative_tolerance >= 0.0) {
            return Err(LinalgError::InvalidParam {
                field: LinalgParam::RelativeTolerance,
                value: self.relative_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        if !(self.zero_column_tolerance.is_finite() && self.zero_column_tolerance >= 0.0) {
            return Err(LinalgError::InvalidParam {
                field: LinalgParam::ZeroColumnTolerance,
                value: self.zero_column_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }
}

/// Outcome of one [`RlxaWorkspace::solve_into`] call (the solution is written in place).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RlxaReport {
    pub iterations: usize,
    pub residual_norm: f64,
    pub status: SolveStatus,
}

/// Reusable buffers for RLXA on m×n systems (no allocation per call once sized).
#[derive(Debug, Clone)]
pub struct RlxaWorkspace {
    r: DVector<f64>,
    r_trial: DVector<f64>,
    inv_norm: DVector<f64>,
    step: DVector<f64>,
}

impl RlxaWorkspace {
    pub fn new(rows: usize, cols: usize) -> Self {
        Self {
            r: DVector::zeros(rows),
            r_trial: DVector::zeros(rows),
            inv_norm: DVector::zeros(cols),
            step: DVector::zeros(cols),
        }
    }

    fn ensure(&mut self, rows: usize, cols: usize) {
        if self.r.len() != rows {
            self.r = DVector::zeros(rows);
            self.r_trial = DVector::zeros(rows);
        }
        if self.inv_norm.len() != cols {
            self.inv_norm = DVector::zeros(cols);
            self.step = DVector::zeros(cols);
        }
    }

    /// Runs RLXA on `A x = b` starting from the `x` passed in (resized to zeros if its
    /// length is wrong) and leaves the last iterate in `x`.
    ///
    /// One iteration with `r = b − A x` (S2 eq. 1, 9–11, 26, Fig. 6):
    /// `λ ~ U(0,1)`, `x ← x + (λ‖r‖/n') · N · sign(Aᵀ r)` with `N = diag(1/‖aⱼ‖)`
    /// over the `n'` non-zero columns (zero columns carry no information and are skipped;
    /// the improper solution is split among the `n'` columns that can take a part),
    /// then `r ← r − A Δx`.
    /// `history`, when given, receives `‖r‖` after each iteration.
    pub fn solve_into<R: Rng + ?Sized>(
        &mut self,
        a: &DMatrix<f64>,
        b: &DVector<f64>,
        x: &mut DVector<f64>,
        params: &RlxaParams,
        rng: &mut R,
        history: Option<&mut Vec<f64>>,
    ) -> Result<RlxaReport, LinalgError> {
        self.solve_into_until(a, b, x, params, rng, history, Deadline::none())
    }

    /// [`RlxaWorkspace::solve_into`], polling `deadline` every
    /// [`STOP_CHECK_WORK`] / (m·n) iterations; a stopped solve reports
    /// [`SolveStatus::IterationCap`] with the iterations done.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_into_until<R: Rng + ?Sized>(
        &mut self,
        a: &DMatrix<f64>,
        b: &DVector<f64>,
        x: &mut DVector<f64>,
        params: &RlxaParams,
        rng: &mut R,
        mut history: Option<&mut Vec<f64>>,
        deadline: Deadline<'_>,
    ) -> Result<RlxaReport, LinalgError> {
        params.validate()?;
        check_system(a, b)?;
        let (m, n) = a.shape();
        self.ensure(m, n);
        if x.len() != n || x.iter().any(|v| !v.is_finite()) {
            *x = DVector::zeros(n);
        }
        let mut active = 0usize;
        for j in 0..n {
            let norm = a.column(j).norm();
            if norm > params.zero_column_tolerance {
                self.inv_norm[j] = 1.0 / norm;
                active += 1;
            } else {
                self.inv_norm[j] = 0.0;
            }
        }
        // r = b − A x
        self.r.copy_from(b);
        self.r.gemv(-1.0, a, x, 1.0);
        let mut rn = self.r.norm();
        let threshold = params.tolerance.max(params.relative_tolerance * b.norm());
        if active == 0 {
            let status = if rn < threshold {
                SolveStatus::Converged
            } else {
                SolveStatus::IterationCap
            };
            return Ok(RlxaReport {
                iterations: 0,
                residual_norm: rn,
                status,
            });
        }
        let n_parts = active as f64;
        // Cost-bounded: about STOP_CHECK_WORK matrix entries touched between checks.
        let check_every = (STOP_CHECK_WORK / (m * n).max(1)).max(1);
        let mut it = 0;
        while it < params.max_iterations {
            if it % check_every == check_every - 1 && deadline.expired() {
                break;
            }
            if rn < threshold {
                return Ok(RlxaReport {
                    iterations: it,
                    residual_norm: rn,
                    status: SolveStatus::Converged,
                });
            }
            it += 1;
            // direction g = N sign(Aᵀ r)
            for j in 0..n {
                let inv = self.inv_norm[j];
                self.step[j] = if inv == 0.0 {
                    0.0
                } else {
                    let d = a.column(j).dot(&self.r);
                    if d > 0.0 {
                        inv
                    } else if d < 0.0 {
                        -inv
                    } else {
                        0.0
                    }
                };
            }
            let lambda = sample_open_unit(rng);
            let mut scale = lambda * rn / n_parts;
            match params.variant {
                RlxaVariant::Faithful => {
                    x.axpy(scale, &self.step, 1.0);
                    self.r.gemv(-scale, a, &self.step, 1.0);
                    rn = self.r.norm();
                }
                RlxaVariant::Safeguarded => {
                    let mut accepted = false;
                    for _ in 0..30 {
                        self.r_trial.copy_from(&self.r);
                        self.r_trial.gemv(-scale, a, &self.step, 1.0);
                        let trial = self.r_trial.norm();
                        if trial <= rn {
                            x.axpy(scale, &self.step, 1.0);
                            std::mem::swap(&mut self.r, &mut self.r_trial);
                            rn = trial;
                            accepted = true;
                            break;
                        }
                        scale *= 0.5;
                    }
                    let _ = accepted;
                }
            }
            // Refresh the residual now and then against rounding drift.
            if it % 256 == 0 {
                self.r.copy_from(b);
                self.r.gemv(-1.0, a, x, 1.0);
                rn = self.r.norm();
            }
            if let Some(h) = history.as_deref_mut() {
                h.push(rn);
            }
            if !rn.is_finite() {
                break;
            }
        }
        let status = if rn < threshold {
            SolveStatus::Converged
        } else {
            SolveStatus::IterationCap
        };
        Ok(RlxaReport {
            iterations: it,
            residual_norm: rn,
            status,
        })
    }
}

/// Matrix entries touched (iterations × m·n) between two cancellation checks:
/// a check costs one clock read, so this keeps checks cheap and prompt.
pub const STOP_CHECK_WORK: usize = 4096;

/// λ uniform in the open interval (0, 1).
fn sample_open_unit<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    loop {
        let v: f64 = rng.random();
        if v > 0.0 {
            return v;
        }
    }
}

/// Solves `A x = b` (any m×n, any rank) by angle relaxation from `x₀ = 0`.
///
/// Iteration (S2 §2, Fig. 6; docs/linear-solvers.md#angle-relaxation-rlxa): with
/// `r = b − A x` and `λ ~ U(0,1)` drawn from `rng`,
/// `x ← x + (λ‖r‖/n) · diag(1/‖aⱼ‖) · sign(Aᵀ r)`, stopping at
/// `‖r‖ < tolerance` ([`SolveStatus::Converged`]) or the iteration cap
/// ([`SolveStatus::IterationCap`]). Approaches the unique solution, the minimum-norm
/// solution, or the least-squares residual (reproduced by tests, not assumed).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use rand::SeedableRng;
/// use kinplan_core::linalg::{solve_angle_relaxation, RlxaParams, SolveStatus};
/// let a = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
/// let b = DVector::from_vec(vec![3.0, 5.0]); // x = (0.8, 1.4)
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
/// let p = RlxaParams { tolerance: 1e-6, ..RlxaParams::default() };
/// let s = solve_angle_relaxation(&a, &b, &p, &mut rng).unwrap();
/// assert_eq!(s.status, SolveStatus::Converged);
/// assert!((s.x[0] - 0.8).abs() < 1e-4 && (s.x[1] - 1.4).abs() < 1e-4);
/// ```
pub fn solve_angle_relaxation<R: Rng + ?Sized>(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    params: &RlxaParams,
    rng: &mut R,
) -> Result<LinearSolution, LinalgError> {
    solve_angle_relaxation_until(a, b, params, rng, Deadline::none())
}

/// [`solve_angle_relaxation`], stopping early (status
/// [`SolveStatus::IterationCap`]) once `deadline` says so.
pub fn solve_angle_relaxation_until<R: Rng + ?Sized>(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    params: &RlxaParams,
    rng: &mut R,
    deadline: Deadline<'_>,
) -> Result<LinearSolution, LinalgError> {
    params.validate()?;
    check_system(a, b)?;
    let mut ws = RlxaWorkspace::new(a.nrows(), a.ncols());
    let mut x = DVector::zeros(a.ncols());
    let mut history = Vec::new();
    let hist = if params.record_history {
        Some(&mut history)
    } else {
        None
    };
    let rep = ws.solve_into_until(a, b, &mut x, params, rng, hist, deadline)?;
    Ok(LinearSolution {
        x,
        residual_norm: rep.residual_norm,
        iterations: rep.iterations,
        status: rep.status,
        history,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::{PseudoinverseParams, solve_pseudoinverse};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn random_matrix(m: usize, n: usize, rng: &mut ChaCha8Rng) -> DMatrix<f64> {
        DMatrix::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0))
    }

    fn params(tol: f64, cap: usize) -> RlxaParams {
        RlxaParams {
            tolerance: tol,
            max_iterations: cap,
            ..RlxaParams::default()
        }
    }

    #[test]
    fn unique_solution_is_reached() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for n in 2..=6 {
            // well-conditioned square system: diagonally dominant
            let mut a = random_matrix(n, n, &mut rng);
            for i in 0..n {
                a[(i, i)] += 3.0;
            }
            let x_true = DVector::from_fn(n, |i, _| i as f64 - 1.0);
            let b = &a * &x_true;
            let s = solve_angle_relaxation(&a, &b, &params(1e-8, 200_000), &mut rng).unwrap();
            assert_eq!(s.status, SolveStatus::Converged, "n={n}");
            assert!((s.x - x_true).norm() < 1e-6, "n={n}");
        }
    }

    #[test]
    fn underdetermined_approaches_minimum_norm() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut ratios = Vec::new();
        for _ in 0..20 {
            let a = random_matrix(3, 6, &mut rng);
            let b = DVector::from_fn(3, |_, _| rng.random_range(-1.0..1.0));
            let pinv = solve_pseudoinverse(&a, &b, &PseudoinverseParams::default()).unwrap();
            let s = solve_angle_relaxation(&a, &b, &params(1e-6, 200_000), &mut rng).unwrap();
            assert_eq!(s.status, SolveStatus::Converged);
            let ratio = s.x.norm() / pinv.x.norm();
            assert!(ratio >= 1.0 - 1e-6, "cannot beat the minimum norm");
            ratios.push(ratio);
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        // S2 Fig. 10: ‖x_RLXA‖ ≈ ‖A⁺b‖. Measured mean ratio is printed for the record.
        eprintln!(
            "min-norm ratio mean {mean:.4}, max {:.4}",
            ratios.iter().cloned().fold(0.0, f64::max)
        );
        assert!(mean < 1.25, "mean ‖x‖/‖A⁺b‖ = {mean}");
    }

    #[test]
    fn inconsistent_approaches_least_squares_residual() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..10 {
            let a = random_matrix(8, 3, &mut rng);
            let b = DVector::from_fn(8, |_, _| rng.random_range(-1.0..1.0));
            let pinv = solve_pseudoinverse(&a, &b, &PseudoinverseParams::default()).unwrap();
            let p = RlxaParams {
                record_history: true,
                ..params(1e-9, 20_000)
            };
            let s = solve_angle_relaxation(&a, &b, &p, &mut rng).unwrap();
            assert_eq!(s.status, SolveStatus::IterationCap);
            assert_eq!(s.history.len(), 20_000);
            let best = s.history.iter().cloned().fold(f64::INFINITY, f64::min);
            assert!(best >= pinv.residual_norm - 1e-9, "cannot beat least squares");
            assert!(
                best < pinv.residual_norm * 1.01,
                "best {best} vs LS {}",
                pinv.residual_norm
            );
        }
    }

    #[test]
    fn zero_columns_are_skipped() {
        let a = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 2.0]);
        let b = DVector::from_vec(vec![1.0, 4.0]);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let s = solve_angle_relaxation(&a, &b, &params(1e-9, 100_000), &mut rng).unwrap();
        assert_eq!(s.x[1], 0.0);
        assert!((s.x[0] - 1.0).abs() < 1e-8 && (s.x[2] - 2.0).abs() < 1e-8);
    }

    #[test]
    fn same_seed_same_answer() {
        let mut r0 = ChaCha8Rng::seed_from_u64(9);
        let a = random_matrix(4, 4, &mut r0);
        let b = DVector::from_fn(4, |i, _| i as f64);
        let run = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            solve_angle_relaxation(&a, &b, &params(1e-3, 500), &mut rng).unwrap()
        };
        assert_eq!(run(42), run(42));
        assert_ne!(run(42).x, run(43).x);
    }

    #[test]
    fn safeguarded_never_increases_residual() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let a = random_matrix(6, 6, &mut rng);
        let b = DVector::from_fn(6, |_, _| rng.random_range(-1.0..1.0));
        let p = RlxaParams {
            variant: RlxaVariant::Safeguarded,
            record_history: true,
            ..params(1e-6, 5_000)
        };
        let s = solve_angle_relaxation(&a, &b, &p, &mut rng).unwrap();
        for w in s.history.windows(2) {
            assert!(w[1] <= w[0] * (1.0 + 1e-9) + 1e-12);
        }
    }

    #[test]
    fn bad_params_are_errors() {
        let a = DMatrix::identity(2, 2);
        let b = DVector::from_vec(vec![1.0, 1.0]);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for p in [params(0.0, 10), params(f64::NAN, 10), params(1e-3, 0)] {
            assert!(matches!(
                solve_angle_relaxation(&a, &b, &p, &mut rng),
                Err(LinalgError::InvalidParam { .. })
            ));
        }
        let bn = DVector::from_vec(vec![f64::INFINITY, 1.0]);
        assert!(matches!(
            solve_angle_relaxation(&a, &bn, &params(1e-3, 10), &mut rng),
            Err(LinalgError::NonFinite { .. })
        ));
    }
}
