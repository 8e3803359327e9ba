//! The eight-lane `f32` check (`lanes8`): its sphere centres within the
//! stated rounding margin of the exact (`f64`) poses; its verdict "clear"
//! never on a state the exact check refuses (generated scenes with states
//! at the contact boundary, and the MotionBenchMaker scenes); the bodies and
//! pairs it flags enough for the exact re-check; the AVX2 and portable
//! builds bit for bit.

use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::lanes8::{Flags, Frame8, Lane8, Lanes8, MAX_BODIES8, MAX_DOF8, WIDTH};
use super::super::*;
use super::lanes::{batched, mixed_chain_urdf, near_contact, panda_with_hand, random_state, scenes};
use super::probe_urdf;
use crate::robot::{Chain, ChainSpec, UrdfLimits, parse_chain};

/// A state drawn within the limits, each joint at one of its limits with
/// probability ½ (the extremes, where the angles and reach are largest).
fn edgy_state(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .joints()
        .iter()
        .map(|j| match rng.random_range(0..4) {
            0 => j.lower,
            1 => j.upper,
            _ => rng.random_range(j.lower..=j.upper),
        })
        .collect()
}

/// Joint-major `f32` lanes of up to [`WIDTH`] states (the last repeated).
fn lanes_of(states: &[Vec<f64>], dof: usize) -> [Lane8; MAX_DOF8] {
    let mut q = [[0.0; WIDTH]; MAX_DOF8];
    for l in 0..WIDTH {
        let s = &states[l.min(states.len() - 1)];
        for j in 0..dof {
            q[j][l] = s[j] as f32;
        }
    }
    q
}

#[test]
fn f32_sphere_centres_stay_within_the_stated_margin_of_the_exact_poses() {
    let (_, panda, _) = panda_with_hand();
    let model_of = |urdf: &str| {
        Arc::new(
            RobotModel::new(Arc::new(
                parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap(),
            ))
            .unwrap(),
        )
    };
    let mixed = model_of(&mixed_chain_urdf());
    let probe = model_of(&probe_urdf(r#"<box size="0.1 0.2 0.3"/>"#));
    let empty =
        Arc::new(SceneGeometry::build(&Scene::new(vec![], &SceneLimits::default()).unwrap()).unwrap());
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    // 100,000 Panda states, fewer of the others
    for (model, count) in [(panda, 100_000), (mixed, 16_000), (probe, 8_000)] {
        let chain = model.chain().clone();
        let dof = chain.dof();
        let spheres = SphereModel::build(&model, &SphereParams::default()).unwrap();
        let lanes = Lanes8::new(&model, &spheres, &empty).expect("batched");
        let mut worst = 0.0f64;
        let mut frames = [Frame8::IDENTITY; MAX_BODIES8];
        let mut portable = [Frame8::IDENTITY; MAX_BODIES8];
        for k in 0..count / WIDTH {
            let states: Vec<Vec<f64>> = (0..WIDTH).map(|_| edgy_state(&chain, &mut rng)).collect();
            let q = lanes_of(&states, dof);
            lanes.body_frames(&q[..dof], &mut frames, false);
            if k % 16 == 0 {
                lanes.body_frames(&q[..dof], &mut portable, true);
                for b in 0..model.body_count() {
                    let (f, g) = (&frames[b], &portable[b]);
                    assert_eq!(f.p.map(|r| r.map(f32::to_bits)), g.p.map(|r| r.map(f32::to_bits)));
                    assert_eq!(
                        f.r.map(|r| r.map(|c| c.map(f32::to_bits))),
                        g.r.map(|r| r.map(|c| c.map(f32::to_bits)))
                    );
                }
            }
            for (l, s) in states.iter().enumerate() {
                let mut poses = [Isometry3::identity(); MAX_BODIES];
                model.body_poses(s, &mut poses);
                for b in 0..model.body_count() {
                    let mut exact = vec![spheres.coarse(b).center];
                    exact.extend(spheres.fine(b).iter().map(|s| s.center));
                    let placed = lanes.placed_centres(b, &frames[b]);
                    for (c, x) in exact.iter().zip(&placed) {
                        let c = poses[b] * c;
                        let d = ((x[0][l] as f64 - c.x).powi(2)
                            + (x[1][l] as f64 - c.y).powi(2)
                            + (x[2][l] as f64 - c.z).powi(2))
                        .sqrt();
                        let margin = lanes.margin(b);
                        assert!(
                            d <= margin,
                            "{}: body {b} at {s:?}: {d:e} > {margin:e}",
                            chain.name()
                        );
                        worst = worst.max(d / margin);
                    }
                }
            }
        }
        let largest = (0..model.body_count())
            .map(|b| lanes.margin(b))
            .fold(0.0, f64::max);
        eprintln!(
            "{}: worst error {worst:.3} of the margin; margins up to {largest:e} m",
            chain.name()
        );
        // the margin is small beside the spheres' overshoot (centimetres)
        assert!(largest < 2e-4, "{}: margin {largest:e}", chain.name());
    }
}

/// The unsure mask and flags of up to [`WIDTH`] states, from the AVX2 build
/// or the portable one.
fn unsure(checker: &SceneChecker, batch: &[Vec<f64>], portable: bool) -> (u32, Flags) {
    let lanes = checker.lanes8().expect("a batched checker");
    let (scene_bodies, self_pairs) = checker.checked_parts();
    let q = lanes_of(batch, lanes.dof());
    let mut flags = Flags::default();
    let m = lanes.unsure(&q[..lanes.dof()], scene_bodies, self_pairs, &mut flags, portable);
    (m, flags)
}

/// Over `states` in batches of eight: both builds agree; no lane is clear
/// whose state collides; the exact re-check of only the flagged bodies and
/// pairs answers as the whole exact check; `states_valid` over the lanes
/// answers as the exact check per batch. Returns (free, cleared).
fn check_states(name: &str, checker: &SceneChecker, states: &[Vec<f64>]) -> (usize, usize) {
    let (mut free, mut cleared) = (0, 0);
    for batch in states.chunks(WIDTH) {
        let (simd, flags) = unsure(checker, batch, false);
        let (portable, portable_flags) = unsure(checker, batch, true);
        assert_eq!(simd, portable, "{name}: builds disagree on {batch:?}");
        assert_eq!(flags.bodies, portable_flags.bodies, "{name}");
        assert_eq!(flags.pairs, portable_flags.pairs, "{name}");
        let mut all_valid = true;
        for (l, s) in batch.iter().enumerate() {
            let exact = checker.is_valid(s);
            all_valid &= exact;
            let sure = simd & (1 << l) == 0;
            assert!(exact || !sure, "{name}: spheres cleared a colliding state {s:?}");
            if !sure {
                assert_eq!(
                    checker.hits_flagged(s, flags.bodies[l], flags.pairs[l]),
                    !exact,
                    "{name}: the flagged re-check of {s:?}"
                );
            }
            free += usize::from(exact);
            cleared += usize::from(sure);
        }
        let rows = batch.concat();
        for portable in [false, true] {
            assert_eq!(
                checker.states_valid_in_lanes(&rows, portable),
                Some(all_valid),
                "{name}: {batch:?}"
            );
        }
    }
    (free, cleared)
}

/// Boxes and capsules turned about every axis around the arm (the generated
/// scenes turn theirs about `z` only).
fn tilted(rng: &mut ChaCha8Rng) -> Vec<Obstacle> {
    (0..12)
        .map(|i| {
            let pose = Isometry3::from_parts(
                Translation3::new(
                    rng.random_range(-0.7..0.7),
                    rng.random_range(-0.7..0.7),
                    rng.random_range(0.0..1.0),
                ),
                UnitQuaternion::from_euler_angles(
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                ),
            );
            let geometry = if i % 2 == 0 {
                Geometry::Box {
                    half_extents: Vector3::new(0.12, 0.04, 0.08),
                }
            } else {
                Geometry::Capsule {
                    radius: 0.03,
                    length: 0.25,
                }
            };
            Obstacle::new(format!("tilted{i}"), pose, geometry)
        })
        .collect()
}

#[test]
fn eight_lanes_never_clear_a_colliding_state_near_contact() {
    let (chain, model, acm) = panda_with_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(88);
    let mut all = scenes(&mut rng);
    all.push(("tilted", tilted(&mut rng)));
    for (name, obstacles) in all {
        let world =
            Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, batched()).unwrap();
        assert!(checker.lanes8().is_some(), "{name}: not batched");
        // random states, then pairs within 1e-7 rad of the boundary between
        // a free and a colliding state (bisected along the line between them)
        let mut states: Vec<Vec<f64>> = (0..1200).map(|_| random_state(&chain, &mut rng)).collect();
        let free: Vec<Vec<f64>> = states
            .iter()
            .filter(|q| checker.is_valid(q))
            .take(100)
            .cloned()
            .collect();
        let hit: Vec<Vec<f64>> = states
            .iter()
            .filter(|q| !checker.is_valid(q))
            .take(100)
            .cloned()
            .collect();
        for (f, h) in free.iter().zip(&hit) {
            states.extend(near_contact(&checker, f, h, 1e-7));
        }
        let (free, cleared) = check_states(name, &checker, &states);
        eprintln!(
            "{name}: {} states, {free} free, {cleared} cleared by the spheres",
            states.len()
        );
        assert!(
            states.len() - free > 100,
            "{name}: {} colliding",
            states.len() - free
        );
        // not vacuous: the spheres clear most free states (the lanes here get
        // every self pair; the checker leaves out those its pair tables prove)
        assert!(5 * cleared > 3 * free, "{name}: {cleared} of {free} cleared");
    }
}

/// On one scene of every MotionBenchMaker set (the real problems, read from
/// the archive beside the repository): 10,000 random states each.
#[test]
fn eight_lanes_never_clear_a_colliding_state_on_every_motionbenchmaker_set() {
    let Some(dir) = crate::mbm_data::problems() else {
        return;
    };
    let (chain, model, acm) = panda_with_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(80_000);
    for set in crate::mbm_data::SETS {
        let (scene, _) = crate::mbm_data::problem(&dir, set, 1);
        let scene = parse_planning_scene(&scene, &SceneLimits::default()).unwrap();
        let world = Arc::new(SceneGeometry::build(&scene).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, batched()).unwrap();
        assert!(checker.lanes8().is_some(), "{set}: not batched");
        let states: Vec<Vec<f64>> = (0..10_000).map(|_| random_state(&chain, &mut rng)).collect();
        let (free, cleared) = check_states(set, &checker, &states);
        eprintln!("{set}: {free} of 10000 states free, {cleared} cleared by the spheres");
        assert!((1_000..9_900).contains(&free), "{set}: {free} free");
        assert!(4 * cleared > 3 * free, "{set}: {cleared} of {free} cleared");
    }
}
