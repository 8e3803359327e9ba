//! TRAC-IK-protocol benchmark: N random reachable poses per arm (FK of uniform random
//! joints within limits), seed at the middle of the limits, tolerance 1e-5 m / rad,
//! 5 ms budget. Prints success rate, mean and median µs per method × solver.
//!
//! `cargo run --release --example ik_bench -- [N] [arm,...] [method,...]`
//! methods: ji-svd ji-rlxa lm-svd lm-rlxa newton-svd newton-rlxa ccd fabrik lr
//! `POS=1` uses position-only targets; `NOBUDGET=1` replaces the 5 ms budget by 200 restarts.
//! `DUMP_TARGETS=<dir>` also writes, per arm, `<dir>/<arm>.csv` (a header line, then one
//! line per target: the sampled joint values, then the full target pose `x y z qx qy qz qw`
//! in the base frame, metres and unit quaternion) and `<dir>/<arm>.json` (base and tip
//! links, joint names, limits and the IK seed, i.e. the middle of the limits), so that
//! other solvers can be run on exactly these targets (`benches/anchors/`).

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use kinplan_core::ik::{IkMethod, IkParams, IkSolver, IkTarget};
use kinplan_core::linalg::LinearSolverKind;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn method(name: &str) -> (IkMethod, LinearSolverKind) {
    use IkMethod::*;
    use LinearSolverKind::*;
    match name {
        "ji-svd" => (JacobianInverse, SvdPseudoinverse),
        "ji-rlxa" => (JacobianInverse, AngleRelaxation),
        "lm-svd" => (LevenbergMarquardt, SvdPseudoinverse),
        "lm-rlxa" => (LevenbergMarquardt, AngleRelaxation),
        "newton-svd" => (Newton, SvdPseudoinverse),
        "newton-rlxa" => (Newton, AngleRelaxation),
        "ccd" => (Ccd, SvdPseudoinverse),
        "fabrik" => (Fabrik, SvdPseudoinverse),
        "lr" => (LengthRelaxation, SvdPseudoinverse),
        other => panic!("unknown method {other}"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let arms: Vec<String> = args
        .get(2)
        .map(|s| s.split(',').map(String::from).collect())
        .unwrap_or_else(|| kinplan_core::robot::ARM_NAMES.map(String::from).to_vec());
    let methods: Vec<String> = args
        .get(3)
        .map(|s| s.split(',').map(String::from).collect())
        .unwrap_or_else(|| vec!["lm-svd".into()]);
    let position_only = std::env::var("POS").is_ok();
    println!(
        "| arm | method | N | success % | mean µs | median µs | p99 µs | mean attempts | mean iterations |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for arm in &arms {
        let chain = kinplan_core::robot::builtin_chain(arm).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2026);
        let samples: Vec<Vec<f64>> = (0..n)
            .map(|_| chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect())
            .collect();
        let targets: Vec<IkTarget> = samples
            .iter()
            .map(|q| {
                let t = chain.fk(q);
                if position_only {
                    IkTarget::Position(nalgebra::Point3::from(t.translation.vector))
                } else {
                    IkTarget::Pose(t)
                }
            })
            .collect();
        let seed = chain.mid_limits();
        if let Ok(dir) = std::env::var("DUMP_TARGETS") {
            dump_targets(Path::new(&dir), arm, &chain, &samples, &seed)
                .unwrap_or_else(|e| panic!("DUMP_TARGETS={dir}: {e}"));
        }
        for m in &methods {
            let (method, linear_solver) = method(m);
            let params = IkParams {
                method,
                linear_solver,
                max_restarts: 100_000,
                time_budget: Some(Duration::from_millis(5)),
                ..IkParams::default()
            };
            let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
            let mut params = params;
            if let Some(v) = env("MAX_STEP") {
                params.max_step = v;
            }
            if let Some(v) = env("DAMPING") {
                params.damping = v;
            }
            if let Some(v) = env("STALL") {
                params.stall_iterations = v as usize;
            }
            if let Some(v) = env("MAXIT") {
                params.max_iterations = v as usize;
            }
            if std::env::var("NOBUDGET").is_ok() {
                // load-independent success rate: no wall clock, 200 restarts
                params.time_budget = None;
                params.max_restarts = 200;
            }
            let mut solver = IkSolver::new(&chain);
            let mut times = Vec::with_capacity(n);
            let mut ok = 0;
            let mut attempts = 0;
            let mut iters = 0;
            for (i, t) in targets.iter().enumerate() {
                let t0 = Instant::now();
                let r = solver
                    .solve(t, Some(&seed), &params, i as u64, kinplan_core::Deadline::none())
                    .unwrap();
                times.push(t0.elapsed().as_secs_f64() * 1e6);
                attempts += r.attempts;
                iters += r.total_iterations;
                if r.success() {
                    ok += 1;
                }
            }
            let mean = times.iter().sum::<f64>() / n as f64;
            times.sort_by(f64::total_cmp);
            println!(
                "| {arm} | {m} | {n} | {:.2} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1} |",
                100.0 * ok as f64 / n as f64,
                mean,
                times[n / 2],
                times[(n * 99) / 100],
                attempts as f64 / n as f64,
                iters as f64 / n as f64
            );
        }
    }
}

/// Writes `<dir>/<arm>.csv` (joint samples and their FK poses) and `<dir>/<arm>.json`
/// (chain and seed). Floats use Rust's shortest round-trip formatting, so a reader
/// parsing them as f64 gets the exact values used here.
fn dump_targets(
    dir: &Path,
    arm: &str,
    chain: &kinplan_core::robot::Chain,
    samples: &[Vec<f64>],
    seed: &[f64],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut csv = std::io::BufWriter::new(std::fs::File::create(dir.join(format!("{arm}.csv")))?);
    let mut header: Vec<String> = (0..chain.dof()).map(|i| format!("q{i}")).collect();
    header.extend(["x", "y", "z", "qx", "qy", "qz", "qw"].map(String::from));
    writeln!(csv, "{}", header.join(","))?;
    for q in samples {
        let t = chain.fk(q);
        let p = t.translation.vector;
        let r = t.rotation;
        let mut row: Vec<String> = q.iter().map(|v| v.to_string()).collect();
        row.extend([p.x, p.y, p.z, r.i, r.j, r.k, r.w].iter().map(|v| v.to_string()));
        writeln!(csv, "{}", row.join(","))?;
    }
    csv.flush()?;
    let json = serde_json::json!({
        "arm": arm,
        "base_link": chain.base_link(),
        "tip_link": chain.tip_link(),
        "n": samples.len(),
        "rng": "ChaCha8 seed 2026, uniform in the limits",
        "joints": chain.joints().iter().map(|j| j.name.as_str()).collect::<Vec<_>>(),
        "lower": chain.limits().map(|(lo, _)| lo).collect::<Vec<_>>(),
        "upper": chain.limits().map(|(_, hi)| hi).collect::<Vec<_>>(),
        "seed": seed,
    });
    let json = serde_json::to_string_pretty(&json).map_err(std::io::Error::other)?;
    std::fs::write(dir.join(format!("{arm}.json")), json)
}
