//! A conservative sphere model of a robot, built from its collision bodies
//! when the model loads: every point of every body lies inside some sphere
//! of that body, at two levels.
//!
//! * **Coarse**: one sphere per body, its bounding sphere (the broad-phase
//!   sphere of [`RobotModel`]).
//! * **Fine**: a cover of each shape whose spheres reach at most
//!   [`SphereParams::max_overshoot`] beyond the shape (unless
//!   [`SphereParams::max_per_shape`] caps the count first; the overshoot
//!   reached is recorded per body, [`SphereModel::overshoot`]).
//!
//! Covers per shape (body frame):
//!
//! * sphere: itself;
//! * capsule (segment `[a, b]` of length `L`, radius `r`): `n + 1` spheres
//!   at `a + (i/n)(b − a)`, `i = 0..=n`, of radius `R = √(r² + s²)` with
//!   `s = L/(2n)`. A point `x` of the capsule is within `r` of its nearest
//!   segment point `p`; if `p` is an end, the sphere there holds `x`; else
//!   `x − p` is normal to the axis and some centre `c` lies within `s` of
//!   `p` along it, so `|x − c|² = |x − p|² + |p − c|² ≤ r² + s²`. Each sphere
//!   contains the ball of radius `r` about its centre, which lies in the
//!   capsule, so it reaches at most `R − r` beyond it; `n` is the least with
//!   `R − r ≤` the overshoot;
//! * box of half extents `h`: an `n_x × n_y × n_z` grid of equal cells of
//!   half extents `e = h/n`, one sphere of radius `|e|` per cell (its
//!   circumsphere). A cell contains the ball of radius `min_k e_k` about its
//!   centre, so a sphere reaches at most `|e| − min_k e_k` beyond the box;
//!   the longest cell axis is split until that meets the overshoot;
//! * a mesh's convex hull or a cylinder: the cover of its closed-form bound
//!   (the capsule or box around it, see `bound`), which holds it; a sphere
//!   of centre `c` and radius `ρ` reaches at most `dist(c, shape) + ρ`
//!   beyond the shape, the overshoot recorded;
//! * anything without a bound: the grid over the
//!   shape's bounding box, keeping only the cells that meet the shape
//!   (parry's intersection test; a cell it cannot decide is kept). Every
//!   kept cell holds a point of the shape, so a sphere reaches at most
//!   `2|e|` beyond it.
//!
//! The spheres are what the VAMP planner's hand-made spherized URDFs
//! describe (Thomason, Kingston, Kavraki, "Motions in Microseconds via
//! Vectorized Sampling-Based Planning", ICRA 2024), computed here for any
//! robot at run time. They only ever over-approximate: a state whose spheres
//! are clear of something is clear of it; one whose spheres touch it may
//! still be free, and the exact geometry decides.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::query;
use parry3d_f64::shape::Cuboid;

use super::CollisionError;
use super::convert::{pose_to_parry, vec_to_parry};
use super::fast::RobotFast;
use super::model::{BodyShape, RobotModel};

/// How fine a [`SphereModel`] is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereParams {
    /// Farthest (m) a fine sphere may reach beyond the shape it covers
    /// (default 0.01 m).
    pub max_overshoot: f64,
    /// Most fine spheres per shape (default 64); a shape that needs more
    /// for `max_overshoot` gets coarser spheres.
    pub max_per_shape: usize,
}

impl Default for SphereParams {
    fn default() -> Self {
        SphereParams {
            max_overshoot: 0.01,
            max_per_shape: 64,
        }
    }
}

impl SphereParams {
    /// Largest allowed `max_overshoot` (m).
    pub const MAX_OVERSHOOT: f64 = 1.0;
    /// Largest allowed `max_per_shape`.
    pub const MAX_PER_SHAPE: usize = 4096;

    pub fn validate(&self) -> Result<(), CollisionError> {
        let o = self.max_overshoot;
        if !(o.is_finite() && o > 0.0 && o <= Self::MAX_OVERSHOOT) {
            return Err(CollisionError::OutOfRange {
                field: "max_overshoot".into(),
                value: o,
                lower: 0.0,
                upper: Self::MAX_OVERSHOOT,
            });
        }
        if self.max_per_shape == 0 || self.max_per_shape > Self::MAX_PER_SHAPE {
            return Err(CollisionError::OutOfRange {
                field: "max_per_shape".into(),
                value: self.max_per_shape as f64,
                lower: 1.0,
                upper: Self::MAX_PER_SHAPE as f64,
            });
        }
        Ok(())
    }
}

/// A sphere in a body's frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: Point3<f64>,
    pub radius: f64,
}

/// The coarse and fine spheres of every body of a [`RobotModel`], in body
/// order (see the module doc).
#[derive(Debug, Clone)]
pub struct SphereModel {
    coarse: Vec<Sphere>,
    fine: Vec<Sphere>,
    /// `fine[start[b]..start[b + 1]]` are body `b`'s.
    start: Vec<usize>,
    /// Per body, the farthest its fine spheres can reach beyond it (m).
    overshoot: Vec<f64>,
}

/// The sphere model of the batched checks: coarser than the default (few
/// spheres per body keep the batch cheap; the exact check settles what they
/// leave unsure). Built once per robot model ([`RobotModel::lane_spheres`]).
pub(crate) const LANE_SPHERES: SphereParams = SphereParams {
    max_overshoot: 0.02,
    max_per_shape: 16,
};

impl SphereModel {
    /// The sphere model of `model` (module doc).
    pub fn build(model: &RobotModel, params: &SphereParams) -> Result<Self, CollisionError> {
        params.validate()?;
        let mut coarse = Vec::with_capacity(model.bodies.len());
        let mut fine = Vec::new();
        let mut start = vec![0];
        let mut overshoot = Vec::with_capacity(model.bodies.len());
        for body in &model.bodies {
            coarse.push(Sphere {
                center: Point3::from(body.center),
                radius: body.radius,
            });
            let mut reach = 0.0f64;
            for shape in &body.shapes {
                reach = reach.max(cover(shape, params, &mut fine));
            }
            start.push(fine.len());
            overshoot.push(reach);
        }
        Ok(SphereModel {
            coarse,
            fine,
            start,
            overshoot,
        })
    }

    /// Bodies covered.
    pub fn body_count(&self) -> usize {
        self.coarse.len()
    }

    /// Body `b`'s bounding sphere.
    pub fn coarse(&self, b: usize) -> Sphere {
        self.coarse[b]
    }

    /// Body `b`'s fine spheres.
    pub fn fine(&self, b: usize) -> &[Sphere] {
        &self.fine[self.start[b]..self.start[b + 1]]
    }

    /// Fine spheres over all bodies.
    pub fn fine_count(&self) -> usize {
        self.fine.len()
    }

    /// The farthest (m) body `b`'s fine spheres reach beyond the body.
    pub fn overshoot(&self, b: usize) -> f64 {
        self.overshoot[b]
    }
}

/// Appends the cover of one shape (body frame) to `out`; returns how far
/// its spheres can reach beyond the shape.
fn cover(shape: &BodyShape, params: &SphereParams, out: &mut Vec<Sphere>) -> f64 {
    if matches!(shape.fast, RobotFast::None) && !matches!(shape.bound, RobotFast::None) {
        // a mesh hull or a cylinder, covered through its closed-form bound;
        // a sphere reaches at most its centre's distance to the shape plus
        // its radius beyond it (the distance to a convex set grows by at
        // most the step)
        let first = out.len();
        cover_closed(&shape.bound, shape, params, out);
        let pose = pose_to_parry(&shape.offset);
        return out[first..]
            .iter()
            .map(|s| {
                shape
                    .shape
                    .distance_to_point(&pose, vec_to_parry(&s.center.coords), true)
                    + s.radius
            })
            .fold(0.0, f64::max);
    }
    cover_closed(&shape.fast, shape, params, out)
}

/// [`cover`] of the closed form `closed` (the shape's own, or its bound);
/// the grid over the bounding box of `shape` when there is none.
fn cover_closed(closed: &RobotFast, shape: &BodyShape, params: &SphereParams, out: &mut Vec<Sphere>) -> f64 {
    let (o, cap) = (params.max_overshoot, params.max_per_shape);
    match *closed {
        RobotFast::Swept { a, b, r } => capsule_cover(&a, &b, r, o, cap, out),
        RobotFast::Box { offset, half } => {
            let n = grid(&half, |e| e.norm() - e.min(), o, cap);
            let e = half.component_div(&Vector3::new(n[0] as f64, n[1] as f64, n[2] as f64));
            for_cells(&half, n, |c| {
                out.push(Sphere {
                    center: offset * Point3::from(c),
                    radius: e.norm(),
                });
            });
            e.norm() - e.min()
        }
        RobotFast::None => {
            let pose = pose_to_parry(&shape.offset);
            let aabb = shape.shape.compute_aabb(&pose);
            let lo = Vector3::new(aabb.mins.x, aabb.mins.y, aabb.mins.z);
            let hi = Vector3::new(aabb.maxs.x, aabb.maxs.y, aabb.maxs.z);
            let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            let n = grid(&half, |e| 2.0 * e.norm(), o, cap);
            let e = half.component_div(&Vector3::new(n[0] as f64, n[1] as f64, n[2] as f64));
            let cell = Cuboid::new(parry3d_f64::math::Vector::new(e.x, e.y, e.z));
            for_cells(&half, n, |c| {
                let centre = mid + c;
                let at = pose_to_parry(&Isometry3::translation(centre.x, centre.y, centre.z));
                let meets = query::intersection_test(&at, &cell, &pose, &*shape.shape)
                    .map_or(true, |i| i.intersecting);
                if meets {
                    out.push(Sphere {
                        center: Point3::from(centre),
                        radius: e.norm(),
                    });
                }
            });
            2.0 * e.norm()
        }
    }
}

/// The capsule cover of the module doc: `n + 1` spheres along `[a, b]`.
fn capsule_cover(a: &Point3<f64>, b: &Point3<f64>, r: f64, o: f64, cap: usize, out: &mut Vec<Sphere>) -> f64 {
    let length = (b - a).norm();
    if length == 0.0 || cap == 1 {
        // one sphere about the middle reaching both ends
        out.push(Sphere {
            center: Point3::from(0.5 * (a.coords + b.coords)),
            radius: r + 0.5 * length,
        });
        return 0.5 * length;
    }
    // the least n with √(r² + s²) − r ≤ o, s = L/(2n)
    let s_max = ((r + o) * (r + o) - r * r).sqrt();
    let n = ((length / (2.0 * s_max)).ceil() as usize).clamp(1, cap - 1);
    let s = length / (2.0 * n as f64);
    let radius = (r * r + s * s).sqrt();
    for i in 0..=n {
        let t = i as f64 / n as f64;
        out.push(Sphere {
            center: a + (b - a) * t,
            radius,
        });
    }
    radius - r
}

/// Cells per axis of a grid over half extents `half`: the longest cell axis
/// is split until `reach(cell half extents) ≤ target` or one more split
/// would pass `cap` cells.
fn grid(half: &Vector3<f64>, reach: impl Fn(&Vector3<f64>) -> f64, target: f64, cap: usize) -> [usize; 3] {
    let mut n = [1usize; 3];
    loop {
        let e = half.component_div(&Vector3::new(n[0] as f64, n[1] as f64, n[2] as f64));
        if reach(&e) <= target {
            return n;
        }
        let k = e.imax();
        let mut more = n;
        more[k] += 1;
        if more.iter().product::<usize>() > cap {
            return n;
        }
        n = more;
    }
}

/// Calls `f` with the centre of every cell of the grid `n` over `[−half,
/// half]`.
fn for_cells(half: &Vector3<f64>, n: [usize; 3], mut f: impl FnMut(Vector3<f64>)) {
    let at = |k: usize, i: usize| -half[k] + half[k] * (2 * i + 1) as f64 / n[k] as f64;
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                f(Vector3::new(at(0, i), at(1, j), at(2, k)));
            }
        }
    }
}
