//! Latency statistics of a load test and its JSON form, shaped like ghz's
//! report (times in nanoseconds) so results compare with the tool gRPC
//! users know.

use std::collections::BTreeMap;
use std::time::Duration;

use serde::Serialize;

/// Percentiles reported, as ghz does, plus 99.9.
const PERCENTAGES: [f64; 8] = [10.0, 25.0, 50.0, 75.0, 90.0, 95.0, 99.0, 99.9];

/// Latency statistics over a set of calls (nanoseconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LatencyReport {
    pub count: u64,
    pub average: u64,
    pub fastest: u64,
    pub slowest: u64,
    /// (percentage, latency) by nearest rank: the smallest latency at or
    /// below which `percentage` % of the calls finished.
    pub percentiles: Vec<(f64, u64)>,
}

impl LatencyReport {
    /// Statistics of `latencies_ns` (sorted in place); `None` when empty.
    pub fn from_latencies(latencies_ns: &mut [u64]) -> Option<Self> {
        if latencies_ns.is_empty() {
            return None;
        }
        latencies_ns.sort_unstable();
        let n = latencies_ns.len();
        let sum: u128 = latencies_ns.iter().map(|&v| v as u128).sum();
        let percentiles = PERCENTAGES
            .iter()
            .map(|&p| {
                // rank = ceil(p/100 · n), in integer per-mille so 99.9 % of 1000
                // is rank 999 exactly (0.999 · 1000 is 999.0000000000001 in f64).
                let per_mille = (p * 10.0).round() as usize;
                let rank = (per_mille * n).div_ceil(1000);
                (p, latencies_ns[rank.clamp(1, n) - 1])
            })
            .collect();
        Some(Self {
            count: n as u64,
            average: (sum / n as u128) as u64,
            fastest: latencies_ns[0],
            slowest: latencies_ns[n - 1],
            percentiles,
        })
    }

    /// The latency at `percentage` (one of the reported ones).
    pub fn at(&self, percentage: f64) -> Option<u64> {
        self.percentiles
            .iter()
            .find(|(p, _)| *p == percentage)
            .map(|(_, v)| *v)
    }
}

/// A whole run: what was asked, how long it took, and what came back.
#[derive(Debug, Clone)]
pub struct Report {
    /// e.g. "kinplan.v1.RobotService/ForwardKinematics".
    pub call: String,
    pub concurrency: usize,
    pub connections: usize,
    /// Target rate (calls/s); 0 for as fast as possible.
    pub rate: f64,
    /// Wall time of the run.
    pub elapsed: Duration,
    /// Latencies of every finished call, whatever its status.
    pub latency: Option<LatencyReport>,
    /// Canonical gRPC code name → count.
    pub status_codes: BTreeMap<String, u64>,
    /// "code: message" of failed calls → count.
    pub errors: BTreeMap<String, u64>,
    /// CPU seconds (user + system) of this process and of the server
    /// process, when its pid was given, over the run.
    pub client_cpu_seconds: Option<f64>,
    pub server_cpu_seconds: Option<f64>,
}

impl Report {
    /// Calls per second over the run.
    pub fn rps(&self) -> f64 {
        let n = self.latency.as_ref().map_or(0, |l| l.count);
        n as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// The text summary printed at the end of a run.
    pub fn summary(&self) -> String {
        let mut out = format!(
            "{}: {} calls in {:.3} s, {:.0} calls/s ({} workers on {} connections{})\n",
            self.call,
            self.latency.as_ref().map_or(0, |l| l.count),
            self.elapsed.as_secs_f64(),
            self.rps(),
            self.concurrency,
            self.connections,
            if self.rate > 0.0 {
                format!(", target {:.0}/s", self.rate)
            } else {
                String::new()
            },
        );
        if let Some(l) = &self.latency {
            let us = |ns: u64| ns as f64 / 1e3;
            out += &format!(
                "latency µs: p50 {:.1}  p90 {:.1}  p99 {:.1}  p99.9 {:.1}  max {:.1}  mean {:.1}  min {:.1}\n",
                us(l.at(50.0).unwrap_or(0)),
                us(l.at(90.0).unwrap_or(0)),
                us(l.at(99.0).unwrap_or(0)),
                us(l.at(99.9).unwrap_or(0)),
                us(l.slowest),
                us(l.average),
                us(l.fastest),
            );
        }
        let codes: Vec<String> = self
            .status_codes
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        out += &format!("status: {}\n", codes.join(", "));
        for (e, n) in &self.errors {
            out += &format!("  {n} × {e}\n");
        }
        if let Some(c) = self.client_cpu_seconds {
            out += &format!("cpu: client {c:.2} s");
            if let Some(s) = self.server_cpu_seconds {
                out += &format!(", server {s:.2} s");
            }
            out += &format!(" over {:.2} s wall\n", self.elapsed.as_secs_f64());
        }
        out
    }

    /// The report as ghz writes it (`-O json`): count, total, average,
    /// fastest, slowest (ns), rps, latencyDistribution, statusCodeDistribution,
    /// errorDistribution; kinplan's CPU figures under `kinplan`.
    pub fn to_ghz_json(&self) -> serde_json::Value {
        let l = self.latency.as_ref();
        serde_json::json!({
            "options": {
                "call": self.call,
                "concurrency": self.concurrency,
                "connections": self.connections,
                "rps": self.rate,
            },
            "count": l.map_or(0, |l| l.count),
            "total": self.elapsed.as_nanos() as u64,
            "average": l.map_or(0, |l| l.average),
            "fastest": l.map_or(0, |l| l.fastest),
            "slowest": l.map_or(0, |l| l.slowest),
            "rps": self.rps(),
            "latencyDistribution": l.map_or(Vec::new(), |l| l
                .percentiles
                .iter()
                .map(|(p, v)| serde_json::json!({"percentage": p, "latency": v}))
                .collect()),
            "statusCodeDistribution": self.status_codes,
            "errorDistribution": self.errors,
            "kinplan": {
                "client_cpu_seconds": self.client_cpu_seconds,
                "server_cpu_seconds": self.server_cpu_seconds,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles_of_one_to_a_thousand() {
        // Latencies 1..=1000 ns in shuffled order: the p-th percentile by
        // nearest rank is ceil(p/100 · 1000).
        let mut v: Vec<u64> = (1..=1000).rev().collect();
        v.swap(3, 700);
        let r = LatencyReport::from_latencies(&mut v).unwrap();
        assert_eq!((r.count, r.fastest, r.slowest), (1000, 1, 1000));
        assert_eq!(r.average, 500); // 500.5 truncated
        assert_eq!(r.at(50.0), Some(500));
        assert_eq!(r.at(90.0), Some(900));
        assert_eq!(r.at(99.0), Some(990));
        assert_eq!(r.at(99.9), Some(999));
        assert_eq!(r.at(10.0), Some(100));
    }

    #[test]
    fn a_single_call_is_every_percentile_and_no_calls_is_none() {
        let r = LatencyReport::from_latencies(&mut [42]).unwrap();
        assert!(r.percentiles.iter().all(|&(_, v)| v == 42));
        assert!(LatencyReport::from_latencies(&mut []).is_none());
    }

    #[test]
    fn ghz_json_has_its_field_names_and_nanoseconds() {
        let mut lat = vec![1_000, 3_000];
        let report = Report {
            call: "kinplan.v1.RobotService/ForwardKinematics".into(),
            concurrency: 2,
            connections: 1,
            rate: 0.0,
            elapsed: Duration::from_millis(2),
            latency: LatencyReport::from_latencies(&mut lat),
            status_codes: [("OK".to_string(), 2)].into(),
            errors: BTreeMap::new(),
            client_cpu_seconds: None,
            server_cpu_seconds: None,
        };
        let j = report.to_ghz_json();
        assert_eq!(j["count"], 2);
        assert_eq!(j["total"], 2_000_000);
        assert_eq!(j["average"], 2_000);
        assert_eq!(j["fastest"], 1_000);
        assert_eq!(j["slowest"], 3_000);
        assert_eq!(j["rps"], 1000.0);
        assert_eq!(j["statusCodeDistribution"]["OK"], 2);
        assert_eq!(j["latencyDistribution"][2]["percentage"], 50.0);
        assert_eq!(j["latencyDistribution"][2]["latency"], 1_000);
    }
}
