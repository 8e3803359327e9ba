//! `kinplan-loadtest` against a real server on a free loopback port: every
//! call is counted once, with its status, and the report adds up.

use kinplan_loadtest::{LoadtestArgs, Rpc, run_loadtest};
use kinplan_server::{ServerConfig, serve};

/// A server on a free loopback port, stopped when dropped.
struct TestServer {
    addr: std::net::SocketAddr,
    _stop: tokio::sync::oneshot::Sender<()>,
}

async fn start(config: ServerConfig) -> TestServer {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    tokio::spawn(async move {
        serve(config, listener, async {
            let _ = stopped.await;
        })
        .await
        .unwrap();
    });
    TestServer { addr, _stop: stop }
}

fn args(target: String, rpc: Rpc, total: u64) -> LoadtestArgs {
    LoadtestArgs {
        target,
        rpc,
        robot: "ur5".into(),
        concurrency: 4,
        connections: 2,
        total,
        duration: 10.0,
        rate: 0.0,
        timeout: 5.0,
        pool: 16,
        seed: 1,
        warmup: 2,
        json: None,
        server_pid: None,
    }
}

#[tokio::test]
async fn every_call_is_counted_once_with_its_status() {
    let server = start(ServerConfig::default()).await;
    let addr = server.addr;
    for rpc in [Rpc::Fk, Rpc::Jacobian, Rpc::Ik, Rpc::Score] {
        let report = run_loadtest(&args(addr.to_string(), rpc, 101)).await.unwrap();
        let latency = report.latency.as_ref().unwrap();
        assert_eq!(latency.count, 101, "{rpc:?}");
        assert_eq!(
            report.status_codes.get("OK"),
            Some(&101),
            "{rpc:?}: {:?}",
            report.errors
        );
        assert!(latency.fastest <= latency.at(50.0).unwrap() && latency.at(50.0).unwrap() <= latency.slowest);
        let json = report.to_ghz_json();
        assert_eq!(json["count"], 101);
    }
}

#[tokio::test]
async fn a_duration_run_stops_and_a_rate_is_held() {
    let server = start(ServerConfig::default()).await;
    let addr = server.addr;
    let mut a = args(format!("http://{addr}"), Rpc::Fk, 0);
    a.duration = 0.5;
    a.rate = 200.0;
    let report = run_loadtest(&a).await.unwrap();
    // 200 calls/s for 0.5 s: 100 scheduled calls (a few more or fewer at the edges).
    let n = report.latency.unwrap().count;
    assert!((90..=110).contains(&n), "{n} calls");
    assert!(report.elapsed.as_secs_f64() < 1.5);
}

#[tokio::test]
async fn an_unreachable_server_is_a_clear_error() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    drop(listener);
    let err = run_loadtest(&args(addr.to_string(), Rpc::Fk, 10))
        .await
        .err()
        .unwrap();
    assert!(err.contains("is `kinplan serve` running?"), "{err}");
}
