//! Moore–Penrose pseudoinverse solve `x = A⁺ b` through an SVD, plus the damped
//! variant `x = Σ σᵢ/(σᵢ² + μ) vᵢ uᵢᵀ b` used by Levenberg–Marquardt.

use nalgebra::{DMatrix, DVector};

use super::{LinalgError, LinearSolution, SolveStatus};

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
                field: "relative_tolerance",
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
        return Err(LinalgError::NonFinite { what: "A" });
    }
    if b.iter().any(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "b" });
    }
    Ok(())
}

/// Solves `A x = b` in the least-squares, minimum-norm sense: `x = A⁺ b` (ALGORITHMS.md §1,
/// the reference the RLXA properties are measured against).
///
/// Uses nalgebra's SVD (`A = U Σ Vᵀ`, `x = V Σ⁺ Uᵀ b`, singular values below
/// `relative_tolerance · σ_max` dropped); falls back to the one-sided Jacobi SVD of
/// [`SvdWorkspace`] if nalgebra's iteration does not converge. Allocates; for hot loops
/// use [`SvdWorkspace`].
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use kinplan::linalg::{solve_pseudoinverse, PseudoinverseParams};
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

/// Reusable buffers for a one-sided (Hestenes) Jacobi SVD of an m×n matrix, so a
/// Jacobian loop can solve `J Δq = e` every iteration without allocating.
///
/// One-sided Jacobi rotates column pairs of `W = Â V` until all columns are orthogonal
/// (`Â = A` when m ≥ n; `Â = Aᵀ` when m < n, which has fewer column pairs — a 3×6
/// position Jacobian needs 3 pairs instead of 15). Then `σⱼ = ‖wⱼ‖` and
/// - m ≥ n: `A = Σ wⱼ vⱼᵀ`, `x = Σⱼ vⱼ (wⱼᵀ b) / (σⱼ² + μ)`;
/// - m < n: `A = Σ vⱼ wⱼᵀ`, `x = Σⱼ wⱼ (vⱼᵀ b) / (σⱼ² + μ)`;
///
/// the pseudoinverse for `μ = 0` and the damped least-squares (Levenberg–Marquardt) step
/// `[J; √μ I] Δq = [e; 0]` for `μ > 0` (S2 eq. 36/37, solved without forming `JᵀJ`).
///
/// The workspace resizes itself when the shape changes (the only allocation).
#[derive(Debug, Clone)]
pub struct SvdWorkspace {
    w: DMatrix<f64>,
    v: DMatrix<f64>,
    sigma: DVector<f64>,
    transposed: bool,
    sweeps: usize,
}

impl SvdWorkspace {
    /// Buffers for `rows × cols` systems.
    pub fn new(rows: usize, cols: usize) -> Self {
        let mut ws = Self {
            w: DMatrix::zeros(0, 0),
            v: DMatrix::zeros(0, 0),
            sigma: DVector::zeros(0),
            transposed: false,
            sweeps: 0,
        };
        ws.ensure(rows, cols);
        ws
    }

    /// Singular values of the last decomposed matrix (unordered; `min(m, n)` of them
    /// when m < n, otherwise n).
    pub fn singular_values(&self) -> &DVector<f64> {
        &self.sigma
    }

    /// Forgets the warm-start rotation (`V ← I`).
    pub fn reset(&mut self) {
        self.v.fill_with_identity();
    }

    /// Number of Jacobi sweeps the last decomposition took.
    pub fn sweeps(&self) -> usize {
        self.sweeps
    }

    /// Sizes the buffers for an m×n `A`; true when they already fitted.
    fn ensure(&mut self, m: usize, n: usize) -> bool {
        let transposed = m < n;
        let (rows, k) = if transposed { (n, m) } else { (m, n) };
        if self.w.shape() == (rows, k) && self.transposed == transposed {
            return true;
        }
        self.transposed = transposed;
        self.w = DMatrix::zeros(rows, k);
        self.v = DMatrix::identity(k, k);
        self.sigma = DVector::zeros(k);
        false
    }

    /// Decomposes `a` (assumed finite; callers validate). Returns the number of sweeps.
    pub fn decompose(&mut self, a: &DMatrix<f64>) -> usize {
        let (m, n) = a.shape();
        self.ensure(m, n);
        if self.transposed {
            self.w.tr_copy_from(a);
        } else {
            self.w.copy_from(a);
        }
        self.v.fill_with_identity();
        self.sweep_until_orthogonal(a.norm_squared())
    }

    /// Like [`decompose`](Self::decompose) but starts from the rotation `V` of the previous
    /// call (`W = Â V_prev`), which saves sweeps when `a` is close to the previous matrix
    /// (consecutive Jacobians). A new shape falls back to a cold start.
    pub fn decompose_warm(&mut self, a: &DMatrix<f64>) -> usize {
        let (m, n) = a.shape();
        if !self.ensure(m, n) {
            return self.decompose(a);
        }
        // W = Â V by hand: nalgebra's dynamic gemm may allocate packing buffers.
        let (rows, k) = self.w.shape();
        let av = a.as_slice();
        let (vv, wv) = (self.v.as_slice(), self.w.as_mut_slice());
        let transposed = self.transposed;
        for j in 0..k {
            let wj = &mut wv[j * rows..(j + 1) * rows];
            wj.fill(0.0);
            for c in 0..k {
                let vcj = vv[j * k + c];
                if vcj == 0.0 {
                    continue;
                }
                if transposed {
                    // column c of Aᵀ = row c of A (stride m)
                    for (r, w) in wj.iter_mut().enumerate() {
                        *w += av[r * m + c] * vcj;
                    }
                } else {
                    let ac = &av[c * rows..(c + 1) * rows];
                    for (w, x) in wj.iter_mut().zip(ac) {
                        *w += x * vcj;
                    }
                }
            }
        }
        self.sweep_until_orthogonal(a.norm_squared())
    }

    fn sweep_until_orthogonal(&mut self, frob2: f64) -> usize {
        let (m, n) = self.w.shape();
        const MAX_SWEEPS: usize = 60;
        // Columns whose squared norm is below this are numerically zero: leave them.
        let negligible = f64::EPSILON * f64::EPSILON * frob2;
        let w = self.w.as_mut_slice();
        let v = self.v.as_mut_slice();
        let mut sweep = 0;
        while sweep < MAX_SWEEPS {
            sweep += 1;
            let mut rotated = false;
            for i in 0..n {
                for j in (i + 1)..n {
                    let (head, tail) = w.split_at_mut(j * m);
                    let wi = &mut head[i * m..(i + 1) * m];
                    let wj = &mut tail[..m];
                    let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                    for k in 0..m {
                        alpha += wi[k] * wi[k];
                        beta += wj[k] * wj[k];
                        gamma += wi[k] * wj[k];
                    }
                    if gamma == 0.0
                        || alpha <= negligible
                        || beta <= negligible
                        || gamma.abs() <= 1e-10 * (alpha * beta).sqrt()
                    {
                        continue;
                    }
                    rotated = true;
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let c = 1.0 / (1.0 + t * t).sqrt();
                    let s = c * t;
                    for k in 0..m {
                        let (x, y) = (wi[k], wj[k]);
                        wi[k] = c * x - s * y;
                        wj[k] = s * x + c * y;
                    }
                    let (vhead, vtail) = v.split_at_mut(j * n);
                    let vi = &mut vhead[i * n..(i + 1) * n];
                    let vj = &mut vtail[..n];
                    for k in 0..n {
                        let (x, y) = (vi[k], vj[k]);
                        vi[k] = c * x - s * y;
                        vj[k] = s * x + c * y;
                    }
                }
            }
            if !rotated {
                break;
            }
        }
        for j in 0..n {
            self.sigma[j] = self.w.column(j).norm();
        }
        self.sweeps = sweep;
        sweep
    }

    /// After [`decompose`](Self::decompose): the (damped) pseudoinverse solution over
    /// `σⱼ > relative_tolerance · σ_max` (formulas on the type). `b.len()` must equal the
    /// row count and `x.len()` the column count of the decomposed `A` (callers validate).
    pub fn solve_decomposed(
        &self,
        b: &DVector<f64>,
        damping: f64,
        relative_tolerance: f64,
        x: &mut DVector<f64>,
    ) {
        let k = self.w.ncols();
        let smax = self.sigma.iter().cloned().fold(0.0, f64::max);
        let cut = relative_tolerance * smax;
        x.fill(0.0);
        if smax == 0.0 {
            return;
        }
        for j in 0..k {
            let s = self.sigma[j];
            if s <= cut || s == 0.0 {
                continue;
            }
            let denom = s * s + damping;
            if self.transposed {
                let coef = self.v.column(j).dot(b) / denom;
                x.axpy(coef, &self.w.column(j), 1.0);
            } else {
                let coef = self.w.column(j).dot(b) / denom;
                x.axpy(coef, &self.v.column(j), 1.0);
            }
        }
    }

    /// Validating one-call form: decomposes `a` and writes the (damped, `μ = damping ≥ 0`)
    /// pseudoinverse solution into `x`, resizing `x` if needed. Returns `‖b − A x‖`.
    pub fn solve_into(
        &mut self,
        a: &DMatrix<f64>,
        b: &DVector<f64>,
        damping: f64,
        params: &PseudoinverseParams,
        x: &mut DVector<f64>,
    ) -> Result<f64, LinalgError> {
        params.validate()?;
        check_system(a, b)?;
        if !damping.is_finite() || damping < 0.0 {
            return Err(LinalgError::InvalidParam {
                field: "damping",
                value: damping,
                reason: "must be finite and >= 0",
            });
        }
        if x.len() != a.ncols() {
            *x = DVector::zeros(a.ncols());
        }
        self.decompose(a);
        self.solve_decomposed(b, damping, params.relative_tolerance, x);
        let mut r2 = 0.0;
        for i in 0..a.nrows() {
            let ri = b[i] - a.row(i).transpose().dot(x);
            r2 += ri * ri;
        }
        Ok(r2.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg_matrix(m: usize, n: usize, seed: u64) -> DMatrix<f64> {
        let mut s = seed;
        DMatrix::from_fn(m, n, |_, _| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    }

    #[test]
    fn jacobi_matches_nalgebra_singular_values() {
        for (m, n) in [(6, 6), (6, 7), (3, 6), (13, 7), (2, 9), (9, 2)] {
            let a = lcg_matrix(m, n, (m * 31 + n) as u64);
            let mut ws = SvdWorkspace::new(m, n);
            ws.decompose(&a);
            let mut ours: Vec<f64> = ws.singular_values().iter().cloned().collect();
            ours.sort_by(|x, y| y.total_cmp(x));
            let theirs = a.clone().svd(false, false).singular_values;
            for (k, s) in theirs.iter().enumerate() {
                assert!((ours[k] - s).abs() < 1e-10, "{m}x{n} σ{k}: {} vs {}", ours[k], s);
            }
            for s in ours.iter().skip(theirs.len()) {
                assert!(s.abs() < 1e-10);
            }
        }
    }

    #[test]
    fn workspace_matches_nalgebra_pseudoinverse_on_rank_deficient() {
        let mut a = lcg_matrix(6, 7, 5);
        // make column 3 a copy of column 1 and column 5 zero
        let c1 = a.column(1).into_owned();
        a.set_column(3, &c1);
        a.column_mut(5).fill(0.0);
        let b = DVector::from_fn(6, |i, _| i as f64 - 2.5);
        let reference = a.clone().pseudo_inverse(1e-10).unwrap() * &b;
        let mut ws = SvdWorkspace::new(1, 1);
        let mut x = DVector::zeros(0);
        ws.solve_into(&a, &b, 0.0, &PseudoinverseParams::default(), &mut x)
            .unwrap();
        assert!((x - reference).norm() < 1e-9);
    }

    #[test]
    fn damped_solution_matches_normal_equations() {
        let a = lcg_matrix(6, 6, 11);
        let b = DVector::from_fn(6, |i, _| (i as f64).sin());
        let mu = 0.3;
        let lhs = a.transpose() * &a + DMatrix::identity(6, 6) * mu;
        let reference = lhs.lu().solve(&(a.transpose() * &b)).unwrap();
        let mut ws = SvdWorkspace::new(6, 6);
        let mut x = DVector::zeros(6);
        ws.solve_into(&a, &b, mu, &PseudoinverseParams::default(), &mut x)
            .unwrap();
        assert!((x - reference).norm() < 1e-10);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, f64::NAN]);
        let b = DVector::from_vec(vec![1.0, 2.0]);
        let p = PseudoinverseParams::default();
        assert!(matches!(
            solve_pseudoinverse(&a, &b, &p),
            Err(LinalgError::NonFinite { what: "A" })
        ));
        let a = DMatrix::identity(2, 2);
        let b3 = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        assert!(matches!(
            solve_pseudoinverse(&a, &b3, &p),
            Err(LinalgError::ShapeMismatch { .. })
        ));
        let e = DMatrix::<f64>::zeros(0, 2);
        assert!(matches!(
            solve_pseudoinverse(&e, &DVector::zeros(0), &p),
            Err(LinalgError::Empty { .. })
        ));
        let bad = PseudoinverseParams {
            relative_tolerance: -1.0,
        };
        assert!(solve_pseudoinverse(&a, &b, &bad).is_err());
    }
}
