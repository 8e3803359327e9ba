//! The sphere model: every sampled point of every body (inside and on the
//! surface, as parry describes the shape) lies in one of its fine spheres and
//! in its coarse sphere, for every built-in robot and for a robot with a
//! cylinder and a mesh hull; every fine sphere reaches no farther beyond its
//! body than the model says (distances by parry's point queries).

use std::sync::Arc;
use std::time::Instant;

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::convert::pose_to_parry;
use super::super::*;
use super::box_mesh;
use crate::robot::{BUILTIN_NAMES, ChainSpec, UrdfLimits, builtin_chain, builtin_urdf, parse_chain};

/// Points of a body (body frame): inside its shapes and on their surfaces.
fn body_points(model: &RobotModel, b: usize, rng: &mut ChaCha8Rng) -> Vec<Point3<f64>> {
    let mut points = Vec::new();
    for s in &model.bodies[b].shapes {
        let pose = pose_to_parry(&s.offset);
        let aabb = s.shape.compute_aabb(&pose);
        let (lo, hi) = (aabb.mins, aabb.maxs);
        let reach = (hi - lo).length();
        let mid = (lo + hi) * 0.5;
        for _ in 0..300 {
            // inside: uniform in the box around the shape, kept when contained
            let p = parry3d_f64::math::Vector::new(
                rng.random_range(lo.x..=hi.x),
                rng.random_range(lo.y..=hi.y),
                rng.random_range(lo.z..=hi.z),
            );
            if s.shape.contains_point(&pose, p) {
                points.push(Point3::new(p.x, p.y, p.z));
            }
            // on the surface: a far point projected onto the shape
            let dir = parry3d_f64::math::Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let far = mid + dir * (2.0 * reach / dir.length().max(1e-9));
            let q = s.shape.project_point(&pose, far, true).point;
            points.push(Point3::new(q.x, q.y, q.z));
        }
    }
    points
}

/// Distance (m) from `p` (body frame) to body `b`, 0 inside.
fn distance_to_body(model: &RobotModel, b: usize, p: &Point3<f64>) -> f64 {
    let v = parry3d_f64::math::Vector::new(p.x, p.y, p.z);
    model.bodies[b]
        .shapes
        .iter()
        .map(|s| s.shape.distance_to_point(&pose_to_parry(&s.offset), v, true))
        .fold(f64::INFINITY, f64::min)
}

fn assert_covers(name: &str, model: &RobotModel, spheres: &SphereModel, rng: &mut ChaCha8Rng) {
    assert_eq!(spheres.body_count(), model.body_count(), "{name}");
    for b in 0..model.body_count() {
        let fine = spheres.fine(b);
        assert!(!fine.is_empty(), "{name} body {b}");
        let coarse = spheres.coarse(b);
        for p in body_points(model, b, rng) {
            let inside = |s: &Sphere| (p - s.center).norm() <= s.radius + 1e-12;
            assert!(
                fine.iter().any(inside),
                "{name} body {b}: {p:?} in no fine sphere"
            );
            assert!(
                inside(&coarse),
                "{name} body {b}: {p:?} outside the coarse sphere"
            );
        }
        // every fine sphere stays within the overshoot of the body: points
        // on its surface in 64 directions
        let reach = spheres.overshoot(b);
        for s in fine {
            for k in 0..64 {
                let u = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let u = if k == 0 || u.norm() < 1e-6 {
                    Vector3::x()
                } else {
                    u.normalize()
                };
                let d = distance_to_body(model, b, &(s.center + u * s.radius));
                assert!(
                    d <= reach + 1e-9,
                    "{name} body {b}: a sphere reaches {d} beyond, model says {reach}"
                );
            }
        }
    }
}

#[test]
fn sphere_covers_contain_every_body_of_every_built_in_robot() {
    let mut rng = ChaCha8Rng::seed_from_u64(25);
    for name in BUILTIN_NAMES {
        let chain = builtin_chain(name).unwrap();
        let model = RobotModel::of_urdf(chain, builtin_urdf(name).unwrap(), &[], &[]).unwrap();
        for params in [
            SphereParams::default(),
            SphereParams {
                max_overshoot: 0.05,
                max_per_shape: 4,
            },
        ] {
            let spheres = SphereModel::build(&model, &params).unwrap();
            assert_covers(name, &model, &spheres, &mut rng);
        }
    }
}

#[test]
fn capsule_and_box_covers_meet_the_overshoot_with_the_counts_derived_by_hand() {
    // Capsule r = 0.09, L = 0.316 (the Panda's link 2), overshoot 0.01:
    // s ≤ √(0.1² − 0.09²) = 0.04359, n = ⌈0.316 / 0.08718⌉ = 4, 5 spheres of
    // radius √(0.09² + 0.0395²) = 0.098287; a 0.1 × 0.1 × 0.1 box: cubic
    // cells of half c need c(√3 − 1) ≤ 0.01, c ≤ 0.01366, so 4 per axis
    // (c = 0.0125), 64 spheres of radius 0.0125·√3.
    let urdf = r#"<robot name="probe">
      <link name="base"/>
      <link name="cap"><collision><geometry><capsule radius="0.09" length="0.316"/></geometry></collision></link>
      <link name="cube"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="cap"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="cap"/><child link="cube"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
    </robot>"#;
    let chain = Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let model = RobotModel::new(chain).unwrap();
    let spheres = SphereModel::build(&model, &SphereParams::default()).unwrap();
    let cap = spheres.fine(0);
    assert_eq!(cap.len(), 5);
    assert!((cap[0].radius - (0.09f64.powi(2) + 0.0395f64.powi(2)).sqrt()).abs() < 1e-12);
    assert!(spheres.overshoot(0) <= 0.01);
    let cube = spheres.fine(1);
    assert_eq!(cube.len(), 64);
    assert!((cube[0].radius - 0.0125 * 3f64.sqrt()).abs() < 1e-12);
    assert!(spheres.overshoot(1) <= 0.01);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    assert_covers("probe", &model, &spheres, &mut rng);
}

#[test]
fn cylinders_and_mesh_hulls_are_covered_through_their_bounds() {
    let (vertices, indices) = box_mesh(Vector3::new(0.05, 0.12, 0.03));
    let urdf = r#"<robot name="probe">
      <link name="base"/>
      <link name="drum"><collision><origin xyz="0.1 0 0" rpy="0.3 0.2 0"/><geometry><cylinder radius="0.06" length="0.25"/></geometry></collision></link>
      <link name="hull"><collision><origin rpy="0 0 0.7"/><geometry><mesh filename="package://probe/hull.stl"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="drum"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="drum"/><child link="hull"/><origin xyz="1 0 0"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
    </robot>"#;
    let chain = Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let mesh = InlineMesh {
        filename: "package://probe/hull.stl".into(),
        vertices,
        indices,
    };
    let model = RobotModel::with_parts(chain, &[], &[mesh]).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for params in [
        SphereParams::default(),
        SphereParams {
            max_overshoot: 0.2,
            max_per_shape: 1,
        },
    ] {
        let spheres = SphereModel::build(&model, &params).unwrap();
        assert!(spheres.fine(0).len() <= params.max_per_shape);
        assert_covers("cylinder and hull", &model, &spheres, &mut rng);
    }
}

#[test]
fn the_panda_sphere_model_builds_within_50_ms() {
    let chain = builtin_chain("franka_panda_hand").unwrap();
    let model = RobotModel::of_urdf(chain, builtin_urdf("franka_panda_hand").unwrap(), &[], &[]).unwrap();
    let t = Instant::now();
    let spheres = SphereModel::build(&model, &SphereParams::default()).unwrap();
    let took = t.elapsed();
    assert!(took.as_secs_f64() < 0.05, "{took:?}");
    assert!(spheres.fine_count() >= model.body_count());
}

#[test]
fn bad_sphere_params_are_refused_by_name() {
    let chain = builtin_chain("franka_panda").unwrap();
    let model = RobotModel::new(chain).unwrap();
    for (params, field) in [
        (
            SphereParams {
                max_overshoot: 0.0,
                ..SphereParams::default()
            },
            "max_overshoot",
        ),
        (
            SphereParams {
                max_overshoot: f64::NAN,
                ..SphereParams::default()
            },
            "max_overshoot",
        ),
        (
            SphereParams {
                max_per_shape: 0,
                ..SphereParams::default()
            },
            "max_per_shape",
        ),
    ] {
        let err = SphereModel::build(&model, &params).unwrap_err();
        assert!(err.to_string().contains(field), "{err}");
    }
}
