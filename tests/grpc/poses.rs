//! Poses between nalgebra and the contract, and the server's own forward
//! kinematics, for the tests that check IK answers against it.

use kinplan_server::pb::{self, robot_service_client::RobotServiceClient};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use tonic::transport::Channel;

use crate::named;

pub fn pose_pb(t: &Isometry3<f64>) -> pb::Pose {
    let q = t.rotation.quaternion();
    let p = t.translation.vector;
    pb::Pose {
        position: Some(pb::Vec3 {
            x: p.x,
            y: p.y,
            z: p.z,
        }),
        orientation: Some(pb::Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }),
    }
}

pub fn iso(p: &pb::Pose) -> Isometry3<f64> {
    let t = p.position.unwrap();
    let q = p.orientation.unwrap();
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::new_normalize(Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

/// The tool pose of built-in `name` at `q`, by RobotService.ForwardKinematics.
pub async fn fk(robots: &mut RobotServiceClient<Channel>, name: &str, q: &[f64]) -> Isometry3<f64> {
    let reply = robots
        .forward_kinematics(pb::ForwardKinematicsRequest {
            robot: named(name),
            joint_positions: q.to_vec(),
            include_links: false,
        })
        .await
        .unwrap()
        .into_inner();
    iso(reply.tool_pose.as_ref().unwrap())
}
