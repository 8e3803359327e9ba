//! RobotService, health, reflection and shutdown.

use std::time::Duration;

use kinplan_server::ServerConfig;
use kinplan_server::pb::{self, robot_ref::Source, robot_service_client::RobotServiceClient};
use tonic::Code;
use tonic_health::pb::{
    HealthCheckRequest, health_check_response::ServingStatus, health_client::HealthClient,
};
use tonic_types::StatusExt;

use crate::{named, start};

fn fk_request(robot: Option<pb::RobotRef>, q: Vec<f64>) -> pb::ForwardKinematicsRequest {
    pb::ForwardKinematicsRequest {
        robot,
        joint_positions: q,
        include_links: false,
    }
}

fn position(pose: &pb::Pose) -> [f64; 3] {
    let p = pose.position.as_ref().unwrap();
    [p.x, p.y, p.z]
}

const TWO_LINK_URDF: &str = r#"<robot name="two_link">
  <link name="base"/><link name="upper"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
</robot>"#;

#[tokio::test]
async fn health_reflection_and_listing() {
    let server = start(ServerConfig::default()).await;
    let mut health = HealthClient::new(server.channel.clone());
    for service in ["", "kinplan.v1.RobotService"] {
        let reply = health
            .check(HealthCheckRequest {
                service: service.into(),
            })
            .await
            .unwrap()
            .into_inner();
        assert_eq!(reply.status(), ServingStatus::Serving, "service `{service}`");
    }

    let mut reflection = tonic_reflection::pb::v1::server_reflection_client::ServerReflectionClient::new(
        server.channel.clone(),
    );
    let request = tonic_reflection::pb::v1::ServerReflectionRequest {
        host: String::new(),
        message_request: Some(
            tonic_reflection::pb::v1::server_reflection_request::MessageRequest::ListServices(String::new()),
        ),
    };
    let mut replies = reflection
        .server_reflection_info(tokio_stream::iter([request]))
        .await
        .unwrap()
        .into_inner();
    let reply = replies.message().await.unwrap().unwrap();
    let Some(tonic_reflection::pb::v1::server_reflection_response::MessageResponse::ListServicesResponse(
        list,
    )) = reply.message_response
    else {
        panic!("unexpected reflection reply");
    };
    let names: Vec<String> = list.service.into_iter().map(|s| s.name).collect();
    for expected in ["kinplan.v1.RobotService", "grpc.health.v1.Health"] {
        assert!(names.contains(&expected.to_string()), "{names:?}");
    }

    let mut robots = RobotServiceClient::new(server.channel.clone());
    let list = robots
        .list_robots(pb::ListRobotsRequest {})
        .await
        .unwrap()
        .into_inner();
    let dof = |name: &str| list.robots.iter().find(|r| r.name == name).map(|r| r.dof);
    assert_eq!(dof("kuka_kr210_r2700_extra"), Some(6));
    assert_eq!(dof("franka_panda"), Some(7));
    assert_eq!(dof("planar_10"), Some(10));
    // The Panda with its hand: the fingers hang off the chain, so still 7 joints.
    assert_eq!(dof("franka_panda_hand"), Some(7));
    assert_eq!(list.robots.len(), 16);
}

#[tokio::test]
async fn fk_and_jacobian_over_grpc() {
    let server = start(ServerConfig::default()).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    // KR 210 stretched: 350 + 1150 + 1200 + 215 mm forward, 675 − 41 mm up.
    let reply = robots
        .forward_kinematics(fk_request(named("kuka_kr210_r2700_extra"), vec![0.0; 6]))
        .await
        .unwrap()
        .into_inner();
    let p = position(reply.tool_pose.as_ref().unwrap());
    assert!(
        (p[0] - 2.915).abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.634).abs() < 1e-9,
        "{p:?}"
    );

    // Inline URDF: planar two-link, hand-computed pose and Jacobian.
    let inline = Some(pb::RobotRef {
        source: Some(Source::Urdf(TWO_LINK_URDF.into())),
        ..Default::default()
    });
    let (a, b) = (0.3_f64, 0.9_f64);
    let reply = robots
        .forward_kinematics(pb::ForwardKinematicsRequest {
            robot: inline.clone(),
            joint_positions: vec![a, b],
            include_links: true,
        })
        .await
        .unwrap()
        .into_inner();
    let p = position(reply.tool_pose.as_ref().unwrap());
    assert!((p[0] - 0.4 * a.cos()).abs() < 1e-12 && (p[1] - 0.4 * a.sin()).abs() < 1e-12);
    assert!((p[2] - 0.5).abs() < 1e-12);
    assert_eq!(reply.links.len(), 3);
    assert_eq!(reply.model_id.len(), 32);

    let jac = robots
        .jacobian(pb::JacobianRequest {
            robot: inline.clone(),
            joint_positions: vec![a, b],
        })
        .await
        .unwrap()
        .into_inner()
        .jacobian
        .unwrap();
    assert_eq!((jac.rows, jac.cols), (6, 2));
    // Tool at the elbow joint: d/dq1 = 0.4·(−sin a, cos a, 0), ω = z; d/dq2 = 0.
    let expect = [
        -0.4 * a.sin(),
        0.0,
        0.4 * a.cos(),
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        1.0,
    ];
    for (got, want) in jac.data.iter().zip(expect) {
        assert!((got - want).abs() < 1e-12, "{:?}", jac.data);
    }

    // The model id now stands in for the URDF.
    let by_id = Some(pb::RobotRef {
        source: Some(Source::ModelId(reply.model_id.clone())),
        ..Default::default()
    });
    let again = robots
        .forward_kinematics(fk_request(by_id, vec![a, b]))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(position(again.tool_pose.as_ref().unwrap()), p);

    let described = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: inline,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(described.joints.len(), 2);
    assert_eq!(described.joints[1].name, "elbow");
    assert_eq!(described.joints[0].max_velocity, 2.0);
    assert_eq!(described.tip_link, "tool");
}

/// Each bad request gets the right code and a message naming the field, and
/// the server keeps serving afterwards.
#[tokio::test]
async fn bad_inputs_are_rejected_and_the_server_keeps_serving() {
    let server = start(ServerConfig {
        max_urdf_bytes: 64 * 1024,
        ..ServerConfig::default()
    })
    .await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let urdf = |text: String, tip: &str| {
        Some(pb::RobotRef {
            source: Some(Source::Urdf(text)),
            tip_link: tip.into(),
            ..Default::default()
        })
    };
    let cases: Vec<(&str, pb::ForwardKinematicsRequest, Code, &str)> = vec![
        ("NaN joint", fk_request(named("ur5"), vec![0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]), Code::InvalidArgument, "joint_positions[1]"),
        ("infinite joint", fk_request(named("ur5"), vec![0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY]), Code::InvalidArgument, "joint_positions[5]"),
        ("wrong joint count", fk_request(named("ur5"), vec![0.0; 5]), Code::InvalidArgument, "joint_positions"),
        ("unknown robot", fk_request(named("r2d2"), vec![]), Code::NotFound, "robot.name"),
        ("missing robot", fk_request(None, vec![]), Code::InvalidArgument, "robot"),
        ("empty robot ref", fk_request(Some(pb::RobotRef::default()), vec![]), Code::InvalidArgument, "robot"),
        ("unknown link", fk_request(urdf(TWO_LINK_URDF.into(), "hand"), vec![0.0, 0.0]), Code::NotFound, "robot.base_link/tip_link"),
        ("malformed URDF", fk_request(urdf("<robot name='x'><link".into(), ""), vec![]), Code::InvalidArgument, "robot.urdf"),
        ("not XML", fk_request(urdf("{\"robot\": 1}".into(), ""), vec![]), Code::InvalidArgument, "robot.urdf"),
        ("oversized URDF", fk_request(urdf(format!("{TWO_LINK_URDF}<!--{}-->", "x".repeat(70_000)), ""), vec![]), Code::InvalidArgument, "robot.urdf"),
        ("NaN in URDF", fk_request(urdf(TWO_LINK_URDF.replace("0.4 0 0", "0.4 nan 0"), ""), vec![0.0, 0.0]), Code::InvalidArgument, "robot.urdf"),
        ("not a serial chain", fk_request(urdf(TWO_LINK_URDF.replace("</robot>", "<link name='side'/><joint name='s' type='fixed'><parent link='base'/><child link='side'/></joint></robot>"), ""), vec![0.0, 0.0]), Code::InvalidArgument, "robot.tip_link"),
        ("bad model id", fk_request(Some(pb::RobotRef { source: Some(Source::ModelId(vec![1, 2, 3])), ..Default::default() }), vec![]), Code::InvalidArgument, "robot.model_id"),
        ("unseen model id", fk_request(Some(pb::RobotRef { source: Some(Source::ModelId(vec![7; 32])), ..Default::default() }), vec![]), Code::NotFound, "robot.model_id"),
    ];
    for (what, request, code, field) in cases {
        let status = robots.forward_kinematics(request).await.unwrap_err();
        assert_eq!(status.code(), code, "{what}: {status:?}");
        assert!(
            status.message().starts_with(field),
            "{what}: {}",
            status.message()
        );
        let details = status.get_details_bad_request().expect("BadRequest details");
        assert_eq!(details.field_violations[0].field, field, "{what}");
        // Still serving.
        robots
            .forward_kinematics(fk_request(named("ur5"), vec![0.1; 6]))
            .await
            .unwrap_or_else(|e| panic!("after {what}: {e:?}"));
    }
    let status = robots
        .jacobian(pb::JacobianRequest {
            robot: named("franka_panda"),
            joint_positions: vec![0.0; 6],
        })
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
}

#[tokio::test]
async fn shutdown_reports_not_serving_then_stops() {
    let mut server = start(ServerConfig {
        drain_delay: Duration::from_millis(400),
        ..ServerConfig::default()
    })
    .await;
    let mut health = HealthClient::new(server.channel.clone());
    server.stop.take().unwrap().send(()).unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;
    let reply = health
        .check(HealthCheckRequest {
            service: "kinplan.v1.RobotService".into(),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.status(), ServingStatus::NotServing);
    tokio::time::timeout(Duration::from_secs(5), server.handle)
        .await
        .expect("server stops after draining")
        .unwrap();
}

/// Batch FK agrees with one-state FK calls, and each batch Jacobian's
/// linear rows agree with central finite differences of batch positions.
#[tokio::test]
async fn batch_fk_matches_single_calls_and_its_jacobians_match_finite_differences() {
    let server = start(ServerConfig::default()).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let dof = 6;
    let states: Vec<Vec<f64>> = (0..40)
        .map(|i| {
            (0..dof)
                .map(|j| ((i * 7 + j * 3) % 11) as f64 * 0.4 - 2.0)
                .collect()
        })
        .collect();
    let matrix = |rows: &[Vec<f64>]| pb::Matrix {
        rows: rows.len() as u32,
        cols: dof as u32,
        data: rows.concat(),
    };
    let batch = robots
        .forward_kinematics_batch(pb::ForwardKinematicsBatchRequest {
            robot: named("ur5"),
            joint_positions: Some(matrix(&states)),
            include_jacobians: true,
        })
        .await
        .unwrap()
        .into_inner();
    let poses = batch.tool_poses.unwrap();
    assert_eq!((poses.rows, poses.cols), (40, 7));
    let jac = batch.jacobians.unwrap();
    assert_eq!((jac.rows, jac.cols), (40, 36));
    for (i, q) in states.iter().enumerate() {
        let single = robots
            .forward_kinematics(pb::ForwardKinematicsRequest {
                robot: named("ur5"),
                joint_positions: q.clone(),
                include_links: false,
            })
            .await
            .unwrap()
            .into_inner()
            .tool_pose
            .unwrap();
        let p = single.position.unwrap();
        let o = single.orientation.unwrap();
        let row = &poses.data[i * 7..i * 7 + 7];
        for (a, b) in row.iter().zip([p.x, p.y, p.z, o.x, o.y, o.z, o.w]) {
            assert!((a - b).abs() < 1e-12, "state {i}");
        }
    }
    // finite differences of positions for state 3, joint by joint
    let h = 1e-6;
    let q = &states[3];
    let mut plus_minus = Vec::new();
    for j in 0..dof {
        for s in [h, -h] {
            let mut x = q.clone();
            x[j] += s;
            plus_minus.push(x);
        }
    }
    let fd = robots
        .forward_kinematics_batch(pb::ForwardKinematicsBatchRequest {
            robot: named("ur5"),
            joint_positions: Some(matrix(&plus_minus)),
            include_jacobians: false,
        })
        .await
        .unwrap()
        .into_inner()
        .tool_poses
        .unwrap();
    let j3 = &jac.data[3 * 36..4 * 36];
    for j in 0..dof {
        for r in 0..3 {
            let d = (fd.data[(2 * j) * 7 + r] - fd.data[(2 * j + 1) * 7 + r]) / (2.0 * h);
            assert!((d - j3[r * dof + j]).abs() < 1e-6, "J[{r},{j}]");
        }
    }
    // bad shapes and values are named
    let bad = robots
        .forward_kinematics_batch(pb::ForwardKinematicsBatchRequest {
            robot: named("ur5"),
            joint_positions: Some(pb::Matrix {
                rows: 2,
                cols: 6,
                data: [vec![0.0; 6], vec![0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0]].concat(),
            }),
            include_jacobians: false,
        })
        .await
        .unwrap_err();
    assert_eq!(bad.code(), Code::InvalidArgument);
    assert!(
        bad.message().contains("joint_positions[1][2]"),
        "{}",
        bad.message()
    );
    let bad = robots
        .forward_kinematics_batch(pb::ForwardKinematicsBatchRequest {
            robot: named("ur5"),
            joint_positions: Some(pb::Matrix {
                rows: 1,
                cols: 5,
                data: vec![0.0; 5],
            }),
            include_jacobians: false,
        })
        .await
        .unwrap_err();
    assert!(
        bad.message().contains("joint_positions.cols"),
        "{}",
        bad.message()
    );
    // 40,000 states with Jacobians would need 1.72 million reply values
    let big = robots
        .forward_kinematics_batch(pb::ForwardKinematicsBatchRequest {
            robot: named("ur5"),
            joint_positions: Some(pb::Matrix {
                rows: 40_000,
                cols: 6,
                data: vec![0.1; 240_000],
            }),
            include_jacobians: true,
        })
        .await
        .unwrap_err();
    assert_eq!(big.code(), Code::ResourceExhausted, "{}", big.message());
    assert!(
        big.message().contains("joint_positions.rows"),
        "{}",
        big.message()
    );
}

/// A built-in's URDF comes back as standard URDF (no <capsule>), which the
/// server itself reads back as the same robot; kept capsules on request.
#[tokio::test]
async fn a_builtin_urdf_round_trips_as_standard_urdf() {
    let server = start(ServerConfig::default()).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let reply = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named("kuka_kr210_r2700_extra"),
            include_urdf: true,
            keep_capsules: false,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert!(reply.urdf.contains("<cylinder") && !reply.urdf.contains("capsule"));
    let q = vec![0.2, -1.0, 1.1, 0.3, 0.7, -0.4];
    let fk = |robot: Option<pb::RobotRef>| pb::ForwardKinematicsRequest {
        robot,
        joint_positions: q.clone(),
        include_links: false,
    };
    let a = robots
        .forward_kinematics(fk(named("kuka_kr210_r2700_extra")))
        .await
        .unwrap()
        .into_inner();
    let inline = Some(pb::RobotRef {
        source: Some(Source::Urdf(reply.urdf.clone())),
        ..Default::default()
    });
    let b = robots.forward_kinematics(fk(inline)).await.unwrap().into_inner();
    assert_eq!(a.tool_pose, b.tool_pose);
    let kept = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named("kuka_kr210_r2700_extra"),
            include_urdf: true,
            keep_capsules: true,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert!(kept.urdf.contains("<capsule"));
    // without include_urdf the reply stays small
    let plain = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named("ur5"),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert!(plain.urdf.is_empty());
}
