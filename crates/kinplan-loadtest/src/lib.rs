//! `kinplan-loadtest`: drives a kinplan server over gRPC at high rate with
//! built-in workloads (random reachable targets on built-in robots, so no
//! files are needed) and reports latency percentiles, throughput and status
//! codes, also as JSON shaped like ghz's report. A client of the public
//! contract (`kinplan-proto`) only: it knows nothing of the server's code.

mod report;
mod run;
mod workload;

pub use report::{LatencyReport, Report};
pub use run::{LoadtestArgs, MIN_WORKER_INTERVAL, run_loadtest, workers_for_rate};
pub use workload::{Rpc, Workload, pose_msg};
