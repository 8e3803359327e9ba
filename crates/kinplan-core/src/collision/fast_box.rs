//! Closed forms for boxes: the exact distance from a segment to a box, and
//! the overlap of two oriented boxes. Lengths in metres.
//!
//! * Segment–box: along `p(t) = a + t d`, `t ∈ [0, 1]`, in the box frame, the
//!   squared distance to the box of half extents `h` is
//!   `f(t) = Σ_k max(0, |p_k(t)| − h_k)²`. Between the parameters where some
//!   `p_k(t)` crosses `±h_k` (at most six) every term is either 0 or the
//!   square of a linear function, so `f` is one quadratic per interval and its
//!   minimum on the interval is at the clamped vertex `−B / 2A`.
//! * Box–box: the separating-axis test over the 15 candidate axes (the three
//!   face normals of each box and the nine cross products of their edges;
//!   Gottschalk, Lin and Manocha, *OBBTree*, 1996). Touching counts as
//!   overlap; near-parallel edges get a 1e-12 allowance, which can only turn
//!   a grazing separation into an overlap (the conservative side).

use nalgebra::{Isometry3, Vector3};

/// The squared distance from the segment `[la, la + d]` (box frame) to the
/// box `[−half, half]` (0 when they meet), exact (see the module doc).
pub(crate) fn segment_box_distance_squared(la: &Vector3<f64>, d: &Vector3<f64>, half: &Vector3<f64>) -> f64 {
    segment_box_closest(la, d, half).0
}

/// [`segment_box_distance_squared`] and a parameter `t ∈ [0, 1]` where the
/// segment comes that close.
pub(crate) fn segment_box_closest(la: &Vector3<f64>, d: &Vector3<f64>, half: &Vector3<f64>) -> (f64, f64) {
    // Interval ends: 0, 1 and every crossing of a face plane inside (0, 1).
    let mut ends = [0.0_f64; 8];
    ends[1] = 1.0;
    let mut count = 2;
    for k in 0..3 {
        if d[k] != 0.0 {
            for face in [-half[k], half[k]] {
                let t = (face - la[k]) / d[k];
                if t > 0.0 && t < 1.0 {
                    ends[count] = t;
                    count += 1;
                }
            }
        }
    }
    let ends = &mut ends[..count];
    ends.sort_unstable_by(f64::total_cmp);
    let at = |t: f64| {
        (0..3)
            .map(|k| {
                let e = ((la[k] + d[k] * t).abs() - half[k]).max(0.0);
                e * e
            })
            .sum::<f64>()
    };
    let (f0, f1) = (at(0.0), at(1.0));
    let mut best = if f1 < f0 { (f1, 1.0) } else { (f0, 0.0) };
    for w in ends.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        if t1 <= t0 {
            continue;
        }
        // f = A t² + B t + C on (t0, t1): the terms active at the middle.
        let mid = 0.5 * (t0 + t1);
        let (mut a, mut b) = (0.0, 0.0);
        for k in 0..3 {
            let p = la[k] + d[k] * mid;
            let (slope, offset) = if p > half[k] {
                (d[k], la[k] - half[k])
            } else if p < -half[k] {
                (-d[k], -la[k] - half[k])
            } else {
                continue;
            };
            a += slope * slope;
            b += 2.0 * slope * offset;
        }
        let t = if a > 0.0 {
            (-b / (2.0 * a)).clamp(t0, t1)
        } else {
            t0
        };
        let f = at(t);
        if f < best.0 {
            best = (f, t);
        }
    }
    best
}

/// True when the boxes `[−ha, ha]` at `pa` and `[−hb, hb]` at `pb` overlap
/// or touch (the separating-axis test; see the module doc).
pub(crate) fn boxes_overlap(
    pa: &Isometry3<f64>,
    ha: &Vector3<f64>,
    pb: &Isometry3<f64>,
    hb: &Vector3<f64>,
) -> bool {
    const PARALLEL: f64 = 1e-12;
    let ra = pa.rotation.to_rotation_matrix();
    let rb = pb.rotation.to_rotation_matrix();
    let at = ra.matrix().transpose();
    // B's axes and centre in A's frame.
    let r = at * rb.matrix();
    let t = at * (pb.translation.vector - pa.translation.vector);
    let abs = r.map(|x| x.abs() + PARALLEL);
    for i in 0..3 {
        let reach_b = hb[0] * abs[(i, 0)] + hb[1] * abs[(i, 1)] + hb[2] * abs[(i, 2)];
        if t[i].abs() > ha[i] + reach_b {
            return false;
        }
    }
    for j in 0..3 {
        let reach_a = ha[0] * abs[(0, j)] + ha[1] * abs[(1, j)] + ha[2] * abs[(2, j)];
        let along = t[0] * r[(0, j)] + t[1] * r[(1, j)] + t[2] * r[(2, j)];
        if along.abs() > reach_a + hb[j] {
            return false;
        }
    }
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let reach_a = ha[i1] * abs[(i2, j)] + ha[i2] * abs[(i1, j)];
            let reach_b = hb[j1] * abs[(i, j2)] + hb[j2] * abs[(i, j1)];
            let along = t[i2] * r[(i1, j)] - t[i1] * r[(i2, j)];
            if along.abs() > reach_a + reach_b {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::convert::{pose_to_parry, vec_to_parry};
    use nalgebra::{Translation3, UnitQuaternion};
    use parry3d_f64::shape::Cuboid;

    struct Lcg(u64);
    impl Lcg {
        /// Uniform in [−1, 1).
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        fn pose(&mut self, reach: f64) -> Isometry3<f64> {
            Isometry3::from_parts(
                Translation3::new(self.next() * reach, self.next() * reach, self.next() * reach),
                UnitQuaternion::from_euler_angles(self.next() * 3.0, self.next() * 3.0, self.next() * 3.0),
            )
        }
        fn half(&mut self) -> Vector3<f64> {
            Vector3::new(
                0.02 + 0.2 * self.next().abs(),
                0.02 + 0.2 * self.next().abs(),
                0.02 + 0.2 * self.next().abs(),
            )
        }
    }

    #[test]
    fn segment_box_distance_matches_hand_cases() {
        let half = Vector3::new(1.0, 1.0, 1.0);
        let v = Vector3::new;
        // Parallel to a face, 0.5 above it.
        let d2 = segment_box_distance_squared(&v(-3.0, 0.0, 1.5), &v(6.0, 0.0, 0.0), &half);
        assert!((d2 - 0.25).abs() < 1e-15);
        // Passing an edge diagonally: closest at the edge (1, 1, z), the
        // segment x + y = 3 → distance from (1, 1) to the line is 1/√2.
        let d2 = segment_box_distance_squared(&v(3.0, 0.0, 0.0), &v(-3.0, 3.0, 0.0), &half);
        assert!((d2 - 0.5).abs() < 1e-15, "{d2}");
        // Through the box.
        assert_eq!(
            segment_box_distance_squared(&v(-2.0, 0.3, 0.2), &v(4.0, 0.0, 0.0), &half),
            0.0
        );
        // Ending short of a corner: nearest point is the end (2, 2, 2).
        let d2 = segment_box_distance_squared(&v(5.0, 5.0, 5.0), &v(-3.0, -3.0, -3.0), &half);
        assert!((d2 - 3.0).abs() < 1e-15);
        // A point.
        let d2 = segment_box_distance_squared(&v(1.0, 3.0, -1.5), &v(0.0, 0.0, 0.0), &half);
        assert!((d2 - 4.25).abs() < 1e-15);
    }

    #[test]
    fn segment_box_distance_matches_dense_sampling() {
        let mut rng = Lcg(7);
        for _ in 0..500 {
            let half = rng.half();
            let la = Vector3::new(rng.next(), rng.next(), rng.next()) * 0.6;
            let d = Vector3::new(rng.next(), rng.next(), rng.next()) * 1.2;
            let sampled = (0..=20_000)
                .map(|i| {
                    let p = la + d * (i as f64 / 20_000.0);
                    (0..3)
                        .map(|k| ((p[k].abs() - half[k]).max(0.0)).powi(2))
                        .sum::<f64>()
                })
                .fold(f64::INFINITY, f64::min);
            let exact = segment_box_distance_squared(&la, &d, &half);
            // The exact minimum is never above a sample, and the samples come
            // within one step (|d| / 20 000) of it.
            assert!(exact <= sampled + 1e-15, "{exact} > {sampled}");
            assert!(sampled.sqrt() - exact.sqrt() < d.norm() / 20_000.0 + 1e-12);
        }
    }

    #[test]
    fn box_overlap_agrees_with_parry() {
        let mut rng = Lcg(2024);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..3000 {
            let (pa, ha) = (rng.pose(0.3), rng.half());
            let (pb, hb) = (rng.pose(0.3), rng.half());
            let (ca, cb) = (Cuboid::new(vec_to_parry(&ha)), Cuboid::new(vec_to_parry(&hb)));
            let dist = parry3d_f64::query::distance(&pose_to_parry(&pa), &ca, &pose_to_parry(&pb), &cb)
                .unwrap()
                .distance;
            if dist > 0.0 && dist < 1e-6 {
                continue; // within GJK's tolerance: either answer is fair
            }
            assert_eq!(boxes_overlap(&pa, &ha, &pb, &hb), dist == 0.0, "distance {dist}");
            if dist == 0.0 {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(hits > 300 && misses > 300, "{hits} hits, {misses} misses");
    }

    #[test]
    fn a_robot_box_against_every_closed_form_agrees_with_parry() {
        use crate::collision::fast::{LeafFast, RobotFast, overlap, overlap_robot};
        use parry3d_f64::shape::SharedShape;
        let mut rng = Lcg(77);
        let mut decided = 0;
        for case in 0..3000 {
            let (body, offset, half) = (rng.pose(0.3), rng.pose(0.1), rng.half());
            let robot = RobotFast::Box { offset, half };
            let world = body * offset;
            let robot_shape = SharedShape::cuboid(half.x, half.y, half.z);
            let other = rng.pose(0.4);
            let (leaf, shape) = match case % 3 {
                0 => {
                    let h = rng.half();
                    (
                        LeafFast::Box { pose: other, half: h },
                        SharedShape::cuboid(h.x, h.y, h.z),
                    )
                }
                1 => {
                    let c = nalgebra::Point3::from(other.translation.vector);
                    (LeafFast::Swept { a: c, b: c, r: 0.08 }, SharedShape::ball(0.08))
                }
                _ => (
                    LeafFast::Swept {
                        a: other * nalgebra::Point3::new(0.0, 0.0, -0.15),
                        b: other * nalgebra::Point3::new(0.0, 0.0, 0.15),
                        r: 0.05,
                    },
                    SharedShape::capsule_z(0.15, 0.05),
                ),
            };
            let dist = parry3d_f64::query::distance(
                &pose_to_parry(&world),
                &*robot_shape,
                &pose_to_parry(&other),
                &*shape,
            )
            .unwrap()
            .distance;
            if dist > 0.0 && dist < 1e-6 {
                continue;
            }
            assert_eq!(
                overlap(&robot, &body, &leaf),
                Some(dist == 0.0),
                "case {case}: distance {dist}"
            );
            // the same pair as two robot shapes, both orders
            if let LeafFast::Swept { a, b, r } = leaf {
                let swept = RobotFast::Swept { a, b, r };
                let id = Isometry3::identity();
                assert_eq!(overlap_robot(&robot, &body, &swept, &id), Some(dist == 0.0));
                assert_eq!(overlap_robot(&swept, &id, &robot, &body), Some(dist == 0.0));
            } else if let LeafFast::Box { pose, half: h } = leaf {
                let other_box = RobotFast::Box {
                    offset: pose,
                    half: h,
                };
                let id = Isometry3::identity();
                assert_eq!(overlap_robot(&robot, &body, &other_box, &id), Some(dist == 0.0));
            }
            decided += 1;
        }
        assert!(decided > 2900);
    }

    #[test]
    fn boxes_touching_face_to_face_overlap() {
        let half = Vector3::new(0.5, 0.5, 0.5);
        let a = Isometry3::identity();
        let touching = Isometry3::translation(1.0, 0.2, 0.0);
        let apart = Isometry3::translation(1.0 + 1e-9, 0.2, 0.0);
        assert!(boxes_overlap(&a, &half, &touching, &half));
        assert!(!boxes_overlap(&a, &half, &apart, &half));
        // An edge-on box (turned 45° about z) whose edge is 1 mm off the face.
        let turned = Isometry3::from_parts(
            Translation3::new(0.5 + 0.5 * 2f64.sqrt() + 1e-3, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_4),
        );
        assert!(!boxes_overlap(&a, &half, &turned, &half));
        let closer = Isometry3::from_parts(
            Translation3::new(0.5 + 0.5 * 2f64.sqrt() - 1e-3, 0.0, 0.0),
            turned.rotation,
        );
        assert!(boxes_overlap(&a, &half, &closer, &half));
    }
}
