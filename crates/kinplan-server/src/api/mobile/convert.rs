//! Proto messages into domain values and back for `MobileService`: unset fields take the
//! domain's defaults, sizes are bounded by the server's limits (below), and parameter sets
//! are validated as they are built.

use tonic::Status;

use crate::pb;
use crate::status::invalid;
use crate::status::mobile::mobile_error;
use kinplan_core::mobile::{
    CarParams, Chassis, ControlStep, ControllerKind, DifferentialParams, GridAstarParams, NavMode,
    NoPathReason, Obstacle, OmniParams, Outcome, PathFollowParams, PathNode, Point2, Pose, RangeSensorParams,
    Saturation, SimParams, SimRun, StepReport, TricycleParams, TurnPreference, Twist, VdfEvent, VdfParams,
    WheelState, World,
};

/// Largest simulation accepted: `sim.max_time / sim.dt` steps.
pub const MAX_STEPS: f64 = 100_000.0;
/// Largest world accepted, obstacles.
pub const MAX_OBSTACLES: usize = 10_000;
/// Largest polygon accepted, vertices.
pub const MAX_POLYGON_VERTICES: usize = 1_000;
/// Most polygon vertices in one world: bounds the cost of one ray cast or
/// distance query (the unit between cancellation checks).
pub const MAX_WORLD_VERTICES: usize = 100_000;
/// Longest path accepted, nodes.
pub const MAX_PATH_NODES: usize = 10_000;
/// Largest sensor ring accepted.
pub const MAX_SENSORS: u32 = 360;
/// Most rays per sensor beam accepted.
pub const MAX_RAYS_PER_BEAM: u32 = 100;
/// Most steering candidates a goal-seeking / shortest-path step evaluates (larger requests
/// are clamped to it).
pub const MAX_STEERING_CANDIDATES: u32 = 100_000;

pub(super) fn pose_in(p: Option<&pb::Pose2D>) -> Pose {
    p.map_or(Pose::default(), |p| Pose::new(p.x, p.y, p.theta))
}

pub(super) fn point_in(p: Option<&pb::Point2D>) -> Point2 {
    p.map_or(Point2::new(0.0, 0.0), |p| Point2::new(p.x, p.y))
}

pub(super) fn twist_in(t: &pb::Twist2D) -> Twist {
    Twist {
        vx: t.vx,
        vy: t.vy,
        omega: t.omega,
    }
}

pub(super) fn pose_out(p: &Pose) -> pb::Pose2D {
    pb::Pose2D {
        x: p.x,
        y: p.y,
        theta: p.theta,
    }
}

pub(super) fn point_out(p: Point2) -> pb::Point2D {
    pb::Point2D { x: p.x, y: p.y }
}

pub(super) fn twist_out(t: Twist) -> pb::Twist2D {
    pb::Twist2D {
        vx: t.vx,
        vy: t.vy,
        omega: t.omega,
    }
}

pub(super) fn saturation_out(s: Saturation) -> pb::Saturation {
    pb::Saturation {
        speed_scale: s.speed_scale,
        steering_clamped: s.steering_clamped,
        lateral_dropped: s.lateral_dropped,
    }
}

/// Unset chassis: differential drive; unset parameters: the kind's defaults (MOBIL-II for the
/// car, OMR-III for the omni base). Validation happens in the domain functions.
pub(super) fn chassis_in(c: Option<&pb::Chassis>) -> Chassis {
    use pb::chassis::Kind;
    match c.and_then(|c| c.kind.as_ref()) {
        None => Chassis::default(),
        Some(Kind::Tricycle(p)) => {
            let d = TricycleParams::default();
            Chassis::Tricycle(TricycleParams {
                wheelbase: p.wheelbase.unwrap_or(d.wheelbase),
                wheel_radius: p.wheel_radius.unwrap_or(d.wheel_radius),
                max_steer: p.max_steer.unwrap_or(d.max_steer),
                max_speed: p.max_speed.unwrap_or(d.max_speed),
            })
        }
        Some(Kind::Car(p)) => {
            let d = CarParams::default();
            Chassis::Car(CarParams {
                wheelbase: p.wheelbase.unwrap_or(d.wheelbase),
                track: p.track.unwrap_or(d.track),
                wheel_radius: p.wheel_radius.unwrap_or(d.wheel_radius),
                max_steer: p.max_steer.unwrap_or(d.max_steer),
                max_speed: p.max_speed.unwrap_or(d.max_speed),
            })
        }
        Some(Kind::Omni(p)) => {
            let d = OmniParams::default();
            Chassis::Omni(OmniParams {
                wheel_radius: p.wheel_radius.unwrap_or(d.wheel_radius),
                center_distance: p.center_distance.unwrap_or(d.center_distance),
                first_wheel_angle: p.first_wheel_angle.unwrap_or(d.first_wheel_angle),
                max_wheel_speed: p.max_wheel_speed.unwrap_or(d.max_wheel_speed),
            })
        }
        Some(Kind::Differential(p)) => {
            let d = DifferentialParams::default();
            Chassis::Differential(DifferentialParams {
                wheel_radius: p.wheel_radius.unwrap_or(d.wheel_radius),
                track: p.track.unwrap_or(d.track),
                max_wheel_speed: p.max_wheel_speed.unwrap_or(d.max_wheel_speed),
            })
        }
    }
}

pub(super) fn wheels_in(w: &pb::WheelState) -> Result<WheelState, Status> {
    use pb::wheel_state::Kind;
    Ok(match &w.kind {
        None => return Err(invalid("wheels", "give the wheel state of the chassis")),
        Some(Kind::Tricycle(t)) => WheelState::Tricycle {
            speed: t.speed,
            steer: t.steer,
        },
        Some(Kind::Car(c)) => WheelState::Car {
            rear_left: c.rear_left,
            rear_right: c.rear_right,
            steer_left: c.steer_left,
            steer_right: c.steer_right,
        },
        Some(Kind::Omni(o)) => {
            let speeds: [f64; 3] = o.speeds.as_slice().try_into().map_err(|_| {
                invalid(
                    "wheels.omni.speeds",
                    format!("needs exactly 3 wheel speeds, got {}", o.speeds.len()),
                )
            })?;
            WheelState::Omni { speeds }
        }
        Some(Kind::Differential(d)) => WheelState::Differential {
            left: d.left,
            right: d.right,
        },
    })
}

pub(super) fn wheels_out(w: &WheelState) -> pb::WheelState {
    use pb::wheel_state::Kind;
    let kind = match *w {
        WheelState::Tricycle { speed, steer } => Kind::Tricycle(pb::TricycleWheels { speed, steer }),
        WheelState::Car {
            rear_left,
            rear_right,
            steer_left,
            steer_right,
        } => Kind::Car(pb::CarWheels {
            rear_left,
            rear_right,
            steer_left,
            steer_right,
        }),
        WheelState::Omni { speeds } => Kind::Omni(pb::OmniWheels {
            speeds: speeds.to_vec(),
        }),
        WheelState::Differential { left, right } => {
            Kind::Differential(pb::DifferentialWheels { left, right })
        }
    };
    pb::WheelState { kind: Some(kind) }
}

pub(super) fn path_in(path: &[pb::PathNode]) -> Result<Vec<PathNode>, Status> {
    if path.len() > MAX_PATH_NODES {
        return Err(invalid(
            "path",
            format!("{} nodes, at most {MAX_PATH_NODES}", path.len()),
        ));
    }
    Ok(path
        .iter()
        .map(|n| PathNode {
            x: n.x,
            y: n.y,
            heading: n.heading,
        })
        .collect())
}

pub(super) fn world_in(obstacles: &[pb::Obstacle]) -> Result<World, Status> {
    use pb::obstacle::Shape;
    if obstacles.len() > MAX_OBSTACLES {
        return Err(invalid(
            "world",
            format!("{} obstacles, at most {MAX_OBSTACLES}", obstacles.len()),
        ));
    }
    let vertices: usize = obstacles
        .iter()
        .map(|o| match &o.shape {
            Some(Shape::Polygon(p)) => p.vertices.len(),
            _ => 1,
        })
        .sum();
    if vertices > MAX_WORLD_VERTICES {
        return Err(invalid(
            "world",
            format!("{vertices} polygon vertices in all, at most {MAX_WORLD_VERTICES}"),
        ));
    }
    let mut out = Vec::with_capacity(obstacles.len());
    for (i, o) in obstacles.iter().enumerate() {
        out.push(match &o.shape {
            None => return Err(invalid(format!("world[{i}]"), "give a circle or a polygon")),
            Some(Shape::Circle(c)) => {
                let centre = point_in(c.center.as_ref());
                Obstacle::circle(centre.x, centre.y, c.radius)
            }
            Some(Shape::Polygon(p)) => {
                if p.vertices.len() > MAX_POLYGON_VERTICES {
                    return Err(invalid(
                        format!("world[{i}].polygon.vertices"),
                        format!("{} vertices, at most {MAX_POLYGON_VERTICES}", p.vertices.len()),
                    ));
                }
                Obstacle::Polygon {
                    vertices: p.vertices.iter().map(|v| Point2::new(v.x, v.y)).collect(),
                }
            }
        });
    }
    World::new(out).map_err(mobile_error)
}

pub(super) fn sim_in(s: Option<&pb::SimOptions>) -> Result<SimParams, Status> {
    let d = SimParams::default();
    let sim = s.map_or(d, |s| SimParams {
        robot_radius: s.robot_radius.unwrap_or(d.robot_radius),
        dt: s.dt.unwrap_or(d.dt),
        max_time: s.max_time.unwrap_or(d.max_time),
    });
    sim.validate().map_err(mobile_error)?;
    let steps = sim.max_time / sim.dt;
    if steps > MAX_STEPS {
        return Err(invalid(
            "sim.max_time",
            format!("max_time / dt = {steps:.0} steps, at most {MAX_STEPS}"),
        ));
    }
    Ok(sim)
}

pub(super) fn sensors_in(s: Option<&pb::RangeSensorParams>) -> Result<RangeSensorParams, Status> {
    let d = RangeSensorParams::default();
    let Some(s) = s else { return Ok(d) };
    let count = s.count.unwrap_or(d.count as u32);
    if count > MAX_SENSORS {
        return Err(invalid(
            "sensors.count",
            format!("{count}, at most {MAX_SENSORS}"),
        ));
    }
    let rays = s.rays_per_beam.unwrap_or(d.rays_per_beam as u32);
    if rays > MAX_RAYS_PER_BEAM {
        return Err(invalid(
            "sensors.rays_per_beam",
            format!("{rays}, at most {MAX_RAYS_PER_BEAM}"),
        ));
    }
    let p = RangeSensorParams {
        count: count as usize,
        max_range: s.max_range.unwrap_or(d.max_range),
        beam_width: s.beam_width.unwrap_or(d.beam_width),
        rays_per_beam: rays as usize,
        noise_sigma: s.noise_sigma.unwrap_or(d.noise_sigma),
    };
    p.validate().map_err(mobile_error)?;
    Ok(p)
}

pub(super) fn vdf_in(v: Option<&pb::VectorDistanceParams>) -> Result<VdfParams, Status> {
    let d = VdfParams::default();
    let Some(v) = v else { return Ok(d) };
    let turn = match pb::TurnPreference::try_from(v.turn) {
        Ok(pb::TurnPreference::Unspecified | pb::TurnPreference::Auto) => TurnPreference::Auto,
        Ok(pb::TurnPreference::Left) => TurnPreference::Left,
        Ok(pb::TurnPreference::Right) => TurnPreference::Right,
        Err(_) => return Err(invalid("vdf.turn", format!("unknown turn preference {}", v.turn))),
    };
    let p = VdfParams {
        safe_distance: v.safe_distance.unwrap_or(d.safe_distance),
        magnitude: v.magnitude.unwrap_or(d.magnitude),
        weight_decay: v.weight_decay.unwrap_or(d.weight_decay),
        turn_gain: v.turn_gain.unwrap_or(d.turn_gain),
        release_distance: v.release_distance.unwrap_or(d.release_distance),
        turn,
        max_speed: v.max_speed.unwrap_or(d.max_speed),
        max_yaw_rate: v.max_yaw_rate.unwrap_or(d.max_yaw_rate),
        heading_gain: v.heading_gain.unwrap_or(d.heading_gain),
        slow_distance: v.slow_distance.unwrap_or(d.slow_distance),
        allow_reverse: v.allow_reverse.unwrap_or(d.allow_reverse),
        avoid_blocked_heading: v.avoid_blocked_heading.unwrap_or(d.avoid_blocked_heading),
        progress_steps: v.progress_steps.map_or(d.progress_steps, |n| n as usize),
        progress_min: v.progress_min.unwrap_or(d.progress_min),
        no_path_steps: v.no_path_steps.map_or(d.no_path_steps, |n| n as usize),
        no_path_min: v.no_path_min.unwrap_or(d.no_path_min),
        leave_tolerance: v.leave_tolerance.unwrap_or(d.leave_tolerance),
        hit_radius: v.hit_radius.unwrap_or(d.hit_radius),
        wall_gain: v.wall_gain.unwrap_or(d.wall_gain),
        goal_tolerance: v.goal_tolerance.unwrap_or(d.goal_tolerance),
        retry_other_side: v.retry_other_side.unwrap_or(d.retry_other_side),
    };
    p.validate().map_err(mobile_error)?;
    Ok(p)
}

pub(super) fn astar_in(a: Option<&pb::GridAstarOptions>) -> Result<GridAstarParams, Status> {
    let d = GridAstarParams::default();
    let p = a.map_or(d, |a| GridAstarParams {
        resolution: a.resolution.unwrap_or(d.resolution),
        inflation: a.inflation.unwrap_or(d.inflation),
        padding: a.padding.unwrap_or(d.padding),
        max_cells: a
            .max_cells
            .map_or(d.max_cells, |n| n.min(d.max_cells as u64) as usize),
    });
    p.validate().map_err(mobile_error)?;
    Ok(p)
}

/// Path-follower parameters; `controller` must be a path-following one; unset: `unset` (the
/// domain's default for the caller: [`PathFollowParams::default`] or
/// [`GRID_PATH_CONTROLLER`](kinplan_core::mobile::GRID_PATH_CONTROLLER)).
pub(super) fn follow_in(
    controller: i32,
    f: Option<&pb::FollowOptions>,
    unset: ControllerKind,
) -> Result<PathFollowParams, Status> {
    let kind = match pb::Controller::try_from(controller) {
        Ok(pb::Controller::Unspecified) => unset,
        Ok(pb::Controller::Lyapunov) => ControllerKind::Lyapunov,
        Ok(pb::Controller::PurePursuit) => ControllerKind::PurePursuit,
        Ok(pb::Controller::GoalSeeking) => ControllerKind::GoalSeeking,
        Ok(pb::Controller::ShortestPath) => ControllerKind::ShortestPath,
        Ok(pb::Controller::VectorDistance) => {
            return Err(invalid(
                "controller",
                "CONTROLLER_VECTOR_DISTANCE does not follow paths (use Navigate or ControlStep)",
            ));
        }
        Err(_) => {
            return Err(invalid("controller", format!("unknown controller {controller}")));
        }
    };
    let d = PathFollowParams::default();
    let mut p = PathFollowParams {
        controller: kind,
        ..d
    };
    if let Some(f) = f {
        p.switching_distance = f.switching_distance.unwrap_or(d.switching_distance);
        p.goal_tolerance = f.goal_tolerance.unwrap_or(d.goal_tolerance);
        p.heading_tolerance = f.heading_tolerance.unwrap_or(d.heading_tolerance);
        if let Some(l) = &f.lyapunov {
            let d = d.lyapunov;
            p.lyapunov.gamma = l.gamma.unwrap_or(d.gamma);
            p.lyapunov.k = l.k.unwrap_or(d.k);
            p.lyapunov.h = l.h.unwrap_or(d.h);
            p.lyapunov.lambda = l.lambda.unwrap_or(d.lambda);
            p.lyapunov.max_speed = l.max_speed.unwrap_or(d.max_speed);
            p.lyapunov.max_yaw_rate = l.max_yaw_rate.unwrap_or(d.max_yaw_rate);
        }
        if let Some(pp) = &f.pure_pursuit {
            let d = d.pure_pursuit;
            p.pure_pursuit.lookahead = pp.lookahead.unwrap_or(d.lookahead);
            p.pure_pursuit.desired_speed = pp.desired_speed.unwrap_or(d.desired_speed);
            p.pure_pursuit.approach_distance = pp.approach_distance.unwrap_or(d.approach_distance);
            p.pure_pursuit.min_approach_speed = pp.min_approach_speed.unwrap_or(d.min_approach_speed);
            p.pure_pursuit.rotate_to_heading = pp.rotate_to_heading.unwrap_or(d.rotate_to_heading);
            p.pure_pursuit.rotate_min_angle = pp.rotate_min_angle.unwrap_or(d.rotate_min_angle);
            p.pure_pursuit.rotate_yaw_rate = pp.rotate_yaw_rate.unwrap_or(d.rotate_yaw_rate);
        }
        if let Some(s) = &f.steering {
            let d = d.steering;
            p.steering.speed = s.speed.unwrap_or(d.speed);
            p.steering.wheelbase = s.wheelbase.unwrap_or(d.wheelbase);
            p.steering.max_steer = s.max_steer.unwrap_or(d.max_steer);
            p.steering.epsilon = s.epsilon.unwrap_or(d.epsilon);
            p.steering.candidates = s
                .candidates
                .map_or(d.candidates, |n| n.min(MAX_STEERING_CANDIDATES) as usize);
        }
    }
    p.validate().map_err(mobile_error)?;
    Ok(p)
}

pub(super) fn mode_out(m: NavMode) -> pb::NavMode {
    match m {
        NavMode::Rotate => pb::NavMode::Rotate,
        NavMode::Lock => pb::NavMode::Lock,
        NavMode::Track => pb::NavMode::Track,
    }
}

pub(super) fn run_out(run: SimRun) -> pb::MobileRun {
    let outcome = match run.outcome {
        Outcome::Reached => pb::Outcome::Reached,
        Outcome::NoPath => pb::Outcome::NoPath,
        Outcome::Timeout => pb::Outcome::Timeout,
        Outcome::Collision => pb::Outcome::Collision,
        Outcome::Cancelled => pb::Outcome::Cancelled,
    };
    let reason = match run.no_path_reason {
        None => pb::NoPathReason::Unspecified,
        Some(NoPathReason::ReturnedToHit) => pb::NoPathReason::ReturnedToHit,
        Some(NoPathReason::NoProgress) => pb::NoPathReason::NoProgress,
        Some(NoPathReason::NoGridPath) => pb::NoPathReason::NoGridPath,
    };
    pb::MobileRun {
        outcome: outcome as i32,
        states: run.states.iter().map(pose_out).collect(),
        commands: run.commands.iter().map(|t| twist_out(*t)).collect(),
        modes: run.modes.iter().map(|m| mode_out(*m) as i32).collect(),
        hit_points: run.hit_points.iter().map(|p| point_out(*p)).collect(),
        leave_points: run.leave_points.iter().map(|p| point_out(*p)).collect(),
        no_path_reason: reason as i32,
        collided_with: run.collided_with.map(|i| i as u32),
        metrics: Some(pb::RunMetrics {
            path_length: run.metrics.path_length,
            time: run.metrics.time,
            // unset without obstacles (the domain says +inf)
            min_clearance: run.metrics.min_clearance.filter(|c| c.is_finite()),
            steps: run.metrics.steps as u32,
        }),
    }
}

pub(super) fn step_out(step: ControlStep) -> pb::ControlStepResponse {
    let mut reply = pb::ControlStepResponse {
        command: Some(twist_out(step.command)),
        applied: Some(twist_out(step.applied)),
        saturation: Some(saturation_out(step.saturation)),
        reached: step.reached,
        state_token: step.token,
        ..Default::default()
    };
    match step.report {
        StepReport::VectorDistance {
            mode,
            readings,
            force,
            event,
        } => {
            reply.mode = mode_out(mode) as i32;
            reply.readings = readings;
            reply.force = Some(point_out(force));
            match event {
                Some(VdfEvent::Hit(h)) => reply.hit_point = Some(point_out(h)),
                Some(VdfEvent::Leave(l)) => reply.leave_point = Some(point_out(l)),
                Some(VdfEvent::NoPath(_)) => reply.no_path = true,
                Some(VdfEvent::Reached) | None => {}
            }
        }
        StepReport::FollowPath { target_node } => reply.target_node = target_node as u32,
    }
    reply
}
