//! `kinplan serve`: the gRPC server with built-in defaults; every setting is
//! a flag and an environment variable. `kinplan health` asks a server for its
//! serving status. (The load test is its own binary, `kinplan-loadtest`.)

use std::net::SocketAddr;
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};
use kinplan_server::{ServerConfig, TlsPem, Tokens, serve};

mod health;

use health::{HealthArgs, check_health};

/// mimalloc instead of the C library's allocator: a call allocates and frees
/// a few dozen small buffers (HTTP/2 frames, headers, messages) across
/// threads, where glibc's malloc/free showed in the server's CPU profile
/// (the figures are in `benches/RESULTS.md`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(name = "kinplan", version, about = "Stateless gRPC motion-planning service")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once at startup: the size of the serve flags does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Run the gRPC server.
    Serve(ServeArgs),
    /// Ask a server for its health (exit 0 when SERVING).
    Health(HealthArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum LogFormat {
    Text,
    Json,
}

#[derive(clap::Args)]
struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "KINPLAN_LISTEN", default_value = "127.0.0.1:50051")]
    listen: SocketAddr,
    /// I/O threads, each running its own single-threaded async runtime that
    /// serves the connections handed to it round robin (0: one per core).
    #[arg(long, env = "KINPLAN_WORKER_THREADS", default_value_t = 0)]
    worker_threads: usize,
    /// Threads of the CPU pool that runs the algorithms (0: one per core).
    #[arg(long, env = "KINPLAN_CPU_THREADS", default_value_t = 0)]
    cpu_threads: usize,
    /// Nice value (0–19) of the CPU pool's threads. The default, 10, keeps
    /// admission and health prompt when every core computes; on a host shared
    /// with other processes, 0 stops those from starving computed calls.
    #[arg(long, env = "KINPLAN_CPU_NICE", default_value_t = 10,
          value_parser = clap::value_parser!(i32).range(0..=19))]
    cpu_nice: i32,
    /// Let the allocator's heap use transparent huge pages where the host
    /// allows them. Off by default: the kernel zeroes (and may compact
    /// memory for) each 2 MiB page inside the call that first touches it.
    #[arg(long, env = "KINPLAN_HUGE_PAGES")]
    huge_pages: bool,
    /// Largest request or response message, bytes.
    #[arg(long, env = "KINPLAN_MAX_MESSAGE_BYTES", default_value_t = 16 * 1024 * 1024)]
    max_message_bytes: usize,
    /// Deadline (seconds) for requests that bring none; 0 for none.
    #[arg(long, env = "KINPLAN_REQUEST_TIMEOUT_SECS", default_value_t = 60.0)]
    request_timeout_secs: f64,
    /// Requests in the server at once; more are shed with RESOURCE_EXHAUSTED.
    #[arg(long, env = "KINPLAN_CONCURRENCY_LIMIT", default_value_t = 256)]
    concurrency_limit: usize,
    /// Serve Prometheus metrics over HTTP on this address (off when unset).
    #[arg(long, env = "KINPLAN_METRICS_LISTEN")]
    metrics_listen: Option<SocketAddr>,
    /// Log format.
    #[arg(long, env = "KINPLAN_LOG_FORMAT", value_enum, default_value = "text")]
    log_format: LogFormat,
    /// Seconds between reporting NOT_SERVING and closing the listener.
    #[arg(long, env = "KINPLAN_DRAIN_DELAY_SECS", default_value_t = 0.0)]
    drain_delay_secs: f64,
    /// Seconds calls in flight may take to finish after the listener closes;
    /// then open streams end with UNAVAILABLE and the server exits.
    #[arg(long, env = "KINPLAN_DRAIN_TIMEOUT_SECS", default_value_t = 10.0)]
    drain_timeout_secs: f64,
    /// Seconds a `StreamIk` stream may stay silent before it is ended.
    #[arg(long, env = "KINPLAN_STREAM_IDLE_TIMEOUT_SECS", default_value_t = 60.0)]
    stream_idle_timeout_secs: f64,
    /// Largest inline URDF, bytes.
    #[arg(long, env = "KINPLAN_MAX_URDF_BYTES", default_value_t = 2 * 1024 * 1024)]
    max_urdf_bytes: usize,
    /// Parsed robot models kept in the cache.
    #[arg(long, env = "KINPLAN_MODEL_CACHE", default_value_t = 256)]
    model_cache: usize,
    /// Random states sampled for each robot's allowed-collision matrix
    /// (computed once per model).
    #[arg(long, env = "KINPLAN_ACM_SAMPLES", default_value_t = 10_000)]
    acm_samples: usize,
    /// Bytes of URDF text and parsed models the cache may hold.
    #[arg(long, env = "KINPLAN_MODEL_CACHE_BYTES", default_value_t = 256 * 1024 * 1024)]
    model_cache_bytes: usize,
    /// Serve TLS with this certificate chain (PEM file); needs --tls-key.
    #[arg(long, env = "KINPLAN_TLS_CERT", requires = "tls_key")]
    tls_cert: Option<std::path::PathBuf>,
    /// The certificate's private key (PEM file).
    #[arg(long, env = "KINPLAN_TLS_KEY", requires = "tls_cert")]
    tls_key: Option<std::path::PathBuf>,
    /// Require client certificates signed by this CA (PEM file): mutual TLS.
    #[arg(long, env = "KINPLAN_TLS_CLIENT_CA", requires = "tls_cert")]
    tls_client_ca: Option<std::path::PathBuf>,
    /// Require `authorization: Bearer <token>` with one of these tokens
    /// (comma-separated); health checks and reflection stay open.
    #[arg(
        long,
        env = "KINPLAN_AUTH_TOKENS",
        value_delimiter = ',',
        hide_env_values = true
    )]
    auth_tokens: Vec<String>,
    /// Like --auth-tokens, from a file with one token per line.
    #[arg(long, env = "KINPLAN_AUTH_TOKENS_FILE")]
    auth_tokens_file: Option<std::path::PathBuf>,
}

/// Reads a file named on the command line (never one named in a request).
fn read_file(path: &std::path::Path, flag: &str) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{flag} {}: {e}", path.display()))
}

/// TLS and token settings from the flags.
fn security(args: &ServeArgs) -> Result<(Option<TlsPem>, Option<Tokens>), String> {
    let tls = match (&args.tls_cert, &args.tls_key) {
        (Some(cert), Some(key)) => Some(TlsPem {
            cert: read_file(cert, "--tls-cert")?,
            key: read_file(key, "--tls-key")?,
            client_ca: args
                .tls_client_ca
                .as_deref()
                .map(|p| read_file(p, "--tls-client-ca"))
                .transpose()?,
        }),
        _ => None,
    };
    let mut tokens = args.auth_tokens.clone();
    if let Some(path) = &args.auth_tokens_file {
        let text = String::from_utf8(read_file(path, "--auth-tokens-file")?)
            .map_err(|_| "--auth-tokens-file is not UTF-8".to_string())?;
        tokens.extend(text.lines().map(str::to_string));
    }
    let any_given = !args.auth_tokens.is_empty() || args.auth_tokens_file.is_some();
    let tokens = Tokens::new(tokens);
    if any_given && tokens.is_none() {
        return Err("--auth-tokens / --auth-tokens-file name no token".into());
    }
    Ok((tls, tokens))
}

fn main() {
    match Cli::parse().command {
        Command::Serve(args) => {
            init_logging(args.log_format);
            if let Err(err) = run(args) {
                tracing::error!("{err}");
                eprintln!("kinplan: {err}");
                std::process::exit(1);
            }
        }
        Command::Health(args) => match client_runtime().and_then(|rt| rt.block_on(check_health(&args))) {
            Ok(status) => {
                println!("{status}");
                std::process::exit(if status == "SERVING" { 0 } else { 1 });
            }
            Err(err) => {
                eprintln!("kinplan health: {err}");
                std::process::exit(2);
            }
        },
    }
}

fn client_runtime() -> Result<tokio::runtime::Runtime, String> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())
}

fn init_logging(format: LogFormat) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let builder = tracing_subscriber::fmt().with_env_filter(filter);
    match format {
        LogFormat::Text => builder.init(),
        LogFormat::Json => builder.json().init(),
    }
}

fn seconds(value: f64, flag: &str) -> Result<Duration, String> {
    Duration::try_from_secs_f64(value).map_err(|_| format!("{flag} must be a non-negative number of seconds"))
}

fn run(args: ServeArgs) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    if !args.huge_pages {
        kinplan_server::runtime::memory::disable_transparent_huge_pages();
    }
    // Accepts connections, handles signals and serves metrics; the calls run
    // on the I/O threads `serve` starts.
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    let timeout = seconds(args.request_timeout_secs, "--request-timeout-secs")?;
    let (tls, auth_tokens) = security(&args)?;
    if tls.is_some() {
        tracing::info!(mutual = args.tls_client_ca.is_some(), "serving TLS");
    }
    if auth_tokens.is_some() {
        tracing::info!("bearer-token authentication on (health and reflection stay open)");
    }
    let config = ServerConfig {
        tls,
        auth_tokens,
        cpu_threads: args.cpu_threads,
        io_threads: args.worker_threads,
        cpu_nice: args.cpu_nice,
        max_message_bytes: args.max_message_bytes,
        request_timeout: (!timeout.is_zero()).then_some(timeout),
        concurrency_limit: args.concurrency_limit,
        max_urdf_bytes: args.max_urdf_bytes,
        model_cache_entries: args.model_cache,
        acm_samples: args.acm_samples,
        model_cache_bytes: args.model_cache_bytes,
        drain_delay: seconds(args.drain_delay_secs, "--drain-delay-secs")?,
        drain_timeout: seconds(args.drain_timeout_secs, "--drain-timeout-secs")?,
        stream_idle_timeout: seconds(args.stream_idle_timeout_secs, "--stream-idle-timeout-secs")?,
        ..ServerConfig::default()
    };
    runtime.block_on(async move {
        if let Some(addr) = args.metrics_listen {
            metrics_exporter_prometheus::PrometheusBuilder::new()
                .with_http_listener(addr)
                .set_buckets_for_metric(
                    metrics_exporter_prometheus::Matcher::Full("grpc_server_handling_seconds".into()),
                    kinplan_server::HANDLING_BUCKETS,
                )?
                .install()?;
            tracing::info!(%addr, "metrics on http://{addr}/metrics");
        }
        let listener = tokio::net::TcpListener::bind(args.listen).await?;
        serve(config, listener, shutdown_signal()).await
    })
}

/// Resolves on SIGINT or SIGTERM.
async fn shutdown_signal() {
    let interrupt = tokio::signal::ctrl_c();
    #[cfg(unix)]
    {
        let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
            .expect("SIGTERM handler installs");
        tokio::select! {
            _ = interrupt => {},
            _ = term.recv() => {},
        }
    }
    #[cfg(not(unix))]
    let _ = interrupt.await;
}
