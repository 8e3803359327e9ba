//! The load-test loop: `concurrency` workers spread over `connections`
//! HTTP/2 connections, each sending calls back to back (or on a schedule when
//! a target rate is set), until a call count or a duration is reached. Each
//! connection and its workers run on a thread of their own.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use tokio::sync::{mpsc, oneshot, watch};
use tonic::transport::{Channel, Endpoint};

use super::report::{LatencyReport, Report};
use super::workload::{Rpc, Workload, build_pool};
use kinplan_proto::code_name;
use kinplan_proto::kinematics_service_client::KinematicsServiceClient;
use kinplan_proto::robot_service_client::RobotServiceClient;
use kinplan_proto::scoring_service_client::ScoringServiceClient;

/// Options of `kinplan-loadtest`.
#[derive(clap::Args, Debug, Clone)]
pub struct LoadtestArgs {
    /// Server address: host:port, or a URI with http://.
    #[arg(long, default_value = "127.0.0.1:50051")]
    pub target: String,
    /// The RPC to call.
    #[arg(long, value_enum, default_value = "fk")]
    pub rpc: Rpc,
    /// Built-in robot the requests name.
    #[arg(long, default_value = "kuka_kr210_r2700_extra")]
    pub robot: String,
    /// Workers sending calls at once.
    #[arg(long, default_value_t = 16)]
    pub concurrency: usize,
    /// HTTP/2 connections the workers share (round robin).
    #[arg(long, default_value_t = 2)]
    pub connections: usize,
    /// Calls to send; 0: run for --duration.
    #[arg(long, default_value_t = 0)]
    pub total: u64,
    /// Seconds to run when --total is 0.
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Target calls per second over all workers; 0: as fast as possible.
    /// With a rate, a call sent late because the server fell behind counts
    /// its latency from its scheduled start (no coordinated omission). Give
    /// enough workers that each sends at most every few milliseconds
    /// (--concurrency ≥ rate × 3 ms): the timer wakes a worker up to 1 ms late,
    /// and a worker whose next call is already due then counts that delay too.
    #[arg(long, default_value_t = 0.0)]
    pub rate: f64,
    /// Deadline of each call, seconds.
    #[arg(long, default_value_t = 1.0)]
    pub timeout: f64,
    /// Distinct prepared requests, cycled through.
    #[arg(long, default_value_t = 1024)]
    pub pool: usize,
    /// Seed of the request pool.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Calls per worker before the clock starts (not counted).
    #[arg(long, default_value_t = 20)]
    pub warmup: u64,
    /// Write the report as ghz-shaped JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Also report this process's CPU time over the run (the server's pid
    /// when it runs on this machine; Linux /proc).
    #[arg(long)]
    pub server_pid: Option<u32>,
}

/// What one worker saw.
#[derive(Default)]
struct Tally {
    latencies_ns: Vec<u64>,
    /// Calls by gRPC status code (0 = OK … 16 = UNAUTHENTICATED).
    codes: [u64; 17],
    errors: BTreeMap<String, u64>,
}

impl Tally {
    fn add(&mut self, other: Tally) {
        self.latencies_ns.extend(other.latencies_ns);
        for (a, b) in self.codes.iter_mut().zip(other.codes) {
            *a += b;
        }
        for (k, v) in other.errors {
            *self.errors.entry(k).or_default() += v;
        }
    }
}

/// Clients of every service on one connection.
#[derive(Clone)]
struct Clients {
    robot: RobotServiceClient<Channel>,
    kinematics: KinematicsServiceClient<Channel>,
    scoring: ScoringServiceClient<Channel>,
}

impl Clients {
    fn new(channel: Channel) -> Self {
        Self {
            robot: RobotServiceClient::new(channel.clone()),
            kinematics: KinematicsServiceClient::new(channel.clone()),
            scoring: ScoringServiceClient::new(channel),
        }
    }

    /// Sends one call; the status code and, on failure, its message.
    async fn call(&mut self, work: &Workload, timeout: Duration) -> Result<(), tonic::Status> {
        fn req<T>(msg: T, timeout: Duration) -> tonic::Request<T> {
            let mut r = tonic::Request::new(msg);
            r.set_timeout(timeout);
            r
        }
        match work {
            Workload::Fk(m) => self
                .robot
                .forward_kinematics(req(m.clone(), timeout))
                .await
                .map(drop),
            Workload::Jacobian(m) => self.robot.jacobian(req(m.clone(), timeout)).await.map(drop),
            Workload::Ik(m) => self.kinematics.solve_ik(req(m.clone(), timeout)).await.map(drop),
            Workload::Score(m) => self
                .scoring
                .score_trajectory(req(m.clone(), timeout))
                .await
                .map(drop),
        }
    }
}

/// What every worker of a run shares.
#[derive(Clone)]
struct Plan {
    pool: Arc<Vec<Workload>>,
    /// Calls started so far, over all workers.
    issued: Arc<AtomicU64>,
    total: u64,
    duration: Option<Duration>,
    timeout: Duration,
    /// Time between one worker's calls when a rate is set.
    interval: Option<Duration>,
    concurrency: usize,
}

impl Plan {
    /// Worker `w`: calls back to back, or on its schedule when a rate is set,
    /// until the call count or the duration is reached.
    async fn worker(self, w: usize, mut clients: Clients, start: Instant) -> Tally {
        // Workers' schedules are staggered evenly over one interval.
        let offset = self
            .interval
            .map(|i| i.mul_f64(w as f64 / self.concurrency as f64));
        let mut tally = Tally::default();
        let mut k: u32 = 0;
        loop {
            let n = self.issued.fetch_add(1, Ordering::Relaxed);
            if self.total > 0 && n >= self.total {
                break;
            }
            // With a rate, a worker behind its schedule counts latency from the
            // scheduled start (the server's backlog is not hidden); one ahead of it
            // sleeps and counts from when it woke (the timer's ~1 ms granularity
            // is the client's, not the server's).
            let scheduled = match (self.interval, offset) {
                (Some(i), Some(o)) => {
                    let at = start + o + i * k;
                    if at > Instant::now() {
                        tokio::time::sleep_until(at.into()).await;
                        Instant::now()
                    } else {
                        at
                    }
                }
                _ => Instant::now(),
            };
            if self
                .duration
                .is_some_and(|d| scheduled.duration_since(start) >= d)
            {
                break;
            }
            k = k.saturating_add(1);
            let result = clients
                .call(&self.pool[n as usize % self.pool.len()], self.timeout)
                .await;
            tally
                .latencies_ns
                .push(scheduled.elapsed().as_nanos().min(u64::MAX as u128) as u64);
            let code = match &result {
                Ok(()) => 0,
                Err(s) => (s.code() as usize).min(16),
            };
            tally.codes[code] += 1;
            if let Err(s) = result {
                let msg: String = s.message().chars().take(120).collect();
                *tally
                    .errors
                    .entry(format!("{}: {msg}", code_name(code as i32)))
                    .or_default() += 1;
            }
        }
        tally
    }
}

fn call_name(rpc: Rpc) -> &'static str {
    match rpc {
        Rpc::Fk => "kinplan.v1.RobotService/ForwardKinematics",
        Rpc::Jacobian => "kinplan.v1.RobotService/Jacobian",
        Rpc::Ik | Rpc::IkCold => "kinplan.v1.KinematicsService/SolveIk",
        Rpc::Score => "kinplan.v1.ScoringService/ScoreTrajectory",
    }
}

/// Shortest time between one worker's calls at a rate that keeps the timer's
/// lateness (up to 1 ms) out of the latencies; see `--rate`.
pub const MIN_WORKER_INTERVAL: Duration = Duration::from_millis(3);

/// Workers that keep each one's interval at `MIN_WORKER_INTERVAL` or more at
/// `rate` calls/s.
pub fn workers_for_rate(rate: f64) -> usize {
    (rate * MIN_WORKER_INTERVAL.as_secs_f64()).ceil().max(1.0) as usize
}

/// Runs the load test and returns its report (also written as JSON when asked).
pub async fn run_loadtest(args: &LoadtestArgs) -> Result<Report, String> {
    if args.concurrency == 0 || args.connections == 0 {
        return Err("--concurrency and --connections must be at least 1".into());
    }
    if !(args.rate >= 0.0 && args.rate.is_finite()) {
        return Err("--rate must be a finite number >= 0".into());
    }
    let timeout = Duration::try_from_secs_f64(args.timeout)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or("--timeout must be a positive number of seconds")?;
    let duration = if args.total == 0 {
        Some(
            Duration::try_from_secs_f64(args.duration)
                .ok()
                .filter(|d| !d.is_zero())
                .ok_or("--duration must be a positive number of seconds")?,
        )
    } else {
        None
    };
    let pool = Arc::new(build_pool(args.rpc, &args.robot, args.pool, args.seed)?);
    let uri = if args.target.contains("://") {
        args.target.clone()
    } else {
        format!("http://{}", args.target)
    };
    let endpoint = Endpoint::from_shared(uri)
        .map_err(|e| format!("--target: {e}"))?
        .tcp_nodelay(true)
        .connect_timeout(Duration::from_secs(5));

    // One thread per connection, each with its own single-threaded runtime
    // running the connection's task and its workers: requests of workers that
    // are ready together leave in one write, as on the server
    // (service/io_threads.rs). Workers go to connections round robin.
    let (ready_tx, mut ready_rx) = mpsc::unbounded_channel::<Result<(), String>>();
    let (start_tx, start_rx) = watch::channel::<Option<Instant>>(None);
    let issued = Arc::new(AtomicU64::new(0));
    let interval = (args.rate > 0.0).then(|| Duration::from_secs_f64(args.concurrency as f64 / args.rate));
    let mut finished = Vec::with_capacity(args.connections);
    for c in 0..args.connections {
        let workers: Vec<usize> = (c..args.concurrency).step_by(args.connections).collect();
        let (done_tx, done_rx) = oneshot::channel::<Tally>();
        finished.push(done_rx);
        let plan = Plan {
            pool: pool.clone(),
            issued: issued.clone(),
            total: args.total,
            duration,
            timeout,
            interval,
            concurrency: args.concurrency,
        };
        let endpoint = endpoint.clone();
        let ready_tx = ready_tx.clone();
        let mut start_rx = start_rx.clone();
        let target = args.target.clone();
        let warmup = args.warmup;
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(|e| e.to_string())?;
        std::thread::Builder::new()
            .name(format!("loadtest-conn-{c}"))
            .spawn(move || {
                runtime.block_on(async move {
                    let mut clients = match endpoint.connect().await {
                        Ok(channel) => Clients::new(channel),
                        Err(e) => {
                            let _ = ready_tx.send(Err(format!(
                                "cannot connect to {target}: {e} (is `kinplan serve` running?)"
                            )));
                            return;
                        }
                    };
                    // Warm-up: models cached, connection open, code paths hot.
                    for k in 0..warmup {
                        let work = &plan.pool[(c + k as usize) % plan.pool.len()];
                        let _ = clients.call(work, plan.timeout).await;
                    }
                    let _ = ready_tx.send(Ok(()));
                    // An error: the run was abandoned (another connection failed).
                    let Ok(start) = start_rx
                        .wait_for(Option::is_some)
                        .await
                        .map(|s| s.unwrap_or_else(Instant::now))
                    else {
                        return;
                    };
                    let tasks: Vec<_> = workers
                        .into_iter()
                        .map(|w| tokio::spawn(plan.clone().worker(w, clients.clone(), start)))
                        .collect();
                    let mut tally = Tally::default();
                    for t in tasks {
                        if let Ok(t) = t.await {
                            tally.add(t);
                        }
                    }
                    let _ = done_tx.send(tally);
                });
            })
            .map_err(|e| e.to_string())?;
    }
    drop(ready_tx);
    for _ in 0..args.connections {
        match ready_rx.recv().await {
            Some(Ok(())) => {}
            Some(Err(e)) => return Err(e),
            None => return Err("a connection thread ended before the run".into()),
        }
    }

    let cpu_before = (
        cpu_seconds("self"),
        args.server_pid.and_then(|p| cpu_seconds(&p.to_string())),
    );
    let start = Instant::now();
    let _ = start_tx.send(Some(start));
    let mut all = Tally::default();
    for done in finished {
        all.add(done.await.map_err(|_| "a connection thread failed".to_string())?);
    }
    let elapsed = start.elapsed();
    let diff = |before: Option<f64>, after: Option<f64>| Some(after? - before?);
    let report = Report {
        call: call_name(args.rpc).to_owned(),
        concurrency: args.concurrency,
        connections: args.connections,
        rate: args.rate,
        elapsed,
        latency: LatencyReport::from_latencies(&mut all.latencies_ns),
        status_codes: all
            .codes
            .iter()
            .enumerate()
            .filter(|(_, n)| **n > 0)
            .map(|(code, n)| (code_name(code as i32).to_owned(), *n))
            .collect(),
        errors: all.errors,
        client_cpu_seconds: diff(cpu_before.0, cpu_seconds("self")),
        server_cpu_seconds: diff(
            cpu_before.1,
            args.server_pid.and_then(|p| cpu_seconds(&p.to_string())),
        ),
    };
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&report.to_ghz_json()).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("--json {}: {e}", path.display()))?;
    }
    Ok(report)
}

/// User + system CPU seconds of a process from `/proc/<pid>/stat` (fields 14
/// and 15, in USER_HZ ticks of 1/100 s on Linux); `None` elsewhere.
fn cpu_seconds(pid: &str) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may contain spaces.
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workers_for_a_rate_send_at_most_every_three_milliseconds() {
        // 20,000 calls/s × 3 ms = 60 workers, each sending every 3 ms.
        assert_eq!(workers_for_rate(20_000.0), 60);
        assert_eq!(workers_for_rate(1_000.0), 3);
        assert_eq!(workers_for_rate(1_001.0), 4);
        assert_eq!(workers_for_rate(10.0), 1);
    }

    #[test]
    fn own_cpu_time_grows_with_work() {
        let before = cpu_seconds("self").expect("Linux /proc");
        let t = Instant::now();
        let mut x = 0u64;
        while t.elapsed() < Duration::from_millis(200) {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
        }
        std::hint::black_box(x);
        let after = cpu_seconds("self").unwrap();
        assert!(after - before >= 0.05, "{before} -> {after}");
    }
}
