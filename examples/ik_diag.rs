//! Diagnostic for the TRAC-IK-protocol benchmark (no wall clock; deterministic):
//! distribution of attempts, iterations spent in failed attempts vs the final one.
//! `cargo run --release --example ik_diag -- [N] [arm,...]`
use kinplan_core::ik::{IkParams, IkSolver, IkTarget};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let arms: Vec<String> = args
        .get(2)
        .map(|s| s.split(',').map(String::from).collect())
        .unwrap_or_else(|| vec!["kuka_kr210_r2700_extra".into()]);
    for arm in &arms {
        let chain = kinplan_core::robot::builtin_chain(arm).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2026);
        let qs: Vec<Vec<f64>> = (0..n)
            .map(|_| chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect())
            .collect();
        let targets: Vec<IkTarget> = qs.iter().map(|q| IkTarget::Pose(chain.fk(q))).collect();
        if std::env::var("SHOW").is_ok() {
            println!(
                "limits {:?}",
                chain
                    .limits()
                    .map(|(a, b)| (a.to_degrees().round(), b.to_degrees().round()))
                    .collect::<Vec<_>>()
            );
        }
        let seed = chain.mid_limits();
        let mut params = IkParams {
            max_restarts: 200,
            ..IkParams::default()
        };
        let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
        if let Some(v) = env("DAMPING") {
            params.damping = v;
        }
        if let Some(v) = env("STALL") {
            params.stall_iterations = v as usize;
        }
        if let Some(v) = env("MAXIT") {
            params.max_iterations = v as usize;
        }
        if let Some(v) = env("MAX_STEP") {
            params.max_step = v;
        }
        if let Some(v) = env("RESTARTS") {
            params.max_restarts = v as usize;
        }
        let mut solver = IkSolver::new(&chain);
        let mut fails: std::collections::BTreeMap<String, usize> = Default::default();
        let mut hist = [0usize; 8];
        let (mut ok, mut it_final, mut it_failed, mut failed_attempts) = (0, 0, 0, 0);
        let mut worst = 0;
        for (i, t) in targets.iter().enumerate() {
            let r = solver
                .solve(t, Some(&seed), &params, i as u64, kinplan_core::Deadline::none())
                .unwrap();
            hist[(r.attempts - 1).min(7)] += 1;
            if std::env::var("SHOW").is_ok() && r.attempts >= 12 {
                let rel: Vec<String> = qs[i]
                    .iter()
                    .zip(chain.limits())
                    .map(|(q, (lo, hi))| format!("{:.2}", (q - lo) / (hi - lo)))
                    .collect();
                let deg: Vec<String> = qs[i].iter().map(|q| format!("{:.0}", q.to_degrees())).collect();
                println!(
                    "  target {i}: attempts {} rel {:?} deg {:?}",
                    r.attempts, rel, deg
                );
            }
            worst = worst.max(r.attempts);
            if let Some(b) = &r.best_attempt {
                let at_limit = b
                    .joints
                    .iter()
                    .zip(chain.limits())
                    .filter(|(q, (lo, hi))| (*q - lo).abs() < 1e-9 || (*q - hi).abs() < 1e-9)
                    .count();
                let key = format!(
                    "{:?} at_limit={at_limit} pos_err>{}",
                    b.status,
                    if b.position_error > 1e-2 {
                        "1cm"
                    } else if b.position_error > 1e-4 {
                        "0.1mm"
                    } else {
                        "0"
                    }
                );
                *fails.entry(key).or_default() += 1;
            }
            if let Some(s) = r.solutions.first() {
                ok += 1;
                it_final += s.iterations;
                it_failed += r.total_iterations - s.iterations;
                failed_attempts += r.attempts - 1;
            }
        }
        if !fails.is_empty() {
            println!("  single-attempt failures: {fails:?}");
        }
        println!(
            "{arm}: ok {ok}/{n}; attempts hist(1..7,8+) {hist:?} worst {worst}; final-attempt it {:.2}; failed attempts {failed_attempts} at {:.2} it each; total it/target {:.2}",
            it_final as f64 / ok as f64,
            it_failed as f64 / failed_attempts.max(1) as f64,
            (it_final + it_failed) as f64 / n as f64
        );
    }
}
