//! Exploration messages ↔ the octree and nbv rooms: camera and NBV options in
//! (unset fields take the domain's `Default`), candidates, stages and tree
//! statistics out.

use nalgebra::Point3;
use tonic::Status;

use crate::api::convert::{finite, optional_seconds, pose_in, vec3_in, vec3_out};
use crate::pb;
use crate::status::invalid;
use crate::status::nbv::nbv_error;
use kinplan_core::nbv::{CameraModel, GainMethod, NbvParams, NbvResult, NbvStatus, Weights};
use kinplan_core::octree::Octree;

fn number(field: &str, v: Option<f64>, default: f64) -> Result<f64, Status> {
    v.map_or(Ok(default), |v| finite(field, v))
}

/// The camera (Kinect v2 defaults), validated by the domain.
pub fn camera_in(c: Option<&pb::CameraModel>) -> Result<CameraModel, Status> {
    let c = c.cloned().unwrap_or_default();
    let d = CameraModel::default();
    let camera = CameraModel {
        hfov: number("camera.horizontal_fov", c.horizontal_fov, d.hfov)?,
        vfov: number("camera.vertical_fov", c.vertical_fov, d.vfov)?,
        near: number("camera.near_range", c.near_range, d.near)?,
        far: number("camera.far_range", c.far_range, d.far)?,
        width: c.width.map_or(d.width, |v| v as usize),
        height: c.height.map_or(d.height, |v| v as usize),
    };
    camera.validate().map_err(|e| nbv_error("camera", e))?;
    Ok(camera)
}

/// NBV parameters from the request (the camera pose and tree are separate).
pub fn nbv_params_in(req: &pb::NextBestViewRequest) -> Result<NbvParams, Status> {
    let o = req.options.clone().unwrap_or_default();
    let d = NbvParams::default();
    let fraction = number("options.ray_fraction", o.ray_fraction, 1.0)?;
    let gain = match pb::GainMethod::try_from(o.gain) {
        Ok(pb::GainMethod::Unspecified | pb::GainMethod::Intersection) => GainMethod::Intersection,
        Ok(pb::GainMethod::Rays) => GainMethod::Rays { fraction },
        Ok(pb::GainMethod::OcclusionAware) => GainMethod::OcclusionAware { fraction },
        Ok(pb::GainMethod::UnobservedVoxels) => GainMethod::UnobservedVoxels { fraction },
        Err(_) => return Err(invalid("options.gain", format!("unknown value {}", o.gain))),
    };
    let w = o.weights.unwrap_or_default();
    let weights = Weights {
        w_i: number(
            "options.weights.information_gain",
            w.information_gain,
            d.weights.w_i,
        )?,
        w_d: number("options.weights.distance", w.distance, d.weights.w_d)?,
        w_r: number("options.weights.rotation", w.rotation, d.weights.w_r)?,
    };
    let time_budget = optional_seconds("options.time_budget", o.time_budget)?;
    let optional_pose = |field: &str, p: Option<&pb::Pose>| match p {
        Some(p) => pose_in(field, Some(p)),
        None => Ok(nalgebra::Isometry3::identity()),
    };
    let params = NbvParams {
        region: o
            .region
            .as_ref()
            .map(|b| box_in("options.region", b))
            .transpose()?,
        frontier_unknown_ratio: number(
            "options.frontier_unknown_ratio",
            o.frontier_unknown_ratio,
            d.frontier_unknown_ratio,
        )?,
        max_frontier_candidates: o
            .max_frontier_candidates
            .map_or(d.max_frontier_candidates, |v| v as usize),
        field_radius: number("options.field_radius", o.field_radius, d.field_radius)?,
        standoff: number("options.standoff", o.standoff, d.standoff)?,
        extra_candidates: req
            .candidate_poses
            .iter()
            .enumerate()
            .map(|(i, p)| pose_in(&format!("candidate_poses[{i}]"), Some(p)))
            .collect::<Result<_, _>>()?,
        robot_base: optional_pose("robot_base", req.robot_base.as_ref())?,
        reach: o.reach.map(|r| finite("options.reach", r)).transpose()?,
        position_threshold: number(
            "options.position_threshold",
            o.position_threshold,
            d.position_threshold,
        )?,
        orientation_threshold: number(
            "options.orientation_threshold",
            o.orientation_threshold,
            d.orientation_threshold,
        )?,
        gain_threshold: number("options.gain_threshold", o.gain_threshold, d.gain_threshold)?,
        gain,
        weights,
        adaptive_weights: o.adaptive_weights,
        ik_check: if req.robot.is_some() {
            o.ik_check.map_or(d.ik_check, |v| v as usize)
        } else {
            0
        },
        camera_mount: optional_pose("camera_mount", req.camera_mount.as_ref())?,
        ik: d.ik,
        count_failures: o.count_failures,
        failure_penalty: number("options.failure_penalty", o.failure_penalty, d.failure_penalty)?,
        prior_failures: o
            .prior_failures
            .iter()
            .enumerate()
            .map(|(i, f)| {
                vec3_in(
                    &format!("options.prior_failures[{i}].position"),
                    f.position.as_ref(),
                )
                .map(|p| (nalgebra::Point3::from(p), f.count))
            })
            .collect::<Result<_, _>>()?,
        max_results: o.max_results.map_or(d.max_results, |v| v as usize),
        free_viewpoint: o.free_viewpoint,
        gain_in_region: o.gain_in_region,
        visibility: o.visibility.as_ref().map(visibility_in),
        time_budget,
        seed: o.seed,
    };
    params.validate().map_err(|e| nbv_error("options", e))?;
    Ok(params)
}

/// The visibility check's options; unset fields take the domain's defaults
/// (ranges are checked by `NbvParams::validate`, naming the field).
pub fn visibility_in(v: &pb::VisibilityCheck) -> kinplan_core::nbv::VisibilityParams {
    let d = kinplan_core::nbv::VisibilityParams::default();
    let count = |v: Option<u32>, d: usize| v.map_or(d, |v| v as usize);
    kinplan_core::nbv::VisibilityParams {
        batch: count(v.batch, d.batch),
        pixel_stride: count(v.pixel_stride, d.pixel_stride),
        lookahead: count(v.lookahead, d.lookahead),
        min_new_cells: count(v.min_new_cells, d.min_new_cells),
    }
}

fn pose_out(t: &nalgebra::Isometry3<f64>) -> pb::Pose {
    crate::api::convert::pose_out(t)
}

/// Ranked candidates, stage counts and times.
pub fn nbv_response(r: NbvResult) -> pb::NextBestViewResponse {
    let s = r.stages;
    let secs = |us: u64| us as f64 * 1e-6;
    pb::NextBestViewResponse {
        candidates: r
            .candidates
            .into_iter()
            .map(|c| pb::ViewCandidate {
                pose: Some(pose_out(&c.pose)),
                frontier: c.frontier.map(|p| vec3_out(&p.coords)),
                distance_score: c.distance_term,
                rotation_score: c.rotation_term,
                information_gain: c.ig,
                unknown_cells: c.unknown_cells,
                utility: c.utility,
                reachability: match c.reachable {
                    None => pb::Reachability::Unchecked,
                    Some(true) => pb::Reachability::Reachable,
                    Some(false) => pb::Reachability::Unreachable,
                } as i32,
                joints: c.joints.unwrap_or_default(),
                failures: c.failures,
                predicted_cells: c.predicted.map(|p| p.first),
                predicted_reached: c.predicted.map(|p| p.reached),
            })
            .collect(),
        stages: Some(pb::NbvStages {
            frontier_cells: s.frontier_cells as u64,
            frontier_candidates: s.frontier_candidates as u64,
            caller_candidates: s.caller_candidates as u64,
            after_orf: s.after_orf as u64,
            after_ptf: s.after_ptf as u64,
            after_igf: s.after_igf as u64,
            ik_checked: s.ik_checked as u64,
            ik_failed: s.ik_failed as u64,
            frontier_time: secs(s.frontier_us),
            field_time: secs(s.field_us),
            orf_time: secs(s.orf_us),
            ptf_time: secs(s.ptf_us),
            igf_time: secs(s.igf_us),
            ik_time: secs(s.ik_us),
            ray_steps: s.ray_steps,
            visibility_checked: s.visibility_checked as u64,
            visibility_dropped: s.visibility_dropped as u64,
            after_visibility: s.after_visibility as u64,
            best_predicted_cells: s.best_predicted_cells,
            visibility_time: secs(s.visibility_us),
        }),
        status: match r.status {
            NbvStatus::Complete => pb::NbvStatus::Complete,
            NbvStatus::TimeBudget => pb::NbvStatus::TimeBudget,
            NbvStatus::Cancelled => pb::NbvStatus::Cancelled,
        } as i32,
        weights: Some(pb::UtilityWeights {
            information_gain: Some(r.weights.w_i),
            distance: Some(r.weights.w_d),
            rotation: Some(r.weights.w_r),
        }),
        reach: r.reach,
        elapsed: secs(r.elapsed_us),
    }
}

/// The tree as OctoMap message bytes (`binary`: max-likelihood pruned `.bt` nodes).
pub fn octree_out(tree: &Octree, binary: bool) -> pb::Octree {
    pb::Octree {
        id: "OcTree".into(),
        resolution: tree.resolution(),
        binary,
        data: tree.to_message_data(binary),
    }
}

/// Counts and bounds of a tree.
pub fn stats_out(tree: &Octree) -> pb::OctreeStats {
    let (occupied, free) = tree.leaf_counts();
    pb::OctreeStats {
        resolution: tree.resolution(),
        nodes: tree.num_nodes() as u64,
        leaves: (occupied + free) as u64,
        occupied_leaves: occupied as u64,
        free_leaves: free as u64,
        bounds: tree.known_bounds().map(|(a, b)| pb::BoundingBox {
            min: Some(vec3_out(&a.coords)),
            max: Some(vec3_out(&b.coords)),
        }),
    }
}

/// A box from the request, min ≤ max on every axis.
pub fn box_in(field: &str, b: &pb::BoundingBox) -> Result<(Point3<f64>, Point3<f64>), Status> {
    let min = vec3_in(&format!("{field}.min"), b.min.as_ref())?;
    let max = vec3_in(&format!("{field}.max"), b.max.as_ref())?;
    if (0..3).any(|i| min[i] > max[i]) {
        return Err(invalid(field, "min must not exceed max on any axis"));
    }
    Ok((Point3::from(min), Point3::from(max)))
}
