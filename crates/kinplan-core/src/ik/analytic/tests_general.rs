//! The searched family (`searched_6r`): hand-made offset-wrist arms, each
//! solution checked by forward kinematics, the sampled configuration found,
//! and Levenberg–Marquardt from many seeds finding nothing the search missed.

use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::tests::{every_analytic_solution, lm_finds_none_missing, pose_close, same_angles, solve_at};
use super::*;
use crate::ik::IkParams;
use crate::robot::{Chain, ChainSpec, UrdfLimits, parse_chain};

/// A 6R arm from `(origin xyz, axis xyz)` per joint (parent-frame origins,
/// limits ±3.2 rad) and a flange offset.
fn arm_urdf(name: &str, joints: [(&str, &str); 6], flange: &str) -> String {
    let mut s = format!(r#"<robot name="{name}"><link name="base"/>"#);
    for i in 1..=6 {
        s += &format!(r#"<link name="l{i}"/>"#);
    }
    s += r#"<link name="tool"/>"#;
    for (i, (xyz, axis)) in joints.iter().enumerate() {
        let parent = if i == 0 {
            "base".to_string()
        } else {
            format!("l{i}")
        };
        s += &format!(
            r#"<joint name="j{n}" type="revolute"><parent link="{parent}"/><child link="l{n}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>"#,
            n = i + 1
        );
    }
    s += &format!(
        r#"<joint name="flange" type="fixed"><parent link="l6"/><child link="tool"/><origin xyz="{flange}"/></joint></robot>"#
    );
    s
}

/// Axes 2, 3 parallel with a shoulder offset; axes 4 and 5 meet, axis 6 is
/// 0.08 m off their meeting point and tilted: no three axes meet and no
/// three are parallel, from either end. Joint 6 is searched.
fn offset_wrist_45() -> Chain {
    chain(&arm_urdf(
        "offset_45",
        [
            ("0 0 0", "0 0 1"),
            ("0.1 0 0.4", "0 1 0"),
            ("0 0 0.8", "0 1 0"),
            ("0.2 0 0.1", "1 0 0"),
            ("0.6 0 0", "0 1 0"),
            ("0.1 0 0.08", "1 0 0.3"),
        ],
        "0.1 0.02 0",
    ))
}

/// As [`offset_wrist_45`] but axes 5 and 6 meet and axis 4 passes 0.07 m
/// from them. Joint 4 is searched.
fn offset_wrist_56() -> Chain {
    chain(&arm_urdf(
        "offset_56",
        [
            ("0 0 0", "0 0 1"),
            ("0.1 0 0.4", "0 1 0"),
            ("0 0 0.8", "0 1 0"),
            ("0.2 0 0.1", "1 0 0"),
            ("0.6 0 0.07", "0 1 0"),
            ("0 0 0", "1 0 0.3"),
        ],
        "0.15 0 0.02",
    ))
}

/// Axes 1, 2 meet (a UR-like shoulder) and axis 3 is tilted out of parallel
/// with axis 2; axes 4, 5 meet, axis 6 offset. Joint 6 is searched.
fn offset_tilted_elbow() -> Chain {
    chain(&arm_urdf(
        "offset_tilted",
        [
            ("0 0 0", "0 0 1"),
            ("0 0 0.4", "0 1 0"),
            ("0 0 0.8", "0 1 0.4"),
            ("0.2 0 0.1", "1 0 0"),
            ("0.6 0 0", "0 1 0"),
            ("0.1 0 0.08", "1 0 0.3"),
        ],
        "0.1 0 0",
    ))
}

/// Covered only from the tool end: axes 1, 2 meet and axes 2, 3 meet at
/// another point (no spherical shoulder), axes 4, 5 parallel, axis 6 passes
/// 0.05 m from axis 5. Read from the tool, axes 5, 4 are parallel and axes
/// 3, 2 meet; joint 1 is searched.
fn reversed_only() -> Chain {
    chain(&arm_urdf(
        "reversed_only",
        [
            ("0 0 0", "0 0 1"),
            ("0 0 0.3", "0 1 0"),
            ("0 0.2 0", "1 0 0"),
            ("0.5 0 0.1", "0 1 0"),
            ("0.4 0 0", "0 1 0"),
            ("0.1 0 0.05", "1 0 0"),
        ],
        "0.1 0 0",
    ))
}

fn chain(urdf: &str) -> Chain {
    parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap()
}

fn random_q(rng: &mut ChaCha8Rng) -> [f64; 6] {
    std::array::from_fn(|_| rng.random_range(-3.1..=3.1))
}

fn nearest() -> AnalyticParams {
    AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    }
}

/// `n` random configurations: every solution reproduces the pose to 1e-9 m /
/// rad, the configuration the pose came from is among them, and its flags
/// are those `config_of` gives.
fn round_trip(chain: &Chain, reversed: bool, n: usize) -> usize {
    let arm = AnalyticArm::new(chain, 1e-9).unwrap();
    assert_eq!(arm.family(), Family::Searched6R, "{}", chain.name());
    assert_eq!(arm.is_reversed(), reversed, "{}", chain.name());
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut out = Vec::new();
    let mut total = 0;
    for _ in 0..n {
        let q = random_q(&mut rng);
        let t = chain.fk(&q);
        arm.solve_into(&t, Some(&q), &nearest(), &mut out);
        total += out.len();
        let same = out.iter().find(|s| same_angles(&s.joints, &q, 1e-7));
        let Some(same) = same else {
            panic!(
                "{}: {q:?} not among {:?}",
                chain.name(),
                out.iter().map(|s| s.joints).collect::<Vec<_>>()
            )
        };
        assert_eq!(same.config, arm.config_of(&q), "{}", chain.name());
        for s in &out {
            assert!(s.exact && s.joints.iter().all(|v| v.is_finite()));
            assert!(
                pose_close(&chain.fk(&s.joints), &t, 1e-9),
                "{}: {:?} for {q:?}",
                chain.name(),
                s.joints
            );
        }
        // no solution twice
        for (i, a) in out.iter().enumerate() {
            assert!(
                !out[i + 1..]
                    .iter()
                    .any(|b| same_angles(&a.joints, &b.joints, 1e-9))
            );
        }
    }
    total
}

#[test]
fn offset_wrist_4_5_round_trips() {
    let total = round_trip(&offset_wrist_45(), false, 200);
    // a general 6R pose has an even number of real solutions, at least 2
    assert!(total >= 2 * 200, "{total}");
}

#[test]
fn offset_wrist_5_6_round_trips() {
    round_trip(&offset_wrist_56(), false, 200);
}

#[test]
fn tilted_elbow_round_trips() {
    round_trip(&offset_tilted_elbow(), false, 200);
}

#[test]
fn reversed_searched_arm_round_trips() {
    round_trip(&reversed_only(), true, 200);
}

#[test]
fn numerical_search_finds_nothing_the_1d_search_missed() {
    // Levenberg–Marquardt from 64 random seeds per pose: each converged
    // answer must be one of the searched solutions (modulo whole turns).
    for chain in [offset_wrist_45(), offset_wrist_56(), reversed_only()] {
        let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let lm = IkParams {
            max_restarts: 0,
            position_tolerance: 1e-10,
            orientation_tolerance: 1e-10,
            max_iterations: 200,
            ..IkParams::default()
        };
        let mut out = Vec::new();
        let mut found = 0;
        for _ in 0..4 {
            let q = random_q(&mut rng);
            let t = chain.fk(&q);
            arm.solve_into(&t, None, &nearest(), &mut out);
            found += lm_finds_none_missing(
                &chain,
                &t,
                &lm,
                &out,
                64,
                || random_q(&mut rng).to_vec(),
                chain.name(),
            );
        }
        assert!(found > 64, "{}: LM converged only {found} times", chain.name());
    }
}

#[test]
fn searched_arm_through_solve_ik_and_its_refusals() {
    let chain = offset_wrist_56();
    let q = [0.4, -0.9, 0.7, 1.0, 0.8, -0.5];
    let params = every_analytic_solution();
    let r = solve_at(&chain, &q, &params).unwrap();
    assert!(r.success());
    assert!(same_angles(&r.solutions[0].joints, &q, 1e-8));
    assert!(
        r.solutions
            .iter()
            .all(|s| s.position_error < 1e-9 && s.config.is_some())
    );
    let analysed = analyse(&chain, &AnalyticParams::default(), None).unwrap();
    assert_eq!(analysed.arm.family().name(), "searched_6r");
    // too few samples are refused, naming the field
    let few = IkParams {
        analytic: AnalyticParams {
            search_samples: 4,
            ..AnalyticParams::default()
        },
        ..params
    };
    let e = solve_at(&chain, &q, &few).unwrap_err();
    assert!(e.to_string().contains("search_samples"), "{e}");
    // an unreachable pose: none, and finite least-squares answers
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    let far = Isometry3::translation(5.0, 0.0, 0.0);
    let mut out = Vec::new();
    arm.solve_into(&far, None, &AnalyticParams::default(), &mut out);
    assert!(out.is_empty());
    arm.nearest(&far, None, &AnalyticParams::default(), &mut out);
    assert!(
        out.iter()
            .all(|s| !s.exact && s.joints.iter().all(|v| v.is_finite()))
    );
}

#[test]
fn no_meeting_wrist_pair_is_not_analytic_and_says_why() {
    // offset_wrist_45 with axis 5 moved 0.07 m off axis 4: no two consecutive
    // wrist axes meet, from either end
    let chain = chain(&arm_urdf(
        "general",
        [
            ("0 0 0", "0 0 1"),
            ("0.1 0 0.4", "0 1 0"),
            ("0 0 0.8", "0 1 0"),
            ("0.2 0 0.1", "1 0 0"),
            ("0.6 0 0.07", "0 1 0"),
            ("0.1 0 0.08", "1 0 0.3"),
        ],
        "0.1 0 0",
    ));
    let reason = AnalyticArm::new(&chain, 1e-9).unwrap_err().reason;
    assert!(reason.contains("wrist axes that meet"), "{reason}");
    assert!(reason.contains("read from the tool end"), "{reason}");
}

#[test]
fn more_samples_find_the_same_solutions() {
    // the default sampling already brackets every root of these poses: 4096
    // samples add none
    let chain = offset_wrist_45();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    let dense = AnalyticParams {
        search_samples: 4096,
        ..nearest()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..10 {
        let t = chain.fk(&random_q(&mut rng));
        arm.solve_into(&t, None, &nearest(), &mut a);
        arm.solve_into(&t, None, &dense, &mut b);
        assert_eq!(a.len(), b.len());
        assert!(
            b.iter()
                .all(|s| a.iter().any(|x| same_angles(&x.joints, &s.joints, 1e-9)))
        );
    }
}
