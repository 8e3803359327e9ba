//! The batched checks' shared fixtures (the Panda with its hand, a chain
//! mixing joint kinds, MotionBenchMaker-like scenes: a table, shelves, a
//! cage of bars, clutter of boxes, cylinders and spheres), the row handling
//! of `states_valid`, and the padded pieces proved eight at a time against
//! sampled states along them.

use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::*;
use crate::robot::{Chain, builtin_chain, builtin_urdf};

/// The Panda with its hand, fingers 4 cm open (as the benchmark runs it).
/// Its matrix also allows the wrist (link_5) against link_7 and the hand,
/// the contacts example-robot-data's SRDF disables: the built-in's fitted
/// shapes for those links come within millimetres in nearly every state, so
/// with them checked the spheres would clear almost no state, and these
/// tests measure what the spheres clear (the built-in matrix checks them).
pub(super) fn panda_with_hand() -> (Arc<Chain>, Arc<RobotModel>, AllowedCollisions) {
    let chain = builtin_chain("franka_panda").unwrap();
    let urdf = builtin_urdf("franka_panda_hand").unwrap();
    let fingers = [("panda_finger_joint1", 0.04), ("panda_finger_joint2", 0.04)];
    let attached = attached_bodies(urdf, &chain, &fingers).unwrap();
    let model = Arc::new(RobotModel::with_parts(chain.clone(), &attached, &[]).unwrap());
    let mut acm = AllowedCollisions::builtin(&model, "franka_panda_hand", &AcmParams::default()).unwrap();
    acm.allow_named(
        &model,
        [("link_5", "link_7"), ("link_5", "panda_hand")],
        AllowReason::User,
    );
    (chain, model, acm)
}

/// A chain turning about x, y and a slanted axis from turned origins, then
/// sliding: every kind of joint motion the lanes apply.
pub(super) fn mixed_chain_urdf() -> String {
    let link = |name: &str| {
        format!(
            r#"<link name="{name}"><collision><origin xyz="0 0 0.1" rpy="0.2 0 0"/>
               <geometry><capsule radius="0.04" length="0.2"/></geometry></collision></link>"#
        )
    };
    let joint = |name: &str, kind: &str, parent: &str, child: &str, xyz: &str, rpy: &str, axis: &str| {
        format!(
            r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
               <origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>
               <limit lower="-2" upper="2" effort="0" velocity="1"/></joint>"#
        )
    };
    format!(
        r#"<robot name="mixed"><link name="base"/>{}{}{}{}{}{}{}{}</robot>"#,
        link("a"),
        link("b"),
        link("c"),
        link("d"),
        joint("j1", "revolute", "base", "a", "0 0 0.1", "0 0 0", "1 0 0"),
        joint("j2", "revolute", "a", "b", "0 0.05 0.2", "0.3 -0.4 0.5", "0 1 0"),
        joint(
            "j3",
            "revolute",
            "b",
            "c",
            "0.1 0 0.2",
            "1.5707963 0 0",
            "0.6 0 0.8"
        ),
        joint("j4", "prismatic", "c", "d", "0 0 0.2", "0 0.7 0", "0 0 1"),
    )
}

pub(super) fn batched() -> CheckerParams {
    CheckerParams {
        batched: true,
        ..CheckerParams::default()
    }
}

pub(super) fn random_state(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .joints()
        .iter()
        .map(|j| rng.random_range(j.lower..=j.upper))
        .collect()
}

/// MotionBenchMaker-like scenes around the Panda, from a seed: a table with
/// clutter on it, a shelf of boards, a cage of bars, a table of cylinders
/// and spheres, turned about z.
pub(super) fn scenes(rng: &mut ChaCha8Rng) -> Vec<(&'static str, Vec<Obstacle>)> {
    let turned = |x: f64, y: f64, z: f64, yaw: f64| {
        Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
        )
    };
    let boxed = |name: String, pose, h: [f64; 3]| {
        Obstacle::new(
            name,
            pose,
            Geometry::Box {
                half_extents: Vector3::new(h[0], h[1], h[2]),
            },
        )
    };
    let mut table = vec![boxed(
        "table".into(),
        turned(0.6, 0.0, 0.15, 0.0),
        [0.3, 0.6, 0.02],
    )];
    for i in 0..6 {
        let (x, y, yaw) = (
            rng.random_range(0.4..0.8),
            rng.random_range(-0.5..0.5),
            rng.random_range(-1.0..1.0),
        );
        table.push(boxed(
            format!("item{i}"),
            turned(x, y, 0.22, yaw),
            [0.03, 0.04, 0.05],
        ));
    }
    let mut shelf = Vec::new();
    for (i, z) in [0.1, 0.45, 0.8, 1.15].iter().enumerate() {
        shelf.push(boxed(
            format!("board{i}"),
            turned(0.75, 0.0, *z, 0.3),
            [0.15, 0.4, 0.01],
        ));
    }
    shelf.push(boxed(
        "side_l".into(),
        turned(0.75 - 0.4 * 0.3f64.sin(), 0.4 * 0.3f64.cos(), 0.6, 0.3),
        [0.15, 0.01, 0.6],
    ));
    shelf.push(boxed(
        "side_r".into(),
        turned(0.75 + 0.4 * 0.3f64.sin(), -0.4 * 0.3f64.cos(), 0.6, 0.3),
        [0.15, 0.01, 0.6],
    ));
    let mut cage = Vec::new();
    for i in 0..4 {
        let a = i as f64 * std::f64::consts::FRAC_PI_2 + 0.4;
        cage.push(Obstacle::new(
            format!("bar{i}"),
            turned(0.55 * a.cos(), 0.55 * a.sin(), 0.5, 0.0),
            Geometry::Cylinder {
                radius: 0.02,
                length: 1.0,
            },
        ));
        cage.push(boxed(
            format!("roof{i}"),
            turned(0.5 * a.cos(), 0.5 * a.sin(), 1.0, a),
            [0.02, 0.4, 0.02],
        ));
    }
    let mut round = vec![boxed(
        "table".into(),
        turned(0.0, 0.6, 0.2, 0.5),
        [0.5, 0.25, 0.02],
    )];
    for i in 0..5 {
        let (x, y) = (rng.random_range(-0.4..0.4), rng.random_range(0.45..0.75));
        round.push(Obstacle::new(
            format!("can{i}"),
            turned(x, y, 0.3, 0.0),
            Geometry::Cylinder {
                radius: 0.04,
                length: 0.16,
            },
        ));
        round.push(Obstacle::new(
            format!("ball{i}"),
            turned(-x, y, 0.35, 0.0),
            Geometry::Sphere { radius: 0.05 },
        ));
        round.push(Obstacle::new(
            format!("pill{i}"),
            turned(x, -y, 0.5, 0.0),
            Geometry::Capsule {
                radius: 0.03,
                length: 0.2,
            },
        ));
    }
    vec![
        ("table", table),
        ("shelf", shelf),
        ("cage", cage),
        ("round", round),
    ]
}

#[test]
fn states_valid_refuses_states_outside_the_limits_and_takes_any_row_count() {
    let (chain, model, acm) = panda_with_hand();
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(vec![], &SceneLimits::default()).unwrap()).unwrap());
    let checker = SceneChecker::new(model, &acm, world, batched()).unwrap();
    let home = vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
    assert!(checker.is_valid(&home));
    for n in 1..=9 {
        let rows = home.repeat(n);
        assert!(checker.states_valid(&rows), "{n} rows");
        let mut bad = rows.clone();
        bad[(n - 1) * 7] = chain.joints()[0].upper + 0.1;
        assert!(
            !checker.states_valid(&bad),
            "{n} rows, the last out of its limits"
        );
        bad[(n - 1) * 7] = f64::NAN;
        assert!(!checker.states_valid(&bad), "{n} rows, the last not a number");
    }
}

/// The two states straddling the boundary between `free` and `hit` on the
/// line between them, within `tolerance` of the line's length apart: the
/// free one and the colliding one (near contact).
pub(super) fn near_contact(
    checker: &SceneChecker,
    free: &[f64],
    hit: &[f64],
    tolerance: f64,
) -> [Vec<f64>; 2] {
    let at = |t: f64| -> Vec<f64> { free.iter().zip(hit).map(|(a, b)| a + t * (b - a)).collect() };
    let (mut lo, mut hi) = (0.0, 1.0);
    while hi - lo > tolerance {
        let mid = 0.5 * (lo + hi);
        if checker.is_valid(&at(mid)) {
            lo = mid
        } else {
            hi = mid
        }
    }
    [at(lo), at(hi)]
}

#[test]
fn pieces_proved_together_are_free_at_every_sampled_state() {
    // Pieces (a midpoint, random or near contact, and a half vector up to
    // 0.1 rad per joint) in every test scene, 13 at a time (a full batch
    // and a partial one). A piece the grown spheres prove free must have
    // every state along it valid (sampled 81 times, ends included); for a
    // piece left unproved, a body said clear of the scene must not touch it
    // at any sampled state, nor the self pairs when they are said clear.
    // The AVX2 and portable builds give the same masks.
    let (chain, model, acm) = panda_with_hand();
    let dof = chain.dof();
    let sweep = SweepBound::new(&model).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let params = CheckerParams {
        padded_motion: true,
        ..batched()
    };
    let (mut proved, mut offered, mut spared) = (0, 0, 0);
    for (name, obstacles) in scenes(&mut rng) {
        let world =
            Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, params).unwrap();
        let (scene_bodies, self_pairs) = checker.checked_parts();
        let lanes = checker.lanes8().expect("a batched checker");
        let states: Vec<Vec<f64>> = (0..400).map(|_| random_state(&chain, &mut rng)).collect();
        let free: Vec<&Vec<f64>> = states.iter().filter(|q| checker.is_valid(q)).collect();
        let hit: Vec<&Vec<f64>> = states.iter().filter(|q| !checker.is_valid(q)).collect();
        for round in 0..60 {
            let span = rng.random_range(0.005..0.1);
            let half: Vec<f64> = (0..dof).map(|_| rng.random_range(-span..span)).collect();
            let rows: Vec<Vec<f64>> = (0..13)
                .map(|i| match (i % 2, hit.is_empty()) {
                    (0, false) => {
                        let (f, h) = (free[(round * 13 + i) % free.len()], hit[(round + i) % hit.len()]);
                        let [near, _] = near_contact(&checker, f, h, 1e-6);
                        near
                    }
                    _ => random_state(&chain, &mut rng),
                })
                .collect();
            let mut cleared = [0u64; 13];
            let free_mask = checker
                .padded_free_batch(&rows.concat(), &half, &mut cleared)
                .unwrap();
            let terms = lanes.pad_terms(&sweep, &half, scene_bodies, self_pairs).unwrap();
            for batch in rows.chunks(8) {
                let mut q = [[0.0f32; 8]; 16];
                for (l, row) in batch.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        q[j][l] = *v as f32;
                    }
                }
                let (mut a, mut b) = ([0u64; 8], [0u64; 8]);
                let simd = lanes.unsure_padded(&q[..dof], &terms, &mut a, false);
                let portable = lanes.unsure_padded(&q[..dof], &terms, &mut b, true);
                assert_eq!((simd, a), (portable, b), "{name}: the builds disagree");
            }
            for (l, m) in rows.iter().enumerate() {
                offered += 1;
                let whole = free_mask & (1 << l) != 0;
                proved += usize::from(whole);
                let bodies = (cleared[l] & !(1 << 63)) as u32;
                let pairs_clear = cleared[l] & (1 << 63) != 0;
                spared += usize::from(!whole && cleared[l] != 0);
                for i in 0..=80 {
                    let sigma = i as f64 / 40.0 - 1.0;
                    let q: Vec<f64> = m.iter().zip(&half).map(|(x, h)| x + sigma * h).collect();
                    if !checker.within_limits(&q) {
                        continue;
                    }
                    assert!(
                        !whole || checker.is_valid(&q),
                        "{name}: piece {m:?} ± {half:?} proved, {q:?} collides"
                    );
                    assert!(
                        !checker.hits_flagged(&q, bodies, 0),
                        "{name}: piece {m:?} ± {half:?}: a body said clear ({bodies:b}) touches the scene at {q:?}"
                    );
                    assert!(
                        !pairs_clear || !checker.hits_flagged(&q, 0, u64::MAX),
                        "{name}: piece {m:?} ± {half:?}: self pairs said clear, {q:?} collides"
                    );
                }
            }
        }
    }
    eprintln!("{proved} of {offered} pieces proved together, {spared} more with parts proved");
    // not vacuous: a good share of the pieces is proved, and of the others
    // some parts
    assert!(proved * 4 > offered, "{proved} of {offered}");
    assert!(spared * 10 > offered, "{spared} of {offered}");
}

#[test]
fn pad_constants_equal_their_sums_joint_by_joint() {
    // The constant terms of the padded batch come from prefix sums; summed
    // here joint by joint from the formula (module doc of `lanes8::padded`):
    // A = Σ_{f<j≤to} L_{j,b} h_j (3 Σ_{f<i<j} h_i + h_j), and the rounding
    // term (a few kinematic margins per radian of the half step) added.
    let (chain, model, acm) = panda_with_hand();
    let sweep = SweepBound::new(&model).unwrap();
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(vec![], &SceneLimits::default()).unwrap()).unwrap());
    let checker = SceneChecker::new(model.clone(), &acm, world, batched()).unwrap();
    let (_, self_pairs) = checker.checked_parts();
    let lanes = checker.lanes8().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let dof = chain.dof();
    let accel = |b: usize, from: Option<usize>, to: usize, d: &[f64]| {
        let first = from.map_or(0, |f| f + 1);
        let mut sum = 0.0;
        for j in first..=to {
            let p: f64 = d[first..j].iter().map(|v| v.abs()).sum();
            sum += sweep.lever(b, j) * d[j].abs() * (3.0 * p + d[j].abs());
        }
        sum
    };
    let mut relative = 0;
    for _ in 0..50 {
        let span = rng.random_range(0.001..0.2);
        let d: Vec<f64> = (0..dof).map(|_| rng.random_range(-span..span)).collect();
        let terms = lanes.pad_terms(&sweep, &d, &[], self_pairs).unwrap();
        let (bodies, pairs) = terms.constants(self_pairs.len());
        let within = |got: f32, want: f64| {
            let got = f64::from(got);
            got >= want && got <= want * 1.01 + 2e-4
        };
        for (b, c) in bodies.iter().enumerate().take(model.body_count()) {
            match (sweep.last(b), c) {
                (None, None) => {}
                (Some(k), Some(c)) => assert!(within(*c, 0.5 * accel(b, None, k, &d)), "body {b}: {c}"),
                other => panic!("body {b}: {other:?}"),
            }
        }
        for (i, p) in pairs.iter().enumerate() {
            let Some((distal, from, to, c)) = *p else { continue };
            let (a, b) = self_pairs[i];
            let proximal = if distal == a as usize { b } else { a } as usize;
            assert_eq!((sweep.last(proximal), sweep.last(distal)), (from, Some(to)));
            let want = 0.5 * accel(distal, from, to, &d);
            assert!(within(c, want), "pair {i}: {c} against {want}");
            relative += usize::from(from.is_some());
        }
    }
    assert!(relative > 100, "{relative} relative pairs");
}

#[test]
fn hostile_pieces_are_left_to_the_one_piece_check() {
    // Half vectors not a number, infinite or beyond any joint's travel, and
    // midpoints outside the limits or not numbers: nothing is proved, no
    // panic; the same rows with a sane half vector are proved.
    let (chain, model, acm) = panda_with_hand();
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(vec![], &SceneLimits::default()).unwrap()).unwrap());
    let params = CheckerParams {
        padded_motion: true,
        ..batched()
    };
    let checker = SceneChecker::new(model, &acm, world, params).unwrap();
    let home = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
    let rows = home.repeat(3);
    let mut cleared = [0u64; 3];
    let sane = [0.01; 7];
    assert_eq!(checker.padded_free_batch(&rows, &sane, &mut cleared), Some(0b111));
    for bad in [f64::NAN, f64::INFINITY, 1e300, 2e4] {
        let mut half = sane;
        half[3] = bad;
        assert_eq!(
            checker.padded_free_batch(&rows, &half, &mut cleared),
            None,
            "{bad}"
        );
    }
    let mut odd = rows.clone();
    odd[0] = f64::NAN;
    odd[7] = chain.joints()[0].upper + 1.0;
    odd[14] = -1e300;
    assert_eq!(checker.padded_free_batch(&odd, &sane, &mut cleared), Some(0));
    assert_eq!(cleared, [0; 3]);
    // too many rows, or too few cleared slots: not offered
    assert_eq!(
        checker.padded_free_batch(&home.repeat(33), &sane, &mut [0; 33]),
        None
    );
    assert_eq!(checker.padded_free_batch(&rows, &sane, &mut [0; 2]), None);
}
