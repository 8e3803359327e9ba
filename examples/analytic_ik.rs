//! Closed-form IK runner: N random reachable poses of a 6R arm (FK of joints
//! drawn uniformly inside the limits, ChaCha8 seed 2026), every solution of
//! each by the analytic solver on one core.
//!
//! Checks (untimed): every solution's FK matches the pose (position ≤ 1e-9 m,
//! rotation ≤ 1e-9 rad), the sampled configuration is among the solutions
//! (modulo 2π), and Levenberg–Marquardt from `LM_SEEDS` random seeds per pose
//! (default 64, on the first `LM_POSES` poses, default all) finds no solution
//! the analytic solver missed.
//! Timing: best of 5 passes (`PASSES`) over all poses, µs per pose, for the 8-configuration
//! answer (`Turns::NearestSeed`, no seed: each joint's turn nearest zero) and
//! for every whole-turn variant (`Turns::All`).
//!
//! `cargo run --release -p kinplan-core --example analytic_ik -- <builtin | file.urdf> [N] [out_dir] [tip_link]`
//!
//! With `out_dir`: writes `<out_dir>/<robot>.csv` (per pose: the sampled joints,
//! then the rotation of `T·M⁻¹` row-major and the tool position of `T`: the pose
//! in the convention of ik-geo and EAIK, whose tool frame is aligned with the
//! base at zero; then our solution count) and
//! `<out_dir>/<robot>_hp.txt` (the 6 axes `H` and 7 offsets `P`, base frame at
//! zero, one vector a line; the wrist axes' points at the wrist point) for `benches/analytic_ik/run.py`.

use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use kinplan_core::Deadline;
use kinplan_core::ik::analytic::{
    AnalyticArm, AnalyticParams, AnalyticSolution, Family, Turns, ZeroAxes, analyse, wrap,
};
use kinplan_core::ik::{IkMethod, IkParams, IkSolver, IkTarget};
use kinplan_core::robot::{Chain, ChainSpec, UrdfLimits, builtin_chain, parse_chain};
use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn load(name: &str, tip: Option<String>) -> (String, Chain) {
    if Path::new(name).exists() {
        let text = std::fs::read_to_string(name).expect("read the URDF");
        let spec = ChainSpec {
            base_link: None,
            tip_link: tip,
        };
        let chain = parse_chain(&text, &spec, UrdfLimits::default()).expect("parse the URDF");
        let stem = Path::new(name)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        (stem, chain)
    } else {
        (
            name.to_string(),
            (*builtin_chain(name).expect("a built-in robot")).clone(),
        )
    }
}

fn same(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| wrap(x - y).abs() <= tol)
}

fn time_passes(arm: &AnalyticArm, poses: &[Isometry3<f64>], params: &AnalyticParams) -> (f64, usize) {
    let mut out: Vec<AnalyticSolution> = Vec::with_capacity(4096);
    let mut best = f64::INFINITY;
    let mut count = 0;
    for _ in 0..passes() {
        count = 0;
        let t0 = Instant::now();
        for p in poses {
            arm.solve_into(black_box(p), None, params, &mut out);
            count += black_box(out.len());
        }
        best = best.min(t0.elapsed().as_secs_f64() * 1e6 / poses.len() as f64);
    }
    (best, count)
}

/// Timed passes over the poses, the best taken: `PASSES` (default 5; more
/// catch a pass without interruption on a shared host).
fn passes() -> usize {
    std::env::var("PASSES").map_or(5, |s| s.parse().expect("PASSES"))
}

fn random_7(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .joints()
        .iter()
        .map(|j| rng.random_range(j.lower..=j.upper))
        .collect()
}

fn dist2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn best_of_5(mut pass: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        pass();
        best = best.min(t0.elapsed().as_secs_f64());
    }
    best
}

/// 7-joint arms. (1) Held: joint values drawn inside the limits, the
/// redundant joint held at its sampled value (chosen by `analyse`), every
/// solution of the other six; timed for the closed form alone (`analyse` +
/// `solve_into`) and through `IkSolver` (FK re-check and ranking of every
/// solution, as the service answers). (2) The same with the held joint at one
/// fixed value (0.5 rad) for all poses, written to `out_dir` for EAIK's locked
/// joint. (3) Searched: each pose's joints with the held joint moved 0.4 rad
/// and the others up to 0.05 rad as the seed; `search_redundant` against
/// Levenberg–Marquardt from the same seed (default restarts), both through
/// `IkSolver`, with the squared joint distance of the answer to the seed
/// (`SAMPLES`: the search's `redundant_samples`, default 24).
fn redundant(label: &str, chain: &Chain, n: usize, out_dir: Option<&String>) {
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let configs: Vec<Vec<f64>> = (0..n).map(|_| random_7(chain, &mut rng)).collect();
    let poses: Vec<Isometry3<f64>> = configs.iter().map(|q| chain.fk(q)).collect();
    let params = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    let mut out = Vec::new();
    let (mut missing, mut bad, mut total) = (0, 0, 0usize);
    let first = match analyse(chain, &params, configs.first().map(|q| &q[..])) {
        Ok(r) => r,
        Err(e) => {
            println!("{label}: {e}");
            return;
        }
    };
    let (j, _) = first.held.expect("a 7-joint chain");
    let family = first.arm.family();
    let reversed = first.arm.is_reversed();
    for (q, t) in configs.iter().zip(&poses) {
        let r = analyse(chain, &params, Some(q)).expect("analytic with a joint held");
        r.arm.solve_into(t, Some(&r.reduce(q)), &params, &mut out);
        total += out.len();
        let full: Vec<Vec<f64>> = out.iter().map(|s| r.expand(&s.joints)).collect();
        if !full.iter().any(|s| same(s, q, 1e-7)) {
            missing += 1;
            if missing <= 3 {
                eprintln!("{label}: {q:?} not among {full:?}");
            }
        }
        for s in &full {
            let f = chain.fk(s);
            if (f.translation.vector - t.translation.vector).norm() > 1e-9
                || f.rotation.angle_to(&t.rotation) > 1e-9
            {
                bad += 1;
            }
        }
    }
    // numerical cross-check on the held chains: LM from LM_SEEDS random seeds
    // (default 64) on the first LM_POSES7 poses (default 500) finds no
    // solution the closed form (every branch, no limits) missed
    let lm_seeds: usize = std::env::var("LM_SEEDS").map_or(64, |s| s.parse().unwrap());
    let lm_poses: usize = std::env::var("LM_POSES7").map_or(500, |s| s.parse().unwrap());
    let lm_check = IkParams {
        max_restarts: 0,
        position_tolerance: 1e-10,
        orientation_tolerance: 1e-10,
        ..IkParams::default()
    };
    let (mut lm_found, mut lm_missed) = (0usize, 0usize);
    for (q, t) in configs.iter().zip(&poses).take(lm_poses) {
        let r = analyse(chain, &params, Some(q)).unwrap();
        let (hj, hv) = r.held.unwrap();
        let six = chain.with_joint_fixed(hj, hv).unwrap();
        let mut ours = Vec::new();
        r.arm.nearest(t, None, &params, &mut ours);
        ours.retain(|s| s.exact);
        let mut lm_solver = IkSolver::new(&six);
        for _ in 0..lm_seeds {
            let seed: Vec<f64> = six
                .joints()
                .iter()
                .map(|j| rng.random_range(j.lower..=j.upper))
                .collect();
            let res = lm_solver
                .solve(&IkTarget::Pose(*t), Some(&seed), &lm_check, 0, Deadline::none())
                .unwrap();
            if let Some(s) = res.solutions.first() {
                lm_found += 1;
                if !ours.iter().any(|a| same(&a.joints, &s.joints, 1e-6)) {
                    lm_missed += 1;
                    if lm_missed <= 3 {
                        eprintln!("{label}: LM found {:?}, not among {:?}", s.joints, ours);
                    }
                }
            }
        }
    }
    let held_us = best_of_5(|| {
        for (q, t) in configs.iter().zip(&poses) {
            let r = analyse(chain, &params, Some(black_box(q))).unwrap();
            r.arm.solve_into(black_box(t), None, &params, &mut out);
            black_box(out.len());
        }
    }) * 1e6
        / n as f64;
    let mut solver = IkSolver::new(chain);
    let service = IkParams {
        method: IkMethod::Analytic,
        num_solutions: 1000,
        analytic: params,
        ..IkParams::default()
    };
    let service_us = best_of_5(|| {
        for (q, t) in configs.iter().zip(&poses) {
            let r = solver
                .solve(&IkTarget::Pose(*t), Some(q), &service, 0, Deadline::none())
                .unwrap();
            black_box(r.solutions.len());
        }
    }) * 1e6
        / n as f64;

    // (2) one fixed held value, for EAIK
    let v_fix = 0.5;
    let fixed: Vec<Vec<f64>> = (0..n)
        .map(|_| {
            let mut q = random_7(chain, &mut rng);
            q[j] = v_fix;
            q
        })
        .collect();
    let fixed_poses: Vec<Isometry3<f64>> = fixed.iter().map(|q| chain.fk(q)).collect();
    let mut fixed_total = 0;
    let fixed_us = best_of_5(|| {
        fixed_total = 0;
        for (q, t) in fixed.iter().zip(&fixed_poses) {
            let r = analyse(chain, &params, Some(black_box(q))).unwrap();
            r.arm.solve_into(black_box(t), None, &params, &mut out);
            fixed_total += black_box(out.len());
        }
    }) * 1e6
        / n as f64;
    if let Some(dir) = out_dir {
        std::fs::create_dir_all(dir).unwrap();
        let z = ZeroAxes::of(chain);
        let m_inv = z.m.inverse();
        let mut f = std::io::BufWriter::new(std::fs::File::create(format!("{dir}/{label}.csv")).unwrap());
        for (q, t) in fixed.iter().zip(&fixed_poses) {
            let r = analyse(chain, &params, Some(q)).unwrap();
            r.arm.solve_into(t, Some(&r.reduce(q)), &params, &mut out);
            writeln!(f, "{} {}", pose_row(q, t, &m_inv), out.len()).unwrap();
        }
        let mut hp = std::fs::File::create(format!("{dir}/{label}_hp.txt")).unwrap();
        for h in &z.h {
            writeln!(hp, "{:.17e} {:.17e} {:.17e}", h.x, h.y, h.z).unwrap();
        }
        let mut prev = nalgebra::Vector3::zeros();
        for p in z.p.iter().chain(std::iter::once(&z.m.translation.vector)) {
            let d = p - prev;
            writeln!(hp, "{:.17e} {:.17e} {:.17e}", d.x, d.y, d.z).unwrap();
            prev = *p;
        }
    }

    // (3) searched, beside LM from the same seed
    let seeds: Vec<Vec<f64>> = configs
        .iter()
        .map(|q| {
            let mut s = q.clone();
            let (lo, hi) = (chain.joints()[j].lower, chain.joints()[j].upper);
            s[j] = if q[j] + 0.4 <= hi { q[j] + 0.4 } else { q[j] - 0.4 }.clamp(lo, hi);
            for (i, v) in s.iter_mut().enumerate() {
                if i != j {
                    *v += rng.random_range(-0.05..0.05);
                }
            }
            s
        })
        .collect();
    let search = IkParams {
        method: IkMethod::Analytic,
        num_solutions: 1,
        analytic: AnalyticParams {
            search_redundant: true,
            redundant_samples: std::env::var("SAMPLES").map_or(24, |s| s.parse().expect("SAMPLES")),
            ..AnalyticParams::default()
        },
        ..IkParams::default()
    };
    let lm = IkParams::default();
    let run = |solver: &mut IkSolver, p: &IkParams| -> (f64, usize, usize, f64) {
        let (mut sum, mut solved, mut as_near) = (0.0, 0usize, 0usize);
        let us = best_of_5(|| {
            (sum, solved, as_near) = (0.0, 0, 0);
            for ((q, t), s) in configs.iter().zip(&poses).zip(&seeds) {
                let r = solver
                    .solve(&IkTarget::Pose(*t), Some(s), p, 0, Deadline::none())
                    .unwrap();
                if let Some(best) = r.solutions.first() {
                    let d = dist2(&best.joints, s);
                    solved += 1;
                    sum += d;
                    if d <= dist2(q, s) + 1e-12 {
                        as_near += 1;
                    }
                }
            }
        }) * 1e6
            / n as f64;
        (us, solved, as_near, sum / solved.max(1) as f64)
    };
    let (search_us, search_solved, search_near, search_d) = run(&mut solver, &search);
    let (lm_us, lm_solved, lm_near, lm_d) = run(&mut solver, &lm);
    println!(
        "{label}: joint {} held, family {family}{}; held at the sampled value: {n} poses, {total} solutions \
         ({:.2}/pose), sampled configuration missing {missing}, FK error > 1e-9: {bad}; µs/pose: closed form \
         {held_us:.3}, through IkSolver (FK check, ranking) {service_us:.3}; held at {v_fix}: {:.2}/pose, \
         {fixed_us:.3} µs; searched: {search_us:.2} µs, solved {search_solved}/{n}, as near as the pose's joints \
         {search_near}/{n}, mean squared distance {search_d:.4}; LM from the seed: {lm_us:.2} µs, solved \
         {lm_solved}/{n}, as near {lm_near}/{n}, mean squared distance {lm_d:.4}; LM {lm_seeds} seeds × \
         {lm_poses} poses on the held chain: {lm_found} converged, {lm_missed} not among ours",
        j + 1,
        if reversed { " (read from the tool end)" } else { "" },
        total as f64 / n as f64,
        fixed_total as f64 / n as f64,
    );
    println!(
        "RESULT7 {label} {family} {} {n} {total} {missing} {bad} {held_us:.4} {service_us:.4} {fixed_us:.4} \
         {search_us:.4} {search_solved} {search_near} {search_d:.6} {lm_us:.4} {lm_solved} {lm_near} {lm_d:.6} {j}",
        reversed
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("ur5", String::as_str);
    let n: usize = args.get(1).map_or(10_000, |s| s.parse().expect("N"));
    let out_dir = args.get(2).filter(|s| !s.is_empty());
    let tip = args.get(3).cloned();
    let lm_seeds: usize = std::env::var("LM_SEEDS").map_or(64, |s| s.parse().unwrap());
    let lm_poses: usize = std::env::var("LM_POSES").map_or(n, |s| s.parse().unwrap());

    let (label, chain) = load(name, tip);
    if chain.dof() == 7 {
        redundant(&label, &chain, n, out_dir);
        return;
    }
    let t0 = Instant::now();
    let arm = match AnalyticArm::new(&chain, 1e-9) {
        Ok(a) => a,
        Err(e) => {
            println!("{label}: {e}");
            return;
        }
    };
    let analyse_us = t0.elapsed().as_secs_f64() * 1e6;
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let configs: Vec<[f64; 6]> = (0..n)
        .map(|_| {
            std::array::from_fn(|i| {
                let j = &chain.joints()[i];
                let (lo, hi) = (
                    j.lower.max(-2.0 * std::f64::consts::PI),
                    j.upper.min(2.0 * std::f64::consts::PI),
                );
                rng.random_range(lo..=hi)
            })
        })
        .collect();
    let poses: Vec<Isometry3<f64>> = configs.iter().map(|q| chain.fk(q)).collect();

    // checks
    let nearest = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    let mut out = Vec::new();
    let (mut missing, mut bad_fk, mut total, mut worst_p, mut worst_r) = (0, 0, 0usize, 0.0f64, 0.0f64);
    let mut counts = Vec::with_capacity(n);
    let mut answers: Vec<Vec<[f64; 6]>> = Vec::with_capacity(n);
    for (q, t) in configs.iter().zip(&poses) {
        arm.solve_into(t, None, &nearest, &mut out);
        total += out.len();
        counts.push(out.len());
        if !out.iter().any(|s| same(&s.joints, q, 1e-7)) {
            missing += 1;
            if missing <= 3 {
                eprintln!(
                    "{label}: sampled configuration {q:?} not among {} solutions",
                    out.len()
                );
            }
        }
        for s in &out {
            let f = chain.fk(&s.joints);
            let dp = (f.translation.vector - t.translation.vector).norm();
            let dr = f.rotation.angle_to(&t.rotation);
            worst_p = worst_p.max(dp);
            worst_r = worst_r.max(dr);
            if dp > 1e-9 || dr > 1e-9 {
                bad_fk += 1;
            }
        }
        answers.push(out.iter().map(|s| s.joints).collect());
    }

    // numerical cross-check
    let lm = IkParams {
        max_restarts: 0,
        position_tolerance: 1e-10,
        orientation_tolerance: 1e-10,
        ..IkParams::default()
    };
    let mut solver = IkSolver::new(&chain);
    let (mut lm_found, mut lm_missed) = (0usize, 0usize);
    let t_lm = Instant::now();
    for (t, ans) in poses.iter().zip(&answers).take(lm_poses) {
        for _ in 0..lm_seeds {
            let seed: Vec<f64> = chain
                .joints()
                .iter()
                .map(|j| {
                    rng.random_range(
                        j.lower.max(-2.0 * std::f64::consts::PI)..=j.upper.min(2.0 * std::f64::consts::PI),
                    )
                })
                .collect();
            let r = solver
                .solve(
                    &IkTarget::Pose(*t),
                    Some(&seed),
                    &lm,
                    0,
                    kinplan_core::Deadline::none(),
                )
                .unwrap();
            if let Some(s) = r.solutions.first() {
                lm_found += 1;
                if !ans.iter().any(|a| same(a, &s.joints, 1e-6)) {
                    lm_missed += 1;
                    if lm_missed <= 3 {
                        eprintln!("LM found {:?}, not among {:?}", s.joints, ans);
                    }
                }
            }
        }
    }
    let lm_s = t_lm.elapsed().as_secs_f64();

    let (us_8, _) = time_passes(&arm, &poses, &nearest);
    let (us_all, all_count) = time_passes(&arm, &poses, &AnalyticParams::default());
    println!(
        "{label}: family {} (analysis {analyse_us:.1} µs); {n} poses, {total} solutions in (−π, π] \
         ({:.2}/pose), {all_count} with every whole turn; original configuration missing: {missing}; \
         solutions with FK error > 1e-9: {bad_fk} (worst {worst_p:.1e} m, {worst_r:.1e} rad); \
         LM {lm_seeds} seeds × {} poses: {lm_found} converged, {lm_missed} not among ours ({lm_s:.1} s); \
         µs/pose on one core: {us_8:.3} (turn nearest zero), {us_all:.3} (all turns)",
        arm.family(),
        total as f64 / n as f64,
        lm_poses.min(n),
    );
    println!(
        "RESULT {label} {} {n} {total} {all_count} {missing} {bad_fk} {lm_found} {lm_missed} {us_8:.4} {us_all:.4}",
        arm.family()
    );

    if let Some(dir) = out_dir {
        std::fs::create_dir_all(dir).unwrap();
        let mut z = ZeroAxes::of(&chain);
        // points on the axes may slide along them: the wrist axes' points at the
        // point where they meet, as ik-geo's spherical and UR-type solvers expect
        let first_wrist_axis = match arm.family() {
            Family::SphericalWrist | Family::SphericalTwoIntersecting => 3,
            Family::ThreeParallel => 4,
            // ik-geo's searched solvers take the axes' points as they are
            Family::Searched6R => 6,
        };
        for p in &mut z.p[first_wrist_axis..] {
            *p = arm.wrist_point();
        }
        let m_inv = z.m.inverse();
        let mut f = std::io::BufWriter::new(std::fs::File::create(format!("{dir}/{label}.csv")).unwrap());
        for ((q, t), c) in configs.iter().zip(&poses).zip(&counts) {
            writeln!(f, "{} {c}", pose_row(q, t, &m_inv)).unwrap();
        }
        let mut hp = std::fs::File::create(format!("{dir}/{label}_hp.txt")).unwrap();
        for h in &z.h {
            writeln!(hp, "{:.17e} {:.17e} {:.17e}", h.x, h.y, h.z).unwrap();
        }
        let mut prev = nalgebra::Vector3::zeros();
        for p in z.p.iter().chain(std::iter::once(&z.m.translation.vector)) {
            let d = p - prev;
            writeln!(hp, "{:.17e} {:.17e} {:.17e}", d.x, d.y, d.z).unwrap();
            prev = *p;
        }
    }
}

/// A CSV row for the anchor scripts: the joints, the rotation of `t · m_inv`
/// row by row, and the position of `t`, all to 17 digits.
fn pose_row(q: &[f64], t: &Isometry3<f64>, m_inv: &Isometry3<f64>) -> String {
    let g = t * m_inv;
    let r = g.rotation.to_rotation_matrix();
    let m = r.matrix();
    let v: Vec<String> = q
        .iter()
        .copied()
        .chain((0..3).flat_map(|i| (0..3).map(move |j| m[(i, j)])))
        .chain(t.translation.vector.iter().copied())
        .map(|x| format!("{x:.17e}"))
        .collect();
    v.join(" ")
}
