//! Following a path of nodal points: pick the active node, drop it once inside its switching
//! distance, and hand the last node (optionally with a heading) to the Lyapunov controller.

use serde::{Deserialize, Serialize};

use super::angle::wrap_angle;
use super::error::{MobileError, check_positive, check_range};
use super::field::{Component, FollowField, FollowParam, MobileField};
use super::goal_seeking::{SteeringParams, goal_seeking_step};
use super::lyapunov::{LyapunovParams, lyapunov_step_unchecked};
use super::pose::{Point2, Pose, Twist};
use super::pure_pursuit::{PurePursuitParams, pure_pursuit_unchecked};
use super::shortest_path::shortest_path_step;
use super::token::ControllerMemory;

/// A nodal point of a path: position (m) and an optional heading (rad) to reach it with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PathNode {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Heading to arrive with, rad; honoured for the last node.
    pub heading: Option<f64>,
}

impl PathNode {
    /// A node without heading.
    pub const fn at(x: f64, y: f64) -> Self {
        Self { x, y, heading: None }
    }

    /// The position.
    pub fn point(&self) -> Point2 {
        Point2::new(self.x, self.y)
    }
}

/// Which controller drives the robot between nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ControllerKind {
    /// Aicardi Lyapunov pose controller to each node (heading: towards the next node).
    #[default]
    Lyapunov,
    /// Pure pursuit along the polyline of the remaining nodes.
    PurePursuit,
    /// S1 §4.2.1 goal seeking to each node.
    GoalSeeking,
    /// S1 §4.2.2 shortest-path steering to each node.
    ShortestPath,
}

/// Parameters of the path follower.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathFollowParams {
    /// Controller between nodes (default Lyapunov).
    pub controller: ControllerKind,
    /// An intermediate node is dropped once the robot is closer than this, m (default 0.3).
    pub switching_distance: f64,
    /// The last node counts as reached within this distance, m (default 0.02).
    pub goal_tolerance: f64,
    /// ... and, if it has a heading, within this heading error, rad (default 1° = 0.01745).
    pub heading_tolerance: f64,
    /// Lyapunov gains (S1 defaults).
    pub lyapunov: LyapunovParams,
    /// Pure pursuit parameters (Nav2 defaults).
    pub pure_pursuit: PurePursuitParams,
    /// Goal-seeking / shortest-path parameters (MOBIL-II).
    pub steering: SteeringParams,
}

impl Default for PathFollowParams {
    fn default() -> Self {
        Self {
            controller: ControllerKind::Lyapunov,
            switching_distance: 0.3,
            goal_tolerance: 0.02,
            heading_tolerance: 1f64.to_radians(),
            lyapunov: LyapunovParams::default(),
            pure_pursuit: PurePursuitParams::default(),
            steering: SteeringParams::default(),
        }
    }
}

impl PathFollowParams {
    /// These parameters as `chassis` can carry them out: a steered chassis (one
    /// with a curvature limit) cannot turn in place, so pure pursuit's
    /// rotate-to-heading is switched off for it instead of being clamped to a
    /// standstill (as [`PurePursuitParams::rotate_to_heading`] documents).
    pub fn for_chassis(&self, chassis: &super::Chassis) -> Self {
        let mut params = *self;
        if chassis.max_curvature().is_some() {
            params.pure_pursuit.rotate_to_heading = false;
        }
        params
    }

    /// Positive distances and tolerances; nested parameter sets valid.
    pub fn validate(&self) -> Result<(), MobileError> {
        check_positive(
            MobileField::Follow(FollowField::Own(FollowParam::SwitchingDistance)),
            self.switching_distance,
        )?;
        check_positive(
            MobileField::Follow(FollowField::Own(FollowParam::GoalTolerance)),
            self.goal_tolerance,
        )?;
        check_range(
            MobileField::Follow(FollowField::Own(FollowParam::HeadingTolerance)),
            self.heading_tolerance,
            1e-9,
            std::f64::consts::PI,
        )?;
        self.lyapunov.validate()?;
        self.pure_pursuit.validate()?;
        self.steering.validate()
    }
}

/// Progress along the path, handed back by the caller each step (serialisable).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PathFollowState {
    /// Index of the active node.
    pub target: usize,
    /// Nearest polyline segment (pure pursuit).
    pub segment: usize,
}

impl ControllerMemory for PathFollowState {
    /// The path's length: both indices must name one of its nodes.
    type Context = usize;

    fn check(&self, path_len: &usize) -> Result<(), &'static str> {
        if self.target < *path_len && self.segment < *path_len {
            Ok(())
        } else {
            Err("the token points beyond the path's last node")
        }
    }
}

/// Output of [`path_follow_step`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathFollowStep {
    /// Command (zero once reached).
    pub twist: Twist,
    /// State for the next step.
    pub next: PathFollowState,
    /// The last node is reached (position and, if given, heading).
    pub reached: bool,
}

/// Validates a path: non-empty, finite coordinates and headings.
pub fn validate_path(path: &[PathNode]) -> Result<(), MobileError> {
    if path.is_empty() {
        return Err(MobileError::EmptyPath);
    }
    for (i, n) in path.iter().enumerate() {
        if n.x.is_finite() && n.y.is_finite() && n.heading.is_none_or(f64::is_finite) {
            continue;
        }
        n.point().validate(|part| MobileField::Path { index: i, part })?;
        if let Some(h) = n.heading {
            super::error::check_finite(
                MobileField::Path {
                    index: i,
                    part: Component::Heading,
                },
                h,
            )?;
        }
    }
    Ok(())
}

/// One step of the nodal-point follower. While the active node is not the last and the robot
/// is within `switching_distance` of it, the next node becomes active. The last node is reached
/// within `goal_tolerance` (and `heading_tolerance` if it has a heading). Controllers:
/// Lyapunov to each node with goal heading = its own heading, or the direction to the next
/// node, or for the last node the approach direction; pure pursuit along the remaining
/// polyline; goal seeking / shortest path to each node's position. Whatever the controller, a
/// last node with a heading is approached with the Lyapunov law once the robot is within
/// max(switching distance, lookahead) of it.
///
/// ```
/// use kinplan_core::mobile::{path_follow_step, PathFollowParams, PathFollowState, PathNode, Pose};
/// let path = [PathNode::at(0.1, 0.0), PathNode::at(2.0, 0.0)];
/// let s = path_follow_step(Pose::new(0.0, 0.0, 0.0), &path, PathFollowState::default(), 0.05,
///                          &PathFollowParams::default()).unwrap();
/// assert_eq!(s.next.target, 1); // node 0 is inside the 0.3 m switching distance
/// assert!(s.twist.vx > 0.0 && !s.reached);
/// ```
pub fn path_follow_step(
    state: Pose,
    path: &[PathNode],
    progress: PathFollowState,
    dt: f64,
    params: &PathFollowParams,
) -> Result<PathFollowStep, MobileError> {
    params.validate()?;
    state.validate(MobileField::State)?;
    validate_path(path)?;
    check_positive(MobileField::Dt, dt)?;
    Ok(path_follow_unchecked(
        state,
        path,
        progress,
        dt,
        params,
        &mut Vec::new(),
    ))
}

pub(crate) fn path_follow_unchecked(
    state: Pose,
    path: &[PathNode],
    progress: PathFollowState,
    dt: f64,
    params: &PathFollowParams,
    scratch: &mut Vec<Point2>,
) -> PathFollowStep {
    let last = path.len() - 1;
    let me = state.point();
    let mut next = progress;
    next.target = next.target.min(last);
    while next.target < last && me.distance(path[next.target].point()) < params.switching_distance {
        next.target += 1;
    }
    let node = path[next.target];
    let d = me.distance(node.point());
    if next.target == last
        && d < params.goal_tolerance
        && node
            .heading
            .is_none_or(|h| wrap_angle(state.theta - h).abs() < params.heading_tolerance)
    {
        return PathFollowStep {
            twist: Twist::ZERO,
            next,
            reached: true,
        };
    }
    let final_heading = next.target == last && node.heading.is_some();
    let near_final = d < params.switching_distance.max(params.pure_pursuit.lookahead);
    let use_lyapunov = params.controller == ControllerKind::Lyapunov || (final_heading && near_final);
    let twist = if use_lyapunov {
        let heading = node.heading.unwrap_or_else(|| {
            if next.target < last {
                let n2 = path[next.target + 1];
                (n2.y - node.y).atan2(n2.x - node.x)
            } else if next.target > 0 {
                let p = path[next.target - 1];
                (node.y - p.y).atan2(node.x - p.x)
            } else {
                (node.y - state.y).atan2(node.x - state.x)
            }
        });
        lyapunov_step_unchecked(state, Pose::new(node.x, node.y, heading), &params.lyapunov).twist
    } else {
        match params.controller {
            ControllerKind::PurePursuit => {
                scratch.clear();
                let first = next.target.saturating_sub(1);
                if next.target == 0 {
                    scratch.push(me);
                }
                scratch.extend(path[first..].iter().map(PathNode::point));
                let seg = if next.target == progress.target.min(last) {
                    progress.segment
                } else {
                    0
                };
                let c = pure_pursuit_unchecked(state, scratch, seg, &params.pure_pursuit);
                next.segment = c.segment;
                c.twist
            }
            ControllerKind::GoalSeeking => goal_seeking_step(state, node.point(), dt, &params.steering)
                .map(|c| c.twist)
                .unwrap_or(Twist::ZERO),
            _ => shortest_path_step(state, node.point(), dt, &params.steering)
                .map(|c| c.twist)
                .unwrap_or(Twist::ZERO),
        }
    };
    if next.target != progress.target.min(last) && params.controller != ControllerKind::PurePursuit {
        next.segment = 0;
    }
    PathFollowStep {
        twist,
        next,
        reached: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_dropped_inside_switching_distance() {
        let path = [PathNode::at(0.1, 0.0), PathNode::at(2.0, 0.0)];
        let s = path_follow_step(
            Pose::default(),
            &path,
            PathFollowState::default(),
            0.1,
            &PathFollowParams::default(),
        )
        .unwrap();
        assert_eq!(s.next.target, 1);
        assert!(!s.reached);
    }

    #[test]
    fn last_node_needs_its_heading() {
        let path = [PathNode {
            x: 0.0,
            y: 0.0,
            heading: Some(1.0),
        }];
        let p = PathFollowParams::default();
        let s = path_follow_step(Pose::default(), &path, PathFollowState::default(), 0.1, &p).unwrap();
        assert!(!s.reached);
        assert!(s.twist.omega > 0.0);
        let s = path_follow_step(
            Pose::new(0.0, 0.0, 1.0),
            &path,
            PathFollowState::default(),
            0.1,
            &p,
        )
        .unwrap();
        assert!(s.reached);
    }

    #[test]
    fn bad_paths_are_rejected() {
        let p = PathFollowParams::default();
        assert_eq!(
            path_follow_step(Pose::default(), &[], PathFollowState::default(), 0.1, &p),
            Err(MobileError::EmptyPath)
        );
        let nan = [PathNode {
            x: 0.0,
            y: 0.0,
            heading: Some(f64::NAN),
        }];
        assert!(path_follow_step(Pose::default(), &nan, PathFollowState::default(), 0.1, &p).is_err());
    }
}
