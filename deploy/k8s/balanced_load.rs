//! Load from the typed Rust client (`kinplan-client`) balanced over several
//! replicas: `Client::connect_balanced` over every address, `ForwardKinematics`
//! calls from `--concurrency` workers, bounded by `--total` calls and
//! `--duration` seconds, optionally paced to `--rate` calls/s. The client's
//! own retry policy is on (UNAVAILABLE retried 3 times, 20/40/80 ms backoff,
//! within the deadline), so a call that fails here failed after its retries:
//! a lost request. Used by deploy/k8s/play.sh while a replica is killed.
//! `--retry-transport-errors` also retries (up to 3 times, at once) a call
//! that failed as UNKNOWN "transport error", which the client does not retry:
//! tonic's status for a call whose connection broke under it.
//!
//! `cargo run --release -p kinplan-client --example balanced_load --
//!  --targets 10.89.0.2:50051,10.89.0.3:50051 --out calls.txt`
//!
//! Writes one line per call to `--out`: start (µs after the first line's
//! epoch), latency (µs), gRPC code (0 = OK). Prints a summary and each
//! distinct error.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use kinplan_client::Client;

struct Args {
    targets: Vec<String>,
    concurrency: usize,
    total: u64,
    duration: f64,
    rate: f64,
    timeout: f64,
    out: String,
    retry_transport_errors: bool,
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        targets: Vec::new(),
        concurrency: 4,
        total: 20_000,
        duration: 30.0,
        rate: 0.0,
        timeout: 5.0,
        out: "balanced_load_rust.txt".into(),
        retry_transport_errors: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        if flag == "--retry-transport-errors" {
            a.retry_transport_errors = true;
            continue;
        }
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        let bad = |e: &dyn std::fmt::Display| format!("{flag} {value}: {e}");
        match flag.as_str() {
            "--targets" => a.targets = value.split(',').map(str::to_owned).collect(),
            "--concurrency" => a.concurrency = value.parse().map_err(|e| bad(&e))?,
            "--total" => a.total = value.parse().map_err(|e| bad(&e))?,
            "--duration" => a.duration = value.parse().map_err(|e| bad(&e))?,
            "--rate" => a.rate = value.parse().map_err(|e| bad(&e))?,
            "--timeout" => a.timeout = value.parse().map_err(|e| bad(&e))?,
            "--out" => a.out = value,
            _ => return Err(format!("unknown flag {flag}")),
        }
    }
    if a.targets.is_empty() || a.concurrency == 0 {
        return Err("give --targets host:port[,host:port...] and --concurrency >= 1".into());
    }
    Ok(a)
}

#[tokio::main(flavor = "multi_thread", worker_threads = 2)]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse()?;
    let client = Client::connect_balanced(args.targets.iter().map(String::as_str))?
        .with_timeout(Duration::from_secs_f64(args.timeout));
    let robot = client.robot("kuka_kr210_r2700_extra");
    let epoch = SystemTime::now().duration_since(UNIX_EPOCH)?.as_secs_f64();
    let start = Instant::now();
    let stop = start + Duration::from_secs_f64(args.duration);
    let sent = Arc::new(AtomicU64::new(0));
    let transport_retries = Arc::new(AtomicU64::new(0));
    // each worker's schedule: one call every `interval` when paced
    let interval = (args.rate > 0.0).then(|| Duration::from_secs_f64(args.concurrency as f64 / args.rate));
    let mut workers = Vec::new();
    for w in 0..args.concurrency {
        let (robot, sent) = (robot.clone(), sent.clone());
        let (total, concurrency) = (args.total, args.concurrency);
        let (retry_transport, transport_retries) = (args.retry_transport_errors, transport_retries.clone());
        workers.push(tokio::spawn(async move {
            let mut calls: Vec<(u64, u64, u8)> = Vec::new();
            let mut errors: BTreeMap<String, u64> = BTreeMap::new();
            // paced workers start spread over one interval
            let mut next =
                start + interval.map_or(Duration::ZERO, |iv| iv.mul_f64(w as f64 / concurrency as f64));
            let mut i = 0u64;
            loop {
                if let Some(iv) = interval {
                    tokio::time::sleep_until(next.into()).await;
                    next += iv;
                }
                let t0 = Instant::now();
                if t0 >= stop || sent.fetch_add(1, Ordering::Relaxed) >= total {
                    break;
                }
                i += 1;
                let q = [0.1 + (i % 100) as f64 * 1e-3, -1.5, 1.4, 0.2, 0.3, 0.4];
                let mut answer = robot.fk(&q).await;
                // what the client does not retry: a call whose connection
                // broke under it (the replica died) is UNKNOWN "transport error"
                for _ in 0..3 {
                    match &answer {
                        Err(e) if retry_transport && is_transport_error(e) => {
                            transport_retries.fetch_add(1, Ordering::Relaxed);
                            answer = robot.fk(&q).await;
                        }
                        _ => break,
                    }
                }
                let code = match answer {
                    Ok(_) => 0,
                    Err(e) => {
                        *errors.entry(e.to_string()).or_default() += 1;
                        e.code() as u8
                    }
                };
                calls.push((
                    (t0 - start).as_micros() as u64,
                    t0.elapsed().as_micros() as u64,
                    code,
                ));
            }
            (calls, errors)
        }));
    }
    let mut calls = Vec::new();
    let mut errors: BTreeMap<String, u64> = BTreeMap::new();
    for w in workers {
        let (c, e) = w.await?;
        calls.extend(c);
        for (message, n) in e {
            *errors.entry(message).or_default() += n;
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    calls.sort_unstable();
    let mut text = format!("# start_epoch {epoch:.6}\n");
    for (t, lat, code) in &calls {
        text.push_str(&format!("{t} {lat} {code}\n"));
    }
    std::fs::write(&args.out, text)?;
    let failed = calls.iter().filter(|c| c.2 != 0).count();
    for (message, n) in &errors {
        println!("  {n} x {message}");
    }
    if args.retry_transport_errors {
        println!(
            "  {} retries of UNKNOWN transport errors (--retry-transport-errors)",
            transport_retries.load(Ordering::Relaxed)
        );
    }
    println!(
        "rust client: {} calls in {elapsed:.1} s, {} answered, {failed} failed after retries",
        calls.len(),
        calls.len() - failed
    );
    Ok(())
}

/// tonic's status for a call whose HTTP/2 connection failed under it.
fn is_transport_error(e: &kinplan_client::Error) -> bool {
    e.code() == kinplan_client::Code::Unknown && e.message() == "transport error"
}
