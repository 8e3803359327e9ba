//! 7-joint arms: the Panda's geometry and closed form with joint 7 held (read
//! from the tool end), the iiwa, a numerical cross-check on the held chains,
//! and the held joint searched for the solution nearest the seed.

use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::family::{meet, point_line_distance};
use super::tests::{lm_finds_none_missing, pose_close};
use super::*;
use crate::ik::{IkMethod, IkParams, IkResult, IkTarget, solve_ik};
use crate::robot::{Chain, ChainSpec, UrdfLimits, builtin_chain, parse_chain};

const ERD_PANDA: &str = "/work/py-venv-coal/lib/python3.11/site-packages/cmeel.prefix/share/\
                         example-robot-data/robots/panda_description/urdf/panda.urdf";

/// The built-in Panda, and example-robot-data's (flange to `panda_hand`) when
/// that package is installed here.
fn pandas() -> Vec<(String, Chain)> {
    let mut out = vec![(
        "franka_panda".to_string(),
        (*builtin_chain("franka_panda").unwrap()).clone(),
    )];
    if let Ok(text) = std::fs::read_to_string(ERD_PANDA) {
        let spec = ChainSpec {
            base_link: None,
            tip_link: Some("panda_hand".into()),
        };
        out.push((
            "erd panda".into(),
            parse_chain(&text, &spec, UrdfLimits::default()).unwrap(),
        ));
    }
    out
}

fn random_q(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .joints()
        .iter()
        .map(|j| rng.random_range(j.lower..=j.upper))
        .collect()
}

fn dist2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn analytic(n: usize, analytic: AnalyticParams) -> IkParams {
    IkParams {
        method: IkMethod::Analytic,
        num_solutions: n,
        analytic,
        ..IkParams::default()
    }
}

fn solve(chain: &Chain, t: &Isometry3<f64>, seed: &[f64], p: &IkParams) -> IkResult {
    solve_ik(
        chain,
        &IkTarget::Pose(*t),
        Some(seed),
        p,
        0,
        crate::Deadline::none(),
    )
    .unwrap()
}

#[test]
fn panda_axes_1_2_3_meet_and_axes_5_6_meet() {
    // the geometry the reversed family rests on, read from the URDF numbers:
    // joints 1, 2, 3 meet at the shoulder 0.333 m above the base, joints 5 and 6
    // meet, axis 7 passes 0.088 m from axis 6, axis 4 0.0825 m from axis 3
    for (name, chain) in pandas() {
        let z = ZeroAxes::of(&chain);
        let (s, d12) = meet(&z.p[0], &z.h[0], &z.p[1], &z.h[1], 1e-9).unwrap();
        assert!(d12 < 1e-12, "{name}");
        assert!(
            (s - Vector3::new(0.0, 0.0, 0.333)).norm() < 1e-12,
            "{name}: {s:?}"
        );
        assert!(point_line_distance(&s, &z.p[2], &z.h[2]) < 1e-12, "{name}");
        let (_, d34) = meet(&z.p[2], &z.h[2], &z.p[3], &z.h[3], 1e-9).unwrap();
        assert!((d34 - 0.0825).abs() < 1e-12, "{name}: {d34}");
        let (_, d56) = meet(&z.p[4], &z.h[4], &z.p[5], &z.h[5], 1e-9).unwrap();
        assert!(d56 < 1e-12, "{name}");
        let (_, d67) = meet(&z.p[5], &z.h[5], &z.p[6], &z.h[6], 1e-9).unwrap();
        assert!((d67 - 0.088).abs() < 1e-12, "{name}: {d67}");
    }
}

#[test]
fn panda_with_joint_7_held_round_trips() {
    let params = analytic(
        1000,
        AnalyticParams {
            turns: Turns::NearestSeed,
            ..AnalyticParams::default()
        },
    );
    for (name, chain) in pandas() {
        let mut rng = ChaCha8Rng::seed_from_u64(29);
        let reduced = analyse(&chain, &params.analytic, None).unwrap();
        assert_eq!(reduced.held.map(|h| h.0), Some(6), "{name}");
        assert!(reduced.arm.is_reversed(), "{name}");
        assert_eq!(reduced.arm.family(), Family::SphericalTwoIntersecting, "{name}");
        let mut total = 0;
        for _ in 0..500 {
            let q = random_q(&chain, &mut rng);
            let t = chain.fk(&q);
            let r = solve(&chain, &t, &q, &params);
            assert!(r.success(), "{name}: {q:?}");
            assert!(
                dist2(&r.solutions[0].joints, &q) < 1e-14,
                "{name}: {q:?} vs {:?}",
                r.solutions[0].joints
            );
            total += r.solutions.len();
            for s in &r.solutions {
                assert_eq!(s.joints[6], q[6]);
                assert!(
                    pose_close(&chain.fk(&s.joints), &t, 1e-9),
                    "{name}: {:?}",
                    s.joints
                );
                for (v, j) in s.joints.iter().zip(chain.joints()) {
                    assert!(*v >= j.lower && *v <= j.upper, "{name}: {v} outside {}", j.name);
                }
            }
            // the configuration flags of the sampled joints are those of its solution
            let six = reduced_of(&chain, &q);
            let mut out = Vec::new();
            six.arm
                .solve_into(&t, Some(&six.reduce(&q)), &params.analytic, &mut out);
            let same = out
                .iter()
                .find(|s| dist2(&six.expand(&s.joints), &q) < 1e-14)
                .unwrap();
            assert_eq!(same.config, six.arm.config_of(&six.reduce(&q)), "{name}");
        }
        // the Panda's limits (joint 4 negative, joint 6 mostly positive) leave
        // fewer than the 8 configurations on average, but more than one
        assert!(total > 500 * 2, "{name}: {total} solutions for 500 poses");
    }
}

fn reduced_of(chain: &Chain, q: &[f64]) -> ReducedArm {
    analyse(chain, &AnalyticParams::default(), Some(q)).unwrap()
}

/// Levenberg–Marquardt on the 6-joint chain left by holding the joint (64
/// random seeds per pose): every answer it converges to is one of ours.
#[test]
fn numerical_search_finds_nothing_the_7_joint_closed_form_missed() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let lm = IkParams {
        max_restarts: 0,
        position_tolerance: 1e-10,
        orientation_tolerance: 1e-10,
        ..IkParams::default()
    };
    let wide = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    for name in ["franka_panda", "kuka_lbr_iiwa14_r820"] {
        let chain = builtin_chain(name).unwrap();
        let (mut found, mut poses) = (0, 0);
        while poses < 3 {
            let q = random_q(&chain, &mut rng);
            let reduced = reduced_of(&chain, &q);
            let (j, v) = reduced.held.unwrap();
            let six = chain.with_joint_fixed(j, v).unwrap();
            let t = chain.fk(&q);
            // ours, without limits: every branch in (−π, π]
            let mut ours = Vec::new();
            reduced.arm.nearest(&t, None, &wide, &mut ours);
            ours.retain(|s| s.exact);
            poses += 1;
            let draw = || {
                six.joints()
                    .iter()
                    .map(|j| rng.random_range(j.lower..=j.upper))
                    .collect()
            };
            found += lm_finds_none_missing(&six, &t, &lm, &ours, 64, draw, name);
        }
        assert!(found > 20, "{name}: LM converged only {found} times");
    }
}

/// The smallest squared distance to `seed` over the solutions at `n` evenly
/// spaced values of the held joint `j` (a brute-force scan).
fn dense_scan(chain: &Chain, j: usize, t: &Isometry3<f64>, seed: &[f64], n: usize) -> f64 {
    let (lo, hi) = (chain.joints()[j].lower, chain.joints()[j].upper);
    let p = analytic(
        1000,
        AnalyticParams {
            turns: Turns::NearestSeed,
            ..AnalyticParams::default()
        },
    );
    (0..n)
        .map(|k| {
            let mut s = seed.to_vec();
            s[j] = lo + (hi - lo) * k as f64 / (n - 1) as f64;
            let r = solve(chain, t, &s, &p);
            r.solutions
                .iter()
                .map(|x| dist2(&x.joints, seed))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn searched_redundant_joint_gives_the_nearest_solution() {
    const CASES: usize = 40;
    let searched = AnalyticParams {
        search_redundant: true,
        ..AnalyticParams::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for name in ["franka_panda", "kuka_lbr_iiwa14_r820"] {
        let chain = builtin_chain(name).unwrap();
        let j = reduced_of(&chain, &chain.mid_limits()).held.unwrap().0;
        let (mut as_near_as_q, mut as_near_as_scan) = (0, 0);
        for case in 0..CASES {
            let q = random_q(&chain, &mut rng);
            let t = chain.fk(&q);
            // the seed: the pose's joints with the held joint moved 0.4 rad
            // (inside the limits) and the others nudged by up to 0.05 rad, so
            // that a solution lies within about 0.4 rad of it
            let mut seed = q.clone();
            let (lo, hi) = (chain.joints()[j].lower, chain.joints()[j].upper);
            seed[j] = if q[j] + 0.4 <= hi { q[j] + 0.4 } else { q[j] - 0.4 }.clamp(lo, hi);
            for (i, s) in seed.iter_mut().enumerate() {
                if i != j {
                    *s += rng.random_range(-0.05..0.05);
                }
            }
            let r = solve(&chain, &t, &seed, &analytic(8, searched));
            assert!(r.success(), "{name} {case}");
            let best = &r.solutions[0];
            assert!(pose_close(&chain.fk(&best.joints), &t, 1e-9), "{name} {case}");
            let d = dist2(&best.joints, &seed);
            // never farther than holding the joint at the seed's value
            let held = solve(&chain, &t, &seed, &analytic(8, AnalyticParams::default()));
            if let Some(h) = held.solutions.first() {
                assert!(d <= dist2(&h.joints, &seed) + 1e-12, "{name} {case}");
            }
            // how often it is as near as the pose's own joints, and as near as
            // a brute-force scan of 2001 held values
            if d <= dist2(&q, &seed) + 1e-12 {
                as_near_as_q += 1;
            }
            let scan = dense_scan(&chain, j, &t, &seed, 2001);
            if d <= scan + 1e-9 {
                as_near_as_scan += 1;
            }
        }
        eprintln!(
            "{name}: {as_near_as_q}/{CASES} as near as the pose's joints, {as_near_as_scan}/{CASES} as a scan"
        );
        // a dip narrower than the sample spacing can be missed (documented):
        // the seeds here lie 0.4 rad from a solution, some of them next to a
        // limit or a singularity where the branch is that narrow
        assert!(as_near_as_q >= CASES * 9 / 10, "{name}: {as_near_as_q}/{CASES}");
        assert!(
            as_near_as_scan >= CASES * 9 / 10,
            "{name}: {as_near_as_scan}/{CASES}"
        );
    }
}

#[test]
fn the_model_is_read_once_and_a_changed_copy_reads_its_own() {
    let panda = builtin_chain("franka_panda").unwrap();
    let a = analyse(&panda, &AnalyticParams::default(), None).unwrap();
    assert!(panda.analytic_cache().get().is_some());
    let b = analyse(&panda, &AnalyticParams::default(), None).unwrap();
    assert_eq!(a, b);
    // the chain with joint 7 held is a 6-joint arm of its own
    let six = panda.with_joint_fixed(6, 0.3).unwrap();
    assert!(six.analytic_cache().get().is_none());
    let r = analyse(&six, &AnalyticParams::default(), None).unwrap();
    assert_eq!(r.held, None);
    assert!(r.arm.is_reversed());
    // a tolerance of its own is read afresh, with the same answer here
    let loose = AnalyticParams {
        geometry_tolerance: 1e-6,
        ..AnalyticParams::default()
    };
    assert_eq!(analyse(&panda, &loose, None).unwrap().held, a.held);
}

#[test]
fn reversed_arm_config_flags_and_refusals() {
    // the iiwa holding joint 7 is now covered from the tool end, holding
    // joint 4 is not (the shoulder then lies on the third axis)
    let iiwa = builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
    let seven = AnalyticParams {
        redundant_joint: Some(6),
        ..AnalyticParams::default()
    };
    assert!(analyse(&iiwa, &seven, None).unwrap().arm.is_reversed());
    let four = AnalyticParams {
        redundant_joint: Some(3),
        ..AnalyticParams::default()
    };
    let e = analyse(&iiwa, &four, None).unwrap_err().reason;
    assert!(e.starts_with("with joint 4 held"), "{e}");
    let planar = builtin_chain("planar_7").unwrap();
    let e = analyse(&planar, &AnalyticParams::default(), None)
        .unwrap_err()
        .reason;
    assert!(e.contains("holding any one of them"), "{e}");
    // samples are validated, naming the field
    let bad = IkParams {
        method: IkMethod::Analytic,
        analytic: AnalyticParams {
            redundant_samples: 1,
            ..AnalyticParams::default()
        },
        ..IkParams::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("redundant_samples"), "{e}");
}

/// The search looks at the deadline: a passed one answers as such, quickly.
#[test]
fn the_search_stops_at_the_deadline() {
    use crate::Deadline;
    use crate::ik::IkStatus;
    let panda = builtin_chain("franka_panda").unwrap();
    let q = [0.2, -0.4, 0.3, -2.1, 0.4, 1.8, 0.5];
    let target = IkTarget::Pose(panda.fk(&q));
    let params = analytic(
        8,
        AnalyticParams {
            search_redundant: true,
            redundant_samples: 4096,
            ..AnalyticParams::default()
        },
    );
    let past = std::time::Instant::now() - std::time::Duration::from_millis(1);
    let t0 = std::time::Instant::now();
    let late = solve_ik(&panda, &target, Some(&q), &params, 0, Deadline::at(past)).unwrap();
    assert_eq!(late.stop_reason, IkStatus::TimeBudget);
    assert!(late.solutions.is_empty());
    // 4096 samples would take far longer than the few polled before stopping
    assert!(t0.elapsed() < std::time::Duration::from_millis(500));
    let live = solve_ik(&panda, &target, Some(&q), &params, 0, Deadline::none()).unwrap();
    assert!(live.success());
}

/// The iiwa's arm turned to a held value (no new analysis) solves the poses of
/// that value: every solution, with the held value put back, reproduces the
/// pose by the chain's own forward kinematics, and the sampled joints are
/// among them; also at joint 3 = 0, where axes 2 and 4 line up and the
/// analysis from scratch reads another family.
#[test]
fn the_turned_iiwa_arm_solves_every_held_value() {
    use super::turned::TurnedArm;
    let iiwa = builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
    let axes = *ChainModel::of_chain(&iiwa).axes().unwrap();
    let tol = AnalyticParams::default().geometry_tolerance;
    let turned = TurnedArm::new(&axes, 2, axes.generic(2), tol).unwrap();
    // analysed afresh at joint 3 = 0, axes 2 and 4 are parallel: another family
    let at_zero = AnalyticArm::from_axes(&axes.held(2, 0.0), tol).unwrap();
    assert_eq!(at_zero.family(), Family::SphericalWrist);
    // holding joint 4 leaves the shoulder on the arm's third axis: refused
    assert!(TurnedArm::new(&axes, 3, axes.generic(3), tol).is_none());
    let params = AnalyticParams {
        turns: Turns::NearestSeed,
        ..AnalyticParams::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut out = Vec::new();
    for case in 0..200 {
        let mut q = random_q(&iiwa, &mut rng);
        if case % 10 == 0 {
            q[2] = 0.0;
        }
        let t = iiwa.fk(&q);
        let arm = turned.at(q[2]);
        let q6 = [q[0], q[1], q[3], q[4], q[5], q[6]];
        arm.solve_into(&t, Some(&q6), &params, &mut out);
        assert!(!out.is_empty(), "case {case}");
        let mut found = false;
        for s in &out {
            let mut full = s.joints.to_vec();
            full.insert(2, q[2]);
            assert!(pose_close(&iiwa.fk(&full), &t, 1e-9), "case {case}: {full:?}");
            found |= dist2(&full, &q) < 1e-12;
        }
        assert!(found, "case {case}: the sampled joints are missing");
    }
}

/// The bounded solve keeps every exact branch nearer the seed than the bound
/// (distances computed here over each joint's nearest whole turn), and with no
/// bound returns exactly the exact branches of the unbounded least-squares
/// solve, on the iiwa and on the Panda (solved reversed).
#[test]
fn bounded_solve_keeps_every_branch_inside_the_bound() {
    use std::f64::consts::{PI, TAU};
    let wrapped = |a: &[f64; 6], b: &[f64; 6]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| {
                let d = (x - y).rem_euclid(TAU);
                let d = if d > PI { TAU - d } else { d };
                d * d
            })
            .sum()
    };
    let params = AnalyticParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(2929);
    let (mut out, mut all) = (Vec::new(), Vec::new());
    for name in ["franka_panda", "kuka_lbr_iiwa14_r820"] {
        let chain = builtin_chain(name).unwrap();
        let mut dropped = 0;
        for case in 0..100 {
            let q = random_q(&chain, &mut rng);
            let r = reduced_of(&chain, &q);
            let q6: [f64; 6] = r.reduce(&q).try_into().unwrap();
            let seed: [f64; 6] = std::array::from_fn(|i| q6[i] + rng.random_range(-0.5..0.5));
            let t = chain.fk(&q);
            r.arm.nearest(&t, Some(&seed), &params, &mut all);
            all.retain(|s| s.exact);
            r.arm
                .exact_near(&t, &seed, params.solve_tolerance, f64::INFINITY, &mut out);
            assert_eq!(out, all, "{name} {case}");
            let mut d: Vec<f64> = all.iter().map(|s| wrapped(&s.joints, &seed)).collect();
            d.sort_by(f64::total_cmp);
            let bound = d[d.len() / 2];
            r.arm
                .exact_near(&t, &seed, params.solve_tolerance, bound, &mut out);
            for s in &all {
                if wrapped(&s.joints, &seed) < bound {
                    assert!(
                        out.contains(s),
                        "{name} {case}: a branch inside the bound was dropped"
                    );
                }
            }
            dropped += all.len() - out.len();
        }
        // the bound does spare work: some far branches are dropped
        assert!(dropped > 0, "{name}");
    }
}
