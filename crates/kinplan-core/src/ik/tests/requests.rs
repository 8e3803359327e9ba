//! What a request asks of the solver: determinism, several distinct solutions,
//! deadlines and cancellation, bad input, batches and their seeds.

use super::*;

/// Same input ⇒ same answer, including restarts and RLXA's random λ.
#[test]
fn deterministic_for_a_fixed_seed() {
    let chain = builtin_chain("franka_panda").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let target = IkTarget::Pose(chain.fk(&random_joints(&chain, &mut rng)));
    for solver in [
        LinearSolverKind::SvdPseudoinverse,
        LinearSolverKind::AngleRelaxation,
    ] {
        let p = IkParams {
            num_solutions: 3,
            linear_solver: solver,
            max_restarts: 60,
            ..IkParams::default()
        };
        let a = solve_ik(&chain, &target, None, &p, 77, Deadline::none()).unwrap();
        let b = solve_ik(&chain, &target, None, &p, 77, Deadline::none()).unwrap();
        let strip = |r: &IkResult| -> Vec<(Vec<f64>, usize, usize)> {
            r.solutions
                .iter()
                .map(|s| (s.joints.clone(), s.iterations, s.attempt))
                .collect()
        };
        assert_eq!(strip(&a), strip(&b));
        assert_eq!(a.total_iterations, b.total_iterations);
    }
}

/// `num_solutions` distinct answers, nearest to the seed first.
#[test]
fn multiple_distinct_solutions_ranked_by_seed_distance() {
    let chain = builtin_chain("ur5").unwrap();
    let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
    let target = IkTarget::Pose(chain.fk(&q));
    let p = IkParams {
        num_solutions: 4,
        max_restarts: 500,
        ..IkParams::default()
    };
    let r = solve_ik(&chain, &target, Some(&q), &p, 11, Deadline::none()).unwrap();
    assert_eq!(r.solutions.len(), 4);
    assert_eq!(r.stop_reason, IkStatus::Converged);
    assert_reaches(&chain, &target, &r, &p, "ur5 4 solutions");
    let d = |s: &IkSolution| s.joints.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    for w in r.solutions.windows(2) {
        assert!(d(&w[0]) <= d(&w[1]));
        assert!(
            w[0].joints
                .iter()
                .zip(&w[1].joints)
                .any(|(a, b)| (a - b).abs() >= p.distinct_tolerance)
        );
    }
    // the seed itself is a solution, so the first one is (almost) the seed
    assert!(d(&r.solutions[0]) < 1e-6);
}

/// An unreachable target with a tight budget returns promptly, flagged.
#[test]
fn tight_deadline_returns_promptly_with_time_budget() {
    let chain = builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
    let target = IkTarget::Position(Point3::new(5.0, 0.0, 0.0));
    for method in [
        IkMethod::LevenbergMarquardt,
        IkMethod::Ccd,
        IkMethod::Fabrik,
        IkMethod::LengthRelaxation,
    ] {
        let p = IkParams {
            method,
            max_restarts: usize::MAX,
            time_budget: Some(Duration::from_millis(3)),
            ..IkParams::default()
        };
        let t0 = Instant::now();
        let r = solve_ik(&chain, &target, None, &p, 1, Deadline::none()).unwrap();
        let took = t0.elapsed();
        assert_eq!(r.stop_reason, IkStatus::TimeBudget, "{method:?}");
        assert!(!r.success());
        let best = r.best_attempt.as_ref().expect("best attempt is reported");
        assert!(best.position_error > 3.0);
        // 3 ms budget; generous slack for a loaded 2-core machine
        assert!(took < Duration::from_millis(150), "{method:?} took {took:?}");
    }
}

/// The caller's deadline and `time_budget` both bound a solve; the earlier
/// stops it (TIME_BUDGET either way), a raised cancellation answers CANCELLED.
#[test]
fn the_earlier_of_deadline_and_time_budget_stops_the_solve() {
    let chain = builtin_chain("ur5").unwrap();
    let target = IkTarget::Position(Point3::new(5.0, 0.0, 0.0));
    let ms = Duration::from_millis;
    for (deadline_ms, budget) in [(5, None), (5, Some(ms(60_000))), (60_000, Some(ms(5)))] {
        let p = IkParams {
            max_restarts: usize::MAX,
            time_budget: budget,
            ..IkParams::default()
        };
        let t0 = Instant::now();
        let d = Deadline::at(t0 + ms(deadline_ms));
        let r = solve_ik(&chain, &target, None, &p, 1, d).unwrap();
        let took = t0.elapsed();
        assert_eq!(
            r.stop_reason,
            IkStatus::TimeBudget,
            "{deadline_ms} ms, {budget:?}"
        );
        assert!(took >= ms(5), "stopped before either limit: {took:?}");
        // generous slack for a loaded 2-core machine
        assert!(took < ms(150), "{deadline_ms} ms, {budget:?}: {took:?}");
    }
    let flag = std::sync::atomic::AtomicBool::new(true);
    let p = IkParams {
        max_restarts: usize::MAX,
        time_budget: Some(ms(60_000)),
        ..IkParams::default()
    };
    let r = solve_ik(
        &chain,
        &target,
        None,
        &p,
        1,
        Deadline::after(ms(60_000)).with_cancel(&flag),
    )
    .unwrap();
    assert_eq!(r.stop_reason, IkStatus::Cancelled);
    assert!(r.total_iterations <= 1);
}

/// A batch past its deadline answers every target TIME_BUDGET without an
/// attempt; a cancelled one answers CANCELLED.
#[test]
fn a_batch_past_its_deadline_answers_time_budget_and_a_cancelled_one_cancelled() {
    let chain = builtin_chain("ur5").unwrap();
    let targets = vec![IkTarget::Position(Point3::new(0.3, 0.1, 0.4)); 8];
    let p = IkParams::default();
    let past = Deadline::at(Instant::now() - Duration::from_millis(1));
    for r in solve_ik_batch(&chain, &targets, BatchSeeds::None, &p, 1, past) {
        let r = r.unwrap();
        assert_eq!((r.stop_reason, r.attempts), (IkStatus::TimeBudget, 0));
    }
    let gone = || true;
    let cancelled = Deadline::none().with_cancel(&gone);
    for r in solve_ik_batch(&chain, &targets, BatchSeeds::None, &p, 1, cancelled) {
        let r = r.unwrap();
        assert_eq!((r.stop_reason, r.attempts), (IkStatus::Cancelled, 0));
    }
}

#[test]
fn cancellation_is_checked_every_iteration() {
    let chain = builtin_chain("ur5").unwrap();
    let target = IkTarget::Position(Point3::new(5.0, 0.0, 0.0));
    let calls = AtomicUsize::new(0);
    let stop = || calls.fetch_add(1, Ordering::Relaxed) >= 25;
    let p = IkParams {
        max_restarts: usize::MAX,
        ..IkParams::default()
    };
    let r = solve_ik(&chain, &target, None, &p, 1, Deadline::none().with_cancel(&stop)).unwrap();
    assert_eq!(r.stop_reason, IkStatus::Cancelled);
    assert!(r.total_iterations <= 26);
}

#[test]
fn bad_inputs_are_errors() {
    let chain = builtin_chain("ur5").unwrap();
    let good = IkTarget::Pose(chain.fk(&[0.0; 6]));
    let p = IkParams::default();
    assert!(matches!(
        solve_ik(&chain, &good, Some(&[0.0; 5]), &p, 0, Deadline::none()),
        Err(IkError::WrongSeedLength { expected: 6, got: 5 })
    ));
    assert!(matches!(
        solve_ik(
            &chain,
            &good,
            Some(&[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]),
            &p,
            0,
            Deadline::none()
        ),
        Err(IkError::NonFiniteSeed { index: 1 })
    ));
    let nan = IkTarget::Position(Point3::new(f64::NAN, 0.0, 0.0));
    assert!(matches!(
        solve_ik(&chain, &nan, None, &p, 0, Deadline::none()),
        Err(IkError::NonFiniteTarget { .. })
    ));
    let skew = Isometry3::from_parts(
        Translation3::new(0.1, 0.2, 0.3),
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    );
    assert!(matches!(
        solve_ik(&chain, &IkTarget::Pose(skew), None, &p, 0, Deadline::none()),
        Err(IkError::NonUnitQuaternion { .. })
    ));
    assert!(matches!(
        IkTarget::from_position_quaternion([0.0; 3], [1.0, 1.0, 0.0, 0.0]),
        Err(IkError::NonUnitQuaternion { .. })
    ));
    for (bad, field) in [
        (
            IkParams {
                position_tolerance: 0.0,
                ..p
            },
            "position_tolerance",
        ),
        (
            IkParams {
                orientation_tolerance: f64::NAN,
                ..p
            },
            "orientation_tolerance",
        ),
        (
            IkParams {
                max_iterations: 0,
                ..p
            },
            "max_iterations",
        ),
        (
            IkParams {
                num_solutions: 0,
                ..p
            },
            "num_solutions",
        ),
        (IkParams { damping: -1.0, ..p }, "damping"),
        (IkParams { max_step: 0.0, ..p }, "max_step"),
        (
            IkParams {
                time_budget: Some(Duration::ZERO),
                ..p
            },
            "time_budget",
        ),
    ] {
        match solve_ik(&chain, &good, None, &bad, 0, Deadline::none()) {
            Err(IkError::InvalidParam { field: f, .. }) => assert_eq!(f.name(), field),
            other => panic!("{field}: expected InvalidParam, got {other:?}"),
        }
    }
    let bad_rlxa = IkParams {
        linear_solver: LinearSolverKind::AngleRelaxation,
        rlxa: crate::linalg::RlxaParams {
            tolerance: 0.0,
            ..p.rlxa
        },
        ..p
    };
    assert!(matches!(
        solve_ik(&chain, &good, None, &bad_rlxa, 0, Deadline::none()),
        Err(IkError::Linalg(_))
    ));
}

/// A batch gives exactly the answers of one-by-one solves with the per-index seeds,
/// whatever the thread count.
#[test]
fn batch_matches_sequential() {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let targets: Vec<IkTarget> = (0..16)
        .map(|_| IkTarget::Pose(chain.fk(&random_joints(&chain, &mut rng))))
        .collect();
    let p = IkParams::default();
    let a = solve_ik_batch(&chain, &targets, BatchSeeds::None, &p, 5, Deadline::none());
    let b = solve_ik_batch(&chain, &targets, BatchSeeds::None, &p, 5, Deadline::none());
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        let (x, y) = (x.as_ref().unwrap(), y.as_ref().unwrap());
        assert_reaches(&chain, &targets[k], x, &p, "batch");
        assert_eq!(x.solutions[0].joints, y.solutions[0].joints);
    }
}

/// Per-target seeds: with no restarts, each target lands on the branch of its
/// own seed (the solution nearest it), and a wrong seed length is an error
/// for every target.
#[test]
fn batch_per_target_seeds_keep_each_target_on_its_seeds_branch() {
    let chain = builtin_chain("ur5").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let qs: Vec<Vec<f64>> = (0..8).map(|_| random_joints(&chain, &mut rng)).collect();
    let targets: Vec<IkTarget> = qs.iter().map(|q| IkTarget::Pose(chain.fk(q))).collect();
    // seeds 0.05 rad away from the joints that made each target
    let seeds: Vec<f64> = qs.iter().flat_map(|q| q.iter().map(|v| v + 0.05)).collect();
    let p = IkParams {
        max_restarts: 0,
        ..IkParams::default()
    };
    let r = solve_ik_batch(
        &chain,
        &targets,
        BatchSeeds::PerTarget(&seeds),
        &p,
        1,
        Deadline::none(),
    );
    for (k, res) in r.iter().enumerate() {
        let res = res.as_ref().unwrap();
        assert_reaches(&chain, &targets[k], res, &p, "per-target seed");
        let far = res.solutions[0]
            .joints
            .iter()
            .zip(&qs[k])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(far < 1e-3, "target {k} left its seed's branch by {far}");
    }
    let short = solve_ik_batch(
        &chain,
        &targets,
        BatchSeeds::PerTarget(&seeds[..6]),
        &p,
        1,
        Deadline::none(),
    );
    assert!(
        short
            .iter()
            .all(|r| matches!(r, Err(IkError::WrongSeedLength { .. })))
    );
}
