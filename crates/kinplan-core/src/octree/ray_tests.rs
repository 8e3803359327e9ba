//! Ray casting and scan integration against independent computations: a slab-test
//! brute force over cells, a brute-force walk, and hand-worked inserts.

use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::Deadline;

/// Parameter interval `[t0, t1]` of the segment `o + t·(e − o)`, t ∈ [0, 1], inside
/// the depth-16 cell `k` (slab test in f64), or None.
fn slab(t: &Octree, k: &OcKey, o: &[f64; 3], e: &[f64; 3]) -> Option<(f64, f64)> {
    let r = t.resolution();
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..3 {
        let lo = (k[i] as f64 - 32768.0) * r;
        let hi = lo + r;
        let d = e[i] - o[i];
        if d == 0.0 {
            if o[i] < lo || o[i] >= hi {
                return None;
            }
        } else {
            let (a, b) = ((lo - o[i]) / d, (hi - o[i]) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t1 >= t0).then_some((t0, t1))
}

/// Cells the segment passes through for a length of at least `tol` (fraction of the
/// segment), in order of entry, found by testing every cell of its bounding box.
fn brute_cells(t: &Octree, o: &[f64; 3], e: &[f64; 3], tol: f64) -> Vec<(f64, OcKey)> {
    let ko = t.key_of(&Point3::from(*o)).unwrap();
    let ke = t.key_of(&Point3::from(*e)).unwrap();
    let mut out = Vec::new();
    for x in ko[0].min(ke[0])..=ko[0].max(ke[0]) {
        for y in ko[1].min(ke[1])..=ko[1].max(ke[1]) {
            for z in ko[2].min(ke[2])..=ko[2].max(ke[2]) {
                if let Some((a, b)) = slab(t, &[x, y, z], o, e)
                    && b - a >= tol
                {
                    out.push((a, [x, y, z]));
                }
            }
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn f32p(p: [f64; 3]) -> [f32; 3] {
    p.map(|v| v as f32)
}

#[test]
fn ray_keys_match_the_cells_a_segment_crosses() {
    let t = Octree::new(0.1).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut ray = Vec::new();
    for _ in 0..300 {
        let o = f32p([0; 3].map(|_| rng.random_range(-1.0..1.0)));
        let e = f32p([0; 3].map(|_| rng.random_range(-1.0..1.0)));
        let (od, ed) = (o.map(|v| v as f64), e.map(|v| v as f64));
        assert!(t.compute_ray_keys(&o, &e, &mut ray));
        let ke = t.key_of(&Point3::from(ed)).unwrap();
        // every cell crossed for a non-negligible length, except the end cell, is listed
        for (_, k) in brute_cells(&t, &od, &ed, 1e-6) {
            if k != ke {
                assert!(ray.contains(&k), "missing {k:?}");
            }
        }
        // and nothing listed is off the segment
        let loose = brute_cells(&t, &od, &ed, -1e-6);
        for k in &ray {
            assert!(loose.iter().any(|(_, c)| c == k), "extra {k:?}");
            assert_ne!(*k, ke);
        }
        // consecutive cells are face neighbours
        for w in ray.windows(2) {
            let d: u32 = (0..3)
                .map(|i| (w[0][i] as i32 - w[1][i] as i32).unsigned_abs())
                .sum();
            assert_eq!(d, 1);
        }
    }
    // same cell: empty; outside the cube: false
    assert!(t.compute_ray_keys(&[0.01, 0.01, 0.01], &[0.02, 0.02, 0.02], &mut ray) && ray.is_empty());
    assert!(!t.compute_ray_keys(&[0.0, 0.0, 0.0], &[1e6, 0.0, 0.0], &mut ray));
}

#[test]
fn cast_ray_stops_where_a_brute_force_walk_stops() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut t = Octree::new(0.1).unwrap();
    let (h, m) = (t.sensor_model().log_odds().hit, t.sensor_model().log_odds().miss);
    // known space: a free cube of 30³ cells with random occupied cells, unknown outside
    for x in 32753..32783u16 {
        for y in 32753..32783u16 {
            for z in 32753..32783u16 {
                let occ = rng.random_bool(0.01);
                t.update_key(&[x, y, z], if occ { h } else { m });
            }
        }
    }
    for trial in 0..200 {
        let o = f32p([0; 3].map(|_| rng.random_range(-1.0..1.0)));
        let d = f32p([0; 3].map(|_| rng.random_range(-1.0..1.0)));
        let params = RayParams {
            ignore_unknown: trial % 2 == 1,
            max_range: if trial % 3 == 0 { 0.7 } else { -1.0 },
        };
        let od = o.map(|v| v as f64);
        let dn = Vector3::from(d.map(|v| v as f64)).normalize();
        let r = t.cast_ray(&Point3::from(od), &dn, &params).unwrap();
        // brute force: cells crossed by the segment to 3 m, in order
        let e = [0, 1, 2].map(|i| od[i] + 3.0 * dn[i]);
        let mut expect = None;
        for (_, k) in brute_cells(&t, &od, &e, 1e-7) {
            let c = t.key_center(&k, 16);
            if params.max_range > 0.0 && (c - Point3::from(od)).norm() > params.max_range + 1e-6 {
                expect = Some((k, RayStop::MaxRange));
                break;
            }
            match t.state_of_key(&k) {
                CellState::Occupied => {
                    expect = Some((k, RayStop::Occupied));
                    break;
                }
                CellState::Unknown if !params.ignore_unknown => {
                    expect = Some((k, RayStop::Unknown));
                    break;
                }
                _ => {}
            }
        }
        if let Some((k, stop)) = expect {
            assert_eq!((r.key, r.stop), (k, stop), "trial {trial}");
            assert_eq!(r.hit, stop == RayStop::Occupied);
        } else {
            assert!(r.stop == RayStop::MaxRange || r.stop == RayStop::Bounds || r.steps > 25);
        }
    }
    // a zero direction is refused unless the origin cell itself is the hit
    let zero = t.cast_ray(
        &Point3::new(0.05, 0.05, 0.05),
        &Vector3::zeros(),
        &RayParams::default(),
    );
    match t.state_of_key(&[32768; 3]) {
        CellState::Occupied => assert!(zero.unwrap().hit),
        _ => assert!(zero.is_err()),
    }
}

#[test]
fn insert_of_a_tiny_scan_by_hand() {
    let mut t = Octree::new(0.1).unwrap();
    let lo = t.sensor_model().log_odds();
    // beams along +x from the centre of cell 32768: to x = 0.45 (cell 32772) twice,
    // and to x = 0.25 (cell 32770), whose cell the first beam also crosses
    let pts = [[0.45f32, 0.05, 0.05], [0.44, 0.05, 0.05], [0.25, 0.05, 0.05]];
    let s = t
        .insert_scan(
            &pts,
            &[0.05, 0.05, 0.05],
            &ScanParams::default(),
            Deadline::none(),
        )
        .unwrap();
    assert_eq!(s.status, ScanStatus::Inserted);
    assert_eq!((s.free_cells, s.occupied_cells), (3, 2));
    let v = |x: u16| t.search_key(&[x, 32768, 32768], 16).map(|(v, _)| v);
    assert_eq!(v(32768), Some(lo.miss));
    assert_eq!(v(32769), Some(lo.miss));
    assert_eq!(v(32770), Some(lo.hit)); // occupied wins, one update only
    assert_eq!(v(32771), Some(lo.miss));
    assert_eq!(v(32772), Some(lo.hit)); // two end points, one update
    assert_eq!(v(32773), None);
    // max range 0.2 m: the beam is cut at x = 0.25, no end point
    let mut t2 = Octree::new(0.1).unwrap();
    let p = ScanParams {
        max_range: 0.2,
        ..ScanParams::default()
    };
    let s = t2
        .insert_scan(&pts[..1], &[0.05, 0.05, 0.05], &p, Deadline::none())
        .unwrap();
    assert_eq!((s.free_cells, s.occupied_cells), (2, 0));
    // max range 0 is no limit, as a negative one (the documented contract):
    // the same tree as the default
    let (mut unlimited, mut zero) = (Octree::new(0.1).unwrap(), Octree::new(0.1).unwrap());
    let origin = [0.05, 0.05, 0.05];
    unlimited
        .insert_scan(&pts, &origin, &ScanParams::default(), Deadline::none())
        .unwrap();
    let p = ScanParams {
        max_range: 0.0,
        ..ScanParams::default()
    };
    let s = zero.insert_scan(&pts, &origin, &p, Deadline::none()).unwrap();
    assert!(s.occupied_cells > 0);
    assert_eq!(zero.write_ot(), unlimited.write_ot());
    // cancellation leaves the tree unchanged
    let before = t.write_ot();
    let s = t
        .insert_scan(
            &pts,
            &[0.05, 0.05, 0.05],
            &ScanParams::default(),
            Deadline::none().with_cancel(&|| true),
        )
        .unwrap();
    assert_eq!(s.status, ScanStatus::Cancelled);
    assert_eq!(t.write_ot(), before);
    assert!(
        t.insert_scan(
            &pts,
            &[f32::NAN, 0.0, 0.0],
            &ScanParams::default(),
            Deadline::none()
        )
        .is_err()
    );
}

#[test]
fn depth_pixels_back_project_by_hand() {
    let k = PinholeIntrinsics {
        fx: 2.0,
        fy: 4.0,
        cx: 1.0,
        cy: 0.0,
    };
    let pose = Isometry3::translation(1.0, 0.0, 0.0);
    // 2×1 image: pixel (0,0) depth 2 → ((0−1)·2/2, 0, 2) = (−1, 0, 2) + (1,0,0); pixel (1,0) no return
    let p = depth_image_points(&[2.0, 0.0], 2, 1, &k, &pose).unwrap();
    assert_eq!(p, vec![[0.0, 0.0, 2.0]]);
    assert!(depth_image_points(&[2.0], 2, 1, &k, &pose).is_err());
}

/// Scans recorded by `benches/octomap/make_fixture.py`: `(origin, max_range, points)`.
fn fixture_scans() -> Vec<([f32; 3], f64, Vec<[f32; 3]>)> {
    let b: &[u8] = include_bytes!("fixtures/scans.bin");
    let f = |i: usize| f32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    let u = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
    let mut pos = 4;
    let mut out = Vec::new();
    for _ in 0..u(0) {
        let origin = [f(pos), f(pos + 4), f(pos + 8)];
        let max_range = f(pos + 12) as f64;
        let n = u(pos + 16);
        pos += 20;
        let pts = (0..n)
            .map(|i| [f(pos + 12 * i), f(pos + 12 * i + 4), f(pos + 12 * i + 8)])
            .collect();
        pos += 12 * n;
        out.push((origin, max_range, pts));
    }
    assert_eq!(pos, b.len());
    out
}

#[test]
fn insert_scan_gives_octomaps_tree_byte_for_byte() {
    // OctoMap 1.10 insertPointCloud on the same three scans, written as .ot (full
    // log-odds of every node): our tree must serialise to the same bytes
    let expected: &[u8] = include_bytes!("fixtures/scans_octomap.ot");
    let mut t = Octree::new(0.1).unwrap();
    for (origin, max_range, pts) in fixture_scans() {
        let p = ScanParams {
            max_range,
            ..ScanParams::default()
        };
        let s = t.insert_scan(&pts, &origin, &p, Deadline::none()).unwrap();
        assert_eq!(s.status, ScanStatus::Inserted);
    }
    let ours = t.write_ot();
    // the sorted-vector path (no dense grid) builds the same tree
    let mut t2 = Octree::new(0.1).unwrap();
    for (origin, max_range, pts) in fixture_scans() {
        let p = ScanParams {
            max_range,
            dense_limit_cells: 0,
            ..ScanParams::default()
        };
        t2.insert_scan(&pts, &origin, &p, Deadline::none()).unwrap();
    }
    assert!(t2.write_ot() == expected, "sorted path differs from OctoMap's");
    assert_eq!(ours.len(), expected.len());
    assert!(ours == expected, "tree differs from OctoMap's");
    // and OctoMap's file reads back into the same tree
    let theirs = Octree::read_ot(expected, &OctreeLimits::default()).unwrap();
    assert_eq!(theirs.write_bt(), t.write_bt());
}

/// `n` points on a sphere of radius `r` (m) about the origin, by a golden-angle spiral.
fn sphere_points(n: usize, r: f32) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let rho = (1.0 - z * z).sqrt();
            let phi = i as f32 * 2.399_963;
            [r * rho * phi.cos(), r * rho * phi.sin(), r * z]
        })
        .collect()
}

/// Regression: 300 points on a 300 m sphere at 1 cm (a 3.6 KB request) grew the
/// tree to 27 million nodes before the node limit was looked at. The distinct
/// cells are now counted as the beams are traced, batch by batch, and the scan is
/// refused once they pass the limit — with the tree unchanged.
#[test]
fn a_scan_with_more_cells_than_the_node_limit_is_refused_while_traced() {
    let mut t = Octree::new(0.01).unwrap();
    let p = ScanParams {
        max_nodes: 5_000_000,
        ..ScanParams::default()
    };
    let t0 = std::time::Instant::now();
    let err = t
        .insert_scan(&sphere_points(300, 300.0), &[0.0; 3], &p, Deadline::none())
        .unwrap_err();
    assert!(
        matches!(err, OctreeError::ScanTooManyCells { limit: 5_000_000, .. }),
        "{err}"
    );
    assert!(t.is_empty(), "a refused scan leaves the tree unchanged");
    assert!(
        t0.elapsed() < std::time::Duration::from_secs(5),
        "took {:?}",
        t0.elapsed()
    );
}

#[test]
fn a_scan_whose_beams_cross_too_many_cells_is_refused_before_tracing() {
    let mut t = Octree::new(0.1).unwrap();
    // one beam of 10 cells along x: 11 cells counted (‖Δkey‖₁ + 1)
    let p = ScanParams {
        max_traced_cells: 10,
        ..ScanParams::default()
    };
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let stop = || {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        false
    };
    let err = t
        .insert_scan(
            &[[1.05, 0.05, 0.05]],
            &[0.05, 0.05, 0.05],
            &p,
            Deadline::none().with_cancel(&stop),
        )
        .unwrap_err();
    assert_eq!(err, OctreeError::ScanTooLarge { cells: 11, limit: 10 });
    assert_eq!(calls.into_inner(), 0, "refused before any beam was traced");
    let ok = ScanParams {
        max_traced_cells: 11,
        ..ScanParams::default()
    };
    let s = t
        .insert_scan(&[[1.05, 0.05, 0.05]], &[0.05, 0.05, 0.05], &ok, Deadline::none())
        .unwrap();
    assert_eq!((s.free_cells, s.occupied_cells), (10, 1));
}

#[test]
fn the_update_stops_when_the_tree_passes_its_node_limit() {
    // three cells in a row below one path from the root:
    // 20 in all
    let mut t = Octree::new(0.1).unwrap();
    let p = ScanParams {
        max_nodes: 19,
        ..ScanParams::default()
    };
    let err = t
        .insert_scan(&[[0.25, 0.05, 0.05]], &[0.05, 0.05, 0.05], &p, Deadline::none())
        .unwrap_err();
    assert_eq!(err, OctreeError::TreeGrewTooLarge { limit: 19 });
    // the same scan fits a limit of 20 nodes
    let mut t = Octree::new(0.1).unwrap();
    let p = ScanParams {
        max_nodes: 20,
        ..ScanParams::default()
    };
    let s = t
        .insert_scan(&[[0.25, 0.05, 0.05]], &[0.05, 0.05, 0.05], &p, Deadline::none())
        .unwrap();
    assert_eq!(s.nodes, 20);
}

#[test]
fn a_long_scan_stops_within_a_chunk_of_its_stop_flag() {
    // 2,000 beams of about 2,000 cells: 4 million cells, dozens of chunks on each
    // path; the flag rises after the third look
    for dense_limit_cells in [1 << 27, 0] {
        let mut t = Octree::new(0.01).unwrap();
        let p = ScanParams {
            dense_limit_cells,
            ..ScanParams::default()
        };
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let stop = || calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 3;
        let s = t
            .insert_scan(
                &sphere_points(2_000, 12.0),
                &[0.0; 3],
                &p,
                Deadline::none().with_cancel(&stop),
            )
            .unwrap();
        assert_eq!(s.status, ScanStatus::Cancelled);
        assert!(t.is_empty(), "stopped while tracing: the tree is unchanged");
    }
}
