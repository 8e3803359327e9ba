//! Round-trip latency of `Navigate` from a Rust (tonic) client: a whole vector-distance run
//! (sensing, navigator, collision checks, ~200–400 steps) in a seeded 20-cylinder world on
//! the server's CPU pool, and the reply with every state and command; plus `ControlStep`
//! (one navigator step with given readings) and `WheelKinematics` for comparison.
//!
//! Start a server (`cargo run --release -- serve`), then
//! `cargo run --release --example navigate_latency -- [address] [calls]`
//! (defaults 127.0.0.1:50051 and 200). Prints median, p99 and mean in ms.

use std::future::Future;
use std::time::Instant;

use kinplan_client::pb::{self, mobile_service_client::MobileServiceClient};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The world of benches/mobile.rs: 30 seeded cylinders between (0, 0) and (10, 0).
fn clutter(seed: u64) -> Vec<pb::Obstacle> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut obs: Vec<(f64, f64, f64)> = Vec::new();
    for _ in 0..100_000 {
        if obs.len() == 20 {
            break;
        }
        let (x, y): (f64, f64) = (rng.random_range(1.5..8.5), rng.random_range(-2.0..2.0));
        let r: f64 = rng.random_range(0.15..0.4);
        if x.hypot(y) < r + 1.0 || (x - 10.0).hypot(y) < r + 1.0 {
            continue;
        }
        if obs
            .iter()
            .any(|&(ox, oy, or)| (ox - x).hypot(oy - y) < r + or + 0.45)
        {
            continue;
        }
        obs.push((x, y, r));
    }
    obs.into_iter()
        .map(|(x, y, radius)| pb::Obstacle {
            shape: Some(pb::obstacle::Shape::Circle(pb::Circle {
                center: Some(pb::Point2D { x, y }),
                radius,
            })),
        })
        .collect()
}

async fn time<F, Fut>(label: &str, calls: usize, mut call: F) -> Result<(), Box<dyn std::error::Error>>
where
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<(), tonic::Status>>,
{
    for _ in 0..5 {
        call().await?;
    }
    let mut ms = Vec::with_capacity(calls);
    for _ in 0..calls {
        let start = Instant::now();
        call().await?;
        ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    ms.sort_by(f64::total_cmp);
    let pct = |p: f64| ms[((ms.len() - 1) as f64 * p).round() as usize];
    let mean = ms.iter().sum::<f64>() / ms.len() as f64;
    println!(
        "rust {label}, {calls} calls: median {:.3} ms, p99 {:.3} ms, mean {mean:.3} ms",
        pct(0.5),
        pct(0.99)
    );
    Ok(())
}

#[tokio::main(flavor = "current_thread")]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let address = args.next().unwrap_or_else(|| "127.0.0.1:50051".into());
    let calls: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(200);
    // the typed client's connection (address forms, keep-alive); navigation calls
    // are not wrapped, so the generated stub runs on its channel
    let client = MobileServiceClient::new(kinplan_client::Client::connect(&address).await?.channel());
    let navigate = pb::NavigateRequest {
        start: Some(pb::Pose2D::default()),
        goal: Some(pb::Point2D { x: 10.0, y: 0.0 }),
        world: clutter(1),
        ..Default::default()
    };
    let run = client.clone().navigate(navigate.clone()).await?.into_inner();
    let m = run.metrics.unwrap_or_default();
    println!(
        "Navigate run: outcome {:?}, {} steps, {:.2} m, reply {} states",
        pb::Outcome::try_from(run.outcome),
        m.steps,
        m.path_length,
        run.states.len()
    );
    time(
        "Navigate (vector distance, 20 cylinders, whole run)",
        calls,
        || {
            let (mut c, r) = (client.clone(), navigate.clone());
            async move { c.navigate(r).await.map(|_| ()) }
        },
    )
    .await?;
    let step = pb::ControlStepRequest {
        controller: pb::Controller::VectorDistance as i32,
        goal: Some(pb::Point2D { x: 5.0, y: 0.0 }),
        readings: vec![0.1, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0],
        ..Default::default()
    };
    time("ControlStep (vector distance, given readings)", calls, || {
        let (mut c, r) = (client.clone(), step.clone());
        async move { c.control_step(r).await.map(|_| ()) }
    })
    .await?;
    let wheels = pb::WheelKinematicsRequest {
        chassis: Some(pb::Chassis {
            kind: Some(pb::chassis::Kind::Omni(Default::default())),
        }),
        input: Some(pb::wheel_kinematics_request::Input::Twist(pb::Twist2D {
            vx: 0.2,
            vy: 0.1,
            omega: 0.5,
        })),
    };
    time("WheelKinematics (omni inverse)", calls, || {
        let (mut c, r) = (client.clone(), wheels.clone());
        async move { c.wheel_kinematics(r).await.map(|_| ()) }
    })
    .await?;
    Ok(())
}
