//! Angle helpers: wrapping to (−π, π] and the removable singularities sin x / x, (1 − cos x) / x.

use std::f64::consts::{PI, TAU};

/// Wraps an angle to (−π, π]. Non-finite input is returned unchanged.
///
/// ```
/// use kinplan_core::mobile::wrap_angle;
/// assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
/// assert_eq!(wrap_angle(0.5), 0.5);
/// ```
pub fn wrap_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let r = a.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

/// sin x / x with the limit 1 at x = 0 (Taylor series below |x| < 1e-4).
pub fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// (1 − cos x) / x with the limit 0 at x = 0.
pub(crate) fn versinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        x / 2.0 - x * x * x / 24.0
    } else {
        let s = (x / 2.0).sin();
        2.0 * s * s / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_is_half_open_at_minus_pi() {
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(-PI - 0.1) - (PI - 0.1)).abs() < 1e-12);
        assert!((wrap_angle(7.0) - (7.0 - TAU)).abs() < 1e-12);
    }

    #[test]
    fn singular_ratios_are_continuous() {
        assert!((sinc(1e-5) - 1.0).abs() < 1e-9);
        assert!((sinc(0.5) - 0.958_851_077_208_406).abs() < 1e-12);
        assert!((versinc(0.5) - (1.0 - 0.5f64.cos()) / 0.5).abs() < 1e-12);
        assert!((versinc(2e-5) - 1e-5).abs() < 1e-12);
    }
}
