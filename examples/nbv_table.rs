//! S0 Tab. 5.1 reproduced (cells found by intersection and by 50/25/10 % rays relative
//! to 100 % rays, time per view) on the synthetic room scanned with our insert at
//! 0.05–0.15 m and on geb079.bt; then NBV end to end with 1,000 frontier candidates at
//! 5 cm. Seeded; prints Markdown.
//!
//! cargo run --release -p kinplan-core --example nbv_table [-- --no-rays | --nbv-only] [--config I] [--repeat N] [--write-bt PATH]
//!
//! `--repeat N` runs each NBV config N times on the same tree (one row per run), so that a
//! profiler's samples are those of the request rather than of the scene's construction.

use std::time::Instant;

use kinplan_core::nbv::{
    CameraModel, Frustum, FrustumCounter, GainMethod, GainWorkspace, NbvParams, VisibilityParams, look_along,
    next_best_view, ray_gain,
};
use kinplan_core::octree::{CellState, Octree, OctreeLimits, ScanParams};
use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "common/room_scene.rs"]
mod room_scene;
#[path = "common/sched.rs"]
mod sched;
use sched::sched_ns;

const VIEWS: usize = 8;

fn room_tree(res: f64) -> Octree {
    let mut t = Octree::new(res).unwrap();
    for (o, yaw, pitch) in room_scene::scan_poses() {
        let pts = room_scene::beams(o, yaw, pitch, 512, 424, 70.6f64.to_radians(), 60f64.to_radians());
        t.insert_scan(
            &pts,
            &o.map(|v| v as f32),
            &ScanParams::default(),
            kinplan_core::Deadline::none(),
        )
        .unwrap();
    }
    t
}

/// Seeded views at free cells inside `[lo, hi]`, random yaw, pitch in ±0.5 rad.
fn views(t: &Octree, lo: [f64; 3], hi: [f64; 3], seed: u64) -> Vec<Isometry3<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    while out.len() < VIEWS {
        let p = Point3::new(
            rng.random_range(lo[0]..hi[0]),
            rng.random_range(lo[1]..hi[1]),
            rng.random_range(lo[2]..hi[2]),
        );
        let (yaw, pitch): (f64, f64) = (
            rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
            rng.random_range(-0.5..0.5),
        );
        if t.state_at(&p, 16).map(|s| s.0) != Ok(CellState::Free) {
            continue;
        }
        let d = Vector3::new(yaw.cos() * pitch.cos(), yaw.sin() * pitch.cos(), pitch.sin());
        out.push(look_along(&p, &d).unwrap());
    }
    out
}

fn row(name: &str, t: &Octree, vs: &[Isometry3<f64>], cam: &CameraModel, no_rays: bool) {
    let mut ws = GainWorkspace::default();
    let mut sums = [0.0f64; 5];
    let mut times = [0.0f64; 5];
    let mut steps = 0u64;
    // the tree's known-cell counts, built once per tree (reported beside the row)
    let s = Instant::now();
    let counter = FrustumCounter::new(t);
    let build_ms = s.elapsed().as_secs_f64() * 1e3;
    for pose in vs {
        let s = Instant::now();
        sums[0] += counter.count(&Frustum::new(cam, pose)) as f64;
        times[0] += s.elapsed().as_secs_f64();
        let fractions: &[f64] = if no_rays { &[] } else { &[1.0, 0.5, 0.25, 0.1] };
        for (i, &f) in fractions.iter().enumerate() {
            let s = Instant::now();
            let g = ray_gain(
                t,
                cam,
                pose,
                GainMethod::Rays { fraction: f },
                &mut ws,
                kinplan_core::Deadline::none(),
            );
            times[i + 1] += s.elapsed().as_secs_f64();
            sums[i + 1] += g.cells;
            if i == 0 {
                steps += g.ray_steps;
            }
        }
    }
    let n = vs.len() as f64;
    let pct = |i: usize| 100.0 * sums[i] / sums[1];
    // without rays: the mean intersection count itself (cells), to compare builds
    let first = if no_rays {
        format!("{:.1} cells", sums[0] / n)
    } else {
        format!("{:.1} %", pct(0))
    };
    println!(
        "| {name} | {first} | {:.2} % | {:.2} % | {:.2} % | {:.0} | {:.3} ({build_ms:.2} build) | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
        pct(2),
        pct(3),
        pct(4),
        sums[1] / n,
        times[0] / n * 1e3,
        times[1] / n * 1e3,
        times[2] / n * 1e3,
        times[3] / n * 1e3,
        times[4] / n * 1e3,
        steps as f64 / times[1] / 1e6,
    );
}

fn main() {
    // --no-rays: intersection column only, as the mean count (ray columns print NaN);
    // --nbv-only: skip Tab. 5.1
    let args: Vec<String> = std::env::args().collect();
    let no_rays = args.iter().any(|a| a == "--no-rays");
    let nbv_only = args.iter().any(|a| a == "--nbv-only");
    let cam = CameraModel::default();
    println!(
        "camera: Kinect v2 model, {}x{} rays, fov {:.1}°x{:.1}°, range {}–{} m; {VIEWS} seeded views per row; rayon threads {}",
        cam.width,
        cam.height,
        cam.hfov.to_degrees(),
        cam.vfov.to_degrees(),
        cam.near,
        cam.far,
        rayon::current_num_threads()
    );
    if !nbv_only {
        println!();
        println!(
            "| scene @ res | intersection | 50 % rays | 25 % rays | 10 % rays | cells by 100 % rays (mean) | ms/view intersection (ms to build the counts once per tree) | 100 % | 50 % | 25 % | 10 % | M steps/s (100 % rays, 1 thread) |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
        for res in [0.05, 0.075, 0.1, 0.125, 0.15] {
            let t = room_tree(res);
            let vs = views(&t, [-2.5, -2.0, 0.4], [2.5, 2.0, 2.6], 11);
            row(
                &format!("room @ {res} m ({} nodes)", t.num_nodes()),
                &t,
                &vs,
                &cam,
                no_rays,
            );
        }
        let geb = "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt";
        match std::fs::read(geb) {
            Ok(b) => {
                let t = Octree::read_bt(&b, &OctreeLimits::default()).unwrap();
                let (lo, hi) = t.known_bounds().unwrap();
                let vs = views(&t, lo.coords.into(), hi.coords.into(), 12);
                row("geb079 @ 0.08 m", &t, &vs, &cam, no_rays);
            }
            Err(_) => println!("| geb079 | SKIPPED: {geb} not present | | | | | | | | | | |"),
        }
    }

    // NBV end to end at 5 cm
    let t = room_tree(0.05);
    // `--write-bt PATH`: the tree as OctoMap .bt, to time the same call over gRPC
    if let Some(path) = args
        .iter()
        .position(|a| a == "--write-bt")
        .and_then(|i| args.get(i + 1))
    {
        std::fs::write(path, t.write_bt()).expect("writing the .bt file");
    }
    let chain = kinplan_core::robot::builtin_chain("abb_irb4600_60_205").unwrap();
    let current = look_along(&Point3::new(0.1, 0.2, 1.3), &Vector3::new(1.0, 0.3, 0.0)).unwrap();
    println!();
    println!("NBV end to end, room @ 0.05 m, robot abb_irb4600_60_205 at the origin, Kinect v2 model:");
    println!();
    println!(
        "| config | frontier cells | candidates | after ORF | after PTF | after IGF | IK checked / failed | frontier ms | field ms | ORF ms | PTF ms | IGF ms | IK ms | visibility ms (checked / dropped) | total ms | CPU ms, all threads (run-queue wait ms) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let cfgs: [(&str, NbvParams); 5] = [
        (
            "S0 filters (PTF 0.2 m / 20°), intersection gain",
            NbvParams::default(),
        ),
        (
            "PTF off (all 1,000 gains), intersection gain, no IK",
            NbvParams {
                position_threshold: 0.0,
                reach: Some(100.0),
                ik_check: 0,
                ..NbvParams::default()
            },
        ),
        (
            "S0 filters, intersection gain + visibility check",
            NbvParams {
                visibility: Some(VisibilityParams::default()),
                ..NbvParams::default()
            },
        ),
        (
            "PTF off, no IK, intersection gain + visibility check",
            NbvParams {
                position_threshold: 0.0,
                reach: Some(100.0),
                ik_check: 0,
                visibility: Some(VisibilityParams::default()),
                ..NbvParams::default()
            },
        ),
        (
            "S0 filters, 10 % rays gain",
            NbvParams {
                gain: GainMethod::Rays { fraction: 0.1 },
                ..NbvParams::default()
            },
        ),
    ];
    // `--config I`: only the I-th row
    let only: Option<usize> = args
        .iter()
        .position(|a| a == "--config")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok());
    let repeat: usize = args
        .iter()
        .position(|a| a == "--repeat")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let runs = cfgs
        .into_iter()
        .enumerate()
        .flat_map(|(i, c)| std::iter::repeat_n((i, c), repeat));
    for (i, (name, p)) in runs {
        if no_rays && !matches!(p.gain, GainMethod::Intersection) || only.is_some_and(|o| o != i) {
            continue;
        }
        let s = Instant::now();
        let c0 = sched_ns();
        let r = next_best_view(
            &t,
            &p,
            &cam,
            &current,
            Some(&chain),
            kinplan_core::Deadline::none(),
        )
        .unwrap();
        let total = s.elapsed().as_secs_f64() * 1e3;
        let cpu = match (c0, sched_ns()) {
            (Some(a), Some(b)) => format!(
                "{:.1} ({:.1})",
                (b.0 - a.0) as f64 / 1e6,
                (b.1 - a.1) as f64 / 1e6
            ),
            _ => "n/a".into(),
        };
        let st = r.stages;
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} / {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} ({} / {}) | {:.1} | {cpu} |",
            st.frontier_cells,
            st.frontier_candidates + st.caller_candidates,
            st.after_orf,
            st.after_ptf,
            st.after_igf,
            st.ik_checked,
            st.ik_failed,
            st.frontier_us as f64 / 1e3,
            st.field_us as f64 / 1e3,
            st.orf_us as f64 / 1e3,
            st.ptf_us as f64 / 1e3,
            st.igf_us as f64 / 1e3,
            st.ik_us as f64 / 1e3,
            st.visibility_us as f64 / 1e3,
            st.visibility_checked,
            st.visibility_dropped,
            total
        );
        if let Some(b) = r.candidates.first() {
            eprintln!(
                "{name}: best f = {:.3} (D {:.3}, R {:.3}, Ig {:.4}), reachable {:?}",
                b.utility, b.distance_term, b.rotation_term, b.ig, b.reachable
            );
        }
        // the whole ranking in one number (FNV-1a over each ranked candidate's position,
        // unknown cells and utility), to compare builds
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        for c in &r.candidates {
            let p = c.pose.translation.vector;
            for v in [p.x, p.y, p.z, c.unknown_cells, c.utility] {
                for byte in v.to_bits().to_le_bytes() {
                    h = (h ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
        eprintln!(
            "{name}: {} ranked, ranking digest {h:016x}, ray steps {}",
            r.candidates.len(),
            st.ray_steps
        );
    }
}
