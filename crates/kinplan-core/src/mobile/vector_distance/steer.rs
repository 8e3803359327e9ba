//! The navigator's command (S1 §3.5, eq. 3.50–3.57): the weighted vector sum F around the
//! w'_0 direction of the current mode, and the unicycle command that turns the robot's axis
//! onto it. Pure functions of the state and what the robot sees.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use super::{NavMode, Percept, TurnPreference, TurnSide, VdfParams, VdfState};
use crate::mobile::angle::wrap_angle;
use crate::mobile::pose::{Point2, Twist};

/// The command of one step in the state's (already switched) mode, and F in the world frame.
///
/// w'_0 points at β_0: the goal in R, the locked direction in L, and in T the direction of
/// the nearest reading turned by ±(π/2 + wall_gain·(0.8·d_sa − d_min)), clamped to [π/4, 3π/4],
/// towards the turning side (boundary following at 0.8·d_sa). F = [`vector_sum`]; its
/// direction ψ = arg F (β_0 ± π/2 when F vanishes). With `avoid_blocked_heading`, a ψ into a
/// blocked direction is replaced by the first free direction towards the turning side (in R:
/// the side [`choose_side`] picks). Then ε = wrap(ψ − θ), ω = clamp(k_h·ε, ±ω_max) (on the
/// reversed axis ε + π when reversing is allowed and cos ε < 0), and
/// v = ±v_max·|cos ε|·clamp(gap along travel / slow_distance, 0, 1) (0 when F points behind
/// and reversing is not allowed).
pub fn steer(s: &VdfState, see: &Percept, p: &VdfParams) -> (Twist, Point2) {
    let sign = side_sign(s.side);
    let theta = see.pose.theta;
    let centre = match s.mode {
        NavMode::Rotate => see.goal_dir,
        NavMode::Lock => s.locked_direction,
        NavMode::Track => {
            let (imin, dmin) = see
                .readings
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::INFINITY), |a, (i, d)| if d < a.1 { (i, d) } else { a });
            let obstacle_dir = theta + TAU * imin as f64 / see.readings.len() as f64;
            let target = 0.8 * p.safe_distance;
            let off = (FRAC_PI_2 + p.wall_gain * (target - dmin)).clamp(FRAC_PI_4, 3.0 * FRAC_PI_4);
            obstacle_dir + sign * off
        }
    };
    let (fx, fy) = vector_sum(see, centre, s.mode != NavMode::Rotate, s.side, p);
    let raw = if fx.hypot(fy) > 1e-9 {
        fy.atan2(fx)
    } else {
        centre + sign * FRAC_PI_2
    };
    // Deadlock guard: never steer into a blocked direction; turn towards the turning side
    // until a free one is found (a potential-field local minimum otherwise parks the robot
    // facing an obstacle with zero speed).
    let psi = if p.avoid_blocked_heading && !see.free(raw, p) {
        let side = if s.mode == NavMode::Rotate {
            choose_side(see, raw, p)
        } else {
            s.side
        };
        first_free(see, raw, side, p)
    } else {
        raw
    };
    let eps = wrap_angle(psi - theta);
    let forward = !p.allow_reverse || eps.cos() >= 0.0;
    let (axis_err, dir, travel_dir) = if forward {
        (eps, 1.0, theta)
    } else {
        (wrap_angle(eps + PI), -1.0, theta + PI)
    };
    let gap = see.gap(travel_dir);
    let v = dir * p.max_speed * eps.cos().abs() * (gap / p.slow_distance).clamp(0.0, 1.0);
    let v = if forward && eps.cos() < 0.0 { 0.0 } else { v };
    let omega = (p.heading_gain * axis_err).clamp(-p.max_yaw_rate, p.max_yaw_rate);
    (Twist::unicycle(v, omega), Point2::new(fx, fy))
}

fn side_sign(side: TurnSide) -> f64 {
    match side {
        TurnSide::Left => 1.0,
        TurnSide::Right => -1.0,
    }
}

/// F = Σ f_i w'_i over the real sensors (eq. 3.50): f_i = ±K along sensor i's world
/// direction β_i = θ + 2πi/N (+K when its gap ≥ d_sa); the weight depends continuously on the
/// angle Δ_i = wrap(β_i − β_0) to the w'_0 direction, w'(Δ) = decay^(|Δ| / (2π/N)), times
/// 1 + (turn_gain − 1)·max(0, ±sin Δ) on the turning side when `turning`. Weights that
/// move continuously with β_0 avoid the chatter of snapping w'_0 to the nearest sensor.
pub(super) fn vector_sum(
    see: &Percept,
    centre: f64,
    turning: bool,
    side: TurnSide,
    p: &VdfParams,
) -> (f64, f64) {
    let n = see.readings.len();
    let step = TAU / n as f64;
    let sign = side_sign(side);
    let (mut fx, mut fy) = (0.0, 0.0);
    for (i, &d) in see.readings.iter().enumerate() {
        let beta = see.pose.theta + step * i as f64;
        let delta = wrap_angle(beta - centre);
        let mut w = p.weight_decay.powf(delta.abs() / step);
        if turning {
            w *= 1.0 + (p.turn_gain - 1.0) * (sign * delta.sin()).max(0.0);
        }
        let f = if d >= p.safe_distance {
            p.magnitude
        } else {
            -p.magnitude
        };
        fx += f * w * beta.cos();
        fy += f * w * beta.sin();
    }
    (fx, fy)
}

/// Turning side for L mode: compare free weighted directions left and right of `towards`
/// (gaps capped at 4·d_sa, weights decay^k for the k-th sensor step; ties: left).
pub(super) fn choose_side(see: &Percept, towards: f64, p: &VdfParams) -> TurnSide {
    match p.turn {
        TurnPreference::Left => TurnSide::Left,
        TurnPreference::Right => TurnSide::Right,
        TurnPreference::Auto => {
            let n = see.readings.len();
            let (mut l, mut r) = (0.0, 0.0);
            for k in 1..n.div_ceil(2) {
                let w = p.weight_decay.powi(k as i32);
                let a = TAU * k as f64 / n as f64;
                l += w * see.gap(towards + a).min(p.safe_distance * 4.0);
                r += w * see.gap(towards - a).min(p.safe_distance * 4.0);
            }
            if r > l { TurnSide::Right } else { TurnSide::Left }
        }
    }
}

/// The first free direction (gap ≥ d_sa) met when turning from `from` towards `side` in
/// sensor steps; `from` itself if none is free.
pub(super) fn first_free(see: &Percept, from: f64, side: TurnSide, p: &VdfParams) -> f64 {
    let n = see.readings.len();
    let sign = side_sign(side);
    for k in 1..=n / 2 {
        let b = from + sign * TAU * k as f64 / n as f64;
        if see.gap(b) >= p.safe_distance {
            return wrap_angle(b);
        }
    }
    from
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::pose::Pose;
    use std::f64::consts::SQRT_2;

    /// F written out term by term: Σ f_i w_i (cos β_i, sin β_i) for sensors at β_i = iπ/4.
    fn sum(terms: [(f64, f64); 8]) -> (f64, f64) {
        terms.iter().enumerate().fold((0.0, 0.0), |(x, y), (i, (f, w))| {
            let beta = i as f64 * PI / 4.0;
            (x + f * w * beta.cos(), y + f * w * beta.sin())
        })
    }

    /// R mode, all free, goal ahead: weights 0.6^k for the k-th sensor from the front (k ≤ 4),
    /// F = (1 + 1.2·cos45° + 0.432·cos135° − 0.1296, 0): drive straight at v_max = 0.5 (the gap
    /// ahead, 2 m, exceeds the slow-down distance).
    #[test]
    fn free_rotate_mode_drives_at_the_goal() {
        let p = VdfParams::default();
        let free = [2.0; 8];
        let see = Percept::new(Pose::default(), Point2::new(5.0, 0.0), &free);
        let (twist, force) = steer(&VdfState::default(), &see, &p);
        let want_x = 1.0 + 1.2 * SQRT_2 / 2.0 - 0.432 * SQRT_2 / 2.0 - 0.1296;
        assert!((force.x - want_x).abs() < 1e-12, "{force:?}");
        assert!(force.y.abs() < 1e-12);
        assert!(
            (twist.vx - 0.5).abs() < 1e-12 && twist.omega.abs() < 1e-12,
            "{twist:?}"
        );
    }

    /// T mode, left turning side, the nearest gap 0.24 m = 0.8·d_sa at sensor 6 (−90°): the
    /// boundary tangent is −90° + 90° = 0. Weights 0.6^k, raised on the left by
    /// 1 + 0.5·sin Δ; sensor 6 repels (gap < d_sa). ψ = arg F points at a free sensor, so the
    /// command is v = 0.5·cos ψ (gap ahead 2 m), ω = clamp(3ψ, ±2).
    #[test]
    fn track_mode_follows_the_boundary_on_its_side() {
        let p = VdfParams::default();
        let mut r = [2.0; 8];
        r[6] = 0.24;
        let see = Percept::new(Pose::default(), Point2::new(5.0, 0.0), &r);
        let s = VdfState {
            mode: NavMode::Track,
            side: TurnSide::Left,
            ..VdfState::default()
        };
        let (twist, force) = steer(&s, &see, &p);
        let lift = 1.0 + 0.5 * SQRT_2 / 2.0;
        let (fx, fy) = sum([
            (1.0, 1.0),
            (1.0, 0.6 * lift),
            (1.0, 0.36 * 1.5),
            (1.0, 0.216 * lift),
            (1.0, 0.1296),
            (1.0, 0.216),
            (-1.0, 0.36),
            (1.0, 0.6),
        ]);
        assert!(
            (force.x - fx).abs() < 1e-9 && (force.y - fy).abs() < 1e-9,
            "{force:?} vs {fx}, {fy}"
        );
        let psi = fy.atan2(fx);
        assert!((twist.vx - 0.5 * psi.cos()).abs() < 1e-9, "{twist:?}");
        assert!(
            (twist.omega - (3.0 * psi).clamp(-2.0, 2.0)).abs() < 1e-9,
            "{twist:?}"
        );
    }
}
