//! Round trips on the built-in arms, hand-made arms with hand-derived
//! solutions, singular poses, refusals, and a numerical cross-check.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::ik::{IkMethod, IkParams, IkTarget, solve_ik};
use crate::robot::{Chain, ChainSpec, UrdfLimits, builtin_chain, parse_chain};

pub(super) fn pose_close(a: &Isometry3<f64>, b: &Isometry3<f64>, tol: f64) -> bool {
    (a.translation.vector - b.translation.vector).norm() <= tol && a.rotation.angle_to(&b.rotation) <= tol
}

fn random_q(chain: &Chain, rng: &mut ChaCha8Rng) -> [f64; 6] {
    std::array::from_fn(|i| {
        let j = &chain.joints()[i];
        let (lo, hi) = (j.lower.max(-2.0 * PI), j.upper.min(2.0 * PI));
        rng.random_range(lo..=hi)
    })
}

/// Analytic IK asking for every solution.
pub(super) fn every_analytic_solution() -> IkParams {
    IkParams {
        method: IkMethod::Analytic,
        num_solutions: 1000,
        ..IkParams::default()
    }
}

/// `solve_ik` at the pose `chain.fk(q)`, seeded at `q`.
pub(super) fn solve_at(
    chain: &Chain,
    q: &[f64],
    params: &IkParams,
) -> Result<crate::ik::IkResult, crate::ik::IkError> {
    solve_ik(
        chain,
        &IkTarget::Pose(chain.fk(q)),
        Some(q),
        params,
        0,
        crate::Deadline::none(),
    )
}

/// Levenberg–Marquardt (`lm`) at `t` from `runs` seeds drawn by `seed`: every
/// answer it converges to is one of `ours` (angles within 1e-6, modulo whole
/// turns). Returns how many runs converged.
pub(super) fn lm_finds_none_missing(
    chain: &Chain,
    t: &Isometry3<f64>,
    lm: &IkParams,
    ours: &[AnalyticSolution],
    runs: usize,
    mut seed: impl FnMut() -> Vec<f64>,
    what: &str,
) -> usize {
    let mut found = 0;
    for _ in 0..runs {
        let seed = seed();
        let r = solve_ik(
            chain,
            &IkTarget::Pose(*t),
            Some(&seed),
            lm,
            0,
            crate::Deadline::none(),
        )
        .unwrap();
        if let Some(s) = r.solutions.first() {
            found += 1;
            assert!(
                ours.iter().any(|a| same_angles(&a.joints, &s.joints, 1e-6)),
                "{what}: LM found {:?}, not among {:?}",
                s.joints,
                ours.iter().map(|a| a.joints).collect::<Vec<_>>()
            );
        }
    }
    found
}

pub(super) fn same_angles(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| wrap(x - y).abs() <= tol)
}

/// Every solution reproduces the pose to 1e-9 and lies inside the limits; the
/// configuration the pose came from is among them (exactly, with
/// `Turns::NearestSeed` and the configuration as the seed).
fn round_trip(name: &str, family: Family, n: usize) {
    let chain = builtin_chain(name).unwrap();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    assert_eq!(arm.family(), family, "{name}");
    let params = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut out = Vec::new();
    let mut total = 0;
    for _ in 0..n {
        let q = random_q(&chain, &mut rng);
        let t = chain.fk(&q);
        arm.solve_into(&t, Some(&q), &params, &mut out);
        total += out.len();
        assert!(
            out.iter()
                .any(|s| s.joints.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-8)),
            "{name}: {q:?} not among {:?}",
            out.iter().map(|s| s.joints).collect::<Vec<_>>()
        );
        for s in &out {
            assert!(
                pose_close(&chain.fk(&s.joints), &t, 1e-9),
                "{name}: {:?} for {q:?}",
                s.joints
            );
            for (v, j) in s.joints.iter().zip(chain.joints()) {
                assert!(*v >= j.lower && *v <= j.upper, "{name}: {v} outside {}", j.name);
            }
        }
        let same = out
            .iter()
            .find(|s| s.joints.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-8));
        assert_eq!(same.unwrap().config, arm.config_of(&q), "{name}");
    }
    // the flags tell the (up to 8) configurations apart
    assert!(total >= 4 * n, "{name}: only {total} solutions for {n} poses");
}

#[test]
fn round_trip_kr210() {
    round_trip("kuka_kr210_r2700_extra", Family::SphericalWrist, 10_000);
}
#[test]
fn round_trip_kr120() {
    round_trip("kuka_kr120_r2500_pro", Family::SphericalWrist, 10_000);
}
#[test]
fn round_trip_irb4600() {
    round_trip("abb_irb4600_60_205", Family::SphericalWrist, 10_000);
}
#[test]
fn round_trip_ur5() {
    round_trip("ur5", Family::ThreeParallel, 10_000);
}

#[test]
fn configurations_are_distinct_flags() {
    // a generic UR5 pose has 8 solutions in (−π, π] with 8 different flag triples
    let chain = builtin_chain("ur5").unwrap();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
    let mut out = Vec::new();
    let params = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    arm.solve_into(&chain.fk(&q), None, &params, &mut out);
    assert_eq!(out.len(), 8);
    let flags: std::collections::HashSet<_> = out.iter().map(|s| s.config).collect();
    assert_eq!(flags.len(), 8);
    // every joint of the UR5 spans ±2π: each of the 6 joints has 2 turn variants
    arm.solve_into(&chain.fk(&q), None, &AnalyticParams::default(), &mut out);
    assert_eq!(out.len(), 8 * 64);
}

const SPHERICAL_ARM: &str = r#"<robot name="hand_spherical">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/><link name="l6"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="l5"/><child link="l6"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="l6"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>
</robot>"#;

const PARALLEL_ARM: &str = r#"<robot name="hand_parallel">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/><link name="l6"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="1 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/><origin xyz="1 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="l5"/><child link="l6"/><origin xyz="0 0 -0.5"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="l6"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>
</robot>"#;

fn hand_arm(urdf: &str) -> (Chain, AnalyticArm) {
    let chain = parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    (chain, arm)
}

fn nearest_params() -> AnalyticParams {
    AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    }
}

#[test]
fn spherical_hand_arm_has_the_hand_derived_solutions() {
    // Shoulder at the origin, upper arm 1 m up, forearm 1 m forward, wrist
    // (x, y, x axes) at (1, 0, 1), flange 0.5 m further; target: the pose of
    // q = (0, 0, 0, 0, π/4, 0). The wrist centre is reached with the shoulder
    // in front (q₁ = 0) by (q₂, q₃) = (0, 0) and (π/2, −π) (upper arm forward,
    // forearm up), behind (q₁ = π) by (0, π) and (−π/2, 0). The wrist then
    // undoes R₁₂₃: R₃₆ = rot(y, π/4), rot(y, 3π/4), rot(x, π) rot(y, π/4) and
    // rot(x, π) rot(y, 3π/4) (using rot(z, π) = rot(x, π) rot(y, π)), each
    // solved by (q₄, q₅, q₆) = (a, b, c) and its flip (a + π, −b, c + π).
    let (chain, arm) = hand_arm(SPHERICAL_ARM);
    assert_eq!(arm.family(), Family::SphericalWrist);
    let t = chain.fk(&[0.0, 0.0, 0.0, 0.0, FRAC_PI_4, 0.0]);
    let mut out = Vec::new();
    arm.solve_into(&t, None, &nearest_params(), &mut out);
    assert_eq!(out.len(), 8);
    let q4 = FRAC_PI_4;
    let q34 = 3.0 * FRAC_PI_4;
    for want in [
        [0.0, 0.0, 0.0, 0.0, q4, 0.0],
        [0.0, 0.0, 0.0, PI, -q4, PI],
        [0.0, FRAC_PI_2, -PI, 0.0, q34, 0.0],
        [0.0, FRAC_PI_2, -PI, PI, -q34, PI],
        [PI, 0.0, PI, PI, q4, 0.0],
        [PI, 0.0, PI, 0.0, -q4, PI],
        [PI, -FRAC_PI_2, 0.0, PI, q34, 0.0],
        [PI, -FRAC_PI_2, 0.0, 0.0, -q34, PI],
    ] {
        assert!(
            out.iter().any(|s| same_angles(&s.joints, &want, 1e-12)),
            "{want:?} missing from {:?}",
            out.iter().map(|s| s.joints).collect::<Vec<_>>()
        );
    }
    for s in &out {
        assert!(pose_close(&chain.fk(&s.joints), &t, 1e-12));
        assert!(!s.singular);
    }
    // the shoulder flag separates q₁ = 0 from q₁ = π
    for s in &out {
        assert_eq!(
            s.config.shoulder_back,
            wrap(s.joints[0] - PI).abs() < 1e-9,
            "{:?}",
            s.joints
        );
    }
}

#[test]
fn parallel_hand_arm_has_the_mirrored_elbow() {
    // Equal 1 m links on parallel axes 2, 3, 4: the elbow mirror of (q₂, q₃, q₄)
    // is (q₂ + q₃, −q₃, q₄ + q₃) with q₁, q₅, q₆ unchanged.
    let (chain, arm) = hand_arm(PARALLEL_ARM);
    assert_eq!(arm.family(), Family::ThreeParallel);
    // (p₄ stays within 1.72 m of the shoulder whatever the wrist does, so all 8 exist)
    let q = [0.0, 1.2, -2.4, 0.3, 0.4, 0.5];
    let mirror = [0.0, -1.2, 2.4, -2.1, 0.4, 0.5];
    let t = chain.fk(&q);
    let mut out = Vec::new();
    arm.solve_into(&t, None, &nearest_params(), &mut out);
    assert_eq!(out.len(), 8);
    let a = out.iter().find(|s| same_angles(&s.joints, &q, 1e-12)).unwrap();
    let b = out
        .iter()
        .find(|s| same_angles(&s.joints, &mirror, 1e-12))
        .unwrap();
    assert_ne!(a.config.elbow_down, b.config.elbow_down);
    assert_eq!(a.config.shoulder_back, b.config.shoulder_back);
    for s in &out {
        assert!(pose_close(&chain.fk(&s.joints), &t, 1e-12));
    }
}

#[test]
fn wrist_singularity_gives_the_seeds_wrist_angle() {
    // KR 210 at q₅ = 0: axes 4 and 6 line up, only q₄ + q₆ (here, with these
    // axis signs) is fixed; q₄ takes the seed's value and q₆ follows.
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    let q = [0.1, -0.5, 0.4, 0.7, 0.0, 0.2];
    let t = chain.fk(&q);
    let mut out = Vec::new();
    let seed = [0.0, 0.0, 0.0, 0.5, 0.0, 0.0];
    arm.solve_into(&t, Some(&seed), &nearest_params(), &mut out);
    assert!(!out.is_empty());
    for s in &out {
        assert!(s.joints.iter().all(|v| v.is_finite()));
        assert!(pose_close(&chain.fk(&s.joints), &t, 1e-9));
    }
    let on_branch = out
        .iter()
        .find(|s| same_angles(&s.joints[..3], &q[..3], 1e-9) && s.joints[4].abs() < 1e-6)
        .unwrap();
    assert!(on_branch.singular);
    assert!((on_branch.joints[3] - 0.5).abs() < 1e-9);
    // q₄ + q₆ is what the pose fixes: 0.7 + 0.2
    assert!(wrap(on_branch.joints[3] + on_branch.joints[5] - 0.9).abs() < 1e-9);
}

#[test]
fn shoulder_singularity_gives_the_seeds_base_angle() {
    // Hand arm with the wrist centre on axis 1 (upper arm −45°, forearm +45°
    // above the horizontal: w = (0, 0, √2)): q₁ is free and taken from the seed.
    let (chain, arm) = hand_arm(SPHERICAL_ARM);
    let q = [0.3, -FRAC_PI_4, 0.0, 0.2, 0.5, 0.1];
    let t = chain.fk(&q);
    let mut out = Vec::new();
    arm.solve_into(&t, Some(&q), &nearest_params(), &mut out);
    assert!(!out.is_empty());
    assert!(
        out.iter()
            .all(|s| s.singular && (s.joints[0] - 0.3).abs() < 1e-12)
    );
    assert!(out.iter().any(|s| same_angles(&s.joints, &q, 1e-9)));
    for s in &out {
        assert!(s.joints.iter().all(|v| v.is_finite()));
        assert!(pose_close(&chain.fk(&s.joints), &t, 1e-9));
    }
}

#[test]
fn unreachable_pose_gives_none_and_finite_nearest() {
    let chain = builtin_chain("ur5").unwrap();
    let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    let far = Isometry3::translation(5.0, 0.0, 0.0);
    let mut out = Vec::new();
    arm.solve_into(&far, None, &AnalyticParams::default(), &mut out);
    assert!(out.is_empty());
    arm.nearest(&far, None, &AnalyticParams::default(), &mut out);
    assert!(!out.is_empty());
    assert!(
        out.iter()
            .all(|s| !s.exact && s.joints.iter().all(|v| v.is_finite()))
    );
}

#[test]
fn not_analytic_says_why() {
    let e = |name: &str| {
        AnalyticArm::new(&builtin_chain(name).unwrap(), 1e-9)
            .unwrap_err()
            .reason
    };
    assert!(e("franka_panda").contains("7 joints"));
    assert!(e("planar_6").contains("axes 1 and 2 are parallel"));
    // the spherical arm with its wrist centre moved off axis 6
    let bent = SPHERICAL_ARM.replace(
        r#"<origin xyz="0 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="flange""#,
        r#"<origin xyz="0 0 0.1"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="flange""#,
    );
    // is no closed form, but axes 4, 5 still meet: the searched family
    let chain = parse_chain(&bent, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    assert_eq!(
        AnalyticArm::new(&chain, 1e-9).unwrap().family(),
        Family::Searched6R
    );
}

#[test]
fn solve_ik_analytic_ranks_and_refuses() {
    let chain = builtin_chain("kuka_kr120_r2500_pro").unwrap();
    let q = [0.4, -0.9, 0.7, 1.0, 0.8, -0.5];
    let params = every_analytic_solution();
    let r = solve_at(&chain, &q, &params).unwrap();
    assert!(r.success());
    assert!(same_angles(&r.solutions[0].joints, &q, 1e-9));
    let d = |s: &crate::ik::IkSolution| s.joints.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    assert!(r.solutions.windows(2).all(|w| d(&w[0]) <= d(&w[1])));
    assert!(r.solutions.iter().all(|s| s.config.is_some()));
    // position targets and non-analytic chains are refused, naming why
    let pos = IkTarget::Position(nalgebra::Point3::new(1.0, 0.0, 1.0));
    assert!(solve_ik(&chain, &pos, None, &params, 0, crate::Deadline::none()).is_err());
    let planar = builtin_chain("planar_7").unwrap();
    let e = solve_ik(
        &planar,
        &IkTarget::Pose(planar.fk(&[0.0; 7])),
        None,
        &params,
        0,
        crate::Deadline::none(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("chain is not analytic"), "{e}");
}

#[test]
fn numerical_search_finds_nothing_the_analytic_solver_missed() {
    // 64 Levenberg–Marquardt runs from random seeds per pose: each converged
    // answer must be one of the analytic solutions (modulo whole turns).
    for name in ["ur5", "kuka_kr210_r2700_extra"] {
        let chain = builtin_chain(name).unwrap();
        let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let lm = IkParams {
            max_restarts: 0,
            position_tolerance: 1e-9,
            orientation_tolerance: 1e-9,
            ..IkParams::default()
        };
        let mut out = Vec::new();
        for _ in 0..3 {
            let q = random_q(&chain, &mut rng);
            let t = chain.fk(&q);
            arm.solve_into(&t, None, &nearest_params(), &mut out);
            lm_finds_none_missing(
                &chain,
                &t,
                &lm,
                &out,
                64,
                || random_q(&chain, &mut rng).to_vec(),
                name,
            );
        }
    }
}

const SHOULDER_ARM: &str = r#"<robot name="hand_shoulder">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/><link name="l6"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0 0 1"/><axis xyz="1 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="l5"/><child link="l6"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="l6"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>
</robot>"#;

#[test]
fn spherical_shoulder_hand_arm_has_the_hand_derived_positions() {
    // Shoulder axes z, y meet at the origin; upper arm 1 m up; elbow about
    // (1, 1, 0)/√2; forearm 1 m along x. The forearm at elbow angle θ is
    // (½ + ½cos θ, ½ − ½cos θ, −sin θ/√2), so ‖w − s‖² = 2 − √2 sin θ. For
    // the zero pose (w = (1, 0, 1)): θ = 0 with (q₁, q₂) = (0, 0) or
    // (π, −π/2) (upper arm to −x, then turned round), and θ = π (forearm
    // along y, w₀ = (0, 1, 1)) with q₂ = 0 tangent and q₁ = −π/2.
    let (chain, arm) = hand_arm(SHOULDER_ARM);
    assert_eq!(arm.family(), Family::SphericalTwoIntersecting);
    let t = chain.fk(&[0.0, 0.0, 0.0, 0.0, FRAC_PI_4, 0.0]);
    let mut out = Vec::new();
    arm.solve_into(&t, None, &nearest_params(), &mut out);
    for want in [[0.0, 0.0, 0.0], [PI, -FRAC_PI_2, 0.0], [-FRAC_PI_2, 0.0, PI]] {
        assert!(
            out.iter().any(|s| same_angles(&s.joints[..3], &want, 1e-7)),
            "{want:?} missing from {:?}",
            out.iter().map(|s| s.joints).collect::<Vec<_>>()
        );
    }
    assert!(out.iter().all(|s| pose_close(&chain.fk(&s.joints), &t, 1e-9)));
    // and random configurations come back
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..2000 {
        let q: [f64; 6] = std::array::from_fn(|_| rng.random_range(-3.0..3.0));
        let t = chain.fk(&q);
        arm.solve_into(&t, Some(&q), &nearest_params(), &mut out);
        assert!(out.iter().any(|s| same_angles(&s.joints, &q, 1e-7)), "{q:?}");
        assert!(out.iter().all(|s| pose_close(&chain.fk(&s.joints), &t, 1e-9)));
    }
}

#[test]
fn iiwa_with_joint_3_held_round_trips() {
    let chain = builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let params = IkParams {
        method: IkMethod::Analytic,
        num_solutions: 1000,
        analytic: nearest_params(),
        ..IkParams::default()
    };
    for _ in 0..1000 {
        let q: Vec<f64> = chain
            .joints()
            .iter()
            .map(|j| rng.random_range(j.lower..=j.upper))
            .collect();
        let t = chain.fk(&q);
        let reduced = analyse(&chain, &params.analytic, Some(&q)).unwrap();
        assert_eq!(reduced.held, Some((2, q[2])));
        let r = solve_ik(
            &chain,
            &IkTarget::Pose(t),
            Some(&q),
            &params,
            0,
            crate::Deadline::none(),
        )
        .unwrap();
        assert!(r.success(), "{q:?}");
        assert!(
            same_angles(&r.solutions[0].joints, &q, 1e-7),
            "{q:?} vs {:?}",
            r.solutions[0].joints
        );
        for s in &r.solutions {
            assert_eq!(s.joints.len(), 7);
            assert_eq!(s.joints[2], q[2]);
            assert!(pose_close(&chain.fk(&s.joints), &t, 1e-9));
        }
    }
}

#[test]
fn analytic_start_puts_lm_on_the_nearest_closed_form_solution() {
    // from a far seed, LM started from the nearest analytic solution needs no
    // iteration beyond checking it, and answers exactly that solution
    let chain = builtin_chain("ur5").unwrap();
    let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
    let seed = [1.5, -0.2, 0.3, 0.9, -0.7, 1.4];
    let t = IkTarget::Pose(chain.fk(&q));
    let lm = IkParams {
        max_restarts: 0,
        analytic_start: true,
        ..IkParams::default()
    };
    let r = solve_ik(&chain, &t, Some(&seed), &lm, 0, crate::Deadline::none()).unwrap();
    assert!(r.success());
    assert_eq!(r.solutions[0].iterations, 0);
    let all = solve_ik(
        &chain,
        &t,
        Some(&seed),
        &IkParams {
            method: IkMethod::Analytic,
            analytic: nearest_params(),
            ..IkParams::default()
        },
        0,
        crate::Deadline::none(),
    )
    .unwrap();
    assert!(same_angles(
        &r.solutions[0].joints,
        &all.solutions[0].joints,
        1e-12
    ));
    // without it, the same LM attempt iterates
    let plain = solve_ik(
        &chain,
        &t,
        Some(&seed),
        &IkParams {
            analytic_start: false,
            ..lm
        },
        0,
        crate::Deadline::none(),
    )
    .unwrap();
    assert!(plain.solutions.first().is_none_or(|s| s.iterations > 0));
}

/// The analytic method looks at the deadline: a passed one or a raised
/// cancellation answers as such, with no solution, where a live one solves.
#[test]
fn the_analytic_method_stops_at_the_deadline_and_on_cancellation() {
    use crate::Deadline;
    use crate::ik::IkStatus;
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let q = [0.2, -1.2, 1.1, 0.3, 0.4, -0.5];
    let target = IkTarget::Pose(chain.fk(&q));
    let params = IkParams {
        method: IkMethod::Analytic,
        num_solutions: 8,
        ..IkParams::default()
    };
    let live = solve_ik(&chain, &target, Some(&q), &params, 0, Deadline::none()).unwrap();
    assert_eq!(live.stop_reason, IkStatus::Converged);
    assert!(!live.solutions.is_empty());
    let past = std::time::Instant::now() - std::time::Duration::from_millis(1);
    let late = solve_ik(&chain, &target, Some(&q), &params, 0, Deadline::at(past)).unwrap();
    assert_eq!(late.stop_reason, IkStatus::TimeBudget);
    assert!(late.solutions.is_empty());
    let gone = std::sync::atomic::AtomicBool::new(true);
    let cancelled = solve_ik(
        &chain,
        &target,
        Some(&q),
        &params,
        0,
        Deadline::none().with_cancel(&gone),
    )
    .unwrap();
    assert_eq!(cancelled.stop_reason, IkStatus::Cancelled);
}

/// Every whole-turn variant of `base` by brute force: per joint, each
/// `q + 2πk` (k = −12..=12) within 1e-9 of the limits, clamped onto them; when
/// more than `MAX_TURNS` lie inside, the one nearest zero and then alternately
/// the next below and above it. A continuous joint keeps its angle.
fn brute_force_turns(chain: &Chain, base: &[AnalyticSolution]) -> Vec<AnalyticSolution> {
    let mut want = Vec::new();
    for s in base {
        let mut rows = vec![*s];
        for (i, j) in chain.joints().iter().enumerate() {
            let q = wrap(s.joints[i]);
            let mut ks: Vec<i32> = if j.kind == crate::robot::JointKind::Continuous {
                vec![0]
            } else {
                (-12..=12)
                    .filter(|&k| {
                        let v = q + 2.0 * PI * f64::from(k);
                        v >= j.lower - 1e-9 && v <= j.upper + 1e-9
                    })
                    .collect()
            };
            if let Some(&k0) = ks.iter().min_by(|a, b| {
                let v = |k: i32| (q + 2.0 * PI * f64::from(k)).abs();
                v(**a).total_cmp(&v(**b))
            }) {
                ks.sort_by_key(|&k| ((k - k0).abs(), k > k0));
            }
            ks.truncate(MAX_TURNS);
            let values: Vec<f64> = ks
                .iter()
                .map(|&k| (q + 2.0 * PI * f64::from(k)).clamp(j.lower, j.upper))
                .collect();
            rows = rows
                .iter()
                .flat_map(|r| {
                    values.iter().map(move |&v| {
                        let mut r = *r;
                        r.joints[i] = v;
                        r
                    })
                })
                .collect();
        }
        want.extend(rows);
    }
    want
}

#[test]
fn every_whole_turn_is_enumerated_once() {
    // the all-turns answer is, per configuration in (−π, π], the product over
    // joints of every q + 2πk inside the limits (brute force above), each
    // variant once and with its configuration's flags: the UR5 (±2π on every
    // joint) and a hand-made three-parallel arm with many turns (capped at
    // MAX_TURNS), narrow, one-sided and continuous joints
    let ur5 = builtin_chain("ur5").unwrap();
    let mut wide = PARALLEL_ARM.to_string();
    for (joint, lo, hi) in [
        ("j1", "-23.5", "23.5"),
        ("j3", "-6.2832", "6.2832"),
        ("j5", "-0.5", "9.0"),
        ("j6", "-1.0", "1.0"),
    ] {
        let from = format!("<joint name=\"{joint}\" type=\"revolute\">");
        let at = wide.find(&from).unwrap();
        let tail = &wide[at..];
        let old = tail[..tail.find("</joint>").unwrap()].to_string();
        let new = old.replace(
            "lower=\"-3.2\" upper=\"3.2\"",
            &format!("lower=\"{lo}\" upper=\"{hi}\""),
        );
        wide = wide.replacen(&old, &new, 1);
    }
    let wide = wide.replacen(
        "<joint name=\"j4\" type=\"revolute\">",
        "<joint name=\"j4\" type=\"continuous\">",
        1,
    );
    let wide = parse_chain(&wide, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    assert_eq!(wide.joints()[3].kind, crate::robot::JointKind::Continuous);
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    for chain in [&*ur5, &wide] {
        let arm = AnalyticArm::new(chain, 1e-9).unwrap();
        let (mut base, mut all) = (Vec::new(), Vec::new());
        let mut rows = 0;
        for _ in 0..60 {
            let t = chain.fk(&random_q(chain, &mut rng));
            arm.solve_into(&t, None, &nearest_params(), &mut base);
            arm.solve_into(&t, None, &AnalyticParams::default(), &mut all);
            let want = brute_force_turns(chain, &base);
            assert_eq!(all.len(), want.len());
            rows += all.len();
            for w in &want {
                let found: Vec<_> = all
                    .iter()
                    .filter(|s| s.joints.iter().zip(&w.joints).all(|(a, b)| (a - b).abs() < 1e-9))
                    .collect();
                assert_eq!(found.len(), 1, "{w:?}");
                assert_eq!(
                    (found[0].config, found[0].singular, found[0].exact),
                    (w.config, w.singular, w.exact)
                );
            }
        }
        assert!(rows >= 60 * 16, "{rows}");
    }
}
