//! Round-trip latency of `SolveIk` and the sustained rate of `StreamIk` from
//! the typed Rust client (`kinplan-client`), on a KUKA KR 210 R2700 extra.
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
//!   pipelined: up to 32 targets in flight (sustained rate).
//!
//! Each line gives the client round trip (median, p99, mean) and the server's solve
//! time (median), so the transport share can be read off.

use std::time::Instant;

use kinplan_client::{Client, IkOptions};
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};

const ROBOT: &str = "kuka_kr210_r2700_extra";

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
    let robot = Client::connect(&address).await?.robot(ROBOT);
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
    let targets: Vec<Isometry3<f64>> = joints.iter().map(|q| chain.fk(q)).collect();
    let options = IkOptions::default();
    for warm in [false, true] {
        let label = if warm {
            "SolveIk warm (seed 0.01 rad away)"
        } else {
            "SolveIk cold (mid-limit seed)"
        };
        let seed = |q: &Vec<f64>| -> Vec<f64> {
            if warm {
                q.iter().map(|v| v + 0.01).collect()
            } else {
                Vec::new()
            }
        };
        for (q, t) in joints.iter().zip(&targets).take(200) {
            robot.ik(t, &seed(q), &options).await?;
        }
        let (mut c, mut s, mut failures) = (Vec::with_capacity(calls), Vec::with_capacity(calls), 0);
        for (q, t) in joints.iter().zip(&targets) {
            let seed = seed(q);
            let start = Instant::now();
            let answer = robot.ik(t, &seed, &options).await?;
            c.push(start.elapsed().as_secs_f64() * 1e6);
            s.push(answer.elapsed.as_secs_f64() * 1e6);
            failures += usize::from(!answer.success);
        }
        report(label, c, s, failures);
    }

    // StreamIk along a 10 mm circle, 1000 steps per turn
    let q0 = [0.2, -1.6, 1.7, 0.3, 0.8, -0.2];
    let start = chain.fk(&q0);
    let centre = start.translation.vector - Vector3::new(0.01, 0.0, 0.0);
    let circle: Vec<Isometry3<f64>> = (0..calls)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 1000.0;
            let mut t = start;
            t.translation.vector = centre + Vector3::new(a.cos(), a.sin(), 0.0) * 0.01;
            t
        })
        .collect();
    // lockstep: send one, await its answer
    let mut session = robot.ik_stream(&q0, &options).await?;
    let (mut c, mut s, mut failures) = (Vec::with_capacity(calls), Vec::with_capacity(calls), 0);
    let began = Instant::now();
    for target in &circle {
        let t = Instant::now();
        let answer = session.solve(target).await?;
        c.push(t.elapsed().as_secs_f64() * 1e6);
        s.push(answer.elapsed.as_secs_f64() * 1e6);
        failures += usize::from(!answer.success);
    }
    let rate = calls as f64 / began.elapsed().as_secs_f64();
    drop(session);
    report("StreamIk lockstep (10 mm circle)", c, s, failures);
    println!("rust StreamIk lockstep sustained rate: {rate:.0} targets/s");

    // pipelined: keep up to 32 targets in flight, read the answers as they come
    let mut session = robot.ik_stream(&q0, &options).await?;
    let began = Instant::now();
    let (mut sent, mut received, mut failures) = (0, 0, 0);
    while received < calls {
        while sent < calls && sent - received < 32 {
            session.send(&circle[sent], &[]).await?;
            sent += 1;
        }
        let (_, answer) = session.recv().await?;
        failures += usize::from(!answer.success);
        received += 1;
    }
    let elapsed = began.elapsed().as_secs_f64();
    println!(
        "rust StreamIk pipelined x{received}: {:.0} targets/s ({:.1} µs per target); not converged {failures}",
        received as f64 / elapsed,
        elapsed * 1e6 / received as f64
    );
    Ok(())
}
