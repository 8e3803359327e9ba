//! The navigator's mode logic (S1 §3.5, §4.2.4), as pure functions of the state and what the
//! robot sees: [`transition`] switches between rotate, lock and track; [`watch_no_path`]
//! decides when there is no path.

use super::steer::{choose_side, first_free};
use super::{NavMode, NoPathReason, Percept, TurnSide, VdfEvent, VdfParams, VdfState};
use crate::mobile::pose::Point2;
use crate::mobile::token::bump;

use super::state::MAX_TOKEN_STEPS;

/// The mode switch of one step. Records the goal distance z in the last n + 1 (`history`),
/// counts the step, then: R→L when the goal direction is blocked (gap < d_sa) or z fell by less
/// than c1 over n steps (choosing the turning side unless a short R episode keeps it, and
/// locking w'_0 onto the first free direction towards that side); L→T when stalled (eq. 3.58),
/// setting the hit point H only when nearer the goal than the previous one by c2 (Bug2 rule),
/// and starting the best-distance watch; L→R when the gap towards the goal exceeds
/// `release_distance` or the locked direction gets blocked (straight back to L, re-locked,
/// while the goal direction is blocked); T→R (leave point) when every gap exceeds d_sa or the
/// robot is on the line H–G, nearer the goal than H by the leave tolerance, with the goal
/// direction open (∠HLG = 180°, eq. 3.59). Returns the next state and the Hit / Leave event.
pub fn transition(mut s: VdfState, see: &Percept, p: &VdfParams) -> (VdfState, Option<VdfEvent>) {
    let (me, z) = (see.me, see.z);
    let goal_free = see.free(see.goal_dir, p);
    let goal_open = see.gap(see.goal_dir) >= p.release_distance;
    s.history.push_back(z);
    while s.history.len() > p.progress_steps + 1 {
        s.history.pop_front();
    }
    s.steps_in_mode = bump(s.steps_in_mode, MAX_TOKEN_STEPS);
    let stalled = s.history.len() == p.progress_steps + 1 && s.history[0] - z < p.progress_min;
    let mut event = None;
    match s.mode {
        NavMode::Rotate => {
            // Blocked goal direction, or no progress (S1: with symmetric weights the robot
            // stops and "must turn left or right").
            if !goal_free || stalled {
                // A short R episode keeps the previous side (no flip-flopping at corners).
                if !s.side_chosen || s.steps_in_mode > p.progress_steps as u64 {
                    s.side = choose_side(see, see.goal_dir, p);
                    s.side_chosen = true;
                }
                s.mode = NavMode::Lock;
                s.locked_direction = first_free(see, see.goal_dir, s.side, p);
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
            } else if goal_open || !see.free(s.locked_direction, p) {
                // Goal direction open again, or w'_0 sees an obstacle: release the lock.
                s.mode = NavMode::Rotate;
                s.steps_in_mode = 0;
                if !goal_free {
                    s.mode = NavMode::Lock;
                    s.locked_direction = first_free(see, see.goal_dir, s.side, p);
                }
            }
        }
        NavMode::Track => {
            let h = s.hit_point.unwrap_or(me);
            let all_clear = see.readings.iter().all(|&d| d > p.safe_distance);
            let on_line =
                line_distance(me, h, see.goal) < p.leave_tolerance && z < s.hit_distance - p.leave_tolerance;
            if all_clear || (on_line && goal_open) {
                s.mode = NavMode::Rotate;
                s.steps_in_mode = 0;
                event = Some(VdfEvent::Leave(me));
            }
        }
    }
    (s, event)
}

/// The "no path" watch (eq. 3.60 and the return to H), from the first hit on and in every
/// mode, so that circling an enclosure through several T episodes is caught too. With a hit
/// point H: the robot has left H's zone once it is farther than 3·hit_radius from H; the best
/// distance improves when z < best − c2 (resetting the step count, otherwise counted). Then:
/// z < |HG| − c2 − 3·hit_radius → clearly past H's obstacle, H and the watch are forgotten;
/// back within hit_radius of H after leaving its zone → ReturnedToHit; m steps without
/// improvement → NoProgress. A verdict is final unless `retry_other_side` allows one retry
/// for this H: the turning side flips and the robot tracks from a new H here (event Hit).
/// Returns the next state and the event: `event` passed through, NoPath, or the retry's Hit.
pub fn watch_no_path(
    mut s: VdfState,
    see: &Percept,
    event: Option<VdfEvent>,
    p: &VdfParams,
) -> (VdfState, Option<VdfEvent>) {
    let Some(h) = s.hit_point else {
        return (s, event);
    };
    let (me, z) = (see.me, see.z);
    let dh = me.distance(h);
    if dh > 3.0 * p.hit_radius {
        s.left_hit_zone = true;
    }
    let best = s.best_distance.unwrap_or(z);
    if z < best - p.no_path_min {
        s.best_distance = Some(z);
        s.steps_since_progress = 0;
    } else {
        s.steps_since_progress = bump(s.steps_since_progress, MAX_TOKEN_STEPS);
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
    let Some(reason) = give_up else {
        return (s, event);
    };
    if !p.retry_other_side || s.side_retried {
        return (s, Some(VdfEvent::NoPath(reason)));
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
    (s, Some(VdfEvent::Hit(me)))
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
    use crate::mobile::pose::Pose;
    use std::collections::VecDeque;
    use std::f64::consts::FRAC_PI_4;

    const GOAL: Point2 = Point2::new(5.0, 0.0);

    fn blocked(sensors: &[usize]) -> [f64; 8] {
        let mut r = [2.0; 8];
        for &i in sensors {
            r[i] = 0.1;
        }
        r
    }

    /// R→L with the goal direction blocked. Auto side: left and right sums
    /// Σ_{k=1..3} 0.6^k·min(gap, 4·0.3) are equal when only the front is blocked (tie → left),
    /// and w'_0 locks onto the first free sensor direction to the left, π/4. Blocking the
    /// front-left sensor too makes the left sum 0.6·0.1 + 0.36·1.2 + 0.216·1.2 smaller than the
    /// right one (0.6 + 0.36 + 0.216)·1.2: right side, lock at −π/4.
    #[test]
    fn a_blocked_goal_direction_locks_towards_the_freer_side() {
        let p = VdfParams::default();
        let front = blocked(&[0]);
        let see = Percept::new(Pose::default(), GOAL, &front);
        let (s, event) = transition(VdfState::default(), &see, &p);
        assert_eq!((s.mode, s.side, event), (NavMode::Lock, TurnSide::Left, None));
        assert!(s.side_chosen);
        assert!((s.locked_direction - FRAC_PI_4).abs() < 1e-12);
        assert_eq!(
            (s.steps_in_mode, s.history.clone()),
            (0, VecDeque::from(vec![5.0]))
        );

        let front_left = blocked(&[0, 1]);
        let see = Percept::new(Pose::default(), GOAL, &front_left);
        let (s, _) = transition(VdfState::default(), &see, &p);
        assert_eq!((s.mode, s.side), (NavMode::Lock, TurnSide::Right));
        assert!((s.locked_direction + FRAC_PI_4).abs() < 1e-12);
    }

    /// L→T: with n = 3, a fourth distance of 5 m after three of 5 m is no progress
    /// (5 − 5 < c1 = 0.05): H is set here, at |HG| = 5, and the best-distance watch starts.
    #[test]
    fn a_stalled_lock_starts_tracking_at_a_hit_point() {
        let p = VdfParams {
            progress_steps: 3,
            ..VdfParams::default()
        };
        let s = VdfState {
            mode: NavMode::Lock,
            locked_direction: FRAC_PI_4,
            side_chosen: true,
            history: VecDeque::from(vec![5.0, 5.0, 5.0]),
            steps_in_mode: 3,
            ..VdfState::default()
        };
        let front = blocked(&[0]);
        let see = Percept::new(Pose::default(), GOAL, &front);
        let (s, event) = transition(s, &see, &p);
        assert_eq!(s.mode, NavMode::Track);
        assert_eq!(event, Some(VdfEvent::Hit(Point2::new(0.0, 0.0))));
        assert_eq!(s.hit_point, Some(Point2::new(0.0, 0.0)));
        assert_eq!(
            (s.hit_distance, s.best_distance, s.steps_since_progress),
            (5.0, Some(5.0), 0)
        );
        assert!(!s.left_hit_zone);
        assert_eq!(s.history.len(), 4);
    }

    /// L→R when the gap towards the goal (2 m) exceeds the release distance (0.6 m); T→R with a
    /// leave point when every gap exceeds d_sa; T kept with an obstacle beside the robot off
    /// the line H–G (0.5 m from it, tolerance 0.1 m).
    #[test]
    fn lock_and_track_end_when_the_way_opens() {
        let p = VdfParams::default();
        let free = [2.0; 8];
        let see = Percept::new(Pose::default(), GOAL, &free);
        let lock = VdfState {
            mode: NavMode::Lock,
            locked_direction: FRAC_PI_4,
            ..VdfState::default()
        };
        let (s, event) = transition(lock, &see, &p);
        assert_eq!((s.mode, event), (NavMode::Rotate, None));

        let track = VdfState {
            mode: NavMode::Track,
            hit_point: Some(Point2::new(0.0, 0.0)),
            hit_distance: 5.0,
            ..VdfState::default()
        };
        let (s, event) = transition(track.clone(), &see, &p);
        assert_eq!(
            (s.mode, event),
            (NavMode::Rotate, Some(VdfEvent::Leave(Point2::new(0.0, 0.0))))
        );

        let beside = blocked(&[2]);
        let off_line = Percept::new(Pose::new(0.0, 0.5, 0.0), GOAL, &beside);
        let (s, event) = transition(track, &off_line, &p);
        assert_eq!((s.mode, event), (NavMode::Track, None));
    }

    /// The no-path watch, by hand with H = (0, 0), |HG| = 5, best 5, hit radius 0.25 (zone
    /// 0.75), c2 = 0.05: at (0.1, 0) after leaving the zone, z = 4.9 improves the best (4.9 <
    /// 4.95) but the robot is back within 0.25 of H → ReturnedToHit. At (0, 1) the robot is
    /// 1 > 0.75 from H: the zone is left, z = √26 does not improve, one step is counted. At
    /// (3, 0), z = 2 < 5 − 0.05 − 0.75: past H's obstacle, the watch is dropped and the event
    /// passes through. Without H nothing changes.
    #[test]
    fn the_no_path_watch_by_hand() {
        let p = VdfParams::default();
        let free = [2.0; 8];
        let watched = VdfState {
            mode: NavMode::Track,
            hit_point: Some(Point2::new(0.0, 0.0)),
            hit_distance: 5.0,
            best_distance: Some(5.0),
            steps_since_progress: 7,
            ..VdfState::default()
        };
        let back = VdfState {
            left_hit_zone: true,
            ..watched.clone()
        };
        let see = Percept::new(Pose::new(0.1, 0.0, 0.0), GOAL, &free);
        let (s, event) = watch_no_path(back, &see, None, &p);
        assert_eq!(event, Some(VdfEvent::NoPath(NoPathReason::ReturnedToHit)));
        assert_eq!((s.best_distance, s.steps_since_progress), (Some(4.9), 0));

        let see = Percept::new(Pose::new(0.0, 1.0, 0.0), GOAL, &free);
        let (s, event) = watch_no_path(watched.clone(), &see, None, &p);
        assert_eq!(event, None);
        assert!(s.left_hit_zone);
        assert_eq!((s.best_distance, s.steps_since_progress), (Some(5.0), 8));

        let past = Point2::new(3.0, 0.0);
        let see = Percept::new(Pose::new(past.x, past.y, 0.0), GOAL, &free);
        let leave = Some(VdfEvent::Leave(past));
        let (s, event) = watch_no_path(watched, &see, leave, &p);
        assert_eq!(event, leave);
        assert_eq!(
            (s.hit_point, s.best_distance, s.steps_since_progress),
            (None, None, 0)
        );

        let (s, event) = watch_no_path(VdfState::default(), &see, leave, &p);
        assert_eq!((s, event), (VdfState::default(), leave));
    }
}
