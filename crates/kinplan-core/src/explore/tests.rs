use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::{Isometry3, Point3, Vector3};

use super::*;
use crate::Deadline;
use crate::collision::{
    AcmParams, AllowedCollisions, Geometry, Obstacle, RobotModel, Scene, SceneGeometry, SceneLimits,
};
use crate::nbv::{CameraModel, look_along};
use crate::robot::{Chain, builtin_chain};

fn geometry(obstacles: Vec<Obstacle>) -> Arc<SceneGeometry> {
    Arc::new(SceneGeometry::build(&Scene::new(obstacles, &SceneLimits::default()).unwrap()).unwrap())
}

fn small_camera() -> CameraModel {
    CameraModel {
        width: 41,
        height: 31,
        ..CameraModel::default()
    }
}

#[test]
fn a_wall_at_known_distance_gives_that_depth_in_every_pixel() {
    // wall face at x = 2 (box from x = 2 to 2.2), camera at the origin looking along +x
    let wall = Obstacle::new(
        "wall",
        Isometry3::translation(2.1, 0.0, 0.0),
        Geometry::Box {
            half_extents: Vector3::new(0.1, 10.0, 10.0),
        },
    );
    let world = geometry(vec![wall]);
    let cam = small_camera();
    let pose = look_along(&Point3::origin(), &Vector3::x()).unwrap();
    let sensor = SensorParams {
        pixel_stride: 1,
        noise_stddev: 0.0,
        ..SensorParams::default()
    };
    let img = render_depth(&world, &cam, &pose, &sensor, 0);
    assert_eq!((img.width, img.height), (41, 31));
    // depth is along the optical axis, so a plane facing the camera has one depth
    assert!(
        img.depth.iter().all(|d| (*d - 2.0).abs() < 1e-5),
        "{:?}",
        &img.depth[..5]
    );
    // and the back-projected points lie on the plane x = 2
    let pts = depth_to_points(&img, &cam, &pose, 1);
    assert_eq!(pts.len(), 41 * 31);
    assert!(pts.iter().all(|p| (p[0] - 2.0).abs() < 1e-5));
    // the corner pixel sees the wall at y = 2·tan(hfov/2)
    let corner = pts.iter().map(|p| p[1].abs()).fold(0.0f32, f32::max) as f64;
    assert!((corner - 2.0 * (cam.hfov / 2.0).tan()).abs() < 1e-4);
}

#[test]
fn a_sphere_is_seen_at_the_distance_of_its_surface_and_out_of_range_is_no_return() {
    let r = 0.5;
    let ball = Obstacle::new(
        "ball",
        Isometry3::translation(0.0, 0.0, 3.0),
        Geometry::Sphere { radius: r },
    );
    let world = geometry(vec![ball]);
    let cam = small_camera();
    let pose = Isometry3::identity(); // optical +z = world +z
    let sensor = SensorParams {
        pixel_stride: 1,
        noise_stddev: 0.0,
        ..SensorParams::default()
    };
    let img = render_depth(&world, &cam, &pose, &sensor, 0);
    // the centre pixel (20, 15) looks straight at the sphere: depth 3 − r
    let centre = img.depth[15 * img.width + 20] as f64;
    assert!((centre - 2.5).abs() < 1e-5);
    // every hit point lies on the sphere's surface
    let pts = depth_to_points(&img, &cam, &pose, 1);
    assert!(!pts.is_empty());
    for p in &pts {
        let d = ((p[0] as f64).powi(2) + (p[1] as f64).powi(2) + (p[2] as f64 - 3.0).powi(2)).sqrt();
        assert!((d - r).abs() < 1e-4, "{d}");
    }
    // beyond the far range the same sphere is not returned
    let far = CameraModel { far: 2.4, ..cam };
    assert_eq!(render_depth(&world, &far, &pose, &sensor, 0).returns(), 0);
    // noise moves depths, reproducibly for a seed
    let noisy = SensorParams {
        pixel_stride: 1,
        noise_stddev: 0.01,
        ..SensorParams::default()
    };
    let a = render_depth(&world, &cam, &pose, &noisy, 7);
    assert_eq!(a, render_depth(&world, &cam, &pose, &noisy, 7));
    let moved = a.depth[15 * a.width + 20] as f64;
    assert!(moved != centre && (moved - centre).abs() < 0.06);
    // a render that is told to stop returns nothing
    assert!(
        render_depth_until(
            &world,
            &cam,
            &pose,
            &sensor,
            0,
            Deadline::none().with_cancel(&|| true)
        )
        .is_none()
    );
}

struct Rig {
    chain: Arc<Chain>,
    model: Arc<RobotModel>,
    acm: AllowedCollisions,
}

fn irb() -> Rig {
    let chain = builtin_chain("abb_irb4600_60_205").unwrap();
    let model = Arc::new(RobotModel::new(chain.clone()).unwrap());
    let acm = AllowedCollisions::sampled(
        &model,
        &AcmParams {
            samples: 300,
            ..AcmParams::default()
        },
    )
    .unwrap();
    Rig { chain, model, acm }
}

/// Coarse and quick: 0.2 m cells, every 8th pixel, 3 iterations.
fn quick_params(scene: &ReferenceScene, dof: usize) -> ExploreParams {
    let mut p = ExploreParams::new(scene.region, dof);
    p.resolution = 0.2;
    p.sensor.pixel_stride = 8;
    p.stop.max_iterations = 3;
    p.plan.algorithm = crate::plan::Algorithm::RrtConnect;
    p.seed = 3;
    p
}

fn run(rig: &Rig, scene: &ReferenceScene, p: &ExploreParams, steps: &mut Vec<ExploreStep>) -> ExploreOutcome {
    let truth = geometry(scene.obstacles.clone());
    let world = ExploreWorld {
        chain: &rig.chain,
        model: &rig.model,
        acm: &rig.acm,
        truth: &truth,
    };
    let mut record = |s: &ExploreStep| steps.push(s.clone());
    let ctl = ExploreControl {
        on_step: Some(&mut record),
        ..ExploreControl::default()
    };
    explore(&world, &scene.start, p, ctl).unwrap()
}

#[test]
fn exploring_the_open_cell_raises_the_known_ratio_monotonically_and_reproducibly() {
    let rig = irb();
    let scene = s0_open_cell(1);
    let p = quick_params(&scene, rig.chain.dof());
    let mut steps = Vec::new();
    let out = run(&rig, &scene, &p, &mut steps);
    assert!(out.iterations >= 1 && out.iterations <= 3, "{:?}", out.status);
    assert_eq!(steps.len(), out.iterations);
    // the known ratio never decreases and ends above the initial scans'
    let mut last = out.initial_known_ratio;
    for s in &steps {
        assert!(s.known_ratio >= last, "{} < {last}", s.known_ratio);
        last = s.known_ratio;
    }
    assert!(out.known_ratio > out.initial_known_ratio);
    // an independent count: cells of the region known in the final tree,
    // recounted from the tree itself over the observable cells
    let truth = geometry(scene.obstacles.clone());
    let cells = ObservableCells::new(&out.tree, &scene.region.0, &scene.region.1, &truth).unwrap();
    assert_eq!(cells.len(), out.observable_cells);
    assert!((cells.known_ratio(&out.tree) - out.known_ratio).abs() < 1e-12);
    // every executed motion starts where the previous iteration ended
    let mut q = scene.start.clone();
    for s in &steps {
        if let Some(m) = &s.motion {
            for (a, b) in m.q[..m.dof].iter().zip(&q) {
                assert!((a - b).abs() < 1e-9);
            }
            q = m.q[m.q.len() - m.dof..].to_vec();
            // the criteria are those of the motion: CD is at least the chord
            let a = rig.chain.fk(&m.q[..m.dof]).translation.vector;
            let b = rig.chain.fk(&q).translation.vector;
            assert!(m.criteria.cd + 1e-9 >= (a - b).norm());
        }
        assert_eq!(s.joints, q);
    }
    // a seeded run is reproducible
    let mut again = Vec::new();
    let out2 = run(&rig, &scene, &p, &mut again);
    assert_eq!(out2.known_ratio, out.known_ratio);
    assert_eq!(out2.final_joints, out.final_joints);
    assert_eq!(out2.tree.write_bt(), out.tree.write_bt());
}

#[test]
fn a_region_out_of_reach_ends_with_a_status_not_a_hang() {
    let rig = irb();
    let mut scene = s0_open_cell(1);
    // the cell 8–10 m away: every view is out of reach (ORF) or unplannable
    scene.region = (Point3::new(8.0, -1.0, 0.0), Point3::new(10.0, 1.0, 1.0));
    let mut p = quick_params(&scene, rig.chain.dof());
    p.stop.max_iterations = 20;
    let t0 = Instant::now();
    let out = run(&rig, &scene, &p, &mut Vec::new());
    assert!(
        matches!(
            out.status,
            ExploreStatus::NoCandidates | ExploreStatus::ConsecutiveFailures
        ),
        "{:?}",
        out.status
    );
    assert!(t0.elapsed() < Duration::from_secs(60));
}

#[test]
fn the_deadline_stops_the_loop_between_stages() {
    let rig = irb();
    let scene = s0_open_cell(1);
    let mut p = quick_params(&scene, rig.chain.dof());
    p.stop.max_iterations = 100;
    p.stop.known_ratio = 1.0;
    // failures under a loaded machine (IK budgets running out) must not end
    // the run before the deadline does
    p.stop.max_consecutive_failures = 10_000;
    let truth = geometry(scene.obstacles.clone());
    let world = ExploreWorld {
        chain: &rig.chain,
        model: &rig.model,
        acm: &rig.acm,
        truth: &truth,
    };
    let t0 = Instant::now();
    // well below the whole run's length in a release build, so
    // the deadline, not the end of the candidates, stops it
    let ctl = ExploreControl {
        deadline: Deadline::at(t0 + Duration::from_millis(40)),
        ..ExploreControl::default()
    };
    let out = explore(&world, &scene.start, &p, ctl).unwrap();
    assert_eq!(out.status, ExploreStatus::Timeout);
    // one stage past the deadline at most (a plan is cut by the same deadline)
    assert!(
        t0.elapsed() < Duration::from_millis(40 + 1500),
        "{:?}",
        t0.elapsed()
    );
}

#[test]
fn bad_parameters_are_refused_naming_the_field() {
    let rig = irb();
    let scene = s0_open_cell(1);
    let truth = geometry(scene.obstacles.clone());
    let world = ExploreWorld {
        chain: &rig.chain,
        model: &rig.model,
        acm: &rig.acm,
        truth: &truth,
    };
    let base = quick_params(&scene, 6);
    let field_of =
        |p: &ExploreParams, start: &[f64]| match explore(&world, start, p, ExploreControl::default()) {
            Err(ExploreError::InvalidParam { field, .. }) => Some(field),
            Err(ExploreError::Nbv(_)) => Some(ExploreField::CameraMount),
            _ => None,
        };
    let mut p = base.clone();
    p.camera.hfov = 0.0;
    assert!(matches!(
        explore(&world, &scene.start, &p, ExploreControl::default()),
        Err(ExploreError::Nbv(_))
    ));
    assert_eq!(field_of(&base, &[0.0; 5]), Some(ExploreField::Start));
    assert_eq!(field_of(&base, &[f64::NAN; 6]), Some(ExploreField::Start));
    let mut p = base.clone();
    p.region.1.x = p.region.0.x;
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::Region));
    let mut p = base.clone();
    p.resolution = 0.0;
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::Resolution));
    let mut p = base.clone();
    p.sensor.pixel_stride = 0;
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::PixelStride));
    for v in [-0.1, 1.5, f64::NAN] {
        let mut p = base.clone();
        p.sensor.near_ray_spacing = v;
        assert_eq!(field_of(&p, &scene.start), Some(ExploreField::NearRaySpacing));
    }
    // 2048 x 2048 rays at stride 1 is more than one image may cast
    let mut p = base.clone();
    p.camera.width = 2048;
    p.camera.height = 2048;
    p.sensor.pixel_stride = 1;
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::PixelStride));
    // a 20 m cube at 0.1 m is 8 million cells
    let mut p = base.clone();
    p.resolution = 0.1;
    p.region = (Point3::new(-10.0, -10.0, -10.0), Point3::new(10.0, 10.0, 10.0));
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::Region));
    // a region wholly inside an obstacle has nothing to observe
    let mut p = base.clone();
    p.region = (Point3::new(2.9, -0.1, 0.0), Point3::new(3.0, 0.1, 0.3));
    assert_eq!(field_of(&p, &scene.start), Some(ExploreField::Region));
    // a start in collision with the scene
    let mut blocked = scene.obstacles.clone();
    blocked.push(Obstacle::new(
        "block",
        Isometry3::translation(1.0, 0.0, 1.2),
        Geometry::Sphere { radius: 0.4 },
    ));
    let truth2 = geometry(blocked);
    let world2 = ExploreWorld {
        truth: &truth2,
        ..world
    };
    assert!(matches!(
        explore(&world2, &scene.start, &base, ExploreControl::default()),
        Err(ExploreError::InvalidParam {
            field: ExploreField::Start,
            ..
        })
    ));
}

#[test]
fn with_the_visibility_check_no_executed_view_is_wasted_in_the_walled_cell() {
    // the wall hides the cell from the start: the occlusion-blind gain keeps
    // luring views whose frusta hold unknown cells behind it
    let rig = irb();
    let scene = s0_walled_cell(1);
    let mut p = quick_params(&scene, rig.chain.dof());
    p.stop.max_iterations = 4;
    let check = p.visibility.expect("on by default");
    let mut steps = Vec::new();
    let out = run(&rig, &scene, &p, &mut steps);
    assert_eq!(out.wasted_moves, 0, "{:?}", out.status);
    let mut last = out.initial_known_ratio;
    for s in &steps {
        if let Some(v) = &s.view {
            // an executed view was predicted to reveal enough, and its scan
            // did add known cells (the independent check: the ratio rose)
            assert!(v.predicted_cells.unwrap() as usize >= check.min_new_cells);
            assert!(s.known_ratio > last, "iteration {}", s.iteration);
        }
        assert!(s.failures.iter().all(|(_, f)| *f != ViewFailure::NoGain));
        last = s.known_ratio;
    }
    assert!(
        out.known_ratio > out.initial_known_ratio + 0.2,
        "{}",
        out.known_ratio
    );
    // the same run with S0's occlusion-blind choice does waste moves
    let blind = ExploreParams {
        visibility: None,
        ..p
    };
    let out = run(&rig, &scene, &blind, &mut Vec::new());
    assert!(out.wasted_moves >= 1, "{:?}", out.status);
}

/// The cells of `t` as (key, occupied) pairs, sorted.
fn cells_of(t: &crate::octree::Octree) -> Vec<([u16; 3], bool)> {
    let mut out = Vec::new();
    let lo = Point3::new(-1.0, -3.5, -2.0);
    let hi = Point3::new(5.0, 3.5, 3.0);
    let (a, b) = (t.key_of(&lo).unwrap(), t.key_of(&hi).unwrap());
    for x in a[0]..=b[0] {
        for y in a[1]..=b[1] {
            for z in a[2]..=b[2] {
                match t.state_of_key(&[x, y, z]) {
                    crate::octree::CellState::Unknown => {}
                    s => out.push(([x, y, z], s == crate::octree::CellState::Occupied)),
                }
            }
        }
    }
    out
}

/// A wall (0.2 m thick, 10 m square) across x at `wall_x`, a box (0.4 × 0.5 ×
/// 0.6 m) at `box_at` and a ball of `ball_r` at `ball_at` before it (m).
fn wall_box_ball(wall_x: f64, box_at: [f64; 3], ball_at: [f64; 3], ball_r: f64) -> Arc<SceneGeometry> {
    geometry(vec![
        Obstacle::new(
            "wall",
            Isometry3::translation(wall_x, 0.0, 0.0),
            Geometry::Box {
                half_extents: Vector3::new(0.1, 5.0, 5.0),
            },
        ),
        Obstacle::new(
            "box",
            Isometry3::translation(box_at[0], box_at[1], box_at[2]),
            Geometry::Box {
                half_extents: Vector3::new(0.2, 0.25, 0.3),
            },
        ),
        Obstacle::new(
            "ball",
            Isometry3::translation(ball_at[0], ball_at[1], ball_at[2]),
            Geometry::Sphere { radius: ball_r },
        ),
    ])
}

#[test]
fn a_depth_image_from_the_simulated_camera_inserts_like_its_points() {
    use crate::octree::{Octree, ScanParams, depth_from_millimetres};
    // a wall 3 m ahead, a box and a ball before it
    let world = wall_box_ball(3.1, [1.6, 0.3, -0.2], [2.0, -0.5, 0.3], 0.3);
    let cam = CameraModel {
        width: 96,
        height: 72,
        ..CameraModel::default()
    };
    let pose = look_along(&Point3::new(0.02, 0.03, 0.01), &Vector3::new(1.0, 0.05, -0.1)).unwrap();
    let sensor = SensorParams {
        pixel_stride: 1,
        noise_stddev: 0.0,
        ..SensorParams::default()
    };
    let img = render_depth(&world, &cam, &pose, &sensor, 0);
    assert!(img.returns() > 96 * 72 / 2);
    let o = pose.translation.vector;
    let origin = [o.x as f32, o.y as f32, o.z as f32];
    let p = ScanParams::default();
    // the points path: back-projected along each pixel's unit ray direction
    let mut by_points = Octree::new(0.05).unwrap();
    by_points
        .insert_scan(
            &depth_to_points(&img, &cam, &pose, 1),
            &origin,
            &p,
            Deadline::none(),
        )
        .unwrap();
    // the image path: pinhole intrinsics of the same camera
    let k = cam.intrinsics();
    let mut by_image = Octree::new(0.05).unwrap();
    by_image
        .insert_depth_image(&img.depth, img.width, img.height, &k, &pose, &p, Deadline::none())
        .unwrap();
    let (a, b) = (cells_of(&by_points), cells_of(&by_image));
    assert!(a.len() > 1000, "{}", a.len());
    assert_eq!(a, b);
    // uint16 millimetres: the same as the points of the depths rounded to 1 mm
    let mm: Vec<u8> = img
        .depth
        .iter()
        .flat_map(|z| ((*z as f64 * 1000.0).round() as u16).to_le_bytes())
        .collect();
    let rounded = DepthImage {
        depth: img
            .depth
            .iter()
            .map(|z| ((*z as f64 * 1000.0).round() / 1000.0) as f32)
            .collect(),
        ..img.clone()
    };
    let mut by_mm_points = Octree::new(0.05).unwrap();
    by_mm_points
        .insert_scan(
            &depth_to_points(&rounded, &cam, &pose, 1),
            &origin,
            &p,
            Deadline::none(),
        )
        .unwrap();
    let depth = depth_from_millimetres(&mm, "depth_mm").unwrap();
    let mut by_mm = Octree::new(0.05).unwrap();
    by_mm
        .insert_depth_image(&depth, img.width, img.height, &k, &pose, &p, Deadline::none())
        .unwrap();
    assert_eq!(cells_of(&by_mm_points), cells_of(&by_mm));
    assert!(depth_from_millimetres(&mm[1..], "depth_mm").is_err());
}

#[test]
fn a_strided_image_with_the_shared_near_field_inserts_like_its_points() {
    use crate::octree::{NEAR_RAY_SPACING, Octree, ScanParams};
    // the explore loop's scan: a Kinect v2 image at stride 4, 0.1 m cells; a wall,
    // a box close to the camera and a ball
    let world = wall_box_ball(3.6, [0.9, 0.3, -0.2], [2.2, -0.6, 0.4], 0.35);
    let cam = CameraModel::default();
    let stride = SensorParams::default().pixel_stride;
    let pose = look_along(&Point3::new(0.02, 0.03, 0.01), &Vector3::new(1.0, 0.05, -0.1)).unwrap();
    let sensor = SensorParams::default();
    let img = render_depth(&world, &cam, &pose, &sensor, 0);
    assert_eq!((img.width, img.height), (128, 106));
    let o = pose.translation.vector;
    let origin = [o.x as f32, o.y as f32, o.z as f32];
    // the reference: the points along each cast pixel's unit ray, every beam traced
    let mut by_points = Octree::new(0.1).unwrap();
    by_points
        .insert_scan(
            &depth_to_points(&img, &cam, &pose, stride),
            &origin,
            &ScanParams::default(),
            Deadline::none(),
        )
        .unwrap();
    let k = strided_intrinsics(&cam, stride);
    let image = |spacing: f64| {
        let mut t = Octree::new(0.1).unwrap();
        let p = ScanParams {
            near_ray_spacing: spacing,
            ..ScanParams::default()
        };
        t.insert_depth_image(&img.depth, img.width, img.height, &k, &pose, &p, Deadline::none())
            .unwrap();
        cells_of(&t)
    };
    let reference = cells_of(&by_points);
    assert!(reference.len() > 5000, "{}", reference.len());
    // the strided intrinsics put every pixel on its ray: the same cells
    assert_eq!(image(0.0), reference);
    // the shared near field: at least 99.9 % of the known cells classified the same
    let shared = image(NEAR_RAY_SPACING);
    let a: std::collections::HashMap<[u16; 3], bool> = reference.into_iter().collect();
    let b: std::collections::HashMap<[u16; 3], bool> = shared.into_iter().collect();
    let differ = a.iter().filter(|(k, v)| b.get(*k) != Some(*v)).count()
        + b.keys().filter(|k| !a.contains_key(*k)).count();
    let known = a.len().max(b.len());
    assert!(
        (differ as f64) <= 0.001 * known as f64,
        "{differ} of {known} cells differ"
    );
}
