//! The analytic IK method over gRPC: every solution of a pose (each checked with
//! the server's forward kinematics), ranked by distance to the seed, with
//! configuration flags; DescribeRobot's family; refusals; and StreamIk along
//! S2's circle keeping one configuration.

use std::f64::consts::PI;

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, kinematics_service_client::KinematicsServiceClient, robot_service_client::RobotServiceClient,
};
use nalgebra::{Isometry3, Translation3, Vector3};
use tonic::Code;

use crate::poses::{fk, pose_pb};
use crate::{named, start};

fn analytic(num_solutions: u32) -> Option<pb::IkOptions> {
    Some(pb::IkOptions {
        method: pb::IkMethod::Analytic as i32,
        num_solutions,
        ..Default::default()
    })
}

/// The robot's description (its analytic family and why not).
async fn describe(server: &crate::TestServer, robot: Option<pb::RobotRef>) -> pb::DescribeRobotResponse {
    RobotServiceClient::new(server.channel.clone())
        .describe_robot(pb::DescribeRobotRequest {
            robot,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner()
}

#[tokio::test]
async fn analytic_ik_returns_every_solution_ranked_with_flags() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    for (name, q, expect) in [
        // ±185°/±350° KUKA joints: 8 configurations, A4 and A6 in two turns each where the
        // limits allow; the UR5's ±2π joints: each of the 8 in 2⁶ turn variants
        (
            "kuka_kr210_r2700_extra",
            vec![0.3, -1.2, 0.9, 0.4, 0.7, -0.3],
            None,
        ),
        ("ur5", vec![0.3, -1.2, 1.4, -0.8, 1.1, 0.2], Some(8 * 64)),
    ] {
        let target = fk(&mut robots, name, &q).await;
        let reply = ik
            .solve_ik(pb::SolveIkRequest {
                robot: named(name),
                target: Some(pose_pb(&target)),
                seed: q.clone(),
                options: analytic(1000),
            })
            .await
            .unwrap()
            .into_inner();
        assert!(reply.success, "{name}");
        if let Some(n) = expect {
            assert_eq!(reply.solutions.len(), n, "{name}");
        }
        // the seed's own configuration first, at distance zero
        let first = &reply.solutions[0];
        assert!(
            first.joints.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9),
            "{name}"
        );
        let dist = |s: &pb::IkSolution| s.joints.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
        assert!(
            reply.solutions.windows(2).all(|w| dist(&w[0]) <= dist(&w[1])),
            "{name}"
        );
        let mut flags = std::collections::HashSet::new();
        for (i, s) in reply.solutions.iter().enumerate() {
            // every answer reaches the pose by the server's own FK
            let got = fk(&mut robots, name, &s.joints).await;
            let dp = (got.translation.vector - target.translation.vector).norm();
            let dr = got.rotation.angle_to(&target.rotation);
            assert!(dp < 1e-9 && dr < 1e-9, "{name} solution {i}: {dp} m, {dr} rad");
            let c = s.config.unwrap();
            flags.insert((c.shoulder_back, c.elbow_down, c.wrist_flipped));
            assert_eq!(s.status, pb::IkStatus::Converged as i32);
            assert!(!s.singular);
            if i > 40 {
                break; // the server's FK per solution is slow in a debug build
            }
        }
        // solutions that differ only by whole turns share their flags; the
        // configurations differ
        assert!(flags.len() >= 2, "{name}: {flags:?}");
        // num_solutions = 1: the nearest
        let one = ik
            .solve_ik(pb::SolveIkRequest {
                robot: named(name),
                target: Some(pose_pb(&target)),
                seed: q.clone(),
                options: analytic(1),
            })
            .await
            .unwrap()
            .into_inner();
        assert_eq!(one.solutions.len(), 1);
        assert_eq!(one.solutions[0].joints, first.joints);
    }
}

#[tokio::test]
async fn describe_robot_names_the_family_and_refusals_name_the_reason() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    for (name, family) in [
        ("kuka_kr210_r2700_extra", "spherical_wrist"),
        ("kuka_kr120_r2500_pro", "spherical_wrist"),
        ("abb_irb4600_60_205", "spherical_wrist"),
        ("ur5", "three_parallel"),
        // held at the middle of its limits (0), joint 3 leaves axes 2 and 4 parallel
        ("kuka_lbr_iiwa14_r820", "spherical_wrist"),
        // joint 7 held, read from the tool end
        ("franka_panda", "spherical_two_intersecting"),
        ("planar_7", ""),
    ] {
        let d = describe(&server, named(name)).await;
        assert_eq!(d.analytic_family, family, "{name}");
        assert_eq!(
            d.analytic_reason.is_empty(),
            !family.is_empty(),
            "{name}: {}",
            d.analytic_reason
        );
        assert_eq!(d.analytic_reversed, name == "franka_panda", "{name}");
        if name == "franka_panda" {
            assert_eq!(d.analytic_held_joint, 6);
        }
    }
    // the iiwa with joint 3 held at the seed's value: every solution keeps it
    let q = vec![0.3, 0.6, -0.4, -1.1, 0.5, 0.8, 0.2];
    let target = fk(&mut robots, "kuka_lbr_iiwa14_r820", &q).await;
    let reply = ik
        .solve_ik(pb::SolveIkRequest {
            robot: named("kuka_lbr_iiwa14_r820"),
            target: Some(pose_pb(&target)),
            seed: q.clone(),
            options: analytic(1000),
        })
        .await
        .unwrap()
        .into_inner();
    assert!(reply.success);
    assert!(
        reply.solutions[0]
            .joints
            .iter()
            .zip(&q)
            .all(|(a, b)| (a - b).abs() < 1e-9)
    );
    for s in &reply.solutions {
        assert_eq!(s.joints[2], q[2]);
        let got = fk(&mut robots, "kuka_lbr_iiwa14_r820", &s.joints).await;
        assert!((got.translation.vector - target.translation.vector).norm() < 1e-9);
        assert!(got.rotation.angle_to(&target.rotation) < 1e-9);
    }
    // a 7-joint arm none of whose joints can be held: INVALID_ARGUMENT naming options.method and the reason
    let q = vec![0.1; 7];
    let target = fk(&mut robots, "planar_7", &q).await;
    let status = ik
        .solve_ik(pb::SolveIkRequest {
            robot: named("planar_7"),
            target: Some(pose_pb(&target)),
            seed: vec![],
            options: analytic(1),
        })
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(
        status.message().contains("chain is not analytic"),
        "{}",
        status.message()
    );
    assert!(
        status.message().starts_with("options.method"),
        "{}",
        status.message()
    );
    // position-only targets cannot be served
    let status = ik
        .solve_ik(pb::SolveIkRequest {
            robot: named("ur5"),
            target: Some(pose_pb(&Isometry3::translation(0.4, 0.1, 0.3))),
            seed: vec![],
            options: Some(pb::IkOptions {
                method: pb::IkMethod::Analytic as i32,
                position_only: true,
                ..Default::default()
            }),
        })
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(status.message().contains("full pose"), "{}", status.message());
    // out of reach: no solution, a flagged least-squares best attempt, no NaN
    let reply = ik
        .solve_ik(pb::SolveIkRequest {
            robot: named("ur5"),
            target: Some(pose_pb(&Isometry3::translation(3.0, 0.0, 0.0))),
            seed: vec![],
            options: analytic(8),
        })
        .await
        .unwrap()
        .into_inner();
    assert!(!reply.success && reply.solutions.is_empty());
    assert_eq!(reply.status, pb::IkStatus::MaxIterations as i32);
    let best = reply.best_attempt.unwrap();
    assert!(best.joints.iter().all(|v| v.is_finite()) && best.position_error > 1.0);
}

/// The Panda with joint 7 held at the seed's value, and searched for the
/// solution nearest the seed; a bad sample count is refused by name.
#[tokio::test]
async fn panda_analytic_holds_or_searches_joint_7() {
    let server = start(ServerConfig::default()).await;
    let ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let q = vec![0.2, -0.4, 0.3, -2.1, 0.4, 1.8, 0.5];
    let target = fk(&mut robots, "franka_panda", &q).await;
    // the seed: the pose's joints with joint 7 moved by 0.4 rad
    let mut seed = q.clone();
    seed[6] += 0.4;
    let dist = |a: &[f64]| a.iter().zip(&seed).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
    let solve = |options: pb::IkOptions| {
        let request = pb::SolveIkRequest {
            robot: named("franka_panda"),
            target: Some(pose_pb(&target)),
            seed: seed.clone(),
            options: Some(options),
        };
        let mut ik = ik.clone();
        async move { ik.solve_ik(request).await }
    };
    let held = solve(analytic(1000).unwrap()).await.unwrap().into_inner();
    assert!(held.success);
    for s in &held.solutions {
        assert_eq!(s.joints[6], seed[6]);
        let got = fk(&mut robots, "franka_panda", &s.joints).await;
        assert!((got.translation.vector - target.translation.vector).norm() < 1e-9);
        assert!(got.rotation.angle_to(&target.rotation) < 1e-9);
    }
    let searched = solve(pb::IkOptions {
        search_redundant: true,
        ..analytic(1000).unwrap()
    })
    .await
    .unwrap()
    .into_inner();
    assert!(searched.success);
    let best = &searched.solutions[0].joints;
    let got = fk(&mut robots, "franka_panda", best).await;
    assert!((got.translation.vector - target.translation.vector).norm() < 1e-9);
    // at least as near as the pose's own joints (0.4 rad away), nearer than holding
    assert!(dist(best) <= dist(&q) + 1e-12, "{best:?}");
    assert!(dist(best) <= dist(&held.solutions[0].joints) + 1e-12);
    let status = solve(pb::IkOptions {
        search_redundant: true,
        redundant_samples: Some(1),
        ..analytic(1).unwrap()
    })
    .await
    .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(
        status.message().starts_with("options.redundant_samples"),
        "{}",
        status.message()
    );
    drop(ik);
}

#[tokio::test]
async fn stream_ik_analytic_keeps_one_configuration_along_s2s_circle() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    for (name, seed) in [
        ("kuka_kr210_r2700_extra", vec![0.2, -1.6, 1.7, 0.3, 0.8, -0.2]),
        ("ur5", vec![0.4, -1.1, 1.3, -0.6, 1.2, 0.3]),
    ] {
        let start = fk(&mut robots, name, &seed).await;
        // S2: a 10 mm circle in steps of π/50 from the tool pose at the seed
        let centre = start.translation.vector - Vector3::new(0.01, 0.0, 0.0);
        let (tx, rx) = tokio::sync::mpsc::channel(8);
        let mut answers = ik
            .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
            .await
            .unwrap()
            .into_inner();
        let mut previous = seed.clone();
        let mut config = None;
        for k in 0..=100u64 {
            let a = k as f64 * PI / 50.0;
            let p = centre + Vector3::new(a.cos(), a.sin(), 0.0) * 0.01;
            let target = Isometry3::from_parts(Translation3::from(p), start.rotation);
            let first = k == 0;
            tx.send(pb::StreamIkRequest {
                sequence: k,
                robot: if first { named(name) } else { None },
                options: if first { analytic(1) } else { None },
                seed: if first { seed.clone() } else { Vec::new() },
                target: Some(pose_pb(&target)),
            })
            .await
            .unwrap();
            let result = answers.message().await.unwrap().unwrap().result.unwrap();
            assert!(result.success, "{name} step {k}");
            let s = &result.solutions[0];
            assert!(s.position_error < 1e-9 && s.orientation_error < 1e-9);
            let jump = s
                .joints
                .iter()
                .zip(&previous)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(jump < 0.1, "{name} step {k}: joint jump {jump} rad");
            let c = s.config.unwrap();
            assert_eq!(
                *config.get_or_insert(c),
                c,
                "{name} step {k}: configuration changed"
            );
            previous = s.joints.clone();
        }
        drop(tx);
    }
}

/// An offset-wrist 6R arm given inline: DescribeRobot names the searched
/// family, and the analytic method returns solutions that the server's own
/// forward kinematics puts on the pose, the seed's configuration first.
#[tokio::test]
async fn offset_wrist_arm_is_searched_and_its_solutions_reach_the_pose() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let robot = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(
            include_str!("../../benches/analytic_ik/offset_wrist_45.urdf").into(),
        )),
        ..Default::default()
    });
    let d = describe(&server, robot.clone()).await;
    assert_eq!(d.analytic_family, "searched_6r");
    assert!(d.analytic_reason.is_empty(), "{}", d.analytic_reason);
    assert!(!d.analytic_reversed);
    let fk_inline = |q: Vec<f64>| pb::ForwardKinematicsRequest {
        robot: robot.clone(),
        joint_positions: q,
        include_links: false,
    };
    let q = vec![0.4, -0.9, 0.7, 1.0, 0.8, -0.5];
    let pose = robots
        .forward_kinematics(fk_inline(q.clone()))
        .await
        .unwrap()
        .into_inner()
        .tool_pose;
    let reply = ik
        .solve_ik(pb::SolveIkRequest {
            robot: robot.clone(),
            target: pose,
            seed: q.clone(),
            options: analytic(1000),
        })
        .await
        .unwrap()
        .into_inner();
    assert!(reply.success);
    assert!(reply.solutions.len() >= 2);
    assert!(
        reply.solutions[0]
            .joints
            .iter()
            .zip(&q)
            .all(|(a, b)| (a - b).abs() < 1e-8)
    );
    let target = crate::poses::iso(pose.as_ref().unwrap());
    for s in &reply.solutions {
        assert!(s.config.is_some());
        let got = robots
            .forward_kinematics(fk_inline(s.joints.clone()))
            .await
            .unwrap()
            .into_inner();
        let got = crate::poses::iso(got.tool_pose.as_ref().unwrap());
        assert!((got.translation.vector - target.translation.vector).norm() < 1e-9);
        assert!(got.rotation.angle_to(&target.rotation) < 1e-9);
    }
    // the searched joint's sampling density: denser sampling finds the same
    // solutions here, a count below 8 is refused naming the field
    let with_samples = |n: u32| pb::SolveIkRequest {
        robot: robot.clone(),
        target: pose,
        seed: q.clone(),
        options: Some(pb::IkOptions {
            search_samples: Some(n),
            ..analytic(1000).unwrap()
        }),
    };
    let dense = ik.solve_ik(with_samples(1024)).await.unwrap().into_inner();
    assert_eq!(dense.solutions.len(), reply.solutions.len());
    for (a, b) in dense.solutions.iter().zip(&reply.solutions) {
        assert!(a.joints.iter().zip(&b.joints).all(|(x, y)| (x - y).abs() < 1e-9));
    }
    for bad in [4, 5000] {
        let status = ik.solve_ik(with_samples(bad)).await.unwrap_err();
        assert_eq!(status.code(), Code::InvalidArgument);
        assert!(
            status.message().starts_with("options.search_samples"),
            "{}",
            status.message()
        );
    }
}

/// A general 6R arm (the offset-wrist arm with axis 5 moved off axis 4: no
/// two consecutive wrist axes meet, from either end) has no analytic family;
/// DescribeRobot says why and the analytic method refuses it by name.
#[tokio::test]
async fn general_6r_arm_is_not_analytic() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let urdf = include_str!("../../benches/analytic_ik/offset_wrist_45.urdf").replace(
        r#"<origin xyz="0.6 0 0"/><axis xyz="0 1 0"/>"#,
        r#"<origin xyz="0.6 0 0.07"/><axis xyz="0 1 0"/>"#,
    );
    assert!(urdf.contains("0.6 0 0.07"));
    let robot = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(urdf)),
        ..Default::default()
    });
    let d = describe(&server, robot.clone()).await;
    assert_eq!(d.analytic_family, "");
    assert!(
        d.analytic_reason.contains("2-D search is not implemented"),
        "{}",
        d.analytic_reason
    );
    let status = ik
        .solve_ik(pb::SolveIkRequest {
            robot,
            target: Some(pose_pb(&Isometry3::translation(0.5, 0.1, 0.6))),
            seed: vec![],
            options: analytic(8),
        })
        .await
        .unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(
        status.message().starts_with("options.method") && status.message().contains("chain is not analytic"),
        "{}",
        status.message()
    );
}
