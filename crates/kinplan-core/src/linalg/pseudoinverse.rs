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
/// order (disjoint pairs in a row, so their rotations overlap in the pipeline; ~9 %
/// fewer sweeps than row-cyclic order on Panda Jacobians), with the squared column norms
/// cached across a sweep (`‖wᵢ'‖² = α − tγ`, `‖wⱼ'‖² = β + tγ`, recomputed at the start
/// of each sweep), the rotation from two square roots, and AVX2 code when the CPU has
/// it; larger shapes use general slice code in row-cyclic order. All are cyclic
/// one-sided Jacobi methods.
///
/// The workspace resizes itself when the shape changes (the only allocation).
#[derive(Debug, Clone)]
pub struct SvdWorkspace {
    w: DMatrix<f64>,
    v: DMatrix<f64>,
    sigma: DVector<f64>,
    transposed: bool,
    sweeps: usize,
    orthogonality: f64,
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
    /// ~15 % of the sweeps (`benches/IK_RESULTS.md`). Not when the unknown is the new
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
    /// and vectorised; larger ones use the general slice code. Both perform the same
    /// rotations in the same order.
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
    fn decompose_from_v_avx2(&mut self, a: &DMatrix<f64>) -> usize {
        self.decompose_from_v_portable(a)
    }

    #[inline(always)]
    fn decompose_from_v_portable(&mut self, a: &DMatrix<f64>) -> usize {
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

    /// Fixed-size path for `W` with `rows ≤ L` rows and `k ≤ rows` columns, `L` even so
    /// the column loops map onto pairs of SIMD lanes. Columns of `W` and `V` are padded
    /// with zeros to length `L`; rotations keep the padding zero.
    #[inline(always)]
    fn fixed<const L: usize>(&mut self, a: &DMatrix<f64>, frob2: f64) -> usize {
        let (rows, k) = self.w.shape();
        debug_assert!(k <= rows && rows <= L && L <= MAX_FIXED && L.is_multiple_of(2));
        let m = a.nrows();
        let av = a.as_slice();
        // columns of Â
        let mut ac = [[0.0f64; L]; MAX_FIXED];
        for (c, col) in ac.iter_mut().enumerate().take(k) {
            for (r, x) in col.iter_mut().enumerate().take(rows) {
                *x = if self.transposed {
                    av[r * m + c]
                } else {
                    av[c * rows + r]
                };
            }
        }
        let mut v = [[0.0f64; L]; MAX_FIXED];
        let vs = self.v.as_slice();
        for (j, col) in v.iter_mut().enumerate().take(k) {
            col[..k].copy_from_slice(&vs[j * k..(j + 1) * k]);
        }
        // W = Â V
        let mut w = [[0.0f64; L]; MAX_FIXED];
        for j in 0..k {
            let mut acc = [0.0f64; L];
            for c in 0..k {
                let vcj = v[j][c];
                for r in 0..L {
                    acc[r] += ac[c][r] * vcj;
                }
            }
            w[j] = acc;
        }
        let negligible = f64::EPSILON * f64::EPSILON * frob2;
        // Squared column norms, recomputed exactly at the start of every sweep and updated
        // by the rotation identities ‖wᵢ'‖² = α − tγ, ‖wⱼ'‖² = β + tγ inside it, so a pair
        // costs one dot product instead of three.
        let mut norms = [0.0f64; MAX_FIXED];
        let tol2 = self.orthogonality * self.orthogonality;
        let mut sweep = 0;
        while sweep < MAX_SWEEPS {
            sweep += 1;
            let mut rotated = false;
            for (d, col) in norms.iter_mut().zip(&w).take(k) {
                *d = dot(col, col);
            }
            for &(i, j) in &ROUND_ROBIN[k][..k * k.saturating_sub(1) / 2] {
                let (i, j) = (i as usize, j as usize);
                let (alpha, beta) = (norms[i], norms[j]);
                if alpha <= negligible || beta <= negligible {
                    continue;
                }
                let gamma = dot(&w[i], &w[j]);
                if gamma * gamma <= tol2 * alpha * beta {
                    continue;
                }
                let (c, s, t) = fast_rotation(alpha, beta, gamma);
                rotated = true;
                norms[i] = alpha - t * gamma;
                norms[j] = beta + t * gamma;
                rotate_pair(&mut w, i, j, c, s);
                rotate_pair(&mut v, i, j, c, s);
            }
            if !rotated {
                break;
            }
        }
        let ws = self.w.as_mut_slice();
        let vs = self.v.as_mut_slice();
        for j in 0..k {
            ws[j * rows..(j + 1) * rows].copy_from_slice(&w[j][..rows]);
            vs[j * k..(j + 1) * k].copy_from_slice(&v[j][..k]);
            self.sigma[j] = w[j].iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        sweep
    }

    fn sweep_until_orthogonal(&mut self, frob2: f64) -> usize {
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

const MAX_SWEEPS: usize = 60;

/// Column pairs of one sweep for `MAX_FIXED` columns.
const PAIRS: usize = MAX_FIXED * (MAX_FIXED - 1) / 2;

/// The round-robin (Brent–Luk) order of the column pairs of one sweep, for every column
/// count `k ≤ MAX_FIXED` (entry `k`, its first `k(k−1)/2` pairs), built at compile time:
/// `k − 1` rounds (k even; an odd `k` gets a dummy column) of disjoint pairs, seat 0
/// fixed and the other seats moving one place per round (circle method). Pairs within
/// a round touch different columns, so their rotations are independent and overlap in
/// the CPU pipeline instead of waiting on each other as in the row-cyclic order.
const ROUND_ROBIN: [[(u8, u8); PAIRS]; MAX_FIXED + 1] = round_robin_tables();

const fn round_robin_tables() -> [[(u8, u8); PAIRS]; MAX_FIXED + 1] {
    let mut out = [[(0u8, 0u8); PAIRS]; MAX_FIXED + 1];
    let mut k = 2;
    while k <= MAX_FIXED {
        let p = k + (k % 2);
        let mut seats = [0usize; MAX_FIXED];
        let mut i = 0;
        while i < p {
            seats[i] = i;
            i += 1;
        }
        let mut len = 0;
        let mut round = 0;
        while round + 1 < p {
            let mut i = 0;
            while i < p / 2 {
                let (a, b) = (seats[i], seats[p - 1 - i]);
                if a < k && b < k {
                    out[k][len] = if a < b {
                        (a as u8, b as u8)
                    } else {
                        (b as u8, a as u8)
                    };
                    len += 1;
                }
                i += 1;
            }
            let last = seats[p - 1];
            let mut j = p - 1;
            while j > 1 {
                seats[j] = seats[j - 1];
                j -= 1;
            }
            seats[1] = last;
            round += 1;
        }
        k += 1;
    }
    out
}

/// Largest `W` row count handled by the fixed-size path.
const MAX_FIXED: usize = 8;
/// Default orthogonality tolerance: pairs with `|wᵢᵀwⱼ| ≤ ORTHOGONAL · ‖wᵢ‖‖wⱼ‖` count
/// as orthogonal.
const ORTHOGONAL: f64 = 1e-10;

/// The Jacobi rotation `(c, s)` that makes columns with Gram entries `α = ‖wᵢ‖²`,
/// `β = ‖wⱼ‖²`, `γ = wᵢᵀwⱼ` orthogonal, or `None` when they already are (or one is
/// numerically zero).
#[inline(always)]
fn jacobi_rotation(alpha: f64, beta: f64, gamma: f64, negligible: f64, tolerance: f64) -> Option<(f64, f64)> {
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

/// The same rotation as [`jacobi_rotation`] (for a pair known to need one), with a
/// shorter chain of dependent square roots and divisions (the latency of a sweep): with
/// `d = β − α`, `h = √(d² + 4γ²)`, `m = h + |d|` and `r = √(2hm)`,
/// `c = m / r`, `s = sign(d) 2γ / r`, `t = s / c = sign(d) 2γ / m` — the same
/// `t = sign(ζ)/(|ζ| + √(1 + ζ²))`, `ζ = d/(2γ)`, `c = 1/√(1 + t²)` (since
/// `m² + 4γ² = 2hm`), with one division on the path to `(c, s)` instead of two.
/// Returns `(c, s, t)`.
#[inline(always)]
fn fast_rotation(alpha: f64, beta: f64, gamma: f64) -> (f64, f64, f64) {
    let d = beta - alpha;
    let g2 = 2.0 * gamma;
    let h = (d * d + g2 * g2).sqrt();
    let m = h + d.abs();
    let r2 = 2.0 * h * m;
    if r2.is_finite() && r2 > 0.0 {
        let inv_r = 1.0 / r2.sqrt();
        let sg = d.signum() * g2;
        (m * inv_r, sg * inv_r, sg / m)
    } else {
        // squares overflowed: the ζ form
        let zeta = d / g2;
        let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
        let c = 1.0 / (1.0 + t * t).sqrt();
        (c, c * t, t)
    }
}

/// Dot product of even-length columns with two partial sums (SIMD lanes).
#[inline(always)]
fn dot<const L: usize>(x: &[f64; L], y: &[f64; L]) -> f64 {
    let mut acc = [0.0f64; 2];
    for (xp, yp) in x.chunks_exact(2).zip(y.chunks_exact(2)) {
        acc[0] += xp[0] * yp[0];
        acc[1] += xp[1] * yp[1];
    }
    acc[0] + acc[1]
}

/// `(xᵢ, xⱼ) ← (c xᵢ − s xⱼ, s xᵢ + c xⱼ)` on two fixed-size columns.
#[inline(always)]
fn rotate_pair<const L: usize>(cols: &mut [[f64; L]; MAX_FIXED], i: usize, j: usize, c: f64, s: f64) {
    debug_assert!(i < j);
    let (head, tail) = cols.split_at_mut(j);
    for (x, y) in head[i].iter_mut().zip(tail[0].iter_mut()) {
        let (a, b) = (*x, *y);
        *x = c * a - s * b;
        *y = s * a + c * b;
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

    /// Sweep counts pinned on fixed matrices, for the fixed-size path (≤ 8 rows)
    /// and the general one: a wrong cached column norm still converges, only
    /// slower, so correctness tests alone would not notice it (checked: leaving
    /// `norms[i]` stale after a rotation fails only this test).
    const PINNED_SWEEPS: [usize; 7] = [5, 5, 4, 6, 2, 2, 8];

    #[test]
    fn sweep_counts_are_pinned() {
        let mut got = Vec::new();
        for (m, n) in [(6, 6), (6, 7), (3, 6), (13, 7), (2, 9), (9, 2), (12, 12)] {
            let a = lcg_matrix(m, n, (m * 17 + n) as u64);
            let mut ws = SvdWorkspace::new(m, n);
            got.push(ws.decompose(&a));
        }
        eprintln!("sweeps: {got:?}");
        assert_eq!(got, PINNED_SWEEPS);
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

    /// Checks one decomposition held in `ws` against `a`: `Â V = W` (so `A = U Σ Vᵀ` with
    /// `U = W Σ⁻¹`), `V` orthogonal, `W` columns orthogonal, singular values = nalgebra's.
    fn check_decomposition(ws: &SvdWorkspace, a: &DMatrix<f64>, what: &str) {
        let (m, n) = a.shape();
        let ahat = if m < n { a.transpose() } else { a.clone() };
        let k = ahat.ncols();
        let scale = a.norm().max(1.0);
        // exact reconstruction Â = W Vᵀ
        let recon = &ws.w * ws.v.transpose();
        assert!(
            (&recon - &ahat).norm() <= 1e-13 * scale,
            "{what}: reconstruction {}",
            (&recon - &ahat).norm()
        );
        // V orthogonal
        let vtv = ws.v.transpose() * &ws.v;
        assert!(
            (vtv - DMatrix::identity(k, k)).norm() <= 1e-13,
            "{what}: V not orthogonal"
        );
        // W columns orthogonal (relative to their norms), i.e. U orthogonal on σ > 0
        for i in 0..k {
            for j in (i + 1)..k {
                let (wi, wj) = (ws.w.column(i), ws.w.column(j));
                let (ni, nj) = (wi.norm(), wj.norm());
                if ni > 1e-12 * scale && nj > 1e-12 * scale {
                    assert!(wi.dot(&wj).abs() <= 1e-9 * ni * nj, "{what}: w{i}·w{j}");
                }
            }
        }
        let mut ours: Vec<f64> = ws.singular_values().iter().cloned().collect();
        ours.sort_by(|x, y| y.total_cmp(x));
        let theirs = a.clone().svd(false, false).singular_values;
        for (i, s) in theirs.iter().enumerate() {
            assert!(
                (ours[i] - s).abs() <= 1e-12 * scale,
                "{what}: σ{i} {} vs {}",
                ours[i],
                s
            );
        }
        for s in ours.iter().skip(theirs.len()) {
            assert!(s.abs() <= 1e-12 * scale, "{what}: extra σ {s}");
        }
    }

    #[test]
    fn fixed_size_path_decomposes_every_small_shape() {
        // every shape with max(m, n) ≤ 8 (fixed-size path), plus shapes on the general path
        let mut shapes: Vec<(usize, usize)> = (1..=8).flat_map(|m| (1..=8).map(move |n| (m, n))).collect();
        shapes.extend([(9, 6), (6, 9), (12, 10), (3, 11)]);
        for (m, n) in shapes {
            for seed in 0..4u64 {
                let mut a = lcg_matrix(m, n, 1000 + seed * 97 + (m * 13 + n) as u64);
                if seed == 2 && n >= 3 {
                    // rank-deficient: a repeated column and a zero column
                    let c0 = a.column(0).into_owned();
                    a.set_column(n - 1, &c0);
                    a.column_mut(1).fill(0.0);
                }
                if seed == 3 && m >= 2 {
                    // rank-deficient: a row that is a combination of two others
                    let r = a.row(0) * 0.5 - a.row(1) * 2.0;
                    a.set_row(m - 1, &r);
                }
                let mut ws = SvdWorkspace::new(m, n);
                ws.decompose(&a);
                check_decomposition(&ws, &a, &format!("{m}x{n} seed {seed} cold"));
                // warm start from the previous rotation on a nearby matrix
                let b = &a + lcg_matrix(m, n, 7 + seed) * 0.05;
                ws.decompose_warm(&b);
                check_decomposition(&ws, &b, &format!("{m}x{n} seed {seed} warm"));
            }
        }
    }

    #[test]
    fn fixed_size_path_matches_general_path() {
        // The fixed-size code (cached norms, two-root rotation) and the general slice code
        // must give the same decomposition up to rounding.
        for (m, n) in [(6, 6), (6, 7), (3, 6), (7, 6), (5, 8)] {
            let a = lcg_matrix(m, n, (m * 7 + n) as u64);
            let mut fast = SvdWorkspace::new(m, n);
            fast.decompose(&a);
            let mut slow = SvdWorkspace::new(m, n);
            let ahat = if m < n { a.transpose() } else { a.clone() };
            slow.w.copy_from(&ahat);
            slow.v.fill_with_identity();
            slow.sweep_until_orthogonal(a.norm_squared());
            let b = DVector::from_fn(m, |i, _| (i as f64 * 0.7).cos());
            let (mut xf, mut xs) = (DVector::zeros(n), DVector::zeros(n));
            for mu in [0.0, 1e-3, 0.5] {
                fast.solve_decomposed(&b, mu, 1e-10, &mut xf);
                slow.solve_decomposed(&b, mu, 1e-10, &mut xs);
                assert!((&xf - &xs).norm() <= 1e-10 * xs.norm().max(1.0), "{m}x{n} μ={mu}");
            }
        }
    }

    /// Every round-robin table visits each column pair exactly once, in rounds of
    /// disjoint pairs.
    #[test]
    fn round_robin_tables_cover_every_pair_once() {
        for k in 2..=MAX_FIXED {
            let pairs = &ROUND_ROBIN[k][..k * (k - 1) / 2];
            let mut seen = std::collections::HashSet::new();
            for &(i, j) in pairs {
                assert!(i < j && (j as usize) < k, "k={k}: ({i}, {j})");
                assert!(seen.insert((i, j)), "k={k}: ({i}, {j}) twice");
            }
            let per_round = k / 2;
            for round in pairs.chunks(per_round) {
                let mut cols: Vec<u8> = round.iter().flat_map(|&(i, j)| [i, j]).collect();
                cols.sort_unstable();
                cols.dedup();
                assert_eq!(
                    cols.len(),
                    2 * round.len(),
                    "k={k}: round {round:?} shares a column"
                );
            }
        }
    }

    /// The AVX2 build of the fixed-size sweeps must give bit-identical factors (no FMA:
    /// every operation rounds as in the portable build).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_path_is_bit_identical_to_portable() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        for (m, n) in [(6, 6), (6, 7), (3, 6), (3, 7), (6, 3), (2, 5), (8, 8), (7, 4)] {
            for seed in 0..10u64 {
                let a = lcg_matrix(m, n, seed * 131 + (7 * m + n) as u64);
                let mut portable = SvdWorkspace::new(m, n);
                let mut avx2 = SvdWorkspace::new(m, n);
                let s1 = portable.decompose_from_v_portable(&a);
                // SAFETY: AVX2 support checked above.
                let s2 = unsafe { avx2.decompose_from_v_avx2(&a) };
                assert_eq!(s1, s2, "{m}x{n}: sweeps");
                assert_eq!(portable.w.as_slice(), avx2.w.as_slice(), "{m}x{n}: W");
                assert_eq!(portable.v.as_slice(), avx2.v.as_slice(), "{m}x{n}: V");
                assert_eq!(portable.sigma.as_slice(), avx2.sigma.as_slice(), "{m}x{n}: σ");
            }
        }
    }

    /// A looser orthogonality tolerance τ still gives an exact factorisation `A V = W`
    /// with orthogonal `V`; the singular values are accurate to ~τ² and a damped solution
    /// to ~τ times the conditioning (here ≤ 1e-3 relative for τ = 1e-4).
    #[test]
    fn orthogonality_tolerance_bounds_the_error() {
        for (m, n) in [(6, 6), (6, 7), (3, 7)] {
            for seed in 0..20u64 {
                let a = lcg_matrix(m, n, seed * 17 + (5 * m + n) as u64);
                let b = DVector::from_fn(m, |i, _| (i as f64 * 0.7 + seed as f64).cos());
                let mut exact = SvdWorkspace::new(m, n);
                let mut loose = SvdWorkspace::new(m, n).with_orthogonality(1e-4);
                let s_exact = exact.decompose(&a);
                let s_loose = loose.decompose(&a);
                assert!(s_loose <= s_exact, "{m}x{n}: {s_loose} > {s_exact} sweeps");
                check_decomposition_identity(&loose, &a);
                let mut e: Vec<f64> = exact.singular_values().iter().copied().collect();
                let mut l: Vec<f64> = loose.singular_values().iter().copied().collect();
                e.sort_by(f64::total_cmp);
                l.sort_by(f64::total_cmp);
                let smax = e[e.len() - 1];
                for (x, y) in e.iter().zip(&l) {
                    assert!((x - y).abs() <= 1e-7 * smax, "{m}x{n}: σ {e:?} vs {l:?}");
                }
                let (mut xe, mut xl) = (DVector::zeros(n), DVector::zeros(n));
                exact.solve_decomposed(&b, 1e-3, 1e-12, &mut xe);
                loose.solve_decomposed(&b, 1e-3, 1e-12, &mut xl);
                assert!((&xe - &xl).norm() <= 1e-3 * xe.norm(), "{m}x{n}: {xe} vs {xl}");
            }
        }
    }

    /// `Â V = W` and `VᵀV = I` (holds at any orthogonality tolerance: rotations are exact
    /// up to rounding).
    fn check_decomposition_identity(ws: &SvdWorkspace, a: &DMatrix<f64>) {
        let a_hat = if ws.transposed { a.transpose() } else { a.clone() };
        let k = ws.v.ncols();
        assert!((&a_hat * &ws.v - &ws.w).norm() <= 1e-12 * a.norm());
        assert!((ws.v.transpose() * &ws.v - DMatrix::identity(k, k)).norm() <= 1e-12);
    }

    #[test]
    fn damped_solution_matches_normal_equations_on_jacobian_shapes() {
        for (m, n) in [(6, 6), (6, 7), (3, 6), (3, 7), (6, 3)] {
            let a = lcg_matrix(m, n, (31 * m + n) as u64);
            let b = DVector::from_fn(m, |i, _| (i as f64).sin() + 0.3);
            let mut ws = SvdWorkspace::new(m, n);
            let mut x = DVector::zeros(n);
            for mu in [1e-7, 1e-3, 0.3, 10.0] {
                let lhs = a.transpose() * &a + DMatrix::identity(n, n) * mu;
                let reference = lhs.lu().solve(&(a.transpose() * &b)).unwrap();
                ws.solve_into(&a, &b, mu, &PseudoinverseParams::default(), &mut x)
                    .unwrap();
                assert!(
                    (&x - &reference).norm() <= 1e-8 * reference.norm().max(1.0),
                    "{m}x{n} μ={mu}"
                );
            }
        }
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
