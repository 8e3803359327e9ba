//! The machinery under the solvers: the SVD on redundant Jacobians, joint
//! wrapping, the error history, workspace reuse, Newton's SVD accuracy.

use super::*;

/// Regression: the Jacobi SVD must terminate quickly on rank-deficient 6×7 Jacobians
/// (it once spun 60 sweeps on a numerically zero column).
#[test]
fn svd_workspace_handles_redundant_jacobians() {
    let chain = builtin_chain("franka_panda").unwrap();
    let j = chain.jacobian(&[0.0; 7]);
    let a = nalgebra::DMatrix::from_iterator(6, 7, j.iter().cloned());
    let mut ws = crate::linalg::SvdWorkspace::new(6, 7);
    let sweeps = ws.decompose(&a);
    assert!(sweeps < 20, "{sweeps} sweeps");
}

#[test]
fn wrapping_keeps_the_pose_and_only_turns_full_turn_joints() {
    use super::workspace::IkWorkspace;
    // UR5: every joint has ±2π, so leaving the range is undone by a whole turn.
    let ur5 = crate::robot::builtin_chain("ur5").unwrap();
    let ws = IkWorkspace::new(&ur5);
    assert!(ws.wraps.iter().all(|&w| w));
    let q_out = [7.0, -6.5, 0.3, 6.9, -7.1, 0.0];
    let mut q = q_out;
    IkWorkspace::apply_limits_wrapping(&ws.limits, &ws.wraps, JointLimitMode::Clamp, &mut q);
    for (v, &(lo, hi)) in q.iter().zip(&ws.limits) {
        assert!((lo..=hi).contains(v));
    }
    let (a, b) = (ur5.fk(&q_out), ur5.fk(&q));
    assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
    assert!(a.rotation.angle_to(&b.rotation) < 1e-12);
    // Panda: no joint spans a full turn, so the same call clamps.
    let panda = crate::robot::builtin_chain("franka_panda").unwrap();
    let ws = IkWorkspace::new(&panda);
    assert!(ws.wraps.iter().all(|&w| !w));
    let mut q: Vec<f64> = ws.limits.iter().map(|&(_, hi)| hi + 0.5).collect();
    IkWorkspace::apply_limits_wrapping(&ws.limits, &ws.wraps, JointLimitMode::Clamp, &mut q);
    for (v, &(_, hi)) in q.iter().zip(&ws.limits) {
        assert_eq!(*v, hi);
    }
    // Ignore leaves everything alone.
    let mut q = q_out;
    let ws = IkWorkspace::new(&ur5);
    IkWorkspace::apply_limits_wrapping(&ws.limits, &ws.wraps, JointLimitMode::Ignore, &mut q);
    assert_eq!(q, q_out);
}

/// The error history on request: it starts at the seed's error (computed here from
/// FK), ends at the returned error, has one entry per iteration plus the final one,
/// and never rises for Levenberg–Marquardt (only error-decreasing steps are accepted).
#[test]
fn error_history_on_request() {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let target_pose = chain.fk(&random_joints(&chain, &mut rng));
    let target = IkTarget::Pose(target_pose);
    let params = IkParams {
        record_history: true,
        ..IkParams::default()
    };
    let seed = chain.mid_limits();
    let r = solve_ik(&chain, &target, Some(&seed), &params, 4, Deadline::none()).unwrap();
    let s = &r.solutions[0];
    assert_eq!(s.history.len(), s.iterations + 1);
    let at_seed = chain.fk(&seed);
    let p0 = (at_seed.translation.vector - target_pose.translation.vector).norm();
    let r0 = (target_pose.rotation * at_seed.rotation.inverse()).angle();
    if s.attempt == 0 {
        assert!((s.history[0].0 - p0).abs() < 1e-12 && (s.history[0].1 - r0).abs() < 1e-9);
    }
    let last = *s.history.last().unwrap();
    assert_eq!(last, (s.position_error, s.orientation_error));
    for w in s.history.windows(2) {
        let (a, b) = (w[0].0.powi(2) + w[0].1.powi(2), w[1].0.powi(2) + w[1].1.powi(2));
        assert!(b <= a * (1.0 + 1e-12), "error rose: {w:?}");
    }
    let quiet = solve_ik(
        &chain,
        &target,
        Some(&seed),
        &IkParams::default(),
        4,
        Deadline::none(),
    )
    .unwrap();
    assert!(quiet.solutions[0].history.is_empty());
    assert_eq!(quiet.solutions[0].joints, s.joints);
}

/// A solver built on a lent workspace answers exactly as a fresh one (the StreamIk
/// session reuses one workspace for every target), and a workspace of another chain is
/// not reused.
#[test]
fn reused_workspace_gives_the_fresh_answer() {
    let panda = builtin_chain("franka_panda").unwrap();
    let ur5 = builtin_chain("ur5").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let params = IkParams::default();
    let mut workspace = IkWorkspace::new(&ur5); // wrong chain: must be replaced
    for i in 0..20 {
        let target = IkTarget::Pose(panda.fk(&random_joints(&panda, &mut rng)));
        let fresh = solve_ik(&panda, &target, None, &params, i, Deadline::none()).unwrap();
        let mut solver = IkSolver::with_workspace(&panda, workspace);
        let reused = solver.solve(&target, None, &params, i, Deadline::none()).unwrap();
        workspace = solver.into_workspace();
        assert_eq!(fresh.solutions.len(), reused.solutions.len(), "target {i}");
        for (a, b) in fresh.solutions.iter().zip(&reused.solutions) {
            assert_eq!(a.joints, b.joints, "target {i}");
            assert_eq!(a.iterations, b.iterations, "target {i}");
        }
        assert_eq!(fresh.total_iterations, reused.total_iterations, "target {i}");
    }
}

/// Newton solves for the new iterate `q_{k+1}`, so its SVD must be accurate to the
/// tolerance, not merely to the step (regression: with the IK steps' loose 1e-4
/// orthogonality it stalled at ~1e-4 and needed ~60 attempts per KR 210 target). On a
/// square full-rank arm it takes the Jacobian-inverse path, so it must need about as
/// few attempts.
#[test]
fn newton_svd_converges_like_the_jacobian_inverse_on_a_six_axis_arm() {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let targets: Vec<IkTarget> = (0..40)
        .map(|_| IkTarget::Pose(chain.fk(&random_joints(&chain, &mut rng))))
        .collect();
    let attempts = |method| {
        let p = jacobian_params(method, LinearSolverKind::SvdPseudoinverse);
        targets
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let r = solve_ik(&chain, t, None, &p, i as u64, Deadline::none()).unwrap();
                assert!(r.success(), "{method:?} target {i}");
                r.attempts
            })
            .sum::<usize>()
    };
    let (newton, ji) = (attempts(IkMethod::Newton), attempts(IkMethod::JacobianInverse));
    assert!(
        newton <= ji + ji / 2,
        "Newton {newton} attempts vs Jacobian inverse {ji}"
    );
}
