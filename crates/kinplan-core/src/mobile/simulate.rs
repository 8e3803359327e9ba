//! Closed-loop simulation: path following and vector-distance navigation at a fixed step, with
//! collision detection, to an outcome (REACHED, NO_PATH, TIMEOUT, COLLISION, CANCELLED).

use serde::{Deserialize, Serialize};

use super::chassis::Chassis;
use super::error::{MobileError, check_positive};
use super::field::{MobileField, SimField};
use super::grid_astar::{GridAstarParams, plan_grid_astar_until};
use super::path_follow::{PathFollowParams, PathFollowState, PathNode, path_follow_unchecked, validate_path};
use super::pose::{Point2, Pose, Twist, integrate_twist};
use super::sensors::{RangeSensorParams, RangeSensors};
use super::vector_distance::{NavMode, NoPathReason, VdfEvent, VdfParams, VdfState, vdf_step_mut};
use super::world::World;

/// How a run ended.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Outcome {
    /// Goal (and heading, if asked) reached.
    Reached,
    /// The navigator decided there is no path.
    NoPath,
    /// `max_time` elapsed.
    #[default]
    Timeout,
    /// The robot's disc touched an obstacle; the last state is the first colliding one.
    Collision,
    /// `should_stop` returned true.
    Cancelled,
}

impl Outcome {
    /// "REACHED", "NO_PATH", "TIMEOUT", "COLLISION", "CANCELLED".
    pub fn as_str(&self) -> &'static str {
        match self {
            Outcome::Reached => "REACHED",
            Outcome::NoPath => "NO_PATH",
            Outcome::Timeout => "TIMEOUT",
            Outcome::Collision => "COLLISION",
            Outcome::Cancelled => "CANCELLED",
        }
    }
}

/// Run metrics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunMetrics {
    /// Length of the driven path, m.
    pub path_length: f64,
    /// Simulated time, s.
    pub time: f64,
    /// Smallest clearance between the robot's disc and any obstacle, m (`None` without
    /// obstacles).
    pub min_clearance: Option<f64>,
    /// Control steps taken.
    pub steps: usize,
}

/// A simulated run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SimRun {
    /// How it ended.
    pub outcome: Outcome,
    /// Poses, the start first (x, y, θ).
    pub states: Vec<Pose>,
    /// Applied (saturated) commands, one per step.
    pub commands: Vec<Twist>,
    /// Navigator mode per step (empty for path following).
    pub modes: Vec<NavMode>,
    /// Hit points H.
    pub hit_points: Vec<Point2>,
    /// Leave points L.
    pub leave_points: Vec<Point2>,
    /// Why the navigator reported NO_PATH.
    pub no_path_reason: Option<NoPathReason>,
    /// Index of the obstacle hit, on COLLISION.
    pub collided_with: Option<usize>,
    /// Metrics.
    pub metrics: RunMetrics,
}

/// Simulation settings shared by both runners.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimParams {
    /// Robot disc radius, m (default 0.22, the BARN Jackal's inscribed radius).
    pub robot_radius: f64,
    /// Control period, s (default 0.05).
    pub dt: f64,
    /// Time limit, s (default 100, as in BARN).
    pub max_time: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            robot_radius: 0.22,
            dt: 0.05,
            max_time: 100.0,
        }
    }
}

impl SimParams {
    /// Positive radius, dt and time; dt ≤ max_time; at most 10⁷ steps.
    pub fn validate(&self) -> Result<(), MobileError> {
        check_positive(MobileField::Sim(SimField::RobotRadius), self.robot_radius)?;
        check_positive(MobileField::Sim(SimField::Dt), self.dt)?;
        check_positive(MobileField::Sim(SimField::MaxTime), self.max_time)?;
        super::error::check_range(MobileField::Sim(SimField::Dt), self.dt, 0.0, self.max_time)?;
        super::error::check_range(
            MobileField::Sim(SimField::Steps),
            self.max_time / self.dt,
            0.0,
            MAX_STEPS,
        )
    }
}

/// Largest number of simulation steps accepted.
const MAX_STEPS: f64 = 1e7;

/// Settings of [`navigate`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NavigateParams {
    /// Step, radius, time limit.
    pub sim: SimParams,
    /// Sensor ring.
    pub sensors: RangeSensorParams,
    /// Navigator.
    pub vdf: VdfParams,
    /// Seed of the sensor noise.
    pub seed: u64,
}

/// What one simulated control period did.
struct PeriodOutcome {
    /// Pose at the end of the period (or where a collision stopped it).
    pose: Pose,
    /// The command after the chassis' saturation.
    applied: Twist,
    /// Smallest clearance seen over the sub-steps (m); `None` without a world.
    min_clearance: Option<f64>,
    /// Index of the obstacle hit, if the robot collided.
    hit: Option<usize>,
}

/// Integrates one control period with sub-steps no longer than a quarter of the robot radius,
/// checking the clearance after each and stopping at the first collision.
fn advance(
    world: Option<&World>,
    chassis: &Chassis,
    pose: Pose,
    cmd: Twist,
    sim: &SimParams,
) -> PeriodOutcome {
    let (applied, _) = chassis.saturate(cmd);
    let speed = applied.vx.hypot(applied.vy);
    let subs = ((speed * sim.dt / (0.25 * sim.robot_radius)).ceil() as usize).clamp(1, 1000);
    let h = sim.dt / subs as f64;
    let mut outcome = PeriodOutcome {
        pose,
        applied,
        min_clearance: None,
        hit: None,
    };
    for _ in 0..subs {
        outcome.pose = integrate_twist(outcome.pose, applied, h);
        if let Some(w) = world {
            let (d, i) = w.distance(outcome.pose.point());
            let c = d - sim.robot_radius;
            outcome.min_clearance = Some(outcome.min_clearance.map_or(c, |m| m.min(c)));
            if c < 0.0 {
                outcome.hit = i;
                return outcome;
            }
        }
    }
    outcome
}

fn start_check(world: Option<&World>, start: Pose, radius: f64) -> Result<Option<f64>, MobileError> {
    let Some(w) = world else { return Ok(None) };
    let (d, i) = w.distance(start.point());
    let c = d - radius;
    if c < 0.0 {
        return Err(MobileError::StartInCollision {
            obstacle: i.unwrap_or(0),
            clearance: c,
        });
    }
    Ok(i.map(|_| c))
}

fn merge(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Simulates [`path_follow_step`](super::path_follow_step) on `chassis` from `start` along
/// `path` (optionally among obstacles, with collision detection) until the last node is
/// reached, the time runs out, a collision happens or `should_stop()` returns true (checked
/// every step).
///
/// ```
/// use kinplan_core::mobile::{follow_path, Chassis, Outcome, PathFollowParams, PathNode, Pose, SimParams};
/// let path = [PathNode { x: 1.0, y: 1.0, heading: Some(0.0) }];
/// let sim = SimParams { dt: 0.02, max_time: 120.0, ..SimParams::default() };
/// let run = follow_path(&Chassis::omr_iii(), Pose::default(), &path, None, &PathFollowParams::default(), &sim, &|| false).unwrap();
/// assert_eq!(run.outcome, Outcome::Reached);
/// ```
pub fn follow_path(
    chassis: &Chassis,
    start: Pose,
    path: &[PathNode],
    world: Option<&World>,
    follow: &PathFollowParams,
    sim: &SimParams,
    should_stop: &dyn Fn() -> bool,
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
        if should_stop() {
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

/// Applies one step; records it; returns true on collision.
fn step_into(
    run: &mut SimRun,
    world: Option<&World>,
    chassis: &Chassis,
    pose: &mut Pose,
    cmd: Twist,
    sim: &SimParams,
) -> bool {
    let period = advance(world, chassis, *pose, cmd, sim);
    run.metrics.path_length += period.pose.point().distance(pose.point());
    run.metrics.time += sim.dt;
    run.metrics.steps += 1;
    run.metrics.min_clearance = merge(run.metrics.min_clearance, period.min_clearance);
    run.commands.push(period.applied);
    run.states.push(period.pose);
    *pose = period.pose;
    if period.hit.is_some() {
        run.outcome = Outcome::Collision;
        run.collided_with = period.hit;
        return true;
    }
    false
}

/// Simulates the vector-distance navigator ([`vdf_step`](super::vdf_step)) with the range
/// sensors of `params.sensors` (noise seeded by `params.seed`, so a run is deterministic)
/// from `start` to `goal` among `world`'s obstacles.
///
/// ```
/// use kinplan_core::mobile::{navigate, Chassis, NavigateParams, Obstacle, Outcome, Point2, Pose, World};
/// let world = World::new(vec![Obstacle::circle(2.0, 0.0, 0.5)]).unwrap();
/// let run = navigate(&Chassis::default(), Pose::new(0.0, 0.0, 0.0), Point2::new(4.0, 0.0), &world,
///                    &NavigateParams::default(), &|| false).unwrap();
/// assert_eq!(run.outcome, Outcome::Reached);
/// ```
pub fn navigate(
    chassis: &Chassis,
    start: Pose,
    goal: Point2,
    world: &World,
    params: &NavigateParams,
    should_stop: &dyn Fn() -> bool,
) -> Result<SimRun, MobileError> {
    chassis.validate()?;
    start.validate(MobileField::Start)?;
    goal.validate(MobileField::Goal)?;
    params.sim.validate()?;
    params.vdf.validate()?;
    let sim = &params.sim;
    let mut sensors = RangeSensors::new(params.sensors, params.seed)?;
    let mut run = SimRun::default();
    run.metrics.min_clearance = start_check(Some(world), start, sim.robot_radius)?;
    let steps = (sim.max_time / sim.dt).ceil() as usize;
    let mut readings = vec![0.0; params.sensors.count];
    let mut state = VdfState::default();
    let mut pose = start;
    run.states.push(pose);
    for k in 0..=steps {
        if should_stop() {
            run.outcome = Outcome::Cancelled;
            break;
        }
        if !sensors.sense_until(world, pose, sim.robot_radius, &mut readings, should_stop) {
            run.outcome = Outcome::Cancelled;
            break;
        }
        let out = vdf_step_mut(&mut state, pose, goal, &readings, &params.vdf);
        match out.event {
            Some(VdfEvent::Reached) => {
                run.outcome = Outcome::Reached;
                break;
            }
            Some(VdfEvent::NoPath(reason)) => {
                run.outcome = Outcome::NoPath;
                run.no_path_reason = Some(reason);
                break;
            }
            Some(VdfEvent::Hit(h)) => run.hit_points.push(h),
            Some(VdfEvent::Leave(l)) => run.leave_points.push(l),
            None => {}
        }
        if k == steps {
            run.outcome = Outcome::Timeout;
            break;
        }
        run.modes.push(out.mode);
        if step_into(&mut run, Some(world), chassis, &mut pose, out.twist, sim) {
            break;
        }
    }
    Ok(run)
}

/// Global navigation: plans with [`plan_grid_astar`] on the known world, then follows the
/// path with [`follow_path`] (the controller in `follow`, typically pure pursuit). No grid
/// path gives a run with outcome NO_PATH and only the start state.
#[allow(clippy::too_many_arguments)]
pub fn navigate_astar(
    chassis: &Chassis,
    start: Pose,
    goal: Point2,
    world: &World,
    astar: &GridAstarParams,
    follow: &PathFollowParams,
    sim: &SimParams,
    should_stop: &dyn Fn() -> bool,
) -> Result<SimRun, MobileError> {
    start.validate(MobileField::Start)?;
    sim.validate()?;
    start_check(Some(world), start, sim.robot_radius)?;
    let Some(points) = plan_grid_astar_until(world, start.point(), goal, astar, should_stop)? else {
        return Ok(SimRun {
            outcome: if should_stop() {
                Outcome::Cancelled
            } else {
                Outcome::NoPath
            },
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
    follow_path(chassis, start, &path, Some(world), follow, sim, should_stop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::path_follow::ControllerKind;
    use crate::mobile::world::Obstacle;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    /// Random convex obstacles (circles and axis-aligned squares) between start and goal, kept
    /// 0.6 m apart from each other and 1 m away from start and goal.
    fn convex_world(seed: u64) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut obs: Vec<(Point2, f64, bool)> = Vec::new();
        let (s, g) = (Point2::new(0.0, 0.0), Point2::new(10.0, 0.0));
        for _ in 0..200 {
            if obs.len() >= 7 {
                break;
            }
            let c = Point2::new(rng.random_range(1.5..8.5), rng.random_range(-2.5..2.5));
            let r = rng.random_range(0.2..0.7);
            let square = rng.random_bool(0.4);
            if c.distance(s) < r + 1.0 || c.distance(g) < r + 1.0 {
                continue;
            }
            if obs.iter().any(|(o, ro, _)| o.distance(c) < r + ro + 0.9) {
                continue;
            }
            obs.push((c, r, square));
        }
        World::new(
            obs.into_iter()
                .map(|(c, r, sq)| {
                    if sq {
                        let h = r / 2f64.sqrt();
                        Obstacle::polygon(&[
                            (c.x - h, c.y - h),
                            (c.x + h, c.y - h),
                            (c.x + h, c.y + h),
                            (c.x - h, c.y + h),
                        ])
                    } else {
                        Obstacle::circle(c.x, c.y, r)
                    }
                })
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn navigator_reaches_the_goal_among_convex_obstacles() {
        let params = NavigateParams {
            sim: SimParams {
                robot_radius: 0.2,
                dt: 0.05,
                max_time: 120.0,
            },
            ..NavigateParams::default()
        };
        let mut failures = Vec::new();
        for seed in 0..20 {
            let w = convex_world(seed);
            let run = navigate(
                &Chassis::default(),
                Pose::new(0.0, 0.0, 0.0),
                Point2::new(10.0, 0.0),
                &w,
                &params,
                &|| false,
            )
            .unwrap();
            if run.outcome != Outcome::Reached {
                failures.push((seed, run.outcome));
            }
            assert!(run.metrics.min_clearance.unwrap() >= 0.0 || run.outcome == Outcome::Collision);
        }
        assert!(failures.is_empty(), "{failures:?}");
    }

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
                &|| false,
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
    fn walled_in_goal_is_no_path() {
        // Goal at (6, 0) inside a closed ring of 28 touching cylinders of radius 0.15 on a
        // circle of radius 1.3 around it.
        let mut obs = Vec::new();
        for i in 0..28 {
            let a = 2.0 * PI * i as f64 / 28.0;
            obs.push(Obstacle::circle(6.0 + 1.3 * a.cos(), 1.3 * a.sin(), 0.16));
        }
        let w = World::new(obs).unwrap();
        let p = NavigateParams {
            sim: SimParams {
                max_time: 300.0,
                ..SimParams::default()
            },
            ..NavigateParams::default()
        };
        let run = navigate(
            &Chassis::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(6.0, 0.0),
            &w,
            &p,
            &|| false,
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::NoPath, "{:?}", run.metrics);
        assert!(!run.hit_points.is_empty());
        // Going round the other way once does not change the verdict; it takes longer.
        let retry = NavigateParams {
            vdf: VdfParams {
                retry_other_side: true,
                ..VdfParams::default()
            },
            ..p
        };
        let again = navigate(
            &Chassis::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(6.0, 0.0),
            &w,
            &retry,
            &|| false,
        )
        .unwrap();
        assert_eq!(again.outcome, Outcome::NoPath, "{:?}", again.metrics);
        assert!(again.metrics.steps > run.metrics.steps);
    }

    #[test]
    fn runs_are_deterministic_with_noise_and_cancellable() {
        let w = convex_world(3);
        let p = NavigateParams {
            sensors: RangeSensorParams {
                noise_sigma: 0.02,
                ..RangeSensorParams::default()
            },
            seed: 11,
            ..NavigateParams::default()
        };
        let a = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            &|| false,
        )
        .unwrap();
        let b = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            &|| false,
        )
        .unwrap();
        assert_eq!(a, b);
        let c = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            &|| true,
        )
        .unwrap();
        assert_eq!(c.outcome, Outcome::Cancelled);
        assert_eq!(c.states.len(), 1);
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
                &|| false,
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
                &|| false,
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
            &|| false,
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::Collision);
        assert_eq!(run.collided_with, Some(0));
        let last = run.states.last().unwrap();
        // Contact happens when x + 0.22 ≥ 1.0; sub-steps are ≤ 0.055 m long.
        assert!(last.x >= 0.78 - 1e-9 && last.x < 0.78 + 0.06, "{last:?}");
    }

    #[test]
    fn bad_inputs_are_rejected() {
        let w = World::new(vec![Obstacle::circle(0.0, 0.0, 0.5)]).unwrap();
        let p = NavigateParams::default();
        let c = Chassis::default();
        assert!(matches!(
            navigate(&c, Pose::default(), Point2::new(1.0, 0.0), &w, &p, &|| { false }),
            Err(MobileError::StartInCollision { obstacle: 0, .. })
        ));
        let bad_dt = NavigateParams {
            sim: SimParams {
                dt: -0.1,
                ..SimParams::default()
            },
            ..p
        };
        let too_long = SimParams {
            dt: 1e-6,
            max_time: 1e3,
            ..SimParams::default()
        };
        assert!(matches!(too_long.validate(), Err(MobileError::OutOfRange { .. })));
        assert!(
            navigate(
                &c,
                Pose::new(3.0, 0.0, 0.0),
                Point2::new(1.0, 0.0),
                &w,
                &bad_dt,
                &|| false
            )
            .is_err()
        );
        assert!(
            navigate(
                &c,
                Pose::new(f64::NAN, 0.0, 0.0),
                Point2::new(1.0, 0.0),
                &w,
                &p,
                &|| false
            )
            .is_err()
        );
        assert_eq!(
            follow_path(
                &c,
                Pose::default(),
                &[],
                None,
                &PathFollowParams::default(),
                &SimParams::default(),
                &|| false
            ),
            Err(MobileError::EmptyPath)
        );
    }
}
