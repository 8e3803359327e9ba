//! PlanningService.Retime and the timing methods of Plan: closed-form
//! durations, limits at every point and by finite differences, bad input
//! named by field.

use kinplan_server::ServerConfig;
use kinplan_server::pb::{self, plan_request::Goal, planning_service_client::PlanningServiceClient};
use tonic::Code;

use crate::{named, start};

const V: [f64; 6] = [1.0, 1.2, 1.5, 2.0, 2.0, 2.5];
const A: [f64; 6] = [2.0, 2.5, 3.0, 4.0, 4.0, 5.0];
const J: [f64; 6] = [10.0, 12.0, 15.0, 20.0, 20.0, 25.0];

fn timing(method: pb::TimingMethod) -> pb::TimingOptions {
    pb::TimingOptions {
        max_velocity: V.to_vec(),
        max_acceleration: A.to_vec(),
        max_jerk: J.to_vec(),
        method: method as i32,
        ..Default::default()
    }
}

fn request(waypoints: &[[f64; 6]], timing: pb::TimingOptions) -> pb::RetimeRequest {
    pb::RetimeRequest {
        robot: named("ur5"),
        waypoints: waypoints
            .iter()
            .map(|q| pb::JointState {
                positions: q.to_vec(),
            })
            .collect(),
        timing: Some(timing),
    }
}

const PATH: [[f64; 6]; 4] = [
    [-1.2, -1.3, 1.4, -1.6, -1.57, 0.0],
    [-0.4, -1.0, 1.0, -1.2, -1.2, 0.3],
    [0.5, -1.4, 1.3, -1.5, -1.5, 0.1],
    [1.2, -1.3, 1.4, -1.6, -1.57, 0.0],
];

fn check_points(t: &pb::JointTrajectory, first: &[f64], last: &[f64]) {
    assert!(t.points.len() > 10);
    for (i, p) in t.points.iter().enumerate() {
        assert_eq!((p.velocities.len(), p.accelerations.len()), (6, 6));
        for j in 0..6 {
            assert!(
                p.velocities[j].abs() <= V[j] * (1.0 + 1e-6),
                "point {i}: v{j} {}",
                p.velocities[j]
            );
            assert!(
                p.accelerations[j].abs() <= A[j] * (1.0 + 1e-6),
                "point {i}: a{j} {}",
                p.accelerations[j]
            );
        }
        if i > 0 {
            assert!(p.time_from_start > t.points[i - 1].time_from_start);
        }
    }
    let (p0, pn) = (&t.points[0], t.points.last().unwrap());
    assert!(p0.positions.iter().zip(first).all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(pn.positions.iter().zip(last).all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(p0.velocities.iter().chain(&pn.velocities).all(|v| v.abs() < 1e-9));
}

#[tokio::test]
async fn retime_is_time_optimal_on_a_line_and_keeps_the_limits_on_a_path() {
    let server = start(ServerConfig::default()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    // joint 0 alone moves 1 rad at v = 1, a = 2: trapezoid 1/1 + 1/2 = 1.5 s
    let mut line = [PATH[0], PATH[0]];
    line[1][0] += 1.0;
    let r = planning
        .retime(request(&line, timing(pb::TimingMethod::TimeOptimal)))
        .await
        .unwrap()
        .into_inner();
    assert!((r.duration - 1.5).abs() < 2e-3, "{}", r.duration);
    let pts = &r.trajectory.as_ref().unwrap().points;
    // cruising at the limit in the middle
    let mid = pts.iter().find(|p| p.time_from_start >= 0.75).unwrap();
    assert!((mid.velocities[0] - 1.0).abs() < 1e-6 && mid.accelerations[0].abs() < 1e-6);

    let r = planning
        .retime(request(&PATH, timing(pb::TimingMethod::TimeOptimal)))
        .await
        .unwrap()
        .into_inner();
    let t = r.trajectory.unwrap();
    check_points(&t, &PATH[0], &PATH[3]);
    assert_eq!(t.joint_names.len(), 6);
    assert!((t.points.last().unwrap().time_from_start - r.duration).abs() < 1e-12);
    // faster than the jerk-limited motion, which also bounds the jerk
    let stops = planning
        .retime(request(&PATH, timing(pb::TimingMethod::JerkLimited)))
        .await
        .unwrap()
        .into_inner();
    assert!(
        r.duration < stops.duration,
        "{} vs {}",
        r.duration,
        stops.duration
    );
    for key in ["CD", "JD", "JJ_time", "CJ_time", "JMJ_time", "CMJ_time"] {
        assert!(r.criteria.get(key).is_some_and(|v| v.is_finite()), "{key}");
    }
    assert!(r.compute_time > 0.0 && r.compute_time < 1.0);
}

#[tokio::test]
async fn jerk_limited_retime_matches_the_s_curve_and_keeps_every_limit_at_1_khz() {
    let server = start(ServerConfig::default()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut options = timing(pb::TimingMethod::JerkLimited);
    options.sample_period = Some(1e-3);
    // joint 0 alone: 1 rad at v = 1, a = 2, j = 10 takes
    // 2·(2·0.2 + 0.3) + 0.3 = 1.7 s (T_j = a/j, T_a = v/a − a/j, cruise 0.3)
    let mut line = [PATH[0], PATH[0]];
    line[1][0] += 1.0;
    let r = planning
        .retime(request(&line, options.clone()))
        .await
        .unwrap()
        .into_inner();
    assert!((r.duration - 1.7).abs() < 1e-9, "{}", r.duration);

    let r = planning
        .retime(request(&PATH, options))
        .await
        .unwrap()
        .into_inner();
    let t = r.trajectory.unwrap();
    check_points(&t, &PATH[0], &PATH[3]);
    let h = 1e-3;
    let q: Vec<&[f64]> = t.points.iter().map(|p| p.positions.as_slice()).collect();
    for i in 0..q.len() - 4 {
        for j in 0..6 {
            let vel = (q[i + 1][j] - q[i][j]) / h;
            let acc = (q[i + 2][j] - 2.0 * q[i + 1][j] + q[i][j]) / (h * h);
            let jerk = (q[i + 3][j] - 3.0 * q[i + 2][j] + 3.0 * q[i + 1][j] - q[i][j]) / (h * h * h);
            assert!(vel.abs() <= V[j] * (1.0 + 1e-9), "{i}: v {vel}");
            assert!(acc.abs() <= A[j] * (1.0 + 1e-6), "{i}: a {acc}");
            assert!(jerk.abs() <= J[j] * (1.0 + 1e-3), "{i}: j {jerk}");
        }
    }
}

#[tokio::test]
async fn jerk_limited_retime_starts_at_the_given_velocity() {
    let server = start(ServerConfig::default()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut options = timing(pb::TimingMethod::JerkLimited);
    options.start_velocity = vec![0.5, 0.0, 0.0, 0.0, 0.0, 0.0];
    // joint 0 alone, 1 rad from 0.5 rad/s at v = 1, a = 2, j = 10: 0.45 s
    // to reach 1 rad/s (0.3375 rad), 0.3125 s of cruise, 0.7 s to stop
    // (0.35 rad): 1.4625 s
    let mut line = [PATH[0], PATH[0]];
    line[1][0] += 1.0;
    let r = planning
        .retime(request(&line, options.clone()))
        .await
        .unwrap()
        .into_inner();
    assert!((r.duration - 1.4625).abs() < 1e-5, "{}", r.duration);
    let first = &r.trajectory.unwrap().points[0];
    assert!((first.velocities[0] - 0.5).abs() < 1e-12 && (first.positions[0] - PATH[0][0]).abs() < 1e-9);
    // beyond joint 0's speed limit: refused by field
    options.start_velocity[0] = 1.5;
    let err = planning.retime(request(&line, options)).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(
        err.message().contains("timing.start_velocity"),
        "{}",
        err.message()
    );
}

#[tokio::test]
async fn plan_times_its_path_by_the_requested_method() {
    let server = start(ServerConfig {
        acm_samples: 300,
        ..ServerConfig::default()
    })
    .await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    for method in [pb::TimingMethod::Unspecified, pb::TimingMethod::TimeOptimal] {
        let req = pb::PlanRequest {
            robot: named("ur5"),
            start: PATH[0].to_vec(),
            goal: Some(Goal::GoalJoints(pb::JointState {
                positions: PATH[3].to_vec(),
            })),
            algorithm: pb::PlanAlgorithm::RrtConnect as i32,
            options: Some(pb::PlanOptions {
                timing: Some(timing(method)),
                ..Default::default()
            }),
            ..Default::default()
        };
        let r = planning.plan(req).await.unwrap().into_inner();
        assert_eq!(r.status, pb::PlanStatus::Succeeded as i32, "{}", r.message);
        let t = r.trajectory.unwrap();
        assert!(
            t.points
                .iter()
                .all(|p| p.velocities.len() == 6 && p.accelerations.len() == 6)
        );
        assert!((t.points.last().unwrap().time_from_start - r.duration).abs() < 1e-12);
        assert!(r.criteria.contains_key("JJ_time"));
        if method == pb::TimingMethod::TimeOptimal {
            check_points(&t, &PATH[0], &PATH[3]);
            // 2.4 rad on joint 0 at v = 1, a = 2 takes at least 2.4 + 0.5 s
            assert!(r.duration >= 2.9 - 1e-6, "{}", r.duration);
        } else {
            assert_eq!(t.points.len(), r.deviation.unwrap().translation.len());
        }
    }
}

#[tokio::test]
async fn bad_retime_input_is_named_by_field() {
    let server = start(ServerConfig::default()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let base = || request(&PATH, timing(pb::TimingMethod::TimeOptimal));
    let cases: Vec<(pb::RetimeRequest, &str)> = vec![
        (request(&[], timing(pb::TimingMethod::TimeOptimal)), "waypoints"),
        (
            {
                let mut r = base();
                r.waypoints[1].positions.pop();
                r
            },
            "waypoints[1].positions",
        ),
        (
            {
                let mut r = base();
                r.waypoints[0].positions[2] = f64::INFINITY;
                r
            },
            "waypoints[0].positions[2]",
        ),
        (
            {
                let mut r = base();
                let t = r.timing.as_mut().unwrap();
                t.method = pb::TimingMethod::JerkLimited as i32;
                t.max_jerk.clear();
                r
            },
            "timing.max_jerk",
        ),
        (
            {
                let mut r = base();
                r.timing.as_mut().unwrap().max_acceleration.clear();
                r
            },
            "timing.max_acceleration",
        ),
        (
            {
                let mut r = base();
                r.timing.as_mut().unwrap().method = 9;
                r
            },
            "timing.method",
        ),
        (
            {
                let mut r = base();
                r.timing.as_mut().unwrap().sample_period = Some(0.0);
                r
            },
            "timing.sample_period",
        ),
        (
            {
                let mut r = base();
                r.timing.as_mut().unwrap().path_tolerance = Some(f64::NAN);
                r
            },
            "timing.path_tolerance",
        ),
        (
            {
                // across the first segment, not along it
                let mut r = base();
                r.timing.as_mut().unwrap().start_velocity = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.5];
                r.waypoints.truncate(2);
                r.waypoints[1].positions = vec![-1.0, -1.3, 1.4, -1.6, -1.57, 0.0];
                r
            },
            "timing.start_velocity",
        ),
    ];
    for (req, field) in cases {
        let err = planning.retime(req).await.unwrap_err();
        assert_eq!(err.code(), Code::InvalidArgument, "{field}: {}", err.message());
        assert!(
            err.message().starts_with(&format!("{field}:")),
            "{field}: {}",
            err.message()
        );
    }
    let plan = pb::PlanRequest {
        robot: named("ur5"),
        start: PATH[0].to_vec(),
        goal: Some(Goal::GoalJoints(pb::JointState {
            positions: PATH[3].to_vec(),
        })),
        options: Some(pb::PlanOptions {
            timing: Some(pb::TimingOptions {
                path_tolerance: Some(-1.0),
                ..Default::default()
            }),
            ..Default::default()
        }),
        ..Default::default()
    };
    let err = planning.plan(plan.clone()).await.unwrap_err();
    assert!(
        err.message().starts_with("options.timing.path_tolerance:"),
        "{}",
        err.message()
    );
    // a plan starts at rest: a start velocity is refused before any planning
    let mut moving = plan;
    let timing = moving.options.as_mut().unwrap().timing.as_mut().unwrap();
    timing.path_tolerance = None;
    timing.start_velocity = vec![0.1, 0.0, 0.0, 0.0, 0.0, 0.0];
    let err = planning.plan(moving).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{}", err.message());
    assert!(
        err.message().starts_with("options.timing.start_velocity:"),
        "{}",
        err.message()
    );
}
