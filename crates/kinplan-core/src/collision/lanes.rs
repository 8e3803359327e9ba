//! Several robot states checked at once, one state per vector lane: forward
//! kinematics and the sphere model ([`SphereModel`]) against the scene, as
//! a fast *certainly free* test ahead of the exact check.
//!
//! Layout: structure of arrays over [`LANES`] states — every joint value,
//! rotation entry, position and sphere centre is a `[f64; LANES]`, so each
//! arithmetic step is one vector operation over the states. Obstacles are
//! flat records of scalars broadcast to the lanes (the states vary, the
//! scene does not).
//!
//! Forward kinematics (Craig, *Introduction to Robotics*, §3): with `T` the
//! frame reached so far (rotation `R`, position `p`), each joint applies its
//! fixed origin `(R_o, p_o)`: `R ← R·R_o`, `p ← p + R·p_o`, then its motion:
//! a turn by `q` about `+z` replaces columns `(c₀, c₁)` by
//! `(cos q·c₀ + sin q·c₁, cos q·c₁ − sin q·c₀)`; a turn about a unit axis
//! `a` multiplies by Rodrigues' `cos q·I + sin q·[a]ₓ + (1 − cos q)·aaᵀ`;
//! a slide adds `q·R·a` to `p`. Bodies are posed by their fixed offset
//! after their link's joints, as [`RobotModel::body_poses`] does.
//!
//! Verdict per lane: **clear** when every sphere of every scene-checked
//! body is farther than its radius (plus [`MARGIN`]) from every obstacle
//! and the bounding spheres of every checked self pair are apart; else
//! **unsure**. Only the clear verdict is final: every point of a body lies
//! inside one of its spheres (the cover of [`SphereModel`]), so a sphere
//! clear of an obstacle means that part of the body is clear of it, and a
//! body all of whose spheres are clear does not touch it; the bounding
//! spheres contain their bodies likewise. Obstacles are tested as they are
//! (boxes, spheres, capsules) or by what contains them (a cylinder by its
//! enclosing capsule, a mesh by its axis-aligned box), which only refuses
//! more. [`MARGIN`] covers the rounding of these sums (about 1e-15 m at
//! the scale of an arm), so a lane found clear is clear of the exact
//! geometry; an unsure lane goes to the exact check.
//!
//! The same code is compiled twice: for AVX2 + FMA, taken when the CPU has
//! them (`is_x86_feature_detected!`), and for the baseline target. Rust
//! never fuses a multiply and an add on its own, so both produce the same
//! bits.

// Lane loops index several arrays by lane and axis at once (`a[k][l] +
// b[k][l]·c[k]`): written as index loops, which the vectoriser takes.
#![allow(clippy::needless_range_loop)]

use nalgebra::{Isometry3, Vector3};

use super::bvh::{Aabb, Bvh};
use super::fast::LeafFast;
use super::model::{FkOp, RobotModel};
use super::spheres::SphereModel;
use super::trig::sin_cos_reduced;
use super::world::SceneGeometry;
use crate::robot::JointKind;

/// States per batch.
pub(crate) const LANES: usize = 4;
/// One value per state of a batch.
pub(crate) type Lane = [f64; LANES];
/// Most joints a batched model takes.
pub(crate) const MAX_LANE_DOF: usize = 16;
/// Most bodies a batched model takes.
pub(crate) const MAX_LANE_BODIES: usize = 16;
/// Most fine spheres per body a batched model takes.
const MAX_FINE: usize = 128;
/// Most scene leaves tested in the lanes: a larger scene (octree cells) is
/// left to the bounding-volume hierarchy of the exact check.
pub(crate) const MAX_LANE_LEAVES: usize = 128;
/// Scenes of at most this many leaves are scanned leaf by leaf in the
/// lanes; larger ones through their hierarchy, once per body and batch.
const SCAN_LEAVES: usize = 24;
/// Added to every sphere radius (m): covers rounding in the sums.
pub(crate) const MARGIN: f64 = 1e-9;

/// A fixed transform as a matrix and a vector.
#[derive(Debug, Clone, Copy)]
struct Fixed {
    r: [[f64; 3]; 3],
    p: [f64; 3],
}

impl Fixed {
    fn of(t: &Isometry3<f64>) -> Self {
        let m = t.rotation.to_rotation_matrix();
        let m = m.matrix();
        Fixed {
            r: [0, 1, 2].map(|i| [0, 1, 2].map(|k| m[(i, k)])),
            p: [0, 1, 2].map(|i| t.translation.vector[i]),
        }
    }

    /// Applies `f` to a point.
    fn apply(&self, x: &[f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| self.p[i] + self.r[i][0] * x[0] + self.r[i][1] * x[1] + self.r[i][2] * x[2])
    }
}

#[derive(Debug, Clone, Copy)]
enum Motion {
    AboutZ,
    About([f64; 3]),
    Along([f64; 3]),
}

#[derive(Debug, Clone, Copy)]
enum Op {
    Joint {
        origin: Fixed,
        motion: Motion,
    },
    /// The frame so far is body `body`'s joint frame (its spheres carry the
    /// body offset).
    Body {
        body: usize,
    },
}

/// A sphere in a body's joint frame.
#[derive(Debug, Clone, Copy)]
struct Ball {
    c: [f64; 3],
    r: f64,
}

#[derive(Debug, Clone, Copy)]
enum Prim {
    /// A box: centre, axes (columns of `r`), half extents.
    Box {
        c: [f64; 3],
        r: [[f64; 3]; 3],
        half: [f64; 3],
    },
    /// Segment `[a, a + d]` swept by `r` (`inv` = 1/|d|², 0 for a point).
    Capsule {
        a: [f64; 3],
        d: [f64; 3],
        inv: f64,
        r: f64,
    },
}

#[derive(Debug, Clone, Copy)]
struct LaneLeaf {
    lo: [f64; 3],
    hi: [f64; 3],
    prim: Prim,
}

/// A robot's forward kinematics and spheres, and a scene's obstacles, laid
/// out for batches of [`LANES`] states (module doc).
#[derive(Debug, Clone)]
pub(crate) struct Lanes {
    ops: Vec<Op>,
    dof: usize,
    body_count: usize,
    /// Per body, its bounding sphere (joint frame).
    coarse: Vec<Ball>,
    /// Per body, `fine[start[b]..start[b + 1]]` (joint frame).
    fine: Vec<Ball>,
    start: Vec<usize>,
    leaves: Vec<LaneLeaf>,
}

/// Body frames of a batch: rotation `r[i][k]` (row `i`, column `k`) and
/// position `p`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LaneFrame {
    pub r: [[Lane; 3]; 3],
    pub p: [Lane; 3],
}

impl LaneFrame {
    pub(crate) const IDENTITY: LaneFrame = LaneFrame {
        r: [
            [[1.0; LANES], [0.0; LANES], [0.0; LANES]],
            [[0.0; LANES], [1.0; LANES], [0.0; LANES]],
            [[0.0; LANES], [0.0; LANES], [1.0; LANES]],
        ],
        p: [[0.0; LANES]; 3],
    };
}

impl Lanes {
    /// The batched form of `model` with `spheres` in `world`; `None` when
    /// the model or scene is beyond the batch limits ([`MAX_LANE_DOF`],
    /// [`MAX_LANE_BODIES`], [`MAX_LANE_LEAVES`], 128 fine spheres per body).
    pub(crate) fn new(model: &RobotModel, spheres: &SphereModel, world: &SceneGeometry) -> Option<Self> {
        let dof = model.chain().dof();
        let body_count = model.body_count();
        if dof > MAX_LANE_DOF || body_count > MAX_LANE_BODIES || world.leaves.len() > MAX_LANE_LEAVES {
            return None;
        }
        if spheres.body_count() != body_count || (0..body_count).any(|b| spheres.fine(b).len() > MAX_FINE) {
            return None;
        }
        let mut ops = Vec::new();
        let mut coarse = vec![Ball { c: [0.0; 3], r: 0.0 }; body_count];
        let mut fine_of = vec![Vec::new(); body_count];
        for op in model.fk_program() {
            match op {
                FkOp::Joint { origin, axis, kind } => {
                    let a = [axis.x, axis.y, axis.z];
                    let motion = match kind {
                        JointKind::Prismatic => Motion::Along(a),
                        _ if axis == Vector3::z() => Motion::AboutZ,
                        _ => Motion::About(a),
                    };
                    ops.push(Op::Joint {
                        origin: Fixed::of(&origin),
                        motion,
                    });
                }
                FkOp::Body { body, offset } => {
                    let f = Fixed::of(&offset);
                    let ball = |c: &nalgebra::Point3<f64>, r: f64| Ball {
                        c: f.apply(&[c.x, c.y, c.z]),
                        r,
                    };
                    let s = spheres.coarse(body);
                    coarse[body] = ball(&s.center, s.radius);
                    fine_of[body] = spheres
                        .fine(body)
                        .iter()
                        .map(|s| ball(&s.center, s.radius))
                        .collect();
                    if spheres.fine(body).is_empty() {
                        fine_of[body] = vec![coarse[body]];
                    }
                    ops.push(Op::Body { body });
                }
            }
        }
        let mut fine = Vec::new();
        let mut start = vec![0];
        for f in fine_of {
            fine.extend(f);
            start.push(fine.len());
        }
        let leaves = world.leaves.iter().map(lane_leaf).collect();
        Some(Lanes {
            ops,
            dof,
            body_count,
            coarse,
            fine,
            start,
            leaves,
        })
    }

    /// The body frames of the batch `q` (`q[j]`: joint `j` in every lane;
    /// every value within the reduced range of `sin_cos_reduced`) into
    /// `frames[..body_count]`; the AVX2 build when the CPU has it, unless
    /// `portable`.
    #[cfg(test)]
    pub(crate) fn body_frames(&self, q: &[Lane], frames: &mut [LaneFrame], portable: bool) {
        #[cfg(target_arch = "x86_64")]
        if !portable && std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            #[target_feature(enable = "avx2,fma")]
            unsafe fn fk_avx2(lanes: &Lanes, q: &[Lane], frames: &mut [LaneFrame]) {
                lanes.fk(q, frames)
            }
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { fk_avx2(self, q, frames) };
        }
        let _ = portable;
        self.fk(q, frames);
    }

    /// Unsure lanes (bit `l` for lane `l`) of the batch `q` (module doc):
    /// the scene (`bvh`, over the leaves the lanes were built from) tested
    /// for `scene_bodies`, the bounding spheres of
    /// `self_pairs`. `frames` is scratch of at least the body count.
    /// Dispatches to the AVX2 build when the CPU has it, unless `portable`.
    #[cfg(test)]
    pub(crate) fn unsure(
        &self,
        q: &[Lane],
        bvh: &Bvh,
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        frames: &mut [LaneFrame],
        portable: bool,
    ) -> u32 {
        self.unsure_padded(
            q,
            &[0.0; MAX_LANE_BODIES],
            bvh,
            scene_bodies,
            self_pairs,
            frames,
            portable,
        )
    }

    /// [`Lanes::unsure`] with every sphere of body `b` grown by `pads[b]`
    /// (m, ≥ 0; `pads` holds at least the body count): a lane found clear
    /// has every state within those distances of its state clear — a point
    /// of a body that moves at most `pads[b]` stays inside its sphere grown
    /// by `pads[b]`, and of two bodies in a self pair, inside spheres grown
    /// by both pads.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn unsure_padded(
        &self,
        q: &[Lane],
        pads: &[f64],
        bvh: &Bvh,
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        frames: &mut [LaneFrame],
        portable: bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if !portable && std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { self.unsure_avx2(q, pads, bvh, scene_bodies, self_pairs, frames) };
        }
        let _ = portable;
        self.unsure_in(q, pads, bvh, scene_bodies, self_pairs, frames)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn unsure_avx2(
        &self,
        q: &[Lane],
        pads: &[f64],
        bvh: &Bvh,
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        frames: &mut [LaneFrame],
    ) -> u32 {
        self.unsure_in(q, pads, bvh, scene_bodies, self_pairs, frames)
    }

    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn unsure_in(
        &self,
        q: &[Lane],
        pads: &[f64],
        bvh: &Bvh,
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        frames: &mut [LaneFrame],
    ) -> u32 {
        const ALL: u32 = (1 << LANES) - 1;
        self.fk(q, frames);
        let mut unsure = 0u32;
        // every body's bounding-sphere centre, once for the scene and the
        // self pairs
        let mut centres = [[[0.0; LANES]; 3]; MAX_LANE_BODIES];
        for (b, c) in centres.iter_mut().enumerate().take(self.body_count) {
            *c = place(&frames[b], &self.coarse[b].c);
        }
        // per body: the leaves its bounding sphere meets (and in which
        // lanes), then each fine sphere placed once against those leaves
        let mut near_leaves = [(0u16, 0u32); MAX_LANE_LEAVES];
        for &b in scene_bodies {
            let b = b as usize;
            let f = &frames[b];
            let coarse = self.coarse[b];
            let pad = pads[b] + MARGIN;
            let c = &centres[b];
            let reach = coarse.r + pad;
            let mut count = 0;
            if self.leaves.len() <= SCAN_LEAVES {
                // a plain loop, not the closure below: a closure is compiled
                // apart, without this function's vector features
                for (i, leaf) in self.leaves.iter().enumerate() {
                    let near = mask(&sphere_aabb(c, reach, &leaf.lo, &leaf.hi)) & !unsure;
                    if near != 0 {
                        near_leaves[count] = (i as u16, near);
                        count += 1;
                    }
                }
            } else {
                let visit = |i: u32| {
                    let leaf = &self.leaves[i as usize];
                    let near = mask(&sphere_aabb(c, reach, &leaf.lo, &leaf.hi)) & !unsure;
                    if near != 0 {
                        near_leaves[count] = (i as u16, near);
                        count += 1;
                    }
                    true
                };
                // the scene's hierarchy asked once for the batch: the box
                // around the bounding sphere in every lane
                let mut query = Aabb::empty();
                for k in 0..3 {
                    for l in 0..LANES {
                        query.min[k] = query.min[k].min(c[k][l] - reach);
                        query.max[k] = query.max[k].max(c[k][l] + reach);
                    }
                }
                bvh.for_each_overlap(&query, visit);
            }
            for s in &self.fine[self.start[b]..self.start[b + 1]] {
                if count == 0 {
                    break;
                }
                let x = place(f, &s.c);
                for &(i, near) in &near_leaves[..count] {
                    unsure |= mask(&sphere_prim(&x, s.r + pad, &self.leaves[i as usize].prim)) & near;
                }
            }
            if unsure == ALL {
                return ALL;
            }
        }
        // self pairs: bounding spheres; where they meet, the fine spheres of
        // each body near the other's bounding sphere, pairwise
        for &(a, b) in self_pairs {
            let (a, b) = (a as usize, b as usize);
            let (sa, sb) = (self.coarse[a], self.coarse[b]);
            let pad = pads[a] + pads[b] + MARGIN;
            let (ca, cb) = (&centres[a], &centres[b]);
            let near = mask(&spheres_meet(ca, cb, sa.r + sb.r + pad)) & !unsure;
            if near == 0 {
                continue;
            }
            unsure |= self.fine_pairs_meet(&frames[a], a, &frames[b], b, ca, cb, pad) & near;
            if unsure == ALL {
                return ALL;
            }
        }
        unsure
    }

    /// Lanes where a fine sphere of body `a` (frame `fa`, bounding-sphere
    /// centre `ca`) comes within `pad` of one of body `b`'s; up to
    /// [`CLOSE`] spheres of `b` near `a`'s bounding sphere are kept, and
    /// beyond that every lane counts as meeting (unsure, never wrong).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn fine_pairs_meet(
        &self,
        fa: &LaneFrame,
        a: usize,
        fb: &LaneFrame,
        b: usize,
        ca: &[Lane; 3],
        cb: &[Lane; 3],
        pad: f64,
    ) -> u32 {
        const CLOSE: usize = 24;
        let (sa, sb) = (self.coarse[a], self.coarse[b]);
        let mut kept = [([[0.0; LANES]; 3], 0.0, 0u32); CLOSE];
        let mut count = 0;
        for t in &self.fine[self.start[b]..self.start[b + 1]] {
            let y = place(fb, &t.c);
            let close = mask(&spheres_meet(&y, ca, t.r + sa.r + pad));
            if close != 0 {
                if count == CLOSE {
                    return (1 << LANES) - 1;
                }
                kept[count] = (y, t.r, close);
                count += 1;
            }
        }
        let mut meet = 0u32;
        for s in &self.fine[self.start[a]..self.start[a + 1]] {
            if count == 0 {
                break;
            }
            let x = place(fa, &s.c);
            let close = mask(&spheres_meet(&x, cb, s.r + sb.r + pad));
            if close == 0 {
                continue;
            }
            for (y, r, near) in &kept[..count] {
                meet |= mask(&spheres_meet(&x, y, s.r + r + pad)) & close & near;
            }
        }
        meet
    }

    #[inline(always)]
    fn fk(&self, q: &[Lane], frames: &mut [LaneFrame]) {
        let mut t = LaneFrame::IDENTITY;
        let mut joint = 0;
        for op in &self.ops {
            match op {
                Op::Joint { origin, motion } => {
                    t = compose(&t, origin);
                    let v = &q[joint];
                    joint += 1;
                    match motion {
                        Motion::AboutZ => {
                            let (s, c) = sin_cos_lanes(v);
                            for i in 0..3 {
                                for l in 0..LANES {
                                    let (x, y) = (t.r[i][0][l], t.r[i][1][l]);
                                    t.r[i][0][l] = c[l] * x + s[l] * y;
                                    t.r[i][1][l] = c[l] * y - s[l] * x;
                                }
                            }
                        }
                        Motion::About(a) => {
                            let (s, c) = sin_cos_lanes(v);
                            let mut m = [[[0.0; LANES]; 3]; 3];
                            for j in 0..3 {
                                for k in 0..3 {
                                    // [a]ₓ[j][k] = −ε_jkm a_m
                                    let cross = match (j, k) {
                                        (0, 1) => -a[2],
                                        (0, 2) => a[1],
                                        (1, 0) => a[2],
                                        (1, 2) => -a[0],
                                        (2, 0) => -a[1],
                                        (2, 1) => a[0],
                                        _ => 0.0,
                                    };
                                    let id = if j == k { 1.0 } else { 0.0 };
                                    for l in 0..LANES {
                                        m[j][k][l] = c[l] * id + s[l] * cross + (1.0 - c[l]) * a[j] * a[k];
                                    }
                                }
                            }
                            let r = t.r;
                            for i in 0..3 {
                                for k in 0..3 {
                                    for l in 0..LANES {
                                        t.r[i][k][l] = r[i][0][l] * m[0][k][l]
                                            + r[i][1][l] * m[1][k][l]
                                            + r[i][2][l] * m[2][k][l];
                                    }
                                }
                            }
                        }
                        Motion::Along(a) => {
                            for i in 0..3 {
                                for l in 0..LANES {
                                    let d = t.r[i][0][l] * a[0] + t.r[i][1][l] * a[1] + t.r[i][2][l] * a[2];
                                    t.p[i][l] += d * v[l];
                                }
                            }
                        }
                    }
                }
                Op::Body { body } => frames[*body] = t,
            }
        }
    }

    /// Joints.
    pub(crate) fn dof(&self) -> usize {
        self.dof
    }

    /// Bodies.
    pub(crate) fn body_count(&self) -> usize {
        self.body_count
    }
}

/// Bit `l` set for each true lane (plain loops here and below: closures
/// are compiled apart from the vector-featured callers).
#[inline(always)]
fn mask(m: &[bool; LANES]) -> u32 {
    let mut bits = 0;
    for l in 0..LANES {
        bits |= (m[l] as u32) << l;
    }
    bits
}

/// Lanes whose squared distance is at most `limit`.
#[inline(always)]
fn within(d2: &Lane, limit: f64) -> [bool; LANES] {
    let mut out = [false; LANES];
    for l in 0..LANES {
        out[l] = d2[l] <= limit;
    }
    out
}

/// `sin_cos_reduced` in every lane.
#[inline(always)]
fn sin_cos_lanes(v: &Lane) -> (Lane, Lane) {
    let mut s = [0.0; LANES];
    let mut c = [0.0; LANES];
    for l in 0..LANES {
        (s[l], c[l]) = sin_cos_reduced(v[l]);
    }
    (s, c)
}

/// `t · f`.
#[inline(always)]
fn compose(t: &LaneFrame, f: &Fixed) -> LaneFrame {
    let mut out = *t;
    for i in 0..3 {
        for k in 0..3 {
            for l in 0..LANES {
                out.r[i][k][l] =
                    t.r[i][0][l] * f.r[0][k] + t.r[i][1][l] * f.r[1][k] + t.r[i][2][l] * f.r[2][k];
            }
        }
        for l in 0..LANES {
            out.p[i][l] = t.p[i][l] + t.r[i][0][l] * f.p[0] + t.r[i][1][l] * f.p[1] + t.r[i][2][l] * f.p[2];
        }
    }
    out
}

/// The point `x` (frame `f`) in the base frame, per lane.
#[inline(always)]
fn place(f: &LaneFrame, x: &[f64; 3]) -> [Lane; 3] {
    let mut out = [[0.0; LANES]; 3];
    for (i, o) in out.iter_mut().enumerate() {
        for l in 0..LANES {
            o[l] = f.p[i][l] + f.r[i][0][l] * x[0] + f.r[i][1][l] * x[1] + f.r[i][2][l] * x[2];
        }
    }
    out
}

/// Lanes whose points `x` and `y` are at most `reach` apart.
#[inline(always)]
fn spheres_meet(x: &[Lane; 3], y: &[Lane; 3], reach: f64) -> [bool; LANES] {
    let mut d2 = [0.0; LANES];
    for k in 0..3 {
        for l in 0..LANES {
            let d = x[k][l] - y[k][l];
            d2[l] += d * d;
        }
    }
    within(&d2, reach * reach)
}

/// Lanes whose sphere (centre `c`, radius `r`) meets the box `[lo, hi]`.
#[inline(always)]
fn sphere_aabb(c: &[Lane; 3], r: f64, lo: &[f64; 3], hi: &[f64; 3]) -> [bool; LANES] {
    let mut d2 = [0.0; LANES];
    for k in 0..3 {
        for l in 0..LANES {
            let e = (lo[k] - c[k][l]).max(c[k][l] - hi[k]).max(0.0);
            d2[l] += e * e;
        }
    }
    within(&d2, r * r)
}

/// Lanes whose sphere (centre `x`, radius `r`) meets the primitive.
#[inline(always)]
fn sphere_prim(x: &[Lane; 3], r: f64, prim: &Prim) -> [bool; LANES] {
    let mut d2 = [0.0; LANES];
    match prim {
        Prim::Box { c, r: m, half } => {
            for l in 0..LANES {
                let v = [x[0][l] - c[0], x[1][l] - c[1], x[2][l] - c[2]];
                for k in 0..3 {
                    let local = m[0][k] * v[0] + m[1][k] * v[1] + m[2][k] * v[2];
                    let e = (local.abs() - half[k]).max(0.0);
                    d2[l] += e * e;
                }
            }
            within(&d2, r * r)
        }
        Prim::Capsule { a, d, inv, r: rc } => {
            let reach = r + rc;
            for l in 0..LANES {
                let v = [x[0][l] - a[0], x[1][l] - a[1], x[2][l] - a[2]];
                let t = ((v[0] * d[0] + v[1] * d[1] + v[2] * d[2]) * inv).clamp(0.0, 1.0);
                let w = [v[0] - t * d[0], v[1] - t * d[1], v[2] - t * d[2]];
                d2[l] = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
            }
            within(&d2, reach * reach)
        }
    }
}

/// A scene leaf as the lanes test it: what it is, or what contains it.
fn lane_leaf(leaf: &super::world::Leaf) -> LaneLeaf {
    let (lo, hi) = (leaf.aabb.min, leaf.aabb.max);
    let capsule = |a: &nalgebra::Point3<f64>, b: &nalgebra::Point3<f64>, r: f64| {
        let d = b - a;
        let n2 = d.norm_squared();
        Prim::Capsule {
            a: [a.x, a.y, a.z],
            d: [d.x, d.y, d.z],
            inv: if n2 > 0.0 { 1.0 / n2 } else { 0.0 },
            r,
        }
    };
    let prim = match &leaf.fast {
        LeafFast::Box { pose, half } => {
            let f = Fixed::of(pose);
            Prim::Box {
                c: f.p,
                r: f.r,
                half: [half.x, half.y, half.z],
            }
        }
        LeafFast::Swept { a, b, r } => capsule(a, b, *r),
        LeafFast::Cylinder { outer, .. } => capsule(&outer.0, &outer.1, outer.2),
        LeafFast::None => {
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            Prim::Box {
                c: [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k])),
                r: identity,
                half: [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k])),
            }
        }
    };
    LaneLeaf {
        lo: [lo.x, lo.y, lo.z],
        hi: [hi.x, hi.y, hi.z],
        prim,
    }
}
