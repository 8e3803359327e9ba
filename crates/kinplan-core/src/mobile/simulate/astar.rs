//! Global navigation: grid A* on the known world, then path following.

use super::{Outcome, SimParams, SimRun, follow_path, start_check};
use crate::Deadline;
use crate::mobile::chassis::Chassis;
use crate::mobile::error::MobileError;
use crate::mobile::field::MobileField;
use crate::mobile::grid_astar::{GridAstarParams, plan_grid_astar_until};
use crate::mobile::path_follow::{ControllerKind, PathFollowParams, PathNode};
use crate::mobile::pose::{Point2, Pose};
use crate::mobile::vector_distance::NoPathReason;
use crate::mobile::world::World;

/// The controller that follows a grid A* path when the caller names none: pure pursuit. The
/// path is a dense polyline of cell centres; pure pursuit tracks the polyline through its
/// lookahead point, where a node-to-node controller (Lyapunov) would turn at every cell.
pub const GRID_PATH_CONTROLLER: ControllerKind = ControllerKind::PurePursuit;

/// Global navigation: plans with [`plan_grid_astar`](crate::mobile::plan_grid_astar) on the known world, then follows the
/// path with [`follow_path`] (the controller in `follow`, typically [`GRID_PATH_CONTROLLER`]). No
/// grid path gives a run with outcome NO_PATH, reason [`NoPathReason::NoGridPath`], and only
/// the start state.
#[allow(clippy::too_many_arguments)]
pub fn navigate_astar(
    chassis: &Chassis,
    start: Pose,
    goal: Point2,
    world: &World,
    astar: &GridAstarParams,
    follow: &PathFollowParams,
    sim: &SimParams,
    deadline: Deadline<'_>,
) -> Result<SimRun, MobileError> {
    start.validate(MobileField::Start)?;
    sim.validate()?;
    start_check(Some(world), start, sim.robot_radius)?;
    let Some(points) = plan_grid_astar_until(world, start.point(), goal, astar, deadline)? else {
        return Ok(SimRun {
            outcome: if deadline.expired() {
                Outcome::Cancelled
            } else {
                Outcome::NoPath
            },
            no_path_reason: (!deadline.expired()).then_some(NoPathReason::NoGridPath),
            states: vec![start],
            ..SimRun::default()
        });
    };
    let path: Vec<PathNode> = points.iter().skip(1).map(|p| PathNode::at(p.x, p.y)).collect();
    if path.is_empty() {
        return Ok(SimRun {
            outcome: Outcome::Reached,
            states: vec![start],
            ..SimRun::default()
        });
    }
    follow_path(chassis, start, &path, Some(world), follow, sim, deadline)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::world::Obstacle;

    /// A goal inside a 2 m square block has no free grid cell to reach: NO_PATH for the
    /// grid reason, the run holding the start only. An open world is crossed with the default
    /// follower.
    #[test]
    fn no_grid_path_is_a_no_path_outcome_with_its_reason() {
        let block = World::new(vec![Obstacle::polygon(&[
            (2.0, -1.0),
            (4.0, -1.0),
            (4.0, 1.0),
            (2.0, 1.0),
        ])])
        .unwrap();
        let follow = PathFollowParams {
            controller: GRID_PATH_CONTROLLER,
            ..PathFollowParams::default()
        };
        let astar = GridAstarParams::default();
        let sim = SimParams::default();
        let start = Pose::default();
        let run = navigate_astar(
            &Chassis::default(),
            start,
            Point2::new(3.0, 0.0),
            &block,
            &astar,
            &follow,
            &sim,
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::NoPath);
        assert_eq!(run.no_path_reason, Some(NoPathReason::NoGridPath));
        assert_eq!(run.states, vec![start]);
        let run = navigate_astar(
            &Chassis::default(),
            start,
            Point2::new(3.0, 3.0),
            &block,
            &astar,
            &follow,
            &sim,
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::Reached);
        assert_eq!(run.no_path_reason, None);
    }
}
