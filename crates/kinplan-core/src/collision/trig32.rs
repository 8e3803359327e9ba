//! Sine and cosine in `f32` for the eight-lane check (`lanes8`), with an
//! error bound the check's soundness margin is built from.
//!
//! Method (Cody and Waite's reduction, then minimax polynomials on the
//! reduced angle, as in Moshier's Cephes `sinf`/`cosf`): with
//! `k = round(x·2/π)` (the `1.5·2²³` shift, exact for `|k| < 2²²`),
//!
//! ```text
//! r = ((x − k·P1) − k·P2) − k·P3,   P1 + P2 + P3 ≈ π/2,
//! sin r ≈ r + r·z·(S1 + z·(S2 + z·S3)),            z = r²
//! cos r ≈ 1 − z/2 + z²·(C1 + z·(C2 + z·C3))
//! ```
//!
//! and the pair rotated by the quadrant `k mod 4`. `P1` has 8 significant
//! bits, so `k·P1` is exact for `|k| < 2¹⁶`, and `x − k·P1` is exact by
//! Sterbenz's lemma (`x` and `k·P1` within a factor of two for `k ≠ 0`).
//! The polynomials' coefficients are Cephes' minimax ones on `[−π/4, π/4]`.
//!
//! **Bound.** For `x` an `f64` with `|x| ≤` [`MAX_TURN`], rounded to `f32`
//! (`x̂ = x(1 + θ)`, `|θ| ≤ u = 2⁻²⁴`) and passed here,
//!
//! ```text
//! |ŝ − sin x|, |ĉ − cos x| ≤ η(|x|max) = ETA0 + u·|x|max
//! ```
//!
//! where `u·|x|max` covers the input rounding (sine and cosine are
//! 1-Lipschitz) and [`ETA0`] = 2⁻²¹ = 8u the rest: the reduction
//! (`≤ 3u(|r| + |k|(P2 + P3)) + |k|·|π/2 − P1 − P2 − P3|`, below `2u` for
//! `|k| ≤ 2¹³`), the polynomials' approximation error (below `u` on
//! `|r| ≤ π/4 + 2⁻²⁰`) and their evaluation in `f32` (Horner, at most
//! eight roundings on terms of size ≤ 1: below `3u`). The test evaluates the
//! bound densely against the library's `f64` sine and cosine.

/// Largest `|x|` (rad) taken here.
pub(crate) const MAX_TURN: f64 = 1.0e4;
/// The part of the error bound that does not grow with `|x|`.
pub(crate) const ETA0: f64 = 1.0 / (1u64 << 21) as f64;

const TWO_OVER_PI: f32 = std::f32::consts::FRAC_2_PI;
/// 1.5·2²³: adding it leaves an integer in the low mantissa bits.
const SHIFT: f32 = 12_582_912.0;
const P1: f32 = 1.570_312_5;
const P2: f32 = 4.837_513e-4;
const P3: f32 = 7.549_79e-8;

const S1: f32 = -1.666_665_5e-1;
const S2: f32 = 8.332_161e-3;
const S3: f32 = -1.951_529_6e-4;
const C1: f32 = 4.166_664_6e-2;
const C2: f32 = -1.388_731_6e-3;
const C3: f32 = 2.443_315_7e-5;

/// `(sin x, cos x)` within `η` of the bound in the module doc, for
/// `|x| ≤` [`MAX_TURN`]; branch-free, so a loop over lanes vectorises.
#[inline(always)]
pub(crate) fn sin_cos32(x: f32) -> (f32, f32) {
    let shifted = x * TWO_OVER_PI + SHIFT;
    let k = shifted - SHIFT;
    let r = ((x - k * P1) - k * P2) - k * P3;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * S3));
    let c = 1.0 - 0.5 * z + z * z * (C1 + z * (C2 + z * C3));
    // quadrant k mod 4: (s, c), (c, −s), (−s, −c), (−c, s), by bit operations
    let k = shifted.to_bits() as i32;
    let swap = 0u32.wrapping_sub((k & 1) as u32);
    let (s, c) = (s.to_bits(), c.to_bits());
    let (sin, cos) = ((s & !swap) | (c & swap), (c & !swap) | (s & swap));
    let sign = |flip: i32| ((flip & 2) as u32) << 30;
    (
        f32::from_bits(sin ^ sign(k)),
        f32::from_bits(cos ^ sign(k.wrapping_add(1))),
    )
}

/// The bound `η` of the module doc for angles up to `max_abs` (rad).
pub(crate) fn eta(max_abs: f64) -> f64 {
    ETA0 + max_abs * f64::from(f32::EPSILON) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worst error over `xs` against the `f64` library, each argument
    /// rounded to `f32` first (as the lanes receive it).
    fn worst(xs: impl Iterator<Item = f64>) -> (f64, f64) {
        let (mut err, mut ratio) = (0.0f64, 0.0f64);
        for x in xs {
            let (s, c) = sin_cos32(x as f32);
            let (ls, lc) = x.sin_cos();
            let e = (f64::from(s) - ls).abs().max((f64::from(c) - lc).abs());
            err = err.max(e);
            ratio = ratio.max(e / eta(x.abs()));
        }
        (err, ratio)
    }

    #[test]
    fn stays_within_the_stated_bound() {
        // [−8, 8] densely (every joint range of an arm), the quadrant edges
        // to ±2¹³·π/2, and large arguments up to the limit
        let dense = (-2_000_000..=2_000_000).map(|i| i as f64 * 4e-6);
        let (err, ratio) = worst(dense);
        assert!(ratio <= 1.0, "dense: error {err:e}, {ratio} of the bound");
        // measured error well below the bound, but not zero: the test can fail
        assert!(err > 1e-8, "{err:e}");
        let edges = (-8192i32..=8192).flat_map(|k| {
            let e = f64::from(k) * std::f64::consts::FRAC_PI_4;
            [e - 1e-7, e, e + 1e-7]
        });
        let (err, ratio) = worst(edges);
        assert!(ratio <= 1.0, "edges: error {err:e}, {ratio} of the bound");
        let large = (0..200_000).map(|i| -MAX_TURN + i as f64 * (2.0 * MAX_TURN / 200_000.0));
        let (err, ratio) = worst(large.chain([MAX_TURN, -MAX_TURN]));
        assert!(ratio <= 1.0, "large: error {err:e}, {ratio} of the bound");
    }
}
