//! Hostile-client regressions (issue 9): each test is named after what broke —
//! a process abort, a panic, work outliving its deadline, idle streams holding
//! admission, a shutdown that never ends, wrong codes.

use std::time::{Duration, Instant};

use kinplan_server::service::ServerConfig;
use kinplan_server::service::pb::{
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
