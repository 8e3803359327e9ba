//! Moore–Penrose pseudoinverse solve `x = A⁺ b` through an SVD, plus the damped
//! variant `x = Σ σᵢ/(σᵢ² + μ) vᵢ uᵢᵀ b` used by Levenberg–Marquardt.

use nalgebra::{DMatrix, DVector};

use super::{LinalgError, LinalgParam, LinearSolution, Operand, SolveStatus};

mod fixed;
mod svd;
#[cfg(test)]
mod tests;

pub use svd::SvdWorkspace;

/// Options of the SVD pseudoinverse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PseudoinverseParams {
    /// Singular values `σ ≤ relative_tolerance · σ_max` are treated as zero
    /// (dimensionless, ≥ 0). Default `1e-10`.
    pub relative_tolerance: f64,
}

impl Default for PseudoinverseParams {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-10,
        }
    }
}

impl PseudoinverseParams {
    /// Rejects a negative or non-finite tolerance.
    pub fn validate(&self) -> Result<(), LinalgError> {
        if !self.relative_tolerance.is_finite() || self.relative_tolerance < 0.0 {
            return Err(LinalgError::InvalidParam {
                field: LinalgParam::SingularValueTolerance,
                value: self.relative_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }
}

pub(crate) fn check_system(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<(), LinalgError> {
    let (rows, cols) = a.shape();
    if rows == 0 || cols == 0 {
        return Err(LinalgError::Empty { rows, cols });
    }
    if b.len() != rows {
        return Err(LinalgError::ShapeMismatch {
            rows,
            cols,
            rhs_len: b.len(),
        });
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: Operand::A });
    }
    if b.iter().any(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: Operand::B });
    }
    Ok(())
}

/// Solves `A x = b` in the least-squares, minimum-norm sense: `x = A⁺ b`
/// (docs/linear-solvers.md#svd-pseudoinverse, the reference the RLXA properties are measured against).
///
/// Uses nalgebra's SVD (`A = U Σ Vᵀ`, `x = V Σ⁺ Uᵀ b`, singular values below
/// `relative_tolerance · σ_max` dropped); falls back to the one-sided Jacobi SVD of
/// [`SvdWorkspace`] if nalgebra's iteration does not converge. Allocates; for hot loops
/// use [`SvdWorkspace`].
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use kinplan_core::linalg::{solve_pseudoinverse, PseudoinverseParams};
/// // x + y = 2 has the minimum-norm solution (1, 1).
/// let a = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
/// let b = DVector::from_vec(vec![2.0]);
/// let s = solve_pseudoinverse(&a, &b, &PseudoinverseParams::default()).unwrap();
/// assert!((s.x[0] - 1.0).abs() < 1e-12 && (s.x[1] - 1.0).abs() < 1e-12);
/// ```
pub fn solve_pseudoinverse(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    params: &PseudoinverseParams,
) -> Result<LinearSolution, LinalgError> {
    params.validate()?;
    check_system(a, b)?;
    let x = match nalgebra::SVD::try_new(a.clone(), true, true, f64::EPSILON, 10_000) {
        Some(svd) => {
            let smax = svd.singular_values.max();
            let eps = (params.relative_tolerance * smax).max(f64::MIN_POSITIVE);
            match svd.solve(b, eps) {
                Ok(x) => x,
                Err(_) => jacobi_solve(a, b, params.relative_tolerance),
            }
        }
        None => jacobi_solve(a, b, params.relative_tolerance),
    };
    let residual_norm = (b - a * &x).norm();
    Ok(LinearSolution {
        x,
        residual_norm,
        iterations: 1,
        status: SolveStatus::Converged,
        history: Vec::new(),
    })
}

fn jacobi_solve(a: &DMatrix<f64>, b: &DVector<f64>, tol: f64) -> DVector<f64> {
    let mut ws = SvdWorkspace::new(a.nrows(), a.ncols());
    let mut x = DVector::zeros(a.ncols());
    ws.decompose(a);
    ws.solve_decomposed(b, 0.0, tol, &mut x);
    x
}
