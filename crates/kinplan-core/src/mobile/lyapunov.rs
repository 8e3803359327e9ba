//! Lyapunov pose controller (S1 §3.4, §4.2.3; Aicardi, Casalino, Bicchi, Balestrino 1995):
//! drive a unicycle to a goal position *and* heading.

use serde::{Deserialize, Serialize};

use super::angle::{sinc, wrap_angle};
use super::error::{MobileError, check_positive, check_range};
use super::field::{FollowField, LyapunovParam, MobileField};
use super::pose::{Pose, Twist};

/// Gains of the Aicardi controller. S1 recommends γ, λ, h ∈ (0, 1) and k ∈ (0, 6);
/// stability only needs all four positive, which is what [`LyapunovParams::validate`] checks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LyapunovParams {
    /// γ, 1/s: speed gain (default 0.5).
    pub gamma: f64,
    /// k, 1/s: heading-error gain (default 0.3).
    pub k: f64,
    /// h, dimensionless: weight of the goal-heading error Θ (default 0.5).
    pub h: f64,
    /// λ, 1/m²: weight of the distance in V (default 0.55); it does not enter the control law.
    pub lambda: f64,
    /// Speed limit |v|, m/s (default 0.5).
    pub max_speed: f64,
    /// Yaw-rate limit |ω|, rad/s (default 2.0).
    pub max_yaw_rate: f64,
}

impl Default for LyapunovParams {
    fn default() -> Self {
        Self {
            gamma: 0.5,
            k: 0.3,
            h: 0.5,
            lambda: 0.55,
            max_speed: 0.5,
            max_yaw_rate: 2.0,
        }
    }
}

impl LyapunovParams {
    /// All gains and limits positive and at most 1e6 (so no product overflows).
    pub fn validate(&self) -> Result<(), MobileError> {
        for (f, v) in [
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::Gamma)),
                self.gamma,
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::K)),
                self.k,
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::H)),
                self.h,
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::Lambda)),
                self.lambda,
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::MaxSpeed)),
                self.max_speed,
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::MaxYawRate)),
                self.max_yaw_rate,
            ),
        ] {
            check_positive(f, v)?;
            check_range(f, v, 0.0, 1e6)?;
        }
        Ok(())
    }
}

/// Output of [`lyapunov_step`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LyapunovCommand {
    /// Saturated unicycle command (v, 0, ω).
    pub twist: Twist,
    /// Distance to the goal e, m.
    pub e: f64,
    /// Heading error to the line of sight α ∈ (−π, π], rad.
    pub alpha: f64,
    /// Line-of-sight angle relative to the goal heading Θ ∈ (−π, π], rad.
    pub theta: f64,
    /// V = ½(λe² + α² + hΘ²).
    pub v_value: f64,
    /// Common factor s ∈ (0, 1] applied to (v, ω) by saturation.
    pub scale: f64,
}

/// V = ½(λ e² + α² + h Θ²).
pub fn lyapunov_value(e: f64, alpha: f64, theta: f64, params: &LyapunovParams) -> f64 {
    0.5 * (params.lambda * e * e + alpha * alpha + params.h * theta * theta)
}

/// The Aicardi et al. (1995) law (docs/mobile.md#lyapunov-pose-controller; S1 §4.2.3). In
/// the goal frame (goal at the origin, heading 0) with robot position (ξ, η) and heading φ:
///
/// e = √(ξ² + η²), Θ = atan2(−η, −ξ) (bearing of robot→goal), α = wrap(Θ − φ),
/// v = γ e cos α,  ω = k α + γ (cos α · sin α / α)(α + h Θ),
///
/// with sin α / α → 1 at α = 0. The closed loop is ė = −γ e cos²α,
/// α̇ = −kα − γhΘ cosα sinα/α, Θ̇ = γ cosα sinα, so V = ½(λe² + α² + hΘ²) has
/// V̇ = −λγ cos²α e² − kα² ≤ 0. Saturation scales (v, ω) by one factor s ∈ (0, 1]
/// (a time scaling, so V̇ stays ≤ 0). At e = 0, Θ := 0 and the robot turns in place.
///
/// ```
/// use kinplan_core::mobile::{lyapunov_step, LyapunovParams, Pose};
/// // Robot 1 m behind the goal, aligned: α = Θ = 0, v = γe = 0.5, ω = 0.
/// let c = lyapunov_step(Pose::new(-1.0, 0.0, 0.0), Pose::new(0.0, 0.0, 0.0), &LyapunovParams::default()).unwrap();
/// assert!((c.twist.vx - 0.5).abs() < 1e-12 && c.twist.omega.abs() < 1e-12);
/// ```
pub fn lyapunov_step(
    state: Pose,
    goal: Pose,
    params: &LyapunovParams,
) -> Result<LyapunovCommand, MobileError> {
    params.validate()?;
    state.validate(MobileField::State)?;
    goal.validate(MobileField::Goal)?;
    Ok(lyapunov_step_unchecked(state, goal, params))
}

pub(crate) fn lyapunov_step_unchecked(state: Pose, goal: Pose, p: &LyapunovParams) -> LyapunovCommand {
    let (sg, cg) = goal.theta.sin_cos();
    let dx = state.x - goal.x;
    let dy = state.y - goal.y;
    let xi = cg * dx + sg * dy;
    let eta = -sg * dx + cg * dy;
    let phi = wrap_angle(state.theta - goal.theta);
    let e = xi.hypot(eta);
    let th = if e > 0.0 { (-eta).atan2(-xi) } else { 0.0 };
    let alpha = wrap_angle(th - phi);
    let ca = alpha.cos();
    let v = p.gamma * e * ca;
    let omega = p.k * alpha + p.gamma * ca * sinc(alpha) * (alpha + p.h * th);
    let mut scale = 1.0f64;
    if v.abs() > p.max_speed {
        scale = scale.min(p.max_speed / v.abs());
    }
    if omega.abs() > p.max_yaw_rate {
        scale = scale.min(p.max_yaw_rate / omega.abs());
    }
    LyapunovCommand {
        twist: Twist::unicycle(v * scale, omega * scale),
        e,
        alpha,
        theta: th,
        v_value: lyapunov_value(e, alpha, th, p),
        scale,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::pose::integrate_twist;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    fn unlimited(g: f64, k: f64, h: f64, l: f64) -> LyapunovParams {
        LyapunovParams {
            gamma: g,
            k,
            h,
            lambda: l,
            max_speed: 1e6,
            max_yaw_rate: 1e6,
        }
    }

    #[test]
    fn hand_computed_values_at_the_spec_start() {
        // S = (−1, 1, 3π/4), G = 0: e = √2, Θ = atan2(−1, 1) = −π/4, α = wrap(−π) = ±π,
        // v = γ e cos α = −0.5√2, sinα/α = 0 → |ω| = kπ = 0.3π,
        // V = ½(0.55·2 + π² + 0.5·π²/16) = 5.638 998.
        let p = unlimited(0.5, 0.3, 0.5, 0.55);
        let c = lyapunov_step(Pose::new(-1.0, 1.0, 3.0 * FRAC_PI_4), Pose::default(), &p).unwrap();
        assert!((c.e - 2f64.sqrt()).abs() < 1e-12);
        assert!((c.theta + FRAC_PI_4).abs() < 1e-12);
        assert!((c.alpha.abs() - PI).abs() < 1e-12);
        assert!((c.twist.vx + 0.5 * 2f64.sqrt()).abs() < 1e-12);
        assert!((c.twist.omega.abs() - 0.3 * PI).abs() < 1e-9);
        let v = 0.5 * (1.1 + PI * PI + 0.5 * PI * PI / 16.0);
        assert!((c.v_value - v).abs() < 1e-9);
    }

    #[test]
    fn hand_computed_values_beside_the_goal() {
        // Robot at (0, −1) heading 0: Θ = π/2, α = π/2, v = 0, ω = kπ/2 + γ·0 = 0.4712389.
        let p = unlimited(0.5, 0.3, 0.5, 0.55);
        let c = lyapunov_step(Pose::new(0.0, -1.0, 0.0), Pose::default(), &p).unwrap();
        assert!(c.twist.vx.abs() < 1e-12);
        assert!((c.twist.omega - 0.3 * FRAC_PI_2).abs() < 1e-12);
        // Same pose in a goal frame shifted to (2, 3) and rotated by π/2: (2+1, 3+0, π/2).
        let c2 = lyapunov_step(Pose::new(3.0, 3.0, FRAC_PI_2), Pose::new(2.0, 3.0, FRAC_PI_2), &p).unwrap();
        assert!((c2.twist.omega - c.twist.omega).abs() < 1e-12 && (c2.v_value - c.v_value).abs() < 1e-12);
    }

    #[test]
    fn bad_gains_and_states_are_rejected() {
        let g = Pose::default();
        let zero_k = LyapunovParams {
            k: 0.0,
            ..LyapunovParams::default()
        };
        assert!(
            matches!(lyapunov_step(Pose::new(1.0, 0.0, 0.0), g, &zero_k), Err(MobileError::NotPositive { field, .. }) if field == MobileField::Follow(FollowField::Lyapunov(LyapunovParam::K)))
        );
        let huge = LyapunovParams {
            gamma: 1e300,
            ..LyapunovParams::default()
        };
        assert!(lyapunov_step(Pose::new(1.0, 0.0, 0.0), g, &huge).is_err());
        assert!(lyapunov_step(Pose::new(1.0, 0.0, f64::INFINITY), g, &LyapunovParams::default()).is_err());
    }

    #[test]
    fn saturation_is_a_common_scale() {
        let p = LyapunovParams {
            max_speed: 0.1,
            ..LyapunovParams::default()
        };
        let free = lyapunov_step(
            Pose::new(-2.0, 0.5, 0.3),
            Pose::default(),
            &unlimited(0.5, 0.3, 0.5, 0.55),
        )
        .unwrap();
        let c = lyapunov_step(Pose::new(-2.0, 0.5, 0.3), Pose::default(), &p).unwrap();
        assert!((c.twist.vx.abs() - 0.1).abs() < 1e-12);
        assert!((c.twist.omega / c.twist.vx - free.twist.omega / free.twist.vx).abs() < 1e-9);
    }

    /// Simulates the closed loop; returns (max increase of V, final pose).
    fn run(start: Pose, p: &LyapunovParams, dt: f64, t_end: f64) -> (f64, Pose, f64) {
        let mut s = start;
        let mut prev = lyapunov_step(s, Pose::default(), p).unwrap().v_value;
        let v0 = prev;
        let mut worst = f64::NEG_INFINITY;
        for _ in 0..(t_end / dt) as usize {
            let c = lyapunov_step(s, Pose::default(), p).unwrap();
            s = integrate_twist(s, c.twist, dt);
            let v = lyapunov_step(s, Pose::default(), p).unwrap().v_value;
            worst = worst.max(v - prev);
            prev = v;
        }
        (worst, s, v0)
    }

    #[test]
    fn spec_start_converges_and_v_never_increases() {
        let p = LyapunovParams::default();
        let (worst, s, _) = run(Pose::new(-1.0, 1.0, 3.0 * FRAC_PI_4), &p, 0.01, 120.0);
        assert!(worst <= 1e-12, "V increased by {worst}");
        assert!(s.x.hypot(s.y) < 0.01, "{s:?}");
        assert!(wrap_angle(s.theta).abs() < 1f64.to_radians(), "{s:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        #[test]
        fn default_gains_converge_from_random_starts(x in -3.0..3.0f64, y in -3.0..3.0f64, th in -PI..PI) {
            // Discrete steps of 10 ms: V may rise by O(dt²) (seen: ≤ 5e-12 at V ≈ 1e-3, e ≈ 2e-5 m).
            let (worst, s, v0) = run(Pose::new(x, y, th), &LyapunovParams::default(), 0.01, 150.0);
            prop_assert!(worst <= 1e-9 * (1.0 + v0), "V increased by {}", worst);
            prop_assert!(s.x.hypot(s.y) < 0.01 && wrap_angle(s.theta).abs() < 1f64.to_radians(), "{:?}", s);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn v_is_non_increasing_from_random_starts(
            x in -3.0..3.0f64, y in -3.0..3.0f64, th in -PI..PI,
            g in 0.05..0.99f64, k in 0.05..5.9f64, h in 0.05..0.99f64, l in 0.05..0.99f64,
        ) {
            let p = unlimited(g, k, h, l);
            let (worst, _, v0) = run(Pose::new(x, y, th), &p, 0.002, 10.0);
            prop_assert!(worst <= 1e-9 * (1.0 + v0), "V increased by {}", worst);
        }
    }
}
