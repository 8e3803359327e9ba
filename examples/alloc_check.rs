//! Counts heap allocations per solve with a counting global allocator: the per-iteration
//! loops must not allocate, so allocations per solve must not grow with iterations.
//!
//! `cargo run --release --example alloc_check`

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use kinplan_core::ik::{IkMethod, IkParams, IkSolver, IkTarget};
use kinplan_core::linalg::LinearSolverKind;
use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn main() {
    println!("| arm | method | solves | iterations | attempts | allocations | allocations per attempt |");
    println!("|---|---|---|---|---|---|---|");
    for (arm, method, solver, pos) in [
        (
            "kuka_kr210_r2700_extra",
            IkMethod::LevenbergMarquardt,
            LinearSolverKind::SvdPseudoinverse,
            false,
        ),
        (
            "franka_panda",
            IkMethod::LevenbergMarquardt,
            LinearSolverKind::SvdPseudoinverse,
            false,
        ),
        (
            "ur5",
            IkMethod::LevenbergMarquardt,
            LinearSolverKind::AngleRelaxation,
            false,
        ),
        (
            "ur5",
            IkMethod::JacobianInverse,
            LinearSolverKind::SvdPseudoinverse,
            false,
        ),
        ("ur5", IkMethod::Newton, LinearSolverKind::SvdPseudoinverse, false),
        ("ur5", IkMethod::Ccd, LinearSolverKind::SvdPseudoinverse, true),
        ("ur5", IkMethod::Fabrik, LinearSolverKind::SvdPseudoinverse, true),
        (
            "ur5",
            IkMethod::LengthRelaxation,
            LinearSolverKind::SvdPseudoinverse,
            true,
        ),
    ] {
        let chain = kinplan_core::robot::builtin_chain(arm).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let targets: Vec<IkTarget> = (0..200)
            .map(|_| {
                let q: Vec<f64> = chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect();
                let t = chain.fk(&q);
                if pos {
                    IkTarget::Position(Point3::from(t.translation.vector))
                } else {
                    IkTarget::Pose(t)
                }
            })
            .collect();
        let params = IkParams {
            method,
            linear_solver: solver,
            max_restarts: 20,
            ..IkParams::default()
        };
        let mut solver_ws = IkSolver::new(&chain);
        // warm the workspace once (first-use sizing is allowed to allocate)
        let _ = solver_ws
            .solve(&targets[0], None, &params, 0, kinplan_core::Deadline::none())
            .unwrap();
        let before = ALLOCS.load(Ordering::Relaxed);
        let (mut iters, mut attempts) = (0, 0);
        for (i, t) in targets.iter().enumerate() {
            let r = solver_ws
                .solve(t, None, &params, i as u64, kinplan_core::Deadline::none())
                .unwrap();
            iters += r.total_iterations;
            attempts += r.attempts;
        }
        let allocs = ALLOCS.load(Ordering::Relaxed) - before;
        println!(
            "| {arm} | {method:?}+{solver:?} | {} | {iters} | {attempts} | {allocs} | {:.2} |",
            targets.len(),
            allocs as f64 / attempts as f64
        );
    }
}
