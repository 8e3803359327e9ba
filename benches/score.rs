//! Scoring a 10,000-waypoint synthetic 6-joint trajectory in-process.
//!
//! Synthetic data (no robot model): joints are smooth sinusoids plus seeded
//! noise, tool poses a helix with a slowly turning orientation, and 8 robot
//! points per waypoint. Run: `cargo bench --bench score`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::robot::builtin_chain;
use kinplan_core::score::{
    JointLimits, LabelledSet, PointSet, Rows, ScoreInput, ScoreParams, TrajectoryData, compare, sample_chain,
    score,
};
use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 10_000;
const M: usize = 6;
const POINTS: usize = 8;

struct Data {
    q: Vec<f64>,
    poses: Vec<Isometry3<f64>>,
    points: Vec<Point3<f64>>,
    ts: Vec<f64>,
}

fn synthetic(seed: u64) -> Data {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut q = Vec::with_capacity(N * M);
    let mut poses = Vec::with_capacity(N);
    let mut points = Vec::with_capacity(N * POINTS);
    for i in 0..N {
        let s = i as f64 / N as f64;
        for j in 0..M {
            let f = (j + 1) as f64;
            q.push((6.0 * f * s).sin() + 1e-4 * rng.random_range(-1.0..1.0));
        }
        let pos = Vector3::new((20.0 * s).cos(), (20.0 * s).sin(), 0.5 + 0.3 * s);
        let rot = Vector3::new(0.3 * (10.0 * s).sin(), 0.2, 3.0 * s);
        let pose = Isometry3::new(pos, rot);
        for k in 0..POINTS {
            points.push(pose * Point3::new(0.1 * k as f64, 0.0, -0.05 * k as f64));
        }
        poses.push(pose);
    }
    let ts = (0..N).map(|i| 0.004 * i as f64).collect();
    Data { q, poses, points, ts }
}

fn bench(c: &mut Criterion) {
    let d = synthetic(42);
    let v_max = [2.0, 2.0, 2.5, 3.5, 3.5, 4.5];
    let a_max = [10.0; M];
    let traj = TrajectoryData {
        joints: Rows::Flat {
            values: &d.q,
            width: M,
        },
        poses: &d.poses,
        robot_points: Some(Rows::Flat {
            values: &d.points,
            width: POINTS,
        }),
        timestamps: Some(&d.ts),
    };
    let full = ScoreInput {
        trajectory: traj,
        dof: Some(M),
        joint_weights: Some(&[1.0, 1.2, 0.8, 0.3, 0.3, 0.1]),
        limits: Some(JointLimits {
            v_max: &v_max,
            a_max: Some(&a_max),
        }),
    };
    let plain = ScoreInput::new(TrajectoryData::new(
        Rows::Flat {
            values: &d.q,
            width: M,
        },
        &d.poses,
    ));
    let defaults = ScoreParams::default();
    let with_series = ScoreParams {
        series: true,
        ..Default::default()
    };

    let mut g = c.benchmark_group("score_10k_6dof");
    g.bench_function("validate_only", |b| {
        b.iter(|| black_box(&full).validate().unwrap())
    });
    g.bench_function("criteria", |b| {
        b.iter(|| score(black_box(&plain), &defaults).unwrap())
    });
    g.bench_function("criteria+rdm8+timestamps+cycle_time", |b| {
        b.iter(|| score(black_box(&full), &defaults).unwrap())
    });
    g.bench_function("everything+series", |b| {
        b.iter(|| score(black_box(&full), &with_series).unwrap())
    });
    g.finish();

    let scores: Vec<_> = (0..100u64)
        .map(|s| {
            score(
                &ScoreInput::new(TrajectoryData::new(
                    Rows::Flat {
                        values: &d.q[..(500 + s as usize) * M],
                        width: M,
                    },
                    &d.poses[..500 + s as usize],
                )),
                &defaults,
            )
            .unwrap()
            .scores
        })
        .collect();
    c.bench_function("compare_3x100", |b| {
        b.iter(|| {
            compare(black_box(&[
                LabelledSet {
                    label: "a",
                    scores: &scores,
                },
                LabelledSet {
                    label: "b",
                    scores: &scores,
                },
                LabelledSet {
                    label: "c",
                    scores: &scores,
                },
            ]))
            .unwrap()
        })
    });
}

/// KR 210 R2700 extra, 10,000 waypoints of a smooth six-axis move with seeded
/// noise: real FK (tool poses, link frames) then every criterion, as the
/// service does for one ScoreTrajectory request.
fn bench_kr210(c: &mut Criterion) {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let q: Vec<f64> = (0..N)
        .flat_map(|i| {
            let s = i as f64 / N as f64;
            [
                0.9 * s,
                -1.5 + 0.4 * s,
                1.4 - 0.5 * s,
                0.3 * (6.0 * s).sin(),
                0.5 + 0.2 * s,
                -0.4 * s,
            ]
        })
        .map(|v| v + 1e-5 * rng.random_range(-1.0..1.0))
        .collect();
    let joints = Rows::Flat { values: &q, width: M };
    let v_max: Vec<f64> = chain.joints().iter().map(|j| j.max_velocity.unwrap()).collect();
    let run = |points: Option<PointSet>| {
        let samples = sample_chain(&chain, joints, points).unwrap();
        let input = ScoreInput {
            trajectory: TrajectoryData {
                joints,
                poses: &samples.poses,
                robot_points: samples.point_rows(),
                timestamps: None,
            },
            dof: Some(M),
            joint_weights: None,
            limits: Some(JointLimits {
                v_max: &v_max,
                a_max: None,
            }),
        };
        score(&input, &ScoreParams::default()).unwrap().scores
    };
    let mut g = c.benchmark_group("kr210_10k");
    g.bench_function("fk_only", |b| {
        b.iter(|| sample_chain(&chain, black_box(joints), None).unwrap())
    });
    g.bench_function("fk+score (link origins)", |b| {
        b.iter(|| run(black_box(Some(PointSet::LinkOrigins))))
    });
    g.bench_function("fk+score (collision vertices)", |b| {
        b.iter(|| run(black_box(Some(PointSet::CollisionVertices))))
    });
    g.finish();
}

criterion_group!(benches, bench, bench_kr210);
criterion_main!(benches);
