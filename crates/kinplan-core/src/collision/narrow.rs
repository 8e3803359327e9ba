//! Narrow phase between robot bodies and scene leaves: a bounding-sphere
//! test first, then parry's exact shape queries on the pairs that survive.
//! Boolean tests use `intersection_test`; distances use `contact` with a
//! prediction margin, whose `dist` is the signed distance (negative by the
//! penetration depth) and whose points are the witnesses.
//!
//! Boolean tests and distances between a robot sphere or capsule and an
//! obstacle sphere, capsule, box or cell (or another robot sphere or
//! capsule) use the closed forms of `fast` instead of parry; penetration
//! into a box and every other pair go to parry.
//!
//! A mesh hull or a cylinder, which no closed form decides, is tested
//! first through the closed-form bound around it (`BodyShape::bound`):
//! bounds apart are shapes apart. A polytope against a scene leaf is then
//! tried on its face axes (`super::face_axes`), and parry runs only where
//! neither decides. Within-margin tests ask parry's closest points with
//! the margin as prediction (GJK alone), not its contact.
//!
//! A pair parry cannot handle (none among the shapes this room builds) is
//! reported as colliding: the safe answer for a planner.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::{Cuboid, SharedShape};

use super::convert::{point_from_parry, pose_to_parry};
use super::fast::{LeafFast, RobotFast, distance, distance_robot, overlap, overlap_robot};
use super::model::{Body, BodyShape};
use super::world::Leaf;

/// The closest (or deepest) pair of points between two shapes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Witness {
    /// Signed distance (m), negative when overlapping.
    pub distance: f64,
    /// Witness point on the first shape (base frame).
    pub a: Point3<f64>,
    /// Witness point on the second shape (base frame).
    pub b: Point3<f64>,
}

#[inline]
fn intersect(p1: &Pose, s1: &SharedShape, p2: &Pose, s2: &SharedShape) -> bool {
    query::intersection_test(p1, &**s1, p2, &**s2).map_or(true, |i| i.intersecting)
}

/// True unless two parry shapes are more than `margin` (≥ 0) apart: GJK's
/// closest points with `margin` as the prediction, which stops at a
/// separating lower bound and, unlike `contact`, runs no penetration
/// search (EPA) when the shapes overlap. A pair parry cannot handle is
/// within.
#[inline]
fn within(p1: &Pose, s1: &SharedShape, p2: &Pose, s2: &SharedShape, margin: f64) -> bool {
    if let Some(mesh) = s2.as_trimesh() {
        return mesh_within(p1, s1, p2, mesh, margin);
    }
    if let Some(mesh) = s1.as_trimesh() {
        return mesh_within(p2, s2, p1, mesh, margin);
    }
    !matches!(
        query::closest_points(p1, &**s1, p2, &**s2, margin),
        Ok(query::ClosestPoints::Disjoint)
    )
}

/// [`within`] for a triangle mesh, triangle by triangle: parry's mesh query
/// keeps a triangle only when GJK's witness points lie within the margin,
/// and an early GJK stop can overstate their distance; per triangle,
/// `Disjoint` is GJK's proof of a separating gap. Triangles whose boxes
/// miss the shape's box grown by `margin` are apart already.
fn mesh_within(
    ps: &Pose,
    shape: &SharedShape,
    pm: &Pose,
    mesh: &parry3d_f64::shape::TriMesh,
    margin: f64,
) -> bool {
    use parry3d_f64::bounding_volume::BoundingVolume;
    let in_mesh = pm.inverse() * ps;
    let reach = shape.compute_aabb(&in_mesh).loosened(margin);
    let here = Pose::IDENTITY;
    mesh.bvh().intersect_aabb(&reach).any(|i| {
        let triangle = mesh.triangle(i);
        !matches!(
            query::closest_points(&in_mesh, &**shape, &here, &triangle, margin),
            Ok(query::ClosestPoints::Disjoint)
        )
    })
}

/// The contact of two parry shapes when their signed distance is below
/// `margin`. A nearest-pair search passes the best distance so far as the
/// margin, which is a negative penetration depth once a pair overlaps; parry's
/// prediction distance must not be negative (a mesh loosens its boxes by
/// it), so parry is asked with `max(margin, 0)` and deeper-or-not is left to
/// the caller, which keeps the smallest distance.
fn contact(p1: &Pose, s1: &SharedShape, p2: &Pose, s2: &SharedShape, margin: f64) -> Option<Witness> {
    match query::contact(p1, &**s1, p2, &**s2, margin.max(0.0)) {
        Ok(Some(c)) => Some(Witness {
            distance: c.dist,
            a: point_from_parry(c.point1),
            b: point_from_parry(c.point2),
        }),
        Ok(None) => None,
        Err(_) => {
            let p = point_from_parry(p1.translation);
            Some(Witness {
                distance: 0.0,
                a: p,
                b: p,
            })
        }
    }
}

/// World centre of a body's bounding sphere.
#[inline]
pub(crate) fn sphere_center(body: &Body, pose: &Isometry3<f64>) -> Vector3<f64> {
    (pose * Point3::from(body.center)).coords
}

/// True when body `a` at `pa` and body `b` at `pb` overlap (touching counts).
pub(crate) fn body_body_intersect(a: &Body, pa: &Isometry3<f64>, b: &Body, pb: &Isometry3<f64>) -> bool {
    let r = a.radius + b.radius;
    if (sphere_center(a, pa) - sphere_center(b, pb)).norm_squared() > r * r {
        return false;
    }
    for sa in &a.shapes {
        for sb in &b.shapes {
            let hit = match overlap_robot(&sa.fast, pa, &sb.fast, pb) {
                Some(hit) => hit,
                None => {
                    bounds_meet_robot(sa, pa, sb, pb, 0.0)
                        && !faces_apart_robot(sa, pa, sb, pb, 0.0)
                        && intersect(
                            &pose_to_parry(&(pa * sa.offset)),
                            &sa.shape,
                            &pose_to_parry(&(pb * sb.offset)),
                            &sb.shape,
                        )
                }
            };
            if hit {
                return true;
            }
        }
    }
    false
}

/// The smallest signed distance between two bodies when below `margin`.
pub(crate) fn body_body_contact(
    a: &Body,
    pa: &Isometry3<f64>,
    b: &Body,
    pb: &Isometry3<f64>,
    margin: f64,
) -> Option<Witness> {
    let r = a.radius + b.radius + margin;
    if (sphere_center(a, pa) - sphere_center(b, pb)).norm_squared() > r * r {
        return None;
    }
    let mut best: Option<Witness> = None;
    for sa in &a.shapes {
        let qa = pose_to_parry(&(pa * sa.offset));
        for sb in &b.shapes {
            let found = match distance_robot(&sa.fast, pa, &sb.fast, pb) {
                Some((d, x, y)) => (d < margin).then_some(Witness {
                    distance: d,
                    a: x,
                    b: y,
                }),
                None if !bounds_meet_robot(sa, pa, sb, pb, margin.max(0.0)) => None,
                None if faces_apart_robot(sa, pa, sb, pb, margin) => None,
                None => contact(
                    &qa,
                    &sa.shape,
                    &pose_to_parry(&(pb * sb.offset)),
                    &sb.shape,
                    margin,
                ),
            };
            best = closer(best, found);
        }
    }
    best
}

/// True when a body at `pa` overlaps a scene leaf.
#[inline]
pub(crate) fn body_leaf_intersect(a: &Body, pa: &Isometry3<f64>, center: &Vector3<f64>, leaf: &Leaf) -> bool {
    leaf.aabb.distance_squared(center) <= a.radius * a.radius && shapes_intersect_leaf(a, pa, leaf)
}

/// [`body_leaf_intersect`] without the bounding-sphere cull, for callers
/// that culled the leaf with the same sphere already (the BVH query).
#[inline]
pub(crate) fn shapes_intersect_leaf(a: &Body, pa: &Isometry3<f64>, leaf: &Leaf) -> bool {
    a.shapes.iter().any(|sa| match overlap(&sa.fast, pa, &leaf.fast) {
        Some(hit) => hit,
        None => {
            bound_meets_leaf(sa, pa, leaf, 0.0)
                && !faces_apart(sa, pa, leaf, 0.0)
                && intersect(
                    &pose_to_parry(&(pa * sa.offset)),
                    &sa.shape,
                    &leaf.pose,
                    &leaf.shape,
                )
        }
    })
}

/// The smallest signed distance between a body and a leaf when below `margin`.
pub(crate) fn body_leaf_contact(
    a: &Body,
    pa: &Isometry3<f64>,
    center: &Vector3<f64>,
    leaf: &Leaf,
    margin: f64,
) -> Option<Witness> {
    let r = a.radius + margin;
    if leaf.aabb.distance_squared(center) > r * r {
        return None;
    }
    let mut best: Option<Witness> = None;
    for sa in &a.shapes {
        let found = match distance(&sa.fast, pa, &leaf.fast) {
            Some((d, x, y)) => (d < margin).then_some(Witness {
                distance: d,
                a: x,
                b: y,
            }),
            None if !bound_meets_leaf(sa, pa, leaf, margin.max(0.0)) => None,
            None if faces_apart(sa, pa, leaf, margin) => None,
            None => contact(
                &pose_to_parry(&(pa * sa.offset)),
                &sa.shape,
                &leaf.pose,
                &leaf.shape,
                margin,
            ),
        };
        best = closer(best, found);
    }
    best
}

#[inline]
pub(crate) fn closer(a: Option<Witness>, b: Option<Witness>) -> Option<Witness> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if y.distance < x.distance { y } else { x }),
        (x, None) => x,
        (None, y) => y,
    }
}

/// False when the closed-form bounds of two robot shapes, the first grown
/// by `margin` (≥ 0), are apart: then the shapes are more than `margin`
/// apart. True when they meet or no closed form decides.
#[inline]
fn bounds_meet_robot(
    sa: &BodyShape,
    pa: &Isometry3<f64>,
    sb: &BodyShape,
    pb: &Isometry3<f64>,
    margin: f64,
) -> bool {
    overlap_robot(&grown(&sa.bound, margin), pa, &sb.bound, pb) != Some(false)
}

/// [`bounds_meet_robot`] for a robot shape and a scene leaf.
#[inline]
fn bound_meets_leaf(sa: &BodyShape, pa: &Isometry3<f64>, leaf: &Leaf, margin: f64) -> bool {
    overlap(&grown(&sa.bound, margin), pa, &leaf.fast) != Some(false)
}

/// True when a robot shape's face axes ([`super::face_axes`]) prove it
/// more than `margin` (m) from a scene leaf; false when it has none, the
/// margin is negative, or they decide nothing.
#[inline]
fn faces_apart(sa: &BodyShape, pa: &Isometry3<f64>, leaf: &Leaf, margin: f64) -> bool {
    margin >= 0.0
        && sa
            .faces
            .as_ref()
            .is_some_and(|f| f.apart(&(pa * sa.offset), &leaf.fast, margin))
}

/// [`faces_apart`] for two robot shapes: one a polytope with face axes,
/// the other a closed form (box, capsule or sphere) posed in the world.
#[inline]
fn faces_apart_robot(
    sa: &BodyShape,
    pa: &Isometry3<f64>,
    sb: &BodyShape,
    pb: &Isometry3<f64>,
    margin: f64,
) -> bool {
    let one_way = |s: &BodyShape, ps: &Isometry3<f64>, o: &BodyShape, po: &Isometry3<f64>| {
        let Some(faces) = s.faces.as_ref() else {
            return false;
        };
        let other = match o.fast {
            RobotFast::Box { offset, half } => LeafFast::Box {
                pose: po * offset,
                half,
            },
            RobotFast::Swept { a, b, r } => LeafFast::Swept {
                a: po * a,
                b: po * b,
                r,
            },
            RobotFast::None => return false,
        };
        faces.apart(&(ps * s.offset), &other, margin)
    };
    margin >= 0.0 && (one_way(sa, pa, sb, pb) || one_way(sb, pb, sa, pa))
}

/// `shape` grown by `margin`: a swept sphere exactly (radius + margin).
fn grown(shape: &RobotFast, margin: f64) -> RobotFast {
    match *shape {
        RobotFast::Swept { a, b, r } => RobotFast::Swept { a, b, r: r + margin },
        RobotFast::Box { offset, half } => RobotFast::Box {
            offset,
            half: half.add_scalar(margin),
        },
        RobotFast::None => RobotFast::None,
    }
}

/// True when body shape `s` at `pose` (world), grown by `margin`, overlaps
/// `other` at `other_pose`: a cuboid grows to half extents + margin (a box
/// around the rounded one, so never smaller), anything else as [`within`]
/// says.
fn parry_within(s: &BodyShape, pose: &Pose, other_pose: &Pose, other: &SharedShape, margin: f64) -> bool {
    match s.shape.as_cuboid() {
        Some(c) => {
            let big = Cuboid::new(c.half_extents + Vector::splat(margin));
            query::intersection_test(pose, &big, other_pose, &**other).map_or(true, |i| i.intersecting)
        }
        None => within(pose, &s.shape, other_pose, other, margin),
    }
}

/// True when a body at `pa`, grown by `margin` (m, > 0), overlaps a scene
/// leaf — conservative: whenever some point of the body is within `margin`
/// of the leaf. Swept spheres grow exactly and use the closed forms; other
/// shapes as [`parry_within`] says.
pub(crate) fn body_leaf_within(
    a: &Body,
    pa: &Isometry3<f64>,
    center: &Vector3<f64>,
    leaf: &Leaf,
    margin: f64,
) -> bool {
    let r = a.radius + margin;
    if leaf.aabb.distance_squared(center) > r * r {
        return false;
    }
    a.shapes
        .iter()
        .any(|sa| match overlap(&grown(&sa.fast, margin), pa, &leaf.fast) {
            Some(hit) => hit,
            None => {
                bound_meets_leaf(sa, pa, leaf, margin)
                    && !faces_apart(sa, pa, leaf, margin)
                    && parry_within(
                        sa,
                        &pose_to_parry(&(pa * sa.offset)),
                        &leaf.pose,
                        &leaf.shape,
                        margin,
                    )
            }
        })
}

/// True when body `a` at `pa` comes within `margin` (m, > 0) of body `b` at
/// `pb` (conservative, as [`body_leaf_within`]).
pub(crate) fn body_body_within(
    a: &Body,
    pa: &Isometry3<f64>,
    b: &Body,
    pb: &Isometry3<f64>,
    margin: f64,
) -> bool {
    let r = a.radius + b.radius + margin;
    if (sphere_center(a, pa) - sphere_center(b, pb)).norm_squared() > r * r {
        return false;
    }
    a.shapes.iter().any(|sa| {
        b.shapes.iter().any(
            |sb| match overlap_robot(&grown(&sa.fast, margin), pa, &sb.fast, pb) {
                Some(hit) => hit,
                None if !bounds_meet_robot(sa, pa, sb, pb, margin) => false,
                None if faces_apart_robot(sa, pa, sb, pb, margin) => false,
                None => {
                    let (qa, qb) = (pose_to_parry(&(pa * sa.offset)), pose_to_parry(&(pb * sb.offset)));
                    match sb.shape.as_cuboid() {
                        Some(_) => parry_within(sb, &qb, &qa, &sa.shape, margin),
                        None => parry_within(sa, &qa, &qb, &sb.shape, margin),
                    }
                }
            },
        )
    })
}
