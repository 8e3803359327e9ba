//! How fast a saturated server says "no": starts `<binary> serve` with two CPU
//! threads and four request slots, holds all four with long IK calls, then
//! sends 200 ListRobots calls at once (and 200 one after another) and reports
//! each shed call's latency from the moment it was sent, with a Rust client
//! (so the figure is the server's, not a slow client's). The same burst
//! answered by the idle server first gives the transport's floor. Then the
//! burst spread over eight connections, and the CPU time the server's I/O
//! threads spend per shed call over `SHED_ROUNDS` (default 200) such bursts:
//! a 200-call burst cannot be answered sooner than 200 times that, divided
//! by the I/O threads.
//!
//! `cargo run --release -p kinplan-loadtest --example shed_burst -- target/release/kinplan`

use std::time::{Duration, Instant};

use kinplan_loadtest::LatencyReport;
use kinplan_proto as pb;
use pb::kinematics_service_client::KinematicsServiceClient;
use pb::robot_service_client::RobotServiceClient;
use tonic::transport::{Channel, Endpoint};

/// p50 and p99 (ms, nearest rank, as the load test reports them) of latencies in ms.
fn p50_p99(ms: &[f64]) -> (f64, f64) {
    let mut ns: Vec<u64> = ms.iter().map(|m| (m * 1e6) as u64).collect();
    let at = |r: &LatencyReport, p| r.at(p).map_or(f64::NAN, |v| v as f64 / 1e6);
    LatencyReport::from_latencies(&mut ns).map_or((f64::NAN, f64::NAN), |r| (at(&r, 50.0), at(&r, 99.0)))
}

fn summary(what: &str, shed_ms: &[f64], others: usize) {
    let (p50, p99) = p50_p99(shed_ms);
    let max = shed_ms.iter().copied().fold(f64::NAN, f64::max);
    println!(
        "{what}: {} shed, {others} other answers; shed latency p50 {p50:.3} ms, p99 {p99:.3} ms, max {max:.3} ms",
        shed_ms.len(),
    );
}

/// One ListRobots call: its latency in ms and whether it was shed.
async fn list(mut robots: RobotServiceClient<Channel>) -> (f64, bool) {
    let started = Instant::now();
    let answer = robots.list_robots(pb::ListRobotsRequest {}).await;
    let ms = started.elapsed().as_secs_f64() * 1e3;
    let shed = matches!(&answer, Err(s) if s.code() == tonic::Code::ResourceExhausted);
    (ms, shed)
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free loopback port")
}

#[tokio::main(flavor = "multi_thread", worker_threads = 2)]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let binary = std::env::args()
        .nth(1)
        .ok_or("usage: shed_burst <path to the kinplan binary>")?;
    let port = free_port();
    let _server = KillOnDrop(
        std::process::Command::new(&binary)
            .args(["serve", "--listen", &format!("127.0.0.1:{port}")])
            .args(["--cpu-threads", "2", "--concurrency-limit", "4"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()?,
    );
    let server_pid = _server.0.id();
    let endpoint = Endpoint::from_shared(format!("http://127.0.0.1:{port}"))?.tcp_nodelay(true);
    let mut channel = None;
    for _ in 0..100 {
        if let Ok(c) = endpoint.connect().await {
            channel = Some(c);
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let channel = channel.ok_or("the server did not start")?;
    let robots = RobotServiceClient::new(channel.clone());
    // Warm the connection and the code paths.
    for _ in 0..50 {
        let _ = list(robots.clone()).await;
    }
    // The floor: the same burst answered (not shed) by an idle server.
    let idle = futures_join(robots.clone(), 200).await;
    let answered: Vec<f64> = idle.iter().filter(|(_, s)| !*s).map(|(ms, _)| *ms).collect();
    let (p50, p99) = p50_p99(&answered);
    println!("200 calls at once, idle server (answered): p50 {p50:.3} ms, p99 {p99:.3} ms");
    // Four calls that run for seconds: a target 10 m away, unlimited restarts.
    let far = pb::SolveIkRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Name("ur5".into())),
            ..Default::default()
        }),
        target: Some(pb::Pose {
            position: Some(pb::Vec3 {
                x: 10.0,
                y: 0.0,
                z: 0.5,
            }),
            orientation: None,
        }),
        seed: vec![],
        options: Some(pb::IkOptions {
            max_restarts: Some(u32::MAX),
            time_budget: Some(3.0),
            ..Default::default()
        }),
    };
    let busy: Vec<_> = (0..4)
        .map(|_| {
            let mut ik = KinematicsServiceClient::new(channel.clone());
            let request = far.clone();
            tokio::spawn(async move { ik.solve_ik(request).await })
        })
        .collect();
    tokio::time::sleep(Duration::from_millis(300)).await;

    let burst = futures_join(robots.clone(), 200).await;
    let shed: Vec<f64> = burst.iter().filter(|(_, s)| *s).map(|(ms, _)| *ms).collect();
    summary(
        "200 calls at once",
        &shed,
        burst.iter().filter(|(_, s)| !*s).count(),
    );

    // The same burst spread over eight connections (eight clients at once),
    // then the CPU time the server's I/O threads spend per shed call over
    // many such bursts.
    let mut channels = Vec::new();
    for _ in 0..8 {
        channels.push(RobotServiceClient::new(endpoint.connect().await?));
    }
    for c in &channels {
        let _ = list(c.clone()).await;
    }
    let spread = spread_join(&channels, 200).await;
    let shed: Vec<f64> = spread.iter().filter(|(_, s)| *s).map(|(ms, _)| *ms).collect();
    summary(
        "200 calls at once over 8 connections",
        &shed,
        spread.iter().filter(|(_, s)| !*s).count(),
    );
    let before = io_cpu_seconds(server_pid);
    let rounds: usize = std::env::var("SHED_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(200);
    let mut shed_calls = 0;
    for _ in 0..rounds {
        shed_calls += spread_join(&channels, 200)
            .await
            .iter()
            .filter(|(_, s)| *s)
            .count();
    }
    if let (Some(a), Some(b)) = (before, io_cpu_seconds(server_pid)) {
        println!(
            "server I/O threads' CPU per shed call over {rounds} such bursts: {:.1} us ({shed_calls} shed)",
            (b - a) * 1e6 / shed_calls.max(1) as f64
        );
    }

    let mut sequential = Vec::new();
    let mut others = 0;
    for _ in 0..200 {
        let (ms, shed) = list(robots.clone()).await;
        if shed {
            sequential.push(ms);
        } else {
            others += 1;
        }
    }
    summary("200 calls one after another", &sequential, others);

    for call in busy {
        let _ = call.await;
    }
    Ok(())
}

/// The server process, stopped however `main` returns.
struct KillOnDrop(std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `n` ListRobots calls started together over `channels` in turn, each
/// timed from its own start.
async fn spread_join(channels: &[RobotServiceClient<Channel>], n: usize) -> Vec<(f64, bool)> {
    let calls: Vec<_> = (0..n)
        .map(|k| tokio::spawn(list(channels[k % channels.len()].clone())))
        .collect();
    let mut out = Vec::with_capacity(n);
    for call in calls {
        if let Ok(result) = call.await {
            out.push(result);
        }
    }
    out
}

/// User plus system CPU time of the server's I/O threads (named
/// `kinplan-io-*`; the CPU pool, busy with the long calls, is left out),
/// seconds, from Linux `/proc`.
fn io_cpu_seconds(pid: u32) -> Option<f64> {
    let mut ticks = 0.0;
    for task in std::fs::read_dir(format!("/proc/{pid}/task")).ok()?.flatten() {
        let comm = std::fs::read_to_string(task.path().join("comm")).unwrap_or_default();
        if !comm.starts_with("kinplan-io") {
            continue;
        }
        let stat = std::fs::read_to_string(task.path().join("stat")).ok()?;
        // fields after the command's closing parenthesis; utime and stime are 14 and 15
        let rest = &stat[stat.rfind(')')? + 2..];
        let fields: Vec<&str> = rest.split_whitespace().collect();
        ticks += fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    }
    // USER_HZ is 100 on Linux
    Some(ticks / 100.0)
}

/// `n` ListRobots calls started together, each timed from its own start.
async fn futures_join(robots: RobotServiceClient<Channel>, n: usize) -> Vec<(f64, bool)> {
    let calls: Vec<_> = (0..n).map(|_| tokio::spawn(list(robots.clone()))).collect();
    let mut out = Vec::with_capacity(n);
    for call in calls {
        if let Ok(result) = call.await {
            out.push(result);
        }
    }
    out
}
