//! Whole-frame insertion: the shared near field against the exact insert (whose tree is
//! OctoMap's, byte for byte, see `ray_tests`), and the batched update against one
//! `update_key` per cell.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::batch::BatchUpdate;
use super::*;
use crate::Deadline;

/// A closed 6 × 5 × 3 m room with a box on the floor and a sphere close to the
/// camera, ray-traced by hand: distance along the unit ray `d` from `o` to the first
/// surface.
fn room_hit(o: &Point3<f64>, d: &Vector3<f64>) -> f64 {
    let (lo, hi) = ([-3.0, -2.5, 0.0], [3.0, 2.5, 3.0]);
    let mut t = f64::INFINITY;
    for i in 0..3 {
        if d[i] != 0.0 {
            let exit = ((lo[i] - o[i]) / d[i]).max((hi[i] - o[i]) / d[i]);
            t = t.min(exit);
        }
    }
    // box [0.8, 1.6] × [−1.2, −0.2] × [0, 1.1]: slab entry
    let (bl, bh) = ([0.8, -1.2, 0.0], [1.6, -0.2, 1.1]);
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..3 {
        let (a, b) = ((bl[i] - o[i]) / d[i], (bh[i] - o[i]) / d[i]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t1 >= t0 && t0 > 0.0 {
        t = t.min(t0);
    }
    // sphere of radius 0.3 at (1.0, 0.5, 1.2)
    let oc = o - Point3::new(1.0, 0.5, 1.2);
    let b = oc.dot(d);
    let disc = b * b - (oc.dot(&oc) - 0.09);
    if disc > 0.0 && -b - disc.sqrt() > 0.0 {
        t = t.min(-b - disc.sqrt());
    }
    t
}

/// A `w × h` depth frame (m along the optical axis) of the room from `pose`
/// (optical frame: x right, y down, z forward), focal `f` px; every `hole`-th pixel
/// has no return (0) when `hole > 0`.
fn frame(w: usize, h: usize, f: f64, pose: &Isometry3<f64>, hole: usize) -> (Vec<f32>, PinholeIntrinsics) {
    let k = PinholeIntrinsics {
        fx: f,
        fy: f,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
    };
    let o = Point3::from(pose.translation.vector);
    let mut depth = Vec::with_capacity(w * h);
    for v in 0..h {
        for u in 0..w {
            let local = Vector3::new((u as f64 - k.cx) / f, (v as f64 - k.cy) / f, 1.0);
            let dir = pose.rotation * local.normalize();
            let z = room_hit(&o, &dir) * local.normalize().z;
            let i = v * w + u;
            depth.push(if hole > 0 && i % hole == 7 { 0.0 } else { z as f32 });
        }
    }
    (depth, k)
}

/// Camera at `o` looking along `fwd` with the image's y axis pointing down.
fn camera(o: [f64; 3], fwd: Vector3<f64>) -> Isometry3<f64> {
    let z = fwd.normalize();
    let x = z.cross(&Vector3::z()).normalize();
    let y = z.cross(&x);
    let r = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z]));
    Isometry3::from_parts(
        Translation3::new(o[0], o[1], o[2]),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// Cells whose state differs between the trees, and cells known in either, over
/// the room's key box.
fn differing(a: &Octree, b: &Octree) -> (usize, usize) {
    let lo = a.key_of(&Point3::new(-3.2, -2.7, -0.2)).unwrap();
    let hi = a.key_of(&Point3::new(3.2, 2.7, 3.2)).unwrap();
    let (mut differ, mut known) = (0, 0);
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                let (sa, sb) = (a.state_of_key(&[x, y, z]), b.state_of_key(&[x, y, z]));
                differ += (sa != sb) as usize;
                known += (sa != CellState::Unknown || sb != CellState::Unknown) as usize;
            }
        }
    }
    (differ, known)
}

#[test]
fn the_shared_near_field_classifies_the_cells_of_a_frame_as_the_exact_insert() {
    // a Kinect-v2-sized frame (f = 365 px) at 5 cm, two views: one with the sphere
    // 0.45 m in front of the camera, one with holes and a range cut
    let views = [
        (camera([0.3, 0.1, 1.3], Vector3::new(1.0, 0.4, -0.1)), 0, -1.0),
        (camera([-1.0, 1.0, 1.6], Vector3::new(1.0, -0.8, -0.4)), 13, 3.5),
    ];
    for (pose, hole, max_range) in views {
        let (depth, k) = frame(512, 424, 365.0, &pose, hole);
        let mut exact = Octree::new(0.05).unwrap();
        let base = ScanParams {
            max_range,
            ..ScanParams::default()
        };
        exact
            .insert_depth_image(&depth, 512, 424, &k, &pose, &base, Deadline::none())
            .unwrap();
        for spacing in [NEAR_RAY_SPACING, 1.0] {
            let mut fast = Octree::new(0.05).unwrap();
            let p = ScanParams {
                near_ray_spacing: spacing,
                ..base
            };
            let s = fast
                .insert_depth_image(&depth, 512, 424, &k, &pose, &p, Deadline::none())
                .unwrap();
            assert_eq!(s.status, ScanStatus::Inserted);
            let (differ, known) = differing(&exact, &fast);
            assert!(known > 50_000, "{known} known cells");
            // the target: at least 99.9 % of the cells classified the same
            assert!(
                differ * 1000 <= known,
                "spacing {spacing}, hole {hole}: {differ} of {known} cells differ"
            );
        }
    }
}

#[test]
fn near_ray_spacing_is_checked() {
    for bad in [-0.1, 1.5, f64::NAN] {
        let p = ScanParams {
            near_ray_spacing: bad,
            ..ScanParams::default()
        };
        assert!(matches!(
            p.validate(),
            Err(OctreeError::InvalidParam {
                field: "near_ray_spacing",
                ..
            })
        ));
    }
    let p = ScanParams {
        near_ray_spacing: 0.7,
        discretize: true,
        ..ScanParams::default()
    };
    assert!(p.validate().is_err());
}

#[test]
fn a_batched_update_builds_the_tree_of_one_update_per_key() {
    // a tree with pruned free space, clamped cells and unknown gaps, then keys in an
    // arbitrary order with repeats, some under pruned leaves, some at the clamp
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    let mut base = Octree::new(0.1).unwrap();
    for _ in 0..6 {
        for x in 32760..32776u16 {
            for y in 32760..32768u16 {
                base.update_key(&[x, y, 32768], base.sensor_model().log_odds().miss);
            }
        }
    }
    base.update_key(&[32770, 32770, 32770], 5.0);
    base.to_max_likelihood_pruned();
    for round in 0..4 {
        let keys: Vec<(OcKey, f32)> = (0..3000)
            .map(|_| {
                let k = [
                    rng.random_range(32756u16..32780),
                    rng.random_range(32756u16..32772),
                    rng.random_range(32764u16..32772),
                ];
                let d = if rng.random_bool(0.3) { 0.85 } else { -0.4 };
                (k, d)
            })
            .collect();
        let mut one = base.clone();
        for (k, d) in &keys {
            one.update_key(k, *d);
        }
        let mut batched = base.clone();
        let mut b = BatchUpdate::new();
        for (k, d) in &keys {
            b.update(&mut batched, k, *d);
        }
        b.finish(&mut batched);
        assert_eq!(one.num_nodes(), batched.num_nodes(), "round {round}");
        assert_eq!(one.write_ot(), batched.write_ot(), "round {round}");
        base = one;
    }
}

#[test]
fn sibling_groups_build_the_tree_of_one_update_per_key() {
    // the base tree of the test above (pruned free space, a clamped cell, gaps); the
    // groups come in ascending Morton order of their parents, as a scan hands them,
    // each with random disjoint free and occupied masks, some under pruned leaves at
    // depth 15 and above, some at the clamp
    let mut rng = ChaCha8Rng::seed_from_u64(2027);
    let mut base = Octree::new(0.1).unwrap();
    let miss0 = base.sensor_model().log_odds().miss;
    for _ in 0..6 {
        for x in 32760..32776u16 {
            for y in 32760..32768u16 {
                // 4 × 4 × 4 blocks pruned at depth 14, and a layer that is not
                for z in 32764..32769u16 {
                    base.update_key(&[x, y, z], miss0);
                }
            }
        }
        // one 2 × 2 × 2 cube pruned at depth 15
        for pos in 0..8u16 {
            base.update_key(
                &[32770 | (pos & 1), 32764 | (pos >> 1 & 1), 32770 | (pos >> 2)],
                miss0,
            );
        }
    }
    base.update_key(&[32770, 32770, 32770], 5.0);
    base.to_max_likelihood_pruned();
    // the 640 cells updated: 512 of them in pruned leaves (without, > 640 nodes)
    assert!(base.num_nodes() < 400, "{} nodes", base.num_nodes());
    let (hit, miss) = (0.85f32, -0.4f32);
    for round in 0..6 {
        let mut parents: Vec<u64> = (0..400)
            .map(|_| {
                let k = [
                    rng.random_range(32756u16..32780) & !1,
                    rng.random_range(32756u16..32772) & !1,
                    rng.random_range(32764u16..32772) & !1,
                ];
                morton(&k)
            })
            .collect();
        parents.sort_unstable();
        parents.dedup();
        let groups: Vec<(OcKey, u8, u8)> = parents
            .iter()
            .map(|&m| {
                let cells: u8 = rng.random_range(1..=255);
                let occupied = cells & rng.random::<u8>();
                (crate::octree::key::unmorton(m), cells & !occupied, occupied)
            })
            .collect();
        let mut one = base.clone();
        for (first, free, occupied) in &groups {
            update_siblings_one_by_one(&mut one, first, *free, *occupied, hit, miss);
        }
        let mut grouped = base.clone();
        let mut b = BatchUpdate::new();
        for (first, free, occupied) in &groups {
            b.update_siblings(&mut grouped, first, *free, *occupied, hit, miss);
        }
        b.finish(&mut grouped);
        assert_eq!(one.num_nodes(), grouped.num_nodes(), "round {round}");
        assert_eq!(one.write_ot(), grouped.write_ot(), "round {round}");
        base = one;
    }
    // into an empty tree
    let mut one = Octree::new(0.1).unwrap();
    let mut grouped = one.clone();
    let mut b = BatchUpdate::new();
    for (first, free, occupied) in [
        ([32768u16, 32768, 32768], 0b1010_0101u8, 0b0100_0000u8),
        ([32770, 32768, 32768], 0, 1),
    ] {
        b.update_siblings(&mut grouped, &first, free, occupied, hit, miss);
        update_siblings_one_by_one(&mut one, &first, free, occupied, hit, miss);
    }
    b.finish(&mut grouped);
    assert_eq!(one.num_nodes(), 1 + 15 + 5 + 1 + 1);
    assert_eq!(one.write_ot(), grouped.write_ot());
}

/// The reference for `BatchUpdate::update_siblings`: each of the eight
/// siblings from `first` (position bits x, y, z) updated by its own key —
/// occupied where its bit of `occupied` is set, else free where its bit of
/// `free` is.
fn update_siblings_one_by_one(
    tree: &mut Octree,
    first: &[u16; 3],
    free: u8,
    occupied: u8,
    hit: f32,
    miss: f32,
) {
    for pos in 0..8u16 {
        let k = [
            first[0] | (pos & 1),
            first[1] | (pos >> 1 & 1),
            first[2] | (pos >> 2),
        ];
        if occupied >> pos & 1 != 0 {
            tree.update_key(&k, hit);
        } else if free >> pos & 1 != 0 {
            tree.update_key(&k, miss);
        }
    }
}

/// An image of more than 2^24 pixels is refused by the library itself (the
/// scan's per-pixel indices are 32-bit), naming the width, before its length
/// is looked at.
#[test]
fn depth_images_over_the_pixel_limit_are_refused() {
    let pose = camera([0.0, 0.0, 1.0], Vector3::new(1.0, 0.0, 0.0));
    let (_, k) = frame(8, 6, 365.0, &pose, 0);
    let mut tree = Octree::new(0.05).unwrap();
    let err = tree
        .insert_depth_image(
            &[],
            4096,
            4097,
            &k,
            &pose,
            &ScanParams::default(),
            Deadline::none(),
        )
        .unwrap_err();
    assert!(err.to_string().contains("width"), "{err}");
    assert!(err.to_string().contains("2^24"), "{err}");
}
