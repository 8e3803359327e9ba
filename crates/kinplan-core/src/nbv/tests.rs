//! NBV tests against brute force and hand-built trees.

use nalgebra::{Isometry3, Point3, Vector3};

use super::*;
use crate::Deadline;
use crate::octree::{CellState, OcKey, Octree, TREE_DEPTH};

fn hm(t: &Octree) -> (f32, f32) {
    let m = t.sensor_model().log_odds();
    (m.hit, m.miss)
}

/// Free cells in the key box `[lo, hi]`.
fn free_box(t: &mut Octree, lo: OcKey, hi: OcKey) {
    let (_, miss) = hm(t);
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                t.update_key(&[x, y, z], miss);
            }
        }
    }
}

fn small_camera() -> CameraModel {
    CameraModel {
        hfov: 1.0,
        vfov: 0.8,
        near: 0.15,
        far: 1.2,
        width: 40,
        height: 30,
    }
}

#[test]
fn frustum_count_matches_a_brute_force_count() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let mut t = Octree::new(0.1).unwrap();
    let (hit, miss) = hm(&t);
    for _ in 0..6000 {
        let k = [0; 3].map(|_| 32768u16 - 12 + rng.random_range(0..24u16));
        t.update_key(&k, if rng.random_bool(0.2) { hit } else { miss });
    }
    let cam = small_camera();
    for trial in 0..12 {
        let pos = Point3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-0.5..0.5),
        );
        let dir = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let pose = look_along(&pos, &dir).unwrap();
        let f = Frustum::new(&cam, &pose);
        // brute force: every cell of the corners' key box, centre inside and unknown
        let ks: Vec<OcKey> = f.corners.iter().map(|c| t.key_of(c).unwrap()).collect();
        let lo = [0, 1, 2].map(|i| ks.iter().map(|k| k[i]).min().unwrap());
        let hi = [0, 1, 2].map(|i| ks.iter().map(|k| k[i]).max().unwrap());
        let mut n = 0u64;
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let k = [x, y, z];
                    if t.state_of_key(&k) == CellState::Unknown && f.contains(&t.key_center(&k, 16)) {
                        n += 1;
                    }
                }
            }
        }
        assert_eq!(frustum_unknown_count(&t, &f), n, "trial {trial}");
    }
    // empty tree: the count approaches volume / res³
    let e = Octree::new(0.05).unwrap();
    let pose = look_along(&Point3::new(0.01, 0.02, 0.03), &Vector3::new(1.0, 0.2, 0.1)).unwrap();
    let c = frustum_unknown_count(&e, &Frustum::new(&cam, &pose)) as f64;
    let v = cam.frustum_volume() / 0.05f64.powi(3);
    assert!((c / v - 1.0).abs() < 0.05, "{c} vs {v}");
}

#[test]
fn walk_visits_the_cells_along_an_axis_and_rays_stop_at_occupied() {
    let mut t = Octree::new(0.1).unwrap();
    let mut keys = Vec::new();
    walk(
        &t,
        &Point3::new(0.05, 0.05, 0.05),
        &Vector3::x(),
        0.0,
        1.0,
        |k, s, _| {
            assert_eq!(s, CellState::Unknown);
            keys.push(*k);
            true
        },
    );
    // cells 32768 … 32778: the last is entered at t = 0.95 ≤ 1
    assert_eq!(
        keys,
        (32768..=32778u16).map(|x| [x, 32768, 32768]).collect::<Vec<_>>()
    );
    // a wall of occupied cells at x = 32772 stops the rays of a camera looking along +x
    let (hit, _) = hm(&t);
    for y in 32700..32840u16 {
        for z in 32700..32840u16 {
            t.update_key(&[32772, y, z], hit);
        }
    }
    let cam = CameraModel {
        near: 0.01,
        far: 3.0,
        ..small_camera()
    };
    let pose = look_along(&Point3::new(0.05, 0.05, 0.05), &Vector3::x()).unwrap();
    let mut ws = GainWorkspace::default();
    let g = ray_gain(
        &t,
        &cam,
        &pose,
        GainMethod::Rays { fraction: 1.0 },
        &mut ws,
        Deadline::none(),
    );
    let f = frustum_unknown_count(&t, &Frustum::new(&cam, &pose)) as f64;
    // everything in front of the wall (x < 0.4) is unknown: the rays find no more than
    // the frustum holds there, and far fewer than the whole frustum
    let near_part = Frustum::new(&CameraModel { far: 0.35, ..cam }, &pose);
    assert!(g.cells <= frustum_unknown_count(&t, &near_part) as f64 * 1.5 + 50.0);
    assert!(g.cells < f / 4.0 && g.cells > 0.0);
    let g10 = ray_gain(
        &t,
        &cam,
        &pose,
        GainMethod::Rays { fraction: 0.1 },
        &mut ws,
        Deadline::none(),
    );
    assert!(g10.cells <= g.cells && g10.cells > 0.0);
    let u = ray_gain(
        &t,
        &cam,
        &pose,
        GainMethod::UnobservedVoxels { fraction: 1.0 },
        &mut ws,
        Deadline::none(),
    );
    assert!(u.cells >= g.cells);
    let o = ray_gain(
        &t,
        &cam,
        &pose,
        GainMethod::OcclusionAware { fraction: 1.0 },
        &mut ws,
        Deadline::none(),
    );
    // unknown cells have entropy 1 bit and halve the visibility: Σ 2^−i per ray < 2
    assert!(o.cells > 0.0 && o.cells < 2.0 * 1200.0);
}

#[test]
fn frontier_of_a_free_cube_is_its_surface() {
    let mut t = Octree::new(0.1).unwrap();
    free_box(&mut t, [32768; 3], [32771; 3]);
    // the 4³ block is pruned into one depth-14 cube
    assert_eq!(t.search_key(&[32769; 3], 16).map(|(_, d)| d), Some(14));
    let (a, b) = (Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0));
    let f = frontier_cells(&t, &a, &b, 0.25, Deadline::none()).unwrap();
    assert_eq!(f.len(), 64 - 8);
    // edges and corners: 19/26 and 15/26 unknown; faces 9/26 < 0.5
    let f = frontier_cells(&t, &a, &b, 0.5, Deadline::none()).unwrap();
    assert_eq!(f.len(), 8 + 12 * 2);
}

#[test]
fn potential_field_points_into_the_unknown() {
    let mut t = Octree::new(0.1).unwrap();
    // known free slab x < 0, unknown x ≥ 0, symmetric in y and z about the probe cell
    free_box(&mut t, [32758, 32757, 32757], [32767, 32777, 32777]);
    let k = [32767; 3];
    let p = t.key_center(&k, 16);
    assert_eq!(p, Point3::new(-0.05, -0.05, -0.05));
    let f = potential_field(&t, &k, 0.5).unwrap();
    assert!(f.x > 0.0, "{f}");
    assert!(f.y.abs() < 1e-9 * f.x.abs().max(1.0) + 1e-9 && f.z.abs() < 1e-9 + 1e-9 * f.x.abs());
    let pose = candidate_pose(&p, &f, 0.3, 0.5).unwrap();
    // stand-off raised to the near range, camera behind the frontier looking at it
    assert!((pose.translation.vector - Vector3::new(-0.55, -0.05, -0.05)).norm() < 1e-9);
    assert!((pose.rotation * Vector3::z() - Vector3::x()).norm() < 1e-9);
}

#[test]
fn next_best_view_ranks_filters_and_checks_reach() {
    let mut t = Octree::new(0.1).unwrap();
    free_box(&mut t, [32758, 32758, 32768], [32782, 32778, 32782]);
    let chain = crate::robot::builtin_chain("abb_irb4600_60_205").unwrap();
    let cam = CameraModel {
        width: 64,
        height: 48,
        ..CameraModel::default()
    };
    let current = look_along(&Point3::new(1.0, 0.0, 1.0), &Vector3::x()).unwrap();
    let params = NbvParams {
        extra_candidates: vec![
            look_along(&Point3::new(1.2, 0.3, 1.1), &Vector3::new(1.0, 0.0, -0.3)).unwrap(),
        ],
        ik_check: 4,
        max_results: 8,
        ..NbvParams::default()
    };
    let r = next_best_view(&t, &params, &cam, &current, Some(&chain), Deadline::none()).unwrap();
    assert_eq!(r.status, NbvStatus::Complete);
    let s = r.stages;
    assert!(s.frontier_cells > 0 && s.frontier_candidates > 0 && s.caller_candidates == 1);
    assert!(
        s.after_orf <= s.frontier_candidates + 1 && s.after_ptf <= s.after_orf && s.after_igf <= s.after_ptf
    );
    assert!(!r.candidates.is_empty());
    let w = Weights::default();
    for (i, c) in r.candidates.iter().enumerate() {
        // utility recomputed from its terms, and each term from the poses
        let f = w.w_d * c.distance_term + w.w_r * c.rotation_term + w.w_i * c.ig;
        assert!((c.utility - f).abs() < 1e-12);
        let dr = current.rotation.angle_to(&c.pose.rotation);
        assert!((c.rotation_term - (1.0 - dr / std::f64::consts::PI)).abs() < 1e-12);
        assert!(c.ig >= params.gain_threshold);
        assert!((c.pose.translation.vector).norm() <= r.reach.unwrap() + 1e-9);
        if i > 0 {
            assert!(r.candidates[i - 1].utility >= c.utility);
        }
        if let Some(q) = &c.joints {
            let tip = chain.fk(q);
            assert!((tip.translation.vector - c.pose.translation.vector).norm() < 1e-4);
        }
        // PTF: no two results are close in both position and direction
        for d in &r.candidates[..i] {
            let close =
                (d.pose.translation.vector - c.pose.translation.vector).norm() < params.position_threshold;
            let aligned = (d.pose.rotation * Vector3::z()).angle(&(c.pose.rotation * Vector3::z()))
                < params.orientation_threshold;
            assert!(!(close && aligned));
        }
    }
    assert!(s.ik_checked > 0);
    // cancellation is a status, not an error
    let r = next_best_view(
        &t,
        &params,
        &cam,
        &current,
        Some(&chain),
        Deadline::none().with_cancel(&|| true),
    )
    .unwrap();
    assert_eq!(r.status, NbvStatus::Cancelled);
    // bad parameters are errors
    let bad = NbvParams {
        gain: GainMethod::Rays { fraction: 0.0 },
        ..NbvParams::default()
    };
    assert!(next_best_view(&t, &bad, &cam, &current, None, Deadline::none()).is_err());
    // a visibility check whose ray table would outgrow its bound is refused by name:
    // 2048 × 1024 pixels at stride 1 are 2^21 rays, at stride 2 exactly 2^20
    let wide = CameraModel {
        width: 2048,
        height: 1024,
        ..CameraModel::default()
    };
    let with_stride = |pixel_stride| NbvParams {
        visibility: Some(VisibilityParams {
            pixel_stride,
            ..VisibilityParams::default()
        }),
        ..NbvParams::default()
    };
    let err = next_best_view(&t, &with_stride(1), &wide, &current, None, Deadline::none()).unwrap_err();
    assert!(err.to_string().contains("visibility.pixel_stride"), "{err}");
    assert!(with_stride(2).visibility.unwrap().validate_for(&wide).is_ok());
}

/// The reachability IK runs under the request's deadline: an IK that can never
/// converge (one iteration per attempt, endless restarts, no budget of its own) is cut
/// there, the request ends TIME_BUDGET, and the candidate keeps an unknown reachability
/// (not a failure).
#[test]
fn an_ik_cut_by_the_deadline_leaves_reachability_unknown() {
    let mut t = Octree::new(0.1).unwrap();
    free_box(&mut t, [32758, 32758, 32768], [32782, 32778, 32782]);
    let chain = crate::robot::builtin_chain("abb_irb4600_60_205").unwrap();
    let cam = CameraModel {
        width: 64,
        height: 48,
        ..CameraModel::default()
    };
    let current = look_along(&Point3::new(1.0, 0.0, 1.0), &Vector3::x()).unwrap();
    let mut params = NbvParams {
        extra_candidates: vec![
            look_along(&Point3::new(1.2, 0.3, 1.1), &Vector3::new(1.0, 0.0, -0.3)).unwrap(),
        ],
        ik_check: 4,
        max_results: 8,
        count_failures: true,
        ..NbvParams::default()
    };
    params.ik.max_iterations = 1;
    params.ik.max_restarts = usize::MAX;
    params.ik.time_budget = None;
    let start = std::time::Instant::now();
    // long enough for the stages before the IK in a debug build on a loaded machine
    let deadline = Deadline::after(std::time::Duration::from_millis(1500));
    let r = next_best_view(&t, &params, &cam, &current, Some(&chain), deadline).unwrap();
    let took = start.elapsed();
    assert_eq!(r.status, NbvStatus::TimeBudget);
    assert!(took < std::time::Duration::from_secs(5), "{took:?}");
    assert_eq!(r.stages.ik_checked, 1, "the first IK runs and is cut");
    assert_eq!(r.stages.ik_failed, 0);
    assert!(!r.candidates.is_empty());
    assert!(
        r.candidates
            .iter()
            .all(|c| c.reachable.is_none() && c.failures == 0)
    );
}

#[test]
fn huge_free_cubes_from_a_hostile_tree_stop_at_the_deadline() {
    use crate::octree::OctreeLimits;
    // two node bytes: the root's eight children are free leaves, each 32768 cells wide
    let t = Octree::from_message_data(true, "OcTree", 0.1, &[0x55, 0x55], &OctreeLimits::default()).unwrap();
    assert_eq!(t.num_nodes(), 9);
    let cam = small_camera();
    let current = look_along(&Point3::new(0.0, 0.0, 1.0), &Vector3::x()).unwrap();
    let params = NbvParams {
        time_budget: Some(std::time::Duration::from_millis(50)),
        ..NbvParams::default()
    };
    let start = std::time::Instant::now();
    let r = next_best_view(&t, &params, &cam, &current, None, Deadline::none()).unwrap();
    assert_eq!(r.status, NbvStatus::TimeBudget);
    assert!(
        start.elapsed() < std::time::Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    // a small region clips the scan: done at once, and no frontier (nothing unknown)
    let f = frontier_cells(
        &t,
        &Point3::new(-1.0, -1.0, -1.0),
        &Point3::new(1.0, 1.0, 1.0),
        0.25,
        Deadline::none(),
    )
    .unwrap();
    assert!(f.is_empty());
}

/// One ray along +x from the centre of cell 32768: cells 32768..=32777 are known
/// free (x < 1 m), the rest unknown unless set.
fn corridor() -> (Octree, CameraModel, Isometry3<f64>) {
    let mut t = Octree::new(0.1).unwrap();
    free_box(&mut t, [32768, 32766, 32766], [32777, 32770, 32770]);
    let cam = CameraModel {
        width: 1,
        height: 1,
        ..CameraModel::default()
    };
    let pose = look_along(&Point3::new(0.05, 0.05, 0.05), &Vector3::x()).unwrap();
    (t, cam, pose)
}

#[test]
fn predicted_cells_stop_at_occupied_cells_and_count_the_first_unknown_one_as_certain() {
    let vp = VisibilityParams {
        pixel_stride: 1,
        lookahead: 3,
        ..VisibilityParams::default()
    };
    let mut ws = PredictWorkspace::default();
    let (t, cam, pose) = corridor();
    // the ray leaves the free corridor at x = 1 m: cell 32778 is its first unknown
    // cell, 32779 and 32780 follow within the look-ahead of 3
    let p = predict_view(&t, &cam, &pose, &vp, None, &mut ws, Deadline::none());
    assert_eq!((p.first, p.reached, p.rays), (1, 3, 1));
    // a region starting at cell 32779: the unknown cell 32778 outside it is passed
    // as open, so 32779 is the first unknown region cell, 32780 and 32781 follow
    let region = Some(([32779, 0, 0], [65535, 65535, 65535]));
    let p = predict_view(&t, &cam, &pose, &vp, region, &mut ws, Deadline::none());
    assert_eq!((p.first, p.reached), (1, 3));
    // an occupied cell at 32778 hides everything behind it
    let mut t2 = t.clone();
    let (hit, _) = hm(&t2);
    t2.update_key(&[32778, 32768, 32768], hit);
    let p = predict_view(&t2, &cam, &pose, &vp, None, &mut ws, Deadline::none());
    assert_eq!((p.first, p.reached), (0, 0));
    // an occupied cell at 32780 leaves the two before it
    let mut t3 = t;
    t3.update_key(&[32780, 32768, 32768], hit);
    let p = predict_view(&t3, &cam, &pose, &vp, None, &mut ws, Deadline::none());
    assert_eq!((p.first, p.reached), (1, 2));
    // the same hand counts reading the states from a byte grid that covers the ray up
    // to cell 32779 (the tree beyond it)
    let on_grid = |t: &Octree| {
        let g = grid::StateGrid::new(t, [32760, 32760, 32760], [32779, 32775, 32775], 1 << 20).unwrap();
        let mut ws = PredictWorkspace::default();
        let p = visibility::predict_view_in(t, Some(&g), &cam, &pose, &vp, None, &mut ws, Deadline::none());
        (p.first, p.reached)
    };
    let (t, _, _) = corridor();
    assert_eq!(on_grid(&t), (1, 3));
    assert_eq!(on_grid(&t2), (0, 0));
    assert_eq!(on_grid(&t3), (1, 2));
}

#[test]
fn a_view_behind_a_wall_is_dropped_by_the_visibility_check() {
    // known free space x ∈ [0, 1.2) m, y, z ∈ [−1, 1) m; an occupied wall at
    // x ∈ [1.2, 1.3) covering y < 0; the region x ∈ [1.2, 2.5] beyond is unknown
    let mut t = Octree::new(0.1).unwrap();
    free_box(&mut t, [32768, 32758, 32758], [32779, 32777, 32777]);
    let (hit, _) = hm(&t);
    for y in 32758..=32767 {
        for z in 32758..=32777 {
            t.update_key(&[32780, y, z], hit);
        }
    }
    let cam = CameraModel {
        hfov: 20f64.to_radians(),
        vfov: 20f64.to_radians(),
        width: 64,
        height: 64,
        ..CameraModel::default()
    };
    // A looks at the wall (its frustum beyond the wall is full of unknown region
    // cells); B looks past it
    let a = look_along(&Point3::new(0.55, -0.5, 0.05), &Vector3::x()).unwrap();
    let b = look_along(&Point3::new(0.55, 0.5, 0.05), &Vector3::x()).unwrap();
    let blind = NbvParams {
        region: Some((Point3::new(1.2, -1.0, -1.0), Point3::new(2.5, 1.0, 1.0))),
        max_frontier_candidates: 0,
        extra_candidates: vec![a, b],
        gain_in_region: true,
        ik_check: 0,
        max_results: 5,
        ..NbvParams::default()
    };
    let current = look_along(&Point3::new(0.5, 0.0, 0.05), &Vector3::x()).unwrap();
    let r = next_best_view(&t, &blind, &cam, &current, None, Deadline::none()).unwrap();
    // the occlusion-blind gain keeps both, A with about as much gain as B
    assert_eq!(r.candidates.len(), 2);
    let ig_a = r.candidates.iter().find(|c| c.pose == a).unwrap().ig;
    let ig_b = r.candidates.iter().find(|c| c.pose == b).unwrap().ig;
    assert!(ig_a > 0.5 * ig_b, "{ig_a} {ig_b}");
    let checked = NbvParams {
        visibility: Some(VisibilityParams::default()),
        ..blind
    };
    let r = next_best_view(&t, &checked, &cam, &current, None, Deadline::none()).unwrap();
    assert_eq!(r.candidates.len(), 1);
    let c = &r.candidates[0];
    assert_eq!(c.pose, b);
    assert_eq!((r.stages.visibility_checked, r.stages.visibility_dropped), (2, 1));
    // B's rays (pixels 0, 8, …, 56 of 0..=63 per axis: 8 × 8 rays) enter the
    // region at x = 1.2 m, 0.65 m ahead; per axis they span from one field-of-view
    // edge, 0.65·tan 10° = 0.115 m off the axis, to 0.115·(2·56/63 − 1) = 0.089 m
    // off it on the other side: image right is −y, so y ∈ [0.411, 0.615] (3 cells),
    // image down is −z, so z ∈ [−0.039, 0.165] (3 cells)
    let p = c.predicted.unwrap();
    assert_eq!(p.rays, 64);
    assert_eq!(p.first, 9, "{p:?}");
    assert!(p.reached >= p.first);
    assert!((c.ig - 1.0).abs() < 1e-12);
}

#[test]
fn the_grid_prediction_counts_what_the_tree_walk_counts() {
    use rand::{Rng, SeedableRng};
    let vp = VisibilityParams {
        pixel_stride: 1,
        lookahead: 3,
        ..VisibilityParams::default()
    };
    // hand count: the corridor's ray inside a region that ends with the grid at cell
    // 32779: the unknown cells 32778 and 32779 are reached, 32778 first
    let (t, cam, pose) = corridor();
    let region = ([32770, 32760, 32760], [32779, 32775, 32775]);
    let g = grid::StateGrid::new(&t, [32760, 32760, 32760], [32779, 32775, 32775], 1 << 20).unwrap();
    let mut ws = PredictWorkspace::default();
    let p = visibility::predict_view_in(
        &t,
        Some(&g),
        &cam,
        &pose,
        &vp,
        Some(region),
        &mut ws,
        Deadline::none(),
    );
    assert_eq!((p.first, p.reached), (1, 2));

    // random boxes of free and occupied cells; views inside, at the edge of and
    // outside the grid: the grid path against the tree walk, view by view
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(27);
    let mut t = Octree::new(0.1).unwrap();
    let (hit, miss) = hm(&t);
    free_box(&mut t, [32758, 32758, 32762], [32778, 32778, 32774]);
    for _ in 0..60 {
        let c: [u16; 3] = [0, 1, 2].map(|_| rng.random_range(32752..32784));
        let h: [u16; 3] = [0, 1, 2].map(|_| rng.random_range(0..3));
        let v = if rng.random_bool(0.5) { hit } else { miss };
        for x in c[0]..=c[0] + h[0] {
            for y in c[1]..=c[1] + h[1] {
                for z in c[2]..=c[2] + h[2] {
                    t.update_key(&[x, y, z], v);
                }
            }
        }
    }
    let cam = small_camera();
    let region: (OcKey, OcKey) = ([32754, 32756, 32758], [32782, 32780, 32778]);
    let g = grid::StateGrid::new(&t, [32750, 32752, 32756], [32786, 32784, 32780], 1 << 20).unwrap();
    let mut ws = PredictWorkspace::default();
    let mut counted = 0;
    for i in 0..40 {
        let at = match i % 3 {
            0 => Point3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-0.5..0.5),
            ),
            1 => Point3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-2.0..2.0),
            ),
            _ => Point3::new(3.2, rng.random_range(-0.5..0.5), 0.05),
        };
        let aim = Point3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), 0.0) - at;
        let Some(pose) = look_along(&at, &aim) else {
            continue;
        };
        let on_tree = predict_view(&t, &cam, &pose, &vp, Some(region), &mut ws, Deadline::none());
        let on_grid = visibility::predict_view_in(
            &t,
            Some(&g),
            &cam,
            &pose,
            &vp,
            Some(region),
            &mut ws,
            Deadline::none(),
        );
        assert_eq!(
            (on_grid.first, on_grid.reached, on_grid.rays),
            (on_tree.first, on_tree.reached, on_tree.rays),
            "view {i}"
        );
        assert!(on_grid.steps <= on_tree.steps);
        counted += (on_tree.reached > 0) as usize;
    }
    assert!(counted >= 10, "too few views see unknown cells: {counted}");
}

#[test]
fn four_field_lanes_are_the_per_cell_sums_bit_for_bit() {
    use rand::{Rng, SeedableRng};
    // random free and occupied boxes; the ball of 0.25 m at 0.05 m (reach 6 cells)
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(91);
    let mut t = Octree::new(0.05).unwrap();
    let (hit, miss) = hm(&t);
    for _ in 0..40 {
        let c: [u16; 3] = [0, 1, 2].map(|_| rng.random_range(32750..32786));
        let h: [u16; 3] = [0, 1, 2].map(|_| rng.random_range(0..4));
        let v = if rng.random_bool(0.3) { hit } else { miss };
        for x in c[0]..=c[0] + h[0] {
            for y in c[1]..=c[1] + h[1] {
                for z in c[2]..=c[2] + h[2] {
                    t.update_key(&[x, y, z], v);
                }
            }
        }
    }
    let ball = grid::Ball::new(0.05, 0.25).unwrap();
    let g = grid::StateGrid::new(&t, [32740; 3], [32795; 3], 1 << 20).unwrap();
    let steps = ball.index_steps(&g);
    let mut checked = 0;
    for _ in 0..10 {
        let keys: [OcKey; grid::FIELD_LANES] =
            std::array::from_fn(|_| [0, 1, 2].map(|_| rng.random_range(32746..32790)));
        let got = g.fields(&keys, &ball, &steps);
        for (k, f) in keys.iter().zip(&got) {
            // the same terms in the ball's order, each cell's state from the tree:
            // unknown attracts (+), free and occupied repel (−)
            let mut want = [0.0f64; 3];
            for (o, v) in ball.offsets.iter().zip(&ball.terms) {
                let key = [0, 1, 2].map(|i| (k[i] as i32 + o[i]) as u16);
                let s = match t.search_key(&key, TREE_DEPTH) {
                    None => 1.0,
                    Some(_) => -1.0,
                };
                for i in 0..3 {
                    want[i] += s * v[i];
                }
            }
            assert_eq!(
                [f.x, f.y, f.z].map(f64::to_bits),
                want.map(f64::to_bits),
                "cell {k:?}"
            );
            assert_eq!(*f, g.field(k, &ball));
            checked += (f.norm() > 1.0) as usize;
        }
    }
    // most cells see a mix of known and unknown space: the fields are not trivial
    assert!(checked >= 8, "{checked}");
}

#[test]
fn grid_walks_ending_at_the_key_space_edge_count_like_the_tree_walk() {
    use rand::{Rng, SeedableRng};
    // free cells next to key 0 on every axis, the two layers of keys 0 and 1
    // unknown; the grid reaches two cells past the key space (outside cells), so rays
    // looking towards the corner end there, inside the grid, some after unknown region
    // cells: the grid walk and the tree walk take the very same steps
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut t = Octree::new(0.1).unwrap();
    let (hit, miss) = hm(&t);
    free_box(&mut t, [2, 2, 2], [9, 9, 9]);
    for _ in 0..25 {
        let k: OcKey = [0, 1, 2].map(|_| rng.random_range(0..12));
        t.update_key(&k, if rng.random_bool(0.4) { hit } else { miss });
    }
    let vp = VisibilityParams {
        pixel_stride: 1,
        ..VisibilityParams::default()
    };
    let cam = small_camera();
    let region: (OcKey, OcKey) = ([0, 0, 0], [15, 15, 15]);
    let g = grid::StateGrid::new(&t, [-2, -2, -2], [18, 18, 18], 1 << 20).unwrap();
    let mut ws = PredictWorkspace::default();
    let centre = |k: [f64; 3]| Point3::from(k.map(|v| (v - 32768.0 + 0.5) * 0.1));
    let (mut edge_rays, mut seeing) = (0, 0);
    for i in 0..12 {
        let at = centre([0, 1, 2].map(|_| rng.random_range(3..8) as f64));
        // towards the corner (key 0), along axes and diagonals
        let aim = match i % 3 {
            0 => Vector3::new(-1.0, -1.0, -1.0),
            1 => Vector3::new(-1.0, rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3)),
            _ => Vector3::new(rng.random_range(-1.0..0.0), -1.0, rng.random_range(-1.0..0.0)),
        };
        let pose = look_along(&at, &aim).unwrap();
        let on_tree = predict_view(&t, &cam, &pose, &vp, Some(region), &mut ws, Deadline::none());
        let on_grid = visibility::predict_view_in(
            &t,
            Some(&g),
            &cam,
            &pose,
            &vp,
            Some(region),
            &mut ws,
            Deadline::none(),
        );
        assert_eq!(on_grid, on_tree, "view {i}");
        // the same walks on a state grid one layer wider, recoded in place
        let wide = grid::StateGrid::new(&t, [-3, -3, -3], [19, 19, 19], 1 << 20).unwrap();
        let vg = visibility::ViewGrid::from_padded(wide, region, &cam, 1).unwrap();
        let in_place = visibility::predict_on_grid(&t, &vg, &cam, &pose, &vp, &mut ws, Deadline::none());
        assert_eq!(in_place, on_tree, "view {i}");
        edge_rays += (on_tree.steps > 0) as usize;
        seeing += (on_tree.reached > 0) as usize;
    }
    assert_eq!(edge_rays, 12);
    assert!(seeing >= 6, "{seeing}");
    // a state grid whose inner box does not hold the region is given back
    let small = grid::StateGrid::new(&t, [-1, -1, -1], [10, 10, 10], 1 << 20).unwrap();
    assert!(visibility::ViewGrid::from_padded(small, region, &cam, 1).is_err());
}

#[test]
fn a_state_grid_filled_in_two_slabs_holds_every_cell_state() {
    use rand::{Rng, SeedableRng};
    // over 2^16 cells: filled by two walks side by side (a z slab each); every cell
    // against a lookup of its own, including cells past the key space
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(44);
    let mut t = Octree::new(0.1).unwrap();
    let (hit, miss) = hm(&t);
    free_box(&mut t, [0, 0, 0], [7, 7, 7]);
    free_box(&mut t, [32760, 32760, 32760], [32775, 32775, 32775]);
    for _ in 0..400 {
        let k: OcKey = [0, 1, 2].map(|_| rng.random_range(32744..32792));
        t.update_key(&k, if rng.random_bool(0.5) { hit } else { miss });
    }
    for (lo, hi) in [
        ([32740, 32742, 32738], [32795, 32790, 32779]),
        ([-3, -2, -4], [40, 40, 37]),
    ] {
        let g = grid::StateGrid::new(&t, lo, hi, 1 << 20).unwrap();
        assert!(g.cells.len() > 1 << 16);
        let mut seen = [0usize; 4];
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let k = [x, y, z];
                    let want = if k.iter().any(|v| !(0..65536).contains(v)) {
                        grid::OUTSIDE
                    } else {
                        match t.state_of_key(&k.map(|v| v as u16)) {
                            CellState::Unknown => grid::UNKNOWN,
                            CellState::Free => grid::FREE,
                            CellState::Occupied => grid::OCCUPIED,
                        }
                    };
                    let got = g.cells[g.index([x - lo[0], y - lo[1], z - lo[2]])];
                    assert_eq!(got, want, "{k:?}");
                    seen[got as usize] += 1;
                }
            }
        }
        // known cells in the grid (the first grid has them in both slabs)
        assert!(seen[grid::FREE as usize] > 0, "{seen:?}");
    }
}
