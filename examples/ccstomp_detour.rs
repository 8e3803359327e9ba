//! CCSTOMP with a box across the tool's straight line (docs/planning.md#ccstomp):
//!
//! - `kr210 [seeds] [timesteps]`: the KR 210 R2700 extra turning its base from
//!   −40° to +40° (tool pointing down, the straight tool line 2.1 m long along
//!   y) with a 0.3 m box centred on the line's midpoint; CCSTOMP, STOMP and
//!   RRT-Connect with default parameters, one plan per seed.
//! - `bench [problems] [timesteps]`: seeded problems per robot (KR 210,
//!   IRB 4600, Panda): start and goal states whose straight tool line is
//!   collision-free in joint space by IK, then a box centred on a point of
//!   that line. CCSTOMP with default parameters; success within
//!   t_t = 1 m / t_r = 0.2 rad recomputed here from FK; median / p95 time.
//!
//! Usage: cargo run --release -p kinplan-core --example ccstomp_detour -- kr210 10 40
//!        cargo run --release -p kinplan-core --example ccstomp_detour -- bench 50 40
//! `INIT=line` runs CCSTOMP from the straight-line start only (the code before
//! the detour), for a before/after comparison in one build.

use std::sync::Arc;
use std::time::Instant;

use kinplan_core::collision::{
    AcmParams, AllowedCollisions, CheckerParams, Geometry, Obstacle, RobotModel, Scene, SceneChecker,
    SceneGeometry, SceneLimits, StateChecker,
};
use kinplan_core::ik::{IkParams, IkStatus, IkTarget, solve_ik};
use kinplan_core::plan::{Algorithm, Goal, InitialTrajectory, PlanControl, PlanRequest, PlanStatus, plan};
use kinplan_core::robot::{Chain, builtin_chain};
use nalgebra::{Isometry3, Matrix4, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const T_T: f64 = 1.0;
const T_R: f64 = 0.2;

fn model(chain: &Arc<Chain>) -> (Arc<RobotModel>, AllowedCollisions) {
    let model = Arc::new(RobotModel::new(chain.clone()).expect("robot model"));
    let acm = AllowedCollisions::builtin(&model, chain.name(), &AcmParams::default()).expect("acm");
    (model, acm)
}

fn checker(m: &(Arc<RobotModel>, AllowedCollisions), obstacles: Vec<Obstacle>) -> SceneChecker {
    let scene = Scene::new(obstacles, &SceneLimits::default()).expect("scene");
    let world = Arc::new(SceneGeometry::build(&scene).expect("world"));
    SceneChecker::new(m.0.clone(), &m.1, world, CheckerParams::default()).expect("checker")
}

fn cube(centre: Vector3<f64>, yaw: f64, half: f64) -> Obstacle {
    Obstacle::new(
        "box",
        Isometry3::new(centre, Vector3::z() * yaw),
        Geometry::Box {
            half_extents: Vector3::repeat(half),
        },
    )
}

/// Largest deviation of the waypoints from the straight tool line, computed
/// here with 4×4 matrices: the reference `PL(s)` (position lerp, orientation
/// by quaternion slerp), `Diff = PL⁻¹·FK(q)`, e_t = ‖t(Diff)‖,
/// e_r = acos((tr R(Diff) − 1)/2).
fn worst_deviation(chain: &Chain, q: &[f64]) -> (f64, f64) {
    let dof = chain.dof();
    let n = q.len() / dof;
    let a = chain.fk(&q[..dof]);
    let b = chain.fk(&q[(n - 1) * dof..]);
    let (mut wt, mut wr) = (0.0_f64, 0.0_f64);
    for (i, row) in q.chunks_exact(dof).enumerate() {
        let s = i as f64 / (n - 1) as f64;
        let p = a.translation.vector * (1.0 - s) + b.translation.vector * s;
        let r = a.rotation.slerp(&b.rotation, s);
        let pl: Matrix4<f64> = Isometry3::from_parts(p.into(), r).to_homogeneous();
        let diff = pl.try_inverse().expect("rigid") * chain.fk(row).to_homogeneous();
        let et = diff.fixed_view::<3, 1>(0, 3).norm();
        let tr = diff.fixed_view::<3, 3>(0, 0).trace();
        wt = wt.max(et);
        wr = wr.max(((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos());
    }
    (wt, wr)
}

/// The straight tool line as joints by warm-started IK (no restarts),
/// `n` waypoints; `None` on an IK failure or a jump > 0.5 rad.
fn line_joints(chain: &Chain, start: &[f64], goal: &[f64], n: usize) -> Option<Vec<f64>> {
    let dof = chain.dof();
    let (a, b) = (chain.fk(start), chain.fk(goal));
    let p = IkParams {
        max_restarts: 0,
        ..IkParams::default()
    };
    let mut out = start.to_vec();
    for i in 1..n - 1 {
        let s = i as f64 / (n - 1) as f64;
        let pose = Isometry3::from_parts(
            (a.translation.vector.lerp(&b.translation.vector, s)).into(),
            a.rotation.slerp(&b.rotation, s),
        );
        let prev = out[(i - 1) * dof..i * dof].to_vec();
        let r = solve_ik(
            chain,
            &IkTarget::Pose(pose),
            Some(&prev),
            &p,
            0,
            kinplan_core::Deadline::none(),
        )
        .ok()?;
        if r.stop_reason != IkStatus::Converged {
            return None;
        }
        out.extend_from_slice(&r.solutions.first()?.joints);
    }
    out.extend_from_slice(goal);
    let jump = out
        .chunks_exact(dof)
        .zip(out.chunks_exact(dof).skip(1))
        .map(|(x, y)| x.iter().zip(y).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    (jump <= 0.5).then_some(out)
}

fn path_free(c: &SceneChecker, q: &[f64], dof: usize) -> bool {
    let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
    rows.iter().all(|r| c.is_valid(r)) && rows.windows(2).all(|w| c.motion_valid(w[0], w[1]))
}

/// CPU time of every thread of this process so far (ns, from
/// `/proc/self/task/*/schedstat`): a per-plan cost that a loaded machine
/// does not inflate the way it inflates wall time.
fn cpu_ns() -> u64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| std::fs::read_to_string(e.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next().and_then(|v| v.parse::<u64>().ok()))
        .sum()
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * p).round() as usize]
}

#[derive(Default)]
struct Tally {
    times: Vec<f64>,
    cpu: Vec<f64>,
    ok: usize,
    ok_recomputed: usize,
    statuses: Vec<String>,
    worst_rot: Vec<f64>,
    /// summed µs: start (initial trajectory + goal IK), STOMP loop, re-check
    phases: [u64; 3],
}

impl Tally {
    fn line(&mut self, label: &str, total: usize) -> String {
        let med = percentile(&mut self.times, 0.5);
        let p95 = percentile(&mut self.times, 0.95);
        let cpu_med = percentile(&mut self.cpu, 0.5);
        let cpu_p95 = percentile(&mut self.cpu, 0.95);
        let mut other = self.statuses.clone();
        other.sort();
        other.dedup();
        let per = |us: u64| us as f64 / total as f64 / 1e3;
        format!(
            "| {label} | {}/{total} | {}/{total} | {med:.1} / {p95:.1} | {cpu_med:.1} / {cpu_p95:.1} | {:.1} / {:.1} / {:.1} | {:.3} | {} |",
            self.ok,
            self.ok_recomputed,
            per(self.phases[0]),
            per(self.phases[1]),
            per(self.phases[2]),
            percentile(&mut self.worst_rot, 0.95),
            other.join(", ")
        )
    }
}

fn request(start: &[f64], goal: &[f64], alg: Algorithm, seed: u64, n: usize) -> PlanRequest {
    let mut req = PlanRequest {
        start: start.to_vec(),
        goal: Goal::Joints(goal.to_vec()),
        algorithm: alg,
        seed,
        ..Default::default()
    };
    req.stomp.timesteps = n;
    // parameter probes: `SIGMA_T` (m), `SIGMA_R` (rad), `ITERS`
    let get = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(v) = get("SIGMA_T") {
        req.cartesian.translation_stddev = v;
    }
    if let Some(v) = get("SIGMA_R") {
        req.cartesian.rotation_stddev = v;
    }
    if let Some(v) = get("ITERS") {
        req.stomp.max_iterations = v as usize;
    }
    if alg == Algorithm::Ccstomp && std::env::var("INIT").as_deref() == Ok("line") {
        // the code before the detour: straight line, else RRT-Connect
        req.stomp.initial = InitialTrajectory::RrtConnectIfBlocked;
    }
    req
}

/// One plan: status, time (ms) and the FK-recomputed verdict.
fn run(chain: &Chain, c: &SceneChecker, req: &PlanRequest, t: &mut Tally) {
    let (t0, c0) = (Instant::now(), cpu_ns());
    let r = plan(chain, c, req, PlanControl::default()).expect("plan");
    t.times.push(t0.elapsed().as_secs_f64() * 1e3);
    t.cpu.push((cpu_ns() - c0) as f64 / 1e6);
    let ok = r.status == PlanStatus::Succeeded;
    t.ok += ok as usize;
    let tm = r.timings;
    t.phases[0] += tm.total_us.saturating_sub(tm.stomp_us + tm.verify_us);
    t.phases[1] += tm.stomp_us;
    t.phases[2] += tm.verify_us;
    if !ok {
        t.statuses.push(format!("{:?}", r.status));
    }
    if r.q.is_empty() {
        return;
    }
    let (wt, wr) = worst_deviation(chain, &r.q);
    t.worst_rot.push(wr);
    let within = wt <= T_T && wr <= T_R;
    let free = path_free(c, &r.q, chain.dof());
    if !ok && std::env::var("WHY").is_ok() {
        println!(
            "  {:?} seed {}: {:?}, cost {:.2} → {:.2} in {} iterations, worst e_t {wt:.3} e_r {wr:.3}, free {free}",
            req.algorithm,
            req.seed,
            r.status,
            r.cost_history.first().unwrap_or(&f64::NAN),
            r.cost_history.last().unwrap_or(&f64::NAN),
            r.iterations
        );
    }
    if ok && !(free && (within || req.algorithm != Algorithm::Ccstomp)) {
        println!(
            "  !! {:?} seed {} succeeded but recomputed e_t {wt:.3} e_r {wr:.3} free {free}",
            req.algorithm, req.seed
        );
    }
    t.ok_recomputed += (within && free && req.algorithm == Algorithm::Ccstomp
        || free && req.algorithm != Algorithm::Ccstomp) as usize;
}

fn kr210(seeds: usize, n: usize) {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let m = model(&chain);
    let deg = f64::to_radians;
    let start = vec![deg(-40.0), deg(-85.0), deg(95.0), 0.0, deg(80.0), 0.0];
    let mut goal = start.clone();
    goal[0] = deg(40.0);
    let (a, b) = (chain.fk(&start), chain.fk(&goal));
    let mid = (a.translation.vector + b.translation.vector) / 2.0;
    println!(
        "tool {:.3?} → {:.3?} ({:.2} m), box 0.3 m at {mid:.3?}",
        a.translation.vector,
        b.translation.vector,
        (b.translation.vector - a.translation.vector).norm()
    );
    let c = checker(&m, vec![cube(mid, 0.0, 0.15)]);
    assert!(c.is_valid(&start) && c.is_valid(&goal), "start/goal collide");
    if let Some(line) = line_joints(&chain, &start, &goal, n) {
        println!(
            "straight tool line by IK: collision-free {}",
            path_free(&c, &line, 6)
        );
    }
    println!(
        "| algorithm | succeeded | recomputed | wall ms median / p95 | CPU ms median / p95 | mean wall ms start / STOMP / re-check | p95 worst e_r rad | other statuses |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for alg in [Algorithm::Ccstomp, Algorithm::Stomp, Algorithm::RrtConnect] {
        let mut t = Tally::default();
        for seed in 0..seeds as u64 {
            run(&chain, &c, &request(&start, &goal, alg, seed, n), &mut t);
        }
        println!("{}", t.line(&format!("{alg:?}"), seeds));
    }
}

struct Family {
    name: &'static str,
    /// tool distance from the base axis (m), tool height (m)
    reach: (f64, f64),
    height: (f64, f64),
    /// straight tool line length (m)
    length: (f64, f64),
    /// box half edge (m)
    half: f64,
}

const FAMILIES: [Family; 3] = [
    Family {
        name: "kuka_kr210_r2700_extra",
        reach: (1.2, 2.4),
        height: (0.3, 2.0),
        length: (1.0, 2.2),
        half: 0.15,
    },
    Family {
        name: "abb_irb4600_60_205",
        reach: (0.9, 1.9),
        height: (0.3, 1.8),
        length: (0.8, 1.8),
        half: 0.15,
    },
    Family {
        name: "franka_panda",
        reach: (0.35, 0.75),
        height: (0.15, 0.9),
        length: (0.4, 0.8),
        half: 0.06,
    },
];

/// A start, a goal and the box: the start drawn in the limits with the tool
/// in the reach band, the goal the start with the base turned 0.6–1.6 rad
/// and every other joint moved by up to ±0.3 rad; kept when the straight tool
/// line solves by IK collision-free without the box, the box (random yaw)
/// centred at s ∈ [0.35, 0.65] on it leaves start and goal free and blocks
/// that line.
fn problem(
    chain: &Chain,
    m: &(Arc<RobotModel>, AllowedCollisions),
    f: &Family,
    rng: &mut ChaCha8Rng,
    n: usize,
) -> (Vec<f64>, Vec<f64>, SceneChecker) {
    let lim: Vec<(f64, f64)> = chain.limits().collect();
    let empty = checker(m, vec![]);
    let down = std::env::var("DOWN").ok().and_then(|v| v.parse::<f64>().ok());
    for _ in 0..1_000_000 {
        let start: Vec<f64> = lim
            .iter()
            .map(|&(lo, hi)| rng.random_range(lo.max(-3.0) + 0.1..hi.min(3.0) - 0.1))
            .collect();
        let start_pose = chain.fk(&start);
        let p = start_pose.translation.vector;
        // `DOWN=<deg>`: the tool's z axis within that angle of straight down
        if let Some(max) = down
            && (start_pose.rotation * Vector3::z()).angle(&-Vector3::z()) > max.to_radians()
        {
            continue;
        }
        let rxy = p.xy().norm();
        if !(f.reach.0..f.reach.1).contains(&rxy) || !(f.height.0..f.height.1).contains(&p.z) {
            continue;
        }
        let turn = rng.random_range(0.6..1.6) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let goal: Vec<f64> = start
            .iter()
            .zip(&lim)
            .enumerate()
            .map(|(j, (&v, &(lo, hi)))| {
                let d = if j == 0 { turn } else { rng.random_range(-0.3..0.3) };
                (v + d).clamp(lo + 0.05, hi - 0.05)
            })
            .collect();
        let g = chain.fk(&goal).translation.vector;
        let len = (g - p).norm();
        if !(f.length.0..f.length.1).contains(&len) || g.z < f.height.0 {
            continue;
        }
        if !empty.is_valid(&start) || !empty.is_valid(&goal) {
            continue;
        }
        let Some(line) = line_joints(chain, &start, &goal, n) else {
            continue;
        };
        if !path_free(&empty, &line, chain.dof()) {
            continue;
        }
        let s = rng.random_range(0.35..0.65);
        let centre = p.lerp(&g, s);
        let yaw = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let c = checker(m, vec![cube(centre, yaw, f.half)]);
        if c.is_valid(&start) && c.is_valid(&goal) && !path_free(&c, &line, chain.dof()) {
            return (start, goal, c);
        }
    }
    panic!("{}: no problem in 1,000,000 draws", f.name);
}

fn bench(problems: usize, n: usize) {
    println!(
        "| robot | algorithm | succeeded | within 1 m / 0.2 rad and free (recomputed) | wall ms median / p95 | CPU ms median / p95 | mean wall ms start / STOMP / re-check | p95 worst e_r rad | other statuses |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut all_ok, mut all) = (0, 0);
    let mut all_times = Vec::new();
    let mut all_cpu = Vec::new();
    let only = std::env::var("ROBOT").ok();
    for f in FAMILIES
        .iter()
        .filter(|f| only.as_ref().is_none_or(|o| f.name.contains(o.as_str())))
    {
        let chain = builtin_chain(f.name).unwrap();
        let m = model(&chain);
        let mut rng = ChaCha8Rng::seed_from_u64(2026);
        let cases: Vec<_> = (0..problems)
            .map(|_| problem(&chain, &m, f, &mut rng, n))
            .collect();
        let algs: &[Algorithm] = if std::env::var("ALL").is_ok() {
            &[Algorithm::Ccstomp, Algorithm::Stomp, Algorithm::RrtConnect]
        } else {
            &[Algorithm::Ccstomp]
        };
        for &alg in algs {
            let mut t = Tally::default();
            for (k, (s, g, c)) in cases.iter().enumerate() {
                run(&chain, c, &request(s, g, alg, k as u64, n), &mut t);
            }
            if alg == Algorithm::Ccstomp {
                all_ok += t.ok_recomputed;
                all += problems;
                all_times.extend_from_slice(&t.times);
                all_cpu.extend_from_slice(&t.cpu);
            }
            let short = f.name.split('_').take(2).collect::<Vec<_>>().join(" ");
            println!("{}", t.line(&format!("{short} | {alg:?}"), problems));
        }
    }
    println!(
        "CCSTOMP overall: {all_ok}/{all} ({:.1} %) within the tolerances and free; wall median {:.1} ms, p95 {:.1} ms; CPU median {:.1} ms, p95 {:.1} ms",
        100.0 * all_ok as f64 / all as f64,
        percentile(&mut all_times.clone(), 0.5),
        percentile(&mut all_times, 0.95),
        percentile(&mut all_cpu.clone(), 0.5),
        percentile(&mut all_cpu, 0.95)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize, default: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(default);
    match args.get(1).map(String::as_str) {
        Some("kr210") => kr210(num(2, 10), num(3, 40)),
        Some("bench") => bench(num(2, 50), num(3, 40)),
        _ => eprintln!("usage: ccstomp_detour kr210 [seeds] [timesteps] | bench [problems] [timesteps]"),
    }
}
