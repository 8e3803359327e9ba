//! Planar pose, point and body twist, and exact integration of a constant twist.

use serde::{Deserialize, Serialize};

use super::angle::{sinc, versinc, wrap_angle};
use super::error::{MobileError, check_range};
use super::field::{Component, MobileField};

/// Largest magnitude of a world coordinate, m: bounded so that distances,
/// grids and control laws stay finite (a 1e308 coordinate overflowed them).
pub const MAX_COORDINATE: f64 = 1e6;
/// Largest magnitude of a heading (rad) or a twist component (m/s, rad/s).
pub const MAX_RATE: f64 = 1e6;

fn bounded(field: MobileField, value: f64, bound: f64) -> Result<(), MobileError> {
    check_range(field, value, -bound, bound)
}

/// A point in the world frame, m.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point2 {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
}

impl Point2 {
    /// A point from its coordinates.
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    /// Euclidean distance, m.
    pub fn distance(self, other: Point2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }

    /// Rejects NaN, infinite or out-of-world (beyond [`MAX_COORDINATE`]) coordinates.
    pub fn validate(&self, field: impl Fn(Component) -> MobileField) -> Result<(), MobileError> {
        if self.x.abs() <= MAX_COORDINATE && self.y.abs() <= MAX_COORDINATE {
            return Ok(());
        }
        bounded(field(Component::X), self.x, MAX_COORDINATE)?;
        bounded(field(Component::Y), self.y, MAX_COORDINATE)
    }
}

/// Robot pose in the world frame: position of the reference point (m) and heading θ (rad,
/// counter-clockwise from +x).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Heading θ, rad.
    pub theta: f64,
}

impl Pose {
    /// A pose from its coordinates.
    pub const fn new(x: f64, y: f64, theta: f64) -> Self {
        Self { x, y, theta }
    }

    /// The position.
    pub fn point(&self) -> Point2 {
        Point2::new(self.x, self.y)
    }

    /// Rejects NaN, infinite or out-of-world components (coordinates beyond
    /// [`MAX_COORDINATE`], headings beyond [`MAX_RATE`]).
    pub fn validate(&self, field: impl Fn(Component) -> MobileField) -> Result<(), MobileError> {
        if self.x.abs() <= MAX_COORDINATE && self.y.abs() <= MAX_COORDINATE && self.theta.abs() <= MAX_RATE {
            return Ok(());
        }
        bounded(field(Component::X), self.x, MAX_COORDINATE)?;
        bounded(field(Component::Y), self.y, MAX_COORDINATE)?;
        bounded(field(Component::Theta), self.theta, MAX_RATE)
    }
}

/// Body-frame velocity: `vx` forward (m/s), `vy` to the left (m/s, non-zero only for
/// holonomic chassis), `omega` yaw rate (rad/s, counter-clockwise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Forward speed, m/s.
    pub vx: f64,
    /// Lateral speed (left positive), m/s.
    pub vy: f64,
    /// Yaw rate, rad/s.
    pub omega: f64,
}

impl Twist {
    /// Zero velocity.
    pub const ZERO: Twist = Twist {
        vx: 0.0,
        vy: 0.0,
        omega: 0.0,
    };

    /// A twist of a non-holonomic (unicycle-like) robot: forward speed and yaw rate.
    pub const fn unicycle(v: f64, omega: f64) -> Self {
        Self {
            vx: v,
            vy: 0.0,
            omega,
        }
    }

    /// Every component multiplied by `s`.
    pub fn scaled(self, s: f64) -> Self {
        Self {
            vx: self.vx * s,
            vy: self.vy * s,
            omega: self.omega * s,
        }
    }

    /// Rejects NaN, infinite or absurd (beyond [`MAX_RATE`]) components.
    pub fn validate(&self, field: impl Fn(Component) -> MobileField) -> Result<(), MobileError> {
        if self.vx.abs() <= MAX_RATE && self.vy.abs() <= MAX_RATE && self.omega.abs() <= MAX_RATE {
            return Ok(());
        }
        bounded(field(Component::Vx), self.vx, MAX_RATE)?;
        bounded(field(Component::Vy), self.vy, MAX_RATE)?;
        bounded(field(Component::Omega), self.omega, MAX_RATE)
    }
}

/// Pose after applying the body twist `t` constant for `dt` seconds (exact arc):
///
/// Δ_body = [sin(ωdt)/ω · vx − (1 − cos ωdt)/ω · vy,  (1 − cos ωdt)/ω · vx + sin(ωdt)/ω · vy],
/// rotated by θ into the world frame; θ ← wrap(θ + ω dt).
pub fn integrate_twist(p: Pose, t: Twist, dt: f64) -> Pose {
    let phi = t.omega * dt;
    let s = dt * sinc(phi);
    let c = dt * versinc(phi);
    let bx = s * t.vx - c * t.vy;
    let by = c * t.vx + s * t.vy;
    let (sn, cs) = p.theta.sin_cos();
    Pose {
        x: p.x + cs * bx - sn * by,
        y: p.y + sn * bx + cs * by,
        theta: wrap_angle(p.theta + phi),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn quarter_circle_lands_on_the_arc() {
        // v = 1 m/s, ω = 1 rad/s for π/2 s: a quarter of the unit circle, from (0,0,0) to (1,1,π/2).
        let p = integrate_twist(Pose::new(0.0, 0.0, 0.0), Twist::unicycle(1.0, 1.0), PI / 2.0);
        assert!((p.x - 1.0).abs() < 1e-12 && (p.y - 1.0).abs() < 1e-12);
        assert!((p.theta - PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn straight_lateral_motion_of_a_holonomic_base() {
        let p = integrate_twist(
            Pose::new(1.0, 2.0, PI / 2.0),
            Twist {
                vx: 0.0,
                vy: 1.0,
                omega: 0.0,
            },
            2.0,
        );
        // Heading +y, moving left means −x.
        assert!((p.x + 1.0).abs() < 1e-12 && (p.y - 2.0).abs() < 1e-12);
    }
}
