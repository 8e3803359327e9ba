//! The planner experiments (S0 §3.3, §5.3) with the parry3d `SceneChecker`:
//!
//! - `s33`: S0 §3.3 — KR 210 R2700 extra between two states with one
//!   obstacle between them; CCSTOMP with t_t = 1 m, t_r = 0.2 rad,
//!   σ = 0.5 m / 0.1 rad per axis; N plans × 10 waypoints. Writes every
//!   waypoint's deviation to `target/plan_s33_deviations.csv` (or `$OUT`).
//! - `tab54`: S0 Tab. 5.4/5.5 form — seeded start/goal pairs in a cluttered
//!   cell for the ABB IRB 4600; RRT-Connect, STOMP and CCSTOMP; OC and CD
//!   mean / variance / sum, success rates and planning times.
//!
//! Usage: cargo run --release --example plan_s0 -- s33 [plans] [on-line] [no-clearance]
//!        cargo run --release --example plan_s0 -- tab54 [pairs]

use std::sync::Arc;
use std::time::Instant;

use kinplan_core::collision::{
    AcmParams, AllowedCollisions, CheckerParams, Geometry, Obstacle, RobotModel, Scene, SceneChecker,
    SceneGeometry, SceneLimits, StateChecker,
};
use kinplan_core::ik::{IkParams, IkTarget, solve_ik};
use kinplan_core::plan::{Algorithm, Goal, PlanControl, PlanRequest, PlanResult, PlanStatus, plan};
use kinplan_core::robot::{Chain, builtin_chain};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn checker(chain: &Arc<Chain>, obstacles: Vec<Obstacle>) -> SceneChecker {
    let model = Arc::new(RobotModel::new(chain.clone()).expect("robot model"));
    let acm = AllowedCollisions::sampled(&model, &AcmParams::default()).expect("acm");
    let scene = Scene::new(obstacles, &SceneLimits::default()).expect("scene");
    let world = Arc::new(SceneGeometry::build(&scene).expect("world"));
    SceneChecker::new(model, &acm, world, CheckerParams::default()).expect("checker")
}

fn sphere(name: &str, c: [f64; 3], r: f64) -> Obstacle {
    Obstacle::new(
        name,
        Isometry3::translation(c[0], c[1], c[2]),
        Geometry::Sphere { radius: r },
    )
}

fn cuboid(name: &str, c: [f64; 3], half: [f64; 3]) -> Obstacle {
    Obstacle::new(
        name,
        Isometry3::translation(c[0], c[1], c[2]),
        Geometry::Box {
            half_extents: Vector3::new(half[0], half[1], half[2]),
        },
    )
}

/// Joints for a tool pose: IK seeded at the middle of the limits, first
/// valid solution.
fn joints_for(chain: &Chain, c: &SceneChecker, pose: Isometry3<f64>) -> Vec<f64> {
    let p = IkParams {
        num_solutions: 8,
        max_restarts: 100,
        ..IkParams::default()
    };
    let r = solve_ik(
        chain,
        &IkTarget::Pose(pose),
        None,
        &p,
        1,
        kinplan_core::Deadline::none(),
    )
    .expect("ik");
    r.solutions
        .iter()
        .find(|s| c.is_valid(&s.joints))
        .map(|s| s.joints.clone())
        .expect("a valid IK solution")
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn s33(plans: usize, on_line: bool, clearance_weight: f64) {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    // Tool pointing down (tool z along −z of the base).
    let down = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let pose = |y: f64| Isometry3::from_parts(Translation3::new(1.6, y, 1.0), down);
    // `on_line`: a ball on the straight Cartesian line (the tool must leave
    // it by ≥ 0.25 m); otherwise a ball beyond it, on the arc the tool
    // sweeps when the joints move on their straight line (x ≈ 1.85 m at
    // y = 0), which blocks joint-space interpolation but not the line.
    let ball = if on_line {
        sphere("ball", [1.6, 0.0, 1.0], 0.25)
    } else {
        sphere("ball", [1.95, 0.0, 1.0], 0.15)
    };
    let c = checker(&chain, vec![ball]);
    let start = joints_for(&chain, &c, pose(-0.9));
    let goal = joints_for(&chain, &c, pose(0.9));
    println!("start {start:.3?}\ngoal  {goal:.3?}");
    let mut straight = vec![0.0; 6];
    let line_blocked = (0..=20).any(|i| {
        let s = i as f64 / 20.0;
        for j in 0..6 {
            straight[j] = start[j] + s * (goal[j] - start[j]);
        }
        !c.is_valid(&straight)
    });
    println!("straight joint line blocked: {line_blocked}");
    let mut req = PlanRequest {
        start: start.clone(),
        goal: Goal::Joints(goal.clone()),
        algorithm: Algorithm::Ccstomp,
        ..Default::default()
    };
    req.stomp.timesteps = 10;
    req.cartesian.translation_tolerance = 1.0;
    req.cartesian.rotation_tolerance = 0.2;
    req.cartesian.translation_stddev = 0.5;
    req.cartesian.rotation_stddev = 0.1;
    req.stomp.clearance_weight = clearance_weight;
    env_overrides(&mut req);
    let (mut rrt_us, mut stomp_us, mut verify_us) = (0u64, 0u64, 0u64);
    let mut rows = String::from("plan,waypoint,translation_m,rotation_rad\n");
    let mut times = Vec::new();
    let (mut ok, mut beyond, mut total) = (0, 0, 0);
    let (mut below_t, mut below_r) = (0, 0);
    let mut iters = Vec::new();
    let t_all = Instant::now();
    for k in 0..plans {
        req.seed = k as u64;
        let t0 = Instant::now();
        let r = plan(&chain, &c, &req, PlanControl::default()).expect("plan");
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        iters.push(r.iterations as f64);
        rrt_us += r.timings.rrt_us;
        stomp_us += r.timings.stomp_us;
        verify_us += r.timings.verify_us;
        ok += (r.status == PlanStatus::Succeeded) as usize;
        for (i, d) in r.deviation.iter().enumerate() {
            total += 1;
            beyond += (d.translation > 1.0 || d.rotation > 0.2) as usize;
            below_t += (d.translation < 0.1) as usize;
            below_r += (d.rotation < 0.01) as usize;
            rows.push_str(&format!("{k},{i},{},{}\n", d.translation, d.rotation));
        }
    }
    let wall = t_all.elapsed().as_secs_f64();
    let out = std::env::var("OUT").unwrap_or_else(|_| "target/plan_s33_deviations.csv".into());
    std::fs::write(&out, rows).expect("write csv");
    let med = percentile(&mut times.clone(), 0.5);
    let p95 = percentile(&mut times.clone(), 0.95);
    println!(
        "CCSTOMP S0 §3.3: {plans} plans, succeeded {ok} ({:.1} %), waypoints {total}, beyond tolerance {beyond}",
        100.0 * ok as f64 / plans as f64
    );
    println!(
        "  waypoints < 0.1 m: {:.1} %, < 0.01 rad: {:.1} %",
        100.0 * below_t as f64 / total as f64,
        100.0 * below_r as f64 / total as f64
    );
    println!(
        "  time per plan: median {med:.2} ms, p95 {p95:.2} ms, mean iterations {:.1}; wall {wall:.1} s",
        iters.iter().sum::<f64>() / iters.len() as f64
    );
    let per = |us: u64| us as f64 / plans as f64 / 1e3;
    println!(
        "  mean per plan: RRT-Connect {:.2} ms, STOMP loop {:.2} ms, re-check {:.2} ms",
        per(rrt_us),
        per(stomp_us),
        per(verify_us)
    );
}

/// A cluttered cell for the IRB 4600: a table, a back wall, pillars and
/// balls, fixed by a seed (no floor box: the base meshes reach below z = 0).
fn irb_cell() -> Vec<Obstacle> {
    let mut obs = vec![
        cuboid("table", [1.5, 0.0, 0.35], [0.4, 0.6, 0.35]),
        cuboid("wall", [-1.2, 0.0, 1.2], [0.05, 2.0, 1.2]),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    for i in 0..5 {
        let a: f64 = rng.random_range(-2.5..2.5);
        let r: f64 = rng.random_range(1.3..2.0);
        obs.push(sphere(
            &format!("ball{i}"),
            [r * a.cos(), r * a.sin(), rng.random_range(0.6..1.8)],
            rng.random_range(0.1..0.2),
        ));
    }
    for i in 0..3 {
        let a: f64 = rng.random_range(-2.5..2.5);
        let r: f64 = rng.random_range(1.6..2.3);
        obs.push(cuboid(
            &format!("pillar{i}"),
            [r * a.cos(), r * a.sin(), 1.0],
            [0.08, 0.08, 1.0],
        ));
    }
    obs
}

#[derive(Default)]
struct Tally {
    oc: Vec<f64>,
    cd: Vec<f64>,
    dense_oc: Vec<f64>,
    dense_cd: Vec<f64>,
    times: Vec<f64>,
    ok: usize,
    statuses: Vec<PlanStatus>,
}

/// OC (S0's half angles, sign-safe) and CD of the motion the controller
/// executes: every segment cut into steps of at most 0.05 rad (max-norm), so
/// a sparse RRT-Connect path is measured along its tool curve, not its chords.
fn dense_oc_cd(chain: &Chain, q: &[f64]) -> (f64, f64) {
    let dof = chain.dof();
    let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
    let (mut oc, mut cd) = (0.0, 0.0);
    let mut prev = chain.fk(rows[0]);
    let mut p = vec![0.0; dof];
    for w in rows.windows(2) {
        let span = w[0]
            .iter()
            .zip(w[1])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let k = (span / 0.05).ceil().max(1.0) as usize;
        for i in 1..=k {
            let s = i as f64 / k as f64;
            for j in 0..dof {
                p[j] = w[0][j] + s * (w[1][j] - w[0][j]);
            }
            let cur = chain.fk(&p);
            cd += (cur.translation.vector - prev.translation.vector).norm();
            oc += prev
                .rotation
                .coords
                .dot(&cur.rotation.coords)
                .abs()
                .min(1.0)
                .acos();
            prev = cur;
        }
    }
    (oc, cd)
}

fn stats(v: &[f64]) -> (f64, f64, f64) {
    let n = v.len() as f64;
    let sum: f64 = v.iter().sum();
    let mean = sum / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var, sum)
}

fn tab54(pairs: usize) {
    let chain = builtin_chain("abb_irb4600_60_205").unwrap();
    let c = checker(&chain, irb_cell());
    let lim: Vec<(f64, f64)> = chain.limits().collect();
    let mut rng = ChaCha8Rng::seed_from_u64(54);
    // Camera viewpoints: valid states whose tool is 1.0–2.2 m from the base axis and 0.6–2.0 m high.
    let mut tries = 0usize;
    let mut sample = || loop {
        tries += 1;
        assert!(tries < 1_000_000, "no valid viewpoint state in 1e6 samples");
        let q: Vec<f64> = lim
            .iter()
            .map(|&(lo, hi)| rng.random_range(lo.max(-3.0)..hi.min(3.0)))
            .collect();
        let p: Point3<f64> = chain.fk(&q).translation.vector.into();
        let rxy = (p.x * p.x + p.y * p.y).sqrt();
        if (1.0..2.2).contains(&rxy) && (0.6..2.0).contains(&p.z) && c.is_valid(&q) {
            return q;
        }
    };
    let problems: Vec<(Vec<f64>, Vec<f64>)> = (0..pairs).map(|_| (sample(), sample())).collect();
    eprintln!("{pairs} pairs sampled");
    let algs = [Algorithm::RrtConnect, Algorithm::Stomp, Algorithm::Ccstomp];
    let mut tallies: Vec<Tally> = algs.iter().map(|_| Tally::default()).collect();
    let mut results: Vec<Vec<PlanResult>> = vec![Vec::new(); algs.len()];
    for (k, (s, g)) in problems.iter().enumerate() {
        for (a, alg) in algs.iter().enumerate() {
            let mut req = PlanRequest {
                start: s.clone(),
                goal: Goal::Joints(g.clone()),
                algorithm: *alg,
                seed: k as u64,
                ..Default::default()
            };
            env_overrides(&mut req);
            let t0 = Instant::now();
            let r = plan(&chain, &c, &req, PlanControl::default()).expect("plan");
            let t = &mut tallies[a];
            t.times.push(t0.elapsed().as_secs_f64() * 1e3);
            t.ok += (r.status == PlanStatus::Succeeded) as usize;
            t.statuses.push(r.status);
            results[a].push(r);
        }
        if (k + 1) % 10 == 0 {
            eprintln!("{} pairs planned", k + 1);
        }
    }
    // Criteria over the pairs where every algorithm returned a collision-free
    // trajectory (a like-for-like sum); CCSTOMP results beyond a Cartesian
    // tolerance are counted in, and their number is printed.
    let common: Vec<usize> = (0..pairs)
        .filter(|&k| results.iter().all(|r| r[k].valid))
        .collect();
    for (a, t) in tallies.iter_mut().enumerate() {
        for &k in &common {
            let s = results[a][k].criteria.expect("criteria");
            t.oc.push(s.oc);
            t.cd.push(s.cd);
            let (doc, dcd) = dense_oc_cd(&chain, &results[a][k].q);
            t.dense_oc.push(doc);
            t.dense_cd.push(dcd);
        }
    }
    println!(
        "IRB 4600 cluttered cell: {pairs} pairs, {} collision-free for all three",
        common.len()
    );
    println!(
        "| algorithm | succeeded | collision-free | beyond t_t/t_r | time median ms | p95 ms | OC mean | OC var | OC sum | CD mean | CD var | CD sum | dense OC sum | dense CD sum |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (a, t) in tallies.iter_mut().enumerate() {
        let (om, ov, os) = stats(&t.oc);
        let (cm, cv, cs) = stats(&t.cd);
        let med = percentile(&mut t.times, 0.5);
        let p95 = percentile(&mut t.times, 0.95);
        let free = results[a].iter().filter(|r| r.valid).count();
        let beyond = results[a]
            .iter()
            .filter(|r| r.valid && r.violates_tolerance)
            .count();
        println!(
            "| {:?} | {}/{} | {free} | {beyond} | {med:.1} | {p95:.1} | {om:.2} | {ov:.2} | {os:.2} | {cm:.2} | {cv:.2} | {cs:.2} | {:.2} | {:.2} |",
            algs[a],
            t.ok,
            pairs,
            t.dense_oc.iter().sum::<f64>(),
            t.dense_cd.iter().sum::<f64>()
        );
        let mut other: Vec<String> = t
            .statuses
            .iter()
            .filter(|s| **s != PlanStatus::Succeeded)
            .map(|s| format!("{s:?}"))
            .collect();
        other.sort();
        other.dedup_by(|a, b| a == b);
        if !other.is_empty() {
            println!("  {:?} failures: {other:?}", algs[a]);
        }
    }
}

/// Overrides from the environment (`H`, `IK_ITERS`, `ITERS`, `AFTER_VALID`,
/// `ROLLOUTS`, `INIT=cartesian` or `INIT=rrt` for CCSTOMP's start), for the parameter sweeps reported in PLAN_RESULTS.md.
fn env_overrides(req: &mut PlanRequest) {
    let get = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(h) = get("H") {
        req.stomp.cost_sensitivity = h;
    }
    if let Some(v) = get("IK_ITERS") {
        req.cartesian.ik_iterations = v as usize;
    }
    if let Some(v) = get("ITERS") {
        req.stomp.max_iterations = v as usize;
    }
    if let Some(v) = get("AFTER_VALID") {
        req.stomp.iterations_after_valid = v as usize;
    }
    // CCSTOMP only: STOMP keeps its MoveIt-like start
    if req.algorithm == Algorithm::Ccstomp {
        match std::env::var("INIT").as_deref() {
            Ok("cartesian") => req.stomp.initial = kinplan_core::plan::InitialTrajectory::CartesianLine,
            Ok("rrt") => req.stomp.initial = kinplan_core::plan::InitialTrajectory::RrtConnectIfBlocked,
            _ => {}
        }
    }
    if let Some(v) = get("ROLLOUTS") {
        req.stomp.rollouts = v as usize;
        req.stomp.max_rollouts = req.stomp.max_rollouts.max(v as usize);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n = |default: usize| args.get(2).and_then(|s| s.parse().ok()).unwrap_or(default);
    match args.get(1).map(String::as_str) {
        Some("s33") => s33(
            n(3000),
            args.iter().any(|a| a == "on-line"),
            if args.iter().any(|a| a == "no-clearance") {
                0.0
            } else {
                1.0
            },
        ),
        Some("tab54") => tab54(n(100)),
        _ => eprintln!("usage: plan_s0 s33 [plans] | tab54 [pairs]"),
    }
}
