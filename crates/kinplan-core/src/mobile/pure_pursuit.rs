//! Pure pursuit path tracking (Coulter 1992; parameters and defaults after Nav2's regulated
//! pure pursuit controller): steer on the arc through a lookahead point on the path.

use serde::{Deserialize, Serialize};

use super::angle::wrap_angle;
use super::error::{MobileError, check_positive, check_range};
use super::field::{FollowField, MobileField, PurePursuitParam};
use super::pose::{Point2, Pose, Twist};

/// Parameters (defaults = Nav2 `RegulatedPurePursuitController`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PurePursuitParams {
    /// Lookahead distance L_d, m (Nav2 `lookahead_dist` 0.6).
    pub lookahead: f64,
    /// Cruise speed, m/s (Nav2 `desired_linear_vel` 0.5).
    pub desired_speed: f64,
    /// Below this Euclidean distance to the path end the speed scales down, m (Nav2
    /// `approach_velocity_scaling_dist` 0.6).
    pub approach_distance: f64,
    /// Floor of the approach speed, m/s (Nav2 `min_approach_linear_velocity` 0.05).
    pub min_approach_speed: f64,
    /// Turn in place first when the lookahead point is off by more than
    /// `rotate_min_angle` (Nav2 `use_rotate_to_heading` true). Ignored by steered chassis.
    pub rotate_to_heading: bool,
    /// Angle triggering in-place rotation, rad (Nav2 `rotate_to_heading_min_angle` 0.785).
    pub rotate_min_angle: f64,
    /// In-place yaw rate, rad/s (Nav2 `rotate_to_heading_angular_vel` 1.8).
    pub rotate_yaw_rate: f64,
}

impl Default for PurePursuitParams {
    fn default() -> Self {
        Self {
            lookahead: 0.6,
            desired_speed: 0.5,
            approach_distance: 0.6,
            min_approach_speed: 0.05,
            rotate_to_heading: true,
            rotate_min_angle: 0.785,
            rotate_yaw_rate: 1.8,
        }
    }
}

impl PurePursuitParams {
    /// Positive distances and speeds; rotate angle in (0, π].
    pub fn validate(&self) -> Result<(), MobileError> {
        let field = |p| MobileField::Follow(FollowField::PurePursuit(p));
        check_positive(field(PurePursuitParam::Lookahead), self.lookahead)?;
        check_positive(field(PurePursuitParam::DesiredSpeed), self.desired_speed)?;
        check_positive(field(PurePursuitParam::ApproachDistance), self.approach_distance)?;
        check_range(
            field(PurePursuitParam::MinApproachSpeed),
            self.min_approach_speed,
            0.0,
            self.desired_speed,
        )?;
        check_range(
            field(PurePursuitParam::RotateMinAngle),
            self.rotate_min_angle,
            1e-6,
            std::f64::consts::PI,
        )?;
        check_positive(field(PurePursuitParam::RotateYawRate), self.rotate_yaw_rate)
    }
}

/// Output of [`pure_pursuit_step`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PurePursuitCommand {
    /// Unicycle command (v, 0, ω).
    pub twist: Twist,
    /// The lookahead point, world frame.
    pub lookahead_point: Point2,
    /// Curvature κ = 2 y_l / d², 1/m.
    pub curvature: f64,
    /// Index of the path segment nearest the robot; pass it back as `from_segment` next step so
    /// progress never runs backwards on self-crossing paths.
    pub segment: usize,
}

/// Nearest point on segment a–b to p and its parameter t ∈ [0, 1].
fn project(p: Point2, a: Point2, b: Point2) -> (Point2, f64) {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p.x - a.x) * dx + (p.y - a.y) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (Point2::new(a.x + t * dx, a.y + t * dy), t)
}

/// One pure pursuit step. The segment nearest the robot is searched from `from_segment` on;
/// the lookahead point is the first intersection, beyond that projection, of the path with the
/// circle of radius L_d about the robot (the path end if none). With (x_l, y_l) the point in
/// the robot frame and d² = x_l² + y_l²: κ = 2 y_l / d², ω = κ v. The speed v is
/// `desired_speed`, scaled by (distance to the end / approach_distance) near the end but not
/// below `min_approach_speed`. With `rotate_to_heading`, a lookahead bearing beyond
/// `rotate_min_angle` gives v = 0, ω = ±`rotate_yaw_rate`.
///
/// ```
/// use kinplan_core::mobile::{pure_pursuit_step, Point2, Pose, PurePursuitParams};
/// let path = [Point2::new(-1.0, 0.3), Point2::new(10.0, 0.3)];
/// let p = PurePursuitParams { lookahead: 0.5, ..PurePursuitParams::default() };
/// let c = pure_pursuit_step(Pose::new(0.0, 0.0, 0.0), &path, 0, &p).unwrap();
/// assert!((c.curvature - 2.4).abs() < 1e-12); // point (0.4, 0.3): κ = 2·0.3/0.25
/// ```
pub fn pure_pursuit_step(
    state: Pose,
    path: &[Point2],
    from_segment: usize,
    params: &PurePursuitParams,
) -> Result<PurePursuitCommand, MobileError> {
    params.validate()?;
    state.validate(MobileField::State)?;
    if path.is_empty() {
        return Err(MobileError::EmptyPath);
    }
    for (i, p) in path.iter().enumerate() {
        if !(p.x.is_finite() && p.y.is_finite()) {
            p.validate(|part| MobileField::Path { index: i, part })?;
        }
    }
    Ok(pure_pursuit_unchecked(state, path, from_segment, params))
}

pub(crate) fn pure_pursuit_unchecked(
    state: Pose,
    path: &[Point2],
    from_segment: usize,
    params: &PurePursuitParams,
) -> PurePursuitCommand {
    let me = state.point();
    let last = *path.last().unwrap_or(&me);
    let nseg = path.len().saturating_sub(1);
    // Nearest segment from `from_segment` on.
    let first = from_segment.min(nseg.saturating_sub(1));
    let mut seg = first;
    let mut best = f64::INFINITY;
    let mut best_t = 0.0;
    for i in first..nseg {
        let (q, t) = project(me, path[i], path[i + 1]);
        let d = q.distance(me);
        if d < best {
            best = d;
            seg = i;
            best_t = t;
        }
    }
    // Lookahead point: first circle crossing beyond the projection.
    let ld = params.lookahead;
    let mut target = last;
    'outer: for i in seg..nseg {
        let (a, b) = (path[i], path[i + 1]);
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let (fx, fy) = (a.x - me.x, a.y - me.y);
        let qa = dx * dx + dy * dy;
        if qa == 0.0 {
            continue;
        }
        let qb = 2.0 * (fx * dx + fy * dy);
        let qc = fx * fx + fy * fy - ld * ld;
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            continue;
        }
        let t = (-qb + disc.sqrt()) / (2.0 * qa);
        let t_min = if i == seg { best_t } else { 0.0 };
        if (t_min..=1.0).contains(&t) {
            target = Point2::new(a.x + t * dx, a.y + t * dy);
            break 'outer;
        }
    }
    let (s, c) = state.theta.sin_cos();
    let (gx, gy) = (target.x - me.x, target.y - me.y);
    let xl = c * gx + s * gy;
    let yl = -s * gx + c * gy;
    let d2 = xl * xl + yl * yl;
    let curvature = if d2 > 1e-12 { 2.0 * yl / d2 } else { 0.0 };
    let bearing = wrap_angle(yl.atan2(xl));
    let twist = if params.rotate_to_heading && d2 > 1e-12 && bearing.abs() > params.rotate_min_angle {
        Twist::unicycle(0.0, params.rotate_yaw_rate.copysign(bearing))
    } else {
        let to_end = me.distance(last);
        let mut v = params.desired_speed;
        if to_end < params.approach_distance {
            v = (v * to_end / params.approach_distance).max(params.min_approach_speed);
        }
        if d2 <= 1e-12 {
            v = 0.0;
        }
        Twist::unicycle(v, curvature * v)
    };
    PurePursuitCommand {
        twist,
        lookahead_point: target,
        curvature,
        segment: seg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_behind_triggers_rotation_in_place() {
        let path = [Point2::new(0.0, 0.0), Point2::new(-5.0, 0.0)];
        let c = pure_pursuit_step(Pose::new(0.0, 0.0, 0.0), &path, 0, &PurePursuitParams::default()).unwrap();
        assert_eq!(c.twist.vx, 0.0);
        assert!((c.twist.omega.abs() - 1.8).abs() < 1e-12);
        assert!((c.lookahead_point.x + 0.6).abs() < 1e-12);
    }

    #[test]
    fn approach_speed_scales_down() {
        // Robot 0.3 m from the end, facing it: v = 0.5 · 0.3 / 0.6 = 0.25, κ = 0.
        let path = [Point2::new(-1.0, 0.0), Point2::new(0.3, 0.0)];
        let c = pure_pursuit_step(Pose::new(0.0, 0.0, 0.0), &path, 0, &PurePursuitParams::default()).unwrap();
        assert!((c.twist.vx - 0.25).abs() < 1e-12 && c.twist.omega.abs() < 1e-12);
    }

    #[test]
    fn empty_path_is_rejected() {
        assert_eq!(
            pure_pursuit_step(Pose::default(), &[], 0, &PurePursuitParams::default()),
            Err(MobileError::EmptyPath)
        );
    }
}
