//! Eight robot states checked at once in `f32` lanes: forward kinematics
//! and the sphere model ([`SphereModel`]) against the scene and between the
//! checked body pairs, as a *certainly free* test ahead of the exact check
//! (the design of VAMP — Thomason, Kingston, Kavraki, "Motions in
//! Microseconds via Vectorized Sampling-Based Planning", ICRA 2024 — for a
//! model built at run time from any robot's bodies).
//!
//! Layout: structure of arrays over [`WIDTH`] states — every joint value,
//! frame entry and sphere centre is a `[f32; 8]`, so each arithmetic step
//! is one AVX vector operation. The scene's leaves are laid out once per
//! scene: their boxes as arrays of `f32` bounds (rounded outward), and what
//! each leaf is for the fine test (its box, oriented box or capsule;
//! cylinders by their enclosing capsule, meshes by their box: only ever
//! refusing more).
//!
//! Forward kinematics as 3×4 frames (Craig, *Introduction to Robotics*,
//! §3): every joint is moved to turn or slide along its own `z` (its
//! origin right-multiplied by a rotation `Q` with `Q·ẑ = axis`, and `Qᵀ`
//! folded into what follows), so a turn by `q` replaces only two columns,
//! `(c₀, c₁) ← (cos q·c₀ + sin q·c₁, cos q·c₁ − sin q·c₀)`, and a slide
//! adds `q·c₂` to the position. An origin whose rotation is a signed
//! permutation (the usual URDF `rpy` of quarter turns) moves columns
//! instead of multiplying. Sine and cosine: `trig32`.
//!
//! Per batch and per checked body: its bounding sphere against every leaf
//! box in one pass (distance² by clamping with `min`/`max`, eight lanes at a
//! time), giving per leaf the lanes near it; then each fine sphere against
//! the leaves some lane is near, masked by those lanes. Self pairs likewise:
//! bounding spheres first, fine spheres where they meet.
//!
//! Verdict per lane: **clear** when every tested sphere is apart; else
//! **unsure**, with the bodies and pairs that were not cleared
//! ([`Flags`]), for the exact check to settle. Soundness: every point of a
//! body lies in one of its fine spheres and in its bounding sphere
//! ([`SphereModel`]); every sphere is grown by the bound on how far the
//! `f32` kinematics can misplace its centre (`lanes8_bound`); every leaf is
//! grown by the rounding of its own test (below); and the comparison
//! `d² > t` uses a threshold `t ≥ R²·(1 + 6u)`, with `R` the grown reach,
//! which covers the relative rounding of the distance² itself. So a clear
//! lane is clear of the exact geometry.
//!
//! Rounding of the leaf tests (`X` bounds every placed coordinate, `u` the
//! unit roundoff): an axis-aligned box is tested by `max(lo − x, x − hi,
//! 0)` per axis, each a single rounded difference (relative error `u`);
//! an oriented box by `max(|M̂ᵀx − d̂| − ĥ, 0)`, `d = Mᵀc` (`M̂` rounded and
//! snapped within 1e-12, `d̂` rounded: at most `3u·√3X + u|c|` besides the
//! `γ₄(|c| + √3X)` of the sums), whose local coordinates are within
//! `β = 32u·(X + |c| + |h|)` of the exact ones, so its half extents are
//! grown by `β`; a capsule by the distance to `a + t̂·d`, `t̂`
//! the clamped projection, within `γ₅|v|` of the optimum along the axis
//! and `γ₃(|v| + |d|)` per coordinate, so its radius is grown by
//! `32u·(X + |a| + |d|)`.
//!
//! The same code is compiled twice: for AVX2, taken when the CPU has it
//! (`is_x86_feature_detected!`), and for the baseline target; no multiply
//! and add are fused, so both give the same bits.

// Lane loops index several arrays by lane and axis at once: written as
// index loops, which the vectoriser takes.
#![allow(clippy::needless_range_loop)]

use std::mem::MaybeUninit;

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};

use super::fast::LeafFast;
use super::lanes8_bound::{Bound, SLACK, U};
use super::model::{FkOp, RobotModel};
use super::spheres::SphereModel;
use super::trig32::{MAX_TURN, eta, sin_cos32};
use super::world::SceneGeometry;
use crate::robot::{Chain, JointKind};

mod padded;

/// States per batch.
pub(crate) const WIDTH: usize = 8;
/// One value per state of a batch.
pub(crate) type Lane8 = [f32; WIDTH];
/// Most joints a batched model takes.
pub(crate) const MAX_DOF8: usize = 16;
/// Most bodies a batched model takes.
pub(crate) const MAX_BODIES8: usize = 16;
/// Most fine spheres per body.
const MAX_FINE8: usize = 64;
/// Most scene leaves: larger scenes (octree cells) stay with the exact
/// check's hierarchy.
pub(crate) const MAX_LEAVES8: usize = 128;
/// Largest coordinate (m) and slide travel (m) the layout takes.
const MAX_COORD: f64 = 1.0e3;
/// Self pairs with their own flag bit; the others share the last bit.
const PAIR_BITS: usize = 63;
/// `d² > r²·GROW` clears: `1 + 16u`, above `(1 + 6u)/(1 − u)⁴` (the
/// rounding of `r` summed and squared in `f32`, then of `d²`).
const GROW: f32 = 1.0 + 16.0 * f32::EPSILON / 2.0;

/// A fixed rotation as the lanes apply it.
#[derive(Debug, Clone, Copy)]
enum Rot {
    Identity,
    /// Column `k` of the product is `sign[k]` × column `from[k]`.
    Permute {
        from: [usize; 3],
        sign: [f32; 3],
    },
    Dense([[f32; 3]; 3]),
}

#[derive(Debug, Clone, Copy)]
enum Op {
    /// `t ← t·(rot, p)`, then a turn about or slide along `z` by joint
    /// `joint`.
    Joint { rot: Rot, p: [f32; 3], slide: bool },
    /// The frame so far is body `body`'s (its spheres carry its offset).
    Body { body: usize },
}

/// A sphere in a body's frame: centre, and `r` grown by the kinematics
/// bound (m), `r2` the threshold for its tests against boxes.
#[derive(Debug, Clone, Copy)]
struct Ball {
    c: [f32; 3],
    r: f32,
    r2: f32,
}

#[derive(Debug, Clone, Copy)]
enum Prim {
    /// Axis-aligned box.
    Aabb { lo: [f32; 3], hi: [f32; 3] },
    /// Oriented box: axes (columns of `m`, entries within 1e-12 of 0 or ±1
    /// snapped to them), `d = mᵀ·centre`, grown half extents; a point's
    /// box coordinates are `mᵀx − d`.
    Box {
        m: [[f32; 3]; 3],
        d: [f32; 3],
        half: [f32; 3],
    },
    /// Segment `[a, a + d]` swept by the grown radius `r`; `inv` = 1/|d|²
    /// (0 for a point).
    Capsule {
        a: [f32; 3],
        d: [f32; 3],
        inv: f32,
        r: f32,
    },
}

/// Per lane, what the spheres could not clear: bit `b` of `bodies[l]`, body
/// `b` against the scene; bit `i` of `pairs[l]`, checked self pair `i`
/// (bit 63: some pair from the 63rd on).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Flags {
    pub bodies: [u32; WIDTH],
    pub pairs: [u64; WIDTH],
}

/// Body frames of a batch: rotation `r[i][k]` (row `i`, column `k`) and
/// position `p`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame8 {
    pub r: [[Lane8; 3]; 3],
    pub p: [Lane8; 3],
}

impl Frame8 {
    pub(crate) const IDENTITY: Frame8 = Frame8 {
        r: [
            [[1.0; WIDTH], [0.0; WIDTH], [0.0; WIDTH]],
            [[0.0; WIDTH], [1.0; WIDTH], [0.0; WIDTH]],
            [[0.0; WIDTH], [0.0; WIDTH], [1.0; WIDTH]],
        ],
        p: [[0.0; WIDTH]; 3],
    };
}

/// A robot's kinematics and spheres and a scene's leaves laid out for
/// batches of [`WIDTH`] states (module doc).
#[derive(Debug, Clone)]
pub(crate) struct Lanes8 {
    ops: Vec<Op>,
    dof: usize,
    body_count: usize,
    /// Per body, its bounding sphere.
    coarse: Vec<Ball>,
    /// Per body, `fine[start[b]..start[b + 1]]`.
    fine: Vec<Ball>,
    start: Vec<usize>,
    /// Per body, how far the kinematics can misplace a sphere centre (m;
    /// already in the radii; the padded batch's rounding terms use it).
    margin: Vec<f64>,
    /// Leaf boxes `[lo, hi]` (each leaf's bounds are broadcast to the lanes,
    /// so one record per leaf).
    boxes: Vec<[[f32; 3]; 2]>,
    prims: Vec<Prim>,
    /// Per body, the last joint moving it (`None`: fixed to the base).
    last: Vec<Option<usize>>,
    /// Some joint slides (the padded batch takes turning joints only).
    slides: bool,
    /// The rotation rows' error bound at the end of the chain (the largest
    /// along it; `lanes8_bound`).
    rho: f64,
    /// Every placed coordinate is within this of the base (m).
    reach: f64,
    /// Per body, twice its largest sphere's grown radius (m): bounds how far
    /// a sphere centre lies from the body's points, and a sphere's radius.
    reach_past: Vec<f64>,
}

/// `x` rounded to an `f32` not below it.
fn up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// `x` rounded to an `f32` not above it.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

fn f32s(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// A rotation taking `ẑ` to the unit `axis`; `None` when none is found (the
/// model is then left to the exact check, never posed by a wrong frame).
fn z_to(axis: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let z = Vector3::z();
    if (axis - z).norm() <= 1e-15 {
        Some(Matrix3::identity())
    } else if (axis + z).norm() <= 1e-15 {
        Some(Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)))
    } else {
        Rotation3::rotation_between(&z, axis).map(|r| r.into_inner())
    }
}

/// `x` with values within 1e-12 of 0 or ±1 snapped to them.
fn snap(x: f64) -> f64 {
    if x.abs() <= 1e-12 {
        0.0
    } else if (x.abs() - 1.0).abs() <= 1e-12 {
        x.signum()
    } else {
        x
    }
}

/// The lanes' form of the fixed rotation `m` (entries within 1e-12 of 0
/// or ±1 snapped to them).
fn rot_of(m: &Matrix3<f64>) -> Rot {
    let s = m.map(snap);
    if s == Matrix3::identity() {
        return Rot::Identity;
    }
    let mut from = [0; 3];
    let mut sign = [0.0; 3];
    let permutes = (0..3).all(|k| {
        let col = s.column(k);
        let nonzero: Vec<usize> = (0..3).filter(|&j| col[j] != 0.0).collect();
        if nonzero.len() == 1 && col[nonzero[0]].abs() == 1.0 {
            from[k] = nonzero[0];
            sign[k] = col[nonzero[0]] as f32;
            true
        } else {
            false
        }
    });
    if permutes {
        Rot::Permute { from, sign }
    } else {
        Rot::Dense([0, 1, 2].map(|j| [0, 1, 2].map(|k| m[(j, k)] as f32)))
    }
}

impl Lanes8 {
    /// The batched form of `model` with `spheres` in `world`; `None` beyond
    /// the limits ([`MAX_DOF8`], [`MAX_BODIES8`], [`MAX_LEAVES8`], 64 fine
    /// spheres per body, joints beyond `trig32::MAX_TURN` rad or 1 km,
    /// coordinates beyond 1 km).
    pub(crate) fn new(model: &RobotModel, spheres: &SphereModel, world: &SceneGeometry) -> Option<Self> {
        let chain = model.chain();
        let dof = chain.dof();
        let body_count = model.body_count();
        if dof > MAX_DOF8 || body_count > MAX_BODIES8 || world.leaves.len() > MAX_LEAVES8 {
            return None;
        }
        if spheres.body_count() != body_count || (0..body_count).any(|b| spheres.fine(b).len() > MAX_FINE8) {
            return None;
        }
        let travel = joint_travel(chain)?;
        let mut ops = Vec::new();
        let mut coarse = vec![
            Ball {
                c: [0.0; 3],
                r: 0.0,
                r2: 0.0
            };
            body_count
        ];
        let mut fine_of: Vec<Vec<(Vector3<f64>, f64)>> = vec![Vec::new(); body_count];
        let mut coarse_of = vec![(Vector3::zeros(), 0.0); body_count];
        let mut margin = vec![0.0; body_count];
        let mut last = vec![None; body_count];
        let mut slides = false;
        // the rotation Qᵀ owed by the last joint, folded into what follows
        let mut owed = Matrix3::identity();
        let mut bound = Bound::default();
        let mut joint = 0;
        for op in model.fk_program() {
            match op {
                FkOp::Joint { origin, axis, kind } => {
                    let q = z_to(&axis)?;
                    let r = owed * origin.rotation.to_rotation_matrix().into_inner() * q;
                    let p = owed * origin.translation.vector;
                    owed = q.transpose();
                    bound = bound.origin(p.norm());
                    let slide = kind == JointKind::Prismatic;
                    slides |= slide;
                    bound = if slide {
                        bound.slide(travel[joint])
                    } else {
                        bound.turn(eta(travel[joint]))
                    };
                    joint += 1;
                    ops.push(Op::Joint {
                        rot: rot_of(&r),
                        p: f32s(&p),
                        slide,
                    });
                }
                FkOp::Body { body, offset } => {
                    let place = |c: &Point3<f64>| owed * (offset * c).coords;
                    let s = spheres.coarse(body);
                    coarse_of[body] = (place(&s.center), s.radius);
                    fine_of[body] = spheres
                        .fine(body)
                        .iter()
                        .map(|s| (place(&s.center), s.radius))
                        .collect();
                    if fine_of[body].is_empty() {
                        fine_of[body] = vec![coarse_of[body]];
                    }
                    let far = fine_of[body]
                        .iter()
                        .chain([&coarse_of[body]])
                        .map(|(c, _)| c.norm())
                        .fold(0.0, f64::max);
                    margin[body] = bound.point(far);
                    last[body] = joint.checked_sub(1);
                    ops.push(Op::Body { body });
                }
            }
        }
        // every joint applied (a trailing joint moving no body has no step in
        // the program, and the padded batch keeps a sum per joint)
        if joint != dof {
            return None;
        }
        // every body posed exactly once: the batch reads every body's frame
        let mut posed = vec![0; body_count];
        for op in &ops {
            if let Op::Body { body } = op {
                posed[*body] += 1;
            }
        }
        if posed.iter().any(|&n| n != 1) {
            return None;
        }
        let ball = |(c, r): &(Vector3<f64>, f64), grow: f64| {
            let r = r + grow;
            Ball {
                c: f32s(c),
                r: up(r),
                r2: up(r * r * (1.0 + 8.0 * U)),
            }
        };
        let mut fine = Vec::new();
        let mut start = vec![0];
        for b in 0..body_count {
            coarse[b] = ball(&coarse_of[b], margin[b]);
            fine.extend(fine_of[b].iter().map(|s| ball(s, margin[b])));
            start.push(fine.len());
        }
        // every placed coordinate is within X of the base
        let x = (0..body_count)
            .map(|b| {
                let fine = fine_of[b].iter().map(|(c, r)| c.norm() + r).fold(0.0, f64::max);
                bound.reach + fine.max(coarse_of[b].0.norm() + coarse_of[b].1) + margin[b]
            })
            .fold(bound.reach, f64::max);
        if !(x.is_finite() && x <= MAX_COORD) {
            return None;
        }
        let mut boxes = Vec::with_capacity(world.leaves.len());
        let mut prims = Vec::with_capacity(world.leaves.len());
        for leaf in &world.leaves {
            let (a, b) = (leaf.aabb.min, leaf.aabb.max);
            if !(a
                .iter()
                .chain(b.iter())
                .all(|v| v.is_finite() && v.abs() <= MAX_COORD))
            {
                return None;
            }
            boxes.push([
                [0, 1, 2].map(|k| down(a[k] - SLACK)),
                [0, 1, 2].map(|k| up(b[k] + SLACK)),
            ]);
            prims.push(prim_of(leaf, x));
        }
        let reach_past = (0..body_count)
            .map(|b| {
                let fine = &fine[start[b]..start[b + 1]];
                2.0 * fine
                    .iter()
                    .chain([&coarse[b]])
                    .map(|s| f64::from(s.r))
                    .fold(0.0, f64::max)
            })
            .collect();
        Some(Lanes8 {
            reach_past,
            ops,
            dof,
            body_count,
            coarse,
            fine,
            start,
            margin,
            boxes,
            prims,
            last,
            slides,
            rho: bound.rho,
            reach: x,
        })
    }

    /// Joints.
    pub(crate) fn dof(&self) -> usize {
        self.dof
    }

    /// Per body, the kinematics margin its spheres are grown by (m).
    #[cfg(test)]
    pub(crate) fn margin(&self, b: usize) -> f64 {
        self.margin[b]
    }

    /// The body frames of the batch `q` into `frames` (AVX2 build unless
    /// `portable`), and where body `b`'s frame origin is in its own frame
    /// as the exact kinematics poses it: the folded rotation the lanes'
    /// frame differs by, applied to sphere centres (tests).
    #[cfg(test)]
    pub(crate) fn body_frames(&self, q: &[Lane8], frames: &mut [Frame8], portable: bool) {
        #[cfg(target_arch = "x86_64")]
        if !portable && std::is_x86_feature_detected!("avx2") {
            #[target_feature(enable = "avx2")]
            fn fk_avx2(lanes: &Lanes8, q: &[Lane8], frames: &mut [Frame8]) {
                frames[..lanes.body_count].copy_from_slice(lanes.fk(q, &mut uninit_frames()));
            }
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { fk_avx2(self, q, frames) };
        }
        let _ = portable;
        frames[..self.body_count].copy_from_slice(self.fk(q, &mut uninit_frames()));
    }

    /// Body `b`'s sphere centres (coarse first, then fine) placed at the
    /// frames of [`Lanes8::body_frames`], per lane (tests).
    #[cfg(test)]
    pub(crate) fn placed_centres(&self, b: usize, frame: &Frame8) -> Vec<[Lane8; 3]> {
        std::iter::once(&self.coarse[b])
            .chain(&self.fine[self.start[b]..self.start[b + 1]])
            .map(|s| place(frame, &s.c))
            .collect()
    }

    /// Unsure lanes (bit `l` for lane `l`) of the batch `q` (module doc), for
    /// the scene around `scene_bodies` and the `self_pairs`; `flags` gets
    /// what was not cleared per lane. The AVX2 build when the CPU has it,
    /// unless `portable`.
    pub(crate) fn unsure(
        &self,
        q: &[Lane8],
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        flags: &mut Flags,
        portable: bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if !portable && std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { self.unsure_avx2(q, scene_bodies, self_pairs, flags) };
        }
        let _ = portable;
        self.unsure_in::<false>(q, scene_bodies, self_pairs, flags)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn unsure_avx2(
        &self,
        q: &[Lane8],
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        flags: &mut Flags,
    ) -> u32 {
        self.unsure_in::<true>(q, scene_bodies, self_pairs, flags)
    }

    /// The batch check; `AVX`: built inside [`Lanes8::unsure_avx2`] (the
    /// masks then come from `vmovmskps`).
    #[inline(always)]
    fn unsure_in<const AVX: bool>(
        &self,
        q: &[Lane8],
        scene_bodies: &[u16],
        self_pairs: &[(u16, u16)],
        flags: &mut Flags,
    ) -> u32 {
        // scratch left uninitialised (zeroing it cost more than the checks):
        // every entry is written before it is read
        let mut frames = uninit_frames();
        let frames = self.fk(q, &mut frames);
        *flags = Flags::default();
        let mut unsure = 0u32;
        let mut centres = [const { MaybeUninit::<[Lane8; 3]>::uninit() }; MAX_BODIES8];
        for b in 0..self.body_count {
            centres[b].write(place(&frames[b], &self.coarse[b].c));
        }
        // SAFETY: the first `body_count` entries were just written.
        let centres: &[[Lane8; 3]] = unsafe { assume_init(&centres[..self.body_count]) };
        let mut near = [const { MaybeUninit::<(u16, u32)>::uninit() }; MAX_LEAVES8];
        for &b in scene_bodies {
            let b = b as usize;
            let c = &centres[b];
            let t = self.coarse[b].r2;
            let mut count = 0;
            for (i, [lo, hi]) in self.boxes.iter().enumerate() {
                let mut d2 = [0.0f32; WIDTH];
                for k in 0..3 {
                    let (lo, hi) = (lo[k], hi[k]);
                    for l in 0..WIDTH {
                        let e = max(max(lo - c[k][l], c[k][l] - hi), 0.0);
                        d2[l] += e * e;
                    }
                }
                let m = mask::<AVX>(&d2, t);
                if m != 0 {
                    near[count].write((i as u16, m));
                    count += 1;
                }
            }
            if count == 0 {
                continue;
            }
            let f = &frames[b];
            // SAFETY: the first `count` entries were just written.
            let near: &[(u16, u32)] = unsafe { assume_init(&near[..count]) };
            let mut hit = 0u32;
            for s in &self.fine[self.start[b]..self.start[b + 1]] {
                let x = place(f, &s.c);
                for &(i, m) in near {
                    hit |= sphere_prim::<AVX>(&x, s, &self.prims[i as usize]) & m;
                }
            }
            if hit != 0 {
                unsure |= hit;
                for_bits(hit, |l| flags.bodies[l] |= 1 << b);
            }
        }
        for (i, &(a, b)) in self_pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let reach = self.coarse[a].r + self.coarse[b].r;
            let m = mask::<AVX>(&dist2(&centres[a], &centres[b]), reach * reach * GROW);
            if m == 0 {
                continue;
            }
            let hit = self.fine_pairs_meet::<AVX>(&frames[a], a, &frames[b], b, &centres[a], &centres[b]) & m;
            if hit != 0 {
                unsure |= hit;
                let bit = 1u64 << i.min(PAIR_BITS);
                for_bits(hit, |l| flags.pairs[l] |= bit);
            }
        }
        unsure
    }

    /// Lanes where a fine sphere of body `a` meets one of body `b`'s: `b`'s
    /// spheres near `a`'s bounding sphere kept first (up to 24; beyond
    /// that every lane counts as meeting — unsure, never wrong).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn fine_pairs_meet<const AVX: bool>(
        &self,
        fa: &Frame8,
        a: usize,
        fb: &Frame8,
        b: usize,
        ca: &[Lane8; 3],
        cb: &[Lane8; 3],
    ) -> u32 {
        const CLOSE: usize = 24;
        let (sa, sb) = (self.coarse[a], self.coarse[b]);
        let mut kept = [const { MaybeUninit::<([Lane8; 3], f32, u32)>::uninit() }; CLOSE];
        let mut count = 0;
        for t in &self.fine[self.start[b]..self.start[b + 1]] {
            let y = place(fb, &t.c);
            let reach = t.r + sa.r;
            let close = mask::<AVX>(&dist2(&y, ca), reach * reach * GROW);
            if close != 0 {
                if count == CLOSE {
                    return (1 << WIDTH) - 1;
                }
                kept[count].write((y, t.r, close));
                count += 1;
            }
        }
        if count == 0 {
            return 0;
        }
        // SAFETY: the first `count` entries were just written.
        let kept: &[([Lane8; 3], f32, u32)] = unsafe { assume_init(&kept[..count]) };
        let mut meet = 0u32;
        for s in &self.fine[self.start[a]..self.start[a + 1]] {
            let x = place(fa, &s.c);
            let reach = s.r + sb.r;
            let close = mask::<AVX>(&dist2(&x, cb), reach * reach * GROW);
            if close == 0 {
                continue;
            }
            for (y, r, near) in kept {
                let reach = s.r + r;
                meet |= mask::<AVX>(&dist2(&x, y), reach * reach * GROW) & close & near;
            }
        }
        meet
    }

    /// The body frames of the batch, written into `frames` (at least the
    /// body count) and returned initialised.
    #[inline(always)]
    fn fk<'a>(&self, q: &[Lane8], frames: &'a mut [MaybeUninit<Frame8>]) -> &'a [Frame8] {
        self.fk_with::<false>(q, &[], frames, &mut [])
    }

    /// [`Lanes8::fk`], and when `SWEEP` the prefix sums of the piece with
    /// half vector `d` at every joint into `sums` (`padded` module).
    #[inline(always)]
    fn fk_with<'a, const SWEEP: bool>(
        &self,
        q: &[Lane8],
        d: &[f32],
        frames: &'a mut [MaybeUninit<Frame8>],
        sums: &mut [MaybeUninit<padded::Sums8>],
    ) -> &'a [Frame8] {
        let mut t = Frame8::IDENTITY;
        let mut joint = 0;
        let mut sum = padded::Sums8::ZERO;
        for op in &self.ops {
            match op {
                Op::Joint { rot, p, slide } => {
                    compose(&mut t, rot, p);
                    if SWEEP {
                        // the joint's axis: the frame's z through its origin
                        sum.add(d[joint], [t.r[0][2], t.r[1][2], t.r[2][2]], &t.p);
                        sums[joint].write(sum);
                    }
                    let v = &q[joint];
                    joint += 1;
                    if *slide {
                        for i in 0..3 {
                            for l in 0..WIDTH {
                                t.p[i][l] += t.r[i][2][l] * v[l];
                            }
                        }
                    } else {
                        let mut s = [0.0f32; WIDTH];
                        let mut c = [0.0f32; WIDTH];
                        for l in 0..WIDTH {
                            (s[l], c[l]) = sin_cos32(v[l]);
                        }
                        for i in 0..3 {
                            for l in 0..WIDTH {
                                let (x, y) = (t.r[i][0][l], t.r[i][1][l]);
                                t.r[i][0][l] = c[l] * x + s[l] * y;
                                t.r[i][1][l] = c[l] * y - s[l] * x;
                            }
                        }
                    }
                }
                Op::Body { body } => {
                    frames[*body].write(t);
                }
            }
        }
        // SAFETY: the program poses every body below the body count (checked
        // when the layout was built).
        unsafe { assume_init(&frames[..self.body_count]) }
    }
}

/// Scratch for the body frames of a batch.
#[inline(always)]
fn uninit_frames() -> [MaybeUninit<Frame8>; MAX_BODIES8] {
    [const { MaybeUninit::uninit() }; MAX_BODIES8]
}

/// `items` as initialised values.
///
/// # Safety
/// Every entry of `items` must have been written.
#[inline(always)]
unsafe fn assume_init<T>(items: &[MaybeUninit<T>]) -> &[T] {
    // SAFETY: `MaybeUninit<T>` has the layout of `T`, and the caller vouches
    // that every entry is initialised.
    unsafe { &*(items as *const [MaybeUninit<T>] as *const [T]) }
}

/// Per joint, the largest `|q|` its limits allow; `None` beyond what the
/// lanes take.
fn joint_travel(chain: &Chain) -> Option<Vec<f64>> {
    chain
        .joints()
        .iter()
        .map(|j| {
            let m = j.lower.abs().max(j.upper.abs());
            let limit = if j.kind == JointKind::Prismatic {
                MAX_COORD
            } else {
                MAX_TURN
            };
            (m.is_finite() && m <= limit).then_some(m)
        })
        .collect()
}

/// The leaf as the fine test takes it (module doc), with every placed
/// coordinate within `x` of the base.
fn prim_of(leaf: &super::world::Leaf, x: f64) -> Prim {
    let (lo, hi) = (leaf.aabb.min, leaf.aabb.max);
    let capsule = |a: &Point3<f64>, b: &Point3<f64>, r: f64| {
        let d = b - a;
        let n2 = d.norm_squared();
        let grow = 32.0 * U * (x + a.coords.norm() + d.norm()) + SLACK;
        Prim::Capsule {
            a: f32s(&a.coords),
            d: f32s(&d),
            inv: if n2 > 0.0 { (1.0 / n2) as f32 } else { 0.0 },
            r: up(r + grow),
        }
    };
    let aabb = Prim::Aabb {
        lo: [0, 1, 2].map(|k| down(lo[k] - SLACK)),
        hi: [0, 1, 2].map(|k| up(hi[k] + SLACK)),
    };
    match &leaf.fast {
        LeafFast::Box { pose, half } => {
            let m = pose.rotation.to_rotation_matrix().into_inner();
            if rot_of(&m).is_identity() {
                return aabb;
            }
            let c = pose.translation.vector;
            let grow = 32.0 * U * (x + c.norm() + half.norm()) + SLACK;
            Prim::Box {
                m: [0, 1, 2].map(|j| [0, 1, 2].map(|k| snap(m[(j, k)]) as f32)),
                d: f32s(&(m.transpose() * c)),
                half: [0, 1, 2].map(|k| up(half[k] + grow)),
            }
        }
        LeafFast::Swept { a, b, r } => capsule(a, b, *r),
        LeafFast::Cylinder { outer, .. } => capsule(&outer.0, &outer.1, outer.2),
        LeafFast::None => aabb,
    }
}

impl Rot {
    fn is_identity(&self) -> bool {
        matches!(self, Rot::Identity)
    }
}

/// `max` as the `maxps` instruction computes it (no NaN rules: every input
/// here is finite).
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Lanes whose `d2` is not above `t` ([`mask_each`] with one threshold).
#[inline(always)]
fn mask<const AVX: bool>(d2: &Lane8, t: f32) -> u32 {
    mask_each::<AVX>(d2, &[t; WIDTH])
}

/// Lanes whose `d2` is not above their own `t` (a NaN on either side
/// counts as meeting: unsure, never wrong): one compare and `vmovmskps` in
/// the AVX2 build (`AVX`), a loop elsewhere; the same bits.
#[inline(always)]
fn mask_each<const AVX: bool>(d2: &Lane8, t: &Lane8) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is set only in the AVX2 build, which runs after the
        // CPU was found to have AVX2.
        return unsafe { mask_each_avx(d2, t) };
    }
    let mut bits = 0u32;
    for l in 0..WIDTH {
        bits |= u32::from(d2[l].partial_cmp(&t[l]) != Some(std::cmp::Ordering::Greater)) << l;
    }
    bits
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn mask_each_avx(d2: &Lane8, t: &Lane8) -> u32 {
    use std::arch::x86_64::{_CMP_NGT_UQ, _mm256_cmp_ps, _mm256_loadu_ps, _mm256_movemask_ps};
    // SAFETY: `d2` and `t` are eight readable floats each.
    let (v, t) = unsafe { (_mm256_loadu_ps(d2.as_ptr()), _mm256_loadu_ps(t.as_ptr())) };
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_NGT_UQ>(v, t)) as u32
}

/// Calls `f` with every set bit's index.
#[inline(always)]
fn for_bits(mut bits: u32, mut f: impl FnMut(usize)) {
    while bits != 0 {
        f(bits.trailing_zeros() as usize);
        bits &= bits - 1;
    }
}

/// `t ← t·(rot, p)`.
#[inline(always)]
fn compose(t: &mut Frame8, rot: &Rot, p: &[f32; 3]) {
    // position first: it reads the rotation before the update
    for j in 0..3 {
        if p[j] != 0.0 {
            for i in 0..3 {
                for l in 0..WIDTH {
                    t.p[i][l] += t.r[i][j][l] * p[j];
                }
            }
        }
    }
    match rot {
        Rot::Identity => {}
        Rot::Permute { from, sign } => {
            let r = t.r;
            for i in 0..3 {
                for k in 0..3 {
                    for l in 0..WIDTH {
                        t.r[i][k][l] = sign[k] * r[i][from[k]][l];
                    }
                }
            }
        }
        Rot::Dense(m) => {
            let r = t.r;
            for i in 0..3 {
                for k in 0..3 {
                    for l in 0..WIDTH {
                        t.r[i][k][l] = r[i][0][l] * m[0][k] + r[i][1][l] * m[1][k] + r[i][2][l] * m[2][k];
                    }
                }
            }
        }
    }
}

/// The point `x` (frame `f`) in the base frame, per lane.
#[inline(always)]
fn place(f: &Frame8, x: &[f32; 3]) -> [Lane8; 3] {
    let mut out = [[0.0f32; WIDTH]; 3];
    for i in 0..3 {
        for l in 0..WIDTH {
            out[i][l] = f.p[i][l] + f.r[i][0][l] * x[0] + f.r[i][1][l] * x[1] + f.r[i][2][l] * x[2];
        }
    }
    out
}

/// Squared distance of `x` and `y` per lane.
#[inline(always)]
fn dist2(x: &[Lane8; 3], y: &[Lane8; 3]) -> Lane8 {
    let mut d2 = [0.0f32; WIDTH];
    for k in 0..3 {
        for l in 0..WIDTH {
            let d = x[k][l] - y[k][l];
            d2[l] += d * d;
        }
    }
    d2
}

/// Lanes whose sphere `s` at `x` meets the leaf.
#[inline(always)]
fn sphere_prim<const AVX: bool>(x: &[Lane8; 3], s: &Ball, prim: &Prim) -> u32 {
    let (d2, radius) = prim_dist2(x, prim);
    if radius == 0.0 {
        mask::<AVX>(&d2, s.r2)
    } else {
        let reach = s.r + radius;
        mask::<AVX>(&d2, reach * reach * GROW)
    }
}

/// Per lane, the squared distance from `x` to the leaf's core, and the
/// radius around that core the leaf reaches (its grown radius for a
/// capsule, 0 for a box).
#[inline(always)]
fn prim_dist2(x: &[Lane8; 3], prim: &Prim) -> (Lane8, f32) {
    let mut d2 = [0.0f32; WIDTH];
    match prim {
        Prim::Aabb { lo, hi } => {
            for k in 0..3 {
                for l in 0..WIDTH {
                    let e = max(max(lo[k] - x[k][l], x[k][l] - hi[k]), 0.0);
                    d2[l] += e * e;
                }
            }
            (d2, 0.0)
        }
        Prim::Box { m, d, half } => {
            for k in 0..3 {
                // box coordinate k
                let mut local = [-d[k]; WIDTH];
                for j in 0..3 {
                    for l in 0..WIDTH {
                        local[l] += m[j][k] * x[j][l];
                    }
                }
                for l in 0..WIDTH {
                    let e = max(local[l].abs() - half[k], 0.0);
                    d2[l] += e * e;
                }
            }
            (d2, 0.0)
        }
        Prim::Capsule { a, d, inv, r } => {
            let mut v = [[0.0f32; WIDTH]; 3];
            for k in 0..3 {
                for l in 0..WIDTH {
                    v[k][l] = x[k][l] - a[k];
                }
            }
            let mut t = [0.0f32; WIDTH];
            for l in 0..WIDTH {
                t[l] = min(
                    max((v[0][l] * d[0] + v[1][l] * d[1] + v[2][l] * d[2]) * inv, 0.0),
                    1.0,
                );
            }
            for k in 0..3 {
                for l in 0..WIDTH {
                    let w = v[k][l] - t[l] * d[k];
                    d2[l] += w * w;
                }
            }
            (d2, *r)
        }
    }
}
