//! Sine and cosine for forward kinematics, inlined: every checked state
//! turns each joint once, and the C library's `sincos` is a call (a rounding
//! mode saved and restored, table lookups) on that hot path.
//!
//! Method (the classic one of fdlibm's kernels): reduce `x = k·π/2 + r`,
//! `|r| ≤ π/4`, with π/2 split in two parts so that `r` keeps full
//! precision (Cody and Waite), evaluate
//!
//! ```text
//! sin r ≈ r + r³·(S1 + r²·(S2 + … + r²·S6))
//! cos r ≈ 1 − r²/2 + r⁴·(C1 + r²·(C2 + … + r²·C6))
//! ```
//!
//! with fdlibm's minimax coefficients (error below 2⁻⁵⁸ on `[−π/4, π/4]`),
//! and rotate by the quadrant `k mod 4`. Arguments beyond
//! [`REDUCED_RANGE`] or not finite go to the library.

/// Largest `|x|` reduced here: with `|k| < 2²⁰` the two-part reduction is
/// exact in its first product and loses no more than an ulp of `r`.
const REDUCED_RANGE: f64 = 1.0e5;

// π/2 = PIO2_HI + PIO2_LO, PIO2_HI with its low 33 bits zero, so k·PIO2_HI
// is exact for |k| < 2²⁰.
const PIO2_HI: f64 = 1.5707963267341256;
const PIO2_LO: f64 = 6.077100506506192e-11;
const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
/// 1.5·2⁵²: adding it leaves an integer in the low mantissa bits.
const ROUNDING_SHIFT: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -0.16666666666666632;
const S2: f64 = 0.00833333333332249;
const S3: f64 = -0.0001984126982985795;
const S4: f64 = 2.7557313707070068e-06;
const S5: f64 = -2.5050760253406863e-08;
const S6: f64 = 1.58969099521155e-10;

const C1: f64 = 0.0416666666666666;
const C2: f64 = -0.001388888888887411;
const C3: f64 = 2.480158728947673e-05;
const C4: f64 = -2.7557314351390663e-07;
const C5: f64 = 2.087572321298175e-09;
const C6: f64 = -1.1359647557788195e-11;

/// `(sin x, cos x)`, within a few ulps of 1 of the library's for every
/// finite `x` (tested against it).
#[inline]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() > REDUCED_RANGE {
        return x.sin_cos();
    }
    sin_cos_reduced(x)
}

/// [`sin_cos`] for `|x| ≤` the reduced range only, without the test:
/// branch-free.
#[inline(always)]
pub(crate) fn sin_cos_reduced(x: f64) -> (f64, f64) {
    // k = x·2/π rounded to the nearest integer by the 1.5·2⁵² shift (exact
    // for |k| < 2⁵¹; `f64::round` is a library call on baseline x86-64),
    // and k's low bits read off the shifted mantissa
    let shifted = x * TWO_OVER_PI + ROUNDING_SHIFT;
    let k = shifted - ROUNDING_SHIFT;
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let c = 1.0 - 0.5 * z + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    // Quadrant k mod 4: (s, c), (c, −s), (−s, −c), (−c, s), chosen with bit
    // operations: the quadrant follows the joint angle, so a jump on it is
    // mispredicted whenever a joint crosses ±π/4 (turns are half angles).
    let k = shifted.to_bits() as i64;
    let swap = 0u64.wrapping_sub((k & 1) as u64); // all ones when odd
    let (s, c) = (s.to_bits(), c.to_bits());
    let (sin, cos) = ((s & !swap) | (c & swap), (c & !swap) | (s & swap));
    let sign = |flip: i64| ((flip & 2) as u64) << 62;
    (f64::from_bits(sin ^ sign(k)), f64::from_bits(cos ^ sign(k + 1)))
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    #[test]
    fn matches_the_library_within_a_few_ulps() {
        let mut worst = 0.0f64;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (ls, lc) = x.sin_cos();
            // absolute error (both are ≤ 1): a few ulps of 1
            worst = worst.max((s - ls).abs()).max((c - lc).abs());
        };
        for i in -200_000..=200_000 {
            check(i as f64 * 1e-4); // [−20, 20] densely
        }
        for k in -64..=64 {
            // the quadrant edges, where the reduction switches
            let edge = k as f64 * std::f64::consts::FRAC_PI_4;
            for d in [-1e-12, 0.0, 1e-12] {
                check(edge + d);
            }
        }
        for x in [1e-300, -1e-300, 0.0, -0.0, 3.0e4, -9.9e4, 1e5, 1.5e5, 1e300] {
            check(x);
        }
        assert!(worst <= 4.0 * f64::EPSILON, "worst {worst:e}");
    }

    #[test]
    fn hands_non_finite_and_huge_arguments_to_the_library() {
        assert!(sin_cos(f64::NAN).0.is_nan());
        assert!(sin_cos(f64::INFINITY).1.is_nan());
        assert_eq!(sin_cos(1e300), 1e300f64.sin_cos());
    }
}
