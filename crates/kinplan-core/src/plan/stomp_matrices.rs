//! STOMP's fixed matrices (docs/planning.md#stomp): the finite-difference
//! acceleration matrix A, the control-cost matrix R = AᵀA, the noise
//! covariance R⁻¹ (normalised) with its Cholesky factor, and the smoothing
//! projection M.

use nalgebra::DMatrix;

/// Central finite-difference acceleration stencil, times 12:
/// `q̈(t) ≈ (−q(t−2) + 16q(t−1) − 30q(t) + 16q(t+1) − q(t+2)) / (12 dt²)`.
pub const ACCELERATION_STENCIL: [f64; 5] = [-1.0, 16.0, -30.0, 16.0, -1.0];

/// Waypoints of padding on each side of the free waypoints when R is built:
/// with four, every row of A that touches a free waypoint carries the whole
/// stencil, so R does not depend on how the ends are truncated.
pub const PADDING: usize = 4;

/// The `len × len` acceleration matrix: row `i` holds the stencil
/// `[−1, 16, −30, 16, −1] / (12 dt²)` centred on column `i`; entries that
/// would fall outside the matrix are dropped (rows near the ends are
/// truncated). `dt` in seconds (or 1 for a per-timestep unit).
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

/// STOMP's matrices for `free` optimised waypoints (the trajectory's
/// timesteps minus the fixed start and goal).
///
/// - `a`: [`finite_difference_matrix`] of the padded length `free + 2·PADDING`.
/// - `r = (AᵀA)[PADDING.., PADDING..]`, `free × free` (1/s⁴ with `dt` in s):
///   banded Toeplitz with, ×144 dt⁴, diagonal 1414 and off-diagonals
///   −992, 316, −32, 1 (the stencil's autocorrelation).
/// - `covariance = R⁻¹ / max(R⁻¹)`: the noise of joint d is
///   `ε_d ~ N(0, σ_d² · covariance)` — smooth, largest in the middle,
///   vanishing towards the fixed ends. `covariance_factor` is its lower
///   Cholesky factor L, so `ε_d = σ_d · L z` with `z ~ N(0, I)`.
/// - `m`: R⁻¹ with every column scaled so its largest entry is `1/free`;
///   the update is projected as `θ ← θ + M δθ`.
#[derive(Debug, Clone)]
pub struct StompMatrices {
    pub a: DMatrix<f64>,
    pub r: DMatrix<f64>,
    pub covariance: DMatrix<f64>,
    pub covariance_factor: DMatrix<f64>,
    pub m: DMatrix<f64>,
}

impl StompMatrices {
    /// The matrices for `free ≥ 1` waypoints and timestep `dt > 0` (the
    /// covariance and M do not depend on `dt`). `None` if R were not
    /// positive definite (it always is for a valid size; kept as a guard).
    pub fn new(free: usize, dt: f64) -> Option<Self> {
        if free == 0 || !(dt.is_finite() && dt > 0.0) {
            return None;
        }
        let padded = free + 2 * PADDING;
        let a = finite_difference_matrix(padded, dt);
        let r_padded = a.transpose() * &a;
        let r = r_padded.view((PADDING, PADDING), (free, free)).into_owned();
        let r_inv = r.clone().cholesky()?.inverse();
        let max = r_inv.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !(max.is_finite() && max > 0.0) {
            return None;
        }
        let covariance = &r_inv / max;
        // Symmetrise against round-off before factorising.
        let sym = (&covariance + covariance.transpose()) * 0.5;
        let covariance_factor = sym.cholesky()?.l();
        let mut m = r_inv;
        for mut col in m.column_iter_mut() {
            let col_max = col.iter().fold(0.0_f64, |m, v| m.max(*v));
            if col_max > 0.0 {
                col *= 1.0 / (col_max * free as f64);
            }
        }
        Some(Self {
            a,
            r,
            covariance,
            covariance_factor,
            m,
        })
    }

    /// Free waypoints these matrices are sized for.
    pub fn free(&self) -> usize {
        self.r.nrows()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R by hand: Σ over full stencils of c_i c_j, i.e. the autocorrelation
    /// of [−1, 16, −30, 16, −1] at lag |i − j|, over 144.
    fn r_by_hand(free: usize) -> DMatrix<f64> {
        let lag = [1414.0, -992.0, 316.0, -32.0, 1.0];
        DMatrix::from_fn(free, free, |i, j| {
            let d = i.abs_diff(j);
            if d <= 4 { lag[d] / 144.0 } else { 0.0 }
        })
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
    fn r_matches_the_hand_computed_autocorrelation_for_3_to_5() {
        for free in 3..=5 {
            let m = StompMatrices::new(free, 1.0).unwrap();
            let hand = r_by_hand(free);
            assert!((&m.r - &hand).abs().max() < 1e-9, "free = {free}: {}", m.r);
        }
        // Hand-written N = 3 (no lag beyond 2 fits): ×144
        let m = StompMatrices::new(3, 1.0).unwrap();
        let r144 = &m.r * 144.0;
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
    fn r_scales_with_dt_to_the_minus_four() {
        let a = StompMatrices::new(4, 1.0).unwrap();
        let b = StompMatrices::new(4, 0.5).unwrap();
        assert!((&b.r - &a.r * 16.0).abs().max() < 1e-9);
        // covariance and M are scale-free
        assert!((&b.covariance - &a.covariance).abs().max() < 1e-12);
        assert!((&b.m - &a.m).abs().max() < 1e-12);
    }

    #[test]
    fn m_columns_peak_at_one_over_n_and_covariance_at_one() {
        for free in [1, 3, 5, 38] {
            let m = StompMatrices::new(free, 0.1).unwrap();
            for c in m.m.column_iter() {
                let max = c.iter().fold(f64::MIN, |a, v| a.max(*v));
                assert!((max - 1.0 / free as f64).abs() < 1e-12, "free {free}");
            }
            let cmax = m.covariance.iter().fold(f64::MIN, |a, v| a.max(v.abs()));
            assert!((cmax - 1.0).abs() < 1e-12);
            // M is R⁻¹ with scaled columns: R·M is diagonal
            let rm = &m.r * &m.m;
            for i in 0..free {
                for j in 0..free {
                    if i != j {
                        assert!(rm[(i, j)].abs() < 1e-6 * rm[(j, j)].abs(), "R·M not diagonal");
                    }
                }
            }
        }
    }

    #[test]
    fn the_sampled_noise_has_the_normalised_inverse_covariance() {
        use rand::SeedableRng;
        let free = 5;
        let m = StompMatrices::new(free, 1.0).unwrap();
        let sigma = 0.3;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let samples = 40_000;
        let mut acc = DMatrix::<f64>::zeros(free, free);
        let mut z = nalgebra::DVector::zeros(free);
        for _ in 0..samples {
            for v in z.iter_mut() {
                *v = super::super::noise::standard_normal(&mut rng);
            }
            let e = &m.covariance_factor * &z * sigma;
            acc += &e * e.transpose();
        }
        acc /= samples as f64;
        let expected = &m.covariance * (sigma * sigma);
        let err = (&acc - &expected).abs().max();
        // standard error of a variance estimate ≈ σ²·√(2/n) ≈ 0.0006
        assert!(err < 0.004, "empirical covariance off by {err}");
    }
}
