//! `kinplan-loadtest`: drives a running kinplan server at high rate and
//! reports latency percentiles, throughput and status codes (see `--help`).

use clap::Parser;
use kinplan_loadtest::{LoadtestArgs, MIN_WORKER_INTERVAL, run_loadtest, workers_for_rate};

/// mimalloc instead of the C library's allocator, as the server uses: a call
/// allocates and frees a few dozen small buffers (HTTP/2 frames, headers,
/// messages) across threads, where glibc's malloc/free showed in the client's
/// CPU profile too (the figures are in `benches/RESULTS.md`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "kinplan-loadtest",
    version,
    about = "Load-test a running kinplan server (latency percentiles, throughput, status codes)"
)]
struct Cli {
    #[command(flatten)]
    args: LoadtestArgs,
}

fn main() {
    let args = Cli::parse().args;
    if let Err(err) = loadtest(&args) {
        eprintln!("kinplan-loadtest: {err}");
        std::process::exit(1);
    }
}

fn loadtest(args: &LoadtestArgs) -> Result<(), String> {
    if args.rate > 0.0 && args.concurrency < workers_for_rate(args.rate) {
        eprintln!(
            "kinplan-loadtest: note: {} workers at {} calls/s send every {:.2} ms each, under {} ms; \
             latencies include the client's timer delay (use --concurrency {} or more)",
            args.concurrency,
            args.rate,
            args.concurrency as f64 / args.rate * 1e3,
            MIN_WORKER_INTERVAL.as_millis(),
            workers_for_rate(args.rate),
        );
    }
    // Only coordinates: each connection runs on a thread of its own.
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    let report = runtime.block_on(run_loadtest(args))?;
    print!("{}", report.summary());
    Ok(())
}
