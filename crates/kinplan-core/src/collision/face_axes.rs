//! A separating-axis filter for a robot polytope (a mesh hull, or the
//! polytope of few faces around one) against a scene box, cylinder,
//! capsule or sphere, or another robot body's box, capsule or sphere,
//! tried before parry's distance query.
//!
//! For any unit axis `u`, if `max_{x∈A} u·x + m < min_{y∈B} u·y`, then every
//! `x ∈ A`, `y ∈ B` have `|y − x| ≥ u·(y − x) > m`: the shapes are more than
//! `m` apart. The axes tried are the polytope's face normals (its support
//! along one is the face plane's offset, `h = maxᵢ n·cᵢ` over its corners)
//! and, against a box, the box's three axes (the polytope's corners
//! projected), against a cylinder its axis. These are the face axes of
//! the separating-axis theorem without the edge-against-edge ones, so the
//! filter proves most separations and never a contact: an undecided pair
//! goes on to GJK. Support of the obstacle along `n`: a box `[−e, e]` in
//! frame `(R, t)`, `n·t ± Σₖ eₖ|n·Rₖ|`; a segment `[a, b]` swept by `r`,
//! `min/max(n·a, n·b) ∓ r`; a cylinder of cap centres `a`, `b`, radius `r`
//! and unit axis `w`, `min/max(n·a, n·b) ∓ r·√(1 − (n·w)²)`.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::shape::SharedShape;

use super::convert::point_from_parry;
use super::fast::LeafFast;
use super::gjk::Corners;

/// Most face planes a polytope may have for the filter to be kept: past
/// that, testing every plane costs about what GJK does.
const MAX_PLANES: usize = 64;
/// Added to every gap the filter must beat (m), for rounding.
const SLACK: f64 = 1e-9;

/// A polytope's corners and face planes `n·x ≤ h` (shape frame).
#[derive(Debug, Clone)]
pub(crate) struct FaceAxes {
    corners: Corners,
    planes: Vec<(Vector3<f64>, f64)>,
}

impl FaceAxes {
    /// The filter of a convex polyhedron with at most [`MAX_PLANES`]
    /// faces; `None` for any other shape.
    pub(crate) fn of(shape: &SharedShape) -> Option<Self> {
        let poly = shape.as_convex_polyhedron()?;
        if poly.faces().len() > MAX_PLANES {
            return None;
        }
        let corners: Vec<Point3<f64>> = poly.points().iter().map(|p| point_from_parry(*p)).collect();
        let planes = poly
            .faces()
            .iter()
            .map(|f| {
                let n = Vector3::new(f.normal.x, f.normal.y, f.normal.z);
                let h = corners
                    .iter()
                    .map(|c| n.dot(&c.coords))
                    .fold(f64::NEG_INFINITY, f64::max);
                (n, h)
            })
            .filter(|(n, h)| n.iter().chain([h]).all(|x| x.is_finite()))
            .collect();
        Some(Self {
            corners: Corners::new(&corners),
            planes,
        })
    }

    /// The polytope's corners (shape frame).
    pub(crate) fn corners(&self) -> &Corners {
        &self.corners
    }

    /// True when the polytope at `pose` (world) is proved more than
    /// `margin` (m, ≥ 0) from the leaf by one of the module doc's axes;
    /// false when undecided.
    pub(crate) fn apart(&self, pose: &Isometry3<f64>, leaf: &LeafFast, margin: f64) -> bool {
        let gap = margin + SLACK;
        match leaf {
            LeafFast::Box { pose: box_pose, half } => {
                self.apart_from_box(&(box_pose.inverse() * pose), half, gap)
            }
            LeafFast::Swept { a, b, r } => {
                let (a, b) = (pose.inverse_transform_point(a), pose.inverse_transform_point(b));
                self.planes
                    .iter()
                    .any(|(n, h)| n.dot(&a.coords).min(n.dot(&b.coords)) - r > h + gap)
            }
            LeafFast::Cylinder { outer: (a, b, r), .. } => {
                let (a, b) = (pose.inverse_transform_point(a), pose.inverse_transform_point(b));
                self.apart_from_cylinder(&a, &b, *r, gap)
            }
            LeafFast::None => false,
        }
    }

    /// Against the box `[−half, half]`; `rel` maps the polytope's frame
    /// into the box's.
    fn apart_from_box(&self, rel: &Isometry3<f64>, half: &Vector3<f64>, gap: f64) -> bool {
        let turn = rel.rotation.to_rotation_matrix().into_inner();
        let t = rel.translation.vector;
        // the box's axes, one at a time: the corners' coordinates along it
        for k in 0..3 {
            let row = turn.row(k).transpose();
            let (lo, hi) = self.corners.extent_along(&row);
            if lo + t[k] > half[k] + gap || hi + t[k] < -half[k] - gap {
                return true;
            }
        }
        // the polytope's face normals: the box's centre and axes in its frame, x = Rᵀ(y − t)
        self.planes.iter().any(|(n, h)| {
            let m = turn * n;
            let reach = half.x * m.x.abs() + half.y * m.y.abs() + half.z * m.z.abs();
            -m.dot(&t) - reach > h + gap
        })
    }

    /// Against the cylinder of cap centres `a`, `b` and radius `r`
    /// (polytope frame).
    fn apart_from_cylinder(&self, a: &Point3<f64>, b: &Point3<f64>, r: f64, gap: f64) -> bool {
        let axis = b - a;
        let Some(w) = axis.try_normalize(1e-12) else {
            return false;
        };
        let (lo, hi) = self.corners.extent_along(&w);
        if hi + gap < w.dot(&a.coords) || lo - gap > w.dot(&b.coords) {
            return true;
        }
        self.planes.iter().any(|(n, h)| {
            let across = (1.0 - n.dot(&w).powi(2)).max(0.0).sqrt();
            n.dot(&a.coords).min(n.dot(&b.coords)) - r * across > h + gap
        })
    }
}

#[cfg(test)]
mod tests {
    use parry3d_f64::query;
    use parry3d_f64::shape::SharedShape;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::FaceAxes;
    use crate::collision::builtin_mesh;
    use crate::collision::convert::{pose_to_parry, vec_to_parry};
    use crate::collision::tests::{random_pose, random_primitive};

    /// The filter never proves apart what parry's distance puts within
    /// the margin, and it decides most pairs parry puts beyond it: the
    /// built-in Panda's link polytopes at random poses against random
    /// boxes, cylinders, capsules and spheres, margins 0 and 1 cm.
    #[test]
    fn face_axes_prove_only_true_separations() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let links = ["link_1", "link_4", "link_5", "link_7", "panda_hand"];
        let (mut apart, mut proved) = (0usize, 0usize);
        for link in links {
            let mesh = builtin_mesh(&format!("kinplan://builtin/panda/{link}.obj")).unwrap();
            let points: Vec<_> = mesh.vertices.iter().map(|p| vec_to_parry(&p.coords)).collect();
            let shape = SharedShape::convex_hull(&points).unwrap();
            let faces = FaceAxes::of(&shape).expect("a polytope of few faces");
            for _ in 0..60 {
                let world = random_primitive(&mut rng, 0.3);
                let leaf = &world.leaves[0];
                for _ in 0..100 {
                    let at = random_pose(&mut rng, 0.3);
                    let d = query::distance(&pose_to_parry(&at), &*shape, &leaf.pose, &*leaf.shape)
                        .unwrap()
                        .distance;
                    for margin in [0.0, 0.01] {
                        let says = faces.apart(&at, &leaf.fast, margin);
                        assert!(
                            !says || d > margin,
                            "{link} {leaf_fast:?}: proved apart at distance {d}",
                            leaf_fast = leaf.fast
                        );
                        if d > margin + 1e-6 {
                            apart += 1;
                            proved += says as usize;
                        }
                    }
                }
            }
        }
        assert!(apart > 10_000 && proved * 10 > apart * 8, "{proved} of {apart}");
    }

    #[test]
    fn only_polytopes_of_few_faces_get_a_filter() {
        assert!(FaceAxes::of(&SharedShape::ball(0.1)).is_none());
        assert!(FaceAxes::of(&SharedShape::cuboid(0.1, 0.2, 0.3)).is_none());
    }
}
