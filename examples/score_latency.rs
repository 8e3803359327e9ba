//! Round-trip latency of `ScoreTrajectory` for a 10,000-waypoint KR 210
//! trajectory from a Rust (tonic) client: encode, send (~0.6 MB), FK and
//! every criterion on the server's CPU pool, reply.
//!
//! Start a server (`cargo run --release -- serve`), then
//! `cargo run --release --example score_latency -- [address] [calls] [waypoints]`
//! (defaults 127.0.0.1:50051, 50 and 10000). Prints median, p90 and mean in ms
//! for the default options (link origins) and for collision vertices + series.

use std::time::Instant;

use kinplan_client::pb::{self, robot_ref::Source, scoring_service_client::ScoringServiceClient};

#[tokio::main(flavor = "current_thread")]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let address = args.next().unwrap_or_else(|| "127.0.0.1:50051".into());
    let calls: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(50);
    let n: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(10_000);
    // the typed client's connection; scoring is not wrapped, so the generated stub runs on it
    let mut client = ScoringServiceClient::new(kinplan_client::Client::connect(&address).await?.channel())
        .max_decoding_message_size(64 * 1024 * 1024)
        .max_encoding_message_size(64 * 1024 * 1024);
    let points = (0..n)
        .map(|i| {
            let s = i as f64 / n as f64;
            pb::JointPoint {
                positions: vec![
                    0.9 * s,
                    -1.5 + 0.4 * s,
                    1.4 - 0.5 * s,
                    0.3 * (6.0 * s).sin(),
                    0.5 + 0.2 * s,
                    -0.4 * s,
                ],
                time_from_start: 0.0,
                ..Default::default()
            }
        })
        .collect();
    let base = pb::ScoreTrajectoryRequest {
        robot: Some(pb::RobotRef {
            source: Some(Source::Name("kuka_kr210_r2700_extra".into())),
            ..Default::default()
        }),
        trajectory: Some(pb::JointTrajectory {
            joint_names: Vec::new(),
            points,
        }),
        options: None,
    };
    let full = pb::ScoreTrajectoryRequest {
        options: Some(pb::ScoreOptions {
            series: true,
            robot_points: pb::RobotPoints::CollisionVertices as i32,
            ..Default::default()
        }),
        ..base.clone()
    };
    for (label, request) in [("link origins", base), ("collision vertices + series", full)] {
        for _ in 0..3 {
            client.score_trajectory(request.clone()).await?;
        }
        let mut ms = Vec::with_capacity(calls);
        for _ in 0..calls {
            let request = request.clone(); // not timed: 10,000 row allocations
            let start = Instant::now();
            client.score_trajectory(request).await?;
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        ms.sort_by(f64::total_cmp);
        let pct = |p: f64| ms[((ms.len() - 1) as f64 * p).round() as usize];
        let mean = ms.iter().sum::<f64>() / ms.len() as f64;
        println!(
            "rust ScoreTrajectory KR 210 x{n} waypoints, {label}, {calls} calls: median {:.2} ms, p90 {:.2} ms, mean {mean:.2} ms",
            pct(0.5),
            pct(0.9)
        );
    }
    Ok(())
}
