//! The one-sided (Hestenes) Jacobi SVD workspace: buffers, the general slice
//! code (row-cyclic sweeps, any shape) and the solves from a decomposition.
//! The fixed-size kernel for at most 8 rows is in `fixed.rs`.

use nalgebra::{DMatrix, DVector};

use super::super::{LinalgError, LinalgParam};
use super::{PseudoinverseParams, check_system};

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
/// Sweeps run until no pair has `|wᵢᵀwⱼ| > τ ‖wᵢ‖‖wⱼ‖`, the orthogonality tolerance
/// `τ` (default `1e-10`; see [`with_orthogonality`](Self::with_orthogonality)). When `W`
/// has at most 8 rows (every 6×n and 3×n IK Jacobian with n ≤ 8) the sweeps run on
/// fixed-size stack arrays padded to an even length, visiting the pairs in round-robin
/// order (disjoint pairs in a row, so their rotations overlap in the pipeline; fewer
/// sweeps than row-cyclic order on Panda Jacobians), with the squared column norms
/// cached across a sweep (`‖wᵢ'‖² = α − tγ`, `‖wⱼ'‖² = β + tγ`, recomputed at the start
/// of each sweep), the rotation from two square roots, and AVX2 code when the CPU has
/// it; larger shapes use general slice code in row-cyclic order. All are cyclic
/// one-sided Jacobi methods.
///
/// The workspace resizes itself when the shape changes (the only allocation).
#[derive(Debug, Clone)]
pub struct SvdWorkspace {
    pub(super) w: DMatrix<f64>,
    pub(super) v: DMatrix<f64>,
    pub(super) sigma: DVector<f64>,
    pub(super) transposed: bool,
    pub(super) sweeps: usize,
    pub(super) orthogonality: f64,
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
            orthogonality: ORTHOGONAL,
        };
        ws.ensure(rows, cols);
        ws
    }

    /// Sets the orthogonality tolerance `τ` at which the sweeps stop (clamped to
    /// `[1e-15, 1e-2]`).
    ///
    /// The columns of `A V` are orthogonal to `τ`, so `σⱼ` are accurate to about `τ²`
    /// and a pseudoinverse solution to about `τ` relative times the conditioning of the
    /// (damped) system. A Newton-type iteration needs no more than the accuracy it is
    /// converging by (inexact Newton; Dembo, Eisenstat & Steihaug 1982) when the unknown
    /// is the step itself: the Jacobian-inverse and Levenberg–Marquardt steps use `1e-4`,
    /// which leaves their iteration counts unchanged on every benchmark arm and saves
    /// sweeps (`benches/IK_RESULTS.md`). Not when the unknown is the new
    /// iterate (Newton's `J q_{k+1} = J q_k + e`): its error `τ‖q‖` does not shrink with
    /// `e`, so Newton keeps the default.
    pub fn with_orthogonality(mut self, tolerance: f64) -> Self {
        self.set_orthogonality(tolerance);
        self
    }

    /// In-place form of [`with_orthogonality`](Self::with_orthogonality).
    pub fn set_orthogonality(&mut self, tolerance: f64) {
        self.orthogonality = tolerance.clamp(1e-15, 1e-2);
    }

    /// The default orthogonality tolerance (`1e-10`).
    pub const DEFAULT_ORTHOGONALITY: f64 = ORTHOGONAL;

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
        self.v.fill_with_identity();
        self.decompose_from_v(a)
    }

    /// Like [`decompose`](Self::decompose) but starts from the rotation `V` of the previous
    /// call (`W = Â V_prev`), which saves sweeps when `a` is close to the previous matrix
    /// (consecutive Jacobians). A new shape falls back to a cold start.
    pub fn decompose_warm(&mut self, a: &DMatrix<f64>) -> usize {
        let (m, n) = a.shape();
        if !self.ensure(m, n) {
            return self.decompose(a);
        }
        self.decompose_from_v(a)
    }

    /// `W = Â V` with the current `V`, then Jacobi sweeps. Small shapes (`max(m, n) ≤ 8`,
    /// every IK Jacobian) run on fixed-size stack arrays, so the column loops are unrolled
    /// and vectorised, visiting the column pairs in round-robin order; larger ones use
    /// the general slice code in row-cyclic order. Both are cyclic one-sided Jacobi
    /// methods and converge to the same decomposition, but not through the same
    /// rotations: the pair orders differ.
    fn decompose_from_v(&mut self, a: &DMatrix<f64>) -> usize {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the running CPU supports AVX2 (checked just above).
            return unsafe { self.decompose_from_v_avx2(a) };
        }
        self.decompose_from_v_portable(a)
    }

    /// [`decompose_from_v`](Self::decompose_from_v) compiled for AVX2: the same scalar
    /// code, vectorised over 4 lanes instead of 2. No FMA is enabled, so every product
    /// and sum is rounded as in the portable build and the results are bit-identical
    /// (replicas on different CPUs give the same answers).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn decompose_from_v_avx2(&mut self, a: &DMatrix<f64>) -> usize {
        self.decompose_from_v_portable(a)
    }

    #[inline(always)]
    pub(super) fn decompose_from_v_portable(&mut self, a: &DMatrix<f64>) -> usize {
        let frob2 = a.norm_squared();
        let sweeps = match self.w.nrows() {
            1 | 2 => self.fixed::<2>(a, frob2),
            3 | 4 => self.fixed::<4>(a, frob2),
            5 | 6 => self.fixed::<6>(a, frob2),
            7 | 8 => self.fixed::<8>(a, frob2),
            _ => {
                self.load_w(a);
                self.sweep_until_orthogonal(frob2)
            }
        };
        self.sweeps = sweeps;
        sweeps
    }

    /// General path: `W = Â V` by hand (nalgebra's dynamic gemm may allocate packing
    /// buffers).
    fn load_w(&mut self, a: &DMatrix<f64>) {
        let m = a.nrows();
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
    }

    pub(super) fn sweep_until_orthogonal(&mut self, frob2: f64) -> usize {
        let (m, n) = self.w.shape();
        // Columns whose squared norm is below this are numerically zero: leave them.
        let negligible = f64::EPSILON * f64::EPSILON * frob2;
        let tolerance = self.orthogonality;
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
                    let Some((c, s)) = jacobi_rotation(alpha, beta, gamma, negligible, tolerance) else {
                        continue;
                    };
                    rotated = true;
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
        // Plain slices: nalgebra's generic column views cost more than these few flops.
        let (rows, w, v) = (self.w.nrows(), self.w.as_slice(), self.v.as_slice());
        let (b, x) = (b.as_slice(), x.as_mut_slice());
        for j in 0..k {
            let s = self.sigma[j];
            if s <= cut || s == 0.0 {
                continue;
            }
            let denom = s * s + damping;
            let (wj, vj) = (&w[j * rows..(j + 1) * rows], &v[j * k..(j + 1) * k]);
            // transposed: coefficient from V, direction from W; otherwise the reverse
            let (coef_col, dir_col) = if self.transposed { (vj, wj) } else { (wj, vj) };
            let coef = coef_col.iter().zip(b).map(|(p, q)| p * q).sum::<f64>() / denom;
            for (xi, d) in x.iter_mut().zip(dir_col) {
                *xi += coef * d;
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
                field: LinalgParam::Damping,
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

pub(super) const MAX_SWEEPS: usize = 60;
/// Default orthogonality tolerance: pairs with `|wᵢᵀwⱼ| ≤ ORTHOGONAL · ‖wᵢ‖‖wⱼ‖` count
/// as orthogonal.
pub(super) const ORTHOGONAL: f64 = 1e-10;

/// The Jacobi rotation `(c, s)` that makes columns with Gram entries `α = ‖wᵢ‖²`,
/// `β = ‖wⱼ‖²`, `γ = wᵢᵀwⱼ` orthogonal, or `None` when they already are (or one is
/// numerically zero).
#[inline(always)]
pub(super) fn jacobi_rotation(
    alpha: f64,
    beta: f64,
    gamma: f64,
    negligible: f64,
    tolerance: f64,
) -> Option<(f64, f64)> {
    if gamma == 0.0
        || alpha <= negligible
        || beta <= negligible
        || gamma.abs() <= tolerance * (alpha * beta).sqrt()
    {
        return None;
    }
    let zeta = (beta - alpha) / (2.0 * gamma);
    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
    let c = 1.0 / (1.0 + t * t).sqrt();
    Some((c, c * t))
}
