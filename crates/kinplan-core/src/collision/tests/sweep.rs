//! The sweep bound and the padded motion check: levers derived by hand, the
//! bound against the true motion of body points, and padded motions against
//! a fine interpolated check.

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::model::JointAxis;
use super::super::*;
use crate::robot::{ChainSpec, UrdfLimits, builtin_chain, parse_chain};

/// Two revolute z joints: joint 1 at the base, joint 2 1 m along link 1's x.
/// Link 1 carries a 0.1 m sphere 0.5 m out, link 2 a 0.05 m sphere 0.3 m out.
const TWO_LINK: &str = r#"<robot name="two">
  <link name="base"/>
  <link name="l1"><collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
</robot>"#;

/// One revolute z joint swinging a 1 cm sphere at 1 m.
const SWING: &str = r#"<robot name="swing">
  <link name="base"/>
  <link name="arm"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.01"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
</robot>"#;

fn model_of(urdf: &str) -> Arc<RobotModel> {
    let chain = Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    Arc::new(RobotModel::new(chain).unwrap())
}

fn checker_with(model: Arc<RobotModel>, obstacles: Vec<Obstacle>, padded: bool) -> SceneChecker {
    // the Panda's neighbours of neighbours always touch: sample which pairs never or always do
    let acm = match model.body_count() > 2 {
        true => AllowedCollisions::sampled(
            &model,
            &AcmParams {
                samples: 2000,
                ..AcmParams::default()
            },
        )
        .unwrap(),
        false => AllowedCollisions::adjacent(&model),
    };
    let scene = Scene::new(obstacles, &SceneLimits::default()).unwrap();
    let world = Arc::new(SceneGeometry::build(&scene).unwrap());
    let params = CheckerParams {
        padded_motion: padded,
        ..CheckerParams::default()
    };
    SceneChecker::new(model, &acm, world, params).unwrap()
}

/// Every state `resolution` apart or closer along `a → b` valid (brute force).
fn fine_motion_valid(c: &SceneChecker, a: &[f64], b: &[f64], resolution: f64) -> bool {
    let span = a.iter().zip(b).map(|(x, y)| (y - x).abs()).fold(0.0, f64::max);
    let n = (span / resolution).ceil().max(1.0) as usize;
    (0..n).all(|i| {
        let t = i as f64 / n as f64;
        let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect();
        c.is_valid(&q)
    }) && c.is_valid(b) // the end exactly: a + 1·(b − a) may round past a limit
}

/// A body's bounding-sphere centre and its six poles (body frame).
fn sphere_points(body: &super::super::model::Body) -> Vec<Point3<f64>> {
    let mut points = vec![Point3::from(body.center)];
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut p = body.center;
            p[axis] += sign * body.radius;
            points.push(Point3::from(p));
        }
    }
    points
}

/// Points of a body's own shapes (body frame): a capsule's or sphere's ends
/// and the points at its radius from them in 14 directions, a box's corners
/// and centre, the bounding-sphere points of anything else.
fn shape_points(body: &super::super::model::Body) -> Vec<Point3<f64>> {
    use super::super::fast::RobotFast;
    let mut points = Vec::new();
    let mut directions: Vec<Vector3<f64>> = (0..3)
        .flat_map(|k| [-1.0, 1.0].map(|s| Vector3::ith(k, s)))
        .collect();
    for corner in 0..8 {
        let sign = |k: usize| if corner & (1 << k) == 0 { -1.0 } else { 1.0 };
        directions.push(Vector3::new(sign(0), sign(1), sign(2)) / 3f64.sqrt());
    }
    for shape in &body.shapes {
        match shape.fast {
            RobotFast::Swept { a, b, r } => {
                for end in [a, b] {
                    points.push(end);
                    points.extend(directions.iter().map(|u| end + u * r));
                }
            }
            RobotFast::Box { offset, half } => {
                points.push(offset * Point3::origin());
                for corner in 0..8 {
                    let sign = |k: usize| if corner & (1 << k) == 0 { -1.0 } else { 1.0 };
                    points.push(offset * Point3::new(sign(0) * half.x, sign(1) * half.y, sign(2) * half.z));
                }
            }
            RobotFast::None => points.extend(sphere_points(body)),
        }
    }
    points
}

/// Asserts that no point of any body's shapes ([`shape_points`]) moves
/// farther than `pads[b]` from its place in `from` when the robot is at `q`.
fn assert_shapes_within_pads(
    model: &RobotModel,
    from: &[Isometry3<f64>; MAX_BODIES],
    q: &[f64],
    pads: &[f64],
    context: &str,
) -> f64 {
    let mut at = [Isometry3::identity(); MAX_BODIES];
    model.body_poses(q, &mut at);
    let mut tightest = 0.0f64;
    for (b, body) in model.bodies.iter().enumerate() {
        for p in shape_points(body) {
            let moved = (at[b] * p - from[b] * p).norm();
            assert!(
                moved <= pads[b] + 1e-12,
                "{context}, body {b}: moved {moved} > pad {}",
                pads[b]
            );
            if pads[b] > 0.0 {
                tightest = tightest.max(moved / pads[b]);
            }
        }
    }
    tightest
}

/// Asserts that no bounding-sphere point (centre and poles) of any body
/// moves farther than `pads[b]` from its place in `from` when the robot is
/// at `q`.
fn assert_within_pads(
    model: &RobotModel,
    from: &[Isometry3<f64>; MAX_BODIES],
    q: &[f64],
    pads: &[f64],
    context: &str,
) {
    let mut at = [Isometry3::identity(); MAX_BODIES];
    model.body_poses(q, &mut at);
    for (b, body) in model.bodies.iter().enumerate() {
        for p in sphere_points(body) {
            let moved = (at[b] * p - from[b] * p).norm();
            assert!(
                moved <= pads[b] + 1e-12,
                "{context}, body {b}: moved {moved} > pad {}",
                pads[b]
            );
        }
    }
}

/// The built-in Panda (no hand) as collision bodies.
fn panda() -> Arc<RobotModel> {
    Arc::new(RobotModel::new(builtin_chain("franka_panda").unwrap()).unwrap())
}

/// A state drawn uniformly within the joint limits.
fn random_state(joints: &[crate::robot::Joint], rng: &mut ChaCha8Rng) -> Vec<f64> {
    joints
        .iter()
        .map(|j| rng.random_range(j.lower..j.upper))
        .collect()
}

/// Twelve thin posts and plates 0.35–0.8 m from the Panda's base axis.
fn posts(rng: &mut ChaCha8Rng) -> Vec<Obstacle> {
    (0..12)
        .map(|k| {
            let (angle, radius): (f64, f64) = (
                rng.random_range(0.0..std::f64::consts::TAU),
                rng.random_range(0.35..0.8),
            );
            let p = Vector3::new(
                radius * angle.cos(),
                radius * angle.sin(),
                rng.random_range(0.0..1.0),
            );
            let h = Vector3::new(rng.random_range(0.003..0.05), rng.random_range(0.003..0.05), 0.2);
            Obstacle::new(
                format!("b{k}"),
                Isometry3::translation(p.x, p.y, p.z),
                Geometry::Box { half_extents: h },
            )
        })
        .collect()
}

#[test]
fn levers_of_a_two_link_arm_are_the_hand_derived_reaches() {
    let sweep = SweepBound::new(&model_of(TWO_LINK)).unwrap();
    // body 0 = l1: 0.5 + 0.1 from joint 1, untouched by joint 2
    assert!((sweep.lever(0, 0) - 0.6).abs() < 1e-12);
    assert_eq!(sweep.lever(0, 1), 0.0);
    // body 1 = l2: 0.3 + 0.05 from joint 2; from joint 1 also the 1 m link
    assert!((sweep.lever(1, 1) - 0.35).abs() < 1e-12);
    assert!((sweep.lever(1, 0) - 1.35).abs() < 1e-12);
    let mut pads = [0.0; MAX_BODIES];
    sweep.pads(&[0.1, -0.2], &mut pads);
    assert!((pads[0] - 0.06).abs() < 1e-12);
    assert!((pads[1] - (0.135 + 0.07)).abs() < 1e-12);
}

#[test]
fn no_point_of_a_panda_body_moves_farther_than_its_pad() {
    let model = panda();
    let sweep = SweepBound::new(&model).unwrap();
    let joints = model.chain().joints().to_vec();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut at_a, mut at_t) = (
        [Isometry3::identity(); MAX_BODIES],
        [Isometry3::identity(); MAX_BODIES],
    );
    let mut tightest = 0.0_f64;
    for _ in 0..300 {
        let q = random_state(&joints, &mut rng);
        let dq: Vec<f64> = (0..q.len()).map(|_| rng.random_range(-0.1..0.1)).collect();
        let mut pads = [0.0; MAX_BODIES];
        sweep.pads(&dq, &mut pads);
        model.body_poses(&q, &mut at_a);
        for s in 1..=20 {
            let t = f64::from(s) / 20.0;
            let qt: Vec<f64> = q.iter().zip(&dq).map(|(x, d)| x + t * d).collect();
            model.body_poses(&qt, &mut at_t);
            for (b, body) in model.bodies.iter().enumerate() {
                // the bounding sphere's centre and its six poles
                for p in sphere_points(body) {
                    let moved = (at_t[b] * p - at_a[b] * p).norm();
                    assert!(
                        moved <= pads[b] + 1e-12,
                        "body {b}: moved {moved} > pad {}",
                        pads[b]
                    );
                    if pads[b] > 0.0 {
                        tightest = tightest.max(moved / pads[b]);
                    }
                }
            }
        }
    }
    // the bound is not vacuous: some point comes within a factor 3 of it
    assert!(tightest > 0.33, "tightest ratio {tightest}");
}

#[test]
fn a_padded_check_finds_the_graze_between_two_checked_states() {
    // A 2 mm cube where the swinging sphere passes at θ = 0; the motion
    // θ = -0.025 → 0.025 (one 0.05 rad step) has free end states.
    let cube = Obstacle::new(
        "cube",
        Isometry3::translation(1.0, 0.0, 0.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.001),
        },
    );
    let (a, b) = ([-0.025], [0.025]);
    let plain = checker_with(model_of(SWING), vec![cube.clone()], false);
    let padded = checker_with(model_of(SWING), vec![cube], true);
    assert!(plain.is_valid(&a) && plain.is_valid(&b));
    assert!(
        !fine_motion_valid(&plain, &a, &b, 1e-4),
        "the motion does collide"
    );
    assert!(plain.motion_valid(&a, &b), "0.05 rad interpolation misses it");
    assert!(!padded.motion_valid(&a, &b), "padding catches it");
    assert_eq!(padded.motion_check(), MotionCheck::Padded { resolution: 0.05 });
    // swinging on the far side is free for both
    assert!(plain.motion_valid(&[2.0], &[3.0]) && padded.motion_valid(&[2.0], &[3.0]));
}

#[test]
fn every_motion_a_padded_panda_check_accepts_is_free_at_a_fine_resolution() {
    let model = panda();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let obstacles = posts(&mut rng);
    let plain = checker_with(model.clone(), obstacles.clone(), false);
    let padded = checker_with(model.clone(), obstacles, true);
    let joints = model.chain().joints().to_vec();
    let (mut accepted, mut plain_misses) = (0, 0);
    for _ in 0..400 {
        let a = random_state(&joints, &mut rng);
        let b: Vec<f64> = a
            .iter()
            .zip(&joints)
            .map(|(x, j)| (x + rng.random_range(-0.3..0.3)).clamp(j.lower, j.upper))
            .collect();
        let truth = fine_motion_valid(&plain, &a, &b, 0.002);
        if padded.motion_valid(&a, &b) {
            accepted += 1;
            assert!(truth, "a padded check accepted a colliding motion {a:?} → {b:?}");
        }
        if plain.motion_valid(&a, &b) && !truth {
            plain_misses += 1;
        }
    }
    // the padded check still accepts free motions (it is not vacuous)
    assert!(accepted > 40, "accepted {accepted}");
    eprintln!("padded accepted {accepted}; plain interpolation missed {plain_misses} collisions");
}

#[test]
fn an_unlimited_prismatic_joint_after_a_revolute_one_cannot_be_padded() {
    // A prismatic probe moves each point by |Δq| per joint, limits or not.
    let probe = super::probe_urdf(r#"<sphere radius="0.02"/>"#)
        .replace(r#"lower="-10" upper="10""#, r#"lower="-inf" upper="inf""#);
    let probe = model_of(&probe);
    assert!(probe.chain().joints().iter().all(|j| !j.upper.is_finite()));
    let mut pads = [0.0; MAX_BODIES];
    SweepBound::new(&probe)
        .unwrap()
        .pads(&[0.01, -0.02, 0.03], &mut pads);
    assert!((pads[0] - 0.06).abs() < 1e-15);
    // A telescope on a turntable: the turntable's lever is unbounded.
    let telescope = r#"<robot name="t"><link name="base"/><link name="turn"/>
      <link name="tip"><collision><geometry><sphere radius="0.02"/></geometry></collision></link>
      <joint name="r" type="revolute"><parent link="base"/><child link="turn"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
      <joint name="p" type="prismatic"><parent link="turn"/><child link="tip"/><axis xyz="1 0 0"/>
        <limit lower="-inf" upper="inf" effort="0" velocity="1"/></joint></robot>"#;
    let model = model_of(telescope);
    assert!(SweepBound::new(&model).is_none());
    let acm = AllowedCollisions::adjacent(&model);
    let world = Arc::new(SceneGeometry::build(&Scene::empty()).unwrap());
    let params = CheckerParams {
        padded_motion: true,
        ..CheckerParams::default()
    };
    let err = SceneChecker::new(model.clone(), &acm, world.clone(), params).unwrap_err();
    assert_eq!(err, CollisionError::CannotPad);
    // an unpadded checker of the same robot works, and fails padded states
    let plain = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
    assert!(plain.is_valid(&[0.0, 0.5]));
    assert_eq!(plain.padded_valid(&[0.0, 0.5], &[0.01, 0.01]), None);
    assert_eq!(
        padded_motion_valid(&plain, &[0.0, 0.5], &[0.1, 0.6], 0.05, crate::Deadline::none()),
        Some(false)
    );
    assert!(plain.motion_valid(&[0.0, 0.5], &[0.1, 0.6]));
}

#[test]
fn rrt_connect_with_padded_motions_returns_paths_free_at_a_fine_resolution() {
    use crate::plan::{Algorithm, Goal, PlanControl, PlanRequest, PlanStatus, plan};
    let model = panda();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let obstacles = posts(&mut rng);
    let plain = checker_with(model.clone(), obstacles.clone(), false);
    let padded = checker_with(model.clone(), obstacles, true);
    let joints = model.chain().joints().to_vec();
    let mut random_valid = || loop {
        let q = random_state(&joints, &mut rng);
        if padded.padded_valid(&q, &[0.0; 7]) == Some(true) {
            return q;
        }
    };
    let mut solved = 0;
    for seed in 0..6 {
        let (start, goal) = (random_valid(), random_valid());
        let request = PlanRequest {
            start: start.clone(),
            goal: Goal::Joints(goal.clone()),
            algorithm: Algorithm::RrtConnect,
            seed,
            ..Default::default()
        };
        let r = plan(model.chain(), &padded, &request, PlanControl::default()).unwrap();
        if r.status != PlanStatus::Succeeded {
            continue;
        }
        solved += 1;
        assert!(r.valid);
        for w in r.q.chunks_exact(7).collect::<Vec<_>>().windows(2) {
            assert!(
                fine_motion_valid(&plain, w[0], w[1], 0.002),
                "seed {seed}: a segment collides"
            );
        }
    }
    assert!(solved >= 4, "solved {solved} of 6");
}

#[test]
fn pieces_are_halved_along_a_near_wall_until_their_pads_fit() {
    // The xyz probe (a 2 cm sphere) slides 5 cm along x beside a wall.
    let wall_at = |gap: f64| {
        Obstacle::new(
            "wall",
            Isometry3::translation(0.0, 0.02 + gap + 0.005, 0.0),
            Geometry::Box {
                half_extents: Vector3::new(1.0, 0.005, 1.0),
            },
        )
    };
    let probe = || model_of(&super::probe_urdf(r#"<sphere radius="0.02"/>"#));
    let (a, b) = ([0.0, 0.0, 0.0], [0.05, 0.0, 0.0]);
    // 5 mm away: one 5 cm piece pads 2.5 cm; halved three times it pads
    // 3.1 mm < 5 mm, so the motion is proved free
    let padded = checker_with(probe(), vec![wall_at(0.005)], true);
    assert!(padded.motion_valid(&a, &b));
    // 0.1 mm away it would take pieces of 0.1 mm: more than the budget
    let padded = checker_with(probe(), vec![wall_at(0.0001)], true);
    let plain = checker_with(probe(), vec![wall_at(0.0001)], false);
    assert!(plain.motion_valid(&a, &b) && fine_motion_valid(&plain, &a, &b, 1e-4));
    assert!(
        !padded.motion_valid(&a, &b),
        "refused: conservative within its budget"
    );
    // touching: refused
    let padded = checker_with(probe(), vec![wall_at(0.0)], true);
    assert!(!padded.motion_valid(&a, &b));
}

#[test]
fn a_grown_shape_hits_whatever_is_within_the_margin_and_little_beyond() {
    // Every probe shape against every obstacle kind, at random positions:
    // a clearance below the margin must be a padded hit, and a padded hit
    // is at most √3 margins away (a box grows into the box around the
    // rounded one; everything else grows exactly).
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for (probe, geometry, _, meshes) in super::probes() {
        for (obstacle, shape, _, _) in super::obstacles() {
            let c = super::checker(
                &super::probe_urdf(&geometry),
                &meshes,
                vec![Obstacle::new("o", Isometry3::identity(), shape)],
            );
            for _ in 0..60 {
                let q = [
                    rng.random_range(-0.6..0.6),
                    rng.random_range(-0.6..0.6),
                    rng.random_range(-0.6..0.6),
                ];
                let d = c.clearance(&q, 1.0);
                for margin in [0.005, 0.02, 0.05] {
                    let hit = c.in_collision_padded(&q, &[margin; MAX_BODIES]);
                    assert!(
                        d >= margin || hit,
                        "{probe} vs {obstacle} at {q:?}: clearance {d} < {margin}, no hit"
                    );
                    assert!(
                        !hit || d <= margin * 3f64.sqrt() + 1e-9,
                        "{probe} vs {obstacle} at {q:?}: hit at clearance {d} > √3·{margin}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_bound_around_a_state_holds_for_the_true_motion_and_is_tighter() {
    let model = panda();
    let sweep = SweepBound::new(&model).unwrap();
    let joints = model.chain().joints().to_vec();
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let mut at_m = [Isometry3::identity(); MAX_BODIES];
    let mut axes = [JointAxis::default(); 7];
    let (mut ratio_sum, mut ratio_count) = (0.0, 0);
    for _ in 0..300 {
        let m = random_state(&joints, &mut rng);
        let half: Vec<f64> = (0..7).map(|_| rng.random_range(0.0..0.05)).collect();
        model.body_poses_and_axes(&m, &mut at_m, &mut axes);
        let (mut near, mut far) = ([0.0; MAX_BODIES], [0.0; MAX_BODIES]);
        sweep.pads_at(&model, &at_m, &axes, &half, &mut near);
        sweep.pads(&half, &mut far);
        for k in 0..40 {
            // a state within `half` of m on every joint
            let s: Vec<f64> = m
                .iter()
                .zip(&half)
                .map(|(x, h)| x + h * if k == 0 { 1.0 } else { rng.random_range(-1.0..1.0) })
                .collect();
            assert_within_pads(&model, &at_m, &s, &near, "around a state");
        }
        for b in 0..model.body_count() {
            assert!(near[b] <= far[b] + 1e-15, "body {b}: {} > {}", near[b], far[b]);
            if far[b] > 0.0 {
                ratio_sum += near[b] / far[b];
                ratio_count += 1;
            }
        }
    }
    let mean = ratio_sum / f64::from(ratio_count);
    assert!(
        mean < 0.9,
        "the bound around a state is no tighter: mean ratio {mean}"
    );
    eprintln!("pads around a state / global pads: mean {mean:.3}");
}

#[test]
fn the_bound_around_a_bent_elbow_covers_every_state_of_the_piece() {
    // The two-link arm with point-like spheres, elbow bent: within the piece
    // the elbow opens, so the tip's distance from joint 1's axis grows and
    // joint 1 moves it farther than the distance at the midpoint says.
    let urdf = TWO_LINK
        .replace(r#"radius="0.1""#, r#"radius="0.000001""#)
        .replace(r#"radius="0.05""#, r#"radius="0.000001""#);
    let model = model_of(&urdf);
    let sweep = SweepBound::new(&model).unwrap();
    let (mut at_m, mut at_s) = (
        [Isometry3::identity(); MAX_BODIES],
        [Isometry3::identity(); MAX_BODIES],
    );
    let mut axes = [JointAxis::default(); 2];
    let m = [0.0, 2.0];
    let half = [0.4, 0.6];
    model.body_poses_and_axes(&m, &mut at_m, &mut axes);
    let mut pads = [0.0; MAX_BODIES];
    sweep.pads_at(&model, &at_m, &axes, &half, &mut pads);
    let tip = Point3::from(model.bodies[1].center);
    let mut worst: f64 = 0.0;
    for i in 0..=40 {
        for k in 0..=40 {
            let s = [
                m[0] - half[0] + 2.0 * half[0] * f64::from(i) / 40.0,
                m[1] - half[1] + 2.0 * half[1] * f64::from(k) / 40.0,
            ];
            model.body_poses(&s, &mut at_s);
            worst = worst.max((at_s[1] * tip - at_m[1] * tip).norm());
        }
    }
    assert!(worst <= pads[1], "the tip moved {worst} > pad {}", pads[1]);
}

/// A checker that counts its padded checks; without `spare` it proves
/// halves as the trait's default does (every part again).
struct CountingPads<'a> {
    inner: &'a SceneChecker,
    padded: std::sync::atomic::AtomicUsize,
    spare: bool,
}

impl<'a> CountingPads<'a> {
    fn new(inner: &'a SceneChecker, spare: bool) -> Self {
        CountingPads {
            inner,
            padded: 0.into(),
            spare,
        }
    }
}

impl StateChecker for CountingPads<'_> {
    fn dof(&self) -> usize {
        self.inner.dof()
    }
    fn is_valid(&self, q: &[f64]) -> bool {
        self.inner.is_valid(q)
    }
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
        self.inner.clearance(q, max_distance)
    }
    fn padded_verdict(&self, q: &[f64], half_step: &[f64]) -> Option<PadVerdict> {
        self.padded.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.inner.padded_verdict(q, half_step)
    }
    fn padded_verdict_sparing(&self, q: &[f64], half_step: &[f64], proved: &mut u64) -> Option<PadVerdict> {
        if !self.spare {
            return self.padded_verdict(q, half_step);
        }
        self.padded.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.inner.padded_verdict_sparing(q, half_step, proved)
    }
}

#[test]
fn a_motion_through_an_obstacle_is_refused_before_grazing_pieces_are_halved() {
    // The swing (1 cm sphere at 1 m) turns −1.6 → 1.6 rad: 32 first pieces
    // of 0.1 (two resolutions of 0.05). A cube 0.1 mm off its circle at
    // θ = −1.58 (piece 0, visited first) takes many halvings to prove
    // clear; a wall across the circle at θ = 1.55 (the midpoint of piece
    // 31, visited last) blocks the motion outright.
    let at = |theta: f64, r: f64| Isometry3::translation(theta.cos() * r, theta.sin() * r, 0.0);
    let graze = Obstacle::new(
        "graze",
        at(-1.58, 1.0111),
        Geometry::Box {
            half_extents: Vector3::repeat(0.001),
        },
    );
    let wall = Obstacle::new(
        "wall",
        at(1.55, 1.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.005),
        },
    );
    let checker = checker_with(model_of(SWING), vec![graze, wall], true);
    let (a, b) = ([-1.6], [1.6]);
    assert!(checker.is_valid(&a) && checker.is_valid(&b));
    let counting = CountingPads::new(&checker, true);
    assert_eq!(
        padded_motion_valid(&counting, &a, &b, 0.05, crate::Deadline::none()),
        Some(false)
    );
    // breadth first: the 32 midpoints are checked before any piece is
    // halved, and the wall's midpoint refuses the motion (depth first would
    // halve piece 0 first, then check the 31 others)
    let checks = counting.padded.into_inner();
    assert!(checks <= 32, "{checks} padded checks");
}

#[test]
fn rrt_connect_under_padded_motions_replaces_a_grazing_edge() {
    use crate::plan::{RrtParams, RrtStop, rrt_connect};
    // The xyz probe (a 2 cm sphere) moves 5 cm along x: the straight motion
    // passes a 4 mm cube 1 mm closer than the sphere's radius at x = 0 but
    // its ends are free, and at a 0.05 m resolution no state between them
    // is checked — the interpolated search accepts it, the proof must not.
    let cube = Obstacle::new(
        "cube",
        Isometry3::translation(0.0, 0.021, 0.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.002),
        },
    );
    let probe = || model_of(&super::probe_urdf(r#"<sphere radius="0.02"/>"#));
    let plain = checker_with(probe(), vec![cube.clone()], false);
    let padded = checker_with(probe(), vec![cube], true);
    let (a, b) = ([-0.025, 0.0, 0.0], [0.025, 0.0, 0.0]);
    assert!(plain.motion_valid(&a, &b) && !fine_motion_valid(&plain, &a, &b, 1e-4));
    let chain = padded.model().chain().clone();
    for seed in 0..4 {
        let out = rrt_connect(
            &chain,
            &plain,
            &a,
            &b,
            &RrtParams::default(),
            seed,
            crate::Deadline::none(),
        )
        .unwrap();
        assert_eq!(
            out.path.len(),
            6,
            "the interpolated search takes the straight motion"
        );
        let out = rrt_connect(
            &chain,
            &padded,
            &a,
            &b,
            &RrtParams::default(),
            seed,
            crate::Deadline::none(),
        )
        .unwrap();
        assert_eq!(out.stop, RrtStop::Connected);
        assert!(out.path.len() > 6, "seed {seed}: a detour");
        assert_eq!(
            (&out.path[..3], &out.path[out.path.len() - 3..]),
            (&a[..], &b[..])
        );
        for w in out.path.chunks_exact(3).collect::<Vec<_>>().windows(2) {
            assert!(
                fine_motion_valid(&plain, w[0], w[1], 1e-4),
                "seed {seed}: a segment collides"
            );
        }
    }
}

#[test]
fn the_bound_along_a_piece_holds_for_its_states_and_is_tighter_than_the_box() {
    // Random Panda pieces m ± d, from 0.05 rad (the resolution) to 0.8 rad
    // long on their largest joint: every state sampled along the piece moves
    // every bounding-sphere point within the segment bound, and on pieces of
    // one resolution that bound is mostly below the box bound.
    let model = panda();
    let sweep = SweepBound::new(&model).unwrap();
    let joints = model.chain().joints().to_vec();
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let mut at_m = [Isometry3::identity(); MAX_BODIES];
    let mut axes = [JointAxis::default(); 7];
    let mut ratios = Vec::new();
    for k in 0..400 {
        let m = random_state(&joints, &mut rng);
        let span = [0.025, 0.1, 0.4][k % 3];
        let d: Vec<f64> = (0..7).map(|_| rng.random_range(-span..span)).collect();
        model.body_poses_and_axes(&m, &mut at_m, &mut axes);
        let along: Vec<f64> = (0..model.body_count())
            .map(|b| sweep.pad_along(&model, b, &at_m[b], &axes, &d))
            .collect();
        let boxed: Vec<f64> = (0..model.body_count())
            .map(|b| sweep.pad_at(&model, b, &at_m[b], &axes, &d))
            .collect();
        // the sums shared by a piece's bodies and the sum over one body's
        // joints are the same bound, regrouped (the latter serves long chains)
        for (b, shared) in along.iter().enumerate() {
            let alone = sweep.pad_along_alone(&model, b, &at_m[b], &axes, &d);
            assert!(
                (shared - alone).abs() <= 1e-12 * (1.0 + alone),
                "body {b}: {shared} vs {alone}"
            );
        }
        for i in -20..=20 {
            let s = f64::from(i) / 20.0;
            let q: Vec<f64> = m.iter().zip(&d).map(|(x, dj)| x + s * dj).collect();
            assert_within_pads(&model, &at_m, &q, &along, &format!("along a piece, s = {s}"));
        }
        for b in 0..model.body_count() {
            if boxed[b] > 0.0 && span == 0.025 {
                ratios.push(along[b] / boxed[b]);
            }
        }
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    eprintln!("segment / box bound on 0.05 rad pieces: mean {mean:.3}");
    assert!(mean < 0.8, "the segment bound is no tighter: mean ratio {mean}");
}

#[test]
fn the_bound_along_a_piece_holds_for_the_corners_of_the_hand_and_fingers() {
    // The Panda with its hand (a box) and fingers (boxes) held open: every
    // corner and every capsule point sampled along random pieces stays
    // within the bound taken over the shapes' extreme points.
    let model = super::panda_hand_open();
    let sweep = SweepBound::new(&model).unwrap();
    let joints = model.chain().joints().to_vec();
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut at_m = [Isometry3::identity(); MAX_BODIES];
    let mut axes = [JointAxis::default(); 7];
    let mut tightest = 0.0f64;
    for k in 0..300 {
        let m = random_state(&joints, &mut rng);
        let span = [0.025, 0.1, 0.4][k % 3];
        let d: Vec<f64> = (0..7).map(|_| rng.random_range(-span..span)).collect();
        model.body_poses_and_axes(&m, &mut at_m, &mut axes);
        let along: Vec<f64> = (0..model.body_count())
            .map(|b| sweep.pad_along(&model, b, &at_m[b], &axes, &d))
            .collect();
        for i in -10..=10 {
            let s = f64::from(i) / 10.0;
            let q: Vec<f64> = m.iter().zip(&d).map(|(x, dj)| x + s * dj).collect();
            let t = assert_shapes_within_pads(&model, &at_m, &q, &along, &format!("hand, s = {s}"));
            tightest = tightest.max(t);
        }
    }
    // not vacuous: some point moves most of its pad
    assert!(tightest > 0.8, "tightest ratio {tightest}");
}

#[test]
fn halves_that_skip_the_parts_proved_over_their_piece_accept_more_and_stay_sound() {
    // Panda motions among posts: proving a piece's halves only for the
    // bodies not yet proved free over the whole piece accepts every motion
    // the full checks accept (a body free over a piece is free over its
    // halves), every motion it accepts is free at 2 mm, and it needs no
    // more padded checks.
    let model = panda();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let obstacles = posts(&mut rng);
    let plain = checker_with(model.clone(), obstacles.clone(), false);
    let padded = checker_with(model.clone(), obstacles, true);
    let counting = CountingPads::new(&padded, true);
    let unspared = CountingPads::new(&padded, false);
    let joints = model.chain().joints().to_vec();
    let (mut accepted, mut only_spared) = (0, 0);
    for _ in 0..300 {
        let a = random_state(&joints, &mut rng);
        let b: Vec<f64> = a
            .iter()
            .zip(&joints)
            .map(|(x, j)| (x + rng.random_range(-0.4..0.4)).clamp(j.lower, j.upper))
            .collect();
        if !(plain.is_valid(&a) && plain.is_valid(&b)) {
            continue;
        }
        let spared = padded_motion_valid(&counting, &a, &b, 0.05, crate::Deadline::none()).unwrap();
        let full = padded_motion_valid(&unspared, &a, &b, 0.05, crate::Deadline::none()).unwrap();
        assert!(spared || !full, "{a:?} → {b:?}: accepted by full checks only");
        if spared {
            accepted += 1;
            only_spared += usize::from(!full);
            assert!(fine_motion_valid(&plain, &a, &b, 0.002), "{a:?} → {b:?} collides");
        }
    }
    let (spared_checks, full_checks) = (counting.padded.into_inner(), unspared.padded.into_inner());
    eprintln!(
        "accepted {accepted} ({only_spared} only when sparing); padded checks {spared_checks} sparing, {full_checks} not"
    );
    assert!(accepted > 40, "accepted {accepted}");
    assert!(spared_checks <= full_checks);
}

#[test]
fn a_padded_check_reports_the_bodies_it_proved_and_skips_those_given() {
    // The two-link arm stretched along x; a 2 cm cube 2 cm beside link 2's
    // sphere (centre 1.3 m out): turning joint 2 by ±0.1 rad may bring the
    // sphere 3.5 cm sideways, so link 2 is not proved. A second cube 19 cm
    // beside link 1's sphere, within its reach: joint 1 does not move, so
    // link 1 is proved.
    let cube = |x: f64, y: f64| {
        Obstacle::new(
            "cube",
            Isometry3::translation(x, y, 0.0),
            Geometry::Box {
                half_extents: Vector3::repeat(0.01),
            },
        )
    };
    let checker = checker_with(model_of(TWO_LINK), vec![cube(1.3, 0.08), cube(0.5, 0.3)], true);
    let (q, half) = ([0.0, 0.0], [0.0, 0.1]);
    let mut proved = 0u64;
    assert_eq!(
        checker.padded_verdict_sparing(&q, &half, &mut proved),
        Some(PadVerdict::Unproved)
    );
    assert_eq!(
        proved & 0b11,
        0b01,
        "link 1 (body 0) proved, link 2 not: {proved:#b}"
    );
    // told that link 2 is proved, the same piece passes on link 1 alone
    let mut given = proved | 0b10;
    assert_eq!(
        checker.padded_verdict_sparing(&q, &half, &mut given),
        Some(PadVerdict::Free)
    );
    // a smaller step proves link 2 as well
    let mut proved = 0u64;
    assert_eq!(
        checker.padded_verdict_sparing(&q, &[0.0, 0.02], &mut proved),
        Some(PadVerdict::Free)
    );
    assert_eq!(proved & 0b11, 0b11);
}

#[test]
fn a_padded_check_refuses_a_colliding_state_whichever_obstacle_it_meets_first() {
    // The xyz probe (2 cm sphere) at the origin: one cube 1 cm beyond its
    // surface (within any pad of a few cm, not touching) and one cube
    // through it, in both scene orders: the verdict is Collides, not
    // Unproved, whichever cube the check meets first.
    let near = Obstacle::new(
        "near",
        Isometry3::translation(0.04, 0.0, 0.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.01),
        },
    );
    let through = Obstacle::new(
        "through",
        Isometry3::translation(0.0, -0.015, 0.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.01),
        },
    );
    let probe = || model_of(&super::probe_urdf(r#"<sphere radius="0.02"/>"#));
    for obstacles in [vec![near.clone(), through.clone()], vec![through, near.clone()]] {
        let checker = checker_with(probe(), obstacles, true);
        assert_eq!(
            checker.padded_verdict(&[0.0, 0.0, 0.0], &[0.03, 0.0, 0.0]),
            Some(PadVerdict::Collides)
        );
    }
    // the near cube alone: not proved with the 3 cm step, and not colliding
    let checker = checker_with(probe(), vec![near], true);
    assert_eq!(
        checker.padded_verdict(&[0.0, 0.0, 0.0], &[0.03, 0.0, 0.0]),
        Some(PadVerdict::Unproved)
    );
}

#[test]
fn a_refused_motion_says_where_it_was_refused() {
    // The swing (1 cm sphere at 1 m) turning 0 → 1.6 rad against a 1 cm
    // cube on its circle at θ = 1.2: refused within 0.1 rad of it (first
    // pieces are 0.1 rad long, 1.2 on a border), and proved free on the
    // far side.
    let wall = Obstacle::new(
        "wall",
        Isometry3::translation(1.2f64.cos(), 1.2f64.sin(), 0.0),
        Geometry::Box {
            half_extents: Vector3::repeat(0.005),
        },
    );
    let checker = checker_with(model_of(SWING), vec![wall], true);
    match padded_motion(&checker, &[0.0], &[1.6], 0.05, crate::Deadline::none()) {
        PaddedMotion::Refused { at } => {
            assert!((at * 1.6 - 1.2).abs() <= 0.1, "refused at θ = {}", at * 1.6)
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        padded_motion(&checker, &[-1.0], &[-2.5], 0.05, crate::Deadline::none()),
        PaddedMotion::Free
    );
    // a free motion of at least 32 pieces: asked at the 32nd check
    assert_eq!(
        padded_motion(
            &checker,
            &[-3.0],
            &[1.0],
            0.05,
            crate::Deadline::none().with_cancel(&|| true)
        ),
        PaddedMotion::Interrupted
    );
}
