//! KinematicsService over gRPC. Every IK answer is checked independently of the
//! solver: the returned joints go back through RobotService.ForwardKinematics (or
//! `Chain::fk` for long paths) and must land on the target. Linear systems are
//! checked against hand-solved answers. Then determinism, distinct solutions, time
//! budgets and deadlines, path continuity, the bidirectional stream, and every
//! class of bad input.

use std::f64::consts::PI;
use std::time::{Duration, Instant};

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, kinematics_service_client::KinematicsServiceClient, robot_service_client::RobotServiceClient,
};
use nalgebra::{Isometry3, Translation3, Vector3};
use rand::{Rng, SeedableRng};
use tonic::Code;
use tonic::transport::Channel;
use tonic_types::StatusExt;

use crate::poses::{fk, iso, pose_pb};
use crate::{named, start};

/// Position (m) and rotation angle (rad) between two poses.
fn distance(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// Joints drawn uniformly inside the limits of a built-in arm.
fn random_joints(name: &str, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<f64> {
    let chain = kinplan_core::robot::builtin_chain(name).unwrap();
    chain
        .joints()
        .iter()
        .map(|j| {
            let (lo, hi) = (j.lower.max(-PI), j.upper.min(PI));
            rng.random_range(lo..=hi)
        })
        .collect()
}

fn ik_request(name: &str, target: &Isometry3<f64>, options: pb::IkOptions) -> pb::SolveIkRequest {
    pb::SolveIkRequest {
        robot: named(name),
        target: Some(pose_pb(target)),
        seed: Vec::new(),
        options: Some(options),
    }
}

fn method(m: pb::IkMethod, solver: pb::LinearSolver) -> pb::IkOptions {
    pb::IkOptions {
        method: m as i32,
        linear_solver: solver as i32,
        ..Default::default()
    }
}

/// Checks one answer against the target with the server's forward kinematics.
async fn assert_reaches(
    robots: &mut RobotServiceClient<Channel>,
    name: &str,
    s: &pb::IkSolution,
    target: &Isometry3<f64>,
    position_only: bool,
    tol: f64,
    what: &str,
) {
    let got = fk(robots, name, &s.joints).await;
    let (dp, dr) = distance(&got, target);
    assert!(dp <= tol, "{what}: FK position off by {dp} m");
    assert!(
        (dp - s.position_error).abs() < 1e-9,
        "{what}: reported {} vs {dp}",
        s.position_error
    );
    if !position_only {
        assert!(dr <= tol, "{what}: FK orientation off by {dr} rad");
        assert!(
            (dr - s.orientation_error).abs() < 1e-6,
            "{what}: reported {} vs {dr}",
            s.orientation_error
        );
    }
    assert_eq!(s.status, pb::IkStatus::Converged as i32, "{what}");
}

#[tokio::test]
async fn fk_of_ik_is_the_target_on_several_arms() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for name in kinplan_core::robot::ARM_NAMES {
        let chain = kinplan_core::robot::builtin_chain(name).unwrap();
        for k in 0..4 {
            let q = random_joints(name, &mut rng);
            let target = fk(&mut robots, name, &q).await;
            let reply = ik
                .solve_ik(ik_request(name, &target, Default::default()))
                .await
                .unwrap()
                .into_inner();
            assert!(reply.success, "{name} #{k}: {reply:?}");
            assert_eq!(reply.status, pb::IkStatus::Converged as i32);
            assert!(reply.best_attempt.is_none());
            let s = &reply.solutions[0];
            assert_eq!(s.joints.len(), chain.dof());
            // default tolerance 1e-5 m and rad, joint limits clamped
            assert_reaches(
                &mut robots,
                name,
                s,
                &target,
                false,
                1e-5,
                &format!("{name} #{k}"),
            )
            .await;
            for (v, j) in s.joints.iter().zip(chain.joints()) {
                assert!(
                    *v >= j.lower && *v <= j.upper,
                    "{name}: joint {} = {v} outside limits",
                    j.name
                );
            }
        }
    }
}

#[tokio::test]
async fn every_method_that_claims_a_target_reaches_it() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let q = [0.4, -1.1, 1.3, -0.6, 1.2, 0.3];
    let target = fk(&mut robots, "ur5", &q).await;
    use pb::IkMethod as M;
    use pb::LinearSolver as L;
    // full pose: the Jacobian methods with either solver, and CCD
    let pose_methods = [
        (M::JacobianInverse, L::SvdPseudoinverse, true),
        (M::LevenbergMarquardt, L::SvdPseudoinverse, true),
        (M::Newton, L::SvdPseudoinverse, true),
        (M::JacobianInverse, L::AngleRelaxation, false),
        (M::LevenbergMarquardt, L::AngleRelaxation, false),
        (M::LevenbergMarquardt, L::AngleRelaxationSafeguarded, false),
        (M::Ccd, L::Unspecified, false),
    ];
    let mut converged = 0;
    for (m, l, must) in pose_methods {
        let options = pb::IkOptions {
            time_budget: Some(3.0),
            ..method(m, l)
        };
        let reply = ik
            .solve_ik(ik_request("ur5", &target, options))
            .await
            .unwrap()
            .into_inner();
        let what = format!("{m:?} + {l:?}");
        if must {
            assert!(reply.success, "{what}: {reply:?}");
        }
        if reply.success {
            converged += 1;
            assert_reaches(
                &mut robots,
                "ur5",
                &reply.solutions[0],
                &target,
                false,
                1e-5,
                &what,
            )
            .await;
        } else {
            let best = reply.best_attempt.as_ref().expect("best attempt flagged");
            assert!(reply.solutions.is_empty() && best.status != pb::IkStatus::Converged as i32);
        }
    }
    assert!(converged >= 5, "only {converged} of 7 pose methods converged");

    // Newton + RLXA does not converge (S2 says so): the best attempt comes back, flagged
    let options = pb::IkOptions {
        max_restarts: Some(1),
        ..method(M::Newton, L::AngleRelaxation)
    };
    let reply = ik
        .solve_ik(ik_request("ur5", &target, options))
        .await
        .unwrap()
        .into_inner();
    if !reply.success {
        let best = reply.best_attempt.expect("best attempt when nothing converged");
        assert_eq!(best.joints.len(), 6);
        assert!(best.position_error > 0.0);
        assert_eq!(reply.status, pb::IkStatus::MaxIterations as i32);
        assert_eq!(reply.attempts, 2);
    }

    // position targets: the heuristics on a planar chain and on a 3-D arm
    for (name, q) in [
        ("planar_6", vec![0.3, 0.4, -0.2, 0.5, 0.1, 0.3]),
        ("kuka_lbr_iiwa14_r820", vec![0.3, 0.5, -0.2, -1.1, 0.4, 0.8, 0.1]),
    ] {
        let target = fk(&mut robots, name, &q).await;
        for m in [M::LevenbergMarquardt, M::Ccd, M::Fabrik, M::LengthRelaxation] {
            let options = pb::IkOptions {
                position_only: true,
                time_budget: Some(5.0),
                ..method(m, L::Unspecified)
            };
            let reply = ik
                .solve_ik(ik_request(name, &target, options))
                .await
                .unwrap()
                .into_inner();
            let what = format!("{name} {m:?} position");
            assert!(reply.success, "{what}: {reply:?}");
            let s = &reply.solutions[0];
            assert_eq!(s.orientation_error, 0.0, "{what}");
            assert_reaches(&mut robots, name, s, &target, true, 1e-5, &what).await;
        }
    }
}

#[tokio::test]
async fn same_request_same_answer_and_distinct_solutions() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let q = [1.0, -0.7, 1.9, 0.5, -1.0, 2.0];
    let target = fk(&mut robots, "ur5", &q).await;
    let seed = vec![0.0, -1.5, 1.5, 0.0, 0.0, 0.0];
    let request = pb::SolveIkRequest {
        seed: seed.clone(),
        options: Some(pb::IkOptions {
            num_solutions: 4,
            rng_seed: 42,
            ..Default::default()
        }),
        ..ik_request("ur5", &target, Default::default())
    };
    let strip = |mut r: pb::SolveIkResponse| {
        r.elapsed_us = 0;
        r.solutions.iter_mut().for_each(|s| s.elapsed_us = 0);
        r
    };
    let a = strip(ik.solve_ik(request.clone()).await.unwrap().into_inner());
    let b = strip(ik.solve_ik(request.clone()).await.unwrap().into_inner());
    assert_eq!(a, b, "same request, same answer");
    assert!(a.success);
    assert_eq!(a.solutions.len(), 4, "UR5 has 8 solutions for a generic pose");
    assert_eq!(a.status, pb::IkStatus::Converged as i32);
    let dist = |s: &pb::IkSolution| {
        s.joints
            .iter()
            .zip(&seed)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
    };
    for (i, s) in a.solutions.iter().enumerate() {
        assert_reaches(
            &mut robots,
            "ur5",
            s,
            &target,
            false,
            1e-5,
            &format!("solution {i}"),
        )
        .await;
        for other in &a.solutions[..i] {
            let max_diff = s
                .joints
                .iter()
                .zip(&other.joints)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(max_diff >= 1e-3, "solutions must be distinct");
        }
        if i > 0 {
            assert!(
                dist(&a.solutions[i - 1]) <= dist(s),
                "ranked by distance to the seed"
            );
        }
    }
    // another RNG seed still finds correct (possibly other) solutions
    let mut other = request.clone();
    other.options.as_mut().unwrap().rng_seed = 7;
    let c = ik.solve_ik(other).await.unwrap().into_inner();
    assert!(c.success);
}

#[tokio::test]
async fn time_budgets_and_deadlines_end_promptly_with_a_status() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    // 10 m away: out of reach, so only the clock can end the search
    let target = Isometry3::translation(10.0, 0.0, 0.5);
    let endless = pb::IkOptions {
        max_restarts: Some(u32::MAX),
        ..Default::default()
    };
    // explicit budget
    let started = Instant::now();
    let reply = ik
        .solve_ik(ik_request(
            "kuka_kr210_r2700_extra",
            &target,
            pb::IkOptions {
                time_budget: Some(0.05),
                ..endless
            },
        ))
        .await
        .unwrap()
        .into_inner();
    let wall = started.elapsed();
    assert!(!reply.success);
    assert_eq!(reply.status, pb::IkStatus::TimeBudget as i32);
    let best = reply.best_attempt.expect("best attempt, flagged");
    assert!(best.position_error > 7.0, "{best:?}");
    assert!(
        reply.elapsed_us >= 50_000 && reply.elapsed_us < 1_000_000,
        "{}",
        reply.elapsed_us
    );
    assert!(wall < Duration::from_secs(1), "{wall:?}");

    // the gRPC deadline is the budget: the answer arrives before it
    let mut request = tonic::Request::new(ik_request("kuka_kr210_r2700_extra", &target, endless));
    request.set_timeout(Duration::from_millis(500));
    let started = Instant::now();
    let reply = ik
        .solve_ik(request)
        .await
        .expect("an answer, not DEADLINE_EXCEEDED")
        .into_inner();
    let wall = started.elapsed();
    assert_eq!(reply.status, pb::IkStatus::TimeBudget as i32);
    assert!(reply.best_attempt.is_some() && !reply.success);
    assert!(wall < Duration::from_millis(500), "{wall:?}");
    // budget = the deadline less a reserve of a tenth (50 ms here)
    assert!(
        reply.elapsed_us >= 400_000,
        "used most of the deadline: {}",
        reply.elapsed_us
    );

    // a batch under a deadline: every target answers, those cut end TIME_BUDGET
    let mut request = tonic::Request::new(pb::SolveIkBatchRequest {
        seeds: None,
        robot: named("kuka_kr210_r2700_extra"),
        targets: vec![pose_pb(&target); 8],
        seed: Vec::new(),
        options: Some(endless),
    });
    // a longer deadline than above: the reserve (a tenth) must also absorb
    // the CPU pool waiting behind the other tests of this binary
    request.set_timeout(Duration::from_millis(1500));
    let reply = ik.solve_ik_batch(request).await.unwrap().into_inner();
    assert_eq!(reply.results.len(), 8);
    assert_eq!(reply.succeeded, 0);
    for r in &reply.results {
        assert_eq!(r.status, pb::IkStatus::TimeBudget as i32, "{r:?}");
    }
}

#[tokio::test]
async fn batch_answers_every_target_in_order() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut targets = Vec::new();
    for _ in 0..12 {
        let q = random_joints("kuka_kr210_r2700_extra", &mut rng);
        targets.push(fk(&mut robots, "kuka_kr210_r2700_extra", &q).await);
    }
    let request = pb::SolveIkBatchRequest {
        seeds: None,
        robot: named("kuka_kr210_r2700_extra"),
        targets: targets.iter().map(pose_pb).collect(),
        seed: Vec::new(),
        options: Some(pb::IkOptions {
            rng_seed: 5,
            ..Default::default()
        }),
    };
    let reply = ik.solve_ik_batch(request.clone()).await.unwrap().into_inner();
    assert_eq!(reply.results.len(), 12);
    assert_eq!(reply.succeeded, 12);
    for (i, (r, t)) in reply.results.iter().zip(&targets).enumerate() {
        assert_reaches(
            &mut robots,
            "kuka_kr210_r2700_extra",
            &r.solutions[0],
            t,
            false,
            1e-5,
            &format!("batch target {i}"),
        )
        .await;
    }
    // parallel, yet deterministic
    let again = ik.solve_ik_batch(request).await.unwrap().into_inner();
    for (a, b) in reply.results.iter().zip(&again.results) {
        assert_eq!(a.solutions[0].joints, b.solutions[0].joints);
        assert_eq!(a.attempts, b.attempts);
    }
}

#[tokio::test]
async fn track_path_follows_a_circle_continuously() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let name = "kuka_kr210_r2700_extra";
    let chain = kinplan_core::robot::builtin_chain(name).unwrap();
    let seed = vec![0.2, -1.6, 1.7, 0.3, 0.8, -0.2];
    let start = fk(&mut robots, name, &seed).await;
    // S2: a 10 mm circle, steps of pi/50, from the tool pose at the seed
    let centre = start.translation.vector - Vector3::new(0.01, 0.0, 0.0);
    let steps = 100;
    let reply = ik
        .track_path(pb::TrackPathRequest {
            robot: named(name),
            circle: Some(pb::CirclePath {
                start: None,
                centre: Some(pb::Vec3 {
                    x: centre.x,
                    y: centre.y,
                    z: centre.z,
                }),
                normal: Some(pb::Vec3 {
                    x: 0.0,
                    y: 0.0,
                    z: 2.0,
                }),
                angle_step: PI / 50.0,
                steps,
            }),
            seed: seed.clone(),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.steps.len(), steps as usize + 1);
    assert!(reply.all_converged, "{:?}", reply.status);
    assert_eq!(reply.status, pb::IkStatus::Converged as i32);
    let mut previous = seed.clone();
    let mut largest: f64 = 0.0;
    for (k, s) in reply.steps.iter().enumerate() {
        let target = iso(s.target.as_ref().unwrap());
        // the path itself: on the 10 mm circle, in the start's plane, start's orientation
        let r = target.translation.vector - centre;
        assert!((r.norm() - 0.01).abs() < 1e-12 && r.z.abs() < 1e-12, "step {k}");
        let angle = (k as f64 * PI / 50.0).rem_euclid(2.0 * PI);
        let expect = Vector3::new(angle.cos(), angle.sin(), 0.0) * 0.01;
        assert!((r - expect).norm() < 1e-12, "step {k}: {r:?}");
        assert!(target.rotation.angle_to(&start.rotation) < 1e-12);
        // the joints reach it
        let (dp, dr) = distance(&chain.fk(&s.joints), &target);
        assert!(dp <= 1e-5 && dr <= 1e-5, "step {k}: {dp} m, {dr} rad");
        let jump = s
            .joints
            .iter()
            .zip(&previous)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!((jump - s.max_joint_step).abs() < 1e-12, "step {k}");
        largest = largest.max(jump);
        previous = s.joints.clone();
    }
    assert!((largest - reply.max_joint_step).abs() < 1e-12);
    // continuity: a 10 mm circle in 100 steps needs small joint steps only
    assert!(reply.max_joint_step < 0.05, "{}", reply.max_joint_step);
    // spot check with the server's FK
    let last = reply.steps.last().unwrap();
    let (dp, _) = distance(
        &fk(&mut robots, name, &last.joints).await,
        &iso(last.target.as_ref().unwrap()),
    );
    assert!(dp <= 1e-5);

    // a line given by its end, and the same path as explicit poses
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.0, 0.1, -0.05)),
        start.rotation,
    );
    let line = ik
        .track_path(pb::TrackPathRequest {
            robot: named(name),
            line: Some(pb::LinePath {
                start: None,
                end: Some(pose_pb(&end)),
                steps: 20,
            }),
            seed: seed.clone(),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert!(line.all_converged);
    assert_eq!(line.steps.len(), 21);
    let poses: Vec<pb::Pose> = line.steps.iter().map(|s| s.target.unwrap()).collect();
    let explicit = ik
        .track_path(pb::TrackPathRequest {
            robot: named(name),
            poses,
            seed,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert!(explicit.all_converged);
    for (a, b) in line.steps.iter().zip(&explicit.steps) {
        assert_eq!(a.joints, b.joints);
    }
    let (dp, _) = distance(&chain.fk(&line.steps[20].joints), &end);
    assert!(dp <= 1e-5);
}

#[tokio::test]
async fn stream_ik_answers_each_target_warm_started() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let name = "ur5";
    let seed = vec![0.4, -1.1, 1.3, -0.6, 1.2, 0.3];
    let start = fk(&mut robots, name, &seed).await;
    let (tx, rx) = tokio::sync::mpsc::channel(8);
    let mut answers = ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await
        .unwrap()
        .into_inner();
    let mut previous = seed.clone();
    // a controller: one target per cycle, 2 mm apart, answered before the next
    for k in 0..10u64 {
        let target = Isometry3::from_parts(
            Translation3::from(start.translation.vector + Vector3::new(0.002 * k as f64, 0.0, 0.0)),
            start.rotation,
        );
        let first = k == 0;
        tx.send(pb::StreamIkRequest {
            sequence: 100 + k,
            robot: if first { named(name) } else { None },
            options: first.then(|| pb::IkOptions {
                time_budget: Some(0.5),
                ..Default::default()
            }),
            seed: if first { seed.clone() } else { Vec::new() },
            target: Some(pose_pb(&target)),
        })
        .await
        .unwrap();
        let answer = answers.message().await.unwrap().expect("an answer per target");
        assert_eq!(answer.sequence, 100 + k);
        let result = answer.result.unwrap();
        assert!(result.success, "target {k}");
        let s = &result.solutions[0];
        assert_eq!(s.attempt, 0, "warm start: no restart needed");
        assert_reaches(&mut robots, name, s, &target, false, 1e-5, &format!("stream {k}")).await;
        let jump = s
            .joints
            .iter()
            .zip(&previous)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(jump < 0.05, "target {k}: joint step {jump}");
        previous = s.joints.clone();
    }
    drop(tx);
    assert!(
        answers.message().await.unwrap().is_none(),
        "the stream ends with the client's"
    );

    // a bad message ends the stream with INVALID_ARGUMENT naming the field; answers before it stand
    let (tx, rx) = tokio::sync::mpsc::channel(8);
    let mut answers = ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await
        .unwrap()
        .into_inner();
    tx.send(pb::StreamIkRequest {
        sequence: 1,
        robot: named(name),
        target: Some(pose_pb(&start)),
        ..Default::default()
    })
    .await
    .unwrap();
    assert!(answers.message().await.unwrap().unwrap().result.unwrap().success);
    let mut bad = pose_pb(&start);
    bad.orientation.as_mut().unwrap().w = 3.0;
    tx.send(pb::StreamIkRequest {
        sequence: 2,
        target: Some(bad),
        ..Default::default()
    })
    .await
    .unwrap();
    let status = answers.message().await.unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument);
    assert!(
        status.message().starts_with("target.orientation"),
        "{}",
        status.message()
    );
    assert!(status.message().contains("sequence 2"), "{}", status.message());
    assert_eq!(
        status.get_details_bad_request().unwrap().field_violations[0].field,
        "target.orientation"
    );

    // the first message must name a robot
    let (tx, rx) = tokio::sync::mpsc::channel(8);
    let mut answers = ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await
        .unwrap()
        .into_inner();
    tx.send(pb::StreamIkRequest {
        sequence: 9,
        robot: named("no_such_robot"),
        target: Some(pose_pb(&start)),
        ..Default::default()
    })
    .await
    .unwrap();
    let status = answers.message().await.unwrap_err();
    assert_eq!(status.code(), Code::NotFound, "{status:?}");
    assert!(status.message().starts_with("robot.name"));
}

fn linear(a: (u32, u32, Vec<f64>), b: Vec<f64>, m: pb::LinearSolver) -> pb::SolveLinearSystemRequest {
    pb::SolveLinearSystemRequest {
        a: Some(pb::Matrix {
            rows: a.0,
            cols: a.1,
            data: a.2,
        }),
        b,
        method: m as i32,
        ..Default::default()
    }
}

#[tokio::test]
async fn linear_systems_by_hand() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    use pb::LinearSolver as L;
    // 2x + y = 3, x + 3y = 5  =>  x = 0.8, y = 1.4 (row-major data)
    let square = (2, 2, vec![2.0, 1.0, 1.0, 3.0]);
    let svd = ik
        .solve_linear_system(linear(square.clone(), vec![3.0, 5.0], L::Unspecified))
        .await
        .unwrap()
        .into_inner();
    assert!(
        (svd.x[0] - 0.8).abs() < 1e-12 && (svd.x[1] - 1.4).abs() < 1e-12,
        "{:?}",
        svd.x
    );
    assert!(svd.residual_norm < 1e-12);
    assert_eq!(svd.status, pb::LinearSolveStatus::Converged as i32);
    for solver in [L::AngleRelaxation, L::AngleRelaxationSafeguarded] {
        let r = ik
            .solve_linear_system(pb::SolveLinearSystemRequest {
                tolerance: Some(1e-8),
                max_iterations: 200_000,
                record_history: true,
                rng_seed: 3,
                ..linear(square.clone(), vec![3.0, 5.0], solver)
            })
            .await
            .unwrap()
            .into_inner();
        assert_eq!(r.status, pb::LinearSolveStatus::Converged as i32, "{solver:?}");
        assert!(
            (r.x[0] - 0.8).abs() < 1e-6 && (r.x[1] - 1.4).abs() < 1e-6,
            "{solver:?}: {:?}",
            r.x
        );
        assert!(r.residual_norm < 1e-8);
        assert_eq!(r.residual_history.len(), r.iterations as usize);
        assert_eq!(*r.residual_history.last().unwrap(), r.residual_norm);
        let again = ik
            .solve_linear_system(pb::SolveLinearSystemRequest {
                tolerance: Some(1e-8),
                max_iterations: 200_000,
                record_history: true,
                rng_seed: 3,
                ..linear(square.clone(), vec![3.0, 5.0], solver)
            })
            .await
            .unwrap()
            .into_inner();
        assert_eq!(again.x, r.x, "seeded: same answer");
    }

    // inconsistent: x = 1, y = 1, x + y = 0 => least squares (1/3, 1/3), |r| = 2/sqrt(3)
    let tall = (3, 2, vec![1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    let ls = 2.0 / 3f64.sqrt();
    let svd = ik
        .solve_linear_system(linear(tall.clone(), vec![1.0, 1.0, 0.0], L::SvdPseudoinverse))
        .await
        .unwrap()
        .into_inner();
    assert!((svd.x[0] - 1.0 / 3.0).abs() < 1e-12 && (svd.x[1] - 1.0 / 3.0).abs() < 1e-12);
    assert!((svd.residual_norm - ls).abs() < 1e-12);
    let rlxa = ik
        .solve_linear_system(pb::SolveLinearSystemRequest {
            tolerance: Some(1e-9),
            max_iterations: 50_000,
            ..linear(tall, vec![1.0, 1.0, 0.0], L::AngleRelaxation)
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(
        rlxa.status,
        pb::LinearSolveStatus::IterationCap as i32,
        "cannot reach 1e-9"
    );
    assert_eq!(rlxa.iterations, 50_000);
    assert!(
        rlxa.residual_norm - ls < 1e-2 && rlxa.residual_norm >= ls - 1e-12,
        "{}",
        rlxa.residual_norm
    );

    // underdetermined: x + y = 2 and 2z = 2 => minimum norm (1, 1, 1)
    let wide = (2, 3, vec![1.0, 1.0, 0.0, 0.0, 0.0, 2.0]);
    for solver in [L::SvdPseudoinverse, L::AngleRelaxation] {
        let r = ik
            .solve_linear_system(pb::SolveLinearSystemRequest {
                tolerance: Some(1e-8),
                max_iterations: 100_000,
                ..linear(wide.clone(), vec![2.0, 2.0], solver)
            })
            .await
            .unwrap()
            .into_inner();
        for v in &r.x {
            assert!((v - 1.0).abs() < 1e-6, "{solver:?}: {:?}", r.x);
        }
    }
}

fn assert_field(status: &tonic::Status, code: Code, field: &str, what: &str) {
    assert_eq!(status.code(), code, "{what}: {status:?}");
    assert!(
        status.message().starts_with(field),
        "{what}: {}",
        status.message()
    );
    let details = status.get_details_bad_request().expect("BadRequest details");
    assert_eq!(details.field_violations[0].field, field, "{what}");
}

#[tokio::test]
async fn bad_inputs_name_their_field_and_the_server_keeps_serving() {
    let server = start(ServerConfig::default()).await;
    let mut health = tonic_health::pb::health_client::HealthClient::new(server.channel.clone());
    let reply = health
        .check(tonic_health::pb::HealthCheckRequest {
            service: "kinplan.v1.KinematicsService".into(),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(
        reply.status(),
        tonic_health::pb::health_check_response::ServingStatus::Serving
    );
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let chain = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let target = chain.fk(&[0.1, -1.4, 1.5, 0.2, 0.5, 0.3]);
    let ok = ik_request("kuka_kr210_r2700_extra", &target, Default::default());
    let with = |f: &dyn Fn(&mut pb::SolveIkRequest)| {
        let mut r = ok.clone();
        f(&mut r);
        r
    };
    let opts = |o: pb::IkOptions| with(&|r| r.options = Some(o));
    let mut non_unit = pose_pb(&target);
    non_unit.orientation.as_mut().unwrap().x = 0.5;
    let mut nan = pose_pb(&target);
    nan.position.as_mut().unwrap().y = f64::NAN;
    let cases: Vec<(&str, pb::SolveIkRequest, Code, &str)> = vec![
        (
            "short seed",
            with(&|r| r.seed = vec![0.0; 5]),
            Code::InvalidArgument,
            "seed",
        ),
        (
            "NaN seed",
            with(&|r| r.seed = vec![0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]),
            Code::InvalidArgument,
            "seed[1]",
        ),
        (
            "NaN pose",
            with(&|r| r.target = Some(nan)),
            Code::InvalidArgument,
            "target.position.y",
        ),
        (
            "non-unit quaternion",
            with(&|r| r.target = Some(non_unit)),
            Code::InvalidArgument,
            "target.orientation",
        ),
        (
            "missing target",
            with(&|r| r.target = None),
            Code::InvalidArgument,
            "target",
        ),
        (
            "zero position tolerance",
            opts(pb::IkOptions {
                position_tolerance: Some(0.0),
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.position_tolerance",
        ),
        (
            "negative orientation tolerance",
            opts(pb::IkOptions {
                orientation_tolerance: Some(-1e-5),
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.orientation_tolerance",
        ),
        (
            "NaN damping",
            opts(pb::IkOptions {
                damping: Some(f64::NAN),
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.damping",
        ),
        (
            "negative time budget",
            opts(pb::IkOptions {
                time_budget: Some(-1.0),
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.time_budget",
        ),
        (
            "unknown method",
            opts(pb::IkOptions {
                method: 42,
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.method",
        ),
        (
            "unknown linear solver",
            opts(pb::IkOptions {
                linear_solver: 9,
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.linear_solver",
        ),
        (
            "unknown joint-limit mode",
            opts(pb::IkOptions {
                joint_limits: 7,
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.joint_limits",
        ),
        (
            "FABRIK with an orientation target",
            opts(pb::IkOptions {
                method: pb::IkMethod::Fabrik as i32,
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.method",
        ),
        (
            "length relaxation with an orientation target",
            opts(pb::IkOptions {
                method: pb::IkMethod::LengthRelaxation as i32,
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.method",
        ),
        (
            "zero RLXA iterations",
            opts(pb::IkOptions {
                linear_solver: pb::LinearSolver::AngleRelaxation as i32,
                rlxa_max_iterations: Some(0),
                ..Default::default()
            }),
            Code::InvalidArgument,
            "options.rlxa_max_iterations",
        ),
        (
            "missing robot",
            with(&|r| r.robot = None),
            Code::InvalidArgument,
            "robot",
        ),
        (
            "unknown robot",
            with(&|r| r.robot = named("kr1000")),
            Code::NotFound,
            "robot.name",
        ),
    ];
    for (what, req, code, field) in cases {
        let status = ik.solve_ik(req).await.unwrap_err();
        assert_field(&status, code, field, what);
        ik.solve_ik(ok.clone())
            .await
            .unwrap_or_else(|e| panic!("after {what}: {e:?}"));
    }

    let batch = |targets: Vec<pb::Pose>| pb::SolveIkBatchRequest {
        seeds: None,
        robot: named("kuka_kr210_r2700_extra"),
        targets,
        seed: Vec::new(),
        options: None,
    };
    let good = pose_pb(&target);
    let cases = vec![
        ("no targets", batch(vec![]), "targets"),
        ("too many targets", batch(vec![good; 10_001]), "targets"),
        (
            "too many solutions over the batch",
            pb::SolveIkBatchRequest {
                seeds: None,
                options: Some(pb::IkOptions {
                    num_solutions: 1_000,
                    ..Default::default()
                }),
                ..batch(vec![good; 200])
            },
            "options.num_solutions",
        ),
        (
            "NaN target",
            batch(vec![good, good, nan]),
            "targets[2].position.y",
        ),
        ("non-unit target", batch(vec![non_unit]), "targets[0].orientation"),
    ];
    for (what, req, field) in cases {
        let status = ik.solve_ik_batch(req).await.unwrap_err();
        assert_field(&status, Code::InvalidArgument, field, what);
    }

    let track = |f: &dyn Fn(&mut pb::TrackPathRequest)| {
        let mut r = pb::TrackPathRequest {
            robot: named("kuka_kr210_r2700_extra"),
            circle: Some(pb::CirclePath {
                start: None,
                centre: Some(pb::Vec3 {
                    x: 1.0,
                    y: 0.0,
                    z: 1.0,
                }),
                normal: Some(pb::Vec3 {
                    x: 0.0,
                    y: 0.0,
                    z: 1.0,
                }),
                angle_step: 0.1,
                steps: 10,
            }),
            ..Default::default()
        };
        f(&mut r);
        r
    };
    let cases: Vec<(&str, pb::TrackPathRequest, &str)> = vec![
        ("no path", track(&|r| r.circle = None), "poses"),
        ("two paths", track(&|r| r.poses = vec![good]), "poses"),
        (
            "zero normal",
            track(&|r| r.circle.as_mut().unwrap().normal = Some(Default::default())),
            "circle.normal",
        ),
        (
            "zero steps",
            track(&|r| r.circle.as_mut().unwrap().steps = 0),
            "circle.steps",
        ),
        (
            "NaN angle step",
            track(&|r| r.circle.as_mut().unwrap().angle_step = f64::NAN),
            "circle.angle_step",
        ),
        (
            "missing centre",
            track(&|r| r.circle.as_mut().unwrap().centre = None),
            "circle.centre",
        ),
        ("short seed", track(&|r| r.seed = vec![0.0; 3]), "seed"),
        (
            "too many line steps",
            track(&|r| {
                r.circle = None;
                r.line = Some(pb::LinePath {
                    start: None,
                    end: Some(good),
                    steps: 1_000_000,
                });
            }),
            "line.steps",
        ),
        (
            "line without end",
            track(&|r| {
                r.circle = None;
                r.line = Some(pb::LinePath {
                    start: None,
                    end: None,
                    steps: 10,
                });
            }),
            "line.end",
        ),
        (
            "NaN pose",
            track(&|r| {
                r.circle = None;
                r.poses = vec![good, nan];
            }),
            "poses[1].position.y",
        ),
        (
            "zero tolerance",
            track(&|r| {
                r.options = Some(pb::IkOptions {
                    position_tolerance: Some(0.0),
                    ..Default::default()
                })
            }),
            "options.position_tolerance",
        ),
    ];
    for (what, req, field) in cases {
        let status = ik.track_path(req).await.unwrap_err();
        assert_field(&status, Code::InvalidArgument, field, what);
    }

    use pb::LinearSolver as L;
    let cases: Vec<(&str, pb::SolveLinearSystemRequest, &str)> = vec![
        (
            "ragged data",
            linear((2, 2, vec![1.0; 3]), vec![1.0, 1.0], L::Unspecified),
            "a.data",
        ),
        (
            "b length",
            linear((2, 2, vec![1.0; 4]), vec![1.0], L::Unspecified),
            "b",
        ),
        (
            "NaN b",
            linear((1, 1, vec![1.0]), vec![f64::NAN], L::Unspecified),
            "b[0]",
        ),
        (
            "NaN a",
            linear((1, 2, vec![1.0, f64::INFINITY]), vec![1.0], L::Unspecified),
            "a.data[1]",
        ),
        ("empty a", linear((0, 2, vec![]), vec![], L::Unspecified), "a"),
        (
            "too large",
            linear((101, 100, vec![0.0; 10_100]), vec![0.0; 101], L::Unspecified),
            "a",
        ),
        (
            "missing a",
            pb::SolveLinearSystemRequest {
                a: None,
                ..Default::default()
            },
            "a",
        ),
        (
            "unknown method",
            linear((1, 1, vec![1.0]), vec![1.0], L::Unspecified),
            "method",
        ),
        (
            "zero tolerance",
            pb::SolveLinearSystemRequest {
                tolerance: Some(0.0),
                ..linear((1, 1, vec![1.0]), vec![1.0], L::AngleRelaxation)
            },
            "tolerance",
        ),
        (
            "negative relative tolerance",
            pb::SolveLinearSystemRequest {
                relative_tolerance: Some(-1.0),
                ..linear((1, 1, vec![1.0]), vec![1.0], L::AngleRelaxationSafeguarded)
            },
            "relative_tolerance",
        ),
        (
            "negative singular-value tolerance",
            pb::SolveLinearSystemRequest {
                singular_value_tolerance: Some(-1.0),
                ..linear((1, 1, vec![1.0]), vec![1.0], L::SvdPseudoinverse)
            },
            "singular_value_tolerance",
        ),
        (
            "too much RLXA work",
            pb::SolveLinearSystemRequest {
                max_iterations: u32::MAX,
                ..linear((10, 10, vec![1.0; 100]), vec![1.0; 10], L::AngleRelaxation)
            },
            "max_iterations",
        ),
    ];
    for (what, mut req, field) in cases {
        if what == "unknown method" {
            req.method = 17;
        }
        let status = ik.solve_linear_system(req).await.unwrap_err();
        assert_field(&status, Code::InvalidArgument, field, what);
    }
    let reply = ik.solve_ik(ok).await.expect("still serving").into_inner();
    assert!(reply.success);
}

/// An inline URDF is parsed on the CPU pool before the solve (two uses of the
/// request's budget); the answer is hand-checked and carries the model id.
#[tokio::test]
async fn inline_urdf_is_solved_and_gets_a_model_id() {
    const TWO_LINK: &str = r#"<robot name="two_link">
      <link name="base"/><link name="upper"/><link name="tool"/>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
        <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
      <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/>
        <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
    </robot>"#;
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    // the tool sits on the elbow axis: 0.4 (cos a, sin a) at height 0.5, so a = 0.7
    let a: f64 = 0.7;
    let target = Isometry3::translation(0.4 * a.cos(), 0.4 * a.sin(), 0.5);
    let reply = ik
        .solve_ik(pb::SolveIkRequest {
            robot: Some(pb::RobotRef {
                source: Some(pb::robot_ref::Source::Urdf(TWO_LINK.into())),
                ..Default::default()
            }),
            target: Some(pose_pb(&target)),
            seed: vec![0.0, 0.0],
            options: Some(pb::IkOptions {
                position_only: true,
                ..Default::default()
            }),
        })
        .await
        .unwrap()
        .into_inner();
    assert!(reply.success, "{reply:?}");
    assert!(
        (reply.solutions[0].joints[0] - a).abs() < 1e-4,
        "{:?}",
        reply.solutions[0].joints
    );
    assert_eq!(reply.model_id.len(), 32);
}

/// `return_history`: each solution's per-iteration errors, starting at the seed's
/// error (from the server's FK, compared here) and ending at the returned error.
#[tokio::test]
async fn error_history_on_request() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let target = fk(&mut robots, "ur5", &[1.0, -0.7, 1.9, 0.5, -1.0, 2.0]).await;
    let seed = vec![0.9, -0.8, 1.7, 0.4, -0.9, 1.8];
    let at_seed = fk(&mut robots, "ur5", &seed).await;
    let request = pb::SolveIkRequest {
        seed: seed.clone(),
        options: Some(pb::IkOptions {
            return_history: true,
            ..Default::default()
        }),
        ..ik_request("ur5", &target, Default::default())
    };
    let reply = ik.solve_ik(request).await.unwrap().into_inner();
    let s = &reply.solutions[0];
    assert_eq!(s.attempt, 0);
    assert_eq!(s.position_error_history.len(), s.iterations as usize + 1);
    assert_eq!(s.orientation_error_history.len(), s.position_error_history.len());
    let (p0, r0) = distance(&at_seed, &target);
    assert!(
        (s.position_error_history[0] - p0).abs() < 1e-9,
        "{} vs {p0}",
        s.position_error_history[0]
    );
    assert!((s.orientation_error_history[0] - r0).abs() < 1e-6);
    assert_eq!(*s.position_error_history.last().unwrap(), s.position_error);
    assert_eq!(*s.orientation_error_history.last().unwrap(), s.orientation_error);
    let without = ik
        .solve_ik(pb::SolveIkRequest {
            seed,
            ..ik_request("ur5", &target, Default::default())
        })
        .await
        .unwrap()
        .into_inner();
    assert!(without.solutions[0].position_error_history.is_empty());
}
