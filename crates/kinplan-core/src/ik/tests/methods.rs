//! Each method reaches its targets: pose and position round trips, RLXA inside
//! the Jacobian methods, Newton + RLXA flagged, the heuristics, prismatic joints.

use super::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    /// FK(IK(x)) = x for full poses, every built-in arm, every Jacobian method with SVD.
    #[test]
    fn pose_roundtrip_jacobian_methods_svd(seed in any::<u64>()) {
        for arm in ARMS {
            let chain = builtin_chain(arm).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let target = IkTarget::Pose(chain.fk(&random_joints(&chain, &mut rng)));
            for method in [IkMethod::LevenbergMarquardt, IkMethod::JacobianInverse, IkMethod::Newton] {
                let p = jacobian_params(method, LinearSolverKind::SvdPseudoinverse);
                let r = solve_ik(&chain, &target, None, &p, solver_seed(seed), Deadline::none()).unwrap();
                if method == IkMethod::Newton && !r.success() {
                    // Newton (S2 eq. 29/30) has no damping and may stall on the 7-joint
                    // Panda even with restarts (seed 17532964656178293055): it must then
                    // say so and flag its best attempt, never claim a wrong answer.
                    assert!(r.best_attempt.is_some(), "{arm} Newton: failure without a best attempt");
                    continue;
                }
                assert_reaches(&chain, &target, &r, &p, &format!("{arm} {method:?}"));
            }
        }
    }

    /// Position-only targets: Jacobian methods and CCD on every arm, FABRIK on every arm
    /// (all revolute), every method on the planar chains.
    #[test]
    fn position_roundtrip(seed in any::<u64>()) {
        for arm in BUILTIN_NAMES {
            let chain = builtin_chain(arm).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let target = IkTarget::Position(Point3::from(chain.fk(&random_joints(&chain, &mut rng)).translation.vector));
            let mut methods = vec![IkMethod::LevenbergMarquardt, IkMethod::JacobianInverse];
            // CCD, FABRIK and length relaxation converge linearly with a rate that tends to
            // 1 at the workspace boundaries (a nearly stretched or fully folded planar arm
            // needs > 5 000 sweeps for 1e-5 m); those targets are left to the Jacobian methods.
            let planar = arm.starts_with("planar");
            let reach = chain.fk(&vec![0.0; chain.dof()]).translation.vector.norm();
            let d = target.position().norm();
            if !planar || (d < 0.97 * reach && d > 0.05 * reach) {
                methods.extend([IkMethod::Ccd, IkMethod::Fabrik]);
                if planar {
                    methods.push(IkMethod::LengthRelaxation);
                }
            }
            for method in methods {
                // CCD/FABRIK/LR converge linearly (slowly near a stretched or folded 2-link
                // arm): give them sweeps rather than restarts.
                let max_iterations = if method.is_jacobian_method() { 100 } else { 5_000 };
                let p = IkParams { method, max_restarts: 300, max_iterations, ..IkParams::default() };
                let r = solve_ik(&chain, &target, None, &p, solver_seed(seed), Deadline::none()).unwrap();
                assert_reaches(&chain, &target, &r, &p, &format!("{arm} {method:?}"));
            }
        }
    }
}

/// JI and LM with RLXA as the linear solver reach full poses (S2 §3: usable with both).
#[test]
fn pose_roundtrip_rlxa() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for arm in ARMS {
        let chain = builtin_chain(arm).unwrap();
        let target = IkTarget::Pose(chain.fk(&random_joints(&chain, &mut rng)));
        for method in [IkMethod::JacobianInverse, IkMethod::LevenbergMarquardt] {
            let p = jacobian_params(method, LinearSolverKind::AngleRelaxation);
            let r = solve_ik(&chain, &target, None, &p, 5, Deadline::none()).unwrap();
            assert_reaches(&chain, &target, &r, &p, &format!("{arm} {method:?}+RLXA"));
        }
    }
}

/// Newton + RLXA is implemented faithfully and reported, not claimed (S2 found it poor):
/// here it does not converge, and it must say so truthfully — no solution, the flagged
/// best attempt with a non-converged status, and an error that matches hand-written FK.
#[test]
fn newton_rlxa_returns_a_flagged_answer() {
    let chain = builtin_chain("planar_3").unwrap();
    let goal = Point3::new(0.5, 0.3, 0.0);
    let target = IkTarget::Position(goal);
    let p = IkParams {
        max_restarts: 3,
        ..jacobian_params(IkMethod::Newton, LinearSolverKind::AngleRelaxation)
    };
    let seed = chain.mid_limits();
    let r = solve_ik(&chain, &target, Some(&seed), &p, 1, Deadline::none()).unwrap();
    // No attempt converges: the answer is the flagged best attempt, after every
    // attempt (the seeded one and 3 restarts) ran out.
    assert!(!r.success());
    assert!(r.solutions.is_empty());
    let b = r.best_attempt.as_ref().expect("a flagged best attempt");
    assert_eq!(r.attempts, 4);
    assert!(
        matches!(b.status, IkStatus::Stalled | IkStatus::MaxIterations),
        "{:?}",
        b.status
    );
    assert!(matches!(
        r.stop_reason,
        IkStatus::Stalled | IkStatus::MaxIterations
    ));
    // Its reported error is the residual of planar FK written out by hand (three
    // links of 1/3 m, the tool at the end of the third), and it is truly above the
    // tolerance: the flag is not a false alarm.
    let (mut angle, mut x, mut y) = (0.0, 0.0, 0.0);
    for q in &b.joints {
        angle += q;
        x += angle.cos() / 3.0;
        y += angle.sin() / 3.0;
    }
    let by_hand = ((x - goal.x).powi(2) + (y - goal.y).powi(2)).sqrt();
    assert!(
        (by_hand - b.position_error).abs() < 1e-9,
        "{by_hand} vs {}",
        b.position_error
    );
    assert!(b.position_error > p.position_tolerance, "{}", b.position_error);
    assert!(
        b.joints
            .iter()
            .zip(chain.limits())
            .all(|(q, (lo, hi))| (lo..=hi).contains(q))
    );
    // It is the lowest-error attempt: the attempts are deterministic for a fixed
    // rng seed, so the best of the first k + 1 attempts cannot get worse with k,
    // and the four attempts do not all end equally.
    let best_of = |restarts: usize| {
        let p = IkParams {
            max_restarts: restarts,
            ..p
        };
        let r = solve_ik(&chain, &target, Some(&seed), &p, 1, Deadline::none()).unwrap();
        r.best().unwrap().position_error
    };
    let prefix: Vec<f64> = (0..=3).map(best_of).collect();
    assert!(prefix.windows(2).all(|w| w[1] <= w[0]), "{prefix:?}");
    assert!(prefix[3] < prefix[0], "{prefix:?}");
    assert_eq!(prefix[3], b.position_error);
    // ... and clearly better than the seed.
    let from_seed = (chain.fk(&seed).translation.vector - goal.coords).norm();
    assert!(
        by_hand < 0.5 * from_seed,
        "best attempt {by_hand} is not clearly better than the seed's {from_seed}"
    );
}

/// Heuristics converge on planar chains n = 2…10 from the stretched pose (S2 Tab. 7 setting).
#[test]
fn heuristics_converge_on_planar_chains() {
    for n in 2..=10 {
        let chain = builtin_chain(&format!("planar_{n}")).unwrap();
        let target = IkTarget::Position(Point3::new(0.4, 0.5, 0.0));
        for method in [IkMethod::Ccd, IkMethod::Fabrik, IkMethod::LengthRelaxation] {
            let p = IkParams {
                method,
                max_iterations: 10_000,
                position_tolerance: 1e-5,
                ..IkParams::default()
            };
            let r = solve_ik(&chain, &target, Some(&vec![0.0; n]), &p, 3, Deadline::none()).unwrap();
            assert_reaches(&chain, &target, &r, &p, &format!("planar_{n} {method:?}"));
        }
    }
}

/// CCD on a full pose target (orientation handled by the tool-point construction).
#[test]
fn ccd_reaches_a_nearby_pose() {
    let chain = builtin_chain("ur5").unwrap();
    let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
    let target = IkTarget::Pose(chain.fk(&q));
    let seed: Vec<f64> = q.iter().map(|v| v + 0.1).collect();
    let p = IkParams {
        method: IkMethod::Ccd,
        max_iterations: 20_000,
        max_restarts: 20,
        ..IkParams::default()
    };
    let r = solve_ik(&chain, &target, Some(&seed), &p, 3, Deadline::none()).unwrap();
    assert_reaches(&chain, &target, &r, &p, "ur5 CCD pose");
}

/// 3-D length relaxation with S2 Fig. 27 virtual joints reaches position targets on a
/// 3-D arm with offsets (UR5) and a 7-axis arm (Panda).
#[test]
fn length_relaxation_3d_reaches_positions() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    for arm in ["ur5", "franka_panda"] {
        let chain = builtin_chain(arm).unwrap();
        for _ in 0..3 {
            let target = IkTarget::Position(Point3::from(
                chain.fk(&random_joints(&chain, &mut rng)).translation.vector,
            ));
            let p = IkParams {
                method: IkMethod::LengthRelaxation,
                max_iterations: 2_000,
                max_restarts: 20,
                ..IkParams::default()
            };
            let r = solve_ik(&chain, &target, None, &p, 3, Deadline::none()).unwrap();
            assert_reaches(&chain, &target, &r, &p, &format!("{arm} 3-D length relaxation"));
        }
    }
}

const PRISMATIC_URDF: &str = r#"<robot name="rp">
  <link name="base_link"/><link name="a"/><link name="b"/><link name="tool0"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="a"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="0" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="tool0"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
</robot>"#;

fn prismatic_chain() -> Chain {
    parse_chain(PRISMATIC_URDF, &ChainSpec::default(), UrdfLimits::default()).unwrap()
}

/// CCD and LM handle prismatic joints; FABRIK / length relaxation refuse them by name.
#[test]
fn prismatic_joints() {
    let chain = prismatic_chain();
    assert_eq!(chain.dof(), 3);
    let target = IkTarget::Position(Point3::from(chain.fk(&[0.7, 0.3, -0.4]).translation.vector));
    for method in [IkMethod::Ccd, IkMethod::LevenbergMarquardt] {
        let p = IkParams {
            method,
            max_iterations: 2000,
            ..IkParams::default()
        };
        let r = solve_ik(&chain, &target, None, &p, 1, Deadline::none()).unwrap();
        assert_reaches(&chain, &target, &r, &p, &format!("prismatic {method:?}"));
    }
    for method in [IkMethod::Fabrik, IkMethod::LengthRelaxation] {
        let p = IkParams {
            method,
            ..IkParams::default()
        };
        match solve_ik(&chain, &target, None, &p, 1, Deadline::none()) {
            Err(IkError::MethodCannotServe { reason, .. }) => assert!(reason.contains("j2")),
            other => panic!("expected MethodCannotServe, got {other:?}"),
        }
    }
}

#[test]
fn orientation_target_refused_by_point_heuristics() {
    let chain = builtin_chain("planar_3").unwrap();
    let target = IkTarget::Pose(chain.fk(&[0.1, 0.2, 0.3]));
    for method in [IkMethod::Fabrik, IkMethod::LengthRelaxation] {
        let p = IkParams {
            method,
            ..IkParams::default()
        };
        assert!(matches!(
            solve_ik(&chain, &target, None, &p, 1, Deadline::none()),
            Err(IkError::MethodCannotServe { method: m, .. }) if m == method
        ));
    }
}
