//! STOMP's fixed matrices (docs/planning.md#stomp), kept banded: the control-cost
//! matrix R = AᵀA of the finite-difference acceleration matrix A, the noise
//! covariance R⁻¹ (normalised) and the smoothing projection M, all applied
//! through R's banded Cholesky factor — no dense `free × free` matrix is ever
//! formed, so memory is linear in the timesteps.

use nalgebra::{DMatrix, DVector};

use crate::Deadline;

/// Central finite-difference acceleration stencil, times 12:
/// `q̈(t) ≈ (−q(t−2) + 16q(t−1) − 30q(t) + 16q(t+1) − q(t+2)) / (12 dt²)`.
pub const ACCELERATION_STENCIL: [f64; 5] = [-1.0, 16.0, -30.0, 16.0, -1.0];

/// Waypoints of padding on each side of the free waypoints when R is built:
/// with four, every row of A that touches a free waypoint carries the whole
/// stencil, so R does not depend on how the ends are truncated.
pub const PADDING: usize = 4;

/// Half-bandwidth of R: the stencil spans five waypoints, so R couples
/// waypoints at most four apart.
const BAND: usize = 4;

/// R's entries by lag |i − j| (×144, `dt` = 1): the stencil's
/// autocorrelation. With [`PADDING`] every free row carries the whole
/// stencil, so R is exactly this banded Toeplitz matrix.
const R_LAGS: [f64; BAND + 1] = [1414.0, -992.0, 316.0, -32.0, 1.0];

/// Columns of R⁻¹ solved between two looks at the caller's stop flag while
/// the matrices are built.
const COLUMNS_PER_CHECK: usize = 16;

/// The `len × len` acceleration matrix: row `i` holds the stencil
/// `[−1, 16, −30, 16, −1] / (12 dt²)` centred on column `i`; entries that
/// would fall outside the matrix are dropped (rows near the ends are
/// truncated). `dt` in seconds (or 1 for a per-timestep unit). Dense: for
/// tests and small illustrations; STOMP itself never forms it.
///
/// ```
/// let a = kinplan_core::plan::finite_difference_matrix(5, 1.0);
/// assert_eq!(a[(2, 0)] * 12.0, -1.0);
/// assert_eq!(a[(2, 2)] * 12.0, -30.0);
/// assert_eq!(a[(0, 3)], 0.0);
/// ```
pub fn finite_difference_matrix(len: usize, dt: f64) -> DMatrix<f64> {
    let scale = 1.0 / (12.0 * dt * dt);
    DMatrix::from_fn(len, len, |i, j| {
        let offset = j as isize - i as isize;
        if offset.abs() <= 2 {
            ACCELERATION_STENCIL[(offset + 2) as usize] * scale
        } else {
            0.0
        }
    })
}

/// Why [`StompMatrices::new`] built nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatricesError {
    /// `free` was 0.
    Empty,
    /// The caller's stop flag was raised while R⁻¹'s columns were scanned.
    Stopped,
}

/// STOMP's matrices for `free` optimised waypoints (the trajectory's
/// timesteps minus the fixed start and goal), per timestep (`dt` = 1; the
/// covariance and M do not depend on `dt`).
///
/// - `R = (AᵀA)[PADDING.., PADDING..]` with A the
///   [`finite_difference_matrix`] of the padded length `free + 2·PADDING`:
///   banded Toeplitz with, ×144, diagonal 1414 and off-diagonals −992, 316,
///   −32, 1. It is stored as its "upper" Cholesky factor, `R = U Uᵀ` with U
///   upper triangular and banded (factorised from the last row up).
/// - Noise: `covariance = R⁻¹ / max(R⁻¹)`; joint d draws
///   `ε_d = σ_d · U⁻ᵀ z / √max(R⁻¹)` with `z ~ N(0, I)`. `U⁻ᵀ` is lower
///   triangular with a positive diagonal and `U⁻ᵀ(U⁻ᵀ)ᵀ = R⁻¹`, so it is the
///   lower Cholesky factor of R⁻¹: the same draws as a dense factor of the
///   covariance would give, at O(free) per draw instead of O(free²).
/// - Projection: M is R⁻¹ with column j scaled so its largest entry is
///   `1/free` (Kalakrishnan et al., STOMP, 2011); `M δθ = R⁻¹ (c ∘ δθ)` with
///   `c_j = 1 / (free · max_i (R⁻¹)_ij)`, one banded solve.
///
/// The scales need every column of R⁻¹ once: O(free²) time at build, O(free)
/// memory, with the caller's stop flag polled between columns.
#[derive(Debug, Clone)]
pub struct StompMatrices {
    /// `upper[i][k] = U[i, i + k]`, k = 0..=BAND (entries past the end are 0).
    upper: Vec<[f64; BAND + 1]>,
    /// `1 / √max(R⁻¹)`.
    noise_scale: f64,
    /// `c_j` of the projection.
    column_scale: Vec<f64>,
}

impl StompMatrices {
    /// The matrices for `free ≥ 1` waypoints; `deadline` is polled while
    /// the columns of R⁻¹ are scanned.
    pub fn new(free: usize, deadline: Deadline<'_>) -> Result<Self, MatricesError> {
        if free == 0 {
            return Err(MatricesError::Empty);
        }
        let upper = upper_cholesky(free);
        let mut me = Self {
            upper,
            noise_scale: 0.0,
            column_scale: vec![0.0; free],
        };
        // R is Toeplitz, hence persymmetric (J R J = R with J the reversal),
        // and so is R⁻¹: column free−1−j is column j reversed. Half the
        // columns give every column maximum and the whole diagonal.
        let mut column = DVector::zeros(free);
        let mut max_diagonal = 0.0_f64;
        for j in 0..free.div_ceil(2) {
            if j.is_multiple_of(COLUMNS_PER_CHECK) && deadline.expired() {
                return Err(MatricesError::Stopped);
            }
            column.fill(0.0);
            column[j] = 1.0;
            me.solve_r_in_place(&mut column);
            let col_max = column.iter().fold(f64::MIN, |m, v| m.max(*v));
            let scale = 1.0 / (col_max * free as f64);
            me.column_scale[j] = scale;
            me.column_scale[free - 1 - j] = scale;
            max_diagonal = max_diagonal.max(column[j]);
        }
        // An SPD matrix's largest entry in magnitude is on its diagonal
        // (|a_ij| ≤ √(a_ii a_jj)).
        me.noise_scale = 1.0 / max_diagonal.sqrt();
        Ok(me)
    }

    /// Free waypoints these matrices are sized for.
    pub fn free(&self) -> usize {
        self.upper.len()
    }

    /// `out = σ · U⁻ᵀ z / √max(R⁻¹)`: a draw of `N(0, σ² · covariance)` from
    /// standard normal `z` (both of length `free`).
    pub fn sample_noise(&self, sigma: f64, z: &DVector<f64>, out: &mut DVector<f64>) {
        out.copy_from(z);
        self.solve_upper_transposed(out);
        *out *= sigma * self.noise_scale;
    }

    /// `out = M δθ` (both of length `free`).
    pub fn project(&self, delta: &DVector<f64>, out: &mut DVector<f64>) {
        for ((o, d), c) in out.iter_mut().zip(delta.iter()).zip(&self.column_scale) {
            *o = d * c;
        }
        self.solve_r_in_place(out);
    }

    /// `x ← R⁻¹ x` by `U w = x` (upward) then `Uᵀ y = w` (downward).
    fn solve_r_in_place(&self, x: &mut DVector<f64>) {
        let n = self.free();
        for i in (0..n).rev() {
            let row = &self.upper[i];
            let mut s = x[i];
            for k in 1..=BAND.min(n - 1 - i) {
                s -= row[k] * x[i + k];
            }
            x[i] = s / row[0];
        }
        self.solve_upper_transposed(x);
    }

    /// `x ← U⁻ᵀ x`: forward substitution with the lower triangular `Uᵀ`.
    fn solve_upper_transposed(&self, x: &mut DVector<f64>) {
        for i in 0..x.len() {
            let mut s = x[i];
            for k in 1..=BAND.min(i) {
                s -= self.upper[i - k][k] * x[i - k];
            }
            x[i] = s / self.upper[i][0];
        }
    }
}

/// R's entry at lag `d` (×1, `dt` = 1).
fn r_entry(d: usize) -> f64 {
    if d <= BAND { R_LAGS[d] / 144.0 } else { 0.0 }
}

/// The banded factor U of `R = U Uᵀ`, U upper triangular with a positive
/// diagonal, factorised from the last row up:
/// `U[i,i] = √(R[i,i] − Σ_{k>i} U[i,k]²)`,
/// `U[j,i] = (R[j,i] − Σ_{k>i} U[j,k] U[i,k]) / U[i,i]` for `i − BAND ≤ j < i`.
/// R is positive definite (AᵀA with A of full column rank), so every pivot
/// is positive.
fn upper_cholesky(n: usize) -> Vec<[f64; BAND + 1]> {
    let mut u = vec![[0.0; BAND + 1]; n];
    let at =
        |u: &[[f64; BAND + 1]], r: usize, c: usize| if c >= r && c - r <= BAND { u[r][c - r] } else { 0.0 };
    for i in (0..n).rev() {
        let tail = (i + 1)..(i + BAND + 1).min(n);
        let pivot = r_entry(0) - tail.clone().map(|k| at(&u, i, k).powi(2)).sum::<f64>();
        let d = pivot.sqrt();
        u[i][0] = d;
        for j in i.saturating_sub(BAND)..i {
            let s: f64 = tail.clone().map(|k| at(&u, j, k) * at(&u, i, k)).sum();
            u[j][i - j] = (r_entry(i - j) - s) / d;
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// R by hand: Σ over full stencils of c_i c_j, i.e. the autocorrelation
    /// of [−1, 16, −30, 16, −1] at lag |i − j|, over 144.
    fn r_by_hand(free: usize) -> DMatrix<f64> {
        let lag = [1414.0, -992.0, 316.0, -32.0, 1.0];
        DMatrix::from_fn(free, free, |i, j| {
            let d = i.abs_diff(j);
            if d <= 4 { lag[d] / 144.0 } else { 0.0 }
        })
    }

    /// R from the padded dense A, as the definition reads.
    fn r_from_a(free: usize) -> DMatrix<f64> {
        let a = finite_difference_matrix(free + 2 * PADDING, 1.0);
        (a.transpose() * &a)
            .view((PADDING, PADDING), (free, free))
            .into_owned()
    }

    /// The dense reference: covariance factor `chol(R⁻¹ / max R⁻¹)` and M
    /// (R⁻¹ with each column scaled to a maximum of 1/free).
    fn dense_reference(free: usize) -> (DMatrix<f64>, DMatrix<f64>) {
        let r_inv = r_from_a(free).cholesky().unwrap().inverse();
        let max = r_inv.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let cov = &r_inv / max;
        let factor = ((&cov + cov.transpose()) * 0.5).cholesky().unwrap().l();
        let mut m = r_inv;
        for mut col in m.column_iter_mut() {
            let col_max = col.iter().fold(f64::MIN, |a, v| a.max(*v));
            col *= 1.0 / (col_max * free as f64);
        }
        (factor, m)
    }

    #[test]
    fn a_rows_carry_the_stencil_and_are_truncated_at_the_ends() {
        let a = finite_difference_matrix(4, 0.5);
        // 1/(12·0.25) = 1/3
        let s = 1.0 / 3.0;
        let expected = [
            [-30.0, 16.0, -1.0, 0.0],
            [16.0, -30.0, 16.0, -1.0],
            [-1.0, 16.0, -30.0, 16.0],
            [0.0, -1.0, 16.0, -30.0],
        ];
        for i in 0..4 {
            for j in 0..4 {
                assert!((a[(i, j)] - expected[i][j] * s).abs() < 1e-12, "A[{i},{j}]");
            }
        }
    }

    #[test]
    fn r_of_the_padded_a_is_the_hand_computed_autocorrelation() {
        for free in [1, 3, 4, 5, 12] {
            assert!(
                (r_from_a(free) - r_by_hand(free)).abs().max() < 1e-9,
                "free = {free}"
            );
        }
        // Hand-written N = 3 (no lag beyond 2 fits): ×144
        let r144 = r_from_a(3) * 144.0;
        let expected = [
            [1414.0, -992.0, 316.0],
            [-992.0, 1414.0, -992.0],
            [316.0, -992.0, 1414.0],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((r144[(i, j)] - expected[i][j]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn the_banded_factor_reproduces_r() {
        for free in [1, 2, 5, 9, 40] {
            let m = StompMatrices::new(free, Deadline::none()).unwrap();
            let u = DMatrix::from_fn(free, free, |i, j| {
                if j >= i && j - i <= BAND {
                    m.upper[i][j - i]
                } else {
                    0.0
                }
            });
            let err = (&u * u.transpose() - r_by_hand(free)).abs().max();
            assert!(err < 1e-12, "free = {free}: |UUᵀ − R| = {err}");
        }
    }

    #[test]
    fn noise_and_projection_equal_the_dense_matrices() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for free in [1, 2, 3, 7, 38, 101] {
            let m = StompMatrices::new(free, Deadline::none()).unwrap();
            let (factor, dense_m) = dense_reference(free);
            for _ in 0..5 {
                let z = DVector::from_fn(free, |_, _| super::super::noise::standard_normal(&mut rng));
                let mut got = DVector::zeros(free);
                m.sample_noise(0.7, &z, &mut got);
                let want = &factor * &z * 0.7;
                let err = (&got - &want).abs().max();
                assert!(err < 1e-9 * (1.0 + want.abs().max()), "noise, free {free}: {err}");
                m.project(&z, &mut got);
                let want = &dense_m * &z;
                let err = (&got - &want).abs().max();
                assert!(err < 1e-9 * (1.0 + want.abs().max()), "M δθ, free {free}: {err}");
            }
        }
    }

    #[test]
    fn projected_unit_vectors_peak_at_one_over_n() {
        // M's columns are M e_j: each peaks at exactly 1/free.
        for free in [1, 3, 5, 38] {
            let m = StompMatrices::new(free, Deadline::none()).unwrap();
            let mut e = DVector::zeros(free);
            let mut col = DVector::zeros(free);
            for j in 0..free {
                e.fill(0.0);
                e[j] = 1.0;
                m.project(&e, &mut col);
                let max = col.iter().fold(f64::MIN, |a, v| a.max(*v));
                assert!((max - 1.0 / free as f64).abs() < 1e-12, "free {free}, column {j}");
            }
        }
    }

    #[test]
    fn the_sampled_noise_has_the_normalised_inverse_covariance() {
        let free = 5;
        let m = StompMatrices::new(free, Deadline::none()).unwrap();
        let r_inv = r_by_hand(free).cholesky().unwrap().inverse();
        let covariance = &r_inv / r_inv.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let sigma = 0.3;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let samples = 40_000;
        let mut acc = DMatrix::<f64>::zeros(free, free);
        let mut z = DVector::zeros(free);
        let mut e = DVector::zeros(free);
        for _ in 0..samples {
            for v in z.iter_mut() {
                *v = super::super::noise::standard_normal(&mut rng);
            }
            m.sample_noise(sigma, &z, &mut e);
            acc += &e * e.transpose();
        }
        acc /= samples as f64;
        let expected = covariance * (sigma * sigma);
        let err = (&acc - &expected).abs().max();
        // standard error of a variance estimate ≈ σ²·√(2/n) ≈ 0.0006
        assert!(err < 0.004, "empirical covariance off by {err}");
    }

    #[test]
    fn the_largest_size_builds_in_linear_memory_and_stops_when_asked() {
        // 10,000 timesteps: a dense R⁻¹ would take 800 MB; the banded
        // matrices hold a few vectors.
        let free = 9_998;
        let m = StompMatrices::new(free, Deadline::none()).unwrap();
        assert_eq!(m.free(), free);
        let mut e = DVector::zeros(free);
        e[free / 2] = 1.0;
        let mut col = DVector::zeros(free);
        m.project(&e, &mut col);
        assert!(col.iter().all(|v| v.is_finite()));
        // A raised stop flag ends the build at the next check.
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let stop = || calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 2;
        assert_eq!(
            StompMatrices::new(free, Deadline::none().with_cancel(&stop)).unwrap_err(),
            MatricesError::Stopped
        );
        assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 3);
        assert_eq!(
            StompMatrices::new(0, Deadline::none()).unwrap_err(),
            MatricesError::Empty
        );
    }
}
