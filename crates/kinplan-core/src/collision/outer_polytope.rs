//! A polytope of few faces around a mesh's convex hull, fitted when a
//! robot model loads: the exact collision test's support queries cost
//! about one dot product per vertex, and a hull of a tessellated link has
//! several times the vertices of a polytope that refuses little more.
//!
//! The polytope is an intersection of half-spaces `n·x ≤ h(n) + margin`
//! whose planes support the points (`h(n) = maxᵢ n·pᵢ`), so it holds the
//! points and therefore their hull, whichever planes are chosen. Greedy
//! choice, as the offline `fit_covers.py` of the built-in robots does: it
//! starts from the six axis directions (a box) and adds, one at a time,
//! the hull face plane that leaves the least volume, until `PLANES` planes
//! or until no plane cuts anything. Each candidate is tried by clipping
//! the current polytope (faces as vertex loops, Sutherland–Hodgman per
//! face, the cut closed by a cap face) and summing the tetrahedra from an
//! interior point to its fan triangles.
//!
//! Cost: at most `PLANES − 6` rounds over at most `MAX_CANDIDATES` planes,
//! each clip linear in the polytope's size (at most `PLANES` faces).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{Point3, Vector3};

/// Most planes of a fitted polytope (the six of the box included).
pub(crate) const PLANES: usize = 20;
/// Most hull face planes tried each round (the largest faces first).
pub(crate) const MAX_CANDIDATES: usize = 384;
/// Each plane is moved out by this much (m), so rounding in the corners'
/// intersection cannot leave a point of the mesh outside.
pub(crate) const MARGIN: f64 = 1e-5;

/// A candidate plane's bound on its gain, ordered by gain, then by index
/// (of equal gains the later candidate first).
#[derive(Debug, Clone, Copy)]
struct Bound {
    gain: f64,
    index: usize,
}

impl Ord for Bound {
    fn cmp(&self, other: &Self) -> Ordering {
        self.gain
            .total_cmp(&other.gain)
            .then(self.index.cmp(&other.index))
    }
}

impl PartialOrd for Bound {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Bound {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Bound {}

/// A convex polytope as its faces, each a loop of corners in cyclic order.
#[derive(Debug, Clone)]
struct Polytope {
    faces: Vec<Vec<Point3<f64>>>,
    /// Two points closer than this (m) are one.
    tol: f64,
}

impl Polytope {
    /// The box `[lo, hi]`.
    fn cuboid(lo: Vector3<f64>, hi: Vector3<f64>, tol: f64) -> Self {
        let mut faces = Vec::with_capacity(6);
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for side in [lo[axis], hi[axis]] {
                let corner = |a: f64, b: f64| {
                    let mut p = Point3::origin();
                    p[axis] = side;
                    p[u] = a;
                    p[v] = b;
                    p
                };
                faces.push(vec![
                    corner(lo[u], lo[v]),
                    corner(hi[u], lo[v]),
                    corner(hi[u], hi[v]),
                    corner(lo[u], hi[v]),
                ]);
            }
        }
        Self { faces, tol }
    }

    /// The distinct corners.
    fn corners(&self) -> Vec<Point3<f64>> {
        let mut out: Vec<Point3<f64>> = Vec::new();
        for p in self.faces.iter().flatten() {
            if !out.iter().any(|q| (q - p).norm() <= self.tol) {
                out.push(*p);
            }
        }
        out
    }

    /// The mean of the faces' corners (a convex combination of corners,
    /// so inside).
    fn inner_point(&self) -> Point3<f64> {
        let (sum, count) = self
            .faces
            .iter()
            .flatten()
            .fold((Vector3::zeros(), 0usize), |(s, k), p| (s + p.coords, k + 1));
        Point3::from(sum / count.max(1) as f64)
    }

    /// Σ over faces and their fan triangles of `|det(a − c, b − c, d − c)| / 6`,
    /// `c` an inner point (every face is convex and seen from inside, so
    /// orientation does not matter).
    fn volume(&self) -> f64 {
        let c = self.inner_point();
        let mut six = 0.0;
        for face in &self.faces {
            for k in 1..face.len().saturating_sub(1) {
                six += (face[0] - c).dot(&(face[k] - c).cross(&(face[k + 1] - c))).abs();
            }
        }
        six / 6.0
    }

    /// Whether some corner lies beyond the plane `n·x = h` (by more than `tol`).
    fn reaches_past(&self, n: &Vector3<f64>, h: f64) -> bool {
        self.faces
            .iter()
            .flatten()
            .any(|p| n.dot(&p.coords) - h > self.tol)
    }

    /// The part on the side `n·x ≤ h` (`n` a unit vector): each face loop
    /// clipped, and the cut closed by a cap face of the points on the plane.
    fn clipped(&self, n: &Vector3<f64>, h: f64) -> Self {
        let mut faces = Vec::with_capacity(self.faces.len() + 1);
        let mut cap: Vec<Point3<f64>> = Vec::new();
        for face in &self.faces {
            let mut kept: Vec<Point3<f64>> = Vec::with_capacity(face.len() + 1);
            for (k, a) in face.iter().enumerate() {
                let b = face[(k + 1) % face.len()];
                let (da, db) = (n.dot(&a.coords) - h, n.dot(&b.coords) - h);
                let (a_in, b_in) = (da <= self.tol, db <= self.tol);
                if a_in {
                    push_distinct(&mut kept, *a, self.tol);
                    if da.abs() <= self.tol {
                        push_distinct(&mut cap, *a, self.tol);
                    }
                }
                if a_in != b_in {
                    let t = (da / (da - db)).clamp(0.0, 1.0);
                    let cut = a + (b - a) * t;
                    push_distinct(&mut kept, cut, self.tol);
                    push_distinct(&mut cap, cut, self.tol);
                }
            }
            if kept.len() > 1 && (kept[0] - kept[kept.len() - 1]).norm() <= self.tol {
                kept.pop();
            }
            if kept.len() >= 3 {
                faces.push(kept);
            }
        }
        if cap.len() >= 3 {
            faces.push(in_cyclic_order(cap, n));
        }
        Self { faces, tol: self.tol }
    }
}

fn push_distinct(points: &mut Vec<Point3<f64>>, p: Point3<f64>, tol: f64) {
    if !points.iter().any(|q| (q - p).norm() <= tol) {
        points.push(p);
    }
}

/// Points of one plane (normal `n`) ordered by angle about their mean.
fn in_cyclic_order(mut points: Vec<Point3<f64>>, n: &Vector3<f64>) -> Vec<Point3<f64>> {
    let mean = Point3::from(points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64);
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = n.cross(&helper).normalize();
    let v = n.cross(&u);
    let angle = |p: &Point3<f64>| {
        let d = p - mean;
        d.dot(&v).atan2(d.dot(&u))
    };
    points.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    points
}

/// Where the fit starts: the points' box grown by [`MARGIN`], and the
/// candidate planes `(n, h)`: the distinct finite directions of
/// `face_normals` (at most [`MAX_CANDIDATES`]), each through the farthest
/// point along it plus [`MARGIN`].
fn box_and_planes(
    points: &[Point3<f64>],
    face_normals: &[Vector3<f64>],
) -> (Polytope, Vec<(Vector3<f64>, f64)>) {
    let support = |n: &Vector3<f64>| {
        points
            .iter()
            .map(|p| n.dot(&p.coords))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let lo = points
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |s, p| s.inf(&p.coords));
    let hi = points
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |s, p| s.sup(&p.coords));
    let tol = 1e-9 * (hi - lo).norm().max(1e-6);
    let margin = Vector3::repeat(MARGIN);
    let poly = Polytope::cuboid(lo - margin, hi + margin, tol);
    let mut candidates: Vec<(Vector3<f64>, f64)> = Vec::new();
    for n in face_normals {
        let n = n.normalize();
        if !n.iter().all(|x| x.is_finite()) || candidates.iter().any(|(m, _)| (m - n).norm() < 1e-9) {
            continue;
        }
        candidates.push((n, support(&n) + MARGIN));
        if candidates.len() == MAX_CANDIDATES {
            break;
        }
    }
    (poly, candidates)
}

/// The corners of the polytope of the module doc around `points`, with
/// `face_normals` (unit outward normals of the points' hull, largest faces
/// first) as the candidate planes; `None` when the points are empty or
/// not finite.
pub(crate) fn outer_polytope(
    points: &[Point3<f64>],
    face_normals: &[Vector3<f64>],
) -> Option<Vec<Point3<f64>>> {
    if points.is_empty() || !points.iter().all(|p| p.coords.iter().all(|x| x.is_finite())) {
        return None;
    }
    let (mut poly, mut candidates) = box_and_planes(points, face_normals);
    // Lazy greedy: what a plane cuts from a polytope only shrinks as the
    // polytope shrinks, so a gain found in an earlier round bounds the gain
    // now, and a plane whose fresh gain is at least every other's bound is
    // the greedy choice. The bounds sit in a heap, rebuilt each round (a
    // chosen plane leaves the list by `swap_remove`).
    let mut bound = vec![f64::INFINITY; candidates.len()];
    for _ in 6..PLANES {
        let volume = poly.volume();
        let mut heap: BinaryHeap<Bound> = bound
            .iter()
            .enumerate()
            .map(|(index, &gain)| Bound { gain, index })
            .collect();
        let chosen = loop {
            let Some(Bound { gain, index: k }) = heap.pop() else {
                break None;
            };
            if gain <= 0.0 {
                break None;
            }
            let (n, h) = candidates[k];
            let cut = poly.reaches_past(&n, h).then(|| poly.clipped(&n, h));
            // a gain that is not a number counts as none, so the round ends
            let gain = cut.as_ref().map_or(0.0, |c| volume - c.volume());
            bound[k] = if gain.is_nan() {
                0.0
            } else {
                gain.clamp(0.0, f64::MAX)
            };
            let others = heap.peek().map_or(0.0, |b| b.gain.max(0.0));
            if bound[k] > 0.0 && bound[k] >= others {
                break cut.map(|c| (k, c));
            }
            heap.push(Bound {
                gain: bound[k],
                index: k,
            });
        };
        let Some((k, cut)) = chosen else { break };
        poly = cut;
        candidates.swap_remove(k);
        bound.swap_remove(k);
    }
    Some(poly.corners())
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{MARGIN, PLANES, Polytope, box_and_planes, outer_polytope};
    use crate::collision::tests::random_vector;

    /// Volume of the unit cube cut by `x + y + z ≤ 1`: the corner
    /// tetrahedron of volume 1/6 is what remains.
    #[test]
    fn a_cut_cube_has_the_volume_of_its_part() {
        let cube = Polytope::cuboid(Vector3::zeros(), Vector3::repeat(1.0), 1e-12);
        assert!((cube.volume() - 1.0).abs() < 1e-12);
        let n = Vector3::repeat(1.0).normalize();
        let corner = cube.clipped(&n, 1.0 / 3f64.sqrt());
        assert!((corner.volume() - 1.0 / 6.0).abs() < 1e-12, "{}", corner.volume());
        assert_eq!(corner.corners().len(), 4);
        // the cube less the tetrahedron at the far corner, cut through three
        // of its corners: seven corners are left
        let rest = cube.clipped(&n, 2.0 / 3f64.sqrt());
        assert!((rest.volume() - 5.0 / 6.0).abs() < 1e-12, "{}", rest.volume());
        assert_eq!(rest.corners().len(), 7);
    }

    /// Points on a sphere of radius 1: the polytope holds every point (by
    /// at least the margin), has at most 36 corners (20 planes, each corner
    /// on three), and is much nearer the ball's volume than the box is.
    #[test]
    fn a_fitted_polytope_holds_the_points_and_cuts_the_box() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let points: Vec<Point3<f64>> = (0..400)
            .map(|_| {
                let v = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                Point3::from(v.normalize())
            })
            .collect();
        // candidate normals: the directions of the points (a sphere's face normals)
        let normals: Vec<Vector3<f64>> = points.iter().map(|p| p.coords).collect();
        let corners = outer_polytope(&points, &normals).unwrap();
        assert!(corners.len() <= 36, "{} corners", corners.len());
        let hull = parry3d_f64::transformation::convex_hull(
            &corners
                .iter()
                .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
                .collect::<Vec<_>>(),
        );
        let (verts, tris) = hull;
        for p in &points {
            for t in &tris {
                let [a, b, c] = t.map(|i| verts[i as usize]);
                let (a, b, c) = (
                    Vector3::new(a.x, a.y, a.z),
                    Vector3::new(b.x, b.y, b.z),
                    Vector3::new(c.x, c.y, c.z),
                );
                let n = (b - a).cross(&(c - a)).normalize();
                assert!(n.dot(&(p.coords - a)) <= -0.999 * MARGIN, "{p:?} outside");
            }
        }
        let volume: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| verts[i as usize]);
                Vector3::new(a.x, a.y, a.z)
                    .dot(&Vector3::new(b.x, b.y, b.z).cross(&Vector3::new(c.x, c.y, c.z)))
                    / 6.0
            })
            .sum();
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(volume < 1.45 * ball && volume > ball, "volume {volume}");
    }

    /// The greedy choice made plainly from the same box and planes, every
    /// candidate's cut measured in every round: the corners of the lazy fit
    /// are the same, bit for bit, on random clouds (each its own directions
    /// as the candidate planes).
    #[test]
    fn the_lazy_fit_makes_the_plain_greedy_choice() {
        fn plain_greedy(points: &[Point3<f64>], normals: &[Vector3<f64>]) -> Vec<Point3<f64>> {
            let (mut poly, mut planes) = box_and_planes(points, normals);
            for _ in 6..PLANES {
                let volume = poly.volume();
                let gains: Vec<f64> = planes
                    .iter()
                    .map(|(n, h)| match poly.reaches_past(n, *h) {
                        true => (volume - poly.clipped(n, *h).volume()).max(0.0),
                        false => 0.0,
                    })
                    .collect();
                let Some(k) = (0..gains.len()).max_by(|&a, &b| gains[a].total_cmp(&gains[b])) else {
                    break;
                };
                if gains[k] <= 0.0 {
                    break;
                }
                poly = poly.clipped(&planes[k].0, planes[k].1);
                planes.swap_remove(k);
            }
            poly.corners()
        }
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for case in 0..40 {
            let count = rng.random_range(8..200);
            let stretch = Vector3::new(
                rng.random_range(0.01..0.3),
                rng.random_range(0.01..0.3),
                rng.random_range(0.01..0.3),
            );
            let points: Vec<Point3<f64>> = (0..count)
                .map(|_| Point3::from(random_vector(&mut rng, 1.0).normalize().component_mul(&stretch)))
                .collect();
            let normals: Vec<Vector3<f64>> =
                points.iter().map(|p| p.coords.component_div(&stretch)).collect();
            let lazy = outer_polytope(&points, &normals).unwrap();
            assert_eq!(lazy, plain_greedy(&points, &normals), "case {case}");
        }
    }

    #[test]
    fn no_points_no_polytope() {
        assert!(outer_polytope(&[], &[Vector3::x()]).is_none());
        assert!(outer_polytope(&[Point3::new(f64::NAN, 0.0, 0.0)], &[Vector3::x()]).is_none());
    }
}
