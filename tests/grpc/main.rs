//! End-to-end tests, one binary: each module starts the real server on a free
//! loopback port and calls it over gRPC, as clients do.

mod analytic;
mod exploration;
mod explore;
mod hardening;
mod hostile;
mod kinematics;
mod mobile;
mod planning;
mod poses;
mod retime;
mod robot;
mod scoring;
mod security;

use kinplan_server::pb::{self, robot_ref::Source};
use kinplan_server::{ServerConfig, serve};
use tonic::transport::Channel;

pub struct TestServer {
    pub addr: std::net::SocketAddr,
    pub channel: Channel,
    pub stop: Option<tokio::sync::oneshot::Sender<()>>,
    pub handle: tokio::task::JoinHandle<()>,
}

/// Starts the server on a free loopback port without connecting to it.
pub async fn spawn(
    config: ServerConfig,
) -> (
    std::net::SocketAddr,
    tokio::sync::oneshot::Sender<()>,
    tokio::task::JoinHandle<()>,
) {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let handle = tokio::spawn(async move {
        serve(config, listener, async {
            let _ = stopped.await;
        })
        .await
        .unwrap();
    });
    (addr, stop, handle)
}

pub async fn start(config: ServerConfig) -> TestServer {
    let (addr, stop, handle) = spawn(config).await;
    let channel = Channel::from_shared(format!("http://{addr}"))
        .unwrap()
        .connect()
        .await
        .unwrap();
    TestServer {
        addr,
        channel,
        stop: Some(stop),
        handle,
    }
}

/// A reference to a built-in robot.
pub fn named(name: &str) -> Option<pb::RobotRef> {
    Some(pb::RobotRef {
        source: Some(Source::Name(name.into())),
        ..Default::default()
    })
}
