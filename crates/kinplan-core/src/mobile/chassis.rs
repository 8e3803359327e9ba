//! Chassis models (S1 §3.1–3.3, docs/mobile.md#chassis): parameters, presets, command saturation and the
//! pose integrator shared by every controller.

use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

use super::error::{MobileError, check_dimension, check_positive, check_range};
use super::field::{ChassisKind, ChassisParam, MobileField};
use super::pose::{Pose, Twist, integrate_twist};

const DEG70: f64 = 70.0 * PI / 180.0;

/// Tricycle: one steered and driven front wheel at distance `wheelbase` ahead of the rear
/// axle centre (the reference point). Model S1 eq. 3.1–3.4: ẋ = v cosθ, ẏ = v sinθ,
/// θ̇ = v tanδ / L.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TricycleParams {
    /// Wheelbase L, m (default 0.6, MOBIL-II).
    pub wheelbase: f64,
    /// Front wheel radius r, m (default 0.1; S1 gives none).
    pub wheel_radius: f64,
    /// Steering limit |δ| ≤ max_steer, rad (default 70°, S1 §4.2.1 step 8).
    pub max_steer: f64,
    /// Limit on |v| of the reference point, m/s (default 0.5).
    pub max_speed: f64,
}

impl Default for TricycleParams {
    fn default() -> Self {
        Self {
            wheelbase: 0.6,
            wheel_radius: 0.1,
            max_steer: DEG70,
            max_speed: 0.5,
        }
    }
}

/// Four-wheel car with Ackermann front steering and driven rear wheels; reference point the
/// rear axle centre. Default = MOBIL-II (S1 §4.1.1): wheelbase 600 mm, track 620 mm,
/// 0.5 m/s, |δ| ≤ 70°.
///
/// The steering limit is applied to the inner (more steered) front wheel, so the largest
/// curvature is κ_max = tanδ_max / (L + t/2 · tanδ_max) (0.528 m radius at the rear axle
/// centre for MOBIL-II; S1 quotes 730 mm measured at an unstated point).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CarParams {
    /// Wheelbase a + b, m (default 0.6).
    pub wheelbase: f64,
    /// Track (distance between left and right wheels), m (default 0.62).
    pub track: f64,
    /// Wheel radius, m (default 0.1; S1 gives none).
    pub wheel_radius: f64,
    /// Steering limit of each front wheel, rad (default 70°).
    pub max_steer: f64,
    /// Limit on |v| of the reference point, m/s (default 0.5).
    pub max_speed: f64,
}

impl Default for CarParams {
    fn default() -> Self {
        Self {
            wheelbase: 0.6,
            track: 0.62,
            wheel_radius: 0.1,
            max_steer: DEG70,
            max_speed: 0.5,
        }
    }
}

/// Three-wheel omnidirectional ("kiwi") base, wheels 120° apart (OMR-III, S1 §4.1.2).
/// Wheel i sits at angle φ_i = φ_0 + i·120° and distance R from the centre and rolls
/// along the tangent (−sin φ_i, cos φ_i). S1 gives no dimensions; the defaults are ours.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OmniParams {
    /// Wheel radius r, m (default 0.1).
    pub wheel_radius: f64,
    /// Distance R from the centre to each wheel contact, m (default 0.3).
    pub center_distance: f64,
    /// Angle φ_0 of wheel 0 in the body frame, rad (default π/2: wheel 0 on the left).
    pub first_wheel_angle: f64,
    /// Limit on each wheel's rim speed, m/s (default 0.5).
    pub max_wheel_speed: f64,
}

impl Default for OmniParams {
    fn default() -> Self {
        Self {
            wheel_radius: 0.1,
            center_distance: 0.3,
            first_wheel_angle: FRAC_PI_2,
            max_wheel_speed: 0.5,
        }
    }
}

/// Differential drive; reference point the axle centre. Defaults resemble the Clearpath
/// Jackal used by BARN (r = 0.098 m, track 0.37559 m, 2 m/s).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DifferentialParams {
    /// Wheel radius, m.
    pub wheel_radius: f64,
    /// Distance between the wheels, m.
    pub track: f64,
    /// Limit on each wheel's rim speed, m/s.
    pub max_wheel_speed: f64,
}

impl Default for DifferentialParams {
    fn default() -> Self {
        Self {
            wheel_radius: 0.098,
            track: 0.37559,
            max_wheel_speed: 2.0,
        }
    }
}

/// A chassis kind with its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Chassis {
    /// Tricycle (steered, driven front wheel).
    Tricycle(TricycleParams),
    /// Ackermann car (MOBIL-II).
    Car(CarParams),
    /// Three-wheel omnidirectional base (OMR-III).
    Omni(OmniParams),
    /// Differential drive.
    Differential(DifferentialParams),
}

/// What saturation did to a commanded twist.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Saturation {
    /// Common factor (0, 1] applied to the twist to respect speed limits.
    pub speed_scale: f64,
    /// The yaw rate was reduced to respect the steering limit.
    pub steering_clamped: bool,
    /// A lateral speed was dropped because the chassis is not holonomic.
    pub lateral_dropped: bool,
}

impl Saturation {
    /// No limit was hit.
    pub const NONE: Saturation = Saturation {
        speed_scale: 1.0,
        steering_clamped: false,
        lateral_dropped: false,
    };

    /// True when any limit changed the command.
    pub fn any(&self) -> bool {
        self.speed_scale < 1.0 || self.steering_clamped || self.lateral_dropped
    }
}

/// Result of one integration step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChassisStep {
    /// Pose after the step.
    pub pose: Pose,
    /// The feasible twist actually applied.
    pub applied: Twist,
    /// What saturation changed.
    pub saturation: Saturation,
}

impl Default for Chassis {
    fn default() -> Self {
        Chassis::Differential(DifferentialParams::default())
    }
}

impl Chassis {
    /// MOBIL-II preset (car-like, S1 §4.1.1).
    pub fn mobil_ii() -> Self {
        Chassis::Car(CarParams::default())
    }

    /// OMR-III preset (three-wheel omnidirectional, S1 §4.1.2).
    pub fn omr_iii() -> Self {
        Chassis::Omni(OmniParams::default())
    }

    /// Short lowercase name: "tricycle", "car", "omni", "differential".
    pub fn name(&self) -> &'static str {
        match self {
            Chassis::Tricycle(_) => "tricycle",
            Chassis::Car(_) => "car",
            Chassis::Omni(_) => "omni",
            Chassis::Differential(_) => "differential",
        }
    }

    /// Checks every dimension and limit: lengths (wheelbase, track, wheel radius,
    /// centre distance) in [1e-6, 1e3] m (`MIN_DIMENSION`, `MAX_DIMENSION`), speeds positive and
    /// finite, steering limit in (0, 90°).
    pub fn validate(&self) -> Result<(), MobileError> {
        let field = |kind, param| MobileField::Chassis { kind, param };
        let steer_limit = FRAC_PI_2 - 1e-6;
        match self {
            Chassis::Tricycle(p) => {
                let f = |param| field(ChassisKind::Tricycle, param);
                check_dimension(f(ChassisParam::Wheelbase), p.wheelbase)?;
                check_dimension(f(ChassisParam::WheelRadius), p.wheel_radius)?;
                check_positive(f(ChassisParam::MaxSpeed), p.max_speed)?;
                check_positive(f(ChassisParam::MaxSteer), p.max_steer)?;
                check_range(f(ChassisParam::MaxSteer), p.max_steer, 0.0, steer_limit)
            }
            Chassis::Car(p) => {
                let f = |param| field(ChassisKind::Car, param);
                check_dimension(f(ChassisParam::Wheelbase), p.wheelbase)?;
                check_dimension(f(ChassisParam::Track), p.track)?;
                check_dimension(f(ChassisParam::WheelRadius), p.wheel_radius)?;
                check_positive(f(ChassisParam::MaxSpeed), p.max_speed)?;
                check_positive(f(ChassisParam::MaxSteer), p.max_steer)?;
                check_range(f(ChassisParam::MaxSteer), p.max_steer, 0.0, steer_limit)
            }
            Chassis::Omni(p) => {
                let f = |param| field(ChassisKind::Omni, param);
                check_dimension(f(ChassisParam::WheelRadius), p.wheel_radius)?;
                check_dimension(f(ChassisParam::CenterDistance), p.center_distance)?;
                check_positive(f(ChassisParam::MaxWheelSpeed), p.max_wheel_speed)?;
                check_range(
                    f(ChassisParam::FirstWheelAngle),
                    p.first_wheel_angle,
                    -2.0 * PI,
                    2.0 * PI,
                )
            }
            Chassis::Differential(p) => {
                let f = |param| field(ChassisKind::Differential, param);
                check_dimension(f(ChassisParam::WheelRadius), p.wheel_radius)?;
                check_dimension(f(ChassisParam::Track), p.track)?;
                check_positive(f(ChassisParam::MaxWheelSpeed), p.max_wheel_speed)
            }
        }
    }

    /// True when the chassis can move sideways (`vy ≠ 0`).
    pub fn is_holonomic(&self) -> bool {
        matches!(self, Chassis::Omni(_))
    }

    /// Largest straight-line speed, m/s.
    pub fn max_speed(&self) -> f64 {
        match self {
            Chassis::Tricycle(p) => p.max_speed,
            Chassis::Car(p) => p.max_speed,
            // Straight along +x every wheel turns at |sin φ_i|·v; the largest factor is
            // max_i |sin φ_i|, at least sin 60°.
            Chassis::Omni(p) => {
                let m = (0..3)
                    .map(|i| (p.first_wheel_angle + i as f64 * 2.0 * PI / 3.0).sin().abs())
                    .fold(0.0, f64::max);
                p.max_wheel_speed / m
            }
            Chassis::Differential(p) => p.max_wheel_speed,
        }
    }

    /// Largest curvature |ω / v|, 1/m, for steered chassis; `None` when unlimited.
    pub fn max_curvature(&self) -> Option<f64> {
        match self {
            Chassis::Tricycle(p) => Some(p.max_steer.tan() / p.wheelbase),
            Chassis::Car(p) => {
                let t = p.max_steer.tan();
                Some(t / (p.wheelbase + 0.5 * p.track * t))
            }
            _ => None,
        }
    }

    /// The feasible twist nearest in direction to `cmd`:
    /// non-holonomic chassis drop `vy`; steered chassis clamp |ω| ≤ κ_max |v|; then the
    /// whole twist is scaled by one factor s ≤ 1 so that every speed limit holds (a common
    /// factor keeps the path curvature, and is a mere time scaling for the Lyapunov law).
    /// A non-finite command becomes zero with `speed_scale = 0`.
    pub fn saturate(&self, cmd: Twist) -> (Twist, Saturation) {
        if !(cmd.vx.is_finite() && cmd.vy.is_finite() && cmd.omega.is_finite()) {
            return (
                Twist::ZERO,
                Saturation {
                    speed_scale: 0.0,
                    steering_clamped: true,
                    lateral_dropped: true,
                },
            );
        }
        let mut sat = Saturation::NONE;
        let mut t = cmd;
        if !self.is_holonomic() && t.vy != 0.0 {
            t.vy = 0.0;
            sat.lateral_dropped = true;
        }
        if let Some(kmax) = self.max_curvature() {
            let wmax = kmax * t.vx.abs();
            if t.omega.abs() > wmax {
                t.omega = wmax.copysign(t.omega);
                sat.steering_clamped = true;
            }
        }
        let peak = self.peak_speed_ratio(t);
        if peak > 1.0 {
            sat.speed_scale = 1.0 / peak;
            t = t.scaled(sat.speed_scale);
        }
        (t, sat)
    }

    /// max over limited speeds of |speed| / limit for a twist (≤ 1 means feasible).
    fn peak_speed_ratio(&self, t: Twist) -> f64 {
        match self {
            Chassis::Tricycle(p) => t.vx.abs() / p.max_speed,
            Chassis::Car(p) => t.vx.abs() / p.max_speed,
            Chassis::Omni(p) => {
                (0..3)
                    .map(|i| {
                        let phi = p.first_wheel_angle + i as f64 * 2.0 * PI / 3.0;
                        (-phi.sin() * t.vx + phi.cos() * t.vy + p.center_distance * t.omega).abs()
                    })
                    .fold(0.0, f64::max)
                    / p.max_wheel_speed
            }
            Chassis::Differential(p) => {
                let half = 0.5 * p.track * t.omega;
                (t.vx - half).abs().max((t.vx + half).abs()) / p.max_wheel_speed
            }
        }
    }

    /// Saturates `cmd` and integrates it exactly (constant twist = circular arc) for `dt`
    /// seconds. Errors on an invalid chassis, a non-finite pose or command, or dt ≤ 0.
    ///
    /// ```
    /// use kinplan_core::mobile::{Chassis, Pose, Twist};
    /// let s = Chassis::mobil_ii().step(Pose::new(0.0, 0.0, 0.0), Twist::unicycle(1.0, 0.0), 1.0).unwrap();
    /// assert!((s.pose.x - 0.5).abs() < 1e-12); // clamped to MOBIL-II's 0.5 m/s
    /// assert!(s.saturation.speed_scale < 1.0);
    /// ```
    pub fn step(&self, state: Pose, cmd: Twist, dt: f64) -> Result<ChassisStep, MobileError> {
        self.validate()?;
        state.validate(MobileField::State)?;
        cmd.validate(MobileField::Command)?;
        check_positive(MobileField::Dt, dt)?;
        Ok(self.step_unchecked(state, cmd, dt))
    }

    /// [`Chassis::step`] without input validation (for simulation loops whose inputs were
    /// validated once).
    pub fn step_unchecked(&self, state: Pose, cmd: Twist, dt: f64) -> ChassisStep {
        let (applied, saturation) = self.saturate(cmd);
        ChassisStep {
            pose: integrate_twist(state, applied, dt),
            applied,
            saturation,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mobil_ii_curvature_limit_is_inner_wheel_70_degrees() {
        // tan70° = 2.747477; κ = 2.747477 / (0.6 + 0.31 · 2.747477) = 2.747477 / 1.451718 = 1.892570 1/m.
        let k = Chassis::mobil_ii().max_curvature().unwrap();
        assert!((k - 1.892_570).abs() < 1e-5, "{k}");
    }

    #[test]
    fn car_cannot_turn_in_place() {
        let (t, s) = Chassis::mobil_ii().saturate(Twist::unicycle(0.0, 1.0));
        assert_eq!(t.omega, 0.0);
        assert!(s.steering_clamped);
    }

    #[test]
    fn differential_scales_uniformly() {
        // r·u_R = v + ωb/2 = 2 + 2·0.5 = 3 > 2 → s = 2/3, curvature kept.
        let c = Chassis::Differential(DifferentialParams {
            wheel_radius: 0.1,
            track: 1.0,
            max_wheel_speed: 2.0,
        });
        let (t, s) = c.saturate(Twist::unicycle(2.0, 2.0));
        assert!((s.speed_scale - 2.0 / 3.0).abs() < 1e-12);
        assert!((t.vx - 4.0 / 3.0).abs() < 1e-12 && (t.omega - 4.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn bad_inputs_are_rejected() {
        let c = Chassis::default();
        let p = Pose::new(0.0, 0.0, 0.0);
        assert!(matches!(
            c.step(Pose::new(f64::NAN, 0.0, 0.0), Twist::ZERO, 0.1),
            Err(MobileError::NotFinite { .. })
        ));
        assert!(matches!(
            c.step(p, Twist::ZERO, -0.1),
            Err(MobileError::NotPositive { .. })
        ));
        let bad = Chassis::Differential(DifferentialParams {
            wheel_radius: 0.0,
            ..DifferentialParams::default()
        });
        assert!(
            matches!(bad.validate(), Err(MobileError::OutOfRange { field, min, .. }) if min == 1e-6 && field == MobileField::Chassis { kind: ChassisKind::Differential, param: ChassisParam::WheelRadius })
        );
        // a radius too small to divide by (a wheel speed of v / r overflows)
        let tiny = Chassis::Differential(DifferentialParams {
            wheel_radius: 1e-300,
            ..DifferentialParams::default()
        });
        assert!(matches!(tiny.validate(), Err(MobileError::OutOfRange { .. })));
        let nan = c.saturate(Twist::unicycle(f64::NAN, 0.0));
        assert_eq!(nan.0, Twist::ZERO);
    }
}
