//! Counts, per MotionBenchMaker Panda problem set, the starts and goals our
//! collision geometry (built-in `franka_panda_hand`) finds invalid, and
//! names what collides. The problems were generated against MoveIt's Panda
//! meshes, so every invalid state here is a disagreement of our enclosing
//! shapes with those meshes (or a state outside our joint limits).
//!
//! ```text
//! tar xjf ../shared/bench/mbm/panda_problems.tar.bz2 -C target/mbm
//! cargo run --release -p kinplan-core --example mbm_validity -- target/mbm/problems
//! ```
//!
//! Fingers: each request's `panda_finger_joint1/2` start positions as given
//! (MotionBenchMaker's requests say 0.065 m, past the 0.04 m limit of the
//! URDF; MoveIt checked the states with that value). `--clamp-fingers`
//! clamps them into [0, 0.04] instead.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use kinplan_core::collision::{
    CheckerParams, Part, SceneChecker, SceneGeometry, SceneLimits, parse_joint_request, parse_planning_scene,
};
use kinplan_core::robot::builtin_chain;

#[path = "common/mbm_panda.rs"]
mod mbm_panda;
use mbm_panda::{SETS, arm, model};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(
        std::env::args()
            .nth(1)
            .ok_or("usage: mbm_validity <problems dir> [--clamp-fingers]")?,
    );
    let clamp = std::env::args().any(|a| a == "--clamp-fingers");
    let chain = Arc::new(builtin_chain("franka_panda_hand")?);
    let mut cache = BTreeMap::new();
    println!(
        "| set | problems | invalid starts | invalid goals | depth median / max (mm) | colliding pairs (count) |"
    );
    println!("|---|---|---|---|---|---|");
    let (mut checks, mut check_time) = (0usize, 0.0f64);
    for set in SETS {
        let dir = root.join(format!("{set}_panda"));
        let (mut n, mut bad_start, mut bad_goal) = (0, 0, 0);
        let mut pairs: BTreeMap<String, usize> = BTreeMap::new();
        let mut depths: Vec<f64> = Vec::new();
        for k in 1..=100 {
            let scene_path = dir.join(format!("scene{k:04}.yaml"));
            let request_path = dir.join(format!("request{k:04}.yaml"));
            if !Path::new(&scene_path).exists() {
                continue;
            }
            n += 1;
            let scene =
                parse_planning_scene(&std::fs::read_to_string(&scene_path)?, &SceneLimits::default())?;
            let request = parse_joint_request(&std::fs::read_to_string(&request_path)?)?;
            let opening = request
                .start
                .iter()
                .find(|(n, _)| n == "panda_finger_joint1")
                .map_or(0.04, |(_, v)| *v);
            let opening = if clamp { opening.clamp(0.0, 0.04) } else { opening };
            let (model, acm) = model(&chain, opening, &mut cache);
            let world = Arc::new(SceneGeometry::build(&scene)?);
            let checker = SceneChecker::new(model, &acm, world, CheckerParams::default())?;
            for (which, joints) in [("start", &request.start), ("goal", &request.goal)] {
                let q = arm(joints, &format!("{}:{which}", request_path.display()))?;
                let t = Instant::now();
                let valid = kinplan_core::collision::StateChecker::is_valid(&checker, &q);
                check_time += t.elapsed().as_secs_f64();
                checks += 1;
                if !valid {
                    if which == "start" {
                        bad_start += 1;
                    } else {
                        bad_goal += 1;
                    }
                    if let Some(p) = checker.proximity(&q, 0.0)? {
                        depths.push(-p.distance);
                    }
                    let report = checker.report(&q)?;
                    for (link, other) in &report.collisions {
                        let other = match other {
                            Part::Link(l) => l.clone(),
                            Part::Obstacle { name, .. } => name.clone(),
                        };
                        *pairs.entry(format!("{link}–{other}")).or_default() += 1;
                    }
                    for (i, ..) in &report.out_of_limits {
                        *pairs.entry(format!("joint {} out of limits", i + 1)).or_default() += 1;
                    }
                }
            }
        }
        let mut top: Vec<_> = pairs.into_iter().collect();
        top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let top: Vec<String> = top.iter().take(4).map(|(p, c)| format!("{p} ({c})")).collect();
        depths.sort_by(f64::total_cmp);
        let depth = match depths.len() {
            0 => "–".to_string(),
            k => format!("{:.1} / {:.1}", 1e3 * depths[k / 2], 1e3 * depths[k - 1]),
        };
        println!(
            "| {set} | {n} | {bad_start} | {bad_goal} | {depth} | {} |",
            top.join(", ")
        );
    }
    println!(
        "\n{checks} start/goal checks, mean {:.2} µs per is_valid (cold caches, scenes of 10–30 primitives)",
        1e6 * check_time / checks.max(1) as f64
    );
    Ok(())
}
