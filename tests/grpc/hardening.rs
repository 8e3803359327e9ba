//! Hostile-client regressions: each test is named after what broke —
//! a process abort, a panic, work outliving its deadline, idle streams holding
//! admission, a shutdown that never ends, wrong codes.

use std::time::{Duration, Instant};

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, kinematics_service_client::KinematicsServiceClient, robot_service_client::RobotServiceClient,
};
use tonic::Code;
use tonic_health::pb::{HealthCheckRequest, health_client::HealthClient};

use crate::{named, start};

/// A `StreamIk` first message for `ur5` at its zero pose's neighbourhood.
fn stream_first(sequence: u64) -> pb::StreamIkRequest {
    pb::StreamIkRequest {
        sequence,
        robot: named("ur5"),
        target: Some(pb::Pose {
            position: Some(pb::Vec3 {
                x: 0.4,
                y: 0.1,
                z: 0.4,
            }),
            orientation: None,
        }),
        options: Some(pb::IkOptions {
            position_only: true,
            time_budget: Some(0.2),
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// Opens a `StreamIk`, sends one message, waits for its answer and leaves the
/// stream open and idle.
async fn idle_stream(
    ik: &mut KinematicsServiceClient<tonic::transport::Channel>,
) -> (
    tokio::sync::mpsc::Sender<pb::StreamIkRequest>,
    tonic::Streaming<pb::StreamIkResponse>,
) {
    let (tx, rx) = tokio::sync::mpsc::channel(4);
    tx.send(stream_first(1)).await.unwrap();
    let mut answers = ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await
        .unwrap()
        .into_inner();
    answers.message().await.unwrap().expect("the first answer");
    (tx, answers)
}

/// Regression: four idle `StreamIk` streams exhausted `--concurrency-limit 4`
/// and every other call was shed until they closed.
#[tokio::test]
async fn idle_streams_do_not_hold_admission_slots() {
    let server = start(ServerConfig {
        concurrency_limit: 2,
        ..ServerConfig::default()
    })
    .await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let _a = idle_stream(&mut ik).await;
    let _b = idle_stream(&mut ik).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    for _ in 0..5 {
        robots.list_robots(pb::ListRobotsRequest {}).await.unwrap();
    }
    // Open streams are bounded too: a third is shed, at once.
    let (tx, rx) = tokio::sync::mpsc::channel(4);
    tx.send(stream_first(1)).await.unwrap();
    let third = ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await;
    assert_eq!(third.unwrap_err().code(), Code::ResourceExhausted);
}

/// Idle streams are bounded in time: silence past the idle timeout ends them.
#[tokio::test]
async fn idle_stream_is_ended_after_the_idle_timeout() {
    let server = start(ServerConfig {
        stream_idle_timeout: Duration::from_millis(200),
        ..ServerConfig::default()
    })
    .await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let (_tx, mut answers) = idle_stream(&mut ik).await;
    let started = Instant::now();
    let err = tokio::time::timeout(Duration::from_secs(5), answers.message())
        .await
        .expect("the server ends an idle stream")
        .unwrap_err();
    assert_eq!(err.code(), Code::Unavailable, "{err:?}");
    assert!(started.elapsed() < Duration::from_secs(2));
}

/// Regression: SIGTERM while a client held `Health.Watch` or an idle `StreamIk`
/// never exited. After the drain timeout, streams end with UNAVAILABLE.
#[tokio::test]
async fn shutdown_with_open_watch_and_idle_stream_exits() {
    let mut server = start(ServerConfig {
        drain_timeout: Duration::from_millis(300),
        ..ServerConfig::default()
    })
    .await;
    let mut health = HealthClient::new(server.channel.clone());
    let mut watch = health
        .watch(HealthCheckRequest {
            service: String::new(),
        })
        .await
        .unwrap()
        .into_inner();
    watch.message().await.unwrap().expect("the current status");
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let (_tx, mut answers) = idle_stream(&mut ik).await;
    server.stop.take().unwrap().send(()).unwrap();
    tokio::time::timeout(Duration::from_secs(5), server.handle)
        .await
        .expect("the server exits after the drain timeout")
        .unwrap();
    // The watch saw NOT_SERVING, then the stream ended with UNAVAILABLE.
    let mut last = None;
    loop {
        match watch.message().await {
            Ok(Some(_)) => continue,
            Ok(None) => break,
            Err(e) => {
                last = Some(e.code());
                break;
            }
        }
    }
    assert_eq!(last, Some(Code::Unavailable));
    let ended = answers.message().await;
    assert!(!matches!(ended, Ok(Some(_))), "{ended:?}");
}

/// Regression: `grpc-timeout: 18446744073709551615S` (a legal header) overflowed
/// `Instant` arithmetic and panicked, in unary calls and in `StreamIk`, also with
/// no server default timeout.
#[tokio::test]
async fn huge_grpc_timeout_means_no_deadline() {
    let server = start(ServerConfig {
        request_timeout: None,
        ..ServerConfig::default()
    })
    .await;
    let huge = "18446744073709551615S";
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let mut request = tonic::Request::new(pb::ForwardKinematicsRequest {
        robot: named("ur5"),
        joint_positions: vec![0.0; 6],
        ..Default::default()
    });
    request
        .metadata_mut()
        .insert("grpc-timeout", huge.parse().unwrap());
    robots.forward_kinematics(request).await.unwrap();
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let (tx, rx) = tokio::sync::mpsc::channel(4);
    tx.send(stream_first(1)).await.unwrap();
    let mut request = tonic::Request::new(tokio_stream::wrappers::ReceiverStream::new(rx));
    request
        .metadata_mut()
        .insert("grpc-timeout", huge.parse().unwrap());
    let mut answers = ik.stream_ik(request).await.unwrap().into_inner();
    let answer = answers.message().await.unwrap().expect("an answer");
    assert!(answer.result.is_some());
}

use kinplan_server::pb::{
    mobile_service_client::MobileServiceClient, scoring_service_client::ScoringServiceClient,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

fn circle(x: f64, y: f64, radius: f64) -> pb::Obstacle {
    pb::Obstacle {
        shape: Some(pb::obstacle::Shape::Circle(pb::Circle {
            center: Some(pb::Point2D { x, y }),
            radius,
        })),
    }
}

fn differential() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Differential(Default::default())),
    })
}

/// 5,000 small obstacles on a grid, away from the start.
fn big_world() -> Vec<pb::Obstacle> {
    (0..5000)
        .map(|k| circle(2.0 + (k % 100) as f64 * 0.5, -25.0 + (k / 100) as f64, 0.1))
        .collect()
}

fn heavy_sensors() -> Option<pb::RangeSensorParams> {
    Some(pb::RangeSensorParams {
        count: Some(360),
        rays_per_beam: Some(100),
        max_range: Some(30.0),
        ..Default::default()
    })
}

/// A call's own deadline, sent as the `grpc-timeout` header (not as a
/// client-side timer, which would race the server's answer and show the
/// client's own CANCELLED instead of what the server does).
struct Deadline {
    ms: u64,
    sent: Instant,
}

/// `message` with a deadline of `ms` milliseconds from now.
fn with_deadline<T>(message: T, ms: u64) -> (tonic::Request<T>, Deadline) {
    let mut request = tonic::Request::new(message);
    request
        .metadata_mut()
        .insert("grpc-timeout", format!("{ms}m").parse().unwrap());
    let deadline = Deadline {
        ms,
        sent: Instant::now(),
    };
    (request, deadline)
}

/// How late after its deadline an answer may arrive: the server answers at
/// the deadline; this allows for OS scheduling on a loaded 2-core CI machine,
/// yet fails for a call that runs to the server's 60 s default.
const ANSWER_SLACK: Duration = Duration::from_millis(250);

impl Deadline {
    /// The answer arrived by the deadline (plus [`ANSWER_SLACK`]): a reply
    /// cut short by the budget, or the server's deadline answer — the guard's
    /// DEADLINE_EXCEEDED, or tonic's own timer for the same `grpc-timeout`
    /// (CANCELLED, "Timeout expired"), which fires first when the guard's
    /// slightly earlier timer is polled late on a busy I/O thread — and
    /// nothing else.
    fn in_time<T>(&self, answer: Result<tonic::Response<T>, tonic::Status>) {
        let took = self.sent.elapsed();
        let limit = Duration::from_millis(self.ms) + ANSWER_SLACK;
        assert!(
            took <= limit,
            "answered after {took:?}, deadline {} ms (allowed {limit:?})",
            self.ms
        );
        if let Err(err) = answer {
            let deadline_answer = err.code() == Code::DeadlineExceeded
                || (err.code() == Code::Cancelled && err.message() == "Timeout expired");
            assert!(
                deadline_answer,
                "{:?} {} after {took:?}, deadline {} ms",
                err.code(),
                err.message(),
                self.ms
            );
        }
    }
}

/// After a call missed its deadline, how long until no job runs on the pool.
async fn idle_after(running: &Arc<AtomicUsize>) -> Duration {
    let answered = Instant::now();
    while running.load(Ordering::SeqCst) > 0 {
        assert!(
            answered.elapsed() < Duration::from_secs(10),
            "the work never stopped"
        );
        tokio::time::sleep(Duration::from_micros(200)).await;
    }
    answered.elapsed()
}

/// The work of a call that missed its deadline stops promptly. The target is
/// 10 ms (measured: under 1 ms for most RPCs, printed here); the bound asserted
/// allows for OS scheduling on a loaded 2-core CI machine (load average ~10
/// while this was written), yet fails for work that runs on.
fn assert_idle(what: &str, took: Duration) {
    eprintln!("{what}: pool idle {took:?} after the deadline answer");
    assert!(
        took < Duration::from_millis(100),
        "{what}: work ran on {took:?} after the deadline"
    );
}

/// Regression: after DEADLINE_EXCEEDED at 10–50 ms the server kept computing
/// for a minute (Navigate/FollowPath/ControlStep in a 5,000-obstacle world with
/// 360 sensors × 100 rays, SolveLinearSystem RLXA, IK batches). Each RPC's work
/// now stops within a bounded interval of its deadline.
#[tokio::test]
async fn work_stops_soon_after_a_missed_deadline() {
    let running = Arc::new(AtomicUsize::new(0));
    // The server's default deadline (60 s) stays far away: only each call's
    // own deadline can stop its work in time.
    let server = start(ServerConfig {
        running_jobs: running.clone(),
        ..ServerConfig::default()
    })
    .await;
    let mut mobile = MobileServiceClient::new(server.channel.clone());
    let sim = Some(pb::SimOptions {
        robot_radius: Some(0.2),
        dt: Some(0.05),
        max_time: Some(1000.0),
    });
    let nav = pb::NavigateRequest {
        chassis: differential(),
        start: Some(pb::Pose2D {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        }),
        goal: Some(pb::Point2D { x: 80.0, y: 0.3 }),
        world: big_world(),
        sensors: heavy_sensors(),
        sim,
        ..Default::default()
    };
    let (request, deadline) = with_deadline(nav.clone(), 50);
    deadline.in_time(mobile.navigate(request).await);
    assert_idle("Navigate (vector distance)", idle_after(&running).await);

    let astar = pb::NavigateRequest {
        navigator: pb::Navigator::GridAstar as i32,
        astar: Some(pb::GridAstarOptions {
            resolution: Some(0.05),
            ..Default::default()
        }),
        ..nav.clone()
    };
    let (request, deadline) = with_deadline(astar, 50);
    deadline.in_time(mobile.navigate(request).await);
    assert_idle("Navigate (grid A*)", idle_after(&running).await);

    let follow = pb::FollowPathRequest {
        chassis: differential(),
        start: Some(pb::Pose2D {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        }),
        path: (1..2000)
            .map(|k| pb::PathNode {
                x: (k as f64 * 0.7).sin() * 0.5,
                y: -30.0 - k as f64 * 0.05,
                heading: None,
            })
            .collect(),
        world: big_world(),
        sim,
        ..Default::default()
    };
    let (request, deadline) = with_deadline(follow, 30);
    deadline.in_time(mobile.follow_path(request).await);
    assert_idle("FollowPath", idle_after(&running).await);

    let step = pb::ControlStepRequest {
        chassis: differential(),
        state: Some(pb::Pose2D {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        }),
        controller: pb::Controller::VectorDistance as i32,
        goal: Some(pb::Point2D { x: 80.0, y: 0.3 }),
        sensors: heavy_sensors(),
        world: (0..10_000)
            .map(|k| circle(2.0 + (k % 100) as f64 * 0.2, -10.0 + (k / 100) as f64 * 0.2, 0.05))
            .collect(),
        ..Default::default()
    };
    let (request, deadline) = with_deadline(step, 10);
    deadline.in_time(mobile.control_step(request).await);
    assert_idle("ControlStep", idle_after(&running).await);

    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let n = 100;
    let linear = pb::SolveLinearSystemRequest {
        a: Some(pb::Matrix {
            rows: n,
            cols: n,
            data: (0..n * n).map(|k| ((k * 7919) % 101) as f64 - 50.0).collect(),
        }),
        b: (0..n).map(|k| k as f64).collect(),
        method: pb::LinearSolver::AngleRelaxation as i32,
        max_iterations: 100_000,
        tolerance: Some(1e-300),
        ..Default::default()
    };
    // Stopped by the deadline: either the cut answer (ITERATION_CAP) arrives in
    // time, or DEADLINE_EXCEEDED; never minutes of work.
    let (request, deadline) = with_deadline(linear, 50);
    let answer = ik.solve_linear_system(request).await;
    if let Ok(reply) = &answer {
        assert_eq!(reply.get_ref().status, pb::LinearSolveStatus::IterationCap as i32);
    }
    deadline.in_time(answer);
    assert_idle("SolveLinearSystem (RLXA)", idle_after(&running).await);

    let far = pb::Pose {
        position: Some(pb::Vec3 {
            x: 10.0,
            y: 0.0,
            z: 0.5,
        }),
        orientation: None,
    };
    let batch = pb::SolveIkBatchRequest {
        seeds: None,
        robot: named("kuka_kr210_r2700_extra"),
        targets: vec![far; 200],
        options: Some(pb::IkOptions {
            max_restarts: Some(u32::MAX),
            ..Default::default()
        }),
        ..Default::default()
    };
    let (request, deadline) = with_deadline(batch, 50);
    deadline.in_time(ik.solve_ik_batch(request).await);
    assert_idle("SolveIkBatch", idle_after(&running).await);
}

/// An OBJ UV sphere of radius 0.05 m: `rings` rings of `around` vertices.
fn ball_obj(rings: usize, around: usize) -> String {
    let mut ball = String::new();
    for i in 0..rings {
        let polar = std::f64::consts::PI * (i as f64 + 0.5) / rings as f64;
        for j in 0..around {
            let azimuth = 2.0 * std::f64::consts::PI * j as f64 / around as f64;
            let (x, y, z) = (
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                polar.cos(),
            );
            ball += &format!("v {} {} {}\n", 0.05 * x, 0.05 * y, 0.05 * z);
        }
    }
    for i in 0..rings - 1 {
        for j in 0..around {
            let a = i * around + j + 1;
            let b = i * around + (j + 1) % around + 1;
            ball += &format!("f {a} {b} {}\nf {a} {} {}\n", b + around, b + around, a + around);
        }
    }
    ball
}

/// A CheckState of one state `positions` of the robot `urdf`, with the one
/// mesh file `uri` it names.
fn check_with_mesh(urdf: String, uri: &str, mesh: String, positions: Vec<f64>) -> pb::CheckStateRequest {
    pb::CheckStateRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(urdf)),
            meshes: vec![pb::MeshFile {
                uri: uri.into(),
                data: mesh.into_bytes(),
            }],
            ..Default::default()
        }),
        states: vec![pb::JointState { positions }],
        ..Default::default()
    }
}

/// Regression: building a robot's collision model (its bodies and the
/// sampled allowed-collision matrix, up to two million pair tests) ignored
/// the deadline and ran on the pool for seconds after the answer, for every
/// new URDF or held-joint value a client sent. The build now stops at the
/// call's deadline and is not cached half-done.
#[tokio::test]
async fn a_collision_model_build_stops_at_the_deadline() {
    let running = Arc::new(AtomicUsize::new(0));
    let server = start(ServerConfig {
        running_jobs: running.clone(),
        ..ServerConfig::default()
    })
    .await;
    // 30 links 3 cm apart, each a ball mesh of 162 vertices (checked as its
    // hull), so that most pairs reach the narrow phase: 435
    // body pairs, about 4,600 sampled states, seconds of work in all
    let uri = "package://snake/ball.obj";
    let links = 30;
    let mut urdf = String::from(r#"<robot name="snake"><link name="l0"/>"#);
    for k in 1..=links {
        urdf += &format!(
            r#"<link name="l{k}"><collision><geometry><mesh filename="{uri}"/></geometry></collision></link>
            <joint name="j{k}" type="revolute"><parent link="l{}"/><child link="l{k}"/><origin xyz="0 0 0.03"/>
              <axis xyz="{}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"#,
            k - 1,
            if k % 2 == 0 { "0 1 0" } else { "1 0 0" }
        );
    }
    urdf += "</robot>";
    let ball = ball_obj(9, 18);
    let mut planning = pb::planning_service_client::PlanningServiceClient::new(server.channel.clone());
    let check = check_with_mesh(urdf, uri, ball, vec![0.3; links]);
    let (request, deadline) = with_deadline(check, 150);
    let answer = planning.check_state(request).await;
    let err = answer.as_ref().err().map(|e| e.message().to_string());
    deadline.in_time(answer);
    if let Some(message) = err.filter(|m| m.contains("collision model")) {
        assert!(message.contains("longer deadline"), "{message}");
    }
    // The pool's threads run at a lower priority than the rest of a loaded
    // CI machine, so this bound is looser than the other calls': the whole
    // build takes seconds, and its end is what this catches.
    let took = idle_after(&running).await;
    eprintln!("CheckState (collision model build): pool idle {took:?} after the deadline answer");
    assert!(
        took < Duration::from_millis(600),
        "the build ran on {took:?} after the deadline"
    );
}

/// Regression: each collision element naming a mesh got its own hull and
/// polytope fit, so a URDF naming one mesh file thousands of times (a few
/// dozen bytes each) multiplied the work of one file by thousands, with no
/// deadline polled in between. The mesh vertices the elements name are now
/// bounded together, and refused before any hull is built.
#[tokio::test]
async fn a_urdf_naming_one_mesh_many_times_is_refused_before_any_hull() {
    let server = start(ServerConfig::default()).await;
    // a ball of 100 rings of 200 vertices, named by 60 elements of one link
    let uri = "package://many/ball.obj";
    let ball = ball_obj(100, 200);
    let element = format!(r#"<collision><geometry><mesh filename="{uri}"/></geometry></collision>"#);
    let urdf = format!(
        r#"<robot name="many"><link name="base"/><link name="arm">{}</link>
           <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
             <limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>"#,
        element.repeat(60)
    );
    let mut planning = pb::planning_service_client::PlanningServiceClient::new(server.channel.clone());
    let check = check_with_mesh(urdf, uri, ball, vec![0.3]);
    let started = Instant::now();
    let err = planning.check_state(check).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(
        err.message().contains("mesh vertices named by links[].collision"),
        "{err:?}"
    );
    assert!(err.message().contains("1200000"), "{err:?}");
    // reading the one file is all the work done, not the 60 hulls
    assert!(
        started.elapsed() < Duration::from_secs(3),
        "{:?}",
        started.elapsed()
    );
}

/// Health answers within 10 ms while every pool thread is busy (measured with
/// the release binary, see the report; the assertion here allows for a debug
/// build on a loaded 2-core machine, yet fails if health waits for the pool).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn health_answers_while_the_pool_is_saturated() {
    let running = Arc::new(AtomicUsize::new(0));
    let server = start(ServerConfig {
        running_jobs: running.clone(),
        cpu_threads: 2,
        ..ServerConfig::default()
    })
    .await;
    let far = pb::Pose {
        position: Some(pb::Vec3 {
            x: 10.0,
            y: 0.0,
            z: 0.5,
        }),
        orientation: None,
    };
    let mut busy = Vec::new();
    for _ in 0..4 {
        let mut ik = KinematicsServiceClient::new(server.channel.clone());
        let request = pb::SolveIkRequest {
            robot: named("ur5"),
            target: Some(far),
            options: Some(pb::IkOptions {
                max_restarts: Some(u32::MAX),
                time_budget: Some(1.5),
                ..Default::default()
            }),
            ..Default::default()
        };
        busy.push(tokio::spawn(async move { ik.solve_ik(request).await }));
    }
    while running.load(Ordering::SeqCst) < 2 {
        tokio::time::sleep(Duration::from_millis(1)).await;
    }
    let mut health = HealthClient::new(server.channel.clone());
    let mut worst = Duration::ZERO;
    for _ in 0..20 {
        let started = Instant::now();
        health
            .check(HealthCheckRequest {
                service: String::new(),
            })
            .await
            .unwrap();
        worst = worst.max(started.elapsed());
    }
    assert!(running.load(Ordering::SeqCst) >= 2, "the pool stayed saturated");
    eprintln!("health under a saturated pool: worst of 20 = {worst:?}");
    assert!(worst < Duration::from_millis(200), "{worst:?}");
    for b in busy {
        b.await.unwrap().unwrap();
    }
}

/// Regression: a 60-byte `SolveLinearSystem` (2×1, RLXA, 5e8 iterations,
/// tolerance 1e-300, record_history) reached 7.7 GB; 1e308 entries gave
/// non-finite answers.
#[tokio::test]
async fn linear_system_limits_are_checked_up_front() {
    let server = start(ServerConfig::default()).await;
    let mut ik = KinematicsServiceClient::new(server.channel.clone());
    let request = pb::SolveLinearSystemRequest {
        a: Some(pb::Matrix {
            rows: 2,
            cols: 1,
            data: vec![1.0, 2.0],
        }),
        b: vec![1.0, 1.0],
        method: pb::LinearSolver::AngleRelaxation as i32,
        max_iterations: 500_000_000,
        tolerance: Some(1e-300),
        record_history: true,
        ..Default::default()
    };
    let started = Instant::now();
    let err = ik.solve_linear_system(request.clone()).await.unwrap_err();
    assert_eq!(err.code(), Code::ResourceExhausted, "{err:?}");
    assert!(err.message().starts_with("max_iterations"), "{err:?}");
    assert!(started.elapsed() < Duration::from_secs(1));
    let huge = pb::SolveLinearSystemRequest {
        a: Some(pb::Matrix {
            rows: 2,
            cols: 1,
            data: vec![1e308, 1e308],
        }),
        record_history: false,
        max_iterations: 100,
        ..request
    };
    let err = ik.solve_linear_system(huge).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(err.message().starts_with("a.data[0]"), "{err:?}");
}

/// Regression: `Navigate` GRID_ASTAR with `start.x = 1e308` indexed out of
/// bounds (INTERNAL), and pure pursuit with `state.y = 1e308` answered
/// non-finite numbers.
#[tokio::test]
async fn far_away_coordinates_are_invalid_arguments() {
    let server = start(ServerConfig::default()).await;
    let mut mobile = MobileServiceClient::new(server.channel.clone());
    let request = pb::NavigateRequest {
        chassis: differential(),
        navigator: pb::Navigator::GridAstar as i32,
        start: Some(pb::Pose2D {
            x: 1e308,
            y: 0.0,
            theta: 0.0,
        }),
        goal: Some(pb::Point2D { x: 4.0, y: 0.0 }),
        world: vec![circle(2.0, 0.0, 0.5)],
        ..Default::default()
    };
    let err = mobile.navigate(request).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(err.message().starts_with("start.x"), "{err:?}");
    let step = pb::ControlStepRequest {
        chassis: differential(),
        state: Some(pb::Pose2D {
            x: 0.0,
            y: 1e308,
            theta: 0.0,
        }),
        controller: pb::Controller::PurePursuit as i32,
        path: vec![
            pb::PathNode {
                x: 1.0,
                y: 0.0,
                heading: None,
            },
            pb::PathNode {
                x: 2.0,
                y: 0.0,
                heading: None,
            },
        ],
        ..Default::default()
    };
    let err = mobile.control_step(step).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(err.message().starts_with("state.y"), "{err:?}");
}

/// Regression: a client-forged `ControlStep` token with `steps_in_mode =
/// u64::MAX` overflowed the counter.
#[tokio::test]
async fn forged_control_step_token_is_refused() {
    let server = start(ServerConfig::default()).await;
    let mut mobile = MobileServiceClient::new(server.channel.clone());
    let step = |token: Vec<u8>| pb::ControlStepRequest {
        chassis: differential(),
        state: Some(pb::Pose2D {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        }),
        controller: pb::Controller::VectorDistance as i32,
        goal: Some(pb::Point2D { x: 3.0, y: 0.0 }),
        readings: vec![5.0; 8],
        state_token: token,
        ..Default::default()
    };
    let fresh = mobile.control_step(step(Vec::new())).await.unwrap().into_inner();
    assert!(!fresh.state_token.is_empty());
    let mut token: serde_json::Value = serde_json::from_slice(&fresh.state_token).unwrap();
    token["steps_in_mode"] = serde_json::json!(u64::MAX);
    let err = mobile
        .control_step(step(serde_json::to_vec(&token).unwrap()))
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(err.message().starts_with("state_token"), "{err:?}");
}

/// Regression: an unknown robot name of 3,000 characters was echoed whole in
/// the message and details; the client's metadata limit then turned NOT_FOUND
/// into RESOURCE_EXHAUSTED.
#[tokio::test]
async fn echoed_values_are_truncated() {
    let server = start(ServerConfig::default()).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let err = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named(&"r".repeat(3000)),
            ..Default::default()
        })
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::NotFound, "{err:?}");
    assert!(
        err.message().len() < 400 && err.message().contains('…'),
        "{}",
        err.message().len()
    );
}

/// Regression: `DescribeRobot` with 3,500 nested elements aborted the server
/// (a CPU-pool stack overflow); 840 KB of unclosed elements pinned a CPU for
/// 30–42 s. Both are INVALID_ARGUMENT at once, and the server keeps serving.
#[tokio::test]
async fn hostile_urdfs_are_refused_quickly() {
    let server = start(ServerConfig::default()).await;
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let urdf = |text: String| pb::DescribeRobotRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(text)),
            ..Default::default()
        }),
        ..Default::default()
    };
    let nested = format!(
        r#"<robot name="r"><link name="a"/>{}{}</robot>"#,
        "<x>".repeat(3500),
        "</x>".repeat(3500)
    );
    let unclosed = format!(r#"<robot name="r"><link name="a"/>{}"#, "<x>".repeat(280_000));
    for (what, text) in [("nested", nested), ("unclosed", unclosed)] {
        let started = Instant::now();
        let err = robots.describe_robot(urdf(text)).await.unwrap_err();
        assert_eq!(err.code(), Code::InvalidArgument, "{what}: {err:?}");
        assert!(
            started.elapsed() < Duration::from_millis(500),
            "{what}: {:?}",
            started.elapsed()
        );
    }
    robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named("ur5"),
            ..Default::default()
        })
        .await
        .expect("still serving");
}

/// Regression: scoring with `max_velocity = 5e-324` or time steps of 1e-300 s
/// answered infinities; collision-vertex points on a model of many boxes over
/// many waypoints used gigabytes.
#[tokio::test]
async fn scoring_limits_are_checked_up_front() {
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let rows: Vec<Vec<f64>> = (0..10).map(|k| vec![0.01 * k as f64; 6]).collect();
    let trajectory = |times: Option<f64>| pb::JointTrajectory {
        points: rows
            .iter()
            .enumerate()
            .map(|(k, q)| pb::JointPoint {
                positions: q.clone(),
                time_from_start: times.map_or(0.0, |dt| dt * k as f64),
                ..Default::default()
            })
            .collect(),
        ..Default::default()
    };
    let request = |t: pb::JointTrajectory, options: pb::ScoreOptions| pb::ScoreTrajectoryRequest {
        robot: named("ur5"),
        trajectory: Some(t),
        options: Some(options),
    };
    let err = scoring
        .score_trajectory(request(
            trajectory(None),
            pb::ScoreOptions {
                max_velocity: vec![5e-324; 6],
                ..Default::default()
            },
        ))
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(err.message().starts_with("options.max_velocity[0]"), "{err:?}");
    let err = scoring
        .score_trajectory(request(trajectory(Some(1e-300)), pb::ScoreOptions::default()))
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
    assert!(
        err.message().starts_with("trajectory.points[1].time_from_start"),
        "{err:?}"
    );

    // 1,000 boxes (the model limit) × 8 vertices × 2,000 waypoints: refused up front.
    let boxes =
        r#"<collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision>"#.repeat(1000);
    let urdf = format!(
        r#"<robot name="b"><link name="a"/><link name="b">{boxes}</link>
        <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>"#
    );
    let many = pb::ScoreTrajectoryRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(urdf)),
            ..Default::default()
        }),
        trajectory: Some(pb::JointTrajectory {
            points: (0..2000)
                .map(|k| pb::JointPoint {
                    positions: vec![0.001 * k as f64],
                    time_from_start: 0.0,
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        }),
        options: Some(pb::ScoreOptions {
            robot_points: pb::RobotPoints::CollisionVertices as i32,
            ..Default::default()
        }),
    };
    let err = scoring.score_trajectory(many).await.unwrap_err();
    assert_eq!(err.code(), Code::ResourceExhausted, "{err:?}");
    assert!(err.message().starts_with("options.robot_points"), "{err:?}");
}

/// 200 calls in flight when SIGTERM arrives: health turns NOT_SERVING, every
/// call already sent finishes OK (0 lost), and a call made after the
/// listener closed is refused rather than left hanging.
#[tokio::test]
async fn a_drain_finishes_200_calls_in_flight_and_refuses_new_ones() {
    use kinplan_server::pb::kinematics_service_client::KinematicsServiceClient;
    let mut server = crate::start(ServerConfig {
        drain_delay: Duration::from_millis(150),
        drain_timeout: Duration::from_secs(20),
        ..ServerConfig::default()
    })
    .await;
    // an unreachable target: each call runs until its 15 ms budget is spent
    let request = pb::SolveIkRequest {
        robot: crate::named("ur5"),
        target: Some(pb::Pose {
            position: Some(pb::Vec3 {
                x: 5.0,
                y: 0.0,
                z: 0.0,
            }),
            orientation: Some(pb::Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            }),
        }),
        seed: Vec::new(),
        options: Some(pb::IkOptions {
            time_budget: Some(0.015),
            max_restarts: Some(1_000_000),
            ..Default::default()
        }),
    };
    let calls: Vec<_> = (0..200)
        .map(|_| {
            let mut ik = KinematicsServiceClient::new(server.channel.clone());
            let mut r = tonic::Request::new(request.clone());
            r.set_timeout(Duration::from_secs(30));
            tokio::spawn(async move { ik.solve_ik(r).await })
        })
        .collect();
    tokio::time::sleep(Duration::from_millis(20)).await;
    let mut health = HealthClient::new(server.channel.clone());
    server.stop.take().unwrap().send(()).unwrap();
    tokio::time::sleep(Duration::from_millis(50)).await;
    let status = health
        .check(HealthCheckRequest {
            service: String::new(),
        })
        .await
        .unwrap()
        .into_inner()
        .status;
    assert_eq!(status, 2, "NOT_SERVING during the drain delay");
    let mut lost = 0;
    for c in calls {
        if c.await.unwrap().is_err() {
            lost += 1;
        }
    }
    assert_eq!(lost, 0, "calls in flight lost over the drain");
    tokio::time::timeout(Duration::from_secs(20), server.handle)
        .await
        .expect("the server exits once the calls are done")
        .unwrap();
    // the listener is closed: a new connection is refused
    let refused = tonic::transport::Channel::from_shared(format!("http://{}", server.addr))
        .unwrap()
        .connect()
        .await;
    assert!(refused.is_err());
}
