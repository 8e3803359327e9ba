//! Round-trip latency of `ForwardKinematics` from the typed Rust client
//! (`kinplan-client`).
//!
//! Start a server (`cargo run --release -- serve`), then
//! `cargo run --release --example fk_latency -- [address] [calls]`
//! (defaults 127.0.0.1:50051 and 10000). Prints median, p99 and mean in µs.

use std::time::Instant;

use kinplan_client::Client;

#[tokio::main(flavor = "current_thread")]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let address = args.next().unwrap_or_else(|| "127.0.0.1:50051".into());
    let calls: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(10_000);
    let robot = Client::connect(&address).await?.robot("kuka_kr210_r2700_extra");
    let q = [0.1, -1.5, 1.4, 0.2, 0.3, 0.4];
    for _ in 0..500 {
        robot.fk(&q).await?;
    }
    let mut micros = Vec::with_capacity(calls);
    for _ in 0..calls {
        let start = Instant::now();
        robot.fk(&q).await?;
        micros.push(start.elapsed().as_secs_f64() * 1e6);
    }
    micros.sort_by(f64::total_cmp);
    let pct = |p: f64| micros[((micros.len() - 1) as f64 * p).round() as usize];
    let mean = micros.iter().sum::<f64>() / micros.len() as f64;
    println!(
        "rust ForwardKinematics x{calls}: median {:.1} µs, p99 {:.1} µs, mean {mean:.1} µs",
        pct(0.5),
        pct(0.99)
    );
    Ok(())
}
