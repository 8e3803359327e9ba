//! The fixed-size Jacobi kernel: `W` with at most 8 rows (every 6×n and 3×n IK
//! Jacobian with n ≤ 8) on stack arrays padded to an even length, column pairs in
//! round-robin (Brent–Luk) order, squared column norms cached across a sweep.

use nalgebra::DMatrix;

use super::svd::{MAX_SWEEPS, SvdWorkspace};

impl SvdWorkspace {
    /// Fixed-size path for `W` with `rows ≤ L` rows and `k ≤ rows` columns, `L` even so
    /// the column loops map onto pairs of SIMD lanes. Columns of `W` and `V` are padded
    /// with zeros to length `L`; rotations keep the padding zero.
    #[inline(always)]
    pub(super) fn fixed<const L: usize>(&mut self, a: &DMatrix<f64>, frob2: f64) -> usize {
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
}

/// Column pairs of one sweep for `MAX_FIXED` columns.
pub(super) const PAIRS: usize = MAX_FIXED * (MAX_FIXED - 1) / 2;

/// The round-robin (Brent–Luk) order of the column pairs of one sweep, for every column
/// count `k ≤ MAX_FIXED` (entry `k`, its first `k(k−1)/2` pairs), built at compile time:
/// `k − 1` rounds (k even; an odd `k` gets a dummy column) of disjoint pairs, seat 0
/// fixed and the other seats moving one place per round (circle method). Pairs within
/// a round touch different columns, so their rotations are independent and overlap in
/// the CPU pipeline instead of waiting on each other as in the row-cyclic order.
pub(super) const ROUND_ROBIN: [[(u8, u8); PAIRS]; MAX_FIXED + 1] = round_robin_tables();

pub(super) const fn round_robin_tables() -> [[(u8, u8); PAIRS]; MAX_FIXED + 1] {
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
pub(super) const MAX_FIXED: usize = 8;

/// The same rotation as [`jacobi_rotation`] (for a pair known to need one), with a
/// shorter chain of dependent square roots and divisions (the latency of a sweep): with
/// `d = β − α`, `h = √(d² + 4γ²)`, `m = h + |d|` and `r = √(2hm)`,
/// `c = m / r`, `s = sign(d) 2γ / r`, `t = s / c = sign(d) 2γ / m` — the same
/// `t = sign(ζ)/(|ζ| + √(1 + ζ²))`, `ζ = d/(2γ)`, `c = 1/√(1 + t²)` (since
/// `m² + 4γ² = 2hm`), with one division on the path to `(c, s)` instead of two.
/// Returns `(c, s, t)`.
#[inline(always)]
pub(super) fn fast_rotation(alpha: f64, beta: f64, gamma: f64) -> (f64, f64, f64) {
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
pub(super) fn dot<const L: usize>(x: &[f64; L], y: &[f64; L]) -> f64 {
    let mut acc = [0.0f64; 2];
    for (xp, yp) in x.chunks_exact(2).zip(y.chunks_exact(2)) {
        acc[0] += xp[0] * yp[0];
        acc[1] += xp[1] * yp[1];
    }
    acc[0] + acc[1]
}

/// `(xᵢ, xⱼ) ← (c xᵢ − s xⱼ, s xᵢ + c xⱼ)` on two fixed-size columns.
#[inline(always)]
pub(super) fn rotate_pair<const L: usize>(
    cols: &mut [[f64; L]; MAX_FIXED],
    i: usize,
    j: usize,
    c: f64,
    s: f64,
) {
    debug_assert!(i < j);
    let (head, tail) = cols.split_at_mut(j);
    for (x, y) in head[i].iter_mut().zip(tail[0].iter_mut()) {
        let (a, b) = (*x, *y);
        *x = c * a - s * b;
        *y = s * a + c * b;
    }
}
