//! Hand-placed cases for every robot-shape × obstacle pair and distances
//! against closed forms. The probe robot is three prismatic joints (x, y, z)
//! carrying one link, so a joint vector is the probe's position.

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::robot::{ChainSpec, UrdfLimits, builtin_chain, parse_chain};

mod lanes;
mod lanes8;
mod pair_table;
mod robot;
mod spheres;
mod sweep;

/// The built-in Panda with its hand, the fingers held 4 cm open (as the
/// benchmark runs it): every link the chain carries collides.
pub(super) fn panda_hand_open() -> RobotModel {
    let chain = builtin_chain("franka_panda_hand").unwrap();
    let urdf = crate::robot::builtin_urdf("franka_panda_hand").unwrap();
    let fingers = [("panda_finger_joint1", 0.04), ("panda_finger_joint2", 0.04)];
    RobotModel::of_urdf(chain, urdf, &fingers, &[]).unwrap()
}

/// A vector with each coordinate within `reach`.
pub(super) fn random_vector(rng: &mut ChaCha8Rng, reach: f64) -> Vector3<f64> {
    Vector3::new(
        rng.random_range(-reach..reach),
        rng.random_range(-reach..reach),
        rng.random_range(-reach..reach),
    )
}

/// A pose with each coordinate within `reach` (m) and random Euler angles.
pub(super) fn random_pose(rng: &mut ChaCha8Rng, reach: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(random_vector(rng, reach)),
        UnitQuaternion::from_euler_angles(
            rng.random_range(-3.2..3.2),
            rng.random_range(-3.2..3.2),
            rng.random_range(-3.2..3.2),
        ),
    )
}

/// A scene of one random box, cylinder, capsule or sphere (sizes 1–15 cm,
/// lengths twice that) at a random pose within `reach` (m).
pub(super) fn random_primitive(rng: &mut ChaCha8Rng, reach: f64) -> SceneGeometry {
    let size = |rng: &mut ChaCha8Rng| rng.random_range(0.01..0.15);
    let geometry = match rng.random_range(0..4) {
        0 => Geometry::Box {
            half_extents: Vector3::new(size(rng), size(rng), size(rng)),
        },
        1 => Geometry::Cylinder {
            radius: size(rng),
            length: 2.0 * size(rng),
        },
        2 => Geometry::Capsule {
            radius: size(rng),
            length: 2.0 * size(rng),
        },
        _ => Geometry::Sphere { radius: size(rng) },
    };
    let obstacle = Obstacle::new("o", random_pose(rng, reach), geometry);
    SceneGeometry::build(&Scene::new(vec![obstacle], &SceneLimits::default()).unwrap()).unwrap()
}

/// URDF of the xyz probe whose link carries `geometry` (URDF XML).
pub(super) fn probe_urdf(geometry: &str) -> String {
    let joint = |name: &str, parent: &str, child: &str, axis: &str| {
        format!(
            r#"<joint name="{name}" type="prismatic"><parent link="{parent}"/><child link="{child}"/>
               <axis xyz="{axis}"/><limit lower="-10" upper="10" effort="0" velocity="1"/></joint>"#
        )
    };
    format!(
        r#"<robot name="probe"><link name="base"/><link name="px"/><link name="py"/>
           <link name="probe"><collision><geometry>{geometry}</geometry></collision></link>
           {}{}{}</robot>"#,
        joint("jx", "base", "px", "1 0 0"),
        joint("jy", "px", "py", "0 1 0"),
        joint("jz", "py", "probe", "0 0 1"),
    )
}

pub(super) fn checker(urdf: &str, meshes: &[InlineMesh], obstacles: Vec<Obstacle>) -> SceneChecker {
    let chain = Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let model = Arc::new(RobotModel::with_parts(chain, &[], meshes).unwrap());
    let acm = AllowedCollisions::adjacent(&model);
    let scene = Scene::new(obstacles, &SceneLimits::default()).unwrap();
    let world = Arc::new(SceneGeometry::build(&scene).unwrap());
    SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap()
}

/// A closed unit-free box mesh of half extents `h` (12 triangles, outward).
pub(super) fn box_mesh(h: Vector3<f64>) -> (Vec<Point3<f64>>, Vec<u32>) {
    let v: Vec<Point3<f64>> = (0..8)
        .map(|i| {
            Point3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let idx = vec![
        0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3,
        7, 5,
    ];
    (v, idx)
}

/// Robot probe shapes: (name, URDF geometry, half width along x, inline meshes).
fn probes() -> Vec<(&'static str, String, f64, Vec<InlineMesh>)> {
    let (vertices, indices) = box_mesh(Vector3::new(0.05, 0.04, 0.03));
    // ten times larger in the file, scaled by the URDF to the same box
    let (big, big_indices) = box_mesh(Vector3::new(0.5, 0.4, 0.3));
    vec![
        ("sphere", r#"<sphere radius="0.05"/>"#.into(), 0.05, vec![]),
        ("box", r#"<box size="0.1 0.3 0.2"/>"#.into(), 0.05, vec![]),
        (
            "cylinder",
            r#"<cylinder radius="0.05" length="0.3"/>"#.into(),
            0.05,
            vec![],
        ),
        (
            "capsule",
            r#"<capsule radius="0.05" length="0.3"/>"#.into(),
            0.05,
            vec![],
        ),
        (
            "mesh (convex hull)",
            r#"<mesh filename="package://probe/hull.stl"/>"#.into(),
            0.05,
            vec![InlineMesh {
                filename: "package://probe/hull.stl".into(),
                vertices,
                indices,
            }],
        ),
        (
            "mesh scaled by the URDF",
            r#"<mesh filename="package://probe/big.stl" scale="0.1 0.1 0.1"/>"#.into(),
            0.05,
            vec![InlineMesh {
                filename: "package://probe/big.stl".into(),
                vertices: big,
                indices: big_indices,
            }],
        ),
    ]
}

/// Obstacles at the origin: (name, geometry, half width along x, solid).
/// Meshes are surfaces (shells), so "inside" is tested on their surface.
fn obstacles() -> Vec<(&'static str, Geometry, f64, bool)> {
    let (vertices, indices) = box_mesh(Vector3::new(0.2, 0.2, 0.2));
    vec![
        (
            "box",
            Geometry::Box {
                half_extents: Vector3::new(0.2, 0.25, 0.3),
            },
            0.2,
            true,
        ),
        ("sphere", Geometry::Sphere { radius: 0.2 }, 0.2, true),
        (
            "cylinder",
            Geometry::Cylinder {
                radius: 0.2,
                length: 0.5,
            },
            0.2,
            true,
        ),
        (
            "capsule",
            Geometry::Capsule {
                radius: 0.2,
                length: 0.5,
            },
            0.2,
            true,
        ),
        ("mesh", Geometry::Mesh { vertices, indices }, 0.2, false),
        (
            "cells",
            Geometry::OccupiedCells {
                size: 0.1,
                centers: vec![
                    Point3::new(0.15, 0.0, 0.0),
                    Point3::new(0.05, 0.0, 0.0),
                    Point3::new(-0.05, 0.0, 0.0),
                ],
            },
            0.2,
            true,
        ),
    ]
}

#[test]
fn every_pair_touching_one_millimetre_apart_and_inside() {
    for (pname, geometry, ph, meshes) in probes() {
        for (oname, g, oh, solid) in obstacles() {
            let c = checker(
                &probe_urdf(&geometry),
                &meshes,
                vec![Obstacle::new(oname, Isometry3::identity(), g)],
            );
            let contact = ph + oh;
            let case = format!("{pname} × {oname}");
            // Touching: clearance 0 (µm tolerance); a µm closer overlaps.
            let touching = c.clearance(&[contact, 0.0, 0.0], 0.1);
            assert!(touching.abs() < 1e-6, "{case}: touching clearance {touching}");
            assert!(
                !c.is_valid(&[contact - 1e-6, 0.0, 0.0]),
                "{case}: 1 µm overlap is valid"
            );
            // 1 mm apart: valid, clearance 1 mm.
            let q = [contact + 1e-3, 0.0, 0.0];
            assert!(c.is_valid(&q), "{case}: 1 mm apart is invalid");
            let d = c.clearance(&q, 0.1);
            assert!((d - 1e-3).abs() < 1e-6, "{case}: clearance {d} at 1 mm");
            // Inside (on the surface for shells): invalid, negative clearance.
            // Off-centre, so no pair is in a symmetric (degenerate) configuration.
            let inside = if solid {
                [0.01, 0.005, 0.002]
            } else {
                [oh, 0.005, 0.002]
            };
            assert!(!c.is_valid(&inside), "{case}: inside is valid");
            let depth = c.clearance(&inside, 0.1);
            assert!(depth < 0.0, "{case}: inside clearance {depth} not negative");
            let report = c.report(&inside).unwrap();
            assert_eq!(
                report.collisions,
                vec![(
                    "probe".to_string(),
                    Part::Obstacle {
                        index: 0,
                        name: oname.into()
                    }
                )]
            );
        }
    }
}

fn proximity_of(geometry: &str, obstacle: Geometry, pose: Isometry3<f64>, q: [f64; 3]) -> Proximity {
    let c = checker(
        &probe_urdf(geometry),
        &[],
        vec![Obstacle::new("o", pose, obstacle)],
    );
    c.proximity(&q, 10.0).unwrap().expect("within 10 m")
}

#[test]
fn sphere_sphere_distance_is_centre_distance_minus_radii() {
    // Centres 1.3 m apart (0.3, 0.4, 1.2), radii 0.1 and 0.2: 1.0 m.
    let p = proximity_of(
        r#"<sphere radius="0.1"/>"#,
        Geometry::Sphere { radius: 0.2 },
        Isometry3::identity(),
        [0.3, 0.4, 1.2],
    );
    assert!((p.distance - 1.0).abs() < 1e-9, "{}", p.distance);
    let dir: Vector3<f64> = Vector3::new(0.3, 0.4, 1.2) / 1.3;
    assert!((p.point_on_other.coords - 0.2 * dir).norm() < 1e-9);
    assert!((p.point_on_link.coords - 1.2 * dir).norm() < 1e-9);
}

#[test]
fn sphere_box_distance_at_a_face_an_edge_and_a_corner() {
    // Box half extents (0.2, 0.3, 0.4), sphere radius 0.1; the excess over
    // the half extents is 0.3 on every axis the sphere lies beyond.
    let b = || Geometry::Box {
        half_extents: Vector3::new(0.2, 0.3, 0.4),
    };
    let pose = Isometry3::from_parts(
        Translation3::new(1.0, -2.0, 0.5),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.7),
    );
    for (local, expected) in [
        (Vector3::new(0.5, 0.0, 0.0), 0.3 - 0.1),
        (Vector3::new(0.5, 0.6, 0.0), 0.18_f64.sqrt() - 0.1),
        (Vector3::new(0.5, 0.6, 0.7), 0.27_f64.sqrt() - 0.1),
    ] {
        let world = pose * Point3::from(local);
        let p = proximity_of(
            r#"<sphere radius="0.1"/>"#,
            b(),
            pose,
            [world.x, world.y, world.z],
        );
        assert!(
            (p.distance - expected).abs() < 1e-9,
            "{local:?}: {} vs {expected}",
            p.distance
        );
    }
}

#[test]
fn capsule_capsule_distance_between_skew_segments() {
    // Obstacle: segment (−1,0,0)–(1,0,0), radius 0.1 (a z capsule turned
    // onto x). Probe: segment x = 1.3, y = 0.5, z ∈ [0.4, 0.8], radius 0.05.
    // Nearest points (1,0,0) and (1.3,0.5,0.4): √0.5 − 0.15.
    let pose = Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2),
    );
    let p = proximity_of(
        r#"<capsule radius="0.05" length="0.4"/>"#,
        Geometry::Capsule {
            radius: 0.1,
            length: 2.0,
        },
        pose,
        [1.3, 0.5, 0.6],
    );
    let expected = 0.5_f64.sqrt() - 0.15;
    assert!(
        (p.distance - expected).abs() < 1e-7,
        "{} vs {expected}",
        p.distance
    );
    let dir: Vector3<f64> = Vector3::new(0.3, 0.5, 0.4) / 0.5_f64.sqrt();
    // GJK stops within its tolerance: witnesses to 0.1 mm (observed 2e-5 m).
    assert!((p.point_on_other - (Point3::new(1.0, 0.0, 0.0) + 0.1 * dir)).norm() < 1e-4);
    assert!((p.point_on_link - (Point3::new(1.3, 0.5, 0.4) - 0.05 * dir)).norm() < 1e-4);
}

#[test]
fn clearance_stops_at_max_distance_and_the_empty_scene_is_free() {
    let c = checker(&probe_urdf(r#"<sphere radius="0.1"/>"#), &[], vec![]);
    assert!(c.is_valid(&[0.0, 0.0, 0.0]));
    assert_eq!(c.clearance(&[0.0, 0.0, 0.0], 0.25), 0.25);
    let far = checker(
        &probe_urdf(r#"<sphere radius="0.1"/>"#),
        &[],
        vec![Obstacle::new(
            "s",
            Isometry3::identity(),
            Geometry::Sphere { radius: 0.1 },
        )],
    );
    assert_eq!(far.clearance(&[5.0, 0.0, 0.0], 0.25), 0.25);
    assert!(far.proximity(&[5.0, 0.0, 0.0], 0.25).unwrap().is_none());
    // Bad joint vectors: an error from the rich query, invalid and −∞ from the trait.
    assert!(far.proximity(&[f64::NAN, 0.0, 0.0], 1.0).is_err());
    assert!(!far.is_valid(&[0.0, 0.0]));
    assert_eq!(far.clearance(&[0.0, 0.0], 1.0), f64::NEG_INFINITY);
    // Outside the joint limits is invalid even when free.
    assert!(!far.is_valid(&[11.0, 0.0, 0.0]));
    assert_eq!(far.report(&[11.0, 0.0, 0.0]).unwrap().out_of_limits.len(), 1);
}

#[test]
fn validity_and_clearance_together_equal_the_two_queries() {
    // Every probe shape beside every obstacle kind, at states from inside
    // to 0.3 m away, within and outside the limits, and bad vectors.
    for (name, shape, _, meshes) in probes() {
        for (kind, geometry, _, _) in obstacles() {
            let obstacle = Obstacle::new("o", Isometry3::identity(), geometry);
            let c = checker(&probe_urdf(&shape), &meshes, vec![obstacle]);
            for x in [0.0, 0.05, 0.12, 0.2, 0.3, 0.4, 0.6, 11.0] {
                let q = [x, 0.03, -0.02];
                let together = c.valid_and_clearance(&q, 0.25);
                assert_eq!(
                    together,
                    (c.is_valid(&q), c.clearance(&q, 0.25)),
                    "{name} vs {kind} at {x}"
                );
            }
            assert_eq!(
                c.valid_and_clearance(&[0.0, f64::NAN, 0.0], 0.25),
                (false, f64::NEG_INFINITY)
            );
            assert_eq!(
                c.valid_and_clearance(&[0.0, 0.0], 0.25),
                (false, f64::NEG_INFINITY)
            );
        }
    }
}

#[test]
fn bodies_out_of_reach_of_every_obstacle_are_skipped_without_changing_a_verdict() {
    // A 20 cm box where the Panda's hand and forearm reach (0.6 m out, at
    // the shoulder's height) but its shoulder links (within 0.5 m of joint
    // 1's origin) never do: the checker leaves those out of its scene
    // tests; every verdict must still be that of the report, which tests
    // every body against every obstacle.
    let chain = builtin_chain("franka_panda").unwrap();
    let model = Arc::new(RobotModel::new(chain.clone()).unwrap());
    let acm = AllowedCollisions::sampled(&model, &AcmParams::default()).unwrap();
    let block = Obstacle::new(
        "block",
        Isometry3::translation(0.6, 0.0, 0.4),
        Geometry::Box {
            half_extents: Vector3::repeat(0.1),
        },
    );
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(vec![block], &SceneLimits::default()).unwrap()).unwrap());
    let checker = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
    let sweep = SweepBound::new(checker.model()).unwrap();
    // link 1's reach from joint 1's origin (0, 0, 0.333) stops short of the box
    assert!(sweep.lever(1, 0) < 0.5 - 0.1, "{}", sweep.lever(1, 0));
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut valid, mut invalid) = (0, 0);
    for _ in 0..3000 {
        let q: Vec<f64> = chain
            .joints()
            .iter()
            .map(|j| rng.random_range(j.lower..=j.upper))
            .collect();
        let expected = checker.report(&q).unwrap().is_valid();
        assert_eq!(checker.is_valid(&q), expected, "{q:?}");
        if expected {
            valid += 1;
        } else if checker
            .report(&q)
            .unwrap()
            .collisions
            .iter()
            .any(|(_, o)| matches!(o, Part::Obstacle { .. }))
        {
            invalid += 1;
        }
    }
    eprintln!("valid {valid}, hitting the box {invalid}");
    assert!(
        valid > 100 && invalid > 30,
        "valid {valid}, hitting the box {invalid}"
    );
}

#[test]
fn a_model_of_more_bodies_than_the_small_buffers_gets_the_report_verdicts() {
    // A 20-link snake of 0.1 m links turning about z, a 4 cm sphere at each
    // link's end, beside a box: the checks of models beyond the small pose
    // buffers must agree with the report (every body, every obstacle) and
    // the padded check with the padded test on the full buffers.
    let mut urdf = String::from(r#"<robot name="snake"><link name="l0"/>"#);
    for i in 1..=20 {
        urdf += &format!(
            r#"<link name="l{i}"><collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.04"/></geometry></collision></link>
               <joint name="j{i}" type="revolute"><parent link="l{}"/><child link="l{i}"/><origin xyz="{}"/>
               <axis xyz="0 0 1"/><limit lower="-0.6" upper="0.6" effort="0" velocity="1"/></joint>"#,
            i - 1,
            if i == 1 { "0 0 0" } else { "0.1 0 0" }
        );
    }
    urdf += "</robot>";
    let block = Obstacle::new(
        "block",
        Isometry3::translation(1.2, 0.4, 0.0),
        Geometry::Box {
            half_extents: Vector3::new(0.2, 0.1, 0.1),
        },
    );
    let chain = Arc::new(parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let model = Arc::new(RobotModel::new(chain.clone()).unwrap());
    assert_eq!(model.body_count(), 20);
    let acm = AllowedCollisions::adjacent(&model);
    let world =
        Arc::new(SceneGeometry::build(&Scene::new(vec![block], &SceneLimits::default()).unwrap()).unwrap());
    let checker = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
    let sweep = SweepBound::new(checker.model()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let (mut valid, mut invalid, mut proved) = (0, 0, 0);
    for _ in 0..2000 {
        let q: Vec<f64> = (0..20).map(|_| rng.random_range(-0.3..0.3)).collect();
        let expected = checker.report(&q).unwrap().is_valid();
        assert_eq!(checker.is_valid(&q), expected, "{q:?}");
        let half: Vec<f64> = (0..20).map(|_| rng.random_range(-0.01..0.01)).collect();
        let mut pads = [0.0; MAX_BODIES];
        sweep.pads(&half, &mut pads);
        if checker.padded_valid(&q, &half) == Some(true) {
            // the tight pads are within the global ones: free with them too
            assert!(expected);
            proved += 1;
        }
        if !checker.in_collision_padded(&q, &pads) {
            assert_eq!(checker.padded_valid(&q, &half), Some(true), "{q:?}");
        }
        if expected {
            valid += 1;
        } else {
            invalid += 1;
        }
    }
    assert!(
        valid > 100 && invalid > 100 && proved > 100,
        "{valid} {invalid} {proved}"
    );
}

#[test]
fn a_body_fixed_to_the_base_collides_in_every_state_or_in_none() {
    // A 0.2 m base plate (fixed) and a 5 cm sphere on a 1 m arm turning
    // about z: an obstacle touching the plate makes every state invalid,
    // however the arm turns; one beside the plate's edge leaves them valid
    // (the arm passes above it).
    let urdf = r#"<robot name="plate">
      <link name="base"><collision><geometry><box size="0.2 0.2 0.02"/></geometry></collision></link>
      <link name="arm"><collision><origin xyz="1 0 0.5"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint></robot>"#;
    let block = |x: f64| {
        Obstacle::new(
            "block",
            Isometry3::translation(x, 0.0, 0.0),
            Geometry::Box {
                half_extents: Vector3::repeat(0.05),
            },
        )
    };
    // faces touch at x = 0.1 (the plate's edge) when the block is at 0.15
    let touching = checker(urdf, &[], vec![block(0.15)]);
    let clear = checker(urdf, &[], vec![block(0.1501)]);
    for q in [-2.5, -1.0, 0.0, 0.7, 2.9] {
        assert!(!touching.is_valid(&[q]), "q = {q}");
        let report = touching.report(&[q]).unwrap();
        assert_eq!(
            report.collisions,
            vec![(
                "base".to_string(),
                Part::Obstacle {
                    index: 0,
                    name: "block".into()
                }
            )]
        );
        assert!(clear.is_valid(&[q]), "q = {q}");
    }
    let padded = |obstacles| {
        let chain = Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
        let model = Arc::new(RobotModel::new(chain).unwrap());
        let acm = AllowedCollisions::adjacent(&model);
        let world =
            Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap());
        let params = CheckerParams {
            padded_motion: true,
            ..CheckerParams::default()
        };
        SceneChecker::new(model, &acm, world, params).unwrap()
    };
    assert_eq!(
        padded(vec![block(0.15)]).padded_verdict(&[0.3], &[0.01]),
        Some(PadVerdict::Collides)
    );
    assert_eq!(
        padded(vec![block(0.1501)]).padded_verdict(&[0.3], &[0.01]),
        Some(PadVerdict::Free)
    );
}
