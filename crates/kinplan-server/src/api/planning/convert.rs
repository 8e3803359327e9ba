//! `PlanRequest` options → the plan room's parameters (unset fields take the
//! domain's `Default`), and the plan room's results and errors → proto.

use std::time::Duration;

use tonic::Status;

use crate::api::convert::{finite, optional_seconds, pose_in};
use crate::pb;
use crate::status::invalid;
use kinplan_core::collision::{CheckerParams, Part, StateReport};
use kinplan_core::plan::{
    Algorithm, Goal, InitialTrajectory, PlanRequest, PlanResult, PlanStatus, TimedTrajectory, TimingMethod,
    TimingParams,
};
use kinplan_core::robot::Chain;
use kinplan_core::score::Scores;

/// Largest RRT-Connect sample budget (each sample may add a tree node).
pub const MAX_RRT_SAMPLES: usize = 1_000_000;
/// Largest timesteps × max_rollouts × joints of a STOMP request (8 bytes each).
pub const MAX_STOMP_VALUES: usize = 4_000_000;

/// A planning request in domain terms plus the service-side options.
pub struct PlanInput {
    pub request: PlanRequest,
    pub checker: CheckerParams,
    pub time_budget: Option<Duration>,
    pub return_cost_history: bool,
}

/// An optional count (ranges are the domain's to check).
fn count(v: Option<u32>, default: usize) -> usize {
    v.map_or(default, |v| v as usize)
}

fn number(field: &str, v: Option<f64>, default: f64) -> Result<f64, Status> {
    v.map_or(Ok(default), |v| finite(field, v))
}

/// Converts and checks what only the service knows (oneofs, enums, the time
/// budget, the motion resolution); ranges of the planners' parameters are
/// checked by the domain's `validate`, mapped by [`plan_error`](crate::status::plan::plan_error).
pub fn plan_input(req: &pb::PlanRequest) -> Result<PlanInput, Status> {
    let mut request = PlanRequest {
        start: req.start.clone(),
        seed: req.seed,
        ..PlanRequest::default()
    };
    request.goal = match &req.goal {
        Some(pb::plan_request::Goal::GoalJoints(j)) => Goal::Joints(j.positions.clone()),
        Some(pb::plan_request::Goal::GoalPose(p)) => Goal::Pose(pose_in("goal_pose", Some(p))?),
        None => return Err(invalid("goal", "one of goal_joints or goal_pose is required")),
    };
    request.algorithm = match pb::PlanAlgorithm::try_from(req.algorithm) {
        Ok(pb::PlanAlgorithm::Unspecified | pb::PlanAlgorithm::RrtConnect) => Algorithm::RrtConnect,
        Ok(pb::PlanAlgorithm::Stomp) => Algorithm::Stomp,
        Ok(pb::PlanAlgorithm::Ccstomp) => Algorithm::Ccstomp,
        Err(_) => return Err(invalid("algorithm", format!("unknown value {}", req.algorithm))),
    };
    let options = req.options.clone().unwrap_or_default();
    let stomp = options.stomp.unwrap_or_default();
    let s = &mut request.stomp;
    s.timesteps = count(stomp.timesteps, s.timesteps);
    s.rollouts = count(stomp.rollouts, s.rollouts);
    s.max_rollouts = count(stomp.max_rollouts, s.max_rollouts);
    s.max_iterations = count(stomp.max_iterations, s.max_iterations);
    s.iterations_after_valid = count(stomp.iterations_after_valid, s.iterations_after_valid);
    if !stomp.noise_stddev.is_empty() {
        s.noise_stddev = stomp.noise_stddev.clone();
    }
    s.cost_sensitivity = number(
        "options.stomp.cost_sensitivity",
        stomp.cost_sensitivity,
        s.cost_sensitivity,
    )?;
    s.control_cost_weight = number(
        "options.stomp.control_cost_weight",
        stomp.control_cost_weight,
        s.control_cost_weight,
    )?;
    s.collision_penalty = number(
        "options.stomp.collision_penalty",
        stomp.collision_penalty,
        s.collision_penalty,
    )?;
    s.kernel_half_width = count(stomp.kernel_half_width, s.kernel_half_width);
    s.clearance_distance = number(
        "options.stomp.clearance_distance",
        stomp.clearance_distance,
        s.clearance_distance,
    )?;
    s.clearance_weight = number(
        "options.stomp.clearance_weight",
        stomp.clearance_weight,
        s.clearance_weight,
    )?;
    s.joint_limit_weight = number(
        "options.stomp.joint_limit_weight",
        stomp.joint_limit_weight,
        s.joint_limit_weight,
    )?;
    s.initial = match pb::InitialTrajectory::try_from(stomp.initial_trajectory) {
        Ok(pb::InitialTrajectory::Unspecified) => InitialTrajectory::ForAlgorithm,
        Ok(pb::InitialTrajectory::StraightLine) => InitialTrajectory::StraightLine,
        Ok(pb::InitialTrajectory::RrtConnectIfBlocked) => InitialTrajectory::RrtConnectIfBlocked,
        Ok(pb::InitialTrajectory::CartesianLine) => InitialTrajectory::CartesianLine,
        Err(_) => {
            return Err(invalid(
                "options.stomp.initial_trajectory",
                format!("unknown value {}", stomp.initial_trajectory),
            ));
        }
    };
    if stomp.straight_line_start {
        s.initial = InitialTrajectory::StraightLine;
    }

    let cart = options.cartesian.unwrap_or_default();
    let c = &mut request.cartesian;
    c.translation_tolerance = number(
        "options.cartesian.translation_tolerance",
        cart.translation_tolerance,
        c.translation_tolerance,
    )?;
    c.rotation_tolerance = number(
        "options.cartesian.rotation_tolerance",
        cart.rotation_tolerance,
        c.rotation_tolerance,
    )?;
    c.translation_weight = number(
        "options.cartesian.translation_weight",
        cart.translation_weight,
        c.translation_weight,
    )?;
    c.rotation_weight = number(
        "options.cartesian.rotation_weight",
        cart.rotation_weight,
        c.rotation_weight,
    )?;
    c.translation_stddev = number(
        "options.cartesian.translation_stddev",
        cart.translation_stddev,
        c.translation_stddev,
    )?;
    c.rotation_stddev = number(
        "options.cartesian.rotation_stddev",
        cart.rotation_stddev,
        c.rotation_stddev,
    )?;
    c.ik_iterations = count(cart.ik_iterations, c.ik_iterations);
    c.violation_penalty = number(
        "options.cartesian.violation_penalty",
        cart.violation_penalty,
        c.violation_penalty,
    )?;

    let rrt = options.rrt_connect.unwrap_or_default();
    let r = &mut request.rrt;
    r.range = number("options.rrt_connect.range", rrt.range, r.range)?;
    r.max_samples = count(rrt.max_samples, r.max_samples);
    r.shortcut_attempts = count(rrt.shortcut_attempts, r.shortcut_attempts);

    request.timing = timing_in("options.timing", &options.timing.unwrap_or_default())?;

    // Memory bounds a small request could otherwise break (time is bounded by
    // the deadline): RRT trees grow a node per sample, STOMP keeps
    // max_rollouts noisy trajectories.
    if r.max_samples > MAX_RRT_SAMPLES {
        return Err(invalid(
            "options.rrt_connect.max_samples",
            format!("{} exceeds the limit of {MAX_RRT_SAMPLES}", r.max_samples),
        ));
    }
    let stomp_values = s
        .timesteps
        .saturating_mul(s.max_rollouts.max(1))
        .saturating_mul(req.start.len().max(1));
    if stomp_values > MAX_STOMP_VALUES {
        return Err(invalid(
            "options.stomp",
            format!(
                "timesteps x max_rollouts x joints = {stomp_values} exceeds the limit of {MAX_STOMP_VALUES}"
            ),
        ));
    }

    let mut checker = CheckerParams::default();
    if let Some(res) = options.motion_resolution {
        let max = CheckerParams::MAX_MOTION_RESOLUTION;
        if !(res.is_finite() && res > 0.0 && res <= max) {
            return Err(invalid(
                "options.motion_resolution",
                format!("must be in (0, {max}] rad, got {res}"),
            ));
        }
        checker.motion_resolution = res;
    }
    checker.padded_motion = options.padded_motion;
    let time_budget = optional_seconds("options.time_budget", options.time_budget)?;
    Ok(PlanInput {
        request,
        checker,
        time_budget,
        return_cost_history: options.return_cost_history,
    })
}

/// `TimingOptions` → [`TimingParams`] (unset fields: the domain's
/// defaults); `prefix` is where the message sits in the request. Ranges are
/// the domain's `validate` to check.
pub fn timing_in(prefix: &str, timing: &pb::TimingOptions) -> Result<TimingParams, Status> {
    let mut t = TimingParams::default();
    if !timing.max_velocity.is_empty() {
        t.velocity_limits = Some(timing.max_velocity.clone());
    }
    if !timing.max_acceleration.is_empty() {
        t.acceleration_limits = Some(timing.max_acceleration.clone());
    }
    if !timing.max_jerk.is_empty() {
        t.jerk_limits = Some(timing.max_jerk.clone());
    }
    if !timing.start_velocity.is_empty() {
        t.start_velocity = Some(timing.start_velocity.clone());
    }
    let field = |name: &str| format!("{prefix}.{name}");
    t.default_velocity = number(
        &field("default_velocity"),
        timing.default_velocity,
        t.default_velocity,
    )?;
    t.velocity_scale = number(&field("velocity_scale"), timing.velocity_scale, t.velocity_scale)?;
    t.path_tolerance = number(&field("path_tolerance"), timing.path_tolerance, t.path_tolerance)?;
    t.sample_period = number(&field("sample_period"), timing.sample_period, t.sample_period)?;
    t.grid_step = number(&field("grid_step"), timing.grid_step, t.grid_step)?;
    t.method = match pb::TimingMethod::try_from(timing.method) {
        Ok(pb::TimingMethod::Unspecified | pb::TimingMethod::Waypoint) => TimingMethod::Waypoint,
        Ok(pb::TimingMethod::TimeOptimal) => TimingMethod::TimeOptimal,
        Ok(pb::TimingMethod::JerkLimited) => TimingMethod::JerkLimited,
        Err(_) => {
            return Err(invalid(
                field("method"),
                format!("unknown value {}", timing.method),
            ));
        }
    };
    Ok(t)
}

fn status_out(s: PlanStatus) -> pb::PlanStatus {
    match s {
        PlanStatus::Succeeded => pb::PlanStatus::Succeeded,
        PlanStatus::NoValidTrajectory => pb::PlanStatus::NoValidTrajectory,
        PlanStatus::InvalidStart => pb::PlanStatus::InvalidStart,
        PlanStatus::InvalidGoal => pb::PlanStatus::InvalidGoal,
        PlanStatus::GoalUnreachable => pb::PlanStatus::GoalUnreachable,
        PlanStatus::Timeout => pb::PlanStatus::Timeout,
        PlanStatus::Cancelled => pb::PlanStatus::Cancelled,
    }
}

fn status_message(s: PlanStatus, report: Option<&StateReport>) -> String {
    let detail = report.map(|r| format!(": {r}")).unwrap_or_default();
    match s {
        PlanStatus::Succeeded => "a valid trajectory".into(),
        PlanStatus::NoValidTrajectory => "no valid trajectory within the iteration or sample cap".into(),
        PlanStatus::InvalidStart => format!("the start state is invalid{detail}"),
        PlanStatus::InvalidGoal => format!("the goal state is invalid{detail}"),
        PlanStatus::GoalUnreachable => "no IK solution reaches the goal pose within the joint limits".into(),
        PlanStatus::Timeout => "the time budget ran out (best trajectory so far returned)".into(),
        PlanStatus::Cancelled => "cancelled".into(),
    }
}

/// Colliding pairs and limit violations as "link:object" / "link:link" /
/// "joint i" strings.
pub fn colliding_out(report: &StateReport) -> Vec<String> {
    let mut out: Vec<String> = report
        .collisions
        .iter()
        .map(|(link, other)| pair_name(link, other))
        .collect();
    out.extend(report.out_of_limits.iter().map(|(i, ..)| format!("joint {i}")));
    out
}

/// "link:object" or "link:link".
pub fn pair_name(link: &str, other: &Part) -> String {
    match other {
        Part::Link(l) => format!("{link}:{l}"),
        Part::Obstacle { name, .. } => format!("{link}:{name}"),
    }
}

/// Row-major `n × dof` joints (and times, when given) as a trajectory.
pub fn trajectory_out(chain: &Chain, q: &[f64], dof: usize, times: &[f64]) -> pb::JointTrajectory {
    pb::JointTrajectory {
        joint_names: chain.joints().iter().map(|j| j.name.clone()).collect(),
        points: q
            .chunks_exact(dof.max(1))
            .enumerate()
            .map(|(i, row)| pb::JointPoint {
                positions: row.to_vec(),
                time_from_start: times.get(i).copied().unwrap_or(0.0),
                ..Default::default()
            })
            .collect(),
    }
}

/// A timed trajectory with velocities and accelerations at every point.
pub fn timed_out(chain: &Chain, tr: &TimedTrajectory) -> pb::JointTrajectory {
    let dof = tr.dof.max(1);
    pb::JointTrajectory {
        joint_names: chain.joints().iter().map(|j| j.name.clone()).collect(),
        points: (0..tr.len())
            .map(|i| {
                let r = i * dof..(i + 1) * dof;
                pb::JointPoint {
                    positions: tr.q[r.clone()].to_vec(),
                    time_from_start: tr.t[i],
                    velocities: tr.qd[r.clone()].to_vec(),
                    accelerations: tr.qdd[r].to_vec(),
                }
            })
            .collect(),
    }
}

/// The criteria map of a response: the S0 criteria by name and the
/// time-scaled jerk as "JJ_time", "CJ_time", "JMJ_time", "CMJ_time".
pub fn criteria_out(s: &Scores) -> std::collections::HashMap<String, f64> {
    let mut out: std::collections::HashMap<String, f64> =
        s.iter().map(|(c, v)| (c.name().to_owned(), v)).collect();
    if let Some(t) = s.time_scaled {
        out.insert("JJ_time".into(), t.jj);
        out.insert("CJ_time".into(), t.cj);
        out.insert("JMJ_time".into(), t.jmj);
        out.insert("CMJ_time".into(), t.cmj);
    }
    out
}

/// The reply for a finished plan; `report` explains an invalid start or goal.
pub fn plan_response(
    chain: &Chain,
    r: PlanResult,
    report: Option<StateReport>,
    with_history: bool,
    total: Duration,
) -> pb::PlanResponse {
    let us = |v: u64| v as f64 * 1e-6;
    pb::PlanResponse {
        status: status_out(r.status) as i32,
        message: status_message(r.status, report.as_ref()),
        colliding: report.as_ref().map(colliding_out).unwrap_or_default(),
        trajectory: Some(timed_out(chain, &r.trajectory)),
        valid: r.valid,
        cost_history: if with_history { r.cost_history } else { Vec::new() },
        deviation: Some(pb::CartesianDeviation {
            translation: r.deviation.iter().map(|d| d.translation).collect(),
            rotation: r.deviation.iter().map(|d| d.rotation).collect(),
            violates_tolerance: r.violates_tolerance,
        }),
        criteria: r.criteria.as_ref().map(criteria_out).unwrap_or_default(),
        iterations: r.iterations.min(u32::MAX as usize) as u32,
        duration: r.trajectory.duration(),
        goal: r.goal.unwrap_or_default(),
        timings: Some(pb::PlanTimings {
            goal_ik: us(r.timings.goal_ik_us),
            rrt_connect: us(r.timings.rrt_us),
            stomp: us(r.timings.stomp_us),
            verify: us(r.timings.verify_us),
            total: total.as_secs_f64(),
        }),
    }
}
