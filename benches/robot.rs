//! In-process forward kinematics and Jacobian per built-in arm.
//! `cargo bench --bench robot`; figures go to benches/RESULTS.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::robot::builtin_chain;
use nalgebra::Matrix6xX;

fn fk_and_jacobian(c: &mut Criterion) {
    for name in [
        "kuka_kr210_r2700_extra",
        "ur5",
        "franka_panda",
        "kuka_lbr_iiwa14_r820",
        "planar_10",
    ] {
        let chain = builtin_chain(name).unwrap();
        let q: Vec<f64> = chain
            .limits()
            .enumerate()
            .map(|(i, (lo, hi))| lo.max(-3.0) + (hi.min(3.0) - lo.max(-3.0)) * (0.2 + 0.07 * i as f64))
            .collect();
        c.bench_function(&format!("fk/{name}"), |b| b.iter(|| chain.fk(black_box(&q))));
        let mut jac = Matrix6xX::zeros(chain.dof());
        c.bench_function(&format!("jacobian/{name}"), |b| {
            b.iter(|| chain.jacobian_into(black_box(&q), &mut jac))
        });
    }
}

criterion_group!(benches, fk_and_jacobian);
criterion_main!(benches);
