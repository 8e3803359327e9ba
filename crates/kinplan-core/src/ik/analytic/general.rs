//! 6-joint arms outside the closed-form families whose wrist has two
//! consecutive axes that meet: the third wrist joint is searched over its
//! circle, the other five follow in closed form, and the zeros of the one
//! equation left over are bracketed and refined (family
//! [`Family::Searched6R`]).

use std::f64::consts::{PI, TAU};

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use super::family::{AnalyticArm, Axes6, Family, NotAnalytic, meet, normal_to, parallel};
use super::solve::{Base, ConfigFlags, pick};
use super::subproblems::{DEGENERATE, rot, rot_cs, sp1, wrap};

/// Bisection steps that locate where a branch ends (2⁻³⁴ of a sample spacing).
const BOUNDARY_STEPS: usize = 34;
/// Brent's root finder stops when the bracket is this narrow (rad) …
const ROOT_TOLERANCE: f64 = 1e-13;
/// … or after this many evaluations.
const MAX_ROOT_STEPS: usize = 100;
/// Extra samples between a sample and the end of a branch next to it.
const FOLD_SAMPLES: usize = 8;
/// A dip is searched when the parabola through its samples falls below this
/// fraction of its least sample.
const DIP_DEPTH: f64 = 1.0;
/// Golden-section steps spent on one dip of `|r|` (shrinks it by 0.618³²).
const DIP_STEPS: usize = 32;
/// Two roots of one search whose joints all agree to this (rad) are one.
const SAME_ROOT: f64 = 1e-9;

/// How the first three joints place a point: the closed-form 3-joint
/// position problems `E₁E₂E₃ x = w` (joints 1-based as in the docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Position {
    /// Axes 2 and 3 parallel: `q₁` by subproblem 4 (the `h₂` component is
    /// kept by joints 2 and 3), `q₃` by subproblem 3, `q₂` by subproblem 1.
    TwoThreeParallel,
    /// Axes 1 and 2 meet at this point `s`: `q₃` by subproblem 3 from
    /// `‖E₃x − s‖ = ‖w − s‖`, `(q₁, q₂)` by subproblem 2.
    OneTwoMeet(Vector3<f64>),
    /// Axes 2 and 3 meet at this point `t`: `q₁` by subproblem 3 from
    /// `‖E₁⁻¹w − t‖ = ‖x − t‖`, `(q₂, q₃)` by subproblem 2.
    TwoThreeMeet(Vector3<f64>),
}

/// Three evenly spaced residuals of one sign whose middle one is the least
/// in size, and the parabola through them dips below [`DIP_DEPTH`] of it:
/// the minimum of `|r|` between may reach zero (two roots close together).
/// A parabola through `(−h, φ₀), (0, φ₁), (h, φ₂)` has its least value
/// `φ₁ − (φ₂ − φ₀)² / (8 (φ₀ − 2φ₁ + φ₂))`.
fn deep_dip(r0: f64, r1: f64, r2: f64) -> bool {
    if (r0 < 0.0) != (r1 < 0.0) || (r1 < 0.0) != (r2 < 0.0) {
        return false;
    }
    let (f0, f1, f2) = (r0.abs(), r1.abs(), r2.abs());
    if !(f1 < f0 && f1 <= f2) {
        return false;
    }
    let curvature = f0 - 2.0 * f1 + f2;
    curvature > 0.0 && f1 - (f2 - f0).powi(2) / (8.0 * curvature) < DIP_DEPTH * f1
}

/// The geometry the 1-D search uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SearchGeometry {
    pub position: Position,
    /// 0-based index of the first of the two meeting wrist axes: 3 (axes 4
    /// and 5 meet; joint 6 searched) or 4 (axes 5 and 6 meet; joint 4
    /// searched).
    pub pair: usize,
    /// Where the pair meets, zero configuration (m).
    pub c: Vector3<f64>,
    /// A unit vector normal to the pair's second axis.
    pub normal: Vector3<f64>,
}

impl SearchGeometry {
    /// 0-based index of the searched joint.
    pub fn searched(&self) -> usize {
        if self.pair == 3 { 5 } else { 3 }
    }
}

/// An angle as its cosine and sine (no trigonometric call to get either).
type Cs = (f64, f64);

/// The two roots `φ ± acos(C/ρ)` of subproblem 4, `hᵀ rot(k, θ) p = d`
/// (see [`sp4`](super::sp4)), as cosines and sines: with `cos φ = A/ρ`,
/// `sin φ = B/ρ`, `cos α = C/ρ`, `sin α = √(1 − cos²α)`,
/// `cos(φ ± α) = cos φ cos α ∓ sin φ sin α` and
/// `sin(φ ± α) = sin φ cos α ± cos φ sin α`; always in this order, so that
/// each root moves continuously with the data. `C/ρ` is clamped to
/// `[−1, 1]` with `in_range = false` when it was outside (the least-squares
/// angle, both roots then equal). `None` when the left side does not depend
/// on `θ`.
fn sp4_both(h: &Vector3<f64>, k: &Vector3<f64>, p: &Vector3<f64>, d: f64) -> Option<([Cs; 2], bool)> {
    let kp = k.dot(p);
    let perp = p - k * kp;
    let a = h.dot(&perp);
    let b = h.dot(&k.cross(p));
    let c = d - h.dot(k) * kp;
    // √ rather than hypot: the terms are lengths of a robot's size
    let rho = (a * a + b * b).sqrt();
    if rho <= DEGENERATE * (1.0 + h.norm() * p.norm()) {
        return None;
    }
    let ratio = c / rho;
    let ca = ratio.clamp(-1.0, 1.0);
    let sa = (1.0 - ca * ca).max(0.0).sqrt();
    let (cp, sp) = (a / rho, b / rho);
    Some((
        [
            (cp * ca - sp * sa, sp * ca + cp * sa),
            (cp * ca + sp * sa, sp * ca - cp * sa),
        ],
        ratio.abs() <= 1.0,
    ))
}

/// Subproblem 3 in the form of [`sp4_both`]: `‖rot(k, θ) p − q‖ = δ`.
fn sp3_both(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, delta: f64) -> Option<([Cs; 2], bool)> {
    sp4_both(
        q,
        k,
        p,
        0.5 * (p.norm_squared() + q.norm_squared() - delta * delta),
    )
}

/// Subproblem 1 (see [`sp1`]) as a cosine and sine: the normalised
/// `(p′ᵀq′, kᵀ(p′ × q′))` of the projections normal to `k`; `(1, 0)` when
/// one vanishes.
fn sp1_cs(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>) -> Cs {
    let pp = p - k * k.dot(p);
    let qp = q - k * k.dot(q);
    let (c, s) = (pp.dot(&qp), k.dot(&pp.cross(&qp)));
    let n = (c * c + s * s).sqrt();
    if n <= DEGENERATE * DEGENERATE {
        (1.0, 0.0)
    } else {
        (c / n, s / n)
    }
}

/// One branch at one searched value: joints 1–3 (and the searched one), the
/// rotation left for the two joints of the meeting pair, and the residual.
#[derive(Debug, Clone, Copy)]
struct Eval {
    /// Joints 1–3 as cosines and sines.
    cs: [Cs; 3],
    /// `h_aᵀ Q h_b − h_aᵀ h_b`: zero exactly where the pair can produce `Q`.
    residual: f64,
    /// Every subproblem on the way held (no clamped root).
    in_range: bool,
    /// `E₁⁻¹ w` and the point `x` the first three joints place (flags).
    y: Vector3<f64>,
    x: Vector3<f64>,
}

/// The target in the form the search uses.
struct Target {
    g: Isometry3<f64>,
    rg: Matrix3<f64>,
}

impl AnalyticArm {
    /// The 1-D-search reading of a 6-joint arm, or why it has none: a
    /// closed-form position problem for the first three joints
    /// ([`Position`]) and two consecutive wrist axes (4–5 or 5–6) meeting.
    pub(crate) fn classify_searched(a: &Axes6, tol: f64) -> Result<Self, NotAnalytic> {
        let (h, p) = (a.h, a.p);
        let not = |r: &str| NotAnalytic { reason: r.into() };
        let position = if parallel(&h[1], &h[2], tol) {
            if parallel(&h[0], &h[1], tol) {
                return Err(not("axes 1, 2, 3 are parallel"));
            }
            Position::TwoThreeParallel
        } else if let Some((s, d)) = meet(&p[0], &h[0], &p[1], &h[1], tol)
            && d <= tol
        {
            Position::OneTwoMeet(s)
        } else if let Some((t, d)) = meet(&p[1], &h[1], &p[2], &h[2], tol)
            && d <= tol
        {
            if parallel(&h[0], &h[1], tol) {
                return Err(not("axes 1 and 2 are parallel"));
            }
            Position::TwoThreeMeet(t)
        } else {
            return Err(not(
                "axes 2 and 3 are neither parallel nor meet, and axes 1 and 2 do not meet (no closed-form \
                 position problem for joints 1-3; a 2-D search is not implemented)",
            ));
        };
        let pair = [4usize, 3].into_iter().find_map(|k| {
            meet(&p[k], &h[k], &p[k + 1], &h[k + 1], tol)
                .filter(|(_, d)| *d <= tol)
                .map(|(c, _)| (k, c))
        });
        let Some((pair, c)) = pair else {
            return Err(not(
                "neither axes 4, 5 nor axes 5, 6 meet (a 1-D search needs two consecutive wrist axes that meet; \
                 a 2-D search is not implemented)",
            ));
        };
        let mut forward = h[1].cross(&h[0]);
        if forward.norm() <= tol {
            forward = normal_to(&h[0]);
        }
        let mut forward = forward.normalize();
        if forward.dot(&(c - p[0])) < 0.0 {
            forward = -forward;
        }
        let shoulder = match position {
            Position::OneTwoMeet(s) => s,
            _ => Vector3::zeros(),
        };
        let geometry = SearchGeometry {
            position,
            pair,
            c,
            normal: normal_to(&h[pair + 1]),
        };
        Ok(Self {
            family: Family::Searched6R,
            h,
            p,
            m_inv: a.m.inverse(),
            wrist: c,
            shoulder,
            forward,
            q3_stretched: 0.0,
            q5_singular: sp1(&h[4], &h[5], &h[3], 1.0).angles[0],
            x6: normal_to(&h[5]),
            x2: normal_to(&h[1]),
            s3: 1.0,
            s4: 1.0,
            limits: a.limits,
            continuous: a.continuous,
            reversed: false,
            search: Some(geometry),
        })
    }

    /// The point joints 1–3 must carry (`x`) and where to (`w`), at the
    /// searched value `v`: with axes 5, 6 meeting at `c`, `G c = E₁E₂E₃E₄ c`
    /// so `x = E₄(v) c`, `w = G c`; with axes 4, 5 meeting,
    /// `G E₆(v)⁻¹ c = E₁E₂E₃ c` so `x = c`, `w = G E₆(v)⁻¹ c`.
    fn search_points(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        rv: &Matrix3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (p, c) = (&self.p, geo.c);
        if geo.pair == 4 {
            let x = rv * (c - p[3]) + p[3];
            (x, (t.g * Point3::from(c)).coords)
        } else {
            let back = rv.tr_mul(&(c - p[5])) + p[5];
            (c, (t.g * Point3::from(back)).coords)
        }
    }

    /// Branches `(i, j)` (index `2i + j`, roots of the first and second
    /// subproblem of the position problem) at the searched value `v`, all of
    /// them or only `only`.
    fn search_eval(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        v: f64,
        only: Option<usize>,
        out: &mut [Option<Eval>; 4],
    ) {
        *out = [None; 4];
        let (h, p) = (&self.h, &self.p);
        let (sv, cv) = v.sin_cos();
        let rv = rot_cs(&h[geo.searched()], (cv, sv));
        let (x, w) = self.search_points(geo, t, &rv);
        let want = |b: usize| only.is_none_or(|o| o == b);
        // the residual needs only h_aᵀ Q h_b: with pair (5, 6),
        // Q = (R₁R₂R₃R₄)ᵀ R_G, so h₅ᵀ Q h₆ = (R₁R₂R₃ R₄h₅)ᵀ (R_G h₆); with pair
        // (4, 5), Q = (R₁R₂R₃)ᵀ R_G R₆ᵀ, so h₄ᵀ Q h₅ = (R₁R₂R₃ h₄)ᵀ (R_G R₆ᵀ h₅)
        let (a, bb) = (geo.pair, geo.pair + 1);
        let (left, right) = if geo.pair == 4 {
            (rv * h[a], t.rg * h[bb])
        } else {
            (h[a], t.rg * rv.tr_mul(&h[bb]))
        };
        let target_dot = h[a].dot(&h[bb]);
        let mut finish = |b: usize, cs: [Cs; 3], in_range: bool, y: Vector3<f64>| {
            let r0 = rot_cs(&h[0], cs[0]);
            let r1 = rot_cs(&h[1], cs[1]);
            let r2 = rot_cs(&h[2], cs[2]);
            let residual = (r0 * (r1 * (r2 * left))).dot(&right) - target_dot;
            out[b] = Some(Eval {
                cs,
                residual,
                in_range,
                y,
                x,
            });
        };
        match geo.position {
            Position::TwoThreeParallel => {
                let Some((r1, ok1)) = sp4_both(&(w - p[0]), &h[0], &h[1], h[1].dot(&(x - p[0]))) else {
                    return;
                };
                for (i, &c0) in r1.iter().enumerate() {
                    if !(want(2 * i) || want(2 * i + 1)) {
                        continue;
                    }
                    let y = rot_cs(&h[0], c0).tr_mul(&(w - p[0])) + p[0];
                    let Some((r3, ok3)) = sp3_both(&h[2], &(x - p[2]), &(p[1] - p[2]), (y - p[1]).norm())
                    else {
                        continue;
                    };
                    for (j, &c2) in r3.iter().enumerate() {
                        if !want(2 * i + j) {
                            continue;
                        }
                        let e3x = rot_cs(&h[2], c2) * (x - p[2]) + p[2];
                        let c1 = sp1_cs(&h[1], &(e3x - p[1]), &(y - p[1]));
                        finish(2 * i + j, [c0, c1, c2], ok1 && ok3, y);
                    }
                }
            }
            Position::OneTwoMeet(s) => {
                let Some((r3, ok3)) = sp3_both(&h[2], &(x - p[2]), &(s - p[2]), (w - s).norm()) else {
                    return;
                };
                for (i, &c2) in r3.iter().enumerate() {
                    if !(want(2 * i) || want(2 * i + 1)) {
                        continue;
                    }
                    let u = rot_cs(&h[2], c2) * (x - p[2]) + p[2] - s;
                    // subproblem 2: h₁ᵀ R₂ u = h₁ᵀ (w − s), then R₁ (R₂ u) = w − s
                    let Some((r2, ok2)) = sp4_both(&h[0], &h[1], &u, h[0].dot(&(w - s))) else {
                        continue;
                    };
                    for (j, &c1) in r2.iter().enumerate() {
                        if !want(2 * i + j) {
                            continue;
                        }
                        let c0 = sp1_cs(&h[0], &(rot_cs(&h[1], c1) * u), &(w - s));
                        let y = rot_cs(&h[0], c0).tr_mul(&(w - p[0])) + p[0];
                        finish(2 * i + j, [c0, c1, c2], ok3 && ok2, y);
                    }
                }
            }
            Position::TwoThreeMeet(tp) => {
                let Some((r1, ok1)) = sp3_both(&h[0], &(tp - p[0]), &(w - p[0]), (x - tp).norm()) else {
                    return;
                };
                for (i, &c0) in r1.iter().enumerate() {
                    if !(want(2 * i) || want(2 * i + 1)) {
                        continue;
                    }
                    let y = rot_cs(&h[0], c0).tr_mul(&(w - p[0])) + p[0];
                    // subproblem 2: h₂ᵀ R₃ (x − t) = h₂ᵀ (y − t), then R₂ (R₃ (x − t)) = y − t
                    let Some((r3, ok3)) = sp4_both(&h[1], &h[2], &(x - tp), h[1].dot(&(y - tp))) else {
                        continue;
                    };
                    for (j, &c2) in r3.iter().enumerate() {
                        if !want(2 * i + j) {
                            continue;
                        }
                        let c1 = sp1_cs(&h[1], &(rot_cs(&h[2], c2) * (x - tp)), &(y - tp));
                        finish(2 * i + j, [c0, c1, c2], ok1 && ok3, y);
                    }
                }
            }
        }
    }

    /// Branch `b`'s residual at `v`, when the branch exists there.
    fn residual_at(&self, geo: &SearchGeometry, t: &Target, v: f64, b: usize) -> Option<f64> {
        let mut e = [None; 4];
        self.search_eval(geo, t, v, Some(b), &mut e);
        e[b].filter(|e| e.in_range).map(|e| e.residual)
    }

    /// Every solution of a [`Family::Searched6R`] arm for `G = T M⁻¹`.
    ///
    /// Method (after the 1-D searches of Elias & Wen, IK-Geo, 2025; our own
    /// derivation and code): with the wrist pair `(a, b)` meeting at `c`, the
    /// third wrist joint `v` (joint 4 when axes 5, 6 meet, joint 6 when axes
    /// 4, 5 meet) fixes the point joints 1–3 must place, which they do in
    /// closed form on up to four branches ([`Position`]); the rotation left,
    /// `Q(v) = R_a R_b`, is reachable by two joints only when
    /// `r(v) = h_aᵀ Q(v) h_b − h_aᵀ h_b = 0` (joint `a` keeps `h_a`, joint `b`
    /// keeps `h_b`). Each branch's `r` is sampled at `samples` evenly spaced
    /// values over the circle `(−π, π]`; (1) an interval whose ends differ in
    /// sign is refined by Brent's root finder (R. P. Brent, *Algorithms for
    /// Minimization without Derivatives*, 1973, ch. 4) to 1e-13 rad; (2) where
    /// a branch ends inside an interval (a fold: the position problem's two
    /// roots merge and `r` moves like the square root of the distance), the
    /// fold is found by bisection and the piece up to it sampled again evenly
    /// in that square root ([`Self::fold`]); (3) where `|r|` dips at a sample
    /// without a sign change around it, a golden-section search stops at the
    /// first sign change or at a tangent zero ([`Self::dip`]). At each root,
    /// `q_a` and `q_b` follow by subproblem 1.
    ///
    /// Guarantee: every returned root is exact to the root finder's
    /// tolerance (and re-checked by forward kinematics by the caller). A
    /// solution is missed only where one branch's `r` has an even number of
    /// zeros inside one sample spacing `2π/samples` that steps (2) and (3) do
    /// not reveal (zeros next to a fold together with another sign change, a
    /// wiggle of `r` with no dip at a sample), or where a branch exists only
    /// strictly between two samples. More samples narrow that, at four
    /// closed-form position solves each.
    pub(super) fn searched_6r(
        &self,
        g: &Isometry3<f64>,
        seed: &[f64; 6],
        keep: bool,
        tol: f64,
        samples: usize,
        out: &mut Base,
    ) {
        let Some(geo) = self.search else {
            return;
        };
        let t = Target {
            g: *g,
            rg: *g.rotation.to_rotation_matrix().matrix(),
        };
        let in_range = |e: &Option<Eval>| e.filter(|e| e.in_range).map(|e| e.residual);
        let n = samples.max(8);
        let step = TAU / n as f64;
        let mut first = [None; 4];
        let mut second = [None; 4];
        let mut prev = [None; 4];
        let mut prev2 = [None; 4];
        let mut cur = [None; 4];
        // the least |r| per branch (unreachable poses: the nearest answers)
        let mut least: [Option<(f64, f64)>; 4] = [None; 4];
        for k in 0..=n {
            let v = -PI + step * k as f64;
            if k < n {
                self.search_eval(&geo, &t, v, None, &mut cur);
                for (b, e) in cur.iter().enumerate() {
                    if let Some(e) = e
                        && least[b].is_none_or(|(r, _)| e.residual.abs() < r)
                    {
                        least[b] = Some((e.residual.abs(), v));
                    }
                }
            } else {
                cur = first;
            }
            if k == 0 {
                first = cur;
                prev = cur;
                continue;
            }
            if k == 1 {
                second = cur;
            }
            let a = v - step;
            for b in 0..4 {
                let (ra, rb) = (in_range(&prev[b]), in_range(&cur[b]));
                // a dip of |r| at the sample before: two roots may hide in it
                if let (Some(r0), Some(ra), Some(rb)) = (in_range(&prev2[b]), ra, rb)
                    && deep_dip(r0, ra, rb)
                {
                    self.dip(&geo, &t, b, (a - step, a, v), ra, (seed, tol), out);
                }
                match (ra, rb) {
                    (Some(ra), Some(rb)) => {
                        if let Some(x) = self.root(&geo, &t, b, (a, ra), (v, rb)) {
                            self.push_searched(&geo, &t, x, b, seed, tol, true, out);
                        }
                    }
                    (Some(ra), None) => self.fold(&geo, &t, b, (a, ra), v, (seed, tol), out),
                    (None, Some(rb)) => self.fold(&geo, &t, b, (v, rb), a, (seed, tol), out),
                    (None, None) => {}
                }
            }
            prev2 = prev;
            prev = cur;
        }
        // the dip test at the first sample, which the loop saw only as an end
        for b in 0..4 {
            if let (Some(r0), Some(ra), Some(rb)) =
                (in_range(&prev2[b]), in_range(&first[b]), in_range(&second[b]))
                && deep_dip(r0, ra, rb)
            {
                self.dip(&geo, &t, b, (-PI - step, -PI, -PI + step), ra, (seed, tol), out);
            }
        }
        if keep && out.n == 0 {
            for (b, l) in least.iter().enumerate() {
                if let Some((_, v)) = l {
                    self.push_searched(&geo, &t, *v, b, seed, tol, false, out);
                }
            }
        }
    }

    /// The piece of branch `b` from the sample `inside` (where it exists) to
    /// where it ends towards `outside`: near that end (a fold, where the
    /// branch meets its twin) the residual moves like the square root of the
    /// distance, so the piece is sampled again at [`FOLD_SAMPLES`] points
    /// spaced quadratically towards the end (evenly in that square root) and
    /// every sign change among them is refined.
    #[allow(clippy::too_many_arguments)]
    fn fold(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        b: usize,
        inside: (f64, f64),
        outside: f64,
        (seed, tol): (&[f64; 6], f64),
        out: &mut Base,
    ) {
        let end = self.branch_end(geo, t, b, inside.0, outside);
        let mut prev = inside;
        for k in (0..FOLD_SAMPLES).rev() {
            let s = k as f64 / FOLD_SAMPLES as f64;
            let v = end + (inside.0 - end) * s * s;
            let Some(r) = self.residual_at(geo, t, v, b) else {
                return;
            };
            if let Some(x) = self.root(geo, t, b, prev, (v, r)) {
                self.push_searched(geo, t, x, b, seed, tol, true, out);
            }
            prev = (v, r);
        }
    }

    /// A dip of `|r|` on branch `b` at the middle of three samples
    /// `(a, x, c)`, all of one sign: golden-section search (Kiefer 1953) for
    /// the least `|r|` on `[a, c]`, stopped as soon as `r` changes sign there
    /// (two roots, each then bracketed and refined) or touches zero within
    /// the tolerance (a tangent root, returned once).
    #[allow(clippy::too_many_arguments)]
    fn dip(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        b: usize,
        (a0, x0, c0): (f64, f64, f64),
        rx: f64,
        (seed, tol): (&[f64; 6], f64),
        out: &mut Base,
    ) {
        const GOLD: f64 = 0.381_966_011_250_105_1;
        let sign = rx.signum();
        let (mut a, mut c) = (a0, c0);
        let (mut x, mut fx) = (x0, rx.abs());
        for _ in 0..DIP_STEPS {
            if fx <= tol {
                self.push_searched(geo, t, x, b, seed, tol, true, out);
                return;
            }
            // the larger side's golden point
            let u = if x - a > c - x {
                x - GOLD * (x - a)
            } else {
                x + GOLD * (c - x)
            };
            let Some(ru) = self.residual_at(geo, t, u, b) else {
                return;
            };
            if ru * sign <= 0.0 {
                let (rl, rr) = (self.residual_at(geo, t, a0, b), self.residual_at(geo, t, c0, b));
                for side in [rl.map(|r| ((a0, r), (u, ru))), rr.map(|r| ((u, ru), (c0, r)))] {
                    if let Some((lo, hi)) = side
                        && let Some(root) = self.root(geo, t, b, lo, hi)
                    {
                        self.push_searched(geo, t, root, b, seed, tol, true, out);
                    }
                }
                return;
            }
            let fu = ru.abs();
            if fu < fx {
                if u < x {
                    c = x;
                } else {
                    a = x;
                }
                (x, fx) = (u, fu);
            } else if u < x {
                a = u;
            } else {
                c = u;
            }
            if c - a <= ROOT_TOLERANCE {
                return;
            }
        }
    }

    /// The last value from `inside` towards `outside` (within 2⁻³⁴ of their
    /// distance) where branch `b` still exists.
    fn branch_end(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        b: usize,
        mut inside: f64,
        mut outside: f64,
    ) -> f64 {
        let mut e = [None; 4];
        for _ in 0..BOUNDARY_STEPS {
            let m = 0.5 * (inside + outside);
            self.search_eval(geo, t, m, Some(b), &mut e);
            if e[b].is_some_and(|e| e.in_range) {
                inside = m;
            } else {
                outside = m;
            }
        }
        inside
    }

    /// Brent's root finder on branch `b` between `(a, r(a))` and `(c, r(c))`
    /// when their signs differ (a zero at an end counts); `None` otherwise or
    /// when the branch vanishes inside.
    fn root(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        b: usize,
        lo: (f64, f64),
        hi: (f64, f64),
    ) -> Option<f64> {
        let ((mut a, mut fa), (mut bx, mut fb)) = (lo, hi);
        if fa == 0.0 {
            return Some(a);
        }
        if fb == 0.0 {
            return Some(bx);
        }
        if (fa < 0.0) == (fb < 0.0) {
            return None;
        }
        let (mut c, mut fc) = (bx, fb);
        let (mut d, mut e) = (bx - a, bx - a);
        for _ in 0..MAX_ROOT_STEPS {
            if (fb > 0.0) == (fc > 0.0) {
                (c, fc) = (a, fa);
                d = bx - a;
                e = d;
            }
            if fc.abs() < fb.abs() {
                (a, fa) = (bx, fb);
                (bx, fb) = (c, fc);
                (c, fc) = (a, fa);
            }
            let tol1 = 2.0 * f64::EPSILON * bx.abs() + 0.5 * ROOT_TOLERANCE;
            let xm = 0.5 * (c - bx);
            if xm.abs() <= tol1 || fb == 0.0 {
                return Some(bx);
            }
            if e.abs() >= tol1 && fa.abs() > fb.abs() {
                // inverse quadratic interpolation, or secant when a == c
                let s = fb / fa;
                let (mut pp, mut qq) = if a == c {
                    (2.0 * xm * s, 1.0 - s)
                } else {
                    let q = fa / fc;
                    let r = fb / fc;
                    (
                        s * (2.0 * xm * q * (q - r) - (bx - a) * (r - 1.0)),
                        (q - 1.0) * (r - 1.0) * (s - 1.0),
                    )
                };
                if pp > 0.0 {
                    qq = -qq;
                }
                pp = pp.abs();
                if 2.0 * pp < (3.0 * xm * qq - (tol1 * qq).abs()).min((e * qq).abs()) {
                    e = d;
                    d = pp / qq;
                } else {
                    d = xm;
                    e = d;
                }
            } else {
                d = xm;
                e = d;
            }
            (a, fa) = (bx, fb);
            bx += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
            fb = self.residual_at(geo, t, bx, b)?;
        }
        Some(bx)
    }

    /// Completes branch `b` at searched value `v` with the pair's two joints
    /// (subproblem 1 each) and adds it unless an equal solution is there.
    #[allow(clippy::too_many_arguments)]
    fn push_searched(
        &self,
        geo: &SearchGeometry,
        t: &Target,
        v: f64,
        b: usize,
        seed: &[f64; 6],
        tol: f64,
        exact_root: bool,
        out: &mut Base,
    ) {
        let mut e = [None; 4];
        self.search_eval(geo, t, v, Some(b), &mut e);
        let Some(e) = e[b] else {
            return;
        };
        let (h, (a, bb)) = (&self.h, (geo.pair, geo.pair + 1));
        let r012 = rot_cs(&h[0], e.cs[0]) * rot_cs(&h[1], e.cs[1]) * rot_cs(&h[2], e.cs[2]);
        let rv = rot(&h[geo.searched()], v);
        // the rotation left to the pair: R_a R_b = Q
        let qm = if geo.pair == 4 {
            (r012 * rv).tr_mul(&t.rg)
        } else {
            r012.tr_mul(&t.rg) * rv.transpose()
        };
        let aa = pick(sp1(&h[a], &h[bb], &(qm * h[bb]), tol), seed[a]);
        let ra = rot(&h[a], aa.angles[0]);
        let ab = pick(
            sp1(&h[bb], &geo.normal, &(ra.tr_mul(&qm) * geo.normal), tol),
            seed[bb],
        );
        let mut q = [0.0; 6];
        for (i, (c, s)) in e.cs.iter().enumerate() {
            q[i] = s.atan2(*c);
        }
        q[geo.searched()] = v;
        q[a] = aa.angles[0];
        q[bb] = ab.angles[0];
        for x in &mut q {
            *x = wrap(*x);
        }
        let exact = exact_root && e.in_range && e.residual.abs() <= tol && aa.exact && ab.exact;
        if exact_root && !exact {
            return;
        }
        if out.sols[..out.n].iter().any(|s| {
            s.joints
                .iter()
                .zip(&q)
                .all(|(x, y)| wrap(x - y).abs() <= SAME_ROOT)
        }) {
            return;
        }
        out.push(
            q,
            self.searched_flags(&e.y, &e.x, q[2], q[4]),
            aa.free || ab.free,
            exact,
        );
    }

    /// Configuration flags of the searched family: the shoulder from
    /// `y = E₁⁻¹ w`, the elbow from joint 3 against the angle at which the arm
    /// from axis 2 (from the shoulder point when axes 1, 2 meet) to the placed
    /// point `x` is stretched, the wrist from joint 5 as for the other families.
    pub(super) fn searched_flags(&self, y: &Vector3<f64>, x: &Vector3<f64>, q3: f64, q5: f64) -> ConfigFlags {
        let (h, p) = (&self.h, &self.p);
        let near = match self.search.map(|g| g.position) {
            Some(Position::OneTwoMeet(s)) => s,
            _ => p[1],
        };
        let stretched = sp1(&h[2], &(x - p[2]), &(p[2] - near), 1.0).angles[0];
        ConfigFlags {
            shoulder_back: (y - p[0]).dot(&self.forward) < 0.0,
            elbow_down: (q3 - stretched).sin() < 0.0,
            wrist_flipped: (q5 - self.q5_singular).sin() < 0.0,
        }
    }

    /// [`AnalyticArm::config_of`] for the searched family (`q` in the solved
    /// arm's order).
    pub(super) fn searched_config(&self, q: &[f64; 6]) -> ConfigFlags {
        let Some(geo) = self.search else {
            return ConfigFlags::default();
        };
        let (h, p) = (&self.h, &self.p);
        let apply = |i: usize, x: Vector3<f64>| rot(&h[i], q[i]) * (x - p[i]) + p[i];
        let x = if geo.pair == 4 { apply(3, geo.c) } else { geo.c };
        let y = apply(1, apply(2, x));
        self.searched_flags(&y, &x, q[2], q[4])
    }
}
