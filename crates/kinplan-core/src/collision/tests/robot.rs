//! Robot-level cases: adjacency and the sampled ACM, self-collision of the
//! Panda, malformed meshes, and motion checks.

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Translation3, Vector3};

use super::super::*;
use super::{box_mesh, checker, panda_hand_open, probe_urdf};
use crate::robot::{ChainSpec, UrdfLimits, builtin_chain, parse_chain};

fn panda_checker(acm: impl Fn(&RobotModel) -> AllowedCollisions) -> SceneChecker {
    let model = Arc::new(RobotModel::new(builtin_chain("franka_panda").unwrap()).unwrap());
    let acm = acm(&model);
    let world = Arc::new(SceneGeometry::build(&Scene::empty()).unwrap());
    SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap()
}

#[test]
fn adjacent_links_are_allowed_and_others_are_checked() {
    let model = RobotModel::new(builtin_chain("franka_panda").unwrap()).unwrap();
    let names: Vec<&str> = model.body_names().collect();
    assert_eq!(
        names,
        [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
            "link_6",
            "link_7"
        ]
    );
    let acm = AllowedCollisions::adjacent(&model);
    for a in 0..8usize {
        for b in 0..8 {
            let adjacent = a.abs_diff(b) == 1;
            if a != b {
                assert_eq!(acm.is_allowed(a, b), adjacent, "{a}–{b}");
            }
        }
    }
    assert_eq!(acm.reason(2, 3), Some(AllowReason::Adjacent));
    assert_eq!(acm.checked_pairs().count(), 28 - 7);
}

#[test]
fn sampled_acm_keeps_adjacency_is_deterministic_and_keeps_reachable_pairs_checked() {
    let model = RobotModel::new(builtin_chain("franka_panda").unwrap()).unwrap();
    let params = AcmParams {
        samples: 2000,
        ..AcmParams::default()
    };
    let a = AllowedCollisions::sampled(&model, &params).unwrap();
    let b = AllowedCollisions::sampled(&model, &params).unwrap();
    assert_eq!(a, b);
    for k in 0..7 {
        assert_eq!(a.reason(k, k + 1), Some(AllowReason::Adjacent));
    }
    // The base sphere and link_1 sphere are adjacent; the base (r 0.12 at
    // the origin) and link_7 can meet when the arm folds down, so that pair
    // must stay checked; link_1 and link_3 are 0.316 m apart along the
    // upper arm and can never meet (radii 0.09 + 0.08), which joint 2's
    // table proves: allowed as proved, not merely never seen colliding.
    assert_eq!(a.reason(1, 3), Some(AllowReason::Proved));
    assert!(a.reason(0, 7).is_none(), "{:?}", a.reason(0, 7));
    assert!(AllowedCollisions::sampled(&model, &AcmParams { samples: 0, ..params }).is_err());
}

#[test]
fn sampling_the_acm_stops_when_its_deadline_says_so() {
    use std::sync::atomic::AtomicBool;
    let model = RobotModel::new(builtin_chain("franka_panda").unwrap()).unwrap();
    let params = AcmParams::default();
    let past = crate::Deadline::at(std::time::Instant::now());
    let stopped = |what: &str| {
        Err(CollisionError::Stopped {
            what: what.into(),
            stop: crate::Stop::Deadline,
        })
    };
    // first while the pair tables are built, which keeps none of them
    let tables = "proving the robot's self pairs apart (pair tables)";
    assert_eq!(
        AllowedCollisions::sampled_until(&model, &params, past),
        stopped(tables)
    );
    assert_eq!(
        AllowedCollisions::sampled_until(&model, &params, past),
        stopped(tables)
    );
    // with the tables built, in the sampling
    assert!(!model.pair_tables().is_empty());
    assert_eq!(
        AllowedCollisions::sampled_until(&model, &params, past),
        stopped("sampling the allowed-collision matrix")
    );
    let cancelled = AtomicBool::new(true);
    let err =
        AllowedCollisions::sampled_until(&model, &params, crate::Deadline::none().with_cancel(&cancelled))
            .unwrap_err();
    assert!(err.to_string().contains("the call was cancelled"), "{err}");
    // no limit: the same matrix as without one
    assert_eq!(
        AllowedCollisions::sampled_until(&model, &params, crate::Deadline::none()),
        AllowedCollisions::sampled(&model, &params)
    );
}

#[test]
fn malformed_meshes_are_rejected_naming_the_field() {
    let (v, i) = box_mesh(Vector3::new(0.1, 0.1, 0.1));
    let scene = |vertices: Vec<Point3<f64>>, indices: Vec<u32>| {
        Scene::new(
            vec![
                Obstacle::new("b", Isometry3::identity(), Geometry::Sphere { radius: 0.1 }),
                Obstacle::new("m", Isometry3::identity(), Geometry::Mesh { vertices, indices }),
            ],
            &SceneLimits::default(),
        )
    };
    assert!(scene(v.clone(), i.clone()).is_ok());
    let mut bad = i.clone();
    bad[5] = 8;
    assert_eq!(
        scene(v.clone(), bad).unwrap_err(),
        CollisionError::IndexOutOfRange {
            field: "obstacles[1].indices[5]".into(),
            index: 8,
            vertex_count: 8
        }
    );
    let mut nan = v.clone();
    nan[3].y = f64::NAN;
    assert_eq!(
        scene(nan, i.clone()).unwrap_err(),
        CollisionError::NonFinite {
            field: "obstacles[1].vertices[3]".into()
        }
    );
    let mut flat = i.clone();
    flat[4] = flat[3];
    let err = scene(v.clone(), flat).unwrap_err();
    assert!(
        matches!(&err, CollisionError::Degenerate { field, .. } if field == "obstacles[1].indices[3..6]"),
        "{err}"
    );
    // Collinear vertices: zero area.
    let line = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(2.0, 0.0, 0.0),
    ];
    assert!(matches!(
        scene(line, vec![0, 1, 2]).unwrap_err(),
        CollisionError::Degenerate { .. }
    ));
    assert!(matches!(
        scene(v.clone(), i[..5].to_vec()).unwrap_err(),
        CollisionError::Degenerate { .. }
    ));
    assert!(matches!(
        scene(vec![], vec![]).unwrap_err(),
        CollisionError::Empty { .. }
    ));
    let small = SceneLimits {
        max_mesh_triangles: 11,
        ..SceneLimits::default()
    };
    let err = Scene::new(
        vec![Obstacle::new(
            "m",
            Isometry3::identity(),
            Geometry::Mesh {
                vertices: v,
                indices: i,
            },
        )],
        &small,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            CollisionError::TooMany {
                count: 12,
                limit: 11,
                ..
            }
        ),
        "{err}"
    );
    // Primitives: negative and non-finite sizes, NaN poses.
    let bad_box = Scene::new(
        vec![Obstacle::new(
            "b",
            Isometry3::identity(),
            Geometry::Box {
                half_extents: Vector3::new(0.1, -0.2, 0.1),
            },
        )],
        &SceneLimits::default(),
    );
    assert_eq!(
        bad_box.unwrap_err(),
        CollisionError::NotPositive {
            field: "obstacles[0].box.half_extents.y".into(),
            value: -0.2
        }
    );
    let nan_pose = Scene::new(
        vec![Obstacle::new(
            "s",
            Isometry3::from_parts(Translation3::new(f64::NAN, 0.0, 0.0), Default::default()),
            Geometry::Sphere { radius: 0.1 },
        )],
        &SceneLimits::default(),
    );
    assert_eq!(
        nan_pose.unwrap_err(),
        CollisionError::NonFinite {
            field: "obstacles[0].pose".into()
        }
    );
}

#[test]
fn a_robot_mesh_without_inline_geometry_is_an_error() {
    let urdf = probe_urdf(r#"<mesh filename="package://x/link.stl"/>"#);
    let chain = Arc::new(crate::robot::parse_chain(&urdf, &Default::default(), Default::default()).unwrap());
    assert_eq!(
        RobotModel::new(chain).unwrap_err(),
        CollisionError::MeshNotInline {
            field: "links[probe].collision[0]".into(),
            filename: "package://x/link.stl".into()
        }
    );
}

#[test]
fn the_motion_check_finds_a_thin_wall_in_the_middle() {
    // A 1 cm slab at x = 1 between the probe's start (x = 0) and goal
    // (x = 2); the probe sphere has radius 2 cm. Each end state is free.
    let wall = Obstacle::new(
        "wall",
        Isometry3::translation(1.0, 0.0, 0.0),
        Geometry::Box {
            half_extents: Vector3::new(0.005, 1.0, 1.0),
        },
    );
    let c = checker(&probe_urdf(r#"<sphere radius="0.02"/>"#), &[], vec![wall]);
    assert!(c.is_valid(&[0.0, 0.0, 0.0]) && c.is_valid(&[2.0, 0.0, 0.0]));
    assert!(!c.motion_valid(&[0.0, 0.0, 0.0], &[2.0, 0.0, 0.0]));
    // Beside the wall (y = 1.5) the same motion is free.
    assert!(c.motion_valid(&[0.0, 1.5, 0.0], &[2.0, 1.5, 0.0]));
    assert_eq!(c.motion_check(), MotionCheck::Interpolated { resolution: 0.05 });
}

#[test]
fn checkers_are_shared_between_threads_and_agree() {
    use rayon::prelude::*;
    let c = panda_checker(AllowedCollisions::adjacent);
    let qs: Vec<[f64; 7]> = (0..64)
        .map(|k| {
            let t = k as f64 / 64.0;
            [2.0 * t - 1.0, 1.5 * t - 0.7, 0.3, -3.0 + 2.5 * t, 0.1, 1.5, 0.0]
        })
        .collect();
    let serial: Vec<bool> = qs.iter().map(|q| c.is_valid(q)).collect();
    let parallel: Vec<bool> = qs.par_iter().map(|q| c.is_valid(q)).collect();
    assert_eq!(serial, parallel);
}

/// The convex polytope the built-in URDF gives link `name` (an embedded OBJ
/// of outward triangles, read with this test's own parser), posed at `q` by
/// the chain's link frames (checked against DH products in the robot
/// tests): its vertices and its face planes `(n, o)`, inside where
/// `n·x ≤ o`, base frame.
fn posed_polytope(builtin: &str, q: &[f64], name: &str) -> Polytope {
    let robot = urdf_rs::read_from_string(crate::robot::builtin_urdf(builtin).unwrap()).unwrap();
    let chain = builtin_chain(builtin).unwrap();
    let mut frames = Vec::new();
    chain.link_frames_into(q, &mut frames);
    let c = &robot.links.iter().find(|l| l.name == name).unwrap().collision[0];
    let urdf_rs::Geometry::Mesh { filename, .. } = &c.geometry else {
        panic!("{name}: not a mesh")
    };
    let path = filename.strip_prefix("kinplan://builtin/").unwrap();
    let file = format!("{}/src/robot/builtin/meshes/{path}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(file).unwrap();
    let (xyz, rpy) = (c.origin.xyz, c.origin.rpy);
    let pose = frames[chain.links().iter().position(|l| l.name == name).unwrap()]
        * Isometry3::new(Vector3::new(xyz[0], xyz[1], xyz[2]), Vector3::zeros())
        * nalgebra::UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    let mut vertices = Vec::new();
    let mut planes = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let x: Vec<f64> = it.map(|t| t.parse().unwrap()).collect();
                vertices.push(pose * Point3::new(x[0], x[1], x[2]));
            }
            Some("f") => {
                let t: Vec<usize> = it.map(|t| t.parse::<usize>().unwrap() - 1).collect();
                let (a, b, c) = (vertices[t[0]], vertices[t[1]], vertices[t[2]]);
                let n = (b - a).cross(&(c - a)).normalize();
                planes.push((n, n.dot(&a.coords)));
            }
            _ => {}
        }
    }
    (vertices, planes)
}

/// A convex polytope's vertices and face planes (`posed_polytope`).
type Polytope = (Vec<Point3<f64>>, Vec<(Vector3<f64>, f64)>);

/// Bounds on the distance between two convex polytopes, apart from the
/// checker: below, the widest gap along a face normal of either (the
/// projection on a unit vector shortens every distance); above, the
/// nearest pair of vertices. And how deep the deepest vertex of one lies
/// inside the other (> 0: they overlap).
fn polytope_gap((va, pa): &Polytope, (vb, pb): &Polytope) -> (f64, f64, f64) {
    let gap_along = |planes: &[(Vector3<f64>, f64)], other: &[Point3<f64>]| {
        planes
            .iter()
            .map(|(n, o)| {
                other
                    .iter()
                    .map(|v| n.dot(&v.coords) - o)
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let lower = gap_along(pa, vb).max(gap_along(pb, va));
    let upper = va
        .iter()
        .flat_map(|x| vb.iter().map(move |y| (x - y).norm()))
        .fold(f64::INFINITY, f64::min);
    let depth = |planes: &[(Vector3<f64>, f64)], other: &[Point3<f64>]| {
        other
            .iter()
            .map(|v| {
                planes
                    .iter()
                    .map(|(n, o)| o - n.dot(&v.coords))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    (lower, upper, depth(pa, vb).max(depth(pb, va)))
}

#[test]
fn panda_folded_wrist_self_collides_and_a_less_folded_one_is_free() {
    // q6 = 0.5 and the elbow folded swing link_7 (the flange housing) into
    // link_1; less folded, they are apart (the polytopes hold the real
    // meshes; the capsules that stood for them overlapped there too).
    let q_folded = [0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0];
    let q_open = [0.0, 0.0, 0.0, -2.9, 0.0, 0.5, 0.0];
    let at = |q: &[f64]| {
        polytope_gap(
            &posed_polytope("franka_panda", q, "link_1"),
            &posed_polytope("franka_panda", q, "link_7"),
        )
    };
    let (_, _, depth) = at(&q_folded);
    assert!(depth > 0.02, "{depth}");
    let (lower, upper, _) = at(&q_open);
    assert!(lower > 0.005, "{lower}");
    // The ACM from sampling allows the pairs that overlap everywhere
    // (neighbours at their joints) and keeps link_1–link_7 checked.
    let c = panda_checker(|m| {
        AllowedCollisions::sampled(
            m,
            &AcmParams {
                samples: 2000,
                ..AcmParams::default()
            },
        )
        .unwrap()
    });
    let report = c.report(&q_folded).unwrap();
    assert_eq!(
        report.collisions,
        vec![("link_1".to_string(), Part::Link("link_7".into()))],
        "{report}"
    );
    let p = c.proximity(&q_folded, 1.0).unwrap().unwrap();
    assert!(p.distance < 0.0, "{}", p.distance);
    assert!(!c.is_valid(&q_folded));
    assert!(c.is_valid(&q_open), "{}", c.report(&q_open).unwrap());
    // the nearest checked pair is at most this one's gap away, and when it
    // is this pair, within the bounds
    assert!(c.clearance(&q_open, 1.0) <= upper + 1e-9);
    let p = c.proximity(&q_open, 1.0).unwrap().unwrap();
    if p.link == "link_1" || p.link == "link_7" {
        assert!(p.distance >= lower - 1e-6 && p.distance <= upper + 1e-6, "{p:?}");
    }
}

fn panda_hand_checker(opening: f64, obstacles: Vec<Obstacle>) -> SceneChecker {
    let chain = builtin_chain("franka_panda_hand").unwrap();
    let urdf = crate::robot::builtin_urdf("franka_panda_hand").unwrap();
    let fingers = [("panda_finger_joint1", opening), ("panda_finger_joint2", opening)];
    let attached = attached_bodies(urdf, &chain, &fingers).unwrap();
    let model = Arc::new(RobotModel::with_parts(chain, &attached, &[]).unwrap());
    // Scene contacts only: every robot pair allowed.
    let mut acm = AllowedCollisions::adjacent(&model);
    for a in 0..model.body_count() {
        for b in 0..model.body_count() {
            acm.allow(a, b, AllowReason::User);
        }
    }
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
    SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap()
}

#[test]
fn the_panda_hand_carries_two_fingers_at_the_requested_opening() {
    let c = panda_hand_checker(0.04, vec![]);
    let names: Vec<&str> = c.model().body_names().collect();
    assert_eq!(
        &names[7..],
        ["link_7", "panda_hand", "panda_leftfinger", "panda_rightfinger"]
    );
    // link_7 and the hand are adjacent through the flange (no geometry);
    // each finger is adjacent to the hand, the fingers are not adjacent.
    assert!(c.model().adjacent(7, 8) && c.model().adjacent(8, 9) && c.model().adjacent(8, 10));
    assert!(!c.model().adjacent(9, 10) && !c.model().adjacent(7, 9));

    // A 5 mm sphere between the fingertips, 90 mm out along the hand's z.
    let chain = builtin_chain("franka_panda_hand").unwrap();
    let q = [0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.785];
    let mut frames = Vec::new();
    chain.link_frames_into(&q, &mut frames);
    let hand = chain.links().iter().position(|l| l.name == "panda_hand").unwrap();
    let at = frames[hand] * Point3::new(0.0, 0.0, 0.09);
    let ball = || {
        vec![Obstacle::new(
            "ball",
            Isometry3::translation(at.x, at.y, at.z),
            Geometry::Sphere { radius: 0.005 },
        )]
    };
    // Open 40 mm per finger: the nearest part is the housing's top face
    // (the polytope's highest vertices, which the ball sits above), 90 mm
    // less its height less 5 mm away; the finger boxes' inner faces are
    // 40 − 0.6 mm − 5 mm away.
    let (housing, _) = posed_polytope("franka_panda_hand", &q, "panda_hand");
    let top = housing
        .iter()
        .map(|v| (frames[hand].inverse() * v).z)
        .fold(f64::NEG_INFINITY, f64::max);
    let expected = 0.09 - top - 0.005;
    assert!(expected > 0.015 && expected < 0.02, "{expected}");
    let open = panda_hand_checker(0.04, ball());
    assert!(open.is_valid(&q));
    let p = open.proximity(&q, 1.0).unwrap().unwrap();
    assert_eq!(p.link, "panda_hand");
    assert!(
        (p.distance - expected).abs() < 1e-6,
        "{} vs {expected}",
        p.distance
    );
    // Closed: both fingers enclose the ball.
    let closed = panda_hand_checker(0.0, ball());
    let report = closed.report(&q).unwrap();
    let links: Vec<&str> = report.collisions.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(links, ["panda_leftfinger", "panda_rightfinger"], "{report}");
    // An opening past the 40 mm limit is used as given: the fingers move
    // farther out and the housing stays the nearest part.
    let wide = panda_hand_checker(0.065, ball());
    assert!((wide.proximity(&q, 1.0).unwrap().unwrap().distance - expected).abs() < 1e-6);
}

#[test]
fn body_poses_equal_the_chains_link_frames_for_every_builtin_robot() {
    // The collision model's forward kinematics (origins without rotation
    // and z-axis joints written out) against the chain's general product of
    // joint origins and motions, link frame · body offset: arms with x, y,
    // −x and z axes, rotated and plain origins.
    use crate::robot::BUILTIN_NAMES;
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let (mut frames, mut robots) = (Vec::new(), 0);
    for name in BUILTIN_NAMES {
        let chain = builtin_chain(name).unwrap();
        let Ok(model) = RobotModel::new(chain.clone()) else {
            continue;
        };
        robots += 1;
        for _ in 0..20 {
            let q: Vec<f64> = chain
                .joints()
                .iter()
                .map(|j| rng.random_range(j.lower.max(-4.0)..j.upper.min(4.0)))
                .collect();
            let mut poses = [Isometry3::identity(); MAX_BODIES];
            model.body_poses(&q, &mut poses);
            chain.link_frames_into(&q, &mut frames);
            for (b, body) in model.bodies.iter().enumerate() {
                let expected = frames[body.link] * body.offset;
                let (got, want) = (poses[b].to_homogeneous(), expected.to_homogeneous());
                assert!(
                    (got - want).abs().max() < 1e-12,
                    "{name}, body {}: {got} vs {want}",
                    body.name
                );
            }
        }
    }
    assert!(robots >= 8, "only {robots} builtin robots have a collision model");
}

/// Regression: a state that penetrates two obstacles panicked in parry
/// ("loosening margin must be non-negative") when the deeper search passed the
/// first penetration depth on to a mesh as its prediction distance. The
/// clearance is the deeper of the two penetrations, whichever comes first.
#[test]
fn a_state_penetrating_a_mesh_and_a_sphere_has_a_clearance_in_either_order() {
    let at = Isometry3::translation(-0.4223, -0.1914, 0.4184);
    let tetra = || {
        Obstacle::new(
            "tetra",
            at,
            Geometry::Mesh {
                vertices: vec![
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(0.1, 0.0, 0.0),
                    Point3::new(0.0, 0.1, 0.0),
                    Point3::new(0.0, 0.0, 0.1),
                ],
                indices: vec![0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3],
            },
        )
    };
    let sphere = || Obstacle::new("ball", at, Geometry::Sphere { radius: 0.05 });
    let q = [0.0, -1.5, 1.5, 0.0, 0.0, 0.0];
    let mut depths = Vec::new();
    for obstacles in [vec![tetra(), sphere()], vec![sphere(), tetra()]] {
        let model = Arc::new(RobotModel::new(builtin_chain("ur5").unwrap()).unwrap());
        let acm = AllowedCollisions::adjacent(&model);
        let scene = Scene::new(obstacles, &SceneLimits::default()).unwrap();
        let world = Arc::new(SceneGeometry::build(&scene).unwrap());
        let c = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
        assert!(c.in_collision(&q));
        let d = c.clearance(&q, 0.5);
        assert!(d < 0.0, "a penetrating state has a negative clearance, got {d}");
        let p = c.proximity(&q, 0.5).unwrap().unwrap();
        assert!(p.distance <= d + 1e-12);
        depths.push(d);
    }
    assert!(
        (depths[0] - depths[1]).abs() < 1e-9,
        "order changed the depth: {depths:?}"
    );
}

/// A two-joint arm `base → upper → lower` (tip `lower`) whose URDF also holds
/// a pedestal above the base (a fixed joint whose child is the base), a
/// gripper fixed beyond the tip, and a finger on a prismatic joint of the
/// gripper. Boxes: pedestal 0.4 m cube centred 0.3 m below the base origin;
/// upper arm 0.5 m up z; lower arm 0.5 m up z again; gripper a 0.1 m cube
/// centred 0.15 m beyond the lower arm's end; finger 0.02 m cube 0.1 m
/// further, opened along x by its joint.
fn arm_with_pedestal_and_gripper() -> String {
    let boxed = |name: &str, size: &str, xyz: &str| {
        format!(
            r#"<link name="{name}"><collision><origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry></collision></link>"#
        )
    };
    format!(
        r#"<robot name="arm">
        <link name="world"/>
        {pedestal}
        <link name="base"/>
        {upper}{lower}{gripper}{finger}
        <joint name="world_pedestal" type="fixed"><parent link="world"/><child link="pedestal"/></joint>
        <joint name="pedestal_base" type="fixed"><parent link="pedestal"/><child link="base"/><origin xyz="0 0 0.5"/></joint>
        <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
          <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
          <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
        <joint name="flange" type="fixed"><parent link="lower"/><child link="gripper"/><origin xyz="0 0 0.5"/></joint>
        <joint name="finger_joint" type="prismatic"><parent link="gripper"/><child link="finger"/><origin xyz="0 0 0.25"/>
          <axis xyz="1 0 0"/><limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
        </robot>"#,
        pedestal = boxed("pedestal", "0.4 0.4 0.4", "0 0 0.2"),
        upper = boxed("upper", "0.05 0.05 0.5", "0 0 0.25"),
        lower = boxed("lower", "0.05 0.05 0.5", "0 0 0.25"),
        gripper = boxed("gripper", "0.1 0.1 0.1", "0 0 0.15"),
        finger = boxed("finger", "0.02 0.02 0.02", "0 0 0"),
    )
}

fn whole_arm_checker(whole: bool, locked: &[(&str, f64)], obstacle: Obstacle) -> SceneChecker {
    let urdf = arm_with_pedestal_and_gripper();
    let spec = ChainSpec {
        base_link: Some("base".into()),
        tip_link: Some("lower".into()),
    };
    let chain = Arc::new(parse_chain(&urdf, &spec, UrdfLimits::default()).unwrap());
    let model = if whole {
        RobotModel::of_urdf(chain, &urdf, locked, &[]).unwrap()
    } else {
        RobotModel::new(chain).unwrap()
    };
    let model = Arc::new(model);
    let acm = AllowedCollisions::adjacent(&model);
    let world = Arc::new(
        SceneGeometry::build(&Scene::new(vec![obstacle], &SceneLimits::default()).unwrap()).unwrap(),
    );
    SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap()
}

/// Regression: bodies beyond the tip link (a gripper) and above the base (a
/// pedestal) were left out of the collision model, so states whose gripper
/// met an obstacle were reported free. Every point placed here is worked out
/// by hand from the URDF above (chain straight up at q = 0: the arm ends at
/// z = 1.0 in the base frame, the gripper cube spans z 1.1–1.2, the finger sits at
/// z = 1.25, the pedestal spans z −0.5 to −0.1).
#[test]
fn the_whole_robot_collides_the_gripper_beyond_the_tip_and_the_pedestal() {
    let ball = |x: f64, y: f64, z: f64, r: f64| {
        Obstacle::new(
            "ball",
            Isometry3::translation(x, y, z),
            Geometry::Sphere { radius: r },
        )
    };
    let q = [0.0, 0.0];
    // on the gripper only (its face at x = 0.05; the arm's at x = 0.025)
    let at_gripper = || ball(0.06, 0.0, 1.15, 0.02);
    assert!(!whole_arm_checker(true, &[], at_gripper()).is_valid(&q));
    assert!(
        whole_arm_checker(false, &[], at_gripper()).is_valid(&q),
        "chain-only model misses it"
    );
    let names: Vec<String> = whole_arm_checker(true, &[], at_gripper())
        .report(&q)
        .unwrap()
        .collisions
        .iter()
        .map(|(l, _)| l.clone())
        .collect();
    assert_eq!(names, ["gripper"]);
    // on the pedestal, below the base
    let at_pedestal = || ball(0.25, 0.0, -0.3, 0.06);
    assert!(!whole_arm_checker(true, &[], at_pedestal()).is_valid(&q));
    assert!(whole_arm_checker(false, &[], at_pedestal()).is_valid(&q));
    // the finger follows its locked joint: at 0.04 m it meets a ball at x = 0.05
    let at_finger = || ball(0.05, 0.0, 1.25, 0.005);
    assert!(
        whole_arm_checker(true, &[], at_finger()).is_valid(&q),
        "finger at 0: 50 − 10 − 5 mm clear"
    );
    assert!(!whole_arm_checker(true, &[("finger_joint", 0.04)], at_finger()).is_valid(&q));
    // the gripper moves with the chain: turned 90° about y at j2, its cube spans x 0.6–0.7
    let turned = [0.0, std::f64::consts::FRAC_PI_2];
    let moved = || ball(0.65, 0.0, 0.5 + 0.06, 0.02);
    assert!(!whole_arm_checker(true, &[], moved()).is_valid(&turned));
    assert!(whole_arm_checker(true, &[], at_gripper()).is_valid(&turned));
}

/// Regression: a robot mesh file with zero-area slivers (xArm 7's, as shipped)
/// was refused, though a robot mesh collides as its convex hull, which
/// slivers do not change; a scene mesh still refuses them.
#[test]
fn a_robot_mesh_with_zero_area_slivers_is_accepted() {
    let (mut vertices, mut indices) = box_mesh(Vector3::new(0.05, 0.04, 0.03));
    vertices.push(Point3::new(0.0, 0.0, 0.0));
    let n = vertices.len() as u32;
    indices.extend_from_slice(&[0, 1, n - 1]); // a proper triangle to the centre
    indices.extend_from_slice(&[0, 0, 1]); // a repeated corner: zero area
    let mesh = InlineMesh {
        filename: "package://probe/slivers.stl".into(),
        vertices: vertices.clone(),
        indices: indices.clone(),
    };
    let urdf = probe_urdf(r#"<mesh filename="package://probe/slivers.stl"/>"#);
    let c = checker(&urdf, &[mesh], vec![]);
    assert_eq!(c.model().body_count(), 1);
    let scene = Scene::new(
        vec![Obstacle::new(
            "slivers",
            Isometry3::identity(),
            Geometry::Mesh { vertices, indices },
        )],
        &SceneLimits::default(),
    );
    assert!(matches!(scene, Err(CollisionError::Degenerate { .. })));
}

/// A two-link arm on a base that carries `teeth` fixed 2 cm cubes in a row
/// along x (tooth i centred at x = 1 + 0.1 i, z = 0): 2 + `teeth` bodies.
fn arm_with_teeth(teeth: usize) -> String {
    let mut links = String::new();
    let mut joints = String::new();
    for i in 0..teeth {
        links += &format!(
            r#"<link name="tooth{i}"><collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision></link>"#
        );
        joints += &format!(
            r#"<joint name="t{i}" type="fixed"><parent link="base"/><child link="tooth{i}"/><origin xyz="{} 0 0"/></joint>"#,
            1.0 + 0.1 * i as f64
        );
    }
    format!(
        r#"<robot name="rake"><link name="base"/>
        <link name="upper"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision></link>
        <link name="lower"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision></link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
          <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
          <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
        {links}{joints}</robot>"#
    )
}

/// A robot of up to [`MAX_BODIES`] bodies is modelled (Baxter and Talos have
/// 37 and 52), its last body collides in state and motion checks, and one
/// body more is refused with the count and the limit.
#[test]
fn a_robot_of_max_bodies_collides_with_its_last_body_and_one_more_is_refused() {
    let spec = ChainSpec {
        base_link: Some("base".into()),
        tip_link: Some("lower".into()),
    };
    let model = |teeth: usize| {
        let urdf = arm_with_teeth(teeth);
        let chain = Arc::new(parse_chain(&urdf, &spec, UrdfLimits::default()).unwrap());
        RobotModel::of_urdf(chain, &urdf, &[], &[])
    };
    let teeth = MAX_BODIES - 2;
    let full = Arc::new(model(teeth).unwrap());
    assert_eq!(full.body_names().count(), MAX_BODIES);
    let last = 1.0 + 0.1 * (teeth - 1) as f64;
    let checker_with_ball_at = |x: f64| {
        let ball = Obstacle::new(
            "ball",
            Isometry3::translation(x, 0.0, 0.0),
            Geometry::Sphere { radius: 0.02 },
        );
        let world = Arc::new(
            SceneGeometry::build(&Scene::new(vec![ball], &SceneLimits::default()).unwrap()).unwrap(),
        );
        SceneChecker::new(
            full.clone(),
            &AllowedCollisions::adjacent(&full),
            world,
            CheckerParams::default(),
        )
        .unwrap()
    };
    let (a, b) = ([0.0, 0.0], [1.0, 0.5]);
    // On the last tooth (its faces at x = last ± 0.01): every state collides.
    let on_last = checker_with_ball_at(last + 0.02);
    assert!(!on_last.is_valid(&a));
    assert!(!on_last.motion_valid(&a, &b));
    let report = on_last.report(&a).unwrap();
    assert!(
        report
            .collisions
            .iter()
            .any(|(l, _)| l == &format!("tooth{}", teeth - 1)),
        "{report:?}"
    );
    // 5 cm past it, beyond every body: free.
    let past = checker_with_ball_at(last + 0.06);
    assert!(past.is_valid(&a) && past.motion_valid(&a, &b));
    let err = model(teeth + 1).unwrap_err();
    assert!(
        matches!(err, CollisionError::TooManyBodies { count, limit, .. } if count == MAX_BODIES + 1 && limit == MAX_BODIES),
        "{err}"
    );
}

/// The default-state rule of MoveIt's setup assistant is not applied: the
/// built-in Panda's wrist (link_5) touches link_7, the hand and the right
/// finger at the default state in its shapes, which are larger than the real
/// links; only the pair MoveIt's Panda configuration (`panda_moveit_config`,
/// the SRDF MotionBenchMaker plans with) names as a designed contact, finger
/// against finger, is allowed, so the wrist stays checked against link_7,
/// the hand and the fingers, as MoveIt checks the real meshes.
#[test]
fn builtin_panda_allows_only_its_designed_contacts() {
    let model = panda_hand_open();
    let params = AcmParams {
        samples: 2000,
        ..AcmParams::default()
    };
    let index = |name: &str| model.body_names().position(|n| n == name).unwrap();
    let (wrist, link_7, hand) = (index("link_5"), index("link_7"), index("panda_hand"));
    let (left, right) = (index("panda_leftfinger"), index("panda_rightfinger"));
    // the wrist overlaps link_7 and the right finger at the default state (every joint at 0
    // clamped into its limits), and neither pair is adjacent nor always in contact
    let mut poses = [Isometry3::identity(); super::super::model::MAX_BODIES];
    let q0: Vec<f64> = model
        .chain()
        .limits()
        .map(|(lo, hi)| 0.0_f64.clamp(lo, hi))
        .collect();
    model.body_poses(&q0, &mut poses);
    let touch = |a: usize, b: usize| {
        super::super::narrow::body_body_intersect(&model.bodies[a], &poses[a], &model.bodies[b], &poses[b])
    };
    assert!(touch(wrist, link_7) && touch(wrist, right));
    let sampled = AllowedCollisions::sampled(&model, &params).unwrap();
    assert_eq!(sampled.reason(wrist, link_7), None);
    assert_eq!(sampled.reason(wrist, right), None);
    let builtin = AllowedCollisions::builtin(&model, "franka_panda_hand", &params).unwrap();
    // MoveIt's Panda configuration checks the wrist against link_7 and the
    // hand (the real meshes meet there when the hand folds back)
    assert_eq!(builtin.reason(wrist, link_7), None);
    assert_eq!(builtin.reason(wrist, hand), None);
    assert_eq!(builtin.reason(left, right), Some(AllowReason::User));
    assert_eq!(builtin.reason(wrist, right), None);
    assert_eq!(builtin.reason(wrist, left), None);
}

/// The sampled matrix of `model` against a plain count: the same random
/// states (the same seed and draw order), every non-adjacent pair tested
/// exactly in every state, no table and no early decision. A pair the
/// sampling calls "never" or "always" has that count, a pair it calls
/// "proved" is never in collision, and every other pair is checked.
/// Returns the pairs in collision now and then, and those first in
/// collision after the first block of samples.
fn sampled_against_every_sample(model: &RobotModel, params: &AcmParams) -> (usize, usize) {
    use rand::{Rng, SeedableRng};
    let acm = AllowedCollisions::sampled(model, params).unwrap();
    let bounds: Vec<(f64, f64)> = model.chain().limits().collect();
    assert!(bounds.iter().all(|(lo, hi)| lo.is_finite() && hi.is_finite()));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(params.seed);
    let states: Vec<f64> = (0..params.samples * bounds.len())
        .map(|i| {
            let (lo, hi) = bounds[i % bounds.len()];
            rng.random_range(lo..=hi)
        })
        .collect();
    let n = model.body_count();
    let mut counts = vec![0usize; n * n];
    let mut late = 0;
    let mut poses = [Isometry3::identity(); super::super::model::MAX_BODIES];
    for (i, q) in states.chunks(bounds.len()).enumerate() {
        model.body_poses(q, &mut poses);
        for a in 0..n {
            for b in a + 1..n {
                let hit = super::super::narrow::body_body_intersect(
                    &model.bodies[a],
                    &poses[a],
                    &model.bodies[b],
                    &poses[b],
                );
                late += (hit && counts[a * n + b] == 0 && i >= 1000) as usize;
                counts[a * n + b] += hit as usize;
            }
        }
    }
    let always = (params.always_fraction * params.samples as f64).ceil() as usize;
    let mut sometimes = 0;
    for a in 0..n {
        for b in a + 1..n {
            let count = counts[a * n + b];
            match acm.reason(a, b) {
                Some(AllowReason::Adjacent) => assert!(model.adjacent(a, b)),
                Some(AllowReason::Proved) | Some(AllowReason::Never) => assert_eq!(count, 0, "{a}-{b}"),
                Some(AllowReason::Always) => assert!(count >= always, "{a}-{b}: {count}"),
                None => {
                    assert!(count > 0 && count < always, "{a}-{b}: {count}");
                    sometimes += 1;
                }
                Some(AllowReason::User) => panic!("{a}-{b}: no user pairs here"),
            }
        }
    }
    (sometimes, late)
}

/// The Panda with its hand (pairs in collision now and then, decided after
/// the first block of samples); a probe beside a fixed post, rarely in
/// collision, some pairs first after the first block; two boxes rigid and
/// touching (always, from one test).
#[test]
fn the_sampled_matrix_is_the_one_every_sample_gives() {
    let model = panda_hand_open();
    for (samples, always_fraction) in [(3000, 0.95), (2500, 0.02)] {
        let params = AcmParams {
            samples,
            always_fraction,
            seed: 11,
        };
        let (sometimes, _) = sampled_against_every_sample(&model, &params);
        assert!(sometimes >= 3, "{sometimes} pairs in collision now and then");
    }
    let with_links = |links: &str| {
        let urdf = probe_urdf(r#"<sphere radius="0.05"/>"#).replace("</robot>", &format!("{links}</robot>"));
        let spec = ChainSpec {
            base_link: Some("base".into()),
            tip_link: Some("probe".into()),
        };
        let chain = Arc::new(parse_chain(&urdf, &spec, UrdfLimits::default()).unwrap());
        RobotModel::of_urdf(chain, &urdf, &[], &[]).unwrap()
    };
    let post = with_links(
        r#"<link name="post"><collision><geometry><box size="1.6 1.6 1.6"/></geometry></collision></link>
           <joint name="fp" type="fixed"><parent link="base"/><child link="post"/></joint>"#,
    );
    let late: usize = (0..8)
        .map(|seed| {
            let params = AcmParams {
                samples: 3000,
                always_fraction: 0.95,
                seed,
            };
            sampled_against_every_sample(&post, &params).1
        })
        .sum();
    assert!(late >= 1, "no pair first in collision after the first block");
    // two boxes that overlap, fixed to the probe: rigid and touching
    let geometry = r#"<box size="0.1 0.1 0.1"/>"#;
    let boxes = with_links(&format!(
        r#"<link name="a"><collision><geometry>{geometry}</geometry></collision></link>
           <link name="b"><collision><geometry>{geometry}</geometry></collision></link>
           <joint name="fa" type="fixed"><parent link="probe"/><child link="a"/></joint>
           <joint name="fb" type="fixed"><parent link="probe"/><child link="b"/><origin xyz="0.05 0 0"/></joint>"#
    ));
    let index = |name: &str| boxes.body_names().position(|n| n == name).unwrap();
    let (a, b) = (index("a"), index("b"));
    assert!(!boxes.adjacent(a, b));
    let params = AcmParams {
        samples: 200,
        ..AcmParams::default()
    };
    let acm = AllowedCollisions::sampled(&boxes, &params).unwrap();
    assert_eq!(acm.reason(a, b), Some(AllowReason::Always));
}

/// parry's convex hull of a thin cloud can leave some of its points outside
/// (a sliver, thin against its length); the model grows such a hull
/// until it holds them. Checked by support functions: along every sampled
/// direction, the body's shapes reach at least as far as the farthest point.
#[test]
fn a_thin_mesh_is_held_whole_by_its_body() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for case in 0..300 {
        let n = rng.random_range(4..400);
        let scale = Vector3::new(
            10f64.powf(rng.random_range(-4.0..0.5)),
            10f64.powf(rng.random_range(-4.0..0.5)),
            10f64.powf(rng.random_range(-6.0..0.5)),
        );
        let turn = nalgebra::UnitQuaternion::from_euler_angles(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
        );
        let vertices: Vec<Point3<f64>> = (0..n)
            .map(|_| {
                let v = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                Point3::from(turn * v.component_mul(&scale))
            })
            .collect();
        let indices: Vec<u32> = (0..n as u32 - 2).flat_map(|i| [0, i + 1, i + 2]).collect();
        let mesh = InlineMesh {
            filename: "package://probe/sliver.obj".into(),
            vertices: vertices.clone(),
            indices,
        };
        let urdf = probe_urdf(r#"<mesh filename="package://probe/sliver.obj"/>"#);
        let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
        let Ok(model) = RobotModel::with_parts(chain, &[], &[mesh]) else {
            continue; // no 3-D hull: refused by name elsewhere
        };
        holds_points(
            &model.bodies[0],
            &vertices,
            &mut rng,
            200,
            &format!("case {case}"),
        );
    }
}

/// Asserts that along `samples` random directions the body's shapes
/// reach at least as far as the farthest of `vertices`: a convex body
/// holds points exactly when its support function bounds theirs.
fn holds_points(
    body: &super::super::model::Body,
    vertices: &[Point3<f64>],
    rng: &mut rand_chacha::ChaCha8Rng,
    samples: usize,
    what: &str,
) {
    use rand::Rng;
    for _ in 0..samples {
        let d = Vector3::new(
            rng.random_range(-1.0..1.0f64),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize();
        let farthest = vertices
            .iter()
            .map(|p| p.coords.dot(&d))
            .fold(f64::NEG_INFINITY, f64::max);
        let reach = body
            .shapes
            .iter()
            .map(|s| {
                let pose = super::super::convert::pose_to_parry(&s.offset);
                let support = s.shape.as_support_map().expect("a convex shape");
                let at = support.support_point(&pose, super::super::convert::vec_to_parry(&d));
                super::super::convert::point_from_parry(at).coords.dot(&d)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            farthest <= reach + 1e-12,
            "{what}: {farthest} beyond {reach} along {d:?}"
        );
    }
}

/// A cylinder mesh of 96 sides (192 rim corners and the caps' centres).
fn tessellated_cylinder(r: f64, h: f64) -> (RobotModel, Vec<Point3<f64>>) {
    let sides = 96;
    let mut vertices = Vec::new();
    for z in [-0.5 * h, 0.5 * h] {
        for k in 0..sides {
            let a = std::f64::consts::TAU * k as f64 / sides as f64;
            vertices.push(Point3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    vertices.push(Point3::new(0.0, 0.0, -0.5 * h));
    vertices.push(Point3::new(0.0, 0.0, 0.5 * h));
    let mut indices = Vec::new();
    for k in 0..sides as u32 {
        let (a, b) = (k, (k + 1) % sides as u32);
        let n = sides as u32;
        indices.extend([a, b, b + n, a, b + n, a + n, 2 * n, b, a, 2 * n + 1, a + n, b + n]);
    }
    let mesh = InlineMesh {
        filename: "package://probe/cylinder.stl".into(),
        vertices: vertices.clone(),
        indices,
    };
    let urdf = probe_urdf(r#"<mesh filename="package://probe/cylinder.stl"/>"#);
    let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    (RobotModel::with_parts(chain, &[], &[mesh]).unwrap(), vertices)
}

/// A finely tessellated mesh is checked as a polytope of few corners:
/// every mesh vertex lies inside it (support functions along sampled
/// directions reach at least as far), its closed-form bound holds the
/// polytope's corners, and it is barely larger than the cylinder (its
/// volume, hand-derived `πr²h`, against the polytope's, summed from
/// parry's hull triangles).
#[test]
fn a_tessellated_mesh_is_checked_as_a_polytope_of_few_corners() {
    use rand::SeedableRng;
    let (r, h) = (0.06, 0.3);
    let (model, vertices) = tessellated_cylinder(r, h);
    let shape = &model.bodies[0].shapes[0];
    let poly = shape.shape.as_convex_polyhedron().expect("a polytope");
    // the mesh's hull has 192 corners
    assert!(poly.points().len() <= 36, "{} corners", poly.points().len());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    holds_points(&model.bodies[0], &vertices, &mut rng, 2000, "the cylinder");
    for p in poly.points() {
        let corner = shape.offset * super::super::convert::point_from_parry(*p);
        assert!(
            super::super::bound::tests::outside(&shape.bound, &corner) <= 1e-12,
            "{corner:?}"
        );
    }
    let volume: f64 = {
        let (points, triangles) = (poly.points(), poly.to_trimesh().1);
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| super::super::convert::point_from_parry(points[i as usize]).coords);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    };
    let cylinder = std::f64::consts::PI * r * r * h;
    assert!(
        volume > cylinder && volume < 1.08 * cylinder,
        "{volume} against {cylinder}"
    );
}

/// What the polytope calls free, the mesh's own hull (parry's, built
/// here from the vertices) finds free too, and it refuses few states the
/// hull finds free: two copies of the tessellated cylinder, and one
/// against a box and a ball, at random poses, overlap and within 1 cm.
#[test]
fn a_mesh_polytope_only_refuses_more_than_its_hull() {
    use rand::{Rng, SeedableRng};

    use super::super::narrow::{
        body_body_intersect, body_body_within, body_leaf_intersect, body_leaf_within,
    };
    let (model, vertices) = tessellated_cylinder(0.06, 0.3);
    let polytope = model.bodies[0].clone();
    let mut hull = polytope.clone();
    let points: Vec<_> = vertices
        .iter()
        .map(|p| super::super::convert::vec_to_parry(&p.coords))
        .collect();
    hull.shapes[0].shape = parry3d_f64::shape::SharedShape::convex_hull(&points).unwrap();
    hull.shapes[0].bound = super::super::bound::enclosing(&vertices);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut pose = || {
        Isometry3::from_parts(
            Translation3::new(
                rng.random_range(-0.35..0.35),
                rng.random_range(-0.35..0.35),
                rng.random_range(-0.35..0.35),
            ),
            nalgebra::UnitQuaternion::from_euler_angles(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            ),
        )
    };
    let obstacles = vec![
        Obstacle::new(
            "box",
            pose(),
            Geometry::Box {
                half_extents: Vector3::new(0.05, 0.1, 0.02),
            },
        ),
        Obstacle::new("ball", pose(), Geometry::Sphere { radius: 0.04 }),
    ];
    let world = SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap();
    // (free for the hull, refused by the polytope) per test
    let mut tally = [(0usize, 0usize); 4];
    let mut count = |k: usize, hull_hit: bool, polytope_hit: bool| {
        assert!(
            polytope_hit || !hull_hit,
            "test {k}: the polytope calls a hull contact free"
        );
        if !hull_hit {
            tally[k].0 += 1;
            tally[k].1 += polytope_hit as usize;
        }
    };
    for _ in 0..20_000 {
        let pa = pose();
        let centre = super::super::narrow::sphere_center(&hull, &pa);
        for leaf in &world.leaves {
            count(
                0,
                body_leaf_intersect(&hull, &pa, &centre, leaf),
                body_leaf_intersect(&polytope, &pa, &centre, leaf),
            );
            count(
                1,
                body_leaf_within(&hull, &pa, &centre, leaf, 0.01),
                body_leaf_within(&polytope, &pa, &centre, leaf, 0.01),
            );
        }
        let pb = pose();
        count(
            2,
            body_body_intersect(&hull, &pa, &hull, &pb),
            body_body_intersect(&polytope, &pa, &polytope, &pb),
        );
        count(
            3,
            body_body_within(&hull, &pa, &hull, &pb, 0.01),
            body_body_within(&polytope, &pa, &polytope, &pb, 0.01),
        );
    }
    for (k, (free, refused)) in tally.iter().enumerate() {
        assert!(
            *free > 5000 && *refused > 0 && *refused * 50 < *free,
            "test {k}: {refused} of {free}"
        );
    }
}

/// The face axes change no overlap verdict between robot bodies, and a
/// within-1-cm verdict only where parry's distance is beyond 1 cm (the
/// test without them grows a box by the margin into a larger box): the
/// built-in Panda with its hand and fingers (polytopes against the
/// fingers' boxes) at random states, every pair, with the filter and with
/// it removed.
#[test]
fn face_axes_change_no_self_verdict() {
    use rand::{Rng, SeedableRng};

    use super::super::narrow::{body_body_intersect, body_body_within};
    let model = panda_hand_open();
    assert!(
        model
            .bodies
            .iter()
            .flat_map(|b| &b.shapes)
            .any(|s| s.faces.is_some())
    );
    let mut bare = model.bodies.clone();
    for s in bare.iter_mut().flat_map(|b| b.shapes.iter_mut()) {
        s.faces = None;
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut poses = [Isometry3::identity(); super::super::model::MAX_BODIES];
    let (mut hits, mut near, mut spared) = (0, 0, 0);
    for _ in 0..3000 {
        let q: Vec<f64> = model
            .chain()
            .limits()
            .map(|(lo, hi)| rng.random_range(lo..=hi))
            .collect();
        model.body_poses(&q, &mut poses);
        for a in 0..model.bodies.len() {
            for b in a + 1..model.bodies.len() {
                let (ba, bb) = (&model.bodies[a], &model.bodies[b]);
                let hit = body_body_intersect(&bare[a], &poses[a], &bare[b], &poses[b]);
                assert_eq!(
                    body_body_intersect(ba, &poses[a], bb, &poses[b]),
                    hit,
                    "{a} {b} at {q:?}"
                );
                let within = body_body_within(&bare[a], &poses[a], &bare[b], &poses[b], 0.01);
                if body_body_within(ba, &poses[a], bb, &poses[b], 0.01) != within {
                    // only where the test without the filter grows a box by
                    // the margin into a larger box, which the face axes do not
                    assert!(within, "{a} {b} at {q:?}: the filter found contact");
                    let distance = exact_distance(ba, &poses[a], bb, &poses[b]);
                    assert!(distance > 0.01, "{a} {b} at {q:?}: proved apart at {distance}");
                    spared += 1;
                }
                hits += hit as usize;
                near += within as usize;
            }
        }
    }
    assert!(
        hits > 100 && near > hits && spared < near / 10,
        "{hits} {near} {spared}"
    );
}

/// The smallest distance between two bodies' shapes (parry), m.
fn exact_distance(
    a: &super::super::model::Body,
    pa: &Isometry3<f64>,
    b: &super::super::model::Body,
    pb: &Isometry3<f64>,
) -> f64 {
    use super::super::convert::pose_to_parry;
    let mut best = f64::INFINITY;
    for sa in &a.shapes {
        for sb in &b.shapes {
            let d = parry3d_f64::query::distance(
                &pose_to_parry(&(pa * sa.offset)),
                &*sa.shape,
                &pose_to_parry(&(pb * sb.offset)),
                &*sb.shape,
            )
            .unwrap()
            .distance;
            best = best.min(d);
        }
    }
    best
}

/// A UV sphere mesh of radius 0.05 m: `rings × around` vertices.
fn uv_sphere(filename: &str, rings: usize, around: usize) -> InlineMesh {
    let mut vertices = Vec::new();
    for i in 0..rings {
        let polar = std::f64::consts::PI * (i as f64 + 0.5) / rings as f64;
        for j in 0..around {
            let azimuth = 2.0 * std::f64::consts::PI * j as f64 / around as f64;
            vertices.push(Point3::new(
                0.05 * polar.sin() * azimuth.cos(),
                0.05 * polar.sin() * azimuth.sin(),
                0.05 * polar.cos(),
            ));
        }
    }
    let mut indices = Vec::new();
    for i in 0..rings - 1 {
        for j in 0..around {
            let a = (i * around + j) as u32;
            let b = (i * around + (j + 1) % around) as u32;
            let up = around as u32;
            indices.extend([a, b, b + up, a, b + up, a + up]);
        }
    }
    InlineMesh {
        filename: filename.into(),
        vertices,
        indices,
    }
}

/// The URDF of the probe with `n` collision elements, each naming `filename`.
fn naming_n_times(filename: &str, n: usize) -> String {
    let element = format!(r#"<mesh filename="{filename}"/>"#);
    let elements = vec![element; n].join("</geometry></collision><collision><geometry>");
    probe_urdf(&elements)
}

/// Collision elements naming one mesh file at one scale share one hull,
/// each placed at its own origin; the same file at another scale is
/// another hull. Each shape holds its element's vertices (parry's point
/// test, 0.1 mm inside), and its closed-form bound holds its corners.
#[test]
fn a_mesh_named_twice_is_built_once_and_placed_twice() {
    use super::super::convert::{point_from_parry, pose_to_parry, vec_to_parry};
    let mesh = uv_sphere("package://probe/ball.stl", 12, 24);
    let name = &mesh.filename;
    let geometry = format!(
        r#"<mesh filename="{name}"/></geometry></collision>
           <collision><origin xyz="0.3 0 0" rpy="0 0 1"/><geometry><mesh filename="{name}"/></geometry></collision>
           <collision><origin xyz="0 0.3 0"/><geometry><mesh filename="{name}" scale="2 1 2"/>"#
    );
    let chain = Arc::new(
        parse_chain(
            &probe_urdf(&geometry),
            &ChainSpec::default(),
            UrdfLimits::default(),
        )
        .unwrap(),
    );
    let model = RobotModel::with_parts(chain, &[], std::slice::from_ref(&mesh)).unwrap();
    let shapes = &model.bodies[0].shapes;
    assert_eq!(shapes.len(), 3);
    assert!(
        Arc::ptr_eq(&shapes[0].shape.0, &shapes[1].shape.0),
        "one hull for one file and scale"
    );
    assert!(
        !Arc::ptr_eq(&shapes[0].shape.0, &shapes[2].shape.0),
        "another scale, another hull"
    );
    let origins = [
        Isometry3::identity(),
        Isometry3::new(Vector3::new(0.3, 0.0, 0.0), Vector3::new(0.0, 0.0, 1.0)),
        Isometry3::translation(0.0, 0.3, 0.0),
    ];
    let scales = [
        Vector3::repeat(1.0),
        Vector3::repeat(1.0),
        Vector3::new(2.0, 1.0, 2.0),
    ];
    for (k, shape) in shapes.iter().enumerate() {
        let pose = pose_to_parry(&shape.offset);
        for v in &mesh.vertices {
            let at = origins[k] * Point3::from(v.coords.component_mul(&scales[k]));
            // 0.1 mm towards the element's centre: strictly inside the hull
            let inner = at + (origins[k].translation.vector - at.coords).normalize() * 1e-4;
            assert!(
                shape.shape.contains_point(&pose, vec_to_parry(&inner.coords)),
                "element {k}: {at:?} outside"
            );
        }
        for p in shape.shape.as_convex_polyhedron().expect("a polytope").points() {
            let corner = shape.offset * point_from_parry(*p);
            assert!(
                super::super::bound::tests::outside(&shape.bound, &corner) <= 1e-12,
                "{corner:?}"
            );
        }
    }
}

#[test]
fn a_mesh_named_beyond_the_vertex_budget_is_refused_before_any_hull() {
    let mesh = uv_sphere("package://r/m.stl", 100, 200);
    let n = MAX_MESH_VERTICES / mesh.vertices.len() + 1;
    let urdf = naming_n_times(&mesh.filename, n);
    let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let started = std::time::Instant::now();
    let err = RobotModel::with_parts(chain, &[], std::slice::from_ref(&mesh)).expect_err("refused");
    // one hull of this mesh alone takes longer than the refusal may
    assert!(
        started.elapsed() < std::time::Duration::from_millis(50),
        "{:?}",
        started.elapsed()
    );
    assert!(
        matches!(&err, CollisionError::TooMany { count, limit, .. }
            if *count == n * mesh.vertices.len() && *limit == MAX_MESH_VERTICES),
        "{err}"
    );
    assert!(err.to_string().contains("links[].collision"), "{err}");
    // within the budget the same mesh builds
    let urdf = naming_n_times(&mesh.filename, 1);
    let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    assert!(RobotModel::with_parts(chain, &[], std::slice::from_ref(&mesh)).is_ok());
}

#[test]
fn building_mesh_shapes_stops_at_the_deadline() {
    let mesh = uv_sphere("package://r/m.stl", 9, 18);
    let urdf = naming_n_times(&mesh.filename, 3);
    let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let past = crate::Deadline::at(std::time::Instant::now());
    let err = RobotModel::with_parts_until(chain.clone(), &[], std::slice::from_ref(&mesh), past)
        .expect_err("stopped");
    assert!(
        matches!(
            &err,
            CollisionError::Stopped {
                stop: crate::Stop::Deadline,
                ..
            }
        ),
        "{err}"
    );
    let built =
        RobotModel::with_parts_until(chain, &[], std::slice::from_ref(&mesh), crate::Deadline::none());
    assert_eq!(built.unwrap().body_count(), 1);
}
