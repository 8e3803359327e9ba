//! Reproductions of the source's experiments (S2 Tab. 2/3 + Fig. 8, Tab. 5, Tab. 6, Tab. 7).
//!
//! `cargo run --release --example s2_tables -- [rlxa|track|heuristics|all]`

use std::f64::consts::PI;
use std::time::{Duration, Instant};

use kinplan_core::ik::{IkMethod, IkParams, IkSolver, IkTarget, TrackParams, circle_path, track_path};
use kinplan_core::linalg::{
    LinearSolverKind, PseudoinverseParams, RlxaParams, RlxaVariant, SolveStatus, solve_angle_relaxation,
    solve_pseudoinverse,
};
use nalgebra::{DMatrix, DVector, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const NEVER: kinplan_core::Deadline<'static> = kinplan_core::Deadline::none();

/// Random orthogonal matrix (QR of a Gaussian-ish matrix).
fn orthogonal(n: usize, rng: &mut ChaCha8Rng) -> DMatrix<f64> {
    let a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    a.qr().q()
}

fn rlxa_tables() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let trials = 100;
    println!(
        "\n### RLXA vs SVD: square diagonally dominant systems (S2 Tab. 2 setting: ‖r‖ < 0.01, cap 20 000, 100 systems)\n"
    );
    println!(
        "| n | RLXA converged % | RLXA mean iterations | RLXA mean µs | safeguarded mean iterations | safeguarded mean µs | SVD mean µs |"
    );
    println!("|---|---|---|---|---|---|---|");
    for n in [2, 3, 4, 5, 6, 7, 8, 9, 10, 20, 30] {
        let (mut conv, mut it, mut t_r, mut it_s, mut t_s, mut t_svd) = (0, 0usize, 0.0, 0usize, 0.0, 0.0);
        for _ in 0..trials {
            let mut a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
            for i in 0..n {
                a[(i, i)] += n as f64;
            }
            let b = DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0));
            let p = RlxaParams::default();
            let t0 = Instant::now();
            let s = solve_angle_relaxation(&a, &b, &p, &mut rng).unwrap();
            t_r += t0.elapsed().as_secs_f64();
            it += s.iterations;
            if s.status == SolveStatus::Converged {
                conv += 1;
            }
            let ps = RlxaParams {
                variant: RlxaVariant::Safeguarded,
                ..p
            };
            let t0 = Instant::now();
            let s = solve_angle_relaxation(&a, &b, &ps, &mut rng).unwrap();
            t_s += t0.elapsed().as_secs_f64();
            it_s += s.iterations;
            let t0 = Instant::now();
            let _ = solve_pseudoinverse(&a, &b, &PseudoinverseParams::default()).unwrap();
            t_svd += t0.elapsed().as_secs_f64();
        }
        let k = trials as f64;
        println!(
            "| {n} | {:.0} | {:.0} | {:.1} | {:.0} | {:.1} | {:.2} |",
            100.0 * conv as f64 / k,
            it as f64 / k,
            t_r * 1e6 / k,
            it_s as f64 / k,
            t_s * 1e6 / k,
            t_svd * 1e6 / k
        );
    }
    println!(
        "\n### RLXA iterations vs condition number, n = 10 (S2 Fig. 8 setting; A = U diag(σ) Vᵀ, σ log-spaced 1…1/κ)\n"
    );
    println!("| κ(A) | converged % | mean iterations | mean µs |");
    println!("|---|---|---|---|");
    for kappa in [1.0f64, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0] {
        let (mut conv, mut it, mut t) = (0, 0usize, 0.0);
        let trials = 20;
        for _ in 0..trials {
            let u = orthogonal(10, &mut rng);
            let v = orthogonal(10, &mut rng);
            let sig = DMatrix::from_diagonal(&DVector::from_fn(10, |i, _| kappa.powf(-(i as f64) / 9.0)));
            let a = u * sig * v.transpose();
            let b = DVector::from_fn(10, |_, _| rng.random_range(-1.0..1.0));
            let t0 = Instant::now();
            let s = solve_angle_relaxation(&a, &b, &RlxaParams::default(), &mut rng).unwrap();
            t += t0.elapsed().as_secs_f64();
            it += s.iterations;
            if s.status == SolveStatus::Converged {
                conv += 1;
            }
        }
        let k = trials as f64;
        println!(
            "| {kappa} | {:.0} | {:.0} | {:.1} |",
            100.0 * conv as f64 / k,
            it as f64 / k,
            t * 1e6 / k
        );
    }
    println!("\n### Rectangular and singular systems (S2 Tab. 1/3, Fig. 10/11 setting, 100 systems each)\n");
    println!(
        "| shape | kind | RLXA converged % | mean iterations | mean ‖x_RLXA‖/‖A⁺b‖ | mean ‖r_RLXA‖/‖r_SVD‖ (best of history) | RLXA mean µs | SVD mean µs |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (m, n, kind) in [
        (5, 10, "underdetermined"),
        (10, 5, "overdetermined, consistent"),
        (10, 5, "overdetermined, inconsistent"),
        (10, 10, "singular (rank 7), consistent"),
    ] {
        let trials = 100;
        let (mut conv, mut it, mut ratio, mut rratio, mut t_r, mut t_s) = (0, 0usize, 0.0, 0.0, 0.0, 0.0);
        for _ in 0..trials {
            let a = if kind.starts_with("singular") {
                let l = DMatrix::from_fn(m, 7, |_, _| rng.random_range(-1.0..1.0));
                let r = DMatrix::from_fn(7, n, |_, _| rng.random_range(-1.0..1.0));
                l * r
            } else {
                DMatrix::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0))
            };
            let b = if kind.contains("inconsistent") {
                DVector::from_fn(m, |_, _| rng.random_range(-1.0..1.0))
            } else {
                &a * DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0))
            };
            let p = RlxaParams {
                record_history: true,
                ..RlxaParams::default()
            };
            let t0 = Instant::now();
            let s = solve_angle_relaxation(&a, &b, &p, &mut rng).unwrap();
            t_r += t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let pinv = solve_pseudoinverse(&a, &b, &PseudoinverseParams::default()).unwrap();
            t_s += t0.elapsed().as_secs_f64();
            it += s.iterations;
            if s.status == SolveStatus::Converged {
                conv += 1;
            }
            ratio += s.x.norm() / pinv.x.norm();
            let best = s.history.iter().cloned().fold(f64::INFINITY, f64::min);
            rratio += if pinv.residual_norm > 1e-9 {
                best / pinv.residual_norm
            } else {
                f64::NAN
            };
        }
        let k = trials as f64;
        println!(
            "| {m}×{n} | {kind} | {:.0} | {:.0} | {:.3} | {} | {:.1} | {:.2} |",
            100.0 * conv as f64 / k,
            it as f64 / k,
            ratio / k,
            if rratio.is_nan() {
                "— (consistent)".to_string()
            } else {
                format!("{:.4}", rratio / k)
            },
            t_r * 1e6 / k,
            t_s * 1e6 / k
        );
    }
}

fn combos() -> Vec<(&'static str, IkMethod, LinearSolverKind)> {
    use IkMethod::*;
    use LinearSolverKind::*;
    vec![
        ("JI+SVD", JacobianInverse, SvdPseudoinverse),
        ("JI+RLXA", JacobianInverse, AngleRelaxation),
        ("LM+SVD", LevenbergMarquardt, SvdPseudoinverse),
        ("LM+RLXA", LevenbergMarquardt, AngleRelaxation),
        ("Newton+SVD", Newton, SvdPseudoinverse),
        ("Newton+RLXA", Newton, AngleRelaxation),
    ]
}

fn track_tables() {
    println!(
        "\n### S2 Tab. 5: planar n = 2…10 tracing a circle (r = 0.1 m), position tolerance 0.06 mm (norm)\n"
    );
    println!(
        "Cells: mean µs per step / largest joint step (rad) / % steps converged. 'away' starts bent (q = 0.3 rad each joint, centre 0.1 m to −x of the tip); 'singular' starts stretched (q = 0, tip at (1,0,0), centre (0.9,0,0)).\n"
    );
    let header: Vec<&str> = combos().iter().map(|c| c.0).collect();
    println!("| start | step | n | {} |", header.join(" | "));
    println!("|---|---|---|{}", "---|".repeat(header.len()));
    for start in ["away", "singular"] {
        for (step_name, step) in [("π/50", PI / 50.0), ("π/100", PI / 100.0)] {
            for n in 2..=10 {
                let chain = kinplan_core::robot::builtin_chain(&format!("planar_{n}")).unwrap();
                let q0: Vec<f64> = if start == "away" {
                    vec![0.3; n]
                } else {
                    vec![0.0; n]
                };
                let tip = chain.fk(&q0);
                let centre = Point3::from(tip.translation.vector - Vector3::new(0.1, 0.0, 0.0));
                let steps = (2.0 * PI / step).round() as usize;
                let path = circle_path(&tip, &centre, &Vector3::z(), step, steps).unwrap();
                let targets: Vec<IkTarget> = path
                    .iter()
                    .map(|t| IkTarget::Position(Point3::from(t.translation.vector)))
                    .collect();
                let mut cells = Vec::new();
                for (_, method, solver) in combos() {
                    let tp = TrackParams {
                        ik: IkParams {
                            method,
                            linear_solver: solver,
                            position_tolerance: 6e-5,
                            max_restarts: 0,
                            max_iterations: 200,
                            stall_iterations: 0,
                            time_budget: Some(Duration::from_secs(5)),
                            ..IkParams::default()
                        },
                        ..TrackParams::default()
                    };
                    let r = track_path(&chain, &targets, &q0, &tp, 1, NEVER).unwrap();
                    let mean =
                        r.steps.iter().map(|s| s.elapsed_us as f64).sum::<f64>() / r.steps.len() as f64;
                    let ok = r
                        .steps
                        .iter()
                        .filter(|s| s.status == kinplan_core::ik::IkStatus::Converged)
                        .count();
                    cells.push(format!(
                        "{mean:.0} / {:.3} / {:.0}",
                        r.max_joint_step,
                        100.0 * ok as f64 / r.steps.len() as f64
                    ));
                }
                println!("| {start} | {step_name} | {n} | {} |", cells.join(" | "));
            }
        }
    }
    println!(
        "\n### S2 Tab. 6: KR 210 R2700 extra tracing a 10 mm circle in x–y, fixed orientation, 0.06 mm / 1e-4 rad\n"
    );
    println!("| start | step | {} |", header[..4].join(" | "));
    println!("|---|---|{}", "---|".repeat(4));
    let chain = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra").unwrap();
    for (start, q0) in [
        ("away", [0.1, -1.2, 1.0, 0.2, 0.8, 0.1]),
        ("singular (A5 = 0)", [0.0, -PI / 2.0, PI / 2.0, 0.0, 0.0, 0.0]),
    ] {
        for (step_name, step) in [("π/50", PI / 50.0), ("π/100", PI / 100.0)] {
            let tip = chain.fk(&q0);
            let centre = Point3::from(tip.translation.vector - Vector3::new(0.01, 0.0, 0.0));
            let steps = (2.0 * PI / step).round() as usize;
            let path = circle_path(&tip, &centre, &Vector3::z(), step, steps).unwrap();
            let targets: Vec<IkTarget> = path.iter().map(|t| IkTarget::Pose(*t)).collect();
            let mut cells = Vec::new();
            for (_, method, solver) in combos().into_iter().take(4) {
                let tp = TrackParams {
                    ik: IkParams {
                        method,
                        linear_solver: solver,
                        position_tolerance: 6e-5,
                        orientation_tolerance: 1e-4,
                        max_restarts: 0,
                        max_iterations: 200,
                        stall_iterations: 0,
                        time_budget: Some(Duration::from_secs(5)),
                        ..IkParams::default()
                    },
                    ..TrackParams::default()
                };
                let r = track_path(&chain, &targets, &q0, &tp, 1, NEVER).unwrap();
                let mean = r.steps.iter().map(|s| s.elapsed_us as f64).sum::<f64>() / r.steps.len() as f64;
                let ok = r
                    .steps
                    .iter()
                    .filter(|s| s.status == kinplan_core::ik::IkStatus::Converged)
                    .count();
                cells.push(format!(
                    "{mean:.0} / {:.4} / {:.0}",
                    r.max_joint_step,
                    100.0 * ok as f64 / r.steps.len() as f64
                ));
            }
            println!("| {start} | {step_name} | {} |", cells.join(" | "));
        }
    }
}

fn heuristic_table() {
    println!("\n### S2 Tab. 7: CCD, FABRIK, length relaxation on planar n = 2…10, tolerance 0.01 mm\n");
    println!(
        "100 random reachable targets per n (FK of uniform random joints), single attempt from the stretched pose q = 0, iteration cap 100 000 sweeps, no restarts. Cells: mean µs / median µs / % converged / mean sweeps. Thesis (C#, ms): LR 19,77,164,94,222,361,353,379,430; FABRIK 21,79,164,94,225,361,353,379,430; CCD 76,77,124,68,100,155,159,129,196.\n"
    );
    println!("| n | length relaxation | FABRIK | CCD |");
    println!("|---|---|---|---|");
    for n in 2..=10 {
        let chain = kinplan_core::robot::builtin_chain(&format!("planar_{n}")).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
        let targets: Vec<IkTarget> = (0..100)
            .map(|_| {
                let q: Vec<f64> = chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect();
                IkTarget::Position(Point3::from(chain.fk(&q).translation.vector))
            })
            .collect();
        let mut cells = Vec::new();
        for method in [IkMethod::LengthRelaxation, IkMethod::Fabrik, IkMethod::Ccd] {
            let p = IkParams {
                method,
                position_tolerance: 1e-5,
                max_iterations: 100_000,
                max_restarts: 0,
                stall_iterations: 0,
                ..IkParams::default()
            };
            let mut solver = IkSolver::new(&chain);
            let seed = vec![0.0; n];
            let mut times = Vec::new();
            let mut ok = 0;
            let mut sweeps = 0;
            for t in &targets {
                let t0 = Instant::now();
                let r = solver.solve(t, Some(&seed), &p, 1, NEVER).unwrap();
                times.push(t0.elapsed().as_secs_f64() * 1e6);
                if r.success() {
                    ok += 1;
                }
                sweeps += r.total_iterations;
            }
            let mean = times.iter().sum::<f64>() / times.len() as f64;
            times.sort_by(f64::total_cmp);
            cells.push(format!(
                "{mean:.1} / {:.1} / {ok} / {:.0}",
                times[times.len() / 2],
                sweeps as f64 / 100.0
            ));
        }
        println!("| {n} | {} |", cells.join(" | "));
    }
}

fn main() {
    let what = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    if what == "rlxa" || what == "all" {
        rlxa_tables();
    }
    if what == "heuristics" || what == "all" {
        heuristic_table();
    }
    if what == "track" || what == "all" {
        track_tables();
    }
}
