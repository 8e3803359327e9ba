//! The exploration experiments of S0 §5.2–5.3 with kinplan's loop
//! (docs/exploration.md#the-exploration-loop): the IRB 4600 with a simulated Kinect v2 explores the
//! reference cells.
//!
//! - `scene <open|walled>`: one run, printed per iteration.
//! - `tab53 [seeds]`: S0 Tab. 5.3 — weight sets on the open cell
//!   (IG1_T0_R0, IG0_T1_R0, IG0_T0_R1, IG1_T1_R1) and the walled cell
//!   (IG1_T0_R0, IG0_T1_R0, IG1_T025_R01, IG1_T05_R01): iterations, final
//!   known ratio, JD, CPC, CD, OC, RDM sums (mean ± sd over seeds); the
//!   known ratio per iteration goes to `target/explore_known_ratio.csv`.
//!   Seed k runs on the cell variant built with seed k + 1 (other clutter).
//! - `tab54 [seeds]`: S0 Tab. 5.4/5.5 — the open cell explored with
//!   RRT-Connect, STOMP and CCSTOMP: OC and CD mean, variance and sum per
//!   trajectory; per-trajectory values to `target/explore_planners.csv`.
//!
//! - `waste [seeds]`: the open and walled cells built with seeds 1..=seeds,
//!   15 iterations each with RRT-Connect and CCSTOMP, S0's occlusion-blind
//!   choice beside the visibility check in the same run: wasted moves
//!   (views reached whose scan added nothing), failures, final known ratio,
//!   why the loop stopped.
//!
//! Usage: cargo run --release -p kinplan-core --example explore_s0 -- tab53 5

use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

use kinplan_core::collision::{AcmParams, AllowedCollisions, RobotModel, Scene, SceneGeometry, SceneLimits};
use kinplan_core::explore::{
    ExploreControl, ExploreOutcome, ExploreParams, ExploreStep, ExploreWorld, ReferenceScene, explore,
    s0_open_cell, s0_walled_cell,
};
use kinplan_core::nbv::Weights;
use kinplan_core::plan::Algorithm;
use kinplan_core::robot::builtin_chain;

struct Setup {
    chain: Arc<kinplan_core::robot::Chain>,
    model: Arc<RobotModel>,
    acm: AllowedCollisions,
}

fn setup() -> Setup {
    let chain = builtin_chain("abb_irb4600_60_205").expect("robot");
    let model = Arc::new(RobotModel::new(chain.clone()).expect("model"));
    let acm = AllowedCollisions::sampled(&model, &AcmParams::default()).expect("acm");
    Setup { chain, model, acm }
}

fn run(
    s: &Setup,
    scene: &ReferenceScene,
    weights: Weights,
    algorithm: Algorithm,
    seed: u64,
    mut on_step: impl FnMut(&ExploreStep),
) -> ExploreOutcome {
    let truth = Arc::new(
        SceneGeometry::build(&Scene::new(scene.obstacles.clone(), &SceneLimits::default()).expect("scene"))
            .expect("geometry"),
    );
    let world = ExploreWorld {
        chain: &s.chain,
        model: &s.model,
        acm: &s.acm,
        truth: &truth,
    };
    let mut p = ExploreParams::new(scene.region, s.chain.dof());
    p.nbv.weights = weights;
    p.plan.algorithm = algorithm;
    p.seed = seed;
    if let Ok(v) = std::env::var("STANDOFF") {
        p.nbv.standoff = v.parse().expect("STANDOFF");
    }
    if let Ok(v) = std::env::var("CPI") {
        p.candidates_per_iteration = v.parse().expect("CPI");
    }
    if let Ok(v) = std::env::var("PENALTY") {
        p.nbv.failure_penalty = v.parse().expect("PENALTY");
    }
    if let Ok(v) = std::env::var("IK_RESTARTS") {
        p.nbv.ik.max_restarts = v.parse().expect("IK_RESTARTS");
        p.nbv.ik.time_budget = Some(std::time::Duration::from_millis(100));
    }
    if std::env::var("RAYS").is_ok() {
        p.nbv.gain = kinplan_core::nbv::GainMethod::Rays { fraction: 0.25 };
    }
    if std::env::var("BLIND").is_ok() {
        p.visibility = None;
    }
    if let Ok(v) = std::env::var("MAX_ITER") {
        p.stop.max_iterations = v.parse().expect("MAX_ITER");
    }
    let ctl = ExploreControl {
        on_step: Some(&mut on_step),
        ..ExploreControl::default()
    };
    explore(&world, &scene.start, &p, ctl).expect("explore")
}

fn weights(name: &str) -> Weights {
    let (w_i, w_d, w_r) = match name {
        "IG1_T0_R0" => (1.0, 0.0, 0.0),
        "IG0_T1_R0" => (0.0, 1.0, 0.0),
        "IG0_T0_R1" => (0.0, 0.0, 1.0),
        "IG1_T1_R1" => (1.0, 1.0, 1.0),
        "IG1_T025_R01" => (1.0, 0.25, 0.1),
        "IG1_T05_R01" => (1.0, 0.5, 0.1),
        _ => panic!("unknown weight set {name}"),
    };
    Weights { w_i, w_d, w_r }
}

fn scene_named(name: &str, seed: u64) -> ReferenceScene {
    match name {
        "open" => s0_open_cell(seed),
        "walled" => s0_walled_cell(seed),
        _ => panic!("scene is open or walled"),
    }
}

fn one(name: &str) {
    let s = setup();
    let mut scene = scene_named(name, 1);
    if let Ok(v) = std::env::var("START") {
        scene.start = v.split(',').map(|x| x.parse().expect("START")).collect();
        let cam = s.chain.fk(&scene.start);
        println!("tool at {:.2?}", cam.translation.vector);
    }
    let algorithm = match std::env::var("PLANNER").as_deref() {
        Ok("rrt") => Algorithm::RrtConnect,
        Ok("stomp") => Algorithm::Stomp,
        _ => Algorithm::Ccstomp,
    };
    let w = weights(&std::env::var("WEIGHTS").unwrap_or_else(|_| "IG1_T025_R01".into()));
    let out = run(&s, &scene, w, algorithm, 1, |st| {
        let v = st.view.as_ref();
        println!(
            "it {:2} known {:.3} cand {} fail {} f {:.3} Ig {:.3} | nbv {:.0} ms plan {:.0} ms sense {:.0} ms insert {:.0} ms | CD {:.2} OC {:.2}{}",
            st.iteration,
            st.known_ratio,
            st.candidates,
            st.failures.len(),
            v.map_or(f64::NAN, |v| v.utility),
            v.map_or(f64::NAN, |v| v.ig),
            st.times.nbv_us as f64 / 1e3,
            st.times.plan_us as f64 / 1e3,
            st.times.sense_us as f64 / 1e3,
            st.times.insert_us as f64 / 1e3,
            st.motion.as_ref().map_or(f64::NAN, |m| m.criteria.cd),
            st.motion.as_ref().map_or(f64::NAN, |m| m.criteria.oc),
            if st.motion.as_ref().is_some_and(|m| m.hits_truth) {
                " HITS TRUTH"
            } else {
                ""
            },
        );
        for (p, why) in &st.failures {
            println!(
                "      failed view at ({:.2}, {:.2}, {:.2}): {why:?}",
                p.x, p.y, p.z
            );
        }
    });
    println!(
        "{}: {:?} after {} iterations; known {:.3} (initial {:.3}) of {} observable cells; failures {}, truth hits {}, scans {}, {:.2} s; JD {:.1} CPC {:.1} CD {:.1} OC {:.1} RDM {:.1}",
        scene.name,
        out.status,
        out.iterations,
        out.known_ratio,
        out.initial_known_ratio,
        out.observable_cells,
        out.failures,
        out.truth_hits,
        out.scans,
        out.elapsed_us as f64 / 1e6,
        out.totals.jd,
        out.totals.cpc,
        out.totals.cd,
        out.totals.oc,
        out.totals.rdm
    );
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

fn tab53(seeds: u64) {
    let s = setup();
    let sets = [
        ("open", ["IG1_T0_R0", "IG0_T1_R0", "IG0_T0_R1", "IG1_T1_R1"]),
        (
            "walled",
            ["IG1_T0_R0", "IG0_T1_R0", "IG1_T025_R01", "IG1_T05_R01"],
        ),
    ];
    let mut csv = String::from("scene,weights,seed,iteration,known_ratio\n");
    println!(
        "| cell | weights | iterations | initial known | final known | status | JD rad | CPC | CD m | OC rad | RDM m | wall s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (scene_name, names) in sets {
        for name in names {
            let mut cols: Vec<Vec<f64>> = vec![Vec::new(); 10];
            let mut statuses = Vec::new();
            for seed in 0..seeds {
                // each seed is another variant of the cell (clutter sizes and places)
                let scene = scene_named(scene_name, seed + 1);
                let out = run(&s, &scene, weights(name), Algorithm::RrtConnect, seed, |st| {
                    let _ = writeln!(
                        csv,
                        "{scene_name},{name},{seed},{},{}",
                        st.iteration, st.known_ratio
                    );
                });
                let _ = writeln!(csv, "{scene_name},{name},{seed},0,{}", out.initial_known_ratio);
                let t = &out.totals;
                for (c, v) in cols.iter_mut().zip([
                    out.iterations as f64,
                    out.initial_known_ratio,
                    out.known_ratio,
                    t.jd,
                    t.cpc,
                    t.cd,
                    t.oc,
                    t.rdm,
                    out.elapsed_us as f64 / 1e6,
                    out.failures as f64,
                ]) {
                    c.push(v);
                }
                statuses.push(format!("{:?}", out.status));
            }
            let f = |i: usize, d: usize| {
                let (m, sd) = mean_sd(&cols[i]);
                format!("{m:.d$} ± {sd:.d$}")
            };
            statuses.sort();
            statuses.dedup();
            println!(
                "| {scene_name} | {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                f(0, 1),
                f(1, 3),
                f(2, 3),
                statuses.join(", "),
                f(3, 1),
                f(4, 1),
                f(5, 1),
                f(6, 1),
                f(7, 1),
                f(8, 1)
            );
        }
    }
    std::fs::write("target/explore_known_ratio.csv", csv).expect("csv");
}

fn tab54(seeds: u64) {
    let s = setup();
    let mut csv = String::from("planner,seed,iteration,oc,cd\n");
    println!(
        "| planner | trajectories | OC mean rad | OC var | OC sum | CD mean m | CD var | CD sum | failures | truth hits | wall s/run |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (label, algorithm) in [
        ("RRT-Connect", Algorithm::RrtConnect),
        ("STOMP", Algorithm::Stomp),
        ("CCSTOMP", Algorithm::Ccstomp),
    ] {
        let (mut oc, mut cd) = (Vec::new(), Vec::new());
        let (mut failures, mut hits, mut wall) = (0usize, 0usize, 0.0);
        for seed in 0..seeds {
            let scene = s0_open_cell(seed + 1);
            let t0 = Instant::now();
            let out = run(&s, &scene, weights("IG1_T025_R01"), algorithm, seed, |st| {
                if let Some(m) = &st.motion {
                    oc.push(m.criteria.oc);
                    cd.push(m.criteria.cd);
                    let _ = writeln!(
                        csv,
                        "{label},{seed},{},{},{}",
                        st.iteration, m.criteria.oc, m.criteria.cd
                    );
                }
            });
            wall += t0.elapsed().as_secs_f64();
            failures += out.failures;
            hits += out.truth_hits;
        }
        let stats = |v: &[f64]| {
            let (m, sd) = mean_sd(v);
            (m, sd * sd, v.iter().sum::<f64>())
        };
        let (om, ov, os) = stats(&oc);
        let (cm, cv, cs) = stats(&cd);
        println!(
            "| {label} | {} | {om:.2} | {ov:.2} | {os:.2} | {cm:.2} | {cv:.2} | {cs:.2} | {failures} | {hits} | {:.1} |",
            oc.len(),
            wall / seeds as f64
        );
    }
    std::fs::write("target/explore_planners.csv", csv).expect("csv");
}

fn waste(seeds: u64) {
    let s = setup();
    println!(
        "| cell | seed | planner | choice | iterations | wasted moves | other failures | initial known | known after | status | best predicted cells | wall s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for scene_name in ["open", "walled"] {
        for seed in 1..=seeds {
            let scene = scene_named(scene_name, seed);
            for (label, algorithm) in [
                ("RRT-Connect", Algorithm::RrtConnect),
                ("CCSTOMP", Algorithm::Ccstomp),
            ] {
                for blind in [true, false] {
                    let truth = Arc::new(
                        SceneGeometry::build(
                            &Scene::new(scene.obstacles.clone(), &SceneLimits::default()).expect("scene"),
                        )
                        .expect("geometry"),
                    );
                    let world = ExploreWorld {
                        chain: &s.chain,
                        model: &s.model,
                        acm: &s.acm,
                        truth: &truth,
                    };
                    let mut p = ExploreParams::new(scene.region, s.chain.dof());
                    p.plan.algorithm = algorithm;
                    p.stop.max_iterations = 15;
                    if blind {
                        p.visibility = None;
                    }
                    let t0 = Instant::now();
                    let out = explore(&world, &scene.start, &p, ExploreControl::default()).expect("explore");
                    println!(
                        "| {scene_name} | {seed} | {label} | {} | {} | {} | {} | {:.3} | {:.3} | {:?} | {} | {:.1} |",
                        if blind {
                            "intersection (S0)"
                        } else {
                            "visibility check"
                        },
                        out.iterations,
                        out.wasted_moves,
                        out.failures - out.wasted_moves,
                        out.initial_known_ratio,
                        out.known_ratio,
                        out.status,
                        out.best_predicted_cells
                            .map_or("-".to_string(), |c| c.to_string()),
                        t0.elapsed().as_secs_f64()
                    );
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seeds = |i: usize| args.get(i).map_or(3, |v| v.parse().expect("seeds"));
    match args.first().map(String::as_str) {
        Some("scene") => one(args.get(1).map_or("open", String::as_str)),
        Some("tab53") => tab53(seeds(1)),
        Some("tab54") => tab54(seeds(1)),
        Some("waste") => waste(seeds(1)),
        _ => {
            eprintln!("usage: explore_s0 scene <open|walled> | tab53 [seeds] | tab54 [seeds] | waste [seeds]")
        }
    }
}
