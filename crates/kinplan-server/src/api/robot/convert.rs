//! `RobotService` replies: a chain's description (joints, links, collision
//! shapes) as `DescribeRobotResponse`.

use crate::api::convert::{pose_out, vec3_out};
use crate::pb;
use kinplan_core::ik::analytic::{AnalyticParams, analyse};
use kinplan_core::robot::{Chain, JointKind, Shape};

/// A chain's description: joints, links with their collision shapes, the tip.
pub(super) fn describe(chain: &Chain, model_id: Vec<u8>) -> pb::DescribeRobotResponse {
    let analytic = analyse(chain, &AnalyticParams::default(), None);
    let joints = chain
        .joints()
        .iter()
        .map(|j| pb::JointInfo {
            name: j.name.clone(),
            r#type: match j.kind {
                JointKind::Revolute => pb::JointType::Revolute,
                JointKind::Continuous => pb::JointType::Continuous,
                JointKind::Prismatic => pb::JointType::Prismatic,
            } as i32,
            origin: Some(pose_out(&j.origin)),
            axis: Some(vec3_out(&j.axis)),
            lower: j.lower,
            upper: j.upper,
            max_velocity: j.max_velocity.unwrap_or(0.0),
        })
        .collect();
    let links = chain
        .links()
        .iter()
        .zip(chain.collision())
        .map(|(link, collision)| pb::LinkInfo {
            name: link.name.clone(),
            parent_joint: link.after_joint.map_or(-1, |j| j as i32),
            offset: Some(pose_out(&link.offset)),
            collision: collision
                .shapes
                .iter()
                .map(|s| pb::CollisionGeometry {
                    origin: Some(pose_out(&s.origin)),
                    shape: Some(shape_out(&s.shape)),
                })
                .collect(),
        })
        .collect();
    pb::DescribeRobotResponse {
        name: chain.name().into(),
        model_id,
        base_link: chain.base_link().into(),
        tip_link: chain.tip_link().into(),
        joints,
        links,
        tip_offset: Some(pose_out(chain.tip_offset())),
        urdf: String::new(),
        collision_bodies: Vec::new(),
        named_states: Vec::new(),
        analytic_family: analytic
            .as_ref()
            .map_or_else(|_| String::new(), |a| a.arm.family().name().into()),
        analytic_held_joint: analytic
            .as_ref()
            .ok()
            .and_then(|a| a.held)
            .map_or(-1, |(j, _)| j as i32),
        analytic_reversed: analytic.as_ref().is_ok_and(|a| a.arm.is_reversed()),
        analytic_reason: analytic.err().map_or_else(String::new, |e| e.reason),
    }
}

/// A collision primitive of a link.
fn shape_out(shape: &Shape) -> pb::collision_geometry::Shape {
    use pb::collision_geometry::Shape as S;
    match shape {
        Shape::Box { half_extents } => S::Box(pb::Box {
            size: Some(vec3_out(&(half_extents * 2.0))),
        }),
        Shape::Sphere { radius } => S::Sphere(pb::Sphere { radius: *radius }),
        Shape::Cylinder { radius, length } => S::Cylinder(pb::Cylinder {
            radius: *radius,
            length: *length,
        }),
        Shape::Capsule { radius, length } => S::Capsule(pb::Capsule {
            radius: *radius,
            length: *length,
        }),
        Shape::MeshReference { filename, scale } => match kinplan_core::collision::builtin_mesh(filename) {
            // a built-in robot's mesh goes out whole; another is only named
            Some(mesh) => S::Mesh(pb::TriangleMesh {
                vertices: mesh
                    .vertices
                    .iter()
                    .map(|p| vec3_out(&p.coords.component_mul(scale)))
                    .collect(),
                indices: mesh.indices.clone(),
            }),
            None => S::MeshReference(filename.clone()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::describe;
    use crate::pb::collision_geometry::Shape as S;

    /// The built-in Panda's links go out with their embedded meshes, vertex
    /// for vertex as the OBJ file the library carries writes them.
    #[test]
    fn a_built_in_mesh_is_described_whole() {
        let chain = kinplan_core::robot::builtin_chain("franka_panda").unwrap();
        let out = describe(&chain, Vec::new());
        let link = out.links.iter().find(|l| l.name == "link_5").unwrap();
        let Some(S::Mesh(mesh)) = &link.collision[0].shape else {
            panic!("{:?}", link.collision[0].shape)
        };
        let obj = include_str!("../../../../kinplan-core/src/robot/builtin/meshes/panda/link_5.obj");
        let vertices: Vec<Vec<f64>> = obj
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(mesh.vertices.len(), vertices.len());
        assert_eq!(
            mesh.indices.len(),
            3 * obj.lines().filter(|l| l.starts_with("f ")).count()
        );
        for (ours, theirs) in mesh.vertices.iter().zip(&vertices) {
            assert!(
                (ours.x - theirs[0]).abs() + (ours.y - theirs[1]).abs() + (ours.z - theirs[2]).abs() < 1e-12
            );
        }
    }
}
