//! Wheel kinematics (S1 §3.1–3.3, docs/mobile.md#chassis): body twist ↔ wheel angular speeds
//! and steering angles for every chassis.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use super::chassis::{Chassis, Saturation};
use super::error::{MobileError, check_finite};
use super::field::{MobileField, WheelField};
use super::pose::Twist;

/// Wheel speeds (rad/s, positive rolls the robot forward / counter-clockwise for omni wheels)
/// and steering angles (rad, positive to the left).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum WheelState {
    /// Tricycle front wheel.
    Tricycle {
        /// Front wheel angular speed, rad/s.
        speed: f64,
        /// Steering angle δ, rad.
        steer: f64,
    },
    /// Car: driven rear wheels and the two Ackermann steering angles.
    Car {
        /// Rear-left angular speed, rad/s.
        rear_left: f64,
        /// Rear-right angular speed, rad/s.
        rear_right: f64,
        /// Front-left steering angle, rad.
        steer_left: f64,
        /// Front-right steering angle, rad.
        steer_right: f64,
    },
    /// Omni: wheel i at φ_i = φ_0 + i·120°.
    Omni {
        /// Angular speeds, rad/s.
        speeds: [f64; 3],
    },
    /// Differential drive.
    Differential {
        /// Left angular speed, rad/s.
        left: f64,
        /// Right angular speed, rad/s.
        right: f64,
    },
}

/// Steering angle and signed rim speed of a steered wheel whose contact point moves with
/// velocity (vx, vy): δ = atan(vy / vx) ∈ (−π/2, π/2], speed = sign(vx)·|(vx, vy)|.
fn steered(vx: f64, vy: f64) -> (f64, f64) {
    let m = vx.hypot(vy);
    if m == 0.0 {
        return (0.0, 0.0);
    }
    if vx == 0.0 {
        return (PI / 2.0, vy);
    }
    ((vy / vx).atan(), m.copysign(vx))
}

impl Chassis {
    /// Inverse kinematics: saturates `twist` ([`Chassis::saturate`]) and returns the wheel
    /// speeds and steering angles that realise it, with the saturation report.
    ///
    /// * Tricycle (front wheel at (L, 0)): δ = atan(ωL / v), u = sign(v)·√(v² + ω²L²) / r.
    /// * Car (wheels at (0, ±t/2), (L, ±t/2)): u_{l,r} = (v ∓ ωt/2) / r,
    ///   δ_{l,r} = atan(ωL / (v ∓ ωt/2)).
    /// * Omni: u_i = (−sin φ_i v_x + cos φ_i v_y + R ω) / r.
    /// * Differential: u_{l,r} = (v ∓ ωb/2) / r.
    ///
    /// ```
    /// use kinplan_core::mobile::{Chassis, Twist, WheelState};
    /// let (w, _) = Chassis::default().inverse_kinematics(Twist::unicycle(0.98, 0.0)).unwrap();
    /// assert!(matches!(w, WheelState::Differential { left, right } if (left - 10.0).abs() < 1e-9 && left == right));
    /// ```
    pub fn inverse_kinematics(&self, twist: Twist) -> Result<(WheelState, Saturation), MobileError> {
        self.validate()?;
        twist.validate(MobileField::Twist)?;
        let (t, sat) = self.saturate(twist);
        let w = match self {
            Chassis::Tricycle(p) => {
                let (steer, rim) = steered(t.vx, t.omega * p.wheelbase);
                WheelState::Tricycle {
                    speed: rim / p.wheel_radius,
                    steer,
                }
            }
            Chassis::Car(p) => {
                let h = 0.5 * p.track * t.omega;
                let (steer_left, _) = steered(t.vx - h, t.omega * p.wheelbase);
                let (steer_right, _) = steered(t.vx + h, t.omega * p.wheelbase);
                WheelState::Car {
                    rear_left: (t.vx - h) / p.wheel_radius,
                    rear_right: (t.vx + h) / p.wheel_radius,
                    steer_left,
                    steer_right,
                }
            }
            Chassis::Omni(p) => {
                let mut speeds = [0.0; 3];
                for (i, s) in speeds.iter_mut().enumerate() {
                    let phi = p.first_wheel_angle + i as f64 * 2.0 * PI / 3.0;
                    *s =
                        (-phi.sin() * t.vx + phi.cos() * t.vy + p.center_distance * t.omega) / p.wheel_radius;
                }
                WheelState::Omni { speeds }
            }
            Chassis::Differential(p) => {
                let h = 0.5 * p.track * t.omega;
                WheelState::Differential {
                    left: (t.vx - h) / p.wheel_radius,
                    right: (t.vx + h) / p.wheel_radius,
                }
            }
        };
        Ok((w, sat))
    }

    /// Forward kinematics: the body twist produced by wheel speeds (and steering angles).
    ///
    /// * Tricycle: v = r u cos δ, ω = r u sin δ / L.
    /// * Car: odometry from the driven rear wheels, v = r(u_l + u_r)/2, ω = r(u_r − u_l)/t
    ///   (the Ackermann steering angles are implied by them and not used).
    /// * Omni: with three wheels 120° apart Σ sin²φ_i = Σ cos²φ_i = 3/2 and the cross sums
    ///   vanish, so v_x = −(2r/3) Σ sin φ_i u_i, v_y = (2r/3) Σ cos φ_i u_i,
    ///   ω = r Σ u_i / (3R).
    /// * Differential: v = r(u_l + u_r)/2, ω = r(u_r − u_l)/b.
    pub fn forward_kinematics(&self, wheels: &WheelState) -> Result<Twist, MobileError> {
        self.validate()?;
        match (self, wheels) {
            (Chassis::Tricycle(p), WheelState::Tricycle { speed, steer }) => {
                check_finite(MobileField::Wheel(WheelField::Speed), *speed)?;
                check_finite(MobileField::Wheel(WheelField::Steer), *steer)?;
                let rim = p.wheel_radius * speed;
                Ok(Twist::unicycle(
                    rim * steer.cos(),
                    rim * steer.sin() / p.wheelbase,
                ))
            }
            (
                Chassis::Car(p),
                WheelState::Car {
                    rear_left,
                    rear_right,
                    steer_left,
                    steer_right,
                },
            ) => {
                for (f, v) in [
                    (MobileField::Wheel(WheelField::RearLeft), rear_left),
                    (MobileField::Wheel(WheelField::RearRight), rear_right),
                    (MobileField::Wheel(WheelField::SteerLeft), steer_left),
                    (MobileField::Wheel(WheelField::SteerRight), steer_right),
                ] {
                    check_finite(f, *v)?;
                }
                let r = p.wheel_radius;
                Ok(Twist::unicycle(
                    0.5 * r * (rear_left + rear_right),
                    r * (rear_right - rear_left) / p.track,
                ))
            }
            (Chassis::Omni(p), WheelState::Omni { speeds }) => {
                let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
                for (i, u) in speeds.iter().enumerate() {
                    check_finite(MobileField::Wheel(WheelField::Speeds), *u)?;
                    let phi = p.first_wheel_angle + i as f64 * 2.0 * PI / 3.0;
                    sx -= phi.sin() * u;
                    sy += phi.cos() * u;
                    sw += u;
                }
                let r = p.wheel_radius;
                Ok(Twist {
                    vx: 2.0 * r * sx / 3.0,
                    vy: 2.0 * r * sy / 3.0,
                    omega: r * sw / (3.0 * p.center_distance),
                })
            }
            (Chassis::Differential(p), WheelState::Differential { left, right }) => {
                check_finite(MobileField::Wheel(WheelField::Left), *left)?;
                check_finite(MobileField::Wheel(WheelField::Right), *right)?;
                let r = p.wheel_radius;
                Ok(Twist::unicycle(
                    0.5 * r * (left + right),
                    r * (right - left) / p.track,
                ))
            }
            (c, _) => Err(MobileError::WheelMismatch { expected: c.name() }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::chassis::{CarParams, DifferentialParams, OmniParams, TricycleParams};
    use proptest::prelude::*;

    fn close(a: Twist, b: Twist) -> bool {
        (a.vx - b.vx).abs() < 1e-9 && (a.vy - b.vy).abs() < 1e-9 && (a.omega - b.omega).abs() < 1e-9
    }

    #[test]
    fn omni_pure_rotation_turns_every_wheel_equally() {
        // ω = 1 rad/s, R = 0.3, r = 0.1 → u_i = Rω/r = 3 rad/s for all wheels.
        let (w, s) = Chassis::omr_iii()
            .inverse_kinematics(Twist {
                vx: 0.0,
                vy: 0.0,
                omega: 1.0,
            })
            .unwrap();
        assert!(!s.any());
        let WheelState::Omni { speeds } = w else { panic!() };
        for u in speeds {
            assert!((u - 3.0).abs() < 1e-12);
        }
    }

    #[test]
    fn omni_forward_motion_hand_computed() {
        // φ = 90°, 210°, 330°; v_x = 0.3: u_i = −sin φ_i · 0.3 / 0.1 = (−3, 1.5, 1.5).
        let (w, _) = Chassis::omr_iii()
            .inverse_kinematics(Twist {
                vx: 0.3,
                vy: 0.0,
                omega: 0.0,
            })
            .unwrap();
        let WheelState::Omni { speeds } = w else { panic!() };
        assert!(
            (speeds[0] + 3.0).abs() < 1e-12
                && (speeds[1] - 1.5).abs() < 1e-12
                && (speeds[2] - 1.5).abs() < 1e-12
        );
    }

    #[test]
    fn car_ackermann_angles_hand_computed() {
        // v = 0.3, κ = 1 (ω = 0.3): inner (left) tanδ = 0.6 / (1 − 0.31) → 41.009°,
        // outer tanδ = 0.6 / 1.31 → 24.608°.
        let (w, s) = Chassis::mobil_ii()
            .inverse_kinematics(Twist::unicycle(0.3, 0.3))
            .unwrap();
        assert!(!s.any());
        let WheelState::Car {
            steer_left,
            steer_right,
            rear_left,
            rear_right,
        } = w
        else {
            panic!()
        };
        assert!(
            (steer_left.to_degrees() - 41.009).abs() < 1e-3,
            "{}",
            steer_left.to_degrees()
        );
        assert!((steer_right.to_degrees() - 24.608).abs() < 1e-3);
        assert!((rear_left - 2.07).abs() < 1e-9 && (rear_right - 3.93).abs() < 1e-9);
    }

    #[test]
    fn steering_limit_is_respected_for_any_command() {
        for c in [Chassis::mobil_ii(), Chassis::Tricycle(TricycleParams::default())] {
            for &(v, w) in &[(0.5, 10.0), (-0.3, -4.0), (0.01, 1.0), (1.0, -1.0)] {
                let (wh, s) = c.inverse_kinematics(Twist::unicycle(v, w)).unwrap();
                let max = 70f64.to_radians() + 1e-9;
                match wh {
                    WheelState::Car {
                        steer_left,
                        steer_right,
                        ..
                    } => {
                        assert!(steer_left.abs() <= max && steer_right.abs() <= max);
                    }
                    WheelState::Tricycle { steer, .. } => assert!(steer.abs() <= max),
                    _ => unreachable!(),
                }
                assert!(s.steering_clamped || w.abs() <= c.max_curvature().unwrap() * v.abs());
            }
        }
    }

    #[test]
    fn mismatched_wheels_are_rejected() {
        let e = Chassis::omr_iii().forward_kinematics(&WheelState::Differential {
            left: 1.0,
            right: 1.0,
        });
        assert_eq!(e, Err(MobileError::WheelMismatch { expected: "omni" }));
        let bad = Chassis::Omni(OmniParams {
            wheel_radius: 0.0,
            ..OmniParams::default()
        });
        assert!(bad.inverse_kinematics(Twist::ZERO).is_err());
    }

    proptest! {
        #[test]
        fn omni_round_trips(u0 in -5.0..5.0f64, u1 in -5.0..5.0f64, u2 in -5.0..5.0f64) {
            let c = Chassis::Omni(OmniParams { max_wheel_speed: 100.0, ..OmniParams::default() });
            let w = WheelState::Omni { speeds: [u0, u1, u2] };
            let t = c.forward_kinematics(&w).unwrap();
            let (w2, s) = c.inverse_kinematics(t).unwrap();
            prop_assert!(!s.any());
            let WheelState::Omni { speeds } = w2 else { unreachable!() };
            for (a, b) in speeds.iter().zip([u0, u1, u2]) { prop_assert!((a - b).abs() < 1e-9); }
            prop_assert!(close(c.forward_kinematics(&w2).unwrap(), t));
        }

        #[test]
        fn differential_round_trips(l in -15.0..15.0f64, r in -15.0..15.0f64) {
            let c = Chassis::Differential(DifferentialParams::default());
            let t = c.forward_kinematics(&WheelState::Differential { left: l, right: r }).unwrap();
            let (w2, _) = c.inverse_kinematics(t).unwrap();
            let WheelState::Differential { left, right } = w2 else { unreachable!() };
            prop_assert!((left - l).abs() < 1e-9 && (right - r).abs() < 1e-9);
        }

        #[test]
        fn tricycle_round_trips(u in -4.0..4.0f64, d in -1.2..1.2f64) {
            prop_assume!(u.abs() > 1e-3);
            let c = Chassis::Tricycle(TricycleParams { max_speed: 10.0, ..TricycleParams::default() });
            let t = c.forward_kinematics(&WheelState::Tricycle { speed: u, steer: d }).unwrap();
            let (w2, s) = c.inverse_kinematics(t).unwrap();
            prop_assert!(!s.any());
            let WheelState::Tricycle { speed, steer } = w2 else { unreachable!() };
            prop_assert!((speed - u).abs() < 1e-9 && (steer - d).abs() < 1e-9);
        }

        #[test]
        fn car_round_trips(v in -0.5..0.5f64, frac in -1.0..1.0f64) {
            let c = Chassis::Car(CarParams::default());
            let t = Twist::unicycle(v, frac * c.max_curvature().unwrap() * v.abs());
            let (w, s) = c.inverse_kinematics(t).unwrap();
            prop_assert!(!s.any());
            prop_assert!(close(c.forward_kinematics(&w).unwrap(), t));
            let (w2, _) = c.inverse_kinematics(c.forward_kinematics(&w).unwrap()).unwrap();
            let (WheelState::Car { rear_left: a0, rear_right: a1, steer_left: a2, steer_right: a3 },
                 WheelState::Car { rear_left: b0, rear_right: b1, steer_left: b2, steer_right: b3 }) = (w, w2) else { unreachable!() };
            for (a, b) in [(a0, b0), (a1, b1), (a2, b2), (a3, b3)] { prop_assert!((a - b).abs() < 1e-9); }
        }

        #[test]
        fn twist_round_trips_on_every_chassis(vx in -3.0..3.0f64, vy in -3.0..3.0f64, w in -6.0..6.0f64) {
            for c in [Chassis::omr_iii(), Chassis::default(), Chassis::mobil_ii(), Chassis::Tricycle(TricycleParams::default())] {
                let (ws, _) = c.inverse_kinematics(Twist { vx, vy, omega: w }).unwrap();
                let (feasible, _) = c.saturate(Twist { vx, vy, omega: w });
                prop_assert!(close(c.forward_kinematics(&ws).unwrap(), feasible), "{}", c.name());
            }
        }
    }
}
