//! MotionBenchMaker Panda runner: per problem set, how many
//! problems are valid for our geometry, how many RRT-Connect solves, how long
//! planning takes and how long the paths are — with every returned path
//! re-checked independently.
//!
//! ```text
//! tar xjf ../shared/bench/mbm/panda_problems.tar.bz2 -C target/mbm
//! cargo build --release -p kinplan-core --example mbm_bench
//! target/release/examples/mbm_bench target/mbm/problems [--passes 10] [--stomp 10]
//!     [--clamp-fingers] [--padded] [--set NAME] [--problems 3,17,42] [--state-cost N] [--unbatched]
//!     [--out target/mbm_bench]
//! ```
//!
//! `--state-cost N` also times the state check alone in every scene: `N`
//! states drawn uniformly within the joint limits (ChaCha8, seed = problem
//! number), `is_valid` on each (limits, forward kinematics, scene and self
//! pairs), the whole loop timed once; reported as ns per state, median over
//! the scenes of a set, with the fraction of valid states; and the same
//! states through `states_valid` eight at a time (the batched check the
//! motion checks use; a batch stops at its first colliding state), per
//! state.
//!
//! `--states-from FILE` times `is_valid` on the states of `FILE` (rows of
//! seven little-endian f64) in the first selected problem's scene instead
//! of planning, the minimum of five passes over all states and over the
//! ones it finds free and in groups of eight that stop at their first
//! collision (as VAMP's blocks do), the same groups and the free states in
//! blocks of eight through the eight-lane check (`CheckerParams::batched`),
//! and counts the states whose verdict differs from
//! `FILE.vamp` (one byte per state, 1 = free), writes its own verdicts to
//! `FILE.ours` (the same form), then prints one JSON line
//! and stops (`benches/mbm/state_cost_vamp.py` runs it beside VAMP).
//!
//! The states of motions are checked eight at a time through the sphere
//! model in `f32` vector lanes, and the pieces of padded motions offered to
//! it eight at a time (`CheckerParams::batched`, the default);
//! `--unbatched` checks one state and one piece at a time (`--batched` is
//! the default, kept for older scripts).
//!
//! `--problems` keeps only the listed problem numbers (say the band around a
//! set's median, to profile what the median measures).
//!
//! Per problem: the scene is parsed and built once (`build` time, apart from
//! planning); start and goal are checked with the state checker — a problem
//! with either invalid counts as "not valid" and is not planned; RRT-Connect
//! runs with [`RrtParams::default`] and seed = problem number (1..=100), a
//! 10 s deadline as a guard. Planning time is the search
//! ([`RrtOutcome::search_ns`]: straight-line test and tree growth, the
//! quantity VAMP's `result.nanoseconds` measures); shortcutting is timed
//! apart. With `--passes N` every problem is planned N times (same seed, so
//! the same path) and the per-problem median is the "robust" time, as the
//! VAMP anchor script does; the per-problem minimum is written too
//! (`search_min_us`, `search_min_median_us`), the least disturbed by other
//! load when two builds are compared on a shared host.
//!
//! Independent check: every returned path is walked segment by segment at
//! ≤ 0.01 rad per joint (all `ceil(span/0.01)` steps in order, ends
//! included) with the state checker; a path failing anywhere counts as not
//! solved. Path length: Σ Euclidean joint-space segment lengths (rad).
//!
//! `--stomp K` also plans the first K valid problems per set with STOMP and
//! CCSTOMP through [`plan`] (MoveIt-default parameters, same seed, 10 s
//! deadline; CCSTOMP judged valid on collision only, its tolerance verdict
//! reported apart) and applies the same fine check.
//!
//! Writes `<out>.json` (per-set summaries) and `<out>.csv` (one row per
//! problem).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use kinplan_core::collision::{
    CheckerParams, MotionCheck, PadVerdict, SceneChecker, SceneGeometry, SceneLimits, StateChecker,
    parse_joint_request, parse_planning_scene,
};
use kinplan_core::plan::{
    Algorithm, Goal, PlanControl, PlanRequest, PlanStatus, RrtOutcome, RrtParams, RrtStop, plan, rrt_connect,
};
use kinplan_core::robot::{Chain, builtin_chain};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

const FINE: f64 = 0.01;
const DEADLINE: Duration = Duration::from_secs(10);

/// Every state along every segment of `path` at ≤ `step` per joint, in
/// order, both ends included — deliberately not the planner's bisection walk.
/// Returns whether all are valid and the deepest penetration (m, ≥ 0) among
/// the invalid ones (0 when the only failures are joint limits).
#[path = "common/mbm_panda.rs"]
mod mbm_panda;
use mbm_panda::{SETS, arm, model};

fn fine_check(checker: &SceneChecker, path: &[f64], dof: usize, step: f64) -> (bool, f64) {
    let rows: Vec<&[f64]> = path.chunks_exact(dof).collect();
    if rows.len() < 2 {
        return (false, 0.0);
    }
    let mut q = vec![0.0; dof];
    let (mut ok, mut depth) = (true, 0.0f64);
    for w in rows.windows(2) {
        let (a, b) = (w[0], w[1]);
        let span = a.iter().zip(b).map(|(x, y)| (y - x).abs()).fold(0.0, f64::max);
        let n = ((span / step).ceil() as usize).max(1);
        for i in 0..=n {
            let t = i as f64 / n as f64;
            for j in 0..dof {
                // the ends exactly: a + 1·(b − a) may round past a joint limit
                q[j] = if i == n { b[j] } else { a[j] + t * (b[j] - a[j]) };
            }
            if !checker.is_valid(&q) {
                ok = false;
                depth = depth.max(-checker.clearance(&q, 0.0));
            }
        }
    }
    (ok, depth)
}

fn path_length(path: &[f64], dof: usize) -> f64 {
    let rows: Vec<&[f64]> = path.chunks_exact(dof).collect();
    rows.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(w[1])
                .map(|(x, y)| (y - x) * (y - x))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}

/// Linear-interpolation percentile (numpy's default).
fn percentile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let x = p / 100.0 * (s.len() - 1) as f64;
    let (lo, hi) = (x.floor() as usize, x.ceil() as usize);
    s[lo] + (x - lo as f64) * (s[hi] - s[lo])
}

fn median(v: &[f64]) -> f64 {
    percentile(v, 50.0)
}

#[derive(Default)]
struct Row {
    problem: usize,
    build_us: f64,
    start_ok: bool,
    goal_ok: bool,
    solved: bool,
    fine_ok: bool,
    fine_depth_mm: f64,
    search_us: f64,
    search_robust_us: f64,
    /// Fastest of the passes: the least disturbed by other load on the
    /// machine, for comparing two builds on a shared host.
    search_min_us: f64,
    shortcut_us: f64,
    samples: usize,
    nodes: usize,
    /// States checked by search and shortcutting together.
    states: usize,
    /// Of those, the padded checks (pieces of conservative proofs).
    padded_states: usize,
    waypoints: usize,
    length: f64,
    stop: String,
    /// `is_valid` alone on random states: ns per state (NaN when not timed).
    state_ns: f64,
    /// Fraction of those states valid.
    state_valid: f64,
    /// Time per state of `states_valid` over batches of 4 states (ns).
    state_batch_ns: f64,
}

struct StompRow {
    set: String,
    problem: usize,
    algorithm: &'static str,
    status: PlanStatus,
    fine_ok: bool,
    violates: bool,
    total_ms: f64,
    length: f64,
}

struct Args {
    root: PathBuf,
    passes: usize,
    stomp: usize,
    clamp: bool,
    resolution: f64,
    shortcut_resolution: Option<f64>,
    padded: bool,
    /// `None`: the planner's default.
    shortcut_attempts: Option<usize>,
    /// Only this set (`None`: all).
    only_set: Option<String>,
    /// Only these problem numbers (`None`: all), e.g. a median band to profile.
    only_problems: Option<Vec<usize>>,
    /// Random states per scene for the state-check timing (0: none).
    state_cost: usize,
    /// Check motion states eight at a time through the sphere model (`f32` lanes).
    batched: bool,
    /// Time the state check on these states (and compare with VAMP's verdicts).
    states_from: Option<PathBuf>,
    out: PathBuf,
}

fn args() -> Result<Args, String> {
    let usage = "usage: mbm_bench <problems dir> [--passes N] [--stomp K] [--clamp-fingers] [--resolution RAD] [--shortcut-resolution RAD] [--padded] [--shortcut-attempts N] [--set NAME] [--problems N,N,...] [--state-cost N] [--states-from FILE] [--unbatched] [--out PREFIX]";
    let mut it = std::env::args().skip(1);
    let mut a = Args {
        root: PathBuf::new(),
        passes: 1,
        stomp: 0,
        clamp: false,
        resolution: CheckerParams::default().motion_resolution,
        shortcut_resolution: None,
        padded: false,
        shortcut_attempts: None,
        only_set: None,
        only_problems: None,
        state_cost: 0,
        batched: true,
        states_from: None,
        out: PathBuf::from("target/mbm_bench"),
    };
    let mut root = None;
    while let Some(x) = it.next() {
        let mut num = |name: &str| -> Result<usize, String> {
            it.next()
                .and_then(|v| v.parse().ok())
                .ok_or(format!("{name} needs a number; {usage}"))
        };
        match x.as_str() {
            "--passes" => a.passes = num("--passes")?.max(1),
            "--stomp" => a.stomp = num("--stomp")?,
            "--state-cost" => a.state_cost = num("--state-cost")?,
            "--batched" => a.batched = true,
            "--unbatched" => a.batched = false,
            "--clamp-fingers" => a.clamp = true,
            "--padded" => a.padded = true,
            "--shortcut-attempts" => a.shortcut_attempts = Some(num("--shortcut-attempts")?),
            "--shortcut-resolution" => {
                a.shortcut_resolution = Some(
                    it.next()
                        .and_then(|v| v.parse().ok())
                        .ok_or(format!("--shortcut-resolution needs a number; {usage}"))?,
                )
            }
            "--resolution" => {
                a.resolution = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .ok_or(format!("--resolution needs a number; {usage}"))?
            }
            "--set" => a.only_set = Some(it.next().ok_or(usage)?),
            "--problems" => {
                let list = it.next().ok_or(usage)?;
                let numbers: Result<Vec<usize>, _> = list.split(',').map(str::parse).collect();
                a.only_problems =
                    Some(numbers.map_err(|_| format!("--problems needs numbers like 3,17,42; {usage}"))?);
            }
            "--out" => a.out = PathBuf::from(it.next().ok_or(usage)?),
            "--states-from" => a.states_from = Some(PathBuf::from(it.next().ok_or(usage)?)),
            _ if root.is_none() && !x.starts_with("--") => root = Some(PathBuf::from(x)),
            _ => return Err(usage.into()),
        }
    }
    a.root = root.ok_or(usage)?;
    Ok(a)
}

/// The scene checker with a count of the states it was asked about.
struct Counting<'a> {
    inner: &'a SceneChecker,
    states: AtomicUsize,
    padded: AtomicUsize,
}

impl StateChecker for Counting<'_> {
    fn dof(&self) -> usize {
        self.inner.dof()
    }
    fn is_valid(&self, q: &[f64]) -> bool {
        self.states.fetch_add(1, Ordering::Relaxed);
        self.inner.is_valid(q)
    }
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
        self.inner.clearance(q, max_distance)
    }
    fn padded_valid(&self, q: &[f64], half_step: &[f64]) -> Option<bool> {
        self.states.fetch_add(1, Ordering::Relaxed);
        self.padded.fetch_add(1, Ordering::Relaxed);
        self.inner.padded_valid(q, half_step)
    }
    fn padded_verdict(&self, q: &[f64], half_step: &[f64]) -> Option<PadVerdict> {
        self.states.fetch_add(1, Ordering::Relaxed);
        self.padded.fetch_add(1, Ordering::Relaxed);
        self.inner.padded_verdict(q, half_step)
    }
    // forwarded, so the counted run checks exactly what the timed run checks
    fn padded_verdict_sparing(&self, q: &[f64], half_step: &[f64], proved: &mut u64) -> Option<PadVerdict> {
        self.states.fetch_add(1, Ordering::Relaxed);
        self.padded.fetch_add(1, Ordering::Relaxed);
        self.inner.padded_verdict_sparing(q, half_step, proved)
    }
    // a piece the batch proves is counted like one the one-piece check does
    fn padded_free_batch(&self, rows: &[f64], half_step: &[f64], cleared: &mut [u64]) -> Option<u32> {
        let free = self.inner.padded_free_batch(rows, half_step, cleared)?;
        let proved = free.count_ones() as usize;
        self.states.fetch_add(proved, Ordering::Relaxed);
        self.padded.fetch_add(proved, Ordering::Relaxed);
        Some(free)
    }
    fn motion_check(&self) -> MotionCheck {
        self.inner.motion_check()
    }
}

fn run_rrt<C: StateChecker>(
    chain: &Chain,
    checker: &C,
    s: &[f64],
    g: &[f64],
    seed: u64,
    params: &RrtParams,
) -> RrtOutcome {
    rrt_connect(
        chain,
        checker,
        s,
        g,
        params,
        seed,
        kinplan_core::Deadline::after(DEADLINE),
    )
    .expect("valid inputs")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = args()?;
    let chain = builtin_chain("franka_panda_hand")?;
    let dof = chain.dof();
    let mut cache = BTreeMap::new();
    let mut rows_by_set: Vec<(&str, Vec<Row>)> = Vec::new();
    let mut stomp_rows: Vec<StompRow> = Vec::new();
    let wall = Instant::now();
    let rrt = RrtParams {
        shortcut_resolution: a.shortcut_resolution,
        shortcut_attempts: a
            .shortcut_attempts
            .unwrap_or(RrtParams::default().shortcut_attempts),
        ..RrtParams::default()
    };
    // The self-collision pairs our checker tests, for the Python anchors
    // (they use the same pairs, so both sides answer the same question).
    {
        let (m, acm) = model(&chain, if a.clamp { 0.04 } else { 0.065 }, &mut cache);
        let names: Vec<&str> = m.body_names().collect();
        let pairs: Vec<[&str; 2]> = acm.checked_pairs().map(|(i, j)| [names[i], names[j]]).collect();
        let path = a.out.with_extension("acm.json");
        std::fs::write(
            &path,
            serde_json::to_string_pretty(&json!({"bodies": names, "checked_pairs": pairs}))?,
        )?;
    }
    for set in SETS {
        if a.only_set.as_ref().is_some_and(|only| only != set) {
            continue;
        }
        let dir = a.root.join(format!("{set}_panda"));
        let mut rows = Vec::new();
        let mut stomp_done = 0;
        for k in 1..=100usize {
            let scene_path = dir.join(format!("scene{k:04}.yaml"));
            let request_path = dir.join(format!("request{k:04}.yaml"));
            let wanted = a.only_problems.as_ref().is_none_or(|only| only.contains(&k));
            if !wanted || !Path::new(&scene_path).exists() {
                continue;
            }
            let scene_text = std::fs::read_to_string(&scene_path)?;
            let request = parse_joint_request(&std::fs::read_to_string(&request_path)?)?;
            let opening = request
                .start
                .iter()
                .find(|(n, _)| n == "panda_finger_joint1")
                .map_or(0.04, |(_, v)| *v);
            let opening = if a.clamp {
                opening.clamp(0.0, 0.04)
            } else {
                opening
            };
            let (model, acm) = model(&chain, opening, &mut cache);
            let t = Instant::now();
            let scene = parse_planning_scene(&scene_text, &SceneLimits::default())?;
            let world = Arc::new(SceneGeometry::build(&scene)?);
            let checker = SceneChecker::new(
                model,
                &acm,
                world,
                CheckerParams {
                    motion_resolution: a.resolution,
                    padded_motion: a.padded,
                    batched: a.batched,
                },
            )?;
            let build_us = t.elapsed().as_secs_f64() * 1e6;
            let start = arm(&request.start, &format!("{}: start", request_path.display()))?;
            let goal = arm(&request.goal, &format!("{}: goal", request_path.display()))?;
            let mut row = Row {
                problem: k,
                build_us,
                start_ok: checker.is_valid(&start),
                goal_ok: checker.is_valid(&goal),
                state_ns: f64::NAN,
                state_batch_ns: f64::NAN,
                ..Row::default()
            };
            if let Some(path) = &a.states_from {
                // the same scene checked state by state and in eight lanes,
                // one column each, whatever `--unbatched` says
                let with = |batched| {
                    let params = CheckerParams {
                        batched,
                        ..CheckerParams::default()
                    };
                    SceneChecker::new(checker.model().clone(), &acm, checker.world().clone(), params)
                };
                println!("{}", states_from(&with(false)?, &with(true)?, path, dof)?);
                return Ok(());
            }
            if a.state_cost > 0 {
                let mut rng = ChaCha8Rng::seed_from_u64(k as u64);
                let states: Vec<f64> = (0..a.state_cost)
                    .flat_map(|_| {
                        chain
                            .joints()
                            .iter()
                            .map(|j| rng.random_range(j.lower..=j.upper))
                            .collect::<Vec<_>>()
                    })
                    .collect();
                let t = Instant::now();
                let valid = states.chunks_exact(dof).filter(|q| checker.is_valid(q)).count();
                row.state_ns = t.elapsed().as_secs_f64() * 1e9 / a.state_cost as f64;
                row.state_valid = valid as f64 / a.state_cost as f64;
                // the same states handed over eight at a time, as the motion
                // checks do (a batch stops at its first colliding state)
                let t = Instant::now();
                let batches = states.chunks(8 * dof).filter(|g| checker.states_valid(g)).count();
                row.state_batch_ns = t.elapsed().as_secs_f64() * 1e9 / a.state_cost as f64;
                std::hint::black_box(batches);
            }
            if row.start_ok && row.goal_ok {
                let seed = k as u64;
                // The counted run is an extra one, not timed: the counter's
                // atomic add would be charged to the planner otherwise.
                let counting = Counting {
                    inner: &checker,
                    states: AtomicUsize::new(0),
                    padded: AtomicUsize::new(0),
                };
                let counted = run_rrt(&chain, &counting, &start, &goal, seed, &rrt);
                let first = run_rrt(&chain, &checker, &start, &goal, seed, &rrt);
                assert_eq!(
                    counted.path, first.path,
                    "{set} {k}: not deterministic for a seed"
                );
                row.states = counting.states.load(Ordering::Relaxed);
                row.padded_states = counting.padded.load(Ordering::Relaxed);
                let mut times = vec![first.search_ns as f64 / 1e3];
                for _ in 1..a.passes {
                    let again = run_rrt(&chain, &checker, &start, &goal, seed, &rrt);
                    assert_eq!(again.path, first.path, "{set} {k}: not deterministic for a seed");
                    times.push(again.search_ns as f64 / 1e3);
                }
                row.search_us = times[0];
                row.search_robust_us = median(&times);
                row.search_min_us = times.iter().copied().fold(f64::INFINITY, f64::min);
                row.shortcut_us = first.shortcut_ns as f64 / 1e3;
                row.samples = first.samples;
                row.nodes = first.nodes;
                row.stop = format!("{:?}", first.stop);
                if first.stop == RrtStop::Connected {
                    row.waypoints = first.path.len() / dof;
                    row.length = path_length(&first.path, dof);
                    let (ok, depth) = fine_check(&checker, &first.path, dof, FINE);
                    row.fine_depth_mm = depth * 1e3;
                    row.fine_ok = ok
                        && first.path[..dof] == start[..]
                        && first.path[first.path.len() - dof..] == goal[..];
                    row.solved = row.fine_ok;
                }
                if stomp_done < a.stomp {
                    stomp_done += 1;
                    for (algorithm, name) in [(Algorithm::Stomp, "stomp"), (Algorithm::Ccstomp, "ccstomp")] {
                        let req = PlanRequest {
                            start: start.clone(),
                            goal: Goal::Joints(goal.clone()),
                            algorithm,
                            seed,
                            ..PlanRequest::default()
                        };
                        let ctl = PlanControl {
                            deadline: kinplan_core::Deadline::after(DEADLINE),
                            ..PlanControl::default()
                        };
                        let t = Instant::now();
                        let r = plan(&chain, &checker, &req, ctl)?;
                        let total_ms = t.elapsed().as_secs_f64() * 1e3;
                        let fine_ok = r.q.len() >= 2 * dof && fine_check(&checker, &r.q, dof, FINE).0;
                        stomp_rows.push(StompRow {
                            set: set.to_string(),
                            problem: k,
                            algorithm: name,
                            status: r.status,
                            fine_ok,
                            violates: r.violates_tolerance,
                            total_ms,
                            length: path_length(&r.q, dof),
                        });
                    }
                }
            }
            rows.push(row);
        }
        eprintln!(
            "{set}: {} problems done ({:.1} s)",
            rows.len(),
            wall.elapsed().as_secs_f64()
        );
        rows_by_set.push((set, rows));
    }

    // Per-set summary.
    println!(
        "RRT-Connect (range {}, {} shortcut attempts; seed = problem number), \
         motion resolution {} rad{}, shortcut resolution {:?}, passes = {}, fingers {}",
        rrt.range,
        rrt.shortcut_attempts,
        a.resolution,
        if a.padded { " padded (conservative)" } else { "" },
        a.shortcut_resolution,
        a.passes,
        if a.clamp {
            "clamped to 0.04 m"
        } else {
            "as requested"
        }
    );
    println!(
        "| set | problems | valid | solved | median / p95 search µs | robust median µs | median shortcut µs | median build µs | median length rad | fine-check failures |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut sets_json = serde_json::Map::new();
    let mut all_search = Vec::new();
    let (mut all_valid, mut all_solved, mut all_n) = (0, 0, 0);
    let mut csv = std::fs::File::create(a.out.with_extension("csv"))?;
    writeln!(
        csv,
        "set,problem,build_us,start_valid,goal_valid,stop,solved,fine_valid,fine_depth_mm,search_us,search_robust_us,shortcut_us,samples,nodes,states_checked,waypoints,length_rad,padded_states,search_min_us"
    )?;
    for (set, rows) in &rows_by_set {
        for r in rows {
            writeln!(
                csv,
                "{set},{},{:.2},{},{},{},{},{},{:.3},{:.3},{:.3},{:.3},{},{},{},{},{:.6},{},{:.3}",
                r.problem,
                r.build_us,
                r.start_ok,
                r.goal_ok,
                r.stop,
                r.solved,
                r.fine_ok,
                r.fine_depth_mm,
                r.search_us,
                r.search_robust_us,
                r.shortcut_us,
                r.samples,
                r.nodes,
                r.states,
                r.waypoints,
                r.length,
                r.padded_states,
                r.search_min_us
            )?;
        }
        let valid: Vec<&Row> = rows.iter().filter(|r| r.start_ok && r.goal_ok).collect();
        let solved: Vec<&Row> = valid.iter().copied().filter(|r| r.solved).collect();
        let fine_fail = valid
            .iter()
            .filter(|r| r.stop == "Connected" && !r.fine_ok)
            .count();
        let depths: Vec<f64> = valid
            .iter()
            .filter(|r| r.stop == "Connected" && !r.fine_ok)
            .map(|r| r.fine_depth_mm)
            .collect();
        let t1: Vec<f64> = solved.iter().map(|r| r.search_us).collect();
        let tr: Vec<f64> = solved.iter().map(|r| r.search_robust_us).collect();
        let tmin: Vec<f64> = solved.iter().map(|r| r.search_min_us).collect();
        let sc: Vec<f64> = solved.iter().map(|r| r.shortcut_us).collect();
        let bu: Vec<f64> = rows.iter().map(|r| r.build_us).collect();
        let len: Vec<f64> = solved.iter().map(|r| r.length).collect();
        all_search.extend_from_slice(&t1);
        all_valid += valid.len();
        all_solved += solved.len();
        all_n += rows.len();
        println!(
            "| {set} | {} | {} | {} | {:.1} / {:.1} | {:.1} | {:.1} | {:.1} | {:.3} | {fine_fail} (depth median {:.1}, max {:.1} mm) |",
            rows.len(),
            valid.len(),
            solved.len(),
            median(&t1),
            percentile(&t1, 95.0),
            median(&tr),
            median(&sc),
            median(&bu),
            median(&len),
            median(&depths),
            percentile(&depths, 100.0)
        );
        sets_json.insert(
            set.to_string(),
            json!({
                "problems": rows.len(),
                "invalid_start": rows.iter().filter(|r| !r.start_ok).count(),
                "invalid_goal": rows.iter().filter(|r| !r.goal_ok).count(),
                "valid": valid.len(),
                "solved": solved.len(),
                "fine_check_failures": fine_fail,
                "fine_check_depth_median_mm": median(&depths),
                "fine_check_depth_max_mm": percentile(&depths, 100.0),
                "search_median_us": median(&t1),
                "search_p95_us": percentile(&t1, 95.0),
                "search_robust_median_us": median(&tr),
                "search_robust_p95_us": percentile(&tr, 95.0),
                "search_min_median_us": median(&tmin),
                "shortcut_median_us": median(&sc),
                "build_median_us": median(&bu),
                "length_median_rad": median(&len),
                "states_checked_median": median(&solved.iter().map(|r| r.states as f64).collect::<Vec<_>>()),
                "us_per_state_median": median(&solved.iter().map(|r| (r.search_us + r.shortcut_us) / r.states.max(1) as f64).collect::<Vec<_>>()),
                "samples_median": median(&solved.iter().map(|r| r.samples as f64).collect::<Vec<_>>()),
                "state_ns_median": median(&rows.iter().map(|r| r.state_ns).filter(|v| v.is_finite()).collect::<Vec<_>>()),
                "state_batch_ns_median": median(&rows.iter().map(|r| r.state_batch_ns).filter(|v| v.is_finite()).collect::<Vec<_>>()),
                "state_valid_median": median(&rows.iter().filter(|r| r.state_ns.is_finite()).map(|r| r.state_valid).collect::<Vec<_>>()),
            }),
        );
    }
    println!(
        "| all | {all_n} | {all_valid} | {all_solved} | {:.1} / {:.1} | | | | | |",
        median(&all_search),
        percentile(&all_search, 95.0)
    );
    let mut stomp_json = Vec::new();
    if !stomp_rows.is_empty() {
        println!(
            "\nSTOMP / CCSTOMP (first {} valid problems per set, plan(), MoveIt defaults)",
            a.stomp
        );
        println!(
            "| set | algorithm | planned | succeeded | fine-valid | CCSTOMP beyond tolerance | median / p95 ms | median length rad |"
        );
        println!("|---|---|---|---|---|---|---|---|");
        for set in SETS {
            for alg in ["stomp", "ccstomp"] {
                let r: Vec<&StompRow> = stomp_rows
                    .iter()
                    .filter(|r| r.set == set && r.algorithm == alg)
                    .collect();
                if r.is_empty() {
                    continue;
                }
                let ms: Vec<f64> = r.iter().map(|r| r.total_ms).collect();
                let ok: Vec<f64> = r.iter().filter(|r| r.fine_ok).map(|r| r.length).collect();
                let succeeded = r.iter().filter(|r| r.status == PlanStatus::Succeeded).count();
                let violates = r.iter().filter(|r| r.violates).count();
                println!(
                    "| {set} | {alg} | {} | {succeeded} | {} | {violates} | {:.1} / {:.1} | {:.3} |",
                    r.len(),
                    ok.len(),
                    median(&ms),
                    percentile(&ms, 95.0),
                    median(&ok)
                );
                stomp_json.push(json!({
                    "set": set, "algorithm": alg, "planned": r.len(), "succeeded": succeeded,
                    "fine_valid": ok.len(), "violates_tolerance": violates,
                    "median_ms": median(&ms), "p95_ms": percentile(&ms, 95.0),
                    "length_median_rad": median(&ok),
                    "problems": r.iter().map(|r| json!({"problem": r.problem, "status": format!("{:?}", r.status), "fine_valid": r.fine_ok, "ms": r.total_ms})).collect::<Vec<_>>(),
                }));
            }
        }
    }
    let out = json!({
        "planner": "kinplan RRT-Connect",
        "params": {"range": rrt.range, "shortcut_attempts": rrt.shortcut_attempts,
                   "motion_resolution": a.resolution, "shortcut_resolution": a.shortcut_resolution, "fine_check_step": FINE},
        "passes": a.passes,
        "fingers_clamped": a.clamp,
        "sets": sets_json,
        "all": {"problems": all_n, "valid": all_valid, "solved": all_solved,
                "search_median_us": median(&all_search), "search_p95_us": percentile(&all_search, 95.0)},
        "stomp": stomp_json,
        "wall_s": wall.elapsed().as_secs_f64(),
    });
    std::fs::write(a.out.with_extension("json"), serde_json::to_string_pretty(&out)?)?;
    eprintln!(
        "wrote {} and {}",
        a.out.with_extension("json").display(),
        a.out.with_extension("csv").display()
    );
    Ok(())
}

/// `--states-from`: our state check timed on the states of `path`, beside
/// the verdicts VAMP's harness wrote to `path.vamp`; our verdicts are written
/// to `path.ours` (one byte per state, 1 = free) for the coal comparison.
fn states_from(
    checker: &SceneChecker,
    lanes: &SceneChecker,
    path: &Path,
    dof: usize,
) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path)?;
    let states: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("eight bytes")))
        .collect();
    let beside = |ext: &str| PathBuf::from(format!("{}.{ext}", path.display()));
    let vamp = std::fs::read(beside("vamp"))?;
    let n = states.len() / dof;
    if vamp.len() != n {
        return Err(format!("{}: {} verdicts for {n} states", path.display(), vamp.len()).into());
    }
    let ours: Vec<bool> = states.chunks_exact(dof).map(|q| checker.is_valid(q)).collect();
    std::fs::write(
        beside("ours"),
        ours.iter().map(|&v| u8::from(v)).collect::<Vec<u8>>(),
    )?;
    let free: Vec<f64> = states
        .chunks_exact(dof)
        .zip(&ours)
        .filter(|(_, v)| **v)
        .flat_map(|(q, _)| q.iter().copied())
        .collect();
    let time = |rows: &[f64]| -> f64 {
        (0..5)
            .map(|_| {
                let t = Instant::now();
                let valid = rows.chunks_exact(dof).filter(|q| checker.is_valid(q)).count();
                std::hint::black_box(valid);
                t.elapsed().as_secs_f64() * 1e9 / (rows.len() / dof).max(1) as f64
            })
            .fold(f64::INFINITY, f64::min)
    };
    // groups of eight stopping at their first collision, as VAMP's blocks
    let groups = |checker: &SceneChecker, rows: &[f64]| -> f64 {
        (0..5)
            .map(|_| {
                let t = Instant::now();
                let valid = rows.chunks(8 * dof).filter(|g| checker.states_valid(g)).count();
                std::hint::black_box(valid);
                t.elapsed().as_secs_f64() * 1e9 / (rows.len() / dof).max(1) as f64
            })
            .fold(f64::INFINITY, f64::min)
    };
    let lanes_ok = free.chunks(8 * dof).all(|g| lanes.states_valid(g));
    if !lanes_ok {
        return Err("the eight-lane check refused a free state".into());
    }
    Ok(json!({
        "ours_ns": time(&states),
        "ours_groups_ns": groups(checker, &states),
        "ours_lanes_groups_ns": groups(lanes, &states),
        "ours_lanes_free_ns": groups(lanes, &free),
        "ours_free_ns": time(&free),
        "ours_free": free.len() / dof,
        "differ": ours.iter().zip(&vamp).filter(|(o, v)| **o != (**v == 1)).count(),
    }))
}
