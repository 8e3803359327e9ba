//! `ExploreRequest` → the explore room's parameters (unset fields take the
//! domain's defaults; NBV and planner options reuse their RPCs' converters),
//! and the loop's steps and outcome → proto.

use std::time::Duration;

use tonic::Status;

use crate::api::convert::{finite, matrix_in, optional_seconds, pose_in, pose_out, vec3_out};
use crate::api::exploration::convert::{box_in, camera_in, nbv_params_in, visibility_in};
use crate::api::planning::convert::{plan_input, trajectory_out};
use crate::pb;
use crate::status::invalid;
use kinplan_core::explore::{ExploreOutcome, ExploreParams, ExploreStatus, ExploreStep, ViewFailure};
use kinplan_core::plan::PlanStatus;
use kinplan_core::robot::Chain;

/// Most camera poses a request may add as extra views.
const MAX_EXTRA_VIEWS: usize = 10_000;

/// The loop's parameters and the run's time budget.
pub fn explore_params_in(
    req: &pb::ExploreRequest,
    chain: &Chain,
) -> Result<(ExploreParams, Option<Duration>), Status> {
    let dof = chain.dof();
    let region = match &req.region {
        Some(b) => box_in("region", b)?,
        None => return Err(invalid("region", "is required")),
    };
    let mut p = ExploreParams::new(region, dof);
    p.camera = camera_in(req.camera.as_ref())?;
    if let Some(m) = &req.camera_mount {
        p.camera_mount = pose_in("camera_mount", Some(m))?;
    }
    // the loop's own visibility check is ExploreRequest.visibility (or
    // no_visibility_check); one given inside nbv would be silently replaced
    if req.nbv.as_ref().is_some_and(|n| n.visibility.is_some()) {
        return Err(crate::status::invalid(
            "nbv.visibility",
            "the exploration loop takes its visibility check from ExploreRequest.visibility",
        ));
    }
    // NBV options through NextBestView's converter; the loop sets the rest.
    let nbv_req = pb::NextBestViewRequest {
        robot: req.robot.clone(),
        options: req.nbv.clone(),
        ..Default::default()
    };
    p.nbv = nbv_params_in(&nbv_req)
        .map_err(|s| Status::invalid_argument(s.message().replacen("options", "nbv", 1)))?;
    // planner options through Plan's converter
    let plan_req = pb::PlanRequest {
        robot: req.robot.clone(),
        start: req.start.clone(),
        goal: Some(pb::plan_request::Goal::GoalJoints(pb::JointState {
            positions: req.start.clone(),
        })),
        algorithm: req.algorithm,
        options: req.plan_options.clone(),
        seed: req.seed,
        ..Default::default()
    };
    p.plan = plan_input(&plan_req)?.request;
    let number = |field: &str, v: Option<f64>, default: f64| v.map_or(Ok(default), |v| finite(field, v));
    let stop = req.stop.unwrap_or_default();
    p.stop.known_ratio = number("stop.known_ratio", stop.known_ratio, p.stop.known_ratio)?;
    p.stop.max_iterations = stop.max_iterations.map_or(p.stop.max_iterations, |v| v as usize);
    p.stop.max_consecutive_failures = stop
        .max_consecutive_failures
        .map_or(p.stop.max_consecutive_failures, |v| v as usize);
    p.resolution = number("resolution", req.resolution, p.resolution)?;
    p.sensor.pixel_stride = req.pixel_stride.map_or(p.sensor.pixel_stride, |v| v as usize);
    p.sensor.noise_stddev = number("noise_stddev", req.noise_stddev, p.sensor.noise_stddev)?;
    p.sensor.near_ray_spacing = number(
        "near_ray_spacing",
        req.near_ray_spacing,
        p.sensor.near_ray_spacing,
    )?;
    p.candidates_per_iteration = req
        .candidates_per_iteration
        .map_or(p.candidates_per_iteration, |v| v as usize);
    if let Some(b) = optional_seconds("plan_time_budget", req.plan_time_budget)? {
        p.plan_time_budget = b;
    }
    if req.no_initial_offsets {
        p.initial_offsets.clear();
    } else if req.initial_offsets.is_some() {
        let m = matrix_in("initial_offsets", req.initial_offsets.as_ref(), 64 * 64)?;
        if m.ncols() != dof {
            return Err(invalid(
                "initial_offsets",
                format!("has {} columns, the robot has {dof} joints", m.ncols()),
            ));
        }
        p.initial_offsets = m.row_iter().map(|r| r.iter().copied().collect()).collect();
    }
    if req.no_extra_views {
        p.extra_views.clear();
    } else if !req.extra_views.is_empty() {
        if req.extra_views.len() > MAX_EXTRA_VIEWS {
            return Err(invalid(
                "extra_views",
                format!("more than {MAX_EXTRA_VIEWS} poses"),
            ));
        }
        p.extra_views = req
            .extra_views
            .iter()
            .enumerate()
            .map(|(i, v)| pose_in(&format!("extra_views[{i}]"), Some(v)))
            .collect::<Result<_, _>>()?;
    }
    if req.no_visibility_check {
        p.visibility = None;
    } else if let Some(v) = &req.visibility {
        p.visibility = Some(visibility_in(v));
    }
    p.seed = req.seed;
    if !req.camera_link.is_empty() && req.camera_link != chain.tip_link() {
        let on_robot = chain.links().iter().any(|l| l.name == req.camera_link);
        return Err(invalid(
            "camera_link",
            if on_robot {
                format!(
                    "{:?} is not the chain's tip {:?}: only a camera on the tip is supported (use camera_mount for its offset)",
                    req.camera_link,
                    chain.tip_link()
                )
            } else {
                format!("{:?} is not a link of the robot", req.camera_link)
            },
        ));
    }
    if req.start.len() != dof {
        return Err(invalid(
            "start",
            format!("has {} values, the robot has {dof} joints", req.start.len()),
        ));
    }
    p.validate(dof).map_err(|e| match e {
        e @ kinplan_core::explore::ExploreError::InvalidParam { .. } => {
            crate::status::explore::explore_error(e)
        }
        e => invalid("nbv", e.to_string()),
    })?;
    Ok((p, optional_seconds("time_budget", req.time_budget)?))
}

fn failure_reason(f: &ViewFailure) -> String {
    match f {
        ViewFailure::Unreachable => "unreachable".into(),
        ViewFailure::NoGain => "no_gain".into(),
        ViewFailure::Plan(s) => match s {
            PlanStatus::Succeeded => "succeeded",
            PlanStatus::NoValidTrajectory => "no_valid_trajectory",
            PlanStatus::InvalidStart => "invalid_start",
            PlanStatus::InvalidGoal => "invalid_goal",
            PlanStatus::GoalUnreachable => "goal_unreachable",
            PlanStatus::Timeout => "timeout",
            PlanStatus::Cancelled => "cancelled",
        }
        .into(),
    }
}

fn seconds(us: u64) -> f64 {
    us as f64 * 1e-6
}

/// One iteration as a stream message.
pub fn iteration_out(chain: &Chain, s: &ExploreStep) -> pb::ExploreIteration {
    let view = s.view.as_ref().map(|v| pb::ViewCandidate {
        pose: Some(pose_out(&v.pose)),
        distance_score: v.distance_term,
        rotation_score: v.rotation_term,
        information_gain: v.ig,
        utility: v.utility,
        reachability: pb::Reachability::Reachable as i32,
        joints: s.joints.clone(),
        predicted_cells: v.predicted_cells,
        ..Default::default()
    });
    let (trajectory, criteria, hits_scene) = match &s.motion {
        Some(m) => (
            Some(trajectory_out(chain, &m.q, m.dof, &m.time_from_start)),
            m.criteria.iter().map(|(c, v)| (c.name().to_owned(), v)).collect(),
            m.hits_truth,
        ),
        None => (None, Default::default(), false),
    };
    pb::ExploreIteration {
        iteration: s.iteration.min(u32::MAX as usize) as u32,
        view,
        view_rank: s.view.as_ref().map_or(0, |v| v.rank as u32),
        trajectory,
        criteria,
        hits_scene,
        failures: s
            .failures
            .iter()
            .map(|(p, f)| pb::FailedView {
                position: Some(vec3_out(&p.coords)),
                reason: failure_reason(f),
            })
            .collect(),
        candidates: s.candidates.min(u32::MAX as usize) as u32,
        known_ratio: s.known_ratio,
        joints: s.joints.clone(),
        times: Some(pb::ExploreTimes {
            nbv: seconds(s.times.nbv_us),
            plan: seconds(s.times.plan_us),
            sense: seconds(s.times.sense_us),
            insert: seconds(s.times.insert_us),
            total: seconds(s.times.total_us),
        }),
    }
}

fn status_out(s: ExploreStatus) -> pb::ExploreStatus {
    match s {
        ExploreStatus::Explored => pb::ExploreStatus::Explored,
        ExploreStatus::IterationCap => pb::ExploreStatus::IterationCap,
        ExploreStatus::ConsecutiveFailures => pb::ExploreStatus::ConsecutiveFailures,
        ExploreStatus::NoCandidates => pb::ExploreStatus::NoCandidates,
        ExploreStatus::ObservableExhausted => pb::ExploreStatus::ObservableExhausted,
        ExploreStatus::Timeout => pb::ExploreStatus::Timeout,
        ExploreStatus::Cancelled => pb::ExploreStatus::Cancelled,
    }
}

/// The closing message.
pub fn summary_out(o: &ExploreOutcome, octree: pb::Octree, elapsed: Duration) -> pb::ExploreSummary {
    let count = |v: usize| v.min(u32::MAX as usize) as u32;
    pb::ExploreSummary {
        status: status_out(o.status) as i32,
        iterations: count(o.iterations),
        initial_known_ratio: o.initial_known_ratio,
        known_ratio: o.known_ratio,
        observable_cells: o.observable_cells as u64,
        totals: Some(pb::ExploreTotals {
            jd: o.totals.jd,
            cpc: o.totals.cpc,
            cd: o.totals.cd,
            oc: o.totals.oc,
            rdm: o.totals.rdm,
            trajectories: count(o.totals.motions),
        }),
        failures: count(o.failures),
        scene_hits: count(o.truth_hits),
        final_joints: o.final_joints.clone(),
        octree: Some(octree),
        scans: count(o.scans),
        elapsed: elapsed.as_secs_f64(),
        wasted_moves: count(o.wasted_moves),
        best_predicted_cells: o.best_predicted_cells,
    }
}

/// A domain obstacle as a proto collision object (occupied-cell sets, which
/// only octrees produce, have no proto form and are left out).
fn obstacle_out(o: &kinplan_core::collision::Obstacle) -> Option<pb::CollisionObject> {
    use kinplan_core::collision::Geometry;
    use pb::collision_object::Shape;
    let shape = match &o.geometry {
        Geometry::Box { half_extents: h } => Shape::Box(pb::Box {
            size: Some(vec3_out(&(h * 2.0))),
        }),
        Geometry::Sphere { radius } => Shape::Sphere(pb::Sphere { radius: *radius }),
        Geometry::Cylinder { radius, length } => Shape::Cylinder(pb::Cylinder {
            radius: *radius,
            length: *length,
        }),
        Geometry::Capsule { radius, length } => Shape::Capsule(pb::Capsule {
            radius: *radius,
            length: *length,
        }),
        Geometry::Mesh { vertices, indices } => Shape::Mesh(pb::TriangleMesh {
            vertices: vertices.iter().map(|v| vec3_out(&v.coords)).collect(),
            indices: indices.clone(),
        }),
        Geometry::OccupiedCells { .. } => return None,
    };
    Some(pb::CollisionObject {
        id: o.name.clone(),
        pose: Some(pose_out(&o.pose)),
        shape: Some(shape),
        unknown_as_obstacle: false,
    })
}

/// A reference scene as its reply.
pub fn reference_scene_out(s: &kinplan_core::explore::ReferenceScene) -> pb::ReferenceSceneResponse {
    let (a, b) = &s.region;
    pb::ReferenceSceneResponse {
        robot: s.robot.to_owned(),
        scene: Some(pb::Scene {
            objects: s.obstacles.iter().filter_map(obstacle_out).collect(),
        }),
        region: Some(pb::BoundingBox {
            min: Some(vec3_out(&a.coords)),
            max: Some(vec3_out(&b.coords)),
        }),
        start: s.start.clone(),
    }
}
