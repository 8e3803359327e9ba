//! A yes-or-no GJK for a robot polytope against a box, segment, cylinder
//! or another polytope: are the two within `m` of each other?
//!
//! The distance between convex `A` and `B` is the distance from the origin
//! to their difference `C = A − B`, whose support along `d` is
//! `s_C(d) = s_A(d) − s_B(−d)` (Gilbert, Johnson and Keerthi, IEEE J.
//! Robotics and Automation 4(2), 1988). Each step takes the point `v` of the
//! current simplex nearest the origin and the support point
//! `w = s_C(−v)`; then
//!
//! - `|v| ≤ m`: `v` is a convex combination of points of `C`, so the shapes
//!   are within `m` — **within**;
//! - `v·w > (m + ε)|v|`: every `x ∈ C` has `|x| ≥ (v/|v|)·x ≥ v·w/|v| > m`,
//!   so `v/|v|` is a separating direction with a gap beyond `m` —
//!   **apart**. This is the only way to answer apart, and the two support
//!   points it rests on are exact evaluations, so the answer never depends
//!   on the simplex arithmetic being right;
//! - otherwise `w` joins the simplex, which is reduced to the smallest face
//!   holding its point nearest the origin (the Voronoi-region tests of
//!   Ericson, *Real-Time Collision Detection*, 2005, §5.1.5 and §5.1.6).
//!
//! The origin inside the simplex, a step that gains nothing (the distance
//! lies between `v·w/|v|` and `|v|`, which straddle `m` to rounding) or
//! [`MAX_STEPS`] steps answer within: the safe side. Unlike a full
//! closest-points query it stops at the first step that decides.
//!
//! Everything runs in the polytope's own frame: its support is a scan of
//! its corners; the other shape is carried into that frame once.
//!
//! A warm start ([`within_keyed`] inside a [`WarmChecks`]) first tries the
//! direction `d` that last proved the same pair apart: `d·w > (m + ε)|d|`
//! for `w = s_C(−d)` is the same certificate; otherwise `w` starts the
//! simplex.

use std::cell::RefCell;
use std::marker::PhantomData;

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use super::fast::LeafFast;

/// Steps before an undecided query answers within.
const MAX_STEPS: usize = 32;
/// Added to every gap the separating direction must beat (m), for rounding.
const SLACK: f64 = 1e-9;

/// The other shape of a query, in the polytope's frame. A sphere is a
/// segment of equal ends, and the radius of a swept shape is added to the
/// margin.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Convex<'a> {
    /// The box `[−half, half]` turned by `turn` and moved to `center`.
    Box {
        turn: Matrix3<f64>,
        center: Vector3<f64>,
        half: Vector3<f64>,
    },
    /// The segment `[a, b]`.
    Segment { a: Vector3<f64>, b: Vector3<f64> },
    /// The solid cylinder of cap centres `a`, `b` (unit axis `w`) and
    /// radius `r`.
    Cylinder {
        a: Vector3<f64>,
        b: Vector3<f64>,
        w: Vector3<f64>,
        r: f64,
    },
    /// Another polytope's corners (its frame), turned by `turn` and moved
    /// by `shift`.
    Polytope {
        corners: &'a Corners,
        turn: Matrix3<f64>,
        shift: Vector3<f64>,
    },
}

impl<'a> Convex<'a> {
    /// A scene leaf's closed form seen from a polytope at `pose` (world),
    /// with the radius to add to the margin; `None` for a leaf without one
    /// or a cylinder of no length.
    pub(crate) fn of_leaf(pose: &Isometry3<f64>, leaf: &LeafFast) -> Option<(Self, f64)> {
        let inv = pose.inverse();
        match *leaf {
            LeafFast::Box { pose: box_pose, half } => {
                let rel = inv * box_pose;
                Some((
                    Convex::Box {
                        turn: rel.rotation.to_rotation_matrix().into_inner(),
                        center: rel.translation.vector,
                        half,
                    },
                    0.0,
                ))
            }
            LeafFast::Swept { a, b, r } => Some((
                Convex::Segment {
                    a: (inv * a).coords,
                    b: (inv * b).coords,
                },
                r,
            )),
            LeafFast::Cylinder { outer: (a, b, r), .. } => {
                let (a, b) = ((inv * a).coords, (inv * b).coords);
                let w = (b - a).try_normalize(1e-12)?;
                Some((Convex::Cylinder { a, b, w, r }, 0.0))
            }
            LeafFast::None => None,
        }
    }

    /// Another polytope's corners, its frame at `other` (world), seen from
    /// a polytope at `pose`.
    pub(crate) fn of_corners(pose: &Isometry3<f64>, corners: &'a Corners, other: &Isometry3<f64>) -> Self {
        let rel = pose.inverse() * other;
        Convex::Polytope {
            corners,
            turn: rel.rotation.to_rotation_matrix().into_inner(),
            shift: rel.translation.vector,
        }
    }

    /// The point of the shape farthest along `d`.
    #[inline]
    fn support(&self, d: &Vector3<f64>) -> Vector3<f64> {
        match self {
            Convex::Box { turn, center, half } => {
                let local = turn.tr_mul(d);
                let corner = Vector3::new(
                    half.x.copysign(local.x),
                    half.y.copysign(local.y),
                    half.z.copysign(local.z),
                );
                center + turn * corner
            }
            Convex::Segment { a, b } => {
                if d.dot(a) >= d.dot(b) {
                    *a
                } else {
                    *b
                }
            }
            Convex::Cylinder { a, b, w, r } => {
                let cap = if d.dot(w) >= 0.0 { b } else { a };
                let across = d - w * d.dot(w);
                match across.try_normalize(1e-300) {
                    Some(u) => cap + u * *r,
                    None => *cap,
                }
            }
            Convex::Polytope { corners, turn, shift } => {
                let local = turn.tr_mul(d);
                turn * corners.farthest(&local) + shift
            }
        }
    }

    /// Some point of the shape.
    fn any_point(&self) -> Vector3<f64> {
        match self {
            Convex::Box { center, .. } => *center,
            Convex::Segment { a, .. } | Convex::Cylinder { a, .. } => *a,
            Convex::Polytope { corners, turn, shift } => turn * corners.first() + shift,
        }
    }
}

/// Columns a support scan takes at once.
const LANES: usize = 4;

/// A polytope's corners in columns (its frame), padded to a whole number
/// of [`LANES`] by repeating the first corner, so that a scan over them
/// runs in vector lanes.
#[derive(Debug, Clone)]
pub(crate) struct Corners {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    /// A hash of the corners' coordinates: names the shape in the warm
    /// start's table ([`pair_key`]) the same way in every run.
    key: u64,
}

impl Corners {
    /// The columns of `points` (non-empty).
    pub(crate) fn new(points: &[Point3<f64>]) -> Self {
        let padded = points.len().div_ceil(LANES) * LANES;
        let column = |k: usize| {
            let mut c: Vec<f64> = points.iter().map(|p| p[k]).collect();
            c.resize(padded, points[0][k]);
            c
        };
        // FNV-1a over the coordinates' bits
        let key = points
            .iter()
            .flat_map(|p| p.coords.iter())
            .fold(0xcbf2_9ce4_8422_2325_u64, |h, v| {
                (h ^ v.to_bits()).wrapping_mul(0x0000_0100_0000_01b3)
            });
        Corners {
            x: column(0),
            y: column(1),
            z: column(2),
            key,
        }
    }

    /// The hash of the corners' coordinates (for [`pair_key`]).
    pub(crate) fn key(&self) -> u64 {
        self.key
    }

    /// The first corner.
    fn first(&self) -> Vector3<f64> {
        Vector3::new(self.x[0], self.y[0], self.z[0])
    }

    /// The corner farthest along `d`: the AVX2 build of the scan when the
    /// CPU has it, the baseline build otherwise (no multiply and add are
    /// fused, so both give the same bits).
    #[inline]
    pub(crate) fn farthest(&self, d: &Vector3<f64>) -> Vector3<f64> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { self.farthest_avx2(d) };
        }
        self.farthest_in(d)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn farthest_avx2(&self, d: &Vector3<f64>) -> Vector3<f64> {
        self.farthest_in(d)
    }

    #[inline(always)]
    fn farthest_in(&self, d: &Vector3<f64>) -> Vector3<f64> {
        let mut best = [f64::NEG_INFINITY; LANES];
        let mut at = [0usize; LANES];
        let columns = self
            .x
            .chunks_exact(LANES)
            .zip(self.y.chunks_exact(LANES))
            .zip(self.z.chunks_exact(LANES));
        for (k, ((x, y), z)) in columns.enumerate() {
            let base = k * LANES;
            for l in 0..LANES {
                let s = d.x * x[l] + d.y * y[l] + d.z * z[l];
                let take = s > best[l];
                best[l] = if take { s } else { best[l] };
                at[l] = if take { base + l } else { at[l] };
            }
        }
        let mut i = at[0];
        let mut reach = best[0];
        for l in 1..LANES {
            if best[l] > reach {
                reach = best[l];
                i = at[l];
            }
        }
        Vector3::new(self.x[i], self.y[i], self.z[i])
    }

    /// The least and greatest `u·c` over the corners `c`.
    #[inline]
    pub(crate) fn extent_along(&self, u: &Vector3<f64>) -> (f64, f64) {
        let mut lo = [f64::INFINITY; LANES];
        let mut hi = [f64::NEG_INFINITY; LANES];
        let columns = self
            .x
            .chunks_exact(LANES)
            .zip(self.y.chunks_exact(LANES))
            .zip(self.z.chunks_exact(LANES));
        for ((x, y), z) in columns {
            for l in 0..LANES {
                let s = u.x * x[l] + u.y * y[l] + u.z * z[l];
                lo[l] = lo[l].min(s);
                hi[l] = hi[l].max(s);
            }
        }
        (
            lo.iter().copied().fold(f64::INFINITY, f64::min),
            hi.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }
}

/// True unless the polytope of `corners` (its frame) and `other` are
/// proved more than `margin` (m, ≥ 0) apart by a separating direction (the
/// module doc).
pub(crate) fn within(corners: &Corners, other: &Convex, margin: f64) -> bool {
    within_from(corners, other, margin, None).0
}

/// [`within`], trying `hint` first as the separating direction, and with
/// the direction that proved the shapes apart (or `None`).
pub(crate) fn within_from(
    corners: &Corners,
    other: &Convex,
    margin: f64,
    hint: Option<Vector3<f64>>,
) -> (bool, Option<Vector3<f64>>) {
    let beyond = margin + SLACK;
    let mut simplex = Simplex::default();
    let mut v = corners.first() - other.any_point();
    if let Some(d) = hint.filter(|d| d.norm_squared() > 0.0) {
        let w = corners.farthest(&-d) - other.support(&d);
        if d.dot(&w) > beyond * d.norm() {
            return (false, Some(d));
        }
        simplex.push(w);
        v = w;
    }
    for _ in 0..MAX_STEPS {
        let vv = v.norm_squared();
        if vv <= margin * margin {
            return (true, None);
        }
        let w = corners.farthest(&-v) - other.support(&v);
        let vw = v.dot(&w);
        if vw > beyond * vv.sqrt() {
            return (false, Some(v));
        }
        if vv - vw <= 1e-12 * vv {
            return (true, None);
        }
        simplex.push(w);
        match simplex.reduce() {
            Some(nearest) => v = nearest,
            None => return (true, None),
        }
    }
    (true, None)
}

/// Slots of the per-thread table of separating directions.
const HINT_SLOTS: usize = 512;

/// Separating directions kept on one thread while a [`WarmChecks`] lasts.
struct Hints {
    /// Open [`WarmChecks`] on this thread (hints are kept only while > 0).
    depth: u32,
    /// Which opening of the outermost [`WarmChecks`] a slot was filled in.
    generation: u64,
    /// Per slot: the pair's key, the generation, the direction.
    slots: [(u64, u64, [f64; 3]); HINT_SLOTS],
}

thread_local! {
    static HINTS: RefCell<Hints> = const {
        RefCell::new(Hints {
            depth: 0,
            generation: 0,
            slots: [(0, 0, [0.0; 3]); HINT_SLOTS],
        })
    };
}

/// While a value of this type lives, the exact tests on this thread start
/// from the direction that last proved the same pair of shapes apart in
/// that time (nearby states of one search are separated along nearly the
/// same direction, so one support step often settles the pair). The
/// verdict never rests on a hint, but where the search cannot decide
/// (its step limit) a hint may prove a pair apart that a cold start
/// leaves "within", so hold it only around work done in one sequence on
/// one thread (one search, one table row), with no parallel join inside (a
/// thread waiting in a join may run other work meanwhile): that keeps
/// every result a function of the inputs. Opened again inside, it keeps
/// the outer hints.
pub(crate) struct WarmChecks {
    /// Not `Send`: it must end on the thread it began on.
    _thread: PhantomData<*const ()>,
}

impl WarmChecks {
    pub(crate) fn begin() -> Self {
        HINTS.with_borrow_mut(|h| {
            if h.depth == 0 {
                h.generation += 1;
            }
            h.depth += 1;
        });
        WarmChecks { _thread: PhantomData }
    }
}

impl Drop for WarmChecks {
    fn drop(&mut self) {
        HINTS.with_borrow_mut(|h| h.depth -= 1);
    }
}

/// A key naming a pair of shapes for [`within_keyed`] from the keys of the
/// two (a polytope's [`Corners::key`], a scene leaf's place among the
/// leaves): made of the inputs alone, not of where they sit in memory, so
/// which hint a test finds is the same in every run.
pub(crate) fn pair_key(a: u64, b: u64) -> u64 {
    a ^ b.rotate_left(29).wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// [`within`] for the pair of shapes named by `key`, started from the
/// direction that last proved them apart within the current
/// [`WarmChecks`] on this thread (a cold start outside one).
pub(crate) fn within_keyed(corners: &Corners, other: &Convex, margin: f64, key: u64) -> bool {
    let slot =
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (u64::BITS - HINT_SLOTS.trailing_zeros())) as usize;
    let (warm, hint) = HINTS.with_borrow(|h| {
        let (k, generation, d) = h.slots[slot];
        let hint = (h.depth > 0 && k == key && generation == h.generation).then(|| Vector3::from(d));
        (h.depth > 0, hint)
    });
    let (near, apart_along) = within_from(corners, other, margin, hint);
    if let Some(d) = apart_along.filter(|_| warm) {
        HINTS.with_borrow_mut(|h| h.slots[slot] = (key, h.generation, [d.x, d.y, d.z]));
    }
    near
}

/// Up to four points of the difference set.
#[derive(Default)]
struct Simplex {
    points: [Vector3<f64>; 4],
    len: usize,
}

impl Simplex {
    fn push(&mut self, w: Vector3<f64>) {
        self.points[self.len] = w;
        self.len += 1;
    }

    /// Keep the smallest face holding the simplex's point nearest the
    /// origin and return that point; `None` when the origin is inside a
    /// tetrahedron.
    fn reduce(&mut self) -> Option<Vector3<f64>> {
        let p = self.points;
        let (nearest, kept) = match self.len {
            1 => (p[0], Kept::of(&[0])),
            2 => on_segment(&p, 0, 1),
            3 => on_triangle(&p, 0, 1, 2),
            _ => on_tetrahedron(&p)?,
        };
        self.len = kept.len;
        for (k, &i) in kept.index[..kept.len].iter().enumerate() {
            self.points[k] = p[i];
        }
        Some(nearest)
    }
}

/// The simplex points a nearest point lies on.
#[derive(Clone, Copy)]
struct Kept {
    index: [usize; 3],
    len: usize,
}

impl Kept {
    fn of(index: &[usize]) -> Self {
        let mut k = Kept {
            index: [0; 3],
            len: index.len(),
        };
        k.index[..index.len()].copy_from_slice(index);
        k
    }
}

/// The point of segment `[p[i], p[j]]` nearest the origin.
fn on_segment(p: &[Vector3<f64>; 4], i: usize, j: usize) -> (Vector3<f64>, Kept) {
    let (a, b) = (p[i], p[j]);
    let ab = b - a;
    let t = -a.dot(&ab);
    if t <= 0.0 {
        return (a, Kept::of(&[i]));
    }
    let len2 = ab.norm_squared();
    if t >= len2 {
        return (b, Kept::of(&[j]));
    }
    (a + ab * (t / len2), Kept::of(&[i, j]))
}

/// The point of triangle `p[i] p[j] p[k]` nearest the origin (Ericson
/// §5.1.5, the query point at the origin).
fn on_triangle(p: &[Vector3<f64>; 4], i: usize, j: usize, k: usize) -> (Vector3<f64>, Kept) {
    let (a, b, c) = (p[i], p[j], p[k]);
    let (ab, ac) = (b - a, c - a);
    let (d1, d2) = (-ab.dot(&a), -ac.dot(&a));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Kept::of(&[i]));
    }
    let (d3, d4) = (-ab.dot(&b), -ac.dot(&b));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Kept::of(&[j]));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), Kept::of(&[i, j]));
    }
    let (d5, d6) = (-ab.dot(&c), -ac.dot(&c));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Kept::of(&[k]));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), Kept::of(&[i, k]));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return (
            b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))),
            Kept::of(&[j, k]),
        );
    }
    let scale = 1.0 / (va + vb + vc);
    (a + ab * (vb * scale) + ac * (vc * scale), Kept::of(&[i, j, k]))
}

/// The point of tetrahedron `p` nearest the origin (Ericson §5.1.6: the
/// nearest of the faces whose plane has the origin outside); `None` when
/// the origin is inside every face plane.
fn on_tetrahedron(p: &[Vector3<f64>; 4]) -> Option<(Vector3<f64>, Kept)> {
    const FACES: [(usize, usize, usize, usize); 4] = [(0, 1, 2, 3), (0, 2, 3, 1), (0, 3, 1, 2), (1, 3, 2, 0)];
    let mut best: Option<(f64, Vector3<f64>, Kept)> = None;
    for (i, j, k, opposite) in FACES {
        let normal = (p[j] - p[i]).cross(&(p[k] - p[i]));
        let origin_side = -normal.dot(&p[i]);
        let other_side = normal.dot(&(p[opposite] - p[i]));
        // the origin outside this face (on the side away from the fourth
        // point), or a flat tetrahedron: every face is a candidate
        if origin_side * other_side < 0.0 || other_side == 0.0 {
            let (q, kept) = on_triangle(p, i, j, k);
            let d = q.norm_squared();
            if best.is_none_or(|(bd, ..)| d < bd) {
                best = Some((d, q, kept));
            }
        }
    }
    best.map(|(_, q, kept)| (q, kept))
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
    use parry3d_f64::query;
    use parry3d_f64::shape::SharedShape;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::{Convex, Corners, WarmChecks, within, within_from, within_keyed};
    use crate::collision::builtin_mesh;
    use crate::collision::convert::{point_from_parry, pose_to_parry, vec_to_parry};
    use crate::collision::tests::{random_pose, random_primitive, random_vector};

    /// The hull of a built-in Panda link: its parry shape and its corners.
    fn link_hull(link: &str) -> (SharedShape, Corners) {
        let mesh = builtin_mesh(&format!("kinplan://builtin/panda/{link}.obj")).unwrap();
        let points: Vec<_> = mesh.vertices.iter().map(|p| vec_to_parry(&p.coords)).collect();
        let shape = SharedShape::convex_hull(&points).unwrap();
        let corners: Vec<_> = shape
            .as_convex_polyhedron()
            .unwrap()
            .points()
            .iter()
            .map(|p| point_from_parry(*p))
            .collect();
        (shape, Corners::new(&corners))
    }

    /// A unit cube's corners.
    fn cube_points() -> Vec<Point3<f64>> {
        (0..8)
            .map(|i| {
                let side = |bit: usize| if i & bit == 0 { -0.5 } else { 0.5 };
                Point3::new(side(1), side(2), side(4))
            })
            .collect()
    }

    /// The support scan finds a corner as far along the direction as any
    /// (a plain loop over the hull's points), and the vector build picks
    /// the same corner as the portable one: 10,000 random directions on
    /// each of five link hulls.
    #[test]
    fn the_support_scan_finds_the_farthest_corner_in_either_build() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for link in ["link_1", "link_3", "link_5", "link_7", "panda_hand"] {
            let (shape, corners) = link_hull(link);
            let points = shape.as_convex_polyhedron().unwrap().points().to_vec();
            for _ in 0..10_000 {
                let d = random_pose(&mut rng, 1.0).translation.vector;
                let found = corners.farthest(&d);
                let best = points
                    .iter()
                    .map(|p| d.dot(&point_from_parry(*p).coords))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert_eq!(d.dot(&found), best, "{link} along {d:?}");
                assert_eq!(found, corners.farthest_in(&d), "{link} along {d:?}");
            }
        }
    }

    /// Hand-placed shapes 0.1 m from a unit cube: within a margin of
    /// 0.11 m, apart under 0.09 m; touching is within at margin 0.
    #[test]
    fn a_gap_of_a_tenth_is_within_eleven_hundredths_and_apart_under_nine() {
        let corners = Corners::new(&cube_points());
        let turned = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7)
            .to_rotation_matrix()
            .into_inner();
        // a box whose face is 0.1 m beyond the cube's +x face
        let aligned = Convex::Box {
            turn: nalgebra::Matrix3::identity(),
            center: Vector3::new(0.5 + 0.1 + 0.2, 0.3, -0.1),
            half: Vector3::new(0.2, 0.2, 0.2),
        };
        // a segment 0.1 m above the cube's top face, across it
        let segment = Convex::Segment {
            a: Vector3::new(-2.0, 0.1, 0.6),
            b: Vector3::new(2.0, -0.1, 0.6),
        };
        // a cylinder along y whose side is 0.1 m from the cube's −x face
        let cylinder = Convex::Cylinder {
            a: Vector3::new(-0.5 - 0.1 - 0.3, -1.0, 0.0),
            b: Vector3::new(-0.5 - 0.1 - 0.3, 1.0, 0.0),
            w: Vector3::y(),
            r: 0.3,
        };
        // the cube turned, its highest point 0.1 m under the cube
        let top = cube_points()
            .iter()
            .map(|c| (turned * c.coords).z)
            .fold(f64::NEG_INFINITY, f64::max);
        let polytope = Convex::Polytope {
            corners: &corners,
            turn: turned,
            shift: Vector3::new(0.05, -0.02, -0.5 - 0.1 - top),
        };
        for other in [aligned, segment, cylinder, polytope] {
            assert!(within(&corners, &other, 0.11), "{other:?} within 0.11 m");
            assert!(!within(&corners, &other, 0.09), "{other:?} apart under 0.09 m");
            assert!(!within(&corners, &other, 0.0), "{other:?} apart at margin 0");
        }
        let touching = Convex::Segment {
            a: Vector3::new(0.5, -2.0, 0.0),
            b: Vector3::new(0.5, 2.0, 0.0),
        };
        let inside = Convex::Box {
            turn: turned,
            center: Vector3::new(0.1, 0.0, 0.0),
            half: Vector3::new(0.1, 0.1, 0.1),
        };
        assert!(within(&corners, &touching, 0.0), "touching is within");
        assert!(within(&corners, &inside, 0.0), "a box inside is within");
    }

    /// Against parry's distance, an independent implementation: the test
    /// never answers apart for shapes within the margin, and answers apart
    /// for all but a handful of the shapes more than a micrometre beyond
    /// it. The built-in Panda's link hulls at random poses against random
    /// scene boxes, cylinders, capsules and spheres and against each other,
    /// margins 0, 5 mm and 2 cm.
    #[test]
    fn apart_only_beyond_the_margin_and_almost_always_there() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let links = ["link_1", "link_3", "link_5", "link_7", "panda_hand"];
        let hulls: Vec<_> = links.iter().map(|l| link_hull(l)).collect();
        let margins = [0.0, 0.005, 0.02];
        let (mut beyond, mut proved, mut close) = (0usize, 0usize, 0usize);
        let mut judge = |d: f64, margin: f64, says_within: bool, what: &str| {
            assert!(
                says_within || d > margin,
                "{what}: apart at distance {d}, margin {margin}"
            );
            if d > margin + 1e-6 {
                beyond += 1;
                proved += !says_within as usize;
            } else {
                close += 1;
            }
        };
        for (shape, corners) in &hulls {
            for _ in 0..40 {
                let world = random_primitive(&mut rng, 0.25);
                let leaf = &world.leaves[0];
                for _ in 0..100 {
                    let at = random_pose(&mut rng, 0.25);
                    let d = query::distance(&pose_to_parry(&at), &**shape, &leaf.pose, &*leaf.shape)
                        .unwrap()
                        .distance;
                    let (other, radius) = Convex::of_leaf(&at, &leaf.fast).expect("a closed form");
                    for margin in margins {
                        judge(d, margin, within(corners, &other, margin + radius), "leaf");
                    }
                }
            }
            for (other_shape, other_corners) in &hulls {
                for _ in 0..400 {
                    let (at, other_at) = (random_pose(&mut rng, 0.2), random_pose(&mut rng, 0.2));
                    let d = query::distance(
                        &pose_to_parry(&at),
                        &**shape,
                        &pose_to_parry(&other_at),
                        &**other_shape,
                    )
                    .unwrap()
                    .distance;
                    let other = Convex::of_corners(&at, other_corners, &other_at);
                    for margin in margins {
                        judge(d, margin, within(corners, &other, margin), "polytope");
                    }
                }
            }
        }
        assert!(beyond > 20_000 && close > 5_000, "{beyond} beyond, {close} close");
        assert!(proved * 1000 >= beyond * 999, "{proved} of {beyond} proved apart");
    }

    /// Warm starts against parry's distance: link hulls walked in small
    /// steps (5 mm, 0.02 rad) past random primitives inside a
    /// [`WarmChecks`], so each test starts from the last step's separating
    /// direction, and each placement also tried from a random direction
    /// (a wrong hint). Never apart within the margin; apart for all but a
    /// handful beyond it.
    #[test]
    fn a_warm_start_right_or_wrong_keeps_the_verdict_sound() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let _warm = WarmChecks::begin();
        let (mut beyond, mut proved) = (0usize, 0usize);
        for link in ["link_1", "link_5", "panda_hand"] {
            let (shape, corners) = link_hull(link);
            for walk in 0..30 {
                let world = random_primitive(&mut rng, 0.25);
                let leaf = &world.leaves[0];
                let mut at = random_pose(&mut rng, 0.25);
                let key = 1 + walk;
                for _ in 0..100 {
                    let step = Isometry3::new(random_vector(&mut rng, 0.005), random_vector(&mut rng, 0.02));
                    at *= step;
                    let d = query::distance(&pose_to_parry(&at), &*shape, &leaf.pose, &*leaf.shape)
                        .unwrap()
                        .distance;
                    let (other, radius) = Convex::of_leaf(&at, &leaf.fast).expect("a closed form");
                    let margin = 0.005;
                    let wrong = random_pose(&mut rng, 1.0).translation.vector;
                    let warm = within_keyed(&corners, &other, margin + radius, key);
                    let (from_wrong, _) = within_from(&corners, &other, margin + radius, Some(wrong));
                    for says_within in [warm, from_wrong] {
                        assert!(says_within || d > margin, "{link}: apart at distance {d}");
                        if d > margin + 1e-6 {
                            beyond += 1;
                            proved += !says_within as usize;
                        }
                    }
                }
            }
        }
        assert!(beyond > 5_000, "{beyond} beyond");
        assert!(proved * 1000 >= beyond * 999, "{proved} of {beyond} proved apart");
    }
}
