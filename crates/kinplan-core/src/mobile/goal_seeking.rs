//! Goal seeking with a steered chassis model (S1 §4.2.1): steer at the goal, clamp the
//! steering angle, halve the step near the goal.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use super::angle::wrap_angle;
use super::error::{MobileError, check_positive, check_range};
use super::field::{FollowField, MobileField, SteeringParam};
use super::pose::{Point2, Pose, Twist};

/// Parameters of [`goal_seeking_step`] and [`shortest_path_step`](super::shortest_path_step).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SteeringParams {
    /// Cruise speed v, m/s (default 0.5, MOBIL-II).
    pub speed: f64,
    /// Wheelbase a + b, m (default 0.6, MOBIL-II).
    pub wheelbase: f64,
    /// Steering limit, rad (default 70°, S1 §4.2.1 step 8).
    pub max_steer: f64,
    /// Stop once the distance decreases by less than ε per step, m (default 1e-4).
    pub epsilon: f64,
    /// Number of candidate steering angles in [−max_steer, max_steer] for the
    /// shortest-path selection (default 141, i.e. 1° apart).
    pub candidates: usize,
}

impl Default for SteeringParams {
    fn default() -> Self {
        Self {
            speed: 0.5,
            wheelbase: 0.6,
            max_steer: 70f64.to_radians(),
            epsilon: 1e-4,
            candidates: 141,
        }
    }
}

impl SteeringParams {
    /// Positive finite speed, wheelbase and ε; steering limit in (0, 90°); ≥ 2 candidates.
    pub fn validate(&self) -> Result<(), MobileError> {
        let field = |p| MobileField::Follow(FollowField::Steering(p));
        check_positive(field(SteeringParam::Speed), self.speed)?;
        check_positive(field(SteeringParam::Wheelbase), self.wheelbase)?;
        check_positive(field(SteeringParam::MaxSteer), self.max_steer)?;
        check_range(
            field(SteeringParam::MaxSteer),
            self.max_steer,
            0.0,
            PI / 2.0 - 1e-6,
        )?;
        check_positive(field(SteeringParam::Epsilon), self.epsilon)?;
        super::error::check_count(field(SteeringParam::Candidates), self.candidates, 2)
    }
}

/// Command of a steered (tricycle / car) controller.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SteeringCommand {
    /// Speed of the reference point, m/s.
    pub speed: f64,
    /// Steering angle δ, rad.
    pub steer: f64,
    /// The same as a body twist: (v, 0, v tanδ / L).
    pub twist: Twist,
    /// Distance to the goal Z before the step, m.
    pub distance: f64,
}

/// One step of S1 §4.2.1 (docs/mobile.md#goal-seeking): Z = |G − P|, Ω = atan2(y_G − y, x_G − x),
/// δ = clamp(wrap(Ω − θ), ±δ_max), θ̇ = v tanδ / (a + b); speed v while Z ≥ v·dt, else
/// Z / (2 dt) (the step halves the remaining distance). The caller stops when Z decreases by
/// less than `epsilon` per step ([`goal_seeking_finished`]).
///
/// ```
/// use kinplan_core::mobile::{goal_seeking_step, Point2, Pose, SteeringParams};
/// let c = goal_seeking_step(Pose::new(0.0, 0.0, 0.0), Point2::new(1.0, 1.0), 0.1, &SteeringParams::default()).unwrap();
/// assert!((c.steer - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
/// ```
pub fn goal_seeking_step(
    state: Pose,
    goal: Point2,
    dt: f64,
    params: &SteeringParams,
) -> Result<SteeringCommand, MobileError> {
    params.validate()?;
    state.validate(MobileField::State)?;
    goal.validate(MobileField::Goal)?;
    check_positive(MobileField::Dt, dt)?;
    let z = state.point().distance(goal);
    let omega_dir = (goal.y - state.y).atan2(goal.x - state.x);
    let delta = if z > 0.0 {
        wrap_angle(omega_dir - state.theta).clamp(-params.max_steer, params.max_steer)
    } else {
        0.0
    };
    let speed = if z >= params.speed * dt {
        params.speed
    } else {
        z / (2.0 * dt)
    };
    Ok(SteeringCommand {
        speed,
        steer: delta,
        twist: Twist::unicycle(speed, speed * delta.tan() / params.wheelbase),
        distance: z,
    })
}

/// S1 §4.2.1 step 13: stop once Z_{i−1} − Z_i ≤ ε.
pub fn goal_seeking_finished(previous_distance: f64, distance: f64, epsilon: f64) -> bool {
    (previous_distance - distance).partial_cmp(&epsilon) != Some(std::cmp::Ordering::Greater)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn goal_behind_saturates_steering() {
        let p = SteeringParams::default();
        let c = goal_seeking_step(Pose::new(0.0, 0.0, 0.0), Point2::new(-1.0, 0.1), 0.1, &p).unwrap();
        assert!((c.steer - 70f64.to_radians()).abs() < 1e-12);
        // ω = v tan70° / 0.6 = 0.5 · 2.747477 / 0.6 = 2.289565.
        assert!((c.twist.omega - 2.289_564_5).abs() < 1e-6);
    }

    #[test]
    fn speed_halves_the_last_step() {
        let p = SteeringParams::default();
        let c = goal_seeking_step(Pose::new(0.0, 0.0, 0.0), Point2::new(0.02, 0.0), 0.1, &p).unwrap();
        assert!((c.speed - 0.1).abs() < 1e-12); // Z/(2dt) = 0.02/0.2
        assert!(goal_seeking_finished(1.0, 1.0, 1e-4));
        assert!(!goal_seeking_finished(1.0, 0.9, 1e-4));
    }

    #[test]
    fn bad_input() {
        let p = SteeringParams::default();
        assert!(goal_seeking_step(Pose::new(0.0, f64::NAN, 0.0), Point2::new(1.0, 0.0), 0.1, &p).is_err());
        assert!(goal_seeking_step(Pose::new(0.0, 0.0, 0.0), Point2::new(1.0, 0.0), -0.1, &p).is_err());
        let bad = SteeringParams { max_steer: 2.0, ..p };
        assert!(matches!(bad.validate(), Err(MobileError::OutOfRange { .. })));
    }
}
