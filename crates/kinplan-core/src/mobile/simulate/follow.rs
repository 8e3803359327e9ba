//! Closed-loop path following: [`follow_path`] drives a path-following controller on a
//! chassis until the last node is reached, time runs out, it collides or it is stopped.

use super::{Outcome, SimParams, SimRun, start_check, step_into};
use crate::Deadline;
use crate::mobile::chassis::Chassis;
use crate::mobile::error::MobileError;
use crate::mobile::field::MobileField;
use crate::mobile::path_follow::{
    PathFollowParams, PathFollowState, PathNode, path_follow_unchecked, validate_path,
};
use crate::mobile::pose::Pose;
use crate::mobile::world::World;

/// Simulates [`path_follow_step`](crate::mobile::path_follow_step) on `chassis` from `start` along
/// `path` (optionally among obstacles, with collision detection) until the last node is
/// reached, the time runs out, a collision happens or `deadline` expires (checked
/// every step).
///
/// ```
/// use kinplan_core::Deadline;
/// use kinplan_core::mobile::{follow_path, Chassis, Outcome, PathFollowParams, PathNode, Pose, SimParams};
/// let path = [PathNode { x: 1.0, y: 1.0, heading: Some(0.0) }];
/// let sim = SimParams { dt: 0.02, max_time: 120.0, ..SimParams::default() };
/// let run = follow_path(&Chassis::omr_iii(), Pose::default(), &path, None, &PathFollowParams::default(), &sim, Deadline::none()).unwrap();
/// assert_eq!(run.outcome, Outcome::Reached);
/// ```
pub fn follow_path(
    chassis: &Chassis,
    start: Pose,
    path: &[PathNode],
    world: Option<&World>,
    follow: &PathFollowParams,
    sim: &SimParams,
    deadline: Deadline<'_>,
) -> Result<SimRun, MobileError> {
    chassis.validate()?;
    start.validate(MobileField::Start)?;
    validate_path(path)?;
    follow.validate()?;
    sim.validate()?;
    let follow = &follow.for_chassis(chassis);
    let mut run = SimRun::default();
    run.metrics.min_clearance = start_check(world, start, sim.robot_radius)?;
    let steps = (sim.max_time / sim.dt).ceil() as usize;
    let mut pose = start;
    let mut progress = PathFollowState::default();
    let mut scratch = Vec::new();
    run.states.reserve(steps.min(1 << 20) + 1);
    run.states.push(pose);
    let mut finished = false;
    for _ in 0..steps {
        if deadline.expired() {
            run.outcome = Outcome::Cancelled;
            finished = true;
            break;
        }
        let s = path_follow_unchecked(pose, path, progress, sim.dt, follow, &mut scratch);
        progress = s.next;
        if s.reached {
            run.outcome = Outcome::Reached;
            finished = true;
            break;
        }
        if step_into(&mut run, world, chassis, &mut pose, s.twist, sim) {
            finished = true;
            break;
        }
    }
    if !finished {
        let s = path_follow_unchecked(pose, path, progress, sim.dt, follow, &mut scratch);
        run.outcome = if s.reached {
            Outcome::Reached
        } else {
            Outcome::Timeout
        };
    }
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::path_follow::ControllerKind;
    use crate::mobile::world::Obstacle;

    /// Regression: pure pursuit's rotate-to-heading asks for ω ≠ 0 at v = 0, which a steered
    /// chassis clamps to nothing; the car stood still until the timeout. The docs say steered
    /// chassis ignore it, and `follow_path` now does.
    #[test]
    fn steered_chassis_do_not_rotate_in_place_under_pure_pursuit() {
        // Node at a bearing of atan2(2, 1) = 63° > rotate_min_angle (45°).
        let path = [PathNode::at(1.0, 2.0)];
        let follow = PathFollowParams {
            controller: ControllerKind::PurePursuit,
            goal_tolerance: 0.05,
            ..PathFollowParams::default()
        };
        for chassis in [Chassis::mobil_ii(), Chassis::Tricycle(Default::default())] {
            let run = follow_path(
                &chassis,
                Pose::default(),
                &path,
                None,
                &follow,
                &SimParams::default(),
                Deadline::none(),
            )
            .unwrap();
            assert_eq!(
                run.outcome,
                Outcome::Reached,
                "{}: {:?}",
                chassis.name(),
                run.metrics
            );
        }
    }

    #[test]
    fn follow_path_reaches_final_pose_with_every_controller() {
        let path = [
            PathNode::at(1.0, 0.0),
            PathNode::at(2.0, 1.0),
            PathNode {
                x: 3.0,
                y: 1.0,
                heading: Some(0.0),
            },
        ];
        for ctl in [ControllerKind::Lyapunov, ControllerKind::PurePursuit] {
            let f = PathFollowParams {
                controller: ctl,
                ..PathFollowParams::default()
            };
            let sim = SimParams {
                dt: 0.02,
                max_time: 120.0,
                ..SimParams::default()
            };
            let run = follow_path(
                &Chassis::default(),
                Pose::default(),
                &path,
                None,
                &f,
                &sim,
                Deadline::none(),
            )
            .unwrap();
            assert_eq!(run.outcome, Outcome::Reached, "{ctl:?}");
            let last = run.states.last().unwrap();
            assert!((last.x - 3.0).abs() < 0.02 && (last.y - 1.0).abs() < 0.02 && last.theta.abs() < 0.0175);
        }
        // Steered controllers on MOBIL-II to a point without heading.
        let path = [PathNode::at(2.0, 1.0), PathNode::at(4.0, -1.0)];
        for ctl in [ControllerKind::GoalSeeking, ControllerKind::ShortestPath] {
            let f = PathFollowParams {
                controller: ctl,
                goal_tolerance: 0.05,
                ..PathFollowParams::default()
            };
            let sim = SimParams {
                dt: 0.05,
                max_time: 120.0,
                ..SimParams::default()
            };
            let run = follow_path(
                &Chassis::mobil_ii(),
                Pose::default(),
                &path,
                None,
                &f,
                &sim,
                Deadline::none(),
            )
            .unwrap();
            assert_eq!(run.outcome, Outcome::Reached, "{ctl:?}");
        }
    }

    #[test]
    fn collision_is_detected_and_reported() {
        // Pure pursuit straight through a wall.
        let w = World::new(vec![Obstacle::polygon(&[
            (1.0, -1.0),
            (1.2, -1.0),
            (1.2, 1.0),
            (1.0, 1.0),
        ])])
        .unwrap();
        let path = [PathNode::at(3.0, 0.0)];
        let f = PathFollowParams {
            controller: ControllerKind::PurePursuit,
            ..PathFollowParams::default()
        };
        let run = follow_path(
            &Chassis::default(),
            Pose::default(),
            &path,
            Some(&w),
            &f,
            &SimParams::default(),
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::Collision);
        assert_eq!(run.collided_with, Some(0));
        let last = run.states.last().unwrap();
        // Contact happens when x + 0.22 ≥ 1.0; sub-steps are ≤ 0.055 m long.
        assert!(last.x >= 0.78 - 1e-9 && last.x < 0.78 + 0.06, "{last:?}");
    }
}
