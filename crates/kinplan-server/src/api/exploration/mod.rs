//! `ExplorationService`: NextBestView, InsertScan and OctreeInfo over the
//! octree and nbv rooms. Octrees arrive as OctoMap node bytes inside the
//! request (never a path) and are parsed on the CPU pool with a node limit;
//! every long stage checks the request's deadline and cancellation. The
//! service's other two calls, the Explore loop and its reference scenes, are
//! handled in `explore_loop`.

use tonic::{Request, Response, Status};

use crate::api::convert::{finite, pose_in};
use crate::pb::{self, exploration_service_server::ExplorationService};
use crate::runtime::Shared;
use crate::status::invalid;
use crate::status::nbv::nbv_error;
use crate::status::octree::octree_error;
use convert::{box_in, camera_in, nbv_params_in, nbv_response, octree_out, stats_out};
use kinplan_core::nbv::next_best_view;
use kinplan_core::octree::{
    MAX_DEPTH_PIXELS, Octree, OctreeLimits, PinholeIntrinsics, ScanParams, ScanStatus,
};

pub(crate) mod convert;
pub(crate) mod explore_loop;

/// Largest tree a request may carry or grow, in nodes (about 8 bytes per
/// node plus 68 per inner node: a few hundred MB at worst).
pub const MAX_OCTREE_NODES: usize = 5_000_000;

fn limits() -> OctreeLimits {
    OctreeLimits {
        max_nodes: MAX_OCTREE_NODES,
    }
}

/// Parses the tree of a request (`field` names it) on the calling thread.
fn octree_in(field: &str, tree: Option<&pb::Octree>) -> Result<Octree, Status> {
    let Some(t) = tree else {
        return Err(invalid(field, "is required"));
    };
    Octree::from_message_data(t.binary, &t.id, t.resolution, &t.data, &limits())
        .map_err(|e| octree_error(field, e))
}

pub struct ExplorationApi {
    shared: Shared,
}

impl ExplorationApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }
}

#[tonic::async_trait]
impl ExplorationService for ExplorationApi {
    type ExploreStream = explore_loop::ExploreStream;

    async fn reference_scene(
        &self,
        request: Request<pb::ReferenceSceneRequest>,
    ) -> Result<Response<pb::ReferenceSceneResponse>, Status> {
        let req = request.into_inner();
        let scene = match pb::ReferenceSceneName::try_from(req.name) {
            Ok(pb::ReferenceSceneName::S0OpenCell) => kinplan_core::explore::s0_open_cell(req.seed),
            Ok(pb::ReferenceSceneName::S0WalledCell) => kinplan_core::explore::s0_walled_cell(req.seed),
            _ => return Err(invalid("name", format!("unknown reference scene {}", req.name))),
        };
        Ok(Response::new(explore_loop::convert::reference_scene_out(&scene)))
    }

    async fn explore(
        &self,
        request: Request<pb::ExploreRequest>,
    ) -> Result<Response<Self::ExploreStream>, Status> {
        explore_loop::explore_stream(&self.shared, request)
            .await
            .map(Response::new)
    }

    async fn next_best_view(
        &self,
        request: Request<pb::NextBestViewRequest>,
    ) -> Result<Response<pb::NextBestViewResponse>, Status> {
        let (_permit, budget, chain) = match request.get_ref().robot.as_ref() {
            Some(robot) => {
                let (p, b, r) = self.shared.admit_robot(&request, Some(robot)).await?;
                (p, b, Some(r.chain))
            }
            None => {
                let (p, b) = self.shared.compute.admit(&request)?;
                (p, b, None)
            }
        };
        let req = request.into_inner();
        let camera = camera_in(req.camera.as_ref())?;
        let camera_pose = pose_in("camera_pose", req.camera_pose.as_ref())?;
        // options.time_budget stays the NBV's own; the request's deadline comes with `b`
        let params = nbv_params_in(&req)?;
        let reply = self
            .shared
            .compute
            .run(&budget, move |b| -> Result<pb::NextBestViewResponse, Status> {
                let tree = octree_in("octree", req.octree.as_ref())?;
                let result = next_best_view(
                    &tree,
                    &params,
                    &camera,
                    &camera_pose,
                    chain.as_deref(),
                    b.deadline(),
                )
                .map_err(|e| nbv_error("options", e))?;
                Ok(nbv_response(result))
            })
            .await??;
        Ok(Response::new(reply))
    }

    async fn insert_scan(
        &self,
        request: Request<pb::InsertScanRequest>,
    ) -> Result<Response<pb::InsertScanResponse>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let mut req = request.into_inner();
        let sensor = pose_in("sensor_pose", req.sensor_pose.as_ref())?;
        let params = ScanParams {
            max_range: finite("max_range", req.max_range.unwrap_or(-1.0))?,
            discretize: req.discretize,
            max_nodes: MAX_OCTREE_NODES,
            near_ray_spacing: finite("near_ray_spacing", req.near_ray_spacing)?,
            ..ScanParams::default()
        };
        params.validate().map_err(|e| match e {
            kinplan_core::octree::OctreeError::InvalidParam { field, .. } => invalid(field, e.to_string()),
            e => octree_error("scan", e),
        })?;
        let scan = match req.scan.take() {
            None => return Err(invalid("scan", "one of points or depth_image is required")),
            Some(pb::insert_scan_request::Scan::Points(p)) => {
                if p.xyz.len() % 3 != 0 {
                    return Err(invalid(
                        "points.xyz",
                        format!("{} values is not a multiple of 3", p.xyz.len()),
                    ));
                }
                Scan::Points(p.xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
            }
            Some(pb::insert_scan_request::Scan::DepthImage(d)) => depth_image_in(d)?,
        };
        let existing = req.octree.take();
        let resolution = req.resolution;
        let full = req.full;
        let reply = self
            .shared
            .compute
            .run(&budget, move |b| -> Result<pb::InsertScanResponse, Status> {
                let mut tree = match &existing {
                    Some(t) => octree_in("octree", Some(t))?,
                    None => Octree::new(resolution).map_err(|e| octree_error("resolution", e))?,
                };
                let deadline = b.deadline();
                let stats = match &scan {
                    Scan::Points(points) => {
                        let o = sensor.translation.vector;
                        tree.insert_scan(points, &[o.x as f32, o.y as f32, o.z as f32], &params, deadline)
                    }
                    Scan::Depth {
                        depth,
                        width,
                        height,
                        intrinsics,
                    } => tree
                        .insert_depth_image(depth, *width, *height, intrinsics, &sensor, &params, deadline),
                }
                .map_err(|e| octree_error("scan", e))?;
                if stats.status == ScanStatus::Cancelled {
                    return Err(Status::deadline_exceeded(
                        "the deadline passed while the scan was traced",
                    ));
                }
                if tree.num_nodes() > MAX_OCTREE_NODES {
                    return Err(crate::status::too_large(
                        "scan",
                        format!(
                            "the tree grew to {} nodes, over the limit of {MAX_OCTREE_NODES}",
                            tree.num_nodes()
                        ),
                    ));
                }
                Ok(pb::InsertScanResponse {
                    octree: Some(octree_out(&tree, !full)),
                    free_cells: stats.free_cells as u64,
                    occupied_cells: stats.occupied_cells as u64,
                    skipped_points: stats.skipped_points as u64,
                    stats: Some(stats_out(&tree)),
                })
            })
            .await??;
        Ok(Response::new(reply))
    }

    async fn octree_info(
        &self,
        request: Request<pb::OctreeInfoRequest>,
    ) -> Result<Response<pb::OctreeInfoResponse>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        let bounds = match &req.r#box {
            Some(b) => Some(box_in("box", b)?),
            None => None,
        };
        let reply = self
            .shared
            .compute
            .run(&budget, move |_| -> Result<pb::OctreeInfoResponse, Status> {
                let tree = octree_in("octree", req.octree.as_ref())?;
                let stats = stats_out(&tree);
                let volumes = match bounds.or_else(|| tree.known_bounds()) {
                    Some((min, max)) => Some(
                        tree.volumes_in_box(&min, &max)
                            .map_err(|e| octree_error("box", e))?,
                    ),
                    None => None,
                };
                Ok(pb::OctreeInfoResponse {
                    stats: Some(stats),
                    occupied_volume: volumes.map_or(0.0, |v| v.occupied),
                    free_volume: volumes.map_or(0.0, |v| v.free),
                    unknown_volume: volumes.map_or(0.0, |v| v.unknown),
                })
            })
            .await??;
        Ok(Response::new(reply))
    }
}

enum Scan {
    Points(Vec<[f32; 3]>),
    Depth {
        /// Metres along the optical axis, row-major.
        depth: Vec<f32>,
        width: usize,
        height: usize,
        intrinsics: PinholeIntrinsics,
    },
}

/// A depth image in metres (float32 or uint16 millimetres) with its
/// intrinsics (given, or from the camera model), checked field by field.
fn depth_image_in(mut d: pb::DepthImage) -> Result<Scan, Status> {
    let (width, height) = (d.width as usize, d.height as usize);
    if width == 0 || height == 0 {
        return Err(invalid(
            "depth_image.width",
            "width and height must be at least 1",
        ));
    }
    let pixels = width
        .checked_mul(height)
        .filter(|&n| n <= MAX_DEPTH_PIXELS)
        .ok_or_else(|| invalid("depth_image.width", "width x height must be at most 2^24 pixels"))?;
    let depth = match (d.depth.is_empty(), d.depth_mm.is_empty()) {
        (false, false) => {
            return Err(invalid(
                "depth_image.depth_mm",
                "give depth (metres) or depth_mm (millimetres), not both",
            ));
        }
        (true, true) => return Err(invalid("depth_image.depth", "is required (or depth_mm)")),
        (false, true) => {
            if d.depth.len() != pixels {
                return Err(invalid(
                    "depth_image.depth",
                    format!(
                        "has {} values, width x height is {width} x {height}",
                        d.depth.len()
                    ),
                ));
            }
            std::mem::take(&mut d.depth)
        }
        (true, false) => {
            if d.depth_mm.len() != 2 * pixels {
                return Err(invalid(
                    "depth_image.depth_mm",
                    format!(
                        "has {} bytes, width x height x 2 is {}",
                        d.depth_mm.len(),
                        2 * pixels
                    ),
                ));
            }
            kinplan_core::octree::depth_from_millimetres(&d.depth_mm, "depth_image.depth_mm")
                .map_err(|e| octree_error("depth_image.depth_mm", e))?
        }
    };
    let intrinsics = match &d.camera {
        Some(c) => {
            if [d.fx, d.fy, d.cx, d.cy].iter().any(|v| *v != 0.0) {
                return Err(invalid(
                    "depth_image.camera",
                    "give the camera or fx, fy, cx, cy, not both",
                ));
            }
            let cam = camera_in(Some(c))
                .map_err(|s| Status::invalid_argument(format!("depth_image.{}", s.message())))?;
            if (cam.width, cam.height) != (width, height) {
                return Err(invalid(
                    "depth_image.camera.width",
                    format!(
                        "the camera is {} x {}, the image {width} x {height}",
                        cam.width, cam.height
                    ),
                ));
            }
            cam.intrinsics()
        }
        None => {
            for (name, v) in [("fx", d.fx), ("fy", d.fy)] {
                let v = finite(&format!("depth_image.{name}"), v)?;
                if v <= 0.0 {
                    return Err(invalid(format!("depth_image.{name}"), "must be > 0"));
                }
            }
            PinholeIntrinsics {
                fx: d.fx,
                fy: d.fy,
                cx: finite("depth_image.cx", d.cx)?,
                cy: finite("depth_image.cy", d.cy)?,
            }
        }
    };
    Ok(Scan::Depth {
        depth,
        width,
        height,
        intrinsics,
    })
}
