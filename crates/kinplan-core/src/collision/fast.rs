//! Closed-form narrow phase for the shapes robots are usually modelled with:
//! a robot sphere or capsule (a segment `[a, b]` swept by radius `r`; a
//! sphere is the segment with `a = b`) against an obstacle sphere, capsule
//! or box. Overlap (touching counts) when
//!
//! * sphere/capsule: `dist(seg₁, seg₂) ≤ r₁ + r₂`;
//! * box (half extents `h`, frame `T`): `min_t dist(T⁻¹ p(t), box) ≤ r`
//!   with `p(t) = a + t (b − a)`, `t ∈ [0, 1]`.
//!
//! The segment–segment distance is the clamped closed form (Ericson, *Real-
//! Time Collision Detection*, §5.1.9). The segment–box distance is convex
//! in `t` (the distance to a convex set along a line), so it is minimised
//! by golden-section search to |Δt| < 1e-10, stopping as soon as a point
//! within `r` is found. Obstacle cylinders are bracketed between an
//! enclosing and an enclosed capsule, and only the pairs in between go to
//! the exact test. Lengths in metres, base frame.

use nalgebra::{Isometry3, Point3, Vector3};

use super::fast_box::{boxes_overlap, segment_box_closest, segment_box_distance_squared};

/// Robot shape in its body frame, when closed forms apply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RobotFast {
    /// Segment `[a, b]` swept by `r` (a sphere has `a = b`).
    Swept {
        a: Point3<f64>,
        b: Point3<f64>,
        r: f64,
    },
    /// Box `[−half, half]` in the frame `offset` (body frame).
    Box {
        offset: Isometry3<f64>,
        half: Vector3<f64>,
    },
    None,
}

/// Obstacle shape in the base frame, when closed forms apply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum LeafFast {
    Swept {
        a: Point3<f64>,
        b: Point3<f64>,
        r: f64,
    },
    Box {
        pose: Isometry3<f64>,
        half: Vector3<f64>,
    },
    /// A cylinder only bracketed in closed form: `outer` (same axis, same
    /// radius, capsule) contains it and `inner` (axis shortened by ρ, radius
    /// ρ = min(radius, half length)) lies inside it. Overlap with `inner`
    /// proves a collision, no overlap with `outer` proves none; in between
    /// the exact (parry) test decides.
    Cylinder {
        outer: (Point3<f64>, Point3<f64>, f64),
        inner: (Point3<f64>, Point3<f64>, f64),
    },
    None,
}

/// Squared distance between segments `[p1, q1]` and `[p2, q2]`.
#[inline]
pub(crate) fn segment_segment_distance_squared(
    p1: &Point3<f64>,
    q1: &Point3<f64>,
    p2: &Point3<f64>,
    q2: &Point3<f64>,
) -> f64 {
    let (c1, c2) = segment_segment_closest(p1, q1, p2, q2);
    (c1 - c2).norm_squared()
}

/// Closest points of segments `[p1, q1]` and `[p2, q2]`.
pub(crate) fn segment_segment_closest(
    p1: &Point3<f64>,
    q1: &Point3<f64>,
    p2: &Point3<f64>,
    q2: &Point3<f64>,
) -> (Point3<f64>, Point3<f64>) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let eps = 1e-18;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > eps * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

#[inline]
#[cfg(test)]
fn point_box_distance_squared(p: &Vector3<f64>, half: &Vector3<f64>) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let e = (p[k].abs() - half[k]).max(0.0);
        d2 += e * e;
    }
    d2
}

/// True when the segment `[a, b]` (base frame) comes within `r` of the box.
pub(crate) fn segment_box_within(
    a: &Point3<f64>,
    b: &Point3<f64>,
    r: f64,
    pose: &Isometry3<f64>,
    half: &Vector3<f64>,
) -> bool {
    let la = pose.inverse_transform_point(a).coords;
    let lb = pose.inverse_transform_point(b).coords;
    let r2 = r * r;
    // Reject on the slab test of the box grown by r.
    for k in 0..3 {
        let h = half[k] + r;
        if (la[k] > h && lb[k] > h) || (la[k] < -h && lb[k] < -h) {
            return false;
        }
    }
    segment_box_distance_squared(&la, &(lb - la), half) <= r2
}

/// Signed distance and witness points (robot side, other side) of two
/// swept spheres whose segments' closest points are `c1`, `c2`.
fn swept_witness(c1: Point3<f64>, r1: f64, c2: Point3<f64>, r2: f64) -> (f64, Point3<f64>, Point3<f64>) {
    let d = c2 - c1;
    let len = d.norm();
    let n = if len > 1e-12 { d / len } else { Vector3::x() };
    (len - r1 - r2, c1 + n * r1, c2 - n * r2)
}

/// Closed-form signed distance between a robot shape posed by `pose` and a
/// leaf, with witness points (robot side, leaf side), base frame. `None`
/// when no closed form applies, including a segment that enters a box
/// (the penetration depth is then left to parry).
pub(crate) fn distance(
    robot: &RobotFast,
    pose: &Isometry3<f64>,
    leaf: &LeafFast,
) -> Option<(f64, Point3<f64>, Point3<f64>)> {
    let RobotFast::Swept { a, b, r } = robot else {
        return None;
    };
    let (wa, wb) = (pose * a, pose * b);
    match leaf {
        LeafFast::Swept { a: oa, b: ob, r: or } => {
            let (c1, c2) = segment_segment_closest(&wa, &wb, oa, ob);
            Some(swept_witness(c1, *r, c2, *or))
        }
        LeafFast::Box { pose: bp, half } => {
            let la = bp.inverse_transform_point(&wa).coords;
            let lb = bp.inverse_transform_point(&wb).coords;
            let d = lb - la;
            let t = segment_box_closest(&la, &d, half).1;
            let p = la + d * t;
            let q = Vector3::new(
                p.x.clamp(-half.x, half.x),
                p.y.clamp(-half.y, half.y),
                p.z.clamp(-half.z, half.z),
            );
            let gap = (p - q).norm();
            if gap <= 1e-12 {
                return None;
            }
            let (pw, qw) = (bp * Point3::from(p), bp * Point3::from(q));
            let n = (qw - pw) / gap;
            Some((gap - r, pw + n * *r, qw))
        }
        LeafFast::Cylinder { .. } | LeafFast::None => None,
    }
}

/// Closed-form signed distance between two robot shapes, with witnesses.
pub(crate) fn distance_robot(
    x: &RobotFast,
    px: &Isometry3<f64>,
    y: &RobotFast,
    py: &Isometry3<f64>,
) -> Option<(f64, Point3<f64>, Point3<f64>)> {
    match (x, y) {
        (RobotFast::Swept { a, b, r }, RobotFast::Swept { a: c, b: d, r: s }) => {
            let (c1, c2) = segment_segment_closest(&(px * a), &(px * b), &(py * c), &(py * d));
            Some(swept_witness(c1, *r, c2, *s))
        }
        _ => None,
    }
}

/// Closed-form overlap test of a robot shape posed by `pose` and a leaf;
/// `None` when no closed form applies.
#[inline]
pub(crate) fn overlap(robot: &RobotFast, pose: &Isometry3<f64>, leaf: &LeafFast) -> Option<bool> {
    match *robot {
        RobotFast::Swept { a, b, r } => swept_overlap(&(pose * a), &(pose * b), r, leaf),
        RobotFast::Box { offset, half } => box_overlap(&(pose * offset), &half, leaf),
        RobotFast::None => None,
    }
}

/// A swept sphere (base frame) against a leaf.
#[inline]
fn swept_overlap(wa: &Point3<f64>, wb: &Point3<f64>, r: f64, leaf: &LeafFast) -> Option<bool> {
    match leaf {
        LeafFast::Swept { a: oa, b: ob, r: or } => {
            let rr = r + or;
            Some(segment_segment_distance_squared(wa, wb, oa, ob) <= rr * rr)
        }
        LeafFast::Box { pose: bp, half } => Some(segment_box_within(wa, wb, r, bp, half)),
        LeafFast::Cylinder { outer, inner } => {
            let ro = r + outer.2;
            if segment_segment_distance_squared(wa, wb, &outer.0, &outer.1) > ro * ro {
                return Some(false);
            }
            let ri = r + inner.2;
            if segment_segment_distance_squared(wa, wb, &inner.0, &inner.1) <= ri * ri {
                return Some(true);
            }
            None
        }
        LeafFast::None => None,
    }
}

/// A box at `pose` (base frame) against a leaf.
#[inline]
fn box_overlap(pose: &Isometry3<f64>, half: &Vector3<f64>, leaf: &LeafFast) -> Option<bool> {
    match leaf {
        LeafFast::Swept { a, b, r } => Some(segment_box_within(a, b, *r, pose, half)),
        LeafFast::Box { pose: bp, half: bh } => Some(boxes_overlap(pose, half, bp, bh)),
        LeafFast::Cylinder { outer, inner } => {
            if !segment_box_within(&outer.0, &outer.1, outer.2, pose, half) {
                return Some(false);
            }
            if segment_box_within(&inner.0, &inner.1, inner.2, pose, half) {
                return Some(true);
            }
            None
        }
        LeafFast::None => None,
    }
}

/// Closed-form overlap test of two robot shapes.
#[inline]
pub(crate) fn overlap_robot(
    x: &RobotFast,
    px: &Isometry3<f64>,
    y: &RobotFast,
    py: &Isometry3<f64>,
) -> Option<bool> {
    match (*x, *y) {
        (RobotFast::Swept { a, b, r }, RobotFast::Swept { a: c, b: d, r: s }) => {
            let rr = r + s;
            Some(segment_segment_distance_squared(&(px * a), &(px * b), &(py * c), &(py * d)) <= rr * rr)
        }
        (RobotFast::Swept { a, b, r }, RobotFast::Box { offset, half })
        | (RobotFast::Box { offset, half }, RobotFast::Swept { a, b, r }) => {
            let (pa, pb) = match x {
                RobotFast::Swept { .. } => (px, py),
                _ => (py, px),
            };
            Some(segment_box_within(&(pa * a), &(pa * b), r, &(pb * offset), &half))
        }
        (RobotFast::Box { offset: oa, half: ha }, RobotFast::Box { offset: ob, half: hb }) => {
            Some(boxes_overlap(&(px * oa), &ha, &(py * ob), &hb))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn segment_distances_match_hand_cases() {
        let p = |x, y, z| Point3::new(x, y, z);
        // Crossing skew segments 0.5 apart along z.
        let d = segment_segment_distance_squared(
            &p(-1.0, 0.0, 0.0),
            &p(1.0, 0.0, 0.0),
            &p(0.0, -1.0, 0.5),
            &p(0.0, 1.0, 0.5),
        );
        assert!((d - 0.25).abs() < 1e-15);
        // Parallel, overlapping in x, 0.3 apart.
        let d = segment_segment_distance_squared(
            &p(0.0, 0.0, 0.0),
            &p(1.0, 0.0, 0.0),
            &p(0.5, 0.3, 0.0),
            &p(2.0, 0.3, 0.0),
        );
        assert!((d - 0.09).abs() < 1e-15);
        // End to end: (1,0,0) to (1.3,0.5,0.4).
        let d = segment_segment_distance_squared(
            &p(-1.0, 0.0, 0.0),
            &p(1.0, 0.0, 0.0),
            &p(1.3, 0.5, 0.4),
            &p(1.3, 0.5, 0.8),
        );
        assert!((d - 0.5).abs() < 1e-15);
        // Points.
        let d = segment_segment_distance_squared(
            &p(0.0, 0.0, 0.0),
            &p(0.0, 0.0, 0.0),
            &p(3.0, 4.0, 0.0),
            &p(3.0, 4.0, 0.0),
        );
        assert!((d - 25.0).abs() < 1e-12);
    }

    #[test]
    fn segment_box_test_matches_sampling_of_the_segment() {
        // A turned box; segments at random, r from the densely sampled
        // minimum distance: just above it is within, just below is not.
        let pose = Isometry3::from_parts(
            Translation3::new(0.2, -0.1, 0.3),
            UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        );
        let half = Vector3::new(0.1, 0.2, 0.05);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..200 {
            let a = Point3::new(rnd(), rnd(), rnd());
            let b = Point3::new(rnd(), rnd(), rnd());
            let (la, lb) = (
                pose.inverse_transform_point(&a).coords,
                pose.inverse_transform_point(&b).coords,
            );
            let min = (0..=20000)
                .map(|i| point_box_distance_squared(&(la + (lb - la) * (i as f64 / 20000.0)), &half))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            if min > 1e-3 {
                assert!(segment_box_within(&a, &b, min + 1e-6, &pose, &half));
                assert!(!segment_box_within(&a, &b, min - 1e-4, &pose, &half), "{min}");
            } else {
                assert!(segment_box_within(&a, &b, 1e-3, &pose, &half));
            }
        }
    }

    #[test]
    fn closed_form_distances_agree_with_parry() {
        use crate::collision::convert::pose_to_parry;
        use parry3d_f64::shape::SharedShape;
        let mut seed = 99u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for case in 0..300 {
            // Robot capsule at a random pose; obstacle box, sphere or capsule.
            let rp = Isometry3::from_parts(
                Translation3::new(rnd() * 0.5, rnd() * 0.5, rnd() * 0.5),
                UnitQuaternion::from_euler_angles(rnd() * 3.0, rnd() * 3.0, rnd() * 3.0),
            );
            let (r, hl) = (0.05 + 0.05 * rnd().abs(), 0.2 * rnd().abs());
            let robot = RobotFast::Swept {
                a: Point3::new(0.0, 0.0, -hl),
                b: Point3::new(0.0, 0.0, hl),
                r,
            };
            let robot_shape = SharedShape::capsule_z(hl, r);
            let op = Isometry3::from_parts(
                Translation3::new(rnd() * 0.5, rnd() * 0.5, rnd() * 0.5),
                UnitQuaternion::from_euler_angles(rnd() * 3.0, rnd() * 3.0, rnd() * 3.0),
            );
            let (leaf, shape) = match case % 3 {
                0 => {
                    let half = Vector3::new(
                        0.05 + 0.1 * rnd().abs(),
                        0.05 + 0.1 * rnd().abs(),
                        0.05 + 0.1 * rnd().abs(),
                    );
                    (
                        LeafFast::Box { pose: op, half },
                        SharedShape::cuboid(half.x, half.y, half.z),
                    )
                }
                1 => {
                    let c = Point3::from(op.translation.vector);
                    (LeafFast::Swept { a: c, b: c, r: 0.1 }, SharedShape::ball(0.1))
                }
                _ => (
                    LeafFast::Swept {
                        a: op * Point3::new(0.0, 0.0, -0.15),
                        b: op * Point3::new(0.0, 0.0, 0.15),
                        r: 0.07,
                    },
                    SharedShape::capsule_z(0.15, 0.07),
                ),
            };
            let Some((d, _, _)) = distance(&robot, &rp, &leaf) else {
                continue; // a segment inside a box: parry's business
            };
            let c = parry3d_f64::query::contact(
                &pose_to_parry(&rp),
                &*robot_shape,
                &pose_to_parry(&op),
                &*shape,
                10.0,
            )
            .unwrap()
            .unwrap();
            // Both return a feasible pair of points, so both bound the true
            // distance from above; GJK stops within its tolerance (~1e-5 m
            // observed), the closed form is tighter.
            if c.dist > 0.0 {
                assert!(
                    d <= c.dist + 1e-9 && c.dist - d < 2e-5,
                    "closed form {d} vs parry {}",
                    c.dist
                );
            } else {
                assert!((c.dist - d).abs() < 1e-6, "closed form {d} vs parry {}", c.dist);
            }
            assert_eq!(overlap(&robot, &rp, &leaf), Some(d <= 0.0));
        }
    }
}
