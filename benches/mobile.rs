//! Per-step controller time and a full simulated navigation, in-process.
//!
//! The pure step functions (validated public API) on fixed inputs, one navigator step with
//! sensing in a seeded clutter world (8 sensors × 5 rays), and a whole `navigate` run in that
//! world (the work behind one `Navigate` call). Run: `cargo bench --bench mobile`.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::mobile::{
    Chassis, LyapunovParams, NavigateParams, Obstacle, PathFollowParams, PathFollowState, PathNode, Point2,
    Pose, PurePursuitParams, RangeSensorParams, RangeSensors, VdfParams, VdfState, World, lyapunov_step,
    navigate, path_follow_step, pure_pursuit_step, vdf_step,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// 20 seeded cylinders (radius 0.15–0.4 m) in x ∈ [1.5, 8.5], y ∈ [−2, 2], at least 0.45 m
/// apart (rim to rim) and 1 m from the start (0, 0) and the goal (10, 0).
fn clutter(seed: u64) -> World {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut obs: Vec<(Point2, f64)> = Vec::new();
    for _ in 0..100_000 {
        if obs.len() == 20 {
            break;
        }
        let c = Point2::new(rng.random_range(1.5..8.5), rng.random_range(-2.0..2.0));
        let r = rng.random_range(0.15..0.4);
        if c.distance(Point2::new(0.0, 0.0)) < r + 1.0 || c.distance(Point2::new(10.0, 0.0)) < r + 1.0 {
            continue;
        }
        if obs.iter().any(|(o, ro)| o.distance(c) < r + ro + 0.45) {
            continue;
        }
        obs.push((c, r));
    }
    World::new(
        obs.into_iter()
            .map(|(c, r)| Obstacle::circle(c.x, c.y, r))
            .collect(),
    )
    .unwrap()
}

fn steps(c: &mut Criterion) {
    let lyap = LyapunovParams::default();
    let start = Pose::new(-1.0, 1.0, 3.0 * PI / 4.0);
    c.bench_function("lyapunov_step", |b| {
        b.iter(|| lyapunov_step(black_box(start), black_box(Pose::default()), &lyap).unwrap())
    });
    let path: Vec<PathNode> = (0..50)
        .map(|i| PathNode::at(0.2 * i as f64, (0.1 * i as f64).sin()))
        .collect();
    let pts: Vec<Point2> = path.iter().map(PathNode::point).collect();
    let pp = PurePursuitParams::default();
    c.bench_function("pure_pursuit_step (50-node path)", |b| {
        b.iter(|| pure_pursuit_step(black_box(Pose::new(2.0, 0.3, 0.1)), &pts, 0, &pp).unwrap())
    });
    let follow = PathFollowParams::default();
    c.bench_function("path_follow_step lyapunov (50-node path)", |b| {
        b.iter(|| {
            path_follow_step(
                black_box(Pose::new(2.0, 0.3, 0.1)),
                &path,
                PathFollowState::default(),
                0.05,
                &follow,
            )
            .unwrap()
        })
    });
    let sensors = RangeSensorParams::default();
    let vdf = VdfParams::default();
    let mut readings = [2.0; 8];
    readings[0] = 0.1;
    let state = VdfState::default();
    c.bench_function("vdf_step (given readings)", |b| {
        b.iter(|| {
            vdf_step(
                &state,
                black_box(Pose::default()),
                Point2::new(5.0, 0.0),
                &readings,
                &sensors,
                &vdf,
            )
            .unwrap()
        })
    });
    let world = clutter(1);
    let mut ring = RangeSensors::new(sensors, 0).unwrap();
    let mut out = [0.0; 8];
    c.bench_function("sense + vdf_step (20-cylinder world)", |b| {
        b.iter(|| {
            ring.sense(&world, black_box(Pose::new(4.0, 0.2, 0.3)), 0.22, &mut out);
            vdf_step(
                &state,
                Pose::new(4.0, 0.2, 0.3),
                Point2::new(10.0, 0.0),
                &out,
                &sensors,
                &vdf,
            )
            .unwrap()
        })
    });
}

fn runs(c: &mut Criterion) {
    let world = clutter(1);
    let params = NavigateParams::default();
    let chassis = Chassis::default();
    let run = navigate(
        &chassis,
        Pose::default(),
        Point2::new(10.0, 0.0),
        &world,
        &params,
        kinplan_core::Deadline::none(),
    )
    .unwrap();
    println!(
        "navigate, seeded 20-cylinder world: {} in {} steps, {:.2} m",
        run.outcome.as_str(),
        run.metrics.steps,
        run.metrics.path_length
    );
    c.bench_function("navigate (20-cylinder world, whole run)", |b| {
        b.iter(|| {
            navigate(
                &chassis,
                Pose::default(),
                Point2::new(10.0, 0.0),
                &world,
                &params,
                kinplan_core::Deadline::none(),
            )
            .unwrap()
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = steps, runs
}
criterion_main!(benches);
