//! One Kinect v2 depth frame (512 × 424, the Kinect v2 camera model) of the benchmark
//! room inserted at 0.05 m beside OctoMap's `insertPointCloud` of the same points
//! (C++ anchor `benches/octomap/insert_frame.cpp`), then compared cell by cell.
//!
//! - `write`: renders the frame from the room's first scan pose and writes its points
//!   (after the depth image's back-projection) to `target/frame_points.bin`.
//! - `compare OT [runs [exact|discretize|near]]`: times `Octree::insert_depth_image` of the same frame into
//!   fresh trees (median and minimum over `runs`, default 7; set `RAYON_NUM_THREADS=1`
//!   for one core) and compares every cell of the room's key box with OctoMap's tree
//!   read from `OT`: same state (unknown / free / occupied) or not. Then the same with
//!   `ScanParams::discretize` (end points merged per cell and cast from the cell's
//!   centre, OctoMap's `discretize`), against the same OctoMap tree (not discretized),
//!   and with the shared near field (`ScanParams::near_ray_spacing` at
//!   `NEAR_RAY_SPACING`).
//!
//! Run by hand (not in CI):
//!
//! ```text
//! cargo build --release -p kinplan-core --example depth_frame
//! target/release/examples/depth_frame write
//! g++ -O2 -o target/insert_frame benches/octomap/insert_frame.cpp -loctomap -loctomath
//! target/insert_frame target/frame_points.bin 0.05 7 target/frame_octomap.ot
//! RAYON_NUM_THREADS=1 target/release/examples/depth_frame compare target/frame_octomap.ot 7
//! ```

use std::time::Instant;

use kinplan_core::nbv::{CameraModel, look_along};
use kinplan_core::octree::{NEAR_RAY_SPACING, Octree, OctreeLimits, ScanParams, depth_image_points};
use nalgebra::{Isometry3, Point3, Vector3};

#[path = "common/room_scene.rs"]
mod room_scene;
#[path = "common/sched.rs"]
mod sched;

const RES: f64 = 0.05;

/// The frame: depths (m along the optical axis) of the Kinect v2 model from the
/// room's first scan pose, every pixel a return (the room is closed).
fn frame() -> (CameraModel, Isometry3<f64>, Vec<f32>) {
    let cam = CameraModel::default();
    // `FRAME_POSE=i` takes the room's i-th scan pose instead of the first
    let i = std::env::var("FRAME_POSE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let (o, yaw, pitch) = room_scene::scan_poses()[i];
    let dir = Vector3::new(yaw.cos() * pitch.cos(), yaw.sin() * pitch.cos(), pitch.sin());
    let pose = look_along(&Point3::from(o), &dir).unwrap();
    let origin = Point3::from(o);
    let mut depth = Vec::with_capacity(cam.width * cam.height);
    for v in 0..cam.height {
        for u in 0..cam.width {
            let local = cam.ray_direction(u, v);
            let t = room_scene::hit_distance(&origin, &(pose.rotation * local));
            depth.push((t * local.z) as f32);
        }
    }
    (cam, pose, depth)
}

fn origin_of(pose: &Isometry3<f64>) -> [f32; 3] {
    let o = pose.translation.vector;
    [o.x as f32, o.y as f32, o.z as f32]
}

fn write() {
    let (cam, pose, depth) = frame();
    let pts = depth_image_points(&depth, cam.width, cam.height, &cam.intrinsics(), &pose).unwrap();
    let mut bytes = Vec::with_capacity(12 * (pts.len() + 1));
    for p in std::iter::once(origin_of(&pose)).chain(pts.iter().copied()) {
        for c in p {
            bytes.extend(c.to_le_bytes());
        }
    }
    std::fs::write("target/frame_points.bin", bytes).unwrap();
    println!("{} points written to target/frame_points.bin", pts.len());
}

/// How our insert is run.
#[derive(Clone, Copy, Debug)]
enum Mode {
    Exact,
    Discretize,
    /// The shared near field at `NEAR_RAY_SPACING`.
    NearField,
}

fn compare(ot: &str, runs: usize, mode: Mode) {
    let (cam, pose, depth) = frame();
    let k = cam.intrinsics();
    // `NEAR_RAY_SPACING=0.9 depth_frame compare …` tries another spacing (cells)
    let spacing = std::env::var("NEAR_RAY_SPACING")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(NEAR_RAY_SPACING);
    let mut ms = Vec::new();
    let mut cpu_ms = Vec::new();
    let mut split = (0u64, 0u64, 0u64);
    let mut ours = Octree::new(RES).unwrap();
    for _ in 0..runs.max(1) {
        ours = Octree::new(RES).unwrap();
        let c0 = sched::sched_ns();
        let t = Instant::now();
        let stats = ours
            .insert_depth_image(
                &depth,
                cam.width,
                cam.height,
                &k,
                &pose,
                &ScanParams {
                    discretize: matches!(mode, Mode::Discretize),
                    near_ray_spacing: if matches!(mode, Mode::NearField) {
                        spacing
                    } else {
                        0.0
                    },
                    ..ScanParams::default()
                },
                kinplan_core::Deadline::none(),
            )
            .unwrap();
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        if let (Some(a), Some(b)) = (c0, sched::sched_ns()) {
            cpu_ms.push((b.0 - a.0) as f64 / 1e6);
        }
        split = (stats.trace_us, stats.update_us, stats.traced_cells);
    }
    let mut sorted = ms.clone();
    sorted.sort_by(f64::total_cmp);
    cpu_ms.sort_by(f64::total_cmp);
    println!(
        "kinplan insert_depth_image ({mode:?}, near_ray_spacing {spacing} if NearField): {} pixels, res {RES}, median {:.1} ms, min {:.1} ms over {} runs, threads {}",
        depth.len(),
        sorted[sorted.len() / 2],
        sorted[0],
        ms.len(),
        rayon::current_num_threads()
    );
    if !cpu_ms.is_empty() {
        println!(
            "  CPU time, all threads: median {:.1} ms, min {:.1} ms",
            cpu_ms[cpu_ms.len() / 2],
            cpu_ms[0]
        );
    }
    println!(
        "  last run: trace {:.1} ms, update {:.1} ms, {} free-cell visits",
        split.0 as f64 / 1e3,
        split.1 as f64 / 1e3,
        split.2
    );
    let theirs = Octree::read_ot(&std::fs::read(ot).unwrap(), &OctreeLimits::default()).unwrap();
    let lo = ours
        .key_of(&Point3::from(room_scene::ROOM_MIN).map(|v| v - 0.2))
        .unwrap();
    let hi = ours
        .key_of(&Point3::from(room_scene::ROOM_MAX).map(|v| v + 0.2))
        .unwrap();
    let (mut same, mut differ, mut known) = (0u64, 0u64, 0u64);
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                let (a, b) = (ours.state_of_key(&[x, y, z]), theirs.state_of_key(&[x, y, z]));
                if a == b {
                    same += 1;
                } else {
                    differ += 1;
                }
                if a != kinplan_core::octree::CellState::Unknown
                    || b != kinplan_core::octree::CellState::Unknown
                {
                    known += 1;
                }
            }
        }
    }
    println!(
        "cells of the room's box: {} compared, {known} known in either tree, {differ} classified differently ({:.4} % of the known), trees' .ot identical: {}",
        same + differ,
        100.0 * differ as f64 / known.max(1) as f64,
        ours.write_ot() == theirs.write_ot()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("write") => write(),
        Some("compare") => {
            let modes = match args.get(3).map(String::as_str) {
                Some("exact") => vec![Mode::Exact],
                Some("discretize") => vec![Mode::Discretize],
                Some("near") => vec![Mode::NearField],
                _ => vec![Mode::Exact, Mode::Discretize, Mode::NearField],
            };
            for mode in modes {
                compare(
                    args.get(1).expect("the OctoMap .ot path"),
                    args.get(2).map_or(7, |v| v.parse().expect("runs")),
                    mode,
                );
            }
        }
        _ => eprintln!("usage: depth_frame write | compare OT [runs [exact|discretize|near]]"),
    }
}
