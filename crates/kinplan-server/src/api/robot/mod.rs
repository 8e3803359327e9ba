//! `RobotService`: built-in robots, model descriptions, FK and Jacobians.
//!
//! FK and Jacobians cost microseconds (bounded by the URDF element limit), so
//! they run inline; model parsing goes to the CPU pool.

use tonic::{Request, Response, Status};

use crate::api::convert::{matrix_out, pose_out};
use crate::pb::{self, robot_service_server::RobotService};
use crate::runtime::Shared;
use crate::runtime::collision_models::collision_setup;
use crate::status::{invalid, robot_error, too_large};
use kinplan_core::Deadline;
use kinplan_core::robot::{BUILTIN_NAMES, Chain, builtin_chain, builtin_urdf, expand_capsules};

mod convert;

use convert::describe;

pub struct RobotApi {
    shared: Shared,
}

impl RobotApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }
}

#[tonic::async_trait]
impl RobotService for RobotApi {
    async fn list_robots(
        &self,
        request: Request<pb::ListRobotsRequest>,
    ) -> Result<Response<pb::ListRobotsResponse>, Status> {
        let _admitted = self.shared.compute.admit(&request)?;
        let robots = BUILTIN_NAMES
            .iter()
            .map(|name| {
                let chain = builtin_chain(name).map_err(|e| robot_error(e, ""))?;
                Ok(pb::RobotSummary {
                    name: name.to_string(),
                    dof: chain.dof() as u32,
                    description: builtin_urdf(name).map(urdf_comment).unwrap_or_default(),
                    base_link: chain.base_link().into(),
                    tip_link: chain.tip_link().into(),
                })
            })
            .collect::<Result<_, Status>>()?;
        Ok(Response::new(pb::ListRobotsResponse { robots }))
    }

    async fn describe_robot(
        &self,
        request: Request<pb::DescribeRobotRequest>,
    ) -> Result<Response<pb::DescribeRobotResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.get_ref();
        let bodies = if req.include_collision_bodies {
            let setup = collision_setup(&self.shared, &robot, &budget).await?;
            setup
                .model
                .bodies()
                .map(|(name, carrier, shapes)| pb::CollisionBodyInfo {
                    name: name.to_string(),
                    carried_by: carrier.to_string(),
                    shapes: shapes.min(u32::MAX as usize) as u32,
                })
                .collect()
        } else {
            Vec::new()
        };
        let mut reply = describe(&robot.chain, robot.model_id);
        reply.collision_bodies = bodies;
        if let Some(srdf) = &robot.source.srdf {
            reply.named_states = srdf
                .parsed
                .group_states
                .iter()
                .map(|s| pb::NamedState {
                    name: s.name.clone(),
                    group: s.group.clone(),
                    joint_names: s.joints.iter().map(|(n, _)| n.clone()).collect(),
                    positions: s.joints.iter().map(|(_, v)| *v).collect(),
                })
                .collect();
        }
        if req.include_urdf
            && let Some(pb::robot_ref::Source::Name(name)) =
                req.robot.as_ref().and_then(|r| r.source.as_ref())
        {
            let text = builtin_urdf(name).map_err(|e| robot_error(e, "robot"))?;
            reply.urdf = if req.keep_capsules {
                text.to_owned()
            } else {
                expand_capsules(text).map_err(|e| Status::internal(format!("built-in URDF: {e}")))?
            };
        }
        Ok(Response::new(reply))
    }

    async fn forward_kinematics(
        &self,
        request: Request<pb::ForwardKinematicsRequest>,
    ) -> Result<Response<pb::ForwardKinematicsResponse>, Status> {
        let (_permit, _, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.get_ref();
        let q = &req.joint_positions;
        robot
            .chain
            .check_joints(q)
            .map_err(|e| robot_error(e, "joint_positions"))?;
        let chain = &robot.chain;
        // With links, the tip link's frame (the last one) is the tool pose: one FK pass.
        let (tool, links) = if req.include_links {
            let mut frames = Vec::with_capacity(chain.links().len());
            chain.link_frames_into(q, &mut frames);
            let links = chain
                .links()
                .iter()
                .zip(&frames)
                .map(|(link, pose)| pb::LinkPose {
                    name: link.name.clone(),
                    pose: Some(pose_out(pose)),
                })
                .collect();
            (frames.last().copied().unwrap_or_else(|| chain.fk(q)), links)
        } else {
            (chain.fk(q), Vec::new())
        };
        Ok(Response::new(pb::ForwardKinematicsResponse {
            tool_pose: Some(pose_out(&tool)),
            links,
            model_id: robot.model_id,
        }))
    }

    async fn forward_kinematics_batch(
        &self,
        request: Request<pb::ForwardKinematicsBatchRequest>,
    ) -> Result<Response<pb::ForwardKinematicsBatchResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        let dof = robot.chain.dof();
        let Some(m) = req.joint_positions.as_ref() else {
            return Err(invalid("joint_positions", "is required"));
        };
        if m.cols as usize != dof {
            return Err(invalid(
                "joint_positions.cols",
                format!("is {}, the robot has {dof} joints", m.cols),
            ));
        }
        let rows = m.rows as usize;
        if rows == 0 || m.data.len() != rows.saturating_mul(dof) {
            return Err(invalid(
                "joint_positions.data",
                format!(
                    "has {} values, {rows} rows x {dof} joints need {}",
                    m.data.len(),
                    rows.saturating_mul(dof)
                ),
            ));
        }
        let per_row = 7 + if req.include_jacobians { 6 * dof } else { 0 };
        if rows.saturating_mul(per_row) > MAX_BATCH_REPLY_VALUES {
            return Err(too_large(
                "joint_positions.rows",
                format!(
                    "{rows} states would need {} reply values, more than {MAX_BATCH_REPLY_VALUES}: split the batch",
                    rows.saturating_mul(per_row)
                ),
            ));
        }
        for (i, row) in m.data.chunks_exact(dof).enumerate() {
            robot
                .chain
                .check_joints(row)
                .map_err(|e| robot_error(e, &format!("joint_positions[{i}]")))?;
        }
        let chain = robot.chain.clone();
        let jacobians = req.include_jacobians;
        let q = req.joint_positions.map(|m| m.data).unwrap_or_default();
        let (poses, jac) = self
            .shared
            .compute
            .run(&budget, move |b| {
                batch_kinematics(&chain, &q, jacobians, b.deadline())
            })
            .await?
            .ok_or_else(|| Status::deadline_exceeded("the deadline passed during the batch"))?;
        let matrix = |cols: usize, data: Vec<f64>| pb::Matrix {
            rows: rows as u32,
            cols: cols as u32,
            data,
        };
        Ok(Response::new(pb::ForwardKinematicsBatchResponse {
            tool_poses: Some(matrix(7, poses)),
            jacobians: jacobians.then(|| matrix(6 * dof, jac)),
            model_id: robot.model_id,
        }))
    }

    async fn jacobian(
        &self,
        request: Request<pb::JacobianRequest>,
    ) -> Result<Response<pb::JacobianResponse>, Status> {
        let (_permit, _, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let q = &request.get_ref().joint_positions;
        let _req = request.get_ref();
        robot
            .chain
            .check_joints(q)
            .map_err(|e| robot_error(e, "joint_positions"))?;
        let mut jacobian = nalgebra::Matrix6xX::zeros(robot.chain.dof());
        let tool = robot.chain.jacobian_into(q, &mut jacobian);
        Ok(Response::new(pb::JacobianResponse {
            jacobian: Some(matrix_out(&jacobian)),
            tool_pose: Some(pose_out(&tool)),
            model_id: robot.model_id,
        }))
    }
}

/// Rows computed between deadline checks in a batch.
const BATCH_CHECK_ROWS: usize = 1024;
/// Most values a batch reply may carry (poses and Jacobians, 8 bytes each):
/// the reply grows up to 7× the request for a 6-joint arm with Jacobians,
/// so it is bounded here rather than by the request's size alone.
const MAX_BATCH_REPLY_VALUES: usize = 1_500_000;

/// Tool poses (n × 7: x, y, z, qx, qy, qz, qw) and, with `jacobians`, the
/// flattened 6 × dof Jacobians (n × 6·dof) of every row of `q` (n × dof,
/// row-major, already checked). `None` when `deadline` expired.
fn batch_kinematics(
    chain: &Chain,
    q: &[f64],
    jacobians: bool,
    deadline: Deadline<'_>,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let dof = chain.dof();
    let n = q.len() / dof;
    let mut poses = Vec::with_capacity(n * 7);
    let mut jac_out = Vec::with_capacity(if jacobians { n * 6 * dof } else { 0 });
    let mut jac = nalgebra::Matrix6xX::zeros(dof);
    for (i, row) in q.chunks_exact(dof).enumerate() {
        if i % BATCH_CHECK_ROWS == BATCH_CHECK_ROWS - 1 && deadline.expired() {
            return None;
        }
        let tool = if jacobians {
            let tool = chain.jacobian_into(row, &mut jac);
            // row-major 6 × dof
            for r in 0..6 {
                jac_out.extend((0..dof).map(|c| jac[(r, c)]));
            }
            tool
        } else {
            chain.fk(row)
        };
        let t = tool.translation.vector;
        let r = tool.rotation.quaternion().coords; // (i, j, k, w)
        poses.extend([t.x, t.y, t.z, r.x, r.y, r.z, r.w]);
    }
    Some((poses, jac_out))
}

/// The first XML comment of a built-in URDF: its data source.
fn urdf_comment(urdf: &str) -> String {
    urdf.split_once("<!--")
        .and_then(|(_, rest)| rest.split_once("-->"))
        .map(|(comment, _)| comment.trim().to_string())
        .unwrap_or_default()
}
