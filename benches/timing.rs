//! Timing a 50-waypoint 7-joint path in-process: the time-optimal method
//! (circular blends + TOPP-RA, sampled every 10 ms), TOPP-RA alone, and the
//! jerk-limited method.
//!
//! The path is a seeded random walk (each joint steps uniformly in ±0.3 rad
//! between waypoints) with the Franka Panda's datasheet limits; the same
//! kind of path as `benches/timing/compare.py` times against toppra and
//! ruckig. Run: `cargo bench -p kinplan-core --bench timing`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::plan::{BlendedPath, TimingMethod, TimingParams, retime, topp_ra};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DOF: usize = 7;
const N: usize = 50;
const V: [f64; DOF] = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];
const A: [f64; DOF] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];
const J: [f64; DOF] = [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0];

fn random_walk(seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut q = [0.0; DOF];
    let mut out = Vec::with_capacity(N * DOF);
    for _ in 0..N {
        out.extend_from_slice(&q);
        for v in q.iter_mut() {
            *v += rng.random_range(-0.3..0.3);
        }
    }
    out
}

/// CPU time this thread has run, ns (`/proc/thread-self/schedstat`): on a
/// machine shared with other builds, wall time counts the waits for a core.
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// Mean on-CPU time of `f`, µs, over `iters` calls.
fn cpu_us(iters: u32, mut f: impl FnMut()) -> f64 {
    f();
    let t0 = thread_cpu_ns();
    for _ in 0..iters {
        f();
    }
    (thread_cpu_ns() - t0) as f64 / 1e3 / iters as f64
}

fn bench(c: &mut Criterion) {
    let path = random_walk(1);
    let params = |method| TimingParams {
        method,
        acceleration_limits: Some(A.to_vec()),
        jerk_limits: Some(J.to_vec()),
        ..Default::default()
    };
    let optimal = params(TimingMethod::TimeOptimal);
    let jerk = params(TimingMethod::JerkLimited);
    let r = retime(&path, DOF, &V, &optimal, kinplan_core::Deadline::none()).unwrap();
    let blended = BlendedPath::new(&path, DOF, optimal.path_tolerance);
    let grid = topp_ra(
        &blended,
        &V,
        &A,
        0.0,
        optimal.grid_step,
        kinplan_core::Deadline::none(),
    )
    .unwrap()
    .s
    .len();
    println!(
        "time-optimal: {:.4} s, {} samples, {} grid points, {} path pieces; jerk-limited: {:.4} s",
        r.duration(),
        r.len(),
        grid,
        kinplan_core::plan::Curve::pieces(&blended),
        retime(&path, DOF, &V, &jerk, kinplan_core::Deadline::none())
            .unwrap()
            .duration()
    );
    let blended_cpu = BlendedPath::new(&path, DOF, optimal.path_tolerance);
    println!(
        "on-CPU us per call (mean of 2000): time_optimal {:.1}, TOPP-RA alone {:.1}, jerk_limited {:.1}",
        cpu_us(2000, || {
            black_box(
                retime(
                    black_box(&path),
                    DOF,
                    &V,
                    &optimal,
                    kinplan_core::Deadline::none(),
                )
                .unwrap(),
            );
        }),
        cpu_us(2000, || {
            black_box(
                topp_ra(
                    &blended_cpu,
                    &V,
                    &A,
                    0.0,
                    optimal.grid_step,
                    kinplan_core::Deadline::none(),
                )
                .unwrap(),
            );
        }),
        cpu_us(2000, || {
            black_box(retime(black_box(&path), DOF, &V, &jerk, kinplan_core::Deadline::none()).unwrap());
        }),
    );
    c.bench_function(
        "retime time_optimal 50x7 (blend + TOPP-RA + 10 ms samples)",
        |b| {
            b.iter(|| {
                retime(
                    black_box(&path),
                    DOF,
                    &V,
                    &optimal,
                    kinplan_core::Deadline::none(),
                )
                .unwrap()
            })
        },
    );
    c.bench_function("TOPP-RA alone 50x7 (on the blended path)", |b| {
        let blended = BlendedPath::new(&path, DOF, optimal.path_tolerance);
        b.iter(|| {
            topp_ra(
                black_box(&blended),
                &V,
                &A,
                0.0,
                optimal.grid_step,
                kinplan_core::Deadline::none(),
            )
            .unwrap()
        })
    });
    c.bench_function("retime jerk_limited 50x7 (10 ms samples)", |b| {
        b.iter(|| retime(black_box(&path), DOF, &V, &jerk, kinplan_core::Deadline::none()).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
