//! The batched check (`lanes`): forward kinematics in lanes against the
//! scalar poses; the sphere verdicts against the exact check on random and
//! near-contact states in MotionBenchMaker-like scenes (a table, shelves, a
//! cage of bars, clutter of boxes, cylinders and spheres), never clear where
//! the exact check finds a collision; the AVX2 and portable builds bit for
//! bit.

use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::lanes::{LANES, Lane, LaneFrame, MAX_LANE_BODIES, MAX_LANE_DOF};
use super::super::*;
use super::probe_urdf;
use crate::robot::{Chain, ChainSpec, UrdfLimits, builtin_chain, builtin_urdf, parse_chain};

/// The Panda with its hand, fingers 4 cm open (as the benchmark runs it).
pub(super) fn panda_with_hand() -> (Arc<Chain>, Arc<RobotModel>, AllowedCollisions) {
    let chain = builtin_chain("franka_panda").unwrap();
    let urdf = builtin_urdf("franka_panda_hand").unwrap();
    let fingers = [("panda_finger_joint1", 0.04), ("panda_finger_joint2", 0.04)];
    let attached = attached_bodies(urdf, &chain, &fingers).unwrap();
    let model = Arc::new(RobotModel::with_parts(chain.clone(), &attached, &[]).unwrap());
    let acm = AllowedCollisions::builtin(&model, "franka_panda_hand", &AcmParams::default()).unwrap();
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

/// Joint-major lanes of up to [`LANES`] states (the last one repeated).
fn lanes_of(states: &[Vec<f64>], dof: usize) -> [Lane; MAX_LANE_DOF] {
    let mut q = [[0.0; LANES]; MAX_LANE_DOF];
    for l in 0..LANES {
        let s = &states[l.min(states.len() - 1)];
        for j in 0..dof {
            q[j][l] = s[j];
        }
    }
    q
}

#[test]
fn batched_forward_kinematics_equals_the_scalar_poses_in_both_builds() {
    let (_, panda, _) = panda_with_hand();
    let mixed = Arc::new(
        RobotModel::new(Arc::new(
            parse_chain(&mixed_chain_urdf(), &ChainSpec::default(), UrdfLimits::default()).unwrap(),
        ))
        .unwrap(),
    );
    let probe = Arc::new(
        RobotModel::new(Arc::new(
            parse_chain(
                &probe_urdf(r#"<box size="0.1 0.2 0.3"/>"#),
                &ChainSpec::default(),
                UrdfLimits::default(),
            )
            .unwrap(),
        ))
        .unwrap(),
    );
    let empty =
        Arc::new(SceneGeometry::build(&Scene::new(vec![], &SceneLimits::default()).unwrap()).unwrap());
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for model in [panda, mixed, probe] {
        let chain = model.chain().clone();
        let dof = chain.dof();
        let spheres = SphereModel::build(&model, &SphereParams::default()).unwrap();
        let lanes = super::super::lanes::Lanes::new(&model, &spheres, &empty).unwrap();
        assert_eq!(lanes.body_count(), model.body_count());
        let mut worst = 0.0f64;
        for _ in 0..200 {
            let states: Vec<Vec<f64>> = (0..LANES).map(|_| random_state(&chain, &mut rng)).collect();
            let q = lanes_of(&states, dof);
            let mut frames = [LaneFrame::IDENTITY; MAX_LANE_BODIES];
            let mut simd = [LaneFrame::IDENTITY; MAX_LANE_BODIES];
            lanes.body_frames(&q[..dof], &mut frames, true);
            lanes.body_frames(&q[..dof], &mut simd, false);
            for (l, s) in states.iter().enumerate() {
                let mut poses = [Isometry3::identity(); MAX_BODIES];
                model.body_poses(s, &mut poses);
                for b in 0..model.body_count() {
                    // the lanes keep the joint frame (body offsets are folded
                    // into the spheres): the body's pose without its offset
                    let body = &model.bodies[b];
                    let joint_frame = poses[b] * (chain.links()[body.link].offset * body.offset).inverse();
                    let m = joint_frame.rotation.to_rotation_matrix();
                    let (f, g) = (&frames[b], &simd[b]);
                    for i in 0..3 {
                        worst = worst.max((f.p[i][l] - joint_frame.translation.vector[i]).abs());
                        assert_eq!(f.p[i][l].to_bits(), g.p[i][l].to_bits());
                        for k in 0..3 {
                            worst = worst.max((f.r[i][k][l] - m[(i, k)]).abs());
                            assert_eq!(f.r[i][k][l].to_bits(), g.r[i][k][l].to_bits());
                        }
                    }
                }
            }
        }
        assert!(worst <= 1e-12, "{}: worst {worst:e}", chain.name());
    }
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

/// The lanes' unsure mask (bit `l` set: the spheres do not clear state `l`)
/// of up to [`LANES`] states, from the AVX2 build or the portable one.
fn unsure(checker: &SceneChecker, batch: &[Vec<f64>], portable: bool) -> u32 {
    let lanes = checker.lanes().expect("a batched checker");
    let (scene_bodies, self_pairs) = checker.checked_parts();
    let q = lanes_of(batch, lanes.dof());
    let mut frames = [LaneFrame::IDENTITY; MAX_LANE_BODIES];
    lanes.unsure(
        &q[..lanes.dof()],
        &checker.world().bvh,
        scene_bodies,
        self_pairs,
        &mut frames,
        portable,
    )
}

#[test]
fn sphere_verdicts_never_clear_a_colliding_state_and_batches_give_the_exact_answer() {
    let (chain, model, acm) = panda_with_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(25);
    for (name, obstacles) in scenes(&mut rng) {
        let world =
            Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, batched()).unwrap();
        assert!(
            checker.lanes().is_some(),
            "{name}: the Panda in a small scene is batched"
        );
        // random states, then states within 1e-7 rad of the boundary between
        // a free and a colliding one (bisected along the line between them)
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
            let (mut lo, mut hi) = (0.0, 1.0);
            let at = |t: f64| -> Vec<f64> { f.iter().zip(h).map(|(a, b)| a + t * (b - a)).collect() };
            while hi - lo > 1e-7 {
                let mid = 0.5 * (lo + hi);
                if checker.is_valid(&at(mid)) {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            states.push(at(lo));
            states.push(at(hi));
        }
        let (mut colliding, mut clear, mut free_count) = (0, 0, 0);
        for batch in states.chunks(LANES) {
            let (simd, portable) = (unsure(&checker, batch, false), unsure(&checker, batch, true));
            assert_eq!(simd, portable, "{name}: builds disagree on {batch:?}");
            for (l, s) in batch.iter().enumerate() {
                let exact = checker.is_valid(s);
                let report = checker.report(s).unwrap().is_valid();
                assert_eq!(exact, report, "{name}: {s:?}");
                let sure = simd & (1 << l) == 0;
                assert!(exact || !sure, "{name}: spheres cleared a colliding state {s:?}");
                colliding += usize::from(!exact);
                free_count += usize::from(exact);
                clear += usize::from(sure);
            }
            let rows: Vec<f64> = batch.concat();
            let expected = batch.iter().all(|s| checker.is_valid(s));
            assert_eq!(checker.states_valid(&rows), expected, "{name}: {batch:?}");
            assert_eq!(
                checker.states_valid_in_lanes(&rows, true),
                Some(expected),
                "{name}"
            );
        }
        eprintln!(
            "{name}: {} states, {colliding} colliding, {clear} of {free_count} free ones cleared by the spheres",
            states.len()
        );
        assert!(colliding > 100, "{name}: {colliding} colliding");
        // the test is not vacuous: the spheres clear most free states
        assert!(
            4 * clear > 3 * free_count,
            "{name}: {clear} of {free_count} cleared"
        );
    }
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

#[test]
fn pieces_proved_together_are_free_at_every_sampled_state() {
    // Random pieces (midpoint, half vector up to 0.1 rad per joint) in the
    // shelf and cage scenes: a piece the grown spheres prove free must have
    // every state along it valid (sampled 41 times, ends included).
    let (chain, model, acm) = panda_with_hand();
    let dof = chain.dof();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let params = CheckerParams {
        padded_motion: true,
        ..batched()
    };
    let (mut proved, mut offered) = (0, 0);
    for (name, obstacles) in scenes(&mut rng).into_iter().skip(1).take(2) {
        let world =
            Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, params).unwrap();
        for _ in 0..150 {
            let span = rng.random_range(0.005..0.1);
            let half: Vec<f64> = (0..dof).map(|_| rng.random_range(-span..span)).collect();
            let rows: Vec<Vec<f64>> = (0..LANES).map(|_| random_state(&chain, &mut rng)).collect();
            let free = checker.padded_free_batch(&rows.concat(), &half).unwrap();
            for (l, m) in rows.iter().enumerate() {
                offered += 1;
                if free & (1 << l) == 0 {
                    continue;
                }
                proved += 1;
                for i in 0..=40 {
                    let sigma = i as f64 / 20.0 - 1.0;
                    let q: Vec<f64> = m.iter().zip(&half).map(|(x, h)| x + sigma * h).collect();
                    let inside = checker.within_limits(&q);
                    assert!(
                        !inside || checker.is_valid(&q),
                        "{name}: piece {m:?} ± {half:?} proved, {q:?} collides"
                    );
                }
            }
        }
    }
    eprintln!("{proved} of {offered} pieces proved together");
    // not vacuous: a good share of the pieces is proved
    assert!(proved * 8 > offered, "{proved} of {offered}");
}

/// On one scene of every MotionBenchMaker set (the real problems, read from
/// the archive beside the repository): 10,000 random states each, in
/// batches of four. The AVX2 and portable builds give the same unsure
/// masks; a state the spheres clear is free by the exact check (so the
/// batched verdict, the spheres' "free" or else the exact check, equals the
/// exact verdict state by state); and the batched `states_valid` answers as
/// the exact check does for each group of five states.
#[test]
fn batched_verdicts_equal_the_exact_ones_on_every_motionbenchmaker_set() {
    let Some(dir) = crate::mbm_data::problems() else {
        return;
    };
    let (chain, model, acm) = panda_with_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(10_000);
    for set in crate::mbm_data::SETS {
        let (scene, _) = crate::mbm_data::problem(&dir, set, 1);
        let scene = parse_planning_scene(&scene, &SceneLimits::default()).unwrap();
        let world = Arc::new(SceneGeometry::build(&scene).unwrap());
        let checker = SceneChecker::new(model.clone(), &acm, world, batched()).unwrap();
        assert!(checker.lanes().is_some(), "{set}: not batched");
        let states: Vec<Vec<f64>> = (0..10_000).map(|_| random_state(&chain, &mut rng)).collect();
        let exact: Vec<bool> = states.iter().map(|q| checker.is_valid(q)).collect();
        let (mut cleared, mut free) = (0, 0);
        for (batch, exact) in states.chunks(LANES).zip(exact.chunks(LANES)) {
            let simd = unsure(&checker, batch, false);
            assert_eq!(
                simd,
                unsure(&checker, batch, true),
                "{set}: the builds disagree on {batch:?}"
            );
            for (l, (s, &exact)) in batch.iter().zip(exact).enumerate() {
                let sure = simd & (1 << l) == 0;
                let batched = sure || !checker.in_collision(s);
                assert_eq!(batched, exact, "{set}: state {s:?}");
                free += usize::from(exact);
                cleared += usize::from(sure);
            }
        }
        for (group, exact) in states.chunks(LANES + 1).zip(exact.chunks(LANES + 1)) {
            let expected = exact.iter().all(|&v| v);
            for portable in [false, true] {
                let rows = group.concat();
                assert_eq!(
                    checker.states_valid_in_lanes(&rows, portable),
                    Some(expected),
                    "{set}: {group:?}"
                );
            }
        }
        eprintln!("{set}: {free} of 10000 states free, {cleared} cleared by the spheres");
        // neither verdict is vacuous on these scenes
        assert!((1_000..9_900).contains(&free), "{set}: {free} free");
        assert!(4 * cleared > 3 * free, "{set}: {cleared} of {free} cleared");
    }
}
