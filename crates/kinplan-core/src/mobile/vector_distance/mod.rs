//! Vector-distance local navigation (S1 §3.5, §4.2.4): a weighted sum of attracting and
//! repelling sensor vectors, with the rotate / lock / track modes, hit and leave points and
//! "no path" detection. The modal state is a plain serialisable struct so a stateless server
//! can hand it to the caller as an opaque token.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

use super::angle::wrap_angle;
use super::error::{MobileError, check_count, check_finite, check_positive, check_range};
use super::field::{MobileField, VdfField};
use super::pose::{Point2, Pose, Twist};
use super::sensors::RangeSensorParams;

mod state;
mod steer;
mod transition;

pub use state::{MAX_TOKEN_STEPS, VdfState};
pub use steer::steer;
pub use transition::{transition, watch_no_path};

/// Navigation mode (S1 §3.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum NavMode {
    /// R: the largest weight w'_0 follows the goal direction.
    #[default]
    Rotate,
    /// L: weights locked (world-fixed direction, turning side boosted).
    Lock,
    /// T: tracking the obstacle boundary from the hit point H.
    Track,
}

impl NavMode {
    /// "R", "L" or "T".
    pub fn letter(&self) -> &'static str {
        match self {
            NavMode::Rotate => "R",
            NavMode::Lock => "L",
            NavMode::Track => "T",
        }
    }
}

/// Turning mode: the side whose weights are raised (eq. 3.53–3.57).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TurnSide {
    /// Left-turn mode: left weights raised, the obstacle is passed on the robot's right.
    #[default]
    Left,
    /// Right-turn mode.
    Right,
}

/// How the turning side is chosen when locking.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TurnPreference {
    /// Always left.
    Left,
    /// Always right.
    Right,
    /// The side with more free weighted directions next to the goal direction (ties: left).
    #[default]
    Auto,
}

/// Parameters of the vector-distance navigator. S1 names d_sa, K, the weights, n, c1, m, c2
/// without values; the defaults below are ours, chosen once on seeded synthetic worlds (not on
/// BARN).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VdfParams {
    /// Safe distance d_sa from the robot's rim, m (default 0.3).
    pub safe_distance: f64,
    /// Magnitude K of each sensor vector (default 1).
    pub magnitude: f64,
    /// Base weights w_k = decay^k for the k-th direction away from w'_0, ∈ (0, 1) (default 0.6).
    pub weight_decay: f64,
    /// Factor ≥ 1 raising the turning side's weights in L and T modes (default 1.5).
    pub turn_gain: f64,
    /// Gap towards the goal needed to release L or leave T (hysteresis above d_sa), m
    /// (default 0.6).
    pub release_distance: f64,
    /// Turning side choice (default Auto).
    pub turn: TurnPreference,
    /// Speed limit, m/s (default 0.5).
    pub max_speed: f64,
    /// Yaw-rate limit, rad/s (default 2.0).
    pub max_yaw_rate: f64,
    /// Heading gain ω = k_h · (heading error), 1/s (default 3.0).
    pub heading_gain: f64,
    /// Speed scales with the gap ahead below this distance, m (default 0.5).
    pub slow_distance: f64,
    /// Drive backwards when F points behind (default false: reversing flips the turn direction at ε = ±90° and chatters).
    pub allow_reverse: bool,
    /// Replace a heading ψ = arg F that points into a blocked direction by the first free
    /// direction towards the turning side (default true; false = the literal S1 rule: move
    /// along F, which parks the robot in potential-field minima on the synthetic test worlds).
    pub avoid_blocked_heading: bool,
    /// n: window (steps) of the L-mode progress test, eq. 3.58 (default 20).
    pub progress_steps: usize,
    /// c1: minimum progress over n steps before switching to T, m (default 0.05).
    pub progress_min: f64,
    /// m: steps without improving the best distance in T before "no path", eq. 3.60 (default 1000).
    pub no_path_steps: usize,
    /// c2: improvement that counts as progress in T, m (default 0.05).
    pub no_path_min: f64,
    /// Distance to the line H–G at which the leave point L is accepted (∠HLG = 180°), m
    /// (default 0.1).
    pub leave_tolerance: f64,
    /// Coming back within this radius of H (after leaving 3× that radius) means "no path", m
    /// (default 0.25).
    pub hit_radius: f64,
    /// Boundary-following gain: heading offset per metre of gap error, rad/m (default 3.0).
    pub wall_gain: f64,
    /// The goal is reached within this distance, m (default 0.1).
    pub goal_tolerance: f64,
    /// Before reporting NO_PATH, go round the other way once: flip the turning side, take the
    /// current position as a new H and restart the no-path watch (the direction-switching
    /// refinement of the Bug family; S1 gives up at once). Default false (literal S1).
    #[serde(default)]
    pub retry_other_side: bool,
}

impl Default for VdfParams {
    fn default() -> Self {
        Self {
            safe_distance: 0.3,
            magnitude: 1.0,
            weight_decay: 0.6,
            turn_gain: 1.5,
            release_distance: 0.6,
            turn: TurnPreference::Auto,
            max_speed: 0.5,
            max_yaw_rate: 2.0,
            heading_gain: 3.0,
            slow_distance: 0.5,
            allow_reverse: false,
            avoid_blocked_heading: true,
            progress_steps: 20,
            progress_min: 0.05,
            no_path_steps: 1000,
            no_path_min: 0.05,
            leave_tolerance: 0.1,
            hit_radius: 0.25,
            wall_gain: 3.0,
            goal_tolerance: 0.1,
            retry_other_side: false,
        }
    }
}

impl VdfParams {
    /// Positive distances, gains and limits; decay in (0, 1); turn gain ≥ 1; n, m ≥ 1.
    pub fn validate(&self) -> Result<(), MobileError> {
        check_positive(MobileField::Vdf(VdfField::SafeDistance), self.safe_distance)?;
        check_positive(MobileField::Vdf(VdfField::Magnitude), self.magnitude)?;
        check_range(
            MobileField::Vdf(VdfField::WeightDecay),
            self.weight_decay,
            1e-6,
            1.0 - 1e-6,
        )?;
        check_range(MobileField::Vdf(VdfField::TurnGain), self.turn_gain, 1.0, 1e6)?;
        check_range(
            MobileField::Vdf(VdfField::ReleaseDistance),
            self.release_distance,
            self.safe_distance,
            1e6,
        )?;
        check_positive(MobileField::Vdf(VdfField::MaxSpeed), self.max_speed)?;
        check_positive(MobileField::Vdf(VdfField::MaxYawRate), self.max_yaw_rate)?;
        check_positive(MobileField::Vdf(VdfField::HeadingGain), self.heading_gain)?;
        check_positive(MobileField::Vdf(VdfField::SlowDistance), self.slow_distance)?;
        check_count(MobileField::Vdf(VdfField::ProgressSteps), self.progress_steps, 1)?;
        check_range(
            MobileField::Vdf(VdfField::ProgressMin),
            self.progress_min,
            -1e6,
            1e6,
        )?;
        check_count(MobileField::Vdf(VdfField::NoPathSteps), self.no_path_steps, 1)?;
        check_range(MobileField::Vdf(VdfField::NoPathMin), self.no_path_min, 0.0, 1e6)?;
        check_positive(MobileField::Vdf(VdfField::LeaveTolerance), self.leave_tolerance)?;
        check_positive(MobileField::Vdf(VdfField::HitRadius), self.hit_radius)?;
        check_range(MobileField::Vdf(VdfField::WallGain), self.wall_gain, 0.0, 1e6)?;
        check_positive(MobileField::Vdf(VdfField::GoalTolerance), self.goal_tolerance)
    }
}

/// Something that happened during a step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum VdfEvent {
    /// The goal is within tolerance.
    Reached,
    /// T mode entered at hit point H.
    Hit(Point2),
    /// T mode left at leave point L.
    Leave(Point2),
    /// No path: the best distance did not improve by c2 for m steps, or the robot came back
    /// to H.
    NoPath(NoPathReason),
}

/// Why the navigator gave up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoPathReason {
    /// Back within `hit_radius` of the hit point H after leaving it (S1 §4.2.4 step 4).
    ReturnedToHit,
    /// No improvement of the best distance by c2 for m steps (eq. 3.60).
    NoProgress,
    /// The global planner (grid A*, [`navigate_astar`](super::navigate_astar)) found no path
    /// on its grid.
    NoGridPath,
}

/// Output of one navigator step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VdfOutput {
    /// Unicycle command (zero after Reached / NoPath).
    pub twist: Twist,
    /// Mode used for this step.
    pub mode: NavMode,
    /// The vector-distance sum F in the world frame.
    pub force: Point2,
    /// Event of this step, if any.
    pub event: Option<VdfEvent>,
}

/// What the robot sees in one step: its pose, the goal, the range readings (sensor i at
/// θ + 2πi/N), and the distance z and world direction of the goal.
#[derive(Clone, Copy, Debug)]
pub struct Percept<'a> {
    /// Robot pose.
    pub pose: Pose,
    /// The goal.
    pub goal: Point2,
    /// Gaps, one per sensor, m.
    pub readings: &'a [f64],
    /// The robot's position.
    pub me: Point2,
    /// Distance to the goal z, m.
    pub z: f64,
    /// World direction of the goal, rad.
    pub goal_dir: f64,
}

impl<'a> Percept<'a> {
    /// What a robot at `pose` sees of `goal` with `readings` (at least one).
    pub fn new(pose: Pose, goal: Point2, readings: &'a [f64]) -> Self {
        let me = pose.point();
        Self {
            pose,
            goal,
            readings,
            me,
            z: me.distance(goal),
            goal_dir: (goal.y - me.y).atan2(goal.x - me.x),
        }
    }

    /// Gap reading in world direction `beta`: the sensor whose beam centre is nearest.
    pub fn gap(&self, beta: f64) -> f64 {
        let n = self.readings.len();
        let rel = wrap_angle(beta - self.pose.theta).rem_euclid(TAU);
        let i = (rel / (TAU / n as f64)).round() as usize % n;
        self.readings[i]
    }

    /// The gap in direction `beta` is at least d_sa.
    pub fn free(&self, beta: f64, p: &VdfParams) -> bool {
        self.gap(beta) >= p.safe_distance
    }
}

/// One step of the vector-distance navigator (S1 §4.2.4), pure: `state` in, next state out.
///
/// F = Σ_{i=0}^{N−1} f_i w'_i (eq. 3.50), f_i = ±K·u(β_0 + 2πi/N) (eq. 3.51–3.52): +K when
/// the gap in that direction is ≥ d_sa, −K below it; β_0 is the direction of w'_0: the goal in
/// R mode, the locked direction in L mode, the boundary tangent in T mode. Base weights
/// w'_i = decay^min(i, N−i) are symmetric; the turning side's weights are multiplied by
/// `turn_gain` in L and T (eq. 3.53–3.57). Transitions: R→L when the gap towards the goal
/// is < d_sa or the distance fell by less than c1 over n steps; L→R when that gap exceeds
/// `release_distance` or w'_0's own direction gets blocked; L→T (hit point H) when the distance to the goal
/// fell by less than c1 over the last n steps (eq. 3.58); T→R (leave point L) when every gap
/// is > d_sa or the robot is on segment H–G nearer the goal than H with a free goal direction
/// (∠HLG = 180°, eq. 3.59); T stops with NoPath when the best distance did not improve by c2
/// for m steps (eq. 3.60) or the robot returns to H. Readings are our reading of the garbled
/// source; sensors are evenly spaced, sensor 0 forward.
///
/// The command steers the robot's axis onto F: ε = wrap(ψ − θ), ω = k_h·ε (or ε − π when
/// reversing), v = ±v_max |cos ε| · min(1, gap along travel / slow_distance).
///
/// ```
/// use kinplan_core::mobile::{vdf_step, NavMode, Point2, Pose, RangeSensorParams, VdfParams, VdfState};
/// // Everything free, goal straight ahead: drive straight at full speed in R mode.
/// let (next, out) = vdf_step(&VdfState::default(), Pose::new(0.0, 0.0, 0.0), Point2::new(5.0, 0.0),
///                            &[2.0; 8], &RangeSensorParams::default(), &VdfParams::default()).unwrap();
/// assert_eq!(next.mode, NavMode::Rotate);
/// assert!((out.twist.vx - 0.5).abs() < 1e-12 && out.twist.omega.abs() < 1e-12);
/// // The state travels as an opaque token.
/// assert_eq!(VdfState::from_token(&next.to_token().unwrap()).unwrap(), next);
/// ```
pub fn vdf_step(
    state: &VdfState,
    pose: Pose,
    goal: Point2,
    readings: &[f64],
    sensors: &RangeSensorParams,
    params: &VdfParams,
) -> Result<(VdfState, VdfOutput), MobileError> {
    params.validate()?;
    sensors.validate()?;
    pose.validate(MobileField::State)?;
    goal.validate(MobileField::Goal)?;
    if readings.len() != sensors.count {
        return Err(MobileError::TooFew {
            field: MobileField::Readings,
            min: sensors.count,
            got: readings.len(),
        });
    }
    for (i, r) in readings.iter().enumerate() {
        if !r.is_finite() {
            check_finite(MobileField::Reading(i), *r)?;
        }
    }
    let mut next = state.clone();
    let out = vdf_step_mut(&mut next, pose, goal, readings, params);
    Ok((next, out))
}

/// In-place variant of [`vdf_step`] without validation (simulation loops): Reached within
/// the goal tolerance, else [`transition`], [`watch_no_path`] (a NoPath verdict stops with a
/// zero command) and [`steer`].
pub(crate) fn vdf_step_mut(
    s: &mut VdfState,
    pose: Pose,
    goal: Point2,
    readings: &[f64],
    p: &VdfParams,
) -> VdfOutput {
    let see = Percept::new(pose, goal, readings);
    let stop = |mode, event| VdfOutput {
        twist: Twist::ZERO,
        mode,
        force: Point2::default(),
        event: Some(event),
    };
    if see.z <= p.goal_tolerance {
        return stop(s.mode, VdfEvent::Reached);
    }
    let (next, event) = transition(std::mem::take(s), &see, p);
    let (next, event) = watch_no_path(next, &see, event, p);
    *s = next;
    if let Some(VdfEvent::NoPath(reason)) = event {
        return stop(s.mode, VdfEvent::NoPath(reason));
    }
    let (twist, force) = steer(s, &see, p);
    VdfOutput {
        twist,
        mode: s.mode,
        force,
        event,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::VecDeque;
    use std::f64::consts::FRAC_PI_4;

    fn sensors() -> RangeSensorParams {
        RangeSensorParams::default()
    }

    #[test]
    fn free_space_heads_for_the_goal() {
        // All gaps free: F is symmetric about the goal direction (45°) → ψ = 45°,
        // ε = 45°, v = 0.5 cos45° = 0.35355, ω = min(3·π/4, 2) = 2.
        let (next, out) = vdf_step(
            &VdfState::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(5.0, 5.0),
            &[2.0; 8],
            &sensors(),
            &VdfParams::default(),
        )
        .unwrap();
        assert_eq!(next.mode, NavMode::Rotate);
        assert!((out.force.y.atan2(out.force.x) - FRAC_PI_4).abs() < 1e-12);
        assert!((out.twist.vx - 0.5 * FRAC_PI_4.cos()).abs() < 1e-12);
        assert!((out.twist.omega - 2.0).abs() < 1e-12);
    }

    #[test]
    fn blocked_goal_locks_and_picks_the_open_side() {
        // Goal ahead; front and front-left blocked, right side free → Lock, right turn.
        let mut r = [2.0; 8];
        r[0] = 0.1;
        r[1] = 0.1;
        r[2] = 0.2;
        let (next, out) = vdf_step(
            &VdfState::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(5.0, 0.0),
            &r,
            &sensors(),
            &VdfParams::default(),
        )
        .unwrap();
        assert_eq!(next.mode, NavMode::Lock);
        assert_eq!(next.side, TurnSide::Right);
        assert_eq!(out.mode, NavMode::Lock);
        // F must point away from the blocked front-left quadrant: negative y component.
        assert!(out.force.y < 0.0);
    }

    #[test]
    fn lock_without_progress_enters_track_and_records_h() {
        let p = VdfParams {
            progress_steps: 3,
            ..VdfParams::default()
        };
        let mut r = [2.0; 8];
        r[0] = 0.1;
        let mut s = VdfState::default();
        let mut hit = None;
        for _ in 0..6 {
            let (n, out) = vdf_step(
                &s,
                Pose::new(0.0, 0.0, 0.0),
                Point2::new(5.0, 0.0),
                &r,
                &sensors(),
                &p,
            )
            .unwrap();
            s = n;
            if let Some(VdfEvent::Hit(h)) = out.event {
                hit = Some(h);
            }
        }
        assert_eq!(s.mode, NavMode::Track);
        assert_eq!(hit, Some(Point2::new(0.0, 0.0)));
    }

    /// `retry_other_side`: the first "no path" verdict (no progress for m steps) flips the
    /// turning side and restarts the watch from a new H at the current position; the second
    /// verdict stands. Without the option the first verdict stands (literal S1).
    #[test]
    fn retry_other_side_flips_once_then_gives_up() {
        let h = Point2::new(0.0, 0.0);
        let stuck = VdfState {
            mode: NavMode::Track,
            side: TurnSide::Left,
            side_chosen: true,
            hit_point: Some(h),
            hit_distance: 5.0,
            best_distance: Some(5.0),
            steps_since_progress: 999,
            ..VdfState::default()
        };
        // At (0, 0.1), goal (5, 0): z = 5.001, no improvement, the 1000th step without progress.
        let pose = Pose::new(0.0, 0.1, 0.0);
        let goal = Point2::new(5.0, 0.0);
        let mut readings = [2.0; 8];
        readings[0] = 0.1;
        let literal = VdfParams::default();
        let (_, out) = vdf_step(&stuck, pose, goal, &readings, &sensors(), &literal).unwrap();
        assert_eq!(out.event, Some(VdfEvent::NoPath(NoPathReason::NoProgress)));
        let retry = VdfParams {
            retry_other_side: true,
            ..VdfParams::default()
        };
        let (next, out) = vdf_step(&stuck, pose, goal, &readings, &sensors(), &retry).unwrap();
        assert_eq!(out.event, Some(VdfEvent::Hit(pose.point())));
        assert_eq!(next.side, TurnSide::Right);
        assert!(next.side_retried);
        assert_eq!(next.hit_point, Some(pose.point()));
        assert_eq!(next.steps_since_progress, 0);
        assert!(out.twist.vx.is_finite());
        // Stuck again for m steps: now the verdict stands.
        let again = VdfState {
            steps_since_progress: 999,
            ..next
        };
        let (_, out) = vdf_step(&again, pose, goal, &readings, &sensors(), &retry).unwrap();
        assert_eq!(out.event, Some(VdfEvent::NoPath(NoPathReason::NoProgress)));
    }

    /// Tokens written before `side_retried` existed still decode.
    #[test]
    fn token_without_side_retried_decodes() {
        let mut v: serde_json::Value =
            serde_json::from_slice(&VdfState::default().to_token().unwrap()).unwrap();
        v.as_object_mut().unwrap().remove("side_retried");
        let s = VdfState::from_token(&serde_json::to_vec(&v).unwrap()).unwrap();
        assert!(!s.side_retried);
    }

    #[test]
    fn token_round_trip_and_rejection() {
        let s = VdfState {
            mode: NavMode::Track,
            hit_point: Some(Point2::new(1.0, 2.0)),
            history: VecDeque::from(vec![3.0, 2.5]),
            best_distance: Some(2.5),
            ..VdfState::default()
        };
        assert_eq!(VdfState::from_token(&s.to_token().unwrap()).unwrap(), s);
        assert!(matches!(
            VdfState::from_token(b"{not json"),
            Err(MobileError::BadToken { .. })
        ));
        assert_eq!(VdfState::from_token(b"").unwrap(), VdfState::default());
    }

    /// Regression: a client-forged token with `steps_in_mode = u64::MAX`
    /// overflowed the step counter (a panic in debug builds, a wrap in release).
    #[test]
    fn forged_token_counters_are_refused_or_saturate() {
        let mut v: serde_json::Value =
            serde_json::from_slice(&VdfState::default().to_token().unwrap()).unwrap();
        v["steps_in_mode"] = serde_json::json!(u64::MAX);
        assert!(matches!(
            VdfState::from_token(&serde_json::to_vec(&v).unwrap()),
            Err(MobileError::BadToken { .. })
        ));
        for (field, value) in [
            ("steps_since_progress", serde_json::json!(u64::MAX)),
            ("hit_distance", serde_json::json!(-1.0)),
            ("hit_distance", serde_json::json!(1e308)),
            ("locked_direction", serde_json::json!(1e308)),
            ("hit_point", serde_json::json!({"x": 1e308, "y": 0.0})),
            ("best_distance", serde_json::json!(-3.0)),
            ("history", serde_json::json!([1.0, -2.0])),
        ] {
            let mut v: serde_json::Value =
                serde_json::from_slice(&VdfState::default().to_token().unwrap()).unwrap();
            v[field] = value;
            assert!(
                VdfState::from_token(&serde_json::to_vec(&v).unwrap()).is_err(),
                "{field}"
            );
        }
        // The largest accepted counters step without overflow.
        let s = VdfState {
            steps_in_mode: MAX_TOKEN_STEPS,
            steps_since_progress: MAX_TOKEN_STEPS,
            ..VdfState::default()
        };
        let s = VdfState::from_token(&s.to_token().unwrap()).unwrap();
        let (next, _) = vdf_step(
            &s,
            Pose::default(),
            Point2::new(3.0, 0.0),
            &[5.0; 8],
            &sensors(),
            &VdfParams::default(),
        )
        .unwrap();
        assert!(next.steps_in_mode <= MAX_TOKEN_STEPS + 1);
        // A state a token cannot carry is an error, never an empty token.
        let nan = VdfState {
            hit_distance: f64::NAN,
            ..VdfState::default()
        };
        assert!(nan.to_token().is_err());
    }

    #[test]
    fn bad_readings_are_rejected() {
        let s = VdfState::default();
        let e = vdf_step(
            &s,
            Pose::default(),
            Point2::new(1.0, 0.0),
            &[1.0; 3],
            &sensors(),
            &VdfParams::default(),
        );
        assert!(matches!(e, Err(MobileError::TooFew { .. })));
        let mut r = [1.0; 8];
        r[3] = f64::NAN;
        assert!(
            vdf_step(
                &s,
                Pose::default(),
                Point2::new(1.0, 0.0),
                &r,
                &sensors(),
                &VdfParams::default()
            )
            .is_err()
        );
    }
}
