//! Vector-distance local navigation (S1 §3.5, §4.2.4): a weighted sum of attracting and
//! repelling sensor vectors, with the rotate / lock / track modes, hit and leave points and
//! "no path" detection. The modal state is a plain serialisable struct so a stateless server
//! can hand it to the caller as an opaque token.

use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, TAU};

use super::angle::wrap_angle;
use super::error::{MobileError, check_count, check_finite, check_positive, check_range};
use super::field::{MobileField, VdfField};
use super::pose::{MAX_COORDINATE, MAX_RATE, Point2, Pose, Twist};
use super::sensors::RangeSensorParams;

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

/// The navigator's modal state: everything a step needs from the past.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VdfState {
    /// Current mode.
    pub mode: NavMode,
    /// Current turning side.
    pub side: TurnSide,
    /// World direction of w'_0 locked in L mode, rad.
    pub locked_direction: f64,
    /// Hit point H of the current T episode.
    pub hit_point: Option<Point2>,
    /// |HG| when H was set, m.
    pub hit_distance: f64,
    /// The robot has moved away from H since the hit.
    pub left_hit_zone: bool,
    /// A turning side has been chosen before (it is kept through short R episodes).
    pub side_chosen: bool,
    /// Steps spent in the current mode.
    pub steps_in_mode: u64,
    /// Distances to the goal over the last n + 1 steps (L mode), m.
    pub history: VecDeque<f64>,
    /// Best distance to the goal in the current T episode, m.
    pub best_distance: Option<f64>,
    /// Steps since `best_distance` last improved by c2.
    pub steps_since_progress: u64,
    /// The other turning side has been tried for the current H ([`VdfParams::retry_other_side`]).
    #[serde(default)]
    pub side_retried: bool,
}

const MAX_TOKEN_HISTORY: usize = 100_000;
/// Largest step counter a token may carry: counters saturate, and a forged
/// `u64::MAX` is refused rather than trusted.
pub const MAX_TOKEN_STEPS: u64 = 1 << 40;

impl VdfState {
    /// Serialises to an opaque token (JSON bytes). Fails (never an empty
    /// token) if the state holds a value a token cannot carry.
    pub fn to_token(&self) -> Result<Vec<u8>, MobileError> {
        self.check()?;
        serde_json::to_vec(self).map_err(|e| MobileError::BadToken {
            reason: format!("the state could not be encoded: {e}"),
        })
    }

    /// Decodes and checks a token produced by [`VdfState::to_token`]: every
    /// field within its bounds (finite angles and distances within the world,
    /// non-negative distances, counters at most [`MAX_TOKEN_STEPS`]).
    pub fn from_token(token: &[u8]) -> Result<Self, MobileError> {
        if token.is_empty() {
            return Ok(Self::default());
        }
        let s: Self = serde_json::from_slice(token).map_err(|e| MobileError::BadToken {
            reason: e.to_string().chars().take(128).collect(),
        })?;
        s.check()?;
        Ok(s)
    }

    fn check(&self) -> Result<(), MobileError> {
        let bad = |r: &str| MobileError::BadToken { reason: r.to_owned() };
        // Distances in a world of coordinates within ±MAX_COORDINATE.
        let max_distance = 4.0 * MAX_COORDINATE;
        let distance_ok = |d: f64| d.is_finite() && (0.0..=max_distance).contains(&d);
        if !(self.locked_direction.is_finite() && self.locked_direction.abs() <= MAX_RATE) {
            return Err(bad("locked direction not finite or out of range"));
        }
        if !distance_ok(self.hit_distance) {
            return Err(bad("hit distance not finite, negative or out of range"));
        }
        if self
            .hit_point
            .is_some_and(|h| h.validate(MobileField::Goal).is_err())
        {
            return Err(bad("hit point not finite or out of the world"));
        }
        if self.history.len() > MAX_TOKEN_HISTORY || !self.history.iter().all(|d| distance_ok(*d)) {
            return Err(bad(
                "history too long, or a distance not finite, negative or out of range",
            ));
        }
        if self.best_distance.is_some_and(|d| !distance_ok(d)) {
            return Err(bad("best distance not finite, negative or out of range"));
        }
        if self.steps_in_mode > MAX_TOKEN_STEPS || self.steps_since_progress > MAX_TOKEN_STEPS {
            return Err(bad("step counter out of range"));
        }
        Ok(())
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

/// Gap reading in world direction `beta`: the sensor whose beam centre is nearest.
fn reading_at(readings: &[f64], theta: f64, beta: f64) -> f64 {
    let n = readings.len();
    let rel = wrap_angle(beta - theta).rem_euclid(TAU);
    let i = (rel / (TAU / n as f64)).round() as usize % n;
    readings[i]
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

/// In-place variant of [`vdf_step`] without validation (simulation loops).
pub(crate) fn vdf_step_mut(
    s: &mut VdfState,
    pose: Pose,
    goal: Point2,
    readings: &[f64],
    p: &VdfParams,
) -> VdfOutput {
    let me = pose.point();
    let z = me.distance(goal);
    let stop = |mode, event| VdfOutput {
        twist: Twist::ZERO,
        mode,
        force: Point2::default(),
        event: Some(event),
    };
    if z <= p.goal_tolerance {
        return stop(s.mode, VdfEvent::Reached);
    }
    let n = readings.len();
    let goal_dir = (goal.y - me.y).atan2(goal.x - me.x);
    let free = |beta: f64| reading_at(readings, pose.theta, beta) >= p.safe_distance;
    let goal_free = free(goal_dir);
    let goal_open = reading_at(readings, pose.theta, goal_dir) >= p.release_distance;
    s.history.push_back(z);
    while s.history.len() > p.progress_steps + 1 {
        s.history.pop_front();
    }
    s.steps_in_mode = s.steps_in_mode.saturating_add(1);
    let stalled = s.history.len() == p.progress_steps + 1 && s.history[0] - z < p.progress_min;
    let mut event = None;
    match s.mode {
        NavMode::Rotate => {
            // Blocked goal direction, or no progress (S1: with symmetric weights the robot
            // stops and "must turn left or right").
            if !goal_free || stalled {
                // A short R episode keeps the previous side (no flip-flopping at corners).
                if !s.side_chosen || s.steps_in_mode as usize > p.progress_steps {
                    s.side = choose_side(readings, pose.theta, goal_dir, p);
                    s.side_chosen = true;
                }
                s.mode = NavMode::Lock;
                s.locked_direction = first_free(readings, pose.theta, goal_dir, s.side, p);
                s.steps_in_mode = 0;
            }
        }
        NavMode::Lock => {
            if stalled {
                s.mode = NavMode::Track;
                s.steps_in_mode = 0;
                // A new hit point only when nearer the goal than the previous one (Bug2 rule);
                // otherwise the robot is still going round the same obstacle.
                if s.hit_point.is_none() || z < s.hit_distance - p.no_path_min {
                    s.hit_point = Some(me);
                    s.hit_distance = z;
                    s.left_hit_zone = false;
                }
                if s.best_distance.is_none() {
                    s.best_distance = Some(z);
                    s.steps_since_progress = 0;
                }
                event = Some(VdfEvent::Hit(me));
            } else if goal_open || !free(s.locked_direction) {
                // Goal direction open again, or w'_0 sees an obstacle: release the lock.
                s.mode = NavMode::Rotate;
                s.steps_in_mode = 0;
                if !goal_free {
                    s.mode = NavMode::Lock;
                    s.locked_direction = first_free(readings, pose.theta, goal_dir, s.side, p);
                }
            }
        }
        NavMode::Track => {
            let h = s.hit_point.unwrap_or(me);
            let all_clear = readings.iter().all(|&d| d > p.safe_distance);
            let on_line =
                line_distance(me, h, goal) < p.leave_tolerance && z < s.hit_distance - p.leave_tolerance;
            if all_clear || (on_line && goal_open) {
                s.mode = NavMode::Rotate;
                s.steps_in_mode = 0;
                event = Some(VdfEvent::Leave(me));
            }
        }
    }
    // "No path" (eq. 3.60 and the return to H), watched from the first hit on, in every mode
    // so that circling an enclosure through several T episodes is caught too.
    if let Some(h) = s.hit_point {
        let dh = me.distance(h);
        if dh > 3.0 * p.hit_radius {
            s.left_hit_zone = true;
        }
        let best = s.best_distance.unwrap_or(z);
        if z < best - p.no_path_min {
            s.best_distance = Some(z);
            s.steps_since_progress = 0;
        } else {
            s.steps_since_progress = s.steps_since_progress.saturating_add(1);
        }
        let give_up = if z < s.hit_distance - p.no_path_min - 3.0 * p.hit_radius {
            // Clearly past the obstacle of H: forget it.
            s.hit_point = None;
            s.best_distance = None;
            s.steps_since_progress = 0;
            s.side_retried = false;
            None
        } else if s.left_hit_zone && dh < p.hit_radius {
            Some(NoPathReason::ReturnedToHit)
        } else if s.steps_since_progress >= p.no_path_steps as u64 {
            Some(NoPathReason::NoProgress)
        } else {
            None
        };
        if let Some(reason) = give_up {
            if !p.retry_other_side || s.side_retried {
                return stop(s.mode, VdfEvent::NoPath(reason));
            }
            // Go round the other way from here, once.
            s.side_retried = true;
            s.side = match s.side {
                TurnSide::Left => TurnSide::Right,
                TurnSide::Right => TurnSide::Left,
            };
            s.side_chosen = true;
            s.mode = NavMode::Track;
            s.steps_in_mode = 0;
            s.hit_point = Some(me);
            s.hit_distance = z;
            s.left_hit_zone = false;
            s.best_distance = Some(z);
            s.steps_since_progress = 0;
            event = Some(VdfEvent::Hit(me));
        }
    }
    let sign = match s.side {
        TurnSide::Left => 1.0,
        TurnSide::Right => -1.0,
    };
    let centre = match s.mode {
        NavMode::Rotate => goal_dir,
        NavMode::Lock => s.locked_direction,
        NavMode::Track => {
            let (imin, dmin) = readings
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::INFINITY), |a, (i, d)| if d < a.1 { (i, d) } else { a });
            let obstacle_dir = pose.theta + TAU * imin as f64 / n as f64;
            let target = 0.8 * p.safe_distance;
            let off = (FRAC_PI_2 + p.wall_gain * (target - dmin)).clamp(FRAC_PI_4, 3.0 * FRAC_PI_4);
            obstacle_dir + sign * off
        }
    };
    let (fx, fy) = vector_sum(readings, pose.theta, centre, s.mode != NavMode::Rotate, s.side, p);
    let raw = if fx.hypot(fy) > 1e-9 {
        fy.atan2(fx)
    } else {
        centre + sign * FRAC_PI_2
    };
    // Deadlock guard: never steer into a blocked direction; turn towards the turning side
    // until a free one is found (a potential-field local minimum otherwise parks the robot
    // facing an obstacle with zero speed).
    let psi = if p.avoid_blocked_heading && !free(raw) {
        let side = if s.mode == NavMode::Rotate {
            choose_side(readings, pose.theta, raw, p)
        } else {
            s.side
        };
        first_free(readings, pose.theta, raw, side, p)
    } else {
        raw
    };
    let eps = wrap_angle(psi - pose.theta);
    let forward = !p.allow_reverse || eps.cos() >= 0.0;
    let (axis_err, dir) = if forward {
        (eps, 1.0)
    } else {
        (wrap_angle(eps + std::f64::consts::PI), -1.0)
    };
    let travel_dir = if forward {
        pose.theta
    } else {
        pose.theta + std::f64::consts::PI
    };
    let gap = reading_at(readings, pose.theta, travel_dir);
    let v = dir * p.max_speed * eps.cos().abs() * (gap / p.slow_distance).clamp(0.0, 1.0);
    let v = if forward && eps.cos() < 0.0 { 0.0 } else { v };
    let omega = (p.heading_gain * axis_err).clamp(-p.max_yaw_rate, p.max_yaw_rate);
    VdfOutput {
        twist: Twist::unicycle(v, omega),
        mode: s.mode,
        force: Point2::new(fx, fy),
        event,
    }
}

/// F = Σ f_i w'_i over the real sensors (eq. 3.50): f_i = ±K along sensor i's world
/// direction β_i = θ + 2πi/N (+K when its gap ≥ d_sa); the weight depends continuously on the
/// angle Δ_i = wrap(β_i − β_0) to the w'_0 direction, w'(Δ) = decay^(|Δ| / (2π/N)), times
/// 1 + (turn_gain − 1)·max(0, ±sin Δ) on the turning side when `turning`. Weights that
/// move continuously with β_0 avoid the chatter of snapping w'_0 to the nearest sensor.
fn vector_sum(
    readings: &[f64],
    theta: f64,
    centre: f64,
    turning: bool,
    side: TurnSide,
    p: &VdfParams,
) -> (f64, f64) {
    let n = readings.len();
    let step = TAU / n as f64;
    let sign = if side == TurnSide::Left { 1.0 } else { -1.0 };
    let (mut fx, mut fy) = (0.0, 0.0);
    for (i, &d) in readings.iter().enumerate() {
        let beta = theta + step * i as f64;
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

/// Turning side for L mode: compare free weighted directions left and right of the goal.
fn choose_side(readings: &[f64], theta: f64, goal_dir: f64, p: &VdfParams) -> TurnSide {
    match p.turn {
        TurnPreference::Left => TurnSide::Left,
        TurnPreference::Right => TurnSide::Right,
        TurnPreference::Auto => {
            let n = readings.len();
            let (mut l, mut r) = (0.0, 0.0);
            for k in 1..n.div_ceil(2) {
                let w = p.weight_decay.powi(k as i32);
                let a = TAU * k as f64 / n as f64;
                l += w * reading_at(readings, theta, goal_dir + a).min(p.safe_distance * 4.0);
                r += w * reading_at(readings, theta, goal_dir - a).min(p.safe_distance * 4.0);
            }
            if r > l { TurnSide::Right } else { TurnSide::Left }
        }
    }
}

/// The first free direction (gap ≥ d_sa) met when turning from the goal direction towards
/// `side` in sensor steps; the goal direction itself if none is free.
fn first_free(readings: &[f64], theta: f64, goal_dir: f64, side: TurnSide, p: &VdfParams) -> f64 {
    let n = readings.len();
    let sign = if side == TurnSide::Left { 1.0 } else { -1.0 };
    for k in 1..=n / 2 {
        let b = goal_dir + sign * TAU * k as f64 / n as f64;
        if reading_at(readings, theta, b) >= p.safe_distance {
            return wrap_angle(b);
        }
    }
    goal_dir
}

/// Distance from p to the line through a and b (to a when a = b).
fn line_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let l = dx.hypot(dy);
    if l == 0.0 {
        return p.distance(a);
    }
    ((p.x - a.x) * dy - (p.y - a.y) * dx).abs() / l
}

#[cfg(test)]
mod tests {
    use super::*;

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
