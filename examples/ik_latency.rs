//! Round-trip latency of `SolveIk` and the sustained rate of `StreamIk` from a
//! Rust (tonic) client, on a KUKA KR 210 R2700 extra.
//!
//! Start a server (`cargo run --release -- serve`), then
//! `cargo run --release --example ik_latency -- [address] [calls]`
//! (defaults 127.0.0.1:50051 and 2000). Prints, in µs:
//! - `SolveIk` cold: random reachable poses (FK of uniform random joints within the
//!   limits, seeded), seed at the middle of the limits, LM + SVD, default options
//!   (1e-5 m / rad, up to 200 restarts) — the TRAC-IK protocol over gRPC;
//! - `SolveIk` warm: the same poses seeded from joints 0.01 rad away (a tracking
//!   controller's case), which isolates the transport cost;
//! - `StreamIk` lockstep: one target per message along a 10 mm circle (S2), each
//!   answer awaited before the next target is sent (a controller cycle), and
//!   pipelined: all targets sent without waiting (sustained rate).
//!
//! Each line gives the client round trip (median, p99, mean) and the server's solve
//! time (`elapsed_us` median), so the transport share can be read off.

use std::time::Instant;

use kinplan_server::service::pb::{
    self, kinematics_service_client::KinematicsServiceClient, robot_ref::Source,
};
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};

const ROBOT: &str = "kuka_kr210_r2700_extra";

fn robot() -> Option<pb::RobotRef> {
    Some(pb::RobotRef {
        source: Some(Source::Name(ROBOT.into())),
        ..Default::default()
    })
}

fn pose(t: &Isometry3<f64>) -> pb::Pose {
    let q = t.rotation.quaternion();
    let p = t.translation.vector;
    pb::Pose {
        position: Some(pb::Vec3 {
            x: p.x,
            y: p.y,
            z: p.z,
        }),
        orientation: Some(pb::Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }),
    }
}

fn report(label: &str, mut client_us: Vec<f64>, mut server_us: Vec<f64>, failures: usize) {
    client_us.sort_by(f64::total_cmp);
    server_us.sort_by(f64::total_cmp);
    let pct = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let mean = client_us.iter().sum::<f64>() / client_us.len() as f64;
    println!(
        "rust {label} x{}: median {:.1} µs, p99 {:.1} µs, mean {mean:.1} µs; server solve median {:.1} µs; \
         not converged {failures}",
        client_us.len(),
        pct(&client_us, 0.5),
        pct(&client_us, 0.99),
        pct(&server_us, 0.5),
    );
}

#[tokio::main(flavor = "current_thread")]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let address = args.next().unwrap_or_else(|| "127.0.0.1:50051".into());
    let calls: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(2000);
    let mut client = KinematicsServiceClient::connect(format!("http://{address}")).await?;
    let chain = kinplan_core::robot::builtin_chain(ROBOT)?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2026);
    let joints: Vec<Vec<f64>> = (0..calls)
        .map(|_| {
            chain
                .joints()
                .iter()
                .map(|j| rng.random_range(j.lower..=j.upper))
                .collect()
        })
        .collect();
    let requests = |warm: bool| -> Vec<pb::SolveIkRequest> {
        joints
            .iter()
            .map(|q| pb::SolveIkRequest {
                robot: robot(),
                target: Some(pose(&chain.fk(q))),
                seed: if warm {
                    q.iter().map(|v| v + 0.01).collect()
                } else {
                    Vec::new()
                },
                options: None,
            })
            .collect()
    };
    for (label, requests) in [
        ("SolveIk cold (mid-limit seed)", requests(false)),
        ("SolveIk warm (seed 0.01 rad away)", requests(true)),
    ] {
        for r in requests.iter().take(200) {
            client.solve_ik(r.clone()).await?;
        }
        let (mut c, mut s, mut failures) = (Vec::with_capacity(calls), Vec::with_capacity(calls), 0);
        for r in requests {
            let start = Instant::now();
            let reply = client.solve_ik(r).await?.into_inner();
            c.push(start.elapsed().as_secs_f64() * 1e6);
            s.push(reply.elapsed_us as f64);
            failures += usize::from(!reply.success);
        }
        report(label, c, s, failures);
    }

    // StreamIk along a 10 mm circle, 1000 steps per turn
    let q0 = [0.2, -1.6, 1.7, 0.3, 0.8, -0.2];
    let start = chain.fk(&q0);
    let centre = start.translation.vector - Vector3::new(0.01, 0.0, 0.0);
    let targets: Vec<pb::Pose> = (0..calls)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 1000.0;
            let mut t = start;
            t.translation.vector = centre + Vector3::new(a.cos(), a.sin(), 0.0) * 0.01;
            pose(&t)
        })
        .collect();
    let message = |k: usize| pb::StreamIkRequest {
        sequence: k as u64,
        robot: if k == 0 { robot() } else { None },
        options: None,
        seed: if k == 0 { q0.to_vec() } else { Vec::new() },
        target: Some(targets[k]),
    };
    // lockstep: send one, await its answer
    let (tx, rx) = tokio::sync::mpsc::channel(16);
    let mut answers = client
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await?
        .into_inner();
    let (mut c, mut s, mut failures) = (Vec::with_capacity(calls), Vec::with_capacity(calls), 0);
    let began = Instant::now();
    for k in 0..calls {
        let t = Instant::now();
        tx.send(message(k)).await?;
        let answer = answers.message().await?.ok_or("stream ended")?;
        c.push(t.elapsed().as_secs_f64() * 1e6);
        let r = answer.result.unwrap_or_default();
        s.push(r.elapsed_us as f64);
        failures += usize::from(!r.success);
    }
    let rate = calls as f64 / began.elapsed().as_secs_f64();
    drop(tx);
    while answers.message().await?.is_some() {}
    report("StreamIk lockstep (10 mm circle)", c, s, failures);
    println!("rust StreamIk lockstep sustained rate: {rate:.0} targets/s");

    // pipelined: a sender task streams every target, the answers are read as they come
    let (tx, rx) = tokio::sync::mpsc::channel(64);
    let mut answers = client
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await?
        .into_inner();
    let msgs: Vec<_> = (0..calls).map(message).collect();
    let began = Instant::now();
    let sender = tokio::spawn(async move {
        for m in msgs {
            if tx.send(m).await.is_err() {
                break;
            }
        }
    });
    let (mut received, mut failures) = (0, 0);
    while let Some(a) = answers.message().await? {
        failures += usize::from(!a.result.unwrap_or_default().success);
        received += 1;
        if received == calls {
            break;
        }
    }
    let elapsed = began.elapsed().as_secs_f64();
    sender.await?;
    println!(
        "rust StreamIk pipelined x{received}: {:.0} targets/s ({:.1} µs per target); not converged {failures}",
        received as f64 / elapsed,
        elapsed * 1e6 / received as f64
    );
    Ok(())
}
