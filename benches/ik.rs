//! Criterion micro-benchmarks (seeded): one LM+SVD solve on the KR 210, the UR5 and the
//! Panda from the middle of the limits, one RLXA / SVD solve of a 6×6 Jacobian system,
//! and cold Jacobi decompositions of Panda 6×7 Jacobians at the default orthogonality
//! (1e-10) and at the IK steps' 1e-4.
//! The full TRAC-IK-protocol and S2 tables are `examples/ik_bench.rs` and
//! `examples/s2_tables.rs` (see IK_RESULTS.md).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::ik::{IkParams, IkSolver, IkTarget};
use kinplan_core::linalg::{PseudoinverseParams, RlxaParams, SvdWorkspace, solve_angle_relaxation};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn ik(c: &mut Criterion) {
    for arm in ["kuka_kr210_r2700_extra", "ur5", "franka_panda"] {
        let chain = kinplan_core::robot::builtin_chain(arm).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let targets: Vec<IkTarget> = (0..64)
            .map(|_| {
                let q: Vec<f64> = chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect();
                IkTarget::Pose(chain.fk(&q))
            })
            .collect();
        let mut solver = IkSolver::new(&chain);
        let params = IkParams::default();
        let mut k = 0;
        c.bench_function(&format!("lm_svd_{arm}"), |b| {
            b.iter(|| {
                k = (k + 1) % targets.len();
                black_box(
                    solver
                        .solve(
                            &targets[k],
                            None,
                            &params,
                            k as u64,
                            kinplan_core::Deadline::none(),
                        )
                        .unwrap(),
                )
            })
        });
    }
}

fn linear(c: &mut Criterion) {
    let chain = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let j = chain.jacobian(&[0.1, -1.2, 1.0, 0.2, 0.8, 0.1]);
    let a = DMatrix::from_iterator(6, 6, j.iter().cloned());
    let b = DVector::from_fn(6, |i, _| 0.01 * (i as f64 + 1.0));
    let mut ws = SvdWorkspace::new(6, 6);
    let mut x = DVector::zeros(6);
    c.bench_function("svd_workspace_6x6", |bch| {
        bch.iter(|| {
            ws.solve_into(black_box(&a), &b, 0.0, &PseudoinverseParams::default(), &mut x)
                .unwrap()
        })
    });
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let p = RlxaParams {
        tolerance: 1e-4,
        ..RlxaParams::default()
    };
    c.bench_function("rlxa_6x6_tol1e-4", |bch| {
        bch.iter(|| solve_angle_relaxation(black_box(&a), &b, &p, &mut rng).unwrap())
    });
}

fn decompositions(c: &mut Criterion) {
    let chain = kinplan_core::robot::builtin_chain("franka_panda").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let jacobians: Vec<DMatrix<f64>> = (0..256)
        .map(|_| {
            let q: Vec<f64> = chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect();
            DMatrix::from_iterator(6, 7, chain.jacobian(&q).iter().cloned())
        })
        .collect();
    for (name, tolerance) in [("1e-10", 1e-10), ("1e-4", 1e-4)] {
        let mut ws = SvdWorkspace::new(6, 7).with_orthogonality(tolerance);
        let mut k = 0;
        c.bench_function(&format!("svd_decompose_panda_6x7_orth_{name}"), |b| {
            b.iter(|| {
                k = (k + 1) % jacobians.len();
                ws.decompose(black_box(&jacobians[k]))
            })
        });
    }
}

criterion_group!(benches, ik, linear, decompositions);
criterion_main!(benches);
