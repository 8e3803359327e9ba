//! The culled frustum count against a count of every cell, over random trees (pruned
//! free cubes, occupied cells, holes) and random frusta, with and without key boxes.

use nalgebra::{Point3, Vector3};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::Deadline;
use crate::octree::{CellState, KnownCellCounts, OcKey, Octree, TREE_DEPTH};

/// A tree at 0.1 m around the origin: aligned free cubes (pruned to one leaf each),
/// scattered occupied and free cells, and a few unknown holes punched back out of
/// nothing (cells left absent between updates).
fn random_tree(seed: u64) -> Octree {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t = Octree::new(0.1).unwrap();
    let m = t.sensor_model().log_odds();
    for _ in 0..rng.random_range(1..5) {
        // an aligned cube of 2^s cells a side, every cell updated free: pruned
        let s = rng.random_range(1..4u32);
        let base = [0; 3].map(|_| (32768 - 16 + rng.random_range(0..32u16)) & !((1 << s) - 1));
        for x in 0..1u16 << s {
            for y in 0..1u16 << s {
                for z in 0..1u16 << s {
                    for _ in 0..3 {
                        t.update_key(&[base[0] + x, base[1] + y, base[2] + z], m.miss);
                    }
                }
            }
        }
    }
    for _ in 0..rng.random_range(500..4000) {
        let k = [0; 3].map(|_| 32768u16 - 20 + rng.random_range(0..40u16));
        t.update_key(&k, if rng.random_bool(0.3) { m.hit } else { m.miss });
    }
    t
}

/// Every cell of the key box `[lo, hi]`: unknown and centre inside the frustum.
fn brute(t: &Octree, f: &Frustum, lo: OcKey, hi: OcKey) -> u64 {
    let mut n = 0;
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
    n
}

fn corner_box(t: &Octree, f: &Frustum) -> (OcKey, OcKey) {
    let ks: Vec<OcKey> = f.corners.iter().map(|c| t.key_of(c).unwrap()).collect();
    (
        [0, 1, 2].map(|i| ks.iter().map(|k| k[i]).min().unwrap()),
        [0, 1, 2].map(|i| ks.iter().map(|k| k[i]).max().unwrap()),
    )
}

/// Known cells by an independent walk: every leaf at depth d covers 8^(16−d) cells.
fn known_cells(t: &Octree) -> u64 {
    let mut total = 0u64;
    let mut stack: Vec<_> = t.root_ref().map(|r| (r, 0u8)).into_iter().collect();
    while let Some((n, d)) = stack.pop() {
        if !t.has_children(n) {
            total += 1u64 << (3 * (TREE_DEPTH - d) as u32);
            continue;
        }
        for i in 0..8 {
            if let Some(c) = t.child_ref(n, i) {
                stack.push((c, d + 1));
            }
        }
    }
    total
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn culled_count_equals_the_count_of_every_cell(
        seed in 0u64..1_000_000,
        pos in prop::array::uniform3(-1.5f64..1.5),
        dir in prop::array::uniform3(-1.0f64..1.0),
        hfov in 0.3f64..2.0,
        vfov in 0.3f64..1.6,
        near in 0.01f64..0.5,
        depth in 0.3f64..2.5,
        boxed in any::<bool>(),
    ) {
        let t = random_tree(seed);
        let cam = CameraModel { hfov, vfov, near, far: near + depth, width: 8, height: 6 };
        let Some(pose) = look_along(&Point3::from(pos), &Vector3::from(dir)) else {
            return Ok(());
        };
        let f = Frustum::new(&cam, &pose);
        let counter = FrustumCounter::new(&t);
        let (lo, hi) = corner_box(&t, &f);
        if boxed {
            // a key box cutting through the frustum's corner box
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xb0c5);
            let a = [0, 1, 2].map(|i| rng.random_range(lo[i]..=hi[i]));
            let b = [0, 1, 2].map(|i| rng.random_range(a[i]..=hi[i]));
            prop_assert_eq!(counter.count_in(&f, Some((a, b))), brute(&t, &f, a, b));
            prop_assert_eq!(frustum_unknown_count_in(&t, &f, Some((a, b))), brute(&t, &f, a, b));
        } else {
            prop_assert_eq!(counter.count(&f), brute(&t, &f, lo, hi));
        }
    }

    /// Frusta whose planes run through cell centres: the camera at a cell centre,
    /// looking along a small integer direction, tan(fov/2) of ½, 1 or 3/2, near and far a
    /// whole number of cells. Many rows then cross a plane exactly at (or within
    /// rounding of) a cell centre, which the fixed-point row loops must hand to the
    /// per-cell tests; the count still equals the count of every cell.
    #[test]
    fn lattice_aligned_frusta_count_like_every_cell(
        seed in 0u64..1_000_000,
        cell in prop::array::uniform3(-12i32..12),
        dir in prop::array::uniform3(-2i32..=2),
        th in 1u32..=3,
        tv in 1u32..=3,
        near in 1u32..4,
        depth in 3u32..14,
    ) {
        let t = random_tree(seed);
        let key: OcKey = cell.map(|v| (32768 + v) as u16);
        let d = Vector3::new(dir[0] as f64, dir[1] as f64, dir[2] as f64);
        let Some(pose) = look_along(&t.key_center(&key, TREE_DEPTH), &d) else {
            return Ok(());
        };
        let cam = CameraModel {
            hfov: 2.0 * (th as f64 / 2.0).atan(),
            vfov: 2.0 * (tv as f64 / 2.0).atan(),
            near: near as f64 * 0.1,
            far: (near + depth) as f64 * 0.1,
            width: 8,
            height: 6,
        };
        let f = Frustum::new(&cam, &pose);
        let (lo, hi) = corner_box(&t, &f);
        prop_assert_eq!(FrustumCounter::new(&t).count(&f), brute(&t, &f, lo, hi));
    }

    #[test]
    fn known_counts_sum_the_leaves(seed in 0u64..1_000_000) {
        let t = random_tree(seed);
        prop_assert_eq!(KnownCellCounts::new(&t).root(), known_cells(&t));
    }
}

/// A narrow camera of 8 × 6 pixels seeing 0.05–1.5 m.
fn small_camera() -> CameraModel {
    CameraModel {
        hfov: 1.0,
        vfov: 0.8,
        near: 0.05,
        far: 1.5,
        width: 8,
        height: 6,
    }
}

#[test]
fn counts_on_trees_with_no_nodes_one_leaf_and_axis_aligned_views() {
    let cam = small_camera();
    // axis-aligned views put plane normals with zero components along the row axes
    let dirs = [Vector3::x(), -Vector3::y(), Vector3::z(), -Vector3::z()];
    let empty = Octree::new(0.1).unwrap();
    let mut one = Octree::new(0.1).unwrap();
    let m = one.sensor_model().log_odds();
    one.update_key(&[32768, 32768, 32768], m.hit);
    let t = random_tree(7);
    for tree in [&empty, &one, &t] {
        let counter = FrustumCounter::new(tree);
        for d in &dirs {
            let pose = look_along(&Point3::new(0.05, -0.05, 0.15), d).unwrap();
            let f = Frustum::new(&cam, &pose);
            let (lo, hi) = corner_box(tree, &f);
            assert_eq!(counter.count(&f), brute(tree, &f, lo, hi), "{d:?}");
        }
    }
    // known cells: none in an empty tree, one in a tree of one cell
    assert_eq!(KnownCellCounts::new(&empty).root(), 0);
    assert_eq!(KnownCellCounts::new(&one).root(), 1);
}

#[test]
fn a_wholly_known_subtree_of_mixed_cells_counts_no_unknown_cell() {
    // an aligned 8-cell cube, checkerboard of occupied and free cells: never pruned,
    // every cell known, so the walk may skip it whole; one unknown hole beside it
    let mut t = Octree::new(0.1).unwrap();
    let m = t.sensor_model().log_odds();
    for x in 0..8u16 {
        for y in 0..8u16 {
            for z in 0..8u16 {
                let v = if (x + y + z) % 2 == 0 { m.hit } else { m.miss };
                t.update_key(&[32768 + x, 32768 + y, 32768 + z], v);
            }
        }
    }
    assert_eq!(KnownCellCounts::new(&t).root(), 512);
    let cam = CameraModel {
        hfov: 1.2,
        vfov: 1.0,
        near: 0.05,
        far: 2.0,
        width: 8,
        height: 6,
    };
    let counter = FrustumCounter::new(&t);
    for (o, d) in [
        (Point3::new(-0.31, 0.42, 0.38), Vector3::new(1.0, 0.05, 0.02)),
        (Point3::new(0.4, 0.37, -0.5), Vector3::new(0.1, 0.03, 1.0)),
    ] {
        let f = Frustum::new(&cam, &look_along(&o, &d).unwrap());
        let (lo, hi) = corner_box(&t, &f);
        let n = brute(&t, &f, lo, hi);
        // the view crosses the known cube: some of its cells are not counted
        let all = FrustumCounter::new(&Octree::new(0.1).unwrap()).count(&f);
        assert!(n < all, "{n} {all}");
        assert_eq!(counter.count(&f), n);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Frontier cells against a test of every free cell of the region with its 26
    /// neighbours looked up one by one.
    #[test]
    fn frontier_cells_equal_a_scan_of_every_free_cell(seed in 0u64..1_000_000, ratio in 0.01f64..0.9) {
        let t = random_tree(seed);
        let (min, max) = (Point3::new(-1.2, -1.5, -1.0), Point3::new(1.4, 1.1, 1.3));
        let got = frontier_cells(&t, &min, &max, ratio, Deadline::none()).unwrap();
        let (lo, hi) = (t.key_of(&min).unwrap(), t.key_of(&max).unwrap());
        let mut want = Vec::new();
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    if t.state_of_key(&[x, y, z]) != CellState::Free {
                        continue;
                    }
                    let mut unknown = 0;
                    for d in 0..27 {
                        let o = [d % 3, d / 3 % 3, d / 9].map(|v: i32| v - 1);
                        if o == [0, 0, 0] {
                            continue;
                        }
                        let nb = [x as i32 + o[0], y as i32 + o[1], z as i32 + o[2]].map(|v| v as u16);
                        unknown += (t.state_of_key(&nb) == CellState::Unknown) as usize;
                    }
                    if unknown > 0 && unknown as f64 / 26.0 >= ratio {
                        want.push(([x, y, z], unknown as f64 / 26.0));
                    }
                }
            }
        }
        let got: Vec<(OcKey, f64)> = got.iter().map(|f| (f.key, f.unknown_ratio)).collect();
        prop_assert_eq!(&got, &want);
        // the lookup path (taken when the region's grid would be too large) agrees
        let by_lookups = super::frontier::frontier_by_lookups(&t, &min, &max, ratio, Deadline::none()).unwrap();
        let by_lookups: Vec<(OcKey, f64)> = by_lookups.iter().map(|f| (f.key, f.unknown_ratio)).collect();
        prop_assert_eq!(by_lookups, want);
    }

    /// The grid's potential field against the per-cell sum written out with one tree
    /// lookup per cell of the radius' key box, at free and unknown cells and radii of
    /// 0.5–7 cells; the region's shared grid and the per-call grid agree exactly.
    #[test]
    fn potential_field_equals_a_sum_over_every_cell(
        seed in 0u64..1_000_000,
        radius in 0.05f64..0.7,
        o in proptest::array::uniform3(-22i32..22),
    ) {
        let t = random_tree(seed);
        let res = t.resolution();
        let key: OcKey = o.map(|v| (32768 + v) as u16);
        let reach = (radius / res).ceil() as i32 + 1;
        let mut want = Vector3::zeros();
        let mut scale = 0.0;
        for dz in -reach..=reach {
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let d = Vector3::new(dx as f64 * res, dy as f64 * res, dz as f64 * res);
                    let dist = d.norm();
                    if (dx, dy, dz) == (0, 0, 0) || dist > radius {
                        continue;
                    }
                    let k = [0, 1, 2].map(|i| (key[i] as i32 + [dx, dy, dz][i]) as u16);
                    let s = if t.state_of_key(&k) == CellState::Unknown { 1.0 } else { -1.0 };
                    want += d / (dist * dist) * s;
                    scale += 1.0 / dist;
                }
            }
        }
        let got = potential_field(&t, &key, radius).unwrap();
        prop_assert!((got - want).norm() <= 1e-12 * scale, "{} vs {}", got, want);
        let ball = super::grid::Ball::new(res, radius).unwrap();
        let g = super::grid::StateGrid::new(&t, [32700; 3], [32830; 3], usize::MAX).unwrap();
        prop_assert_eq!(g.field(&key, &ball), got);
    }
}

/// At the corner of the key space a cell has 7 neighbours in the tree's cube; the
/// other 19 are neither unknown nor known (the grid marks them outside), so a free
/// cell there has 7/26 unknown neighbours, and its field sums the 7 cells only.
#[test]
fn frontier_and_field_at_the_edge_of_the_key_space() {
    let mut t = Octree::new(0.1).unwrap();
    let miss = t.sensor_model().log_odds().miss;
    t.update_key(&[0, 0, 0], miss);
    let (min, max) = (t.key_center(&[0; 3], 16), t.key_center(&[3; 3], 16));
    for f in [
        frontier_cells(&t, &min, &max, 0.25, Deadline::none()).unwrap(),
        super::frontier::frontier_by_lookups(&t, &min, &max, 0.25, Deadline::none()).unwrap(),
    ] {
        assert_eq!(f.len(), 1);
        assert_eq!((f[0].key, f[0].unknown_ratio), ([0; 3], 7.0 / 26.0));
    }
    assert!(
        frontier_cells(&t, &min, &max, 0.3, Deadline::none())
            .unwrap()
            .is_empty()
    );
    // seven unknown cells at +x, +y, +z, the face diagonals and the body diagonal:
    // F = (1/0.1)·(1 + 2·½ + ⅓)·(1,1,1) per axis = 23.33…·(1, 1, 1)
    let f = potential_field(&t, &[0; 3], 0.18).unwrap();
    let want = (1.0 + 2.0 * 0.5 + 1.0 / 3.0) / 0.1;
    for i in 0..3 {
        assert!((f[i] - want).abs() < 1e-9, "{f}");
    }
}

#[test]
fn a_view_leaving_the_key_space_counts_like_every_cell() {
    // the key space at 0.1 m ends at ±3276.8 m: the far corners of this view lie beyond
    // it, so the view's key box is the whole key space and the counter walks the tree
    let mut t = Octree::new(0.1).unwrap();
    let m = t.sensor_model().log_odds();
    for x in 65_520u16..65_535 {
        for y in 32_760u16..32_772 {
            for z in 32_764u16..32_770 {
                if !(x as u32 + y as u32 + z as u32).is_multiple_of(3) {
                    t.update_key(
                        &[x, y, z],
                        if (x as u32 + z as u32).is_multiple_of(4) {
                            m.hit
                        } else {
                            m.miss
                        },
                    );
                }
            }
        }
    }
    let cam = small_camera();
    let pose = look_along(&Point3::new(3276.05, 0.03, 0.02), &Vector3::new(1.0, 0.1, -0.05)).unwrap();
    let f = Frustum::new(&cam, &pose);
    assert!(f.corners.iter().any(|c| t.key_of(c).is_err()));
    // every cell centre in the frustum lies in the box of its corners clamped to the key space
    let clamped = |i: usize, pick: fn(f64, f64) -> f64, init: f64| {
        let v = f.corners.iter().fold(init, |a, c| pick(a, c[i]));
        v.clamp(-3276.75, 3276.75)
    };
    let lo_p = Point3::new(
        clamped(0, f64::min, f64::MAX),
        clamped(1, f64::min, f64::MAX),
        clamped(2, f64::min, f64::MAX),
    );
    let hi_p = Point3::new(
        clamped(0, f64::max, f64::MIN),
        clamped(1, f64::max, f64::MIN),
        clamped(2, f64::max, f64::MIN),
    );
    let (lo, hi) = (t.key_of(&lo_p).unwrap(), t.key_of(&hi_p).unwrap());
    let n = brute(&t, &f, lo, hi);
    // some cells of the view known, some not
    let all = brute(&Octree::new(0.1).unwrap(), &f, lo, hi);
    assert!(n > 30 && n < all, "{n} {all}");
    assert_eq!(FrustumCounter::new(&t).count(&f), n);
}

#[test]
fn deep_wide_frusta_count_like_every_cell() {
    // the sensor's frustum (70.6° × 60°, 0.5–4.5 m) at 0.1 m: tiles of columns far
    // from the view axis, where the side planes bound the rows and the near plane
    // bounds none, are counted with fewer planes; the count still equals the count
    // of every cell
    let cam = CameraModel::default();
    let mut rng = ChaCha8Rng::seed_from_u64(2711);
    for seed in 0..4u64 {
        let t = random_tree(seed);
        let counter = FrustumCounter::new(&t);
        let at = Point3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-1.0..1.0),
        );
        let aim = Point3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), 0.0) - at;
        let f = Frustum::new(&cam, &look_along(&at, &aim).unwrap());
        let (lo, hi) = corner_box(&t, &f);
        assert_eq!(counter.count(&f), brute(&t, &f, lo, hi), "view {seed}");
    }
}
