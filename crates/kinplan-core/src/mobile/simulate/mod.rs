//! Closed-loop simulation: path following and vector-distance navigation at a fixed step, with
//! collision detection, to an outcome (REACHED, NO_PATH, TIMEOUT, COLLISION, CANCELLED).

use serde::{Deserialize, Serialize};

use super::chassis::Chassis;
use super::error::{MobileError, check_positive};
use super::field::{MobileField, SimField};
use super::pose::{Point2, Pose, Twist, integrate_twist};
use super::vector_distance::{NavMode, NoPathReason};
use super::world::World;

mod astar;
mod follow;
mod navigate;

pub use astar::{GRID_PATH_CONTROLLER, navigate_astar};
pub use follow::follow_path;
pub use navigate::{NavigateParams, navigate};

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
    /// The deadline passed or the caller's cancellation was raised.
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

/// What one simulated control period did.
struct Period {
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
fn advance(world: Option<&World>, chassis: &Chassis, pose: Pose, cmd: Twist, sim: &SimParams) -> Period {
    let (applied, _) = chassis.saturate(cmd);
    let speed = applied.vx.hypot(applied.vy);
    let subs = ((speed * sim.dt / (0.25 * sim.robot_radius)).ceil() as usize).clamp(1, 1000);
    let h = sim.dt / subs as f64;
    let mut outcome = Period {
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
