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
//! bounds apart are shapes apart. Where the bound does not decide, the
//! boolean and within-margin tests of a polytope against a box, sphere,
//! capsule, cylinder or another polytope go to the yes-or-no GJK of
//! `super::gjk`, which stops at the first step that decides; the distance
//! queries first try the polytope's face axes (`super::face_axes`). parry
//! runs for the rest; its within-margin tests ask closest points with the
//! margin as prediction (GJK alone), not its contact.
//!
//! A pair parry cannot handle (none among the shapes this room builds) is
//! reported as colliding: the safe answer for a planner.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::{Cuboid, SharedShape};

use super::convert::{point_from_parry, pose_to_parry};
use super::fast::{LeafFast, RobotFast, distance, distance_robot, overlap, overlap_robot};
use super::gjk::{self, Convex};
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
                        && gjk_robot_within(sa, pa, sb, pb, 0.0).unwrap_or_else(|| {
                            intersect(
                                &pose_to_parry(&(pa * sa.offset)),
                                &sa.shape,
                                &pose_to_parry(&(pb * sb.offset)),
                                &sb.shape,
                            )
                        })
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
                && gjk_leaf_within(sa, pa, leaf, 0.0).unwrap_or_else(|| {
                    intersect(
                        &pose_to_parry(&(pa * sa.offset)),
                        &sa.shape,
                        &leaf.pose,
                        &leaf.shape,
                    )
                })
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
        let Some(other) = posed(&o.fast, po) else {
            return false;
        };
        faces.apart(&(ps * s.offset), &other, margin)
    };
    margin >= 0.0 && (one_way(sa, pa, sb, pb) || one_way(sb, pb, sa, pa))
}

/// A robot shape's closed form posed in the world (body at `pose`), in the
/// form a scene leaf has; `None` when it has none.
fn posed(fast: &RobotFast, pose: &Isometry3<f64>) -> Option<LeafFast> {
    match *fast {
        RobotFast::Box { offset, half } => Some(LeafFast::Box {
            pose: pose * offset,
            half,
        }),
        RobotFast::Swept { a, b, r } => Some(LeafFast::Swept {
            a: pose * a,
            b: pose * b,
            r,
        }),
        RobotFast::None => None,
    }
}

/// [`gjk::within`] for a robot polytope (body at `pa`) against a scene
/// leaf's closed form; `None` when the shape is no polytope with corners
/// or the leaf has no closed form.
#[inline]
fn gjk_leaf_within(sa: &BodyShape, pa: &Isometry3<f64>, leaf: &Leaf, margin: f64) -> Option<bool> {
    let faces = sa.faces.as_ref()?;
    let pose = pa * sa.offset;
    let (other, radius) = Convex::of_leaf(&pose, &leaf.fast)?;
    let key = gjk::pair_key(faces.corners().key(), leaf.key);
    Some(gjk::within_keyed(faces.corners(), &other, margin + radius, key))
}

/// [`gjk::within`] for two robot shapes, one of them a polytope with
/// corners and the other a polytope, box, capsule or sphere; `None`
/// otherwise.
#[inline]
fn gjk_robot_within(
    sa: &BodyShape,
    pa: &Isometry3<f64>,
    sb: &BodyShape,
    pb: &Isometry3<f64>,
    margin: f64,
) -> Option<bool> {
    let (poly, pp, other, po) = if sa.faces.is_some() {
        (sa, pa, sb, pb)
    } else {
        (sb, pb, sa, pa)
    };
    let faces = poly.faces.as_ref()?;
    let pose = pp * poly.offset;
    if let Some(other_faces) = other.faces.as_ref() {
        let shape = Convex::of_corners(&pose, other_faces.corners(), &(po * other.offset));
        let key = gjk::pair_key(faces.corners().key(), other_faces.corners().key());
        return Some(gjk::within_keyed(faces.corners(), &shape, margin, key));
    }
    let (shape, radius) = Convex::of_leaf(&pose, &posed(&other.fast, po)?)?;
    Some(gjk::within(faces.corners(), &shape, margin + radius))
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
                    && gjk_leaf_within(sa, pa, leaf, margin).unwrap_or_else(|| {
                        parry_within(
                            sa,
                            &pose_to_parry(&(pa * sa.offset)),
                            &leaf.pose,
                            &leaf.shape,
                            margin,
                        )
                    })
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
                None if let Some(near) = gjk_robot_within(sa, pa, sb, pb, margin) => near,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::fast::segment_segment_distance_squared;
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::Triangle;

    /// A placement an independent fuzz of these tests found: a small
    /// polytope whose distance to a one-triangle mesh is below a 1e-4 m
    /// margin, where parry's closest-points query over the whole mesh says
    /// `Disjoint` (its witness points, from an early GJK stop, lie farther
    /// apart than the shapes). The distance is bounded here by features:
    /// every polytope corner against the triangle, every triangle corner
    /// against the polytope, every pair of corners against every edge.
    #[test]
    fn a_polytope_just_within_a_mesh_triangle_is_within() {
        let corners = [
            [-0.17873805936104797, 0.29810488350731557, -0.08609290981665668],
            [-0.17883616019504517, 0.29826212966616045, -0.08631377579841897],
            [-0.18017251609687354, 0.29995369881825046, -0.08451589648307711],
            [-0.18007441526287635, 0.2997964526594056, -0.08429503050131483],
            [-0.17747876883781655, 0.2989925617368185, -0.0859920736752756],
            [-0.17759156081523228, 0.2991733563791723, -0.08624601556151423],
            [-0.17892791671706065, 0.3008649255312623, -0.08444813624617238],
            [-0.17881512473964492, 0.30068413088890844, -0.08419419435993375],
            [-0.17929897614104057, 0.299857455015777, -0.08377604519747996],
            [-0.17911049044508742, 0.2999928714530697, -0.08376335374261297],
            [-0.17777413454325905, 0.29830130230097973, -0.08556123305795482],
            [-0.1779626202392122, 0.29816588586368703, -0.08557392451282181],
            [-0.17982450743273126, 0.30069983090193403, -0.08495923579797342],
            [-0.17963602173677812, 0.3008352473392268, -0.08494654434310643],
            [-0.17829966583494974, 0.2991436781871368, -0.08674442365844828],
            [-0.1784881515309029, 0.2990082617498441, -0.08675711511331527],
            [-0.177587775537615, 0.29852860735518544, -0.08563657752607418],
            [-0.1774882120152082, 0.29875866606687684, -0.08577902753198177],
            [-0.1777966759251897, 0.2992531039122089, -0.08647350872587489],
            [-0.17803282208894197, 0.29924197397860586, -0.0866385633347936],
            [-0.1786205318368946, 0.29888205928798284, -0.08673677282009662],
            [-0.17875815540421552, 0.2986988116725701, -0.08666665579615042],
            [-0.1788431746567412, 0.2984694384547928, -0.08651404005754959],
            [-0.1785621212159764, 0.29801893694334125, -0.08588127128696041],
            [-0.17833210718122927, 0.29801589753394847, -0.08570744316549518],
            [-0.1781217906844833, 0.29808262540675023, -0.0856138980209312],
            [-0.17892413143944338, 0.3002201765072754, -0.08383869821073232],
            [-0.17882456791703658, 0.3004502352189668, -0.08398114821663992],
            [-0.17913303182701806, 0.30094467306429884, -0.08467562941053304],
            [-0.17936917799077032, 0.3009335431306958, -0.08484068401945176],
            [-0.17995688773872298, 0.3005736284400728, -0.08493889350475477],
            [-0.1800945113060439, 0.3003903808246601, -0.08486877648080857],
            [-0.18017953055856958, 0.30016100760688275, -0.08471616074220774],
            [-0.17989847711780477, 0.2997105060954312, -0.08408339197161856],
            [-0.17966846308305764, 0.2997074666860384, -0.08390956385015333],
            [-0.17945814658631168, 0.2997741945588402, -0.08381601870558934],
        ]
        .map(|[x, y, z]| Vector::new(x, y, z));
        let triangle = [
            [-0.18022100559207233, 0.2999427629637568, -0.08451049500718058],
            [-0.20753672728909672, 0.22967947802830596, -0.18450326936897457],
            [-0.35492677407840967, 0.21115594050881684, -0.17434495496838448],
        ]
        .map(|[x, y, z]| Vector::new(x, y, z));
        let polytope = SharedShape::convex_hull(&corners).unwrap();
        let mesh = SharedShape::trimesh(triangle.to_vec(), vec![[0, 1, 2]]).unwrap();
        let (tri, poly) = (
            Triangle::new(triangle[0], triangle[1], triangle[2]),
            polytope.as_convex_polyhedron().unwrap(),
        );
        let point = |v: &Vector| Point3::new(v.x, v.y, v.z);
        let mut upper = f64::INFINITY;
        for c in &corners {
            upper = upper.min(tri.distance_to_local_point(*c, true));
        }
        for v in &triangle {
            upper = upper.min(poly.distance_to_local_point(*v, true));
        }
        for (i, a) in corners.iter().enumerate() {
            for b in &corners[i + 1..] {
                for k in 0..3 {
                    let (c, d) = (triangle[k], triangle[(k + 1) % 3]);
                    let squared =
                        segment_segment_distance_squared(&point(a), &point(b), &point(&c), &point(&d));
                    upper = upper.min(squared.sqrt());
                }
            }
        }
        assert!(upper < 1e-4, "{upper}");
        let here = Pose::IDENTITY;
        assert!(within(&here, &polytope, &here, &mesh, 1e-4));
        assert!(within(&here, &mesh, &here, &polytope, 1e-4));
        // and not within once moved a centimetre clear of the triangle
        let away = Pose::from_translation(Vector::new(0.05, 0.0, 0.0));
        let clear = query::distance(&away, &*polytope, &here, &*mesh)
            .unwrap()
            .distance;
        assert!(clear > 1e-3, "{clear}");
        assert!(!within(&away, &polytope, &here, &mesh, 1e-4));
    }
}
