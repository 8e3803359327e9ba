//! Paden–Kahan subproblems: the rotations about known axes that move known
//! vectors into known relations. Each is a small pure function returning up to
//! two angles, an `exact` flag (false: the relation cannot hold and the angle
//! returned is the least-squares one) and a `free` flag (every angle satisfies
//! it equally, e.g. the vector lies on the axis; the caller chooses). Angles
//! are in (−π, π]; no input of finite vectors gives NaN.
//!
//! Sources: R. M. Murray, Z. Li, S. S. Sastry, *A Mathematical Introduction to
//! Robotic Manipulation* (1994), §3.2.2 (subproblems 1–3); A. J. Elias and
//! J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
//! decomposition", Mechanism and Machine Theory 209 (2025) (subproblem 4 and
//! the least-squares forms).

use nalgebra::{Matrix3, Vector3};

/// Lengths and projections below this are treated as zero (dimensionless for
/// unit axes; metres for points given in metres).
pub const DEGENERATE: f64 = 1e-12;

/// Subproblem 4 treats `|C/ρ| ≥ 1 − TANGENT` as tangent (one root).
pub const TANGENT: f64 = 1e-13;

/// The answer of one subproblem: `count` angles in `angles[..count]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angles {
    /// Solutions in (−π, π]; only the first `count` are meaningful.
    pub angles: [f64; 2],
    /// 1 or 2 (a tangent or least-squares answer is one angle).
    pub count: usize,
    /// The relation holds exactly (up to rounding); false: least-squares answer.
    pub exact: bool,
    /// Every angle is an equally good answer (degenerate geometry); `angles[0]`
    /// is then 0 by convention and the caller should substitute its own choice.
    pub free: bool,
}

impl Angles {
    fn one(a: f64, exact: bool) -> Self {
        Self {
            angles: [a, a],
            count: 1,
            exact,
            free: false,
        }
    }
    fn free(exact: bool) -> Self {
        Self {
            angles: [0.0, 0.0],
            count: 1,
            exact,
            free: true,
        }
    }
    /// The solutions as a slice.
    pub fn as_slice(&self) -> &[f64] {
        &self.angles[..self.count]
    }
}

/// Rotation matrix about unit axis `k` by `theta` (Rodrigues):
/// `R = I + sinθ [k]× + (1 − cosθ) [k]×²`.
///
/// ```
/// use kinplan_core::ik::analytic::rot;
/// let r = rot(&nalgebra::Vector3::z(), std::f64::consts::FRAC_PI_2);
/// assert!((r * nalgebra::Vector3::x() - nalgebra::Vector3::y()).norm() < 1e-15);
/// ```
#[inline]
pub fn rot(k: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    rot_cs(k, (c, s))
}

/// [`rot`] from `(cos θ, sin θ)`, for callers that have them without the angle.
#[inline]
pub(crate) fn rot_cs(k: &Vector3<f64>, (c, s): (f64, f64)) -> Matrix3<f64> {
    let v = 1.0 - c;
    let (x, y, z) = (k.x, k.y, k.z);
    Matrix3::new(
        c + x * x * v,
        x * y * v - z * s,
        x * z * v + y * s,
        y * x * v + z * s,
        c + y * y * v,
        y * z * v - x * s,
        z * x * v - y * s,
        z * y * v + x * s,
        c + z * z * v,
    )
}

/// Above this magnitude every `f64` is an integer (2⁵²).
const INTEGRAL: f64 = 4_503_599_627_370_496.0;

/// `x` rounded to the nearest integer, ties to even, in floating point:
/// adding and subtracting `2⁵²` to `|x| < 2⁵²` leaves no fraction bits (IEEE
/// 754 round-to-nearest), and the sign is put back. The baseline x86-64
/// target has no rounding instruction and calls the C library for
/// `f64::floor` and friends; this takes a few additions. Larger magnitudes
/// (integers already) and non-finite values are returned as they are.
#[inline]
fn round_even(x: f64) -> f64 {
    let a = x.abs();
    if a < INTEGRAL {
        ((a + INTEGRAL) - INTEGRAL).copysign(x)
    } else {
        x
    }
}

/// `⌊x⌋` (see [`round_even`]).
#[inline]
pub(crate) fn floor_f(x: f64) -> f64 {
    let r = round_even(x);
    if r > x { r - 1.0 } else { r }
}

/// `⌈x⌉` (see [`round_even`]).
#[inline]
pub(crate) fn ceil_f(x: f64) -> f64 {
    let r = round_even(x);
    if r < x { r + 1.0 } else { r }
}

/// `x` rounded half up, `⌊x + ½⌋` (see [`round_even`]).
#[inline]
pub(crate) fn round_f(x: f64) -> f64 {
    floor_f(x + 0.5)
}

/// Wraps an angle into (−π, π].
#[inline]
pub fn wrap(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let r = a - TAU * round_f(a / TAU);
    if r <= -PI { r + TAU } else { r }
}

/// Subproblem 1: the angle `θ` about unit axis `k` with `rot(k, θ) p = q`.
///
/// With `p′ = p − k kᵀp` and `q′ = q − k kᵀq` the projections onto the plane
/// normal to `k`: `θ = atan2(kᵀ(p′ × q′), p′ᵀq′)`. This is also the
/// least-squares angle (minimising `‖rot(k, θ) p − q‖`) when the relation
/// cannot hold (`kᵀp ≠ kᵀq` or `‖p′‖ ≠ ‖q′‖`), reported `exact = false`.
/// Free when `p′` or `q′` vanishes (a vector on the axis).
///
/// ```
/// use kinplan_core::ik::analytic::sp1;
/// use nalgebra::Vector3;
/// let a = sp1(&Vector3::z(), &Vector3::new(1.0, 0.0, 0.5), &Vector3::new(0.0, -1.0, 0.5), 1e-9);
/// assert!(a.exact && (a.angles[0] + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn sp1(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, tol: f64) -> Angles {
    sp1_cs(k, p, q, tol).angles
}

/// [`sp1`] with the angle's cosine and sine: `(p′ᵀq′, kᵀ(p′ × q′))` divided
/// by `‖p′‖ ‖q′‖`.
#[inline]
pub(crate) fn sp1_cs(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, tol: f64) -> AnglesCs {
    let kp = k.dot(p);
    let kq = k.dot(q);
    let pp = p - k * kp;
    let qp = q - k * kq;
    let (np, nq) = (pp.norm(), qp.norm());
    let exact = (kp - kq).abs() <= tol && (np - nq).abs() <= tol;
    if np <= DEGENERATE || nq <= DEGENERATE {
        return AnglesCs::of(Angles::free(exact));
    }
    let (c, s) = (pp.dot(&qp), k.dot(&pp.cross(&qp)));
    let n = 1.0 / (np * nq);
    AnglesCs::one(atan2_half_open(s, c), (c * n, s * n), exact)
}

/// `atan2(s, c)` in (−π, π] (`atan2(−0, c < 0)` is −π).
#[inline]
fn atan2_half_open(s: f64, c: f64) -> f64 {
    let t = s.atan2(c);
    if t == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        t
    }
}

/// A subproblem's answer with the cosine and sine of each angle, so that a
/// caller turning by it needs no trigonometric call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AnglesCs {
    pub angles: Angles,
    /// `(cos, sin)` of `angles.angles[i]`.
    pub cs: [(f64, f64); 2],
}

impl AnglesCs {
    /// From angles alone (cosines and sines computed).
    pub(crate) fn of(angles: Angles) -> Self {
        let cs = |a: f64| {
            let (s, c) = a.sin_cos();
            (c, s)
        };
        Self {
            angles,
            cs: [cs(angles.angles[0]), cs(angles.angles[1])],
        }
    }

    fn one(a: f64, cs: (f64, f64), exact: bool) -> Self {
        Self {
            angles: Angles::one(a, exact),
            cs: [cs, cs],
        }
    }

    /// Each angle with its `(cos, sin)`.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (f64, (f64, f64))> + '_ {
        self.angles.as_slice().iter().copied().zip(self.cs)
    }
}

/// Subproblem 4: the angles `θ` with `hᵀ rot(k, θ) p = d` (`k` a unit axis,
/// `h` any vector).
///
/// Writing `rot(k, θ) p = k kᵀp + cosθ (p − k kᵀp) + sinθ (k × p)` gives
/// `A cosθ + B sinθ = C` with `A = hᵀ(p − k kᵀp)`, `B = hᵀ(k × p)`,
/// `C = d − (hᵀk)(kᵀp)`, so with `ρ = √(A² + B²)` and `φ = atan2(B, A)`:
/// `θ = φ ± acos(C / ρ)`. When `|C| > ρ` there is no solution and the
/// least-squares one (`θ = φ` or `φ + π`) is returned, `exact = false`; free
/// when `ρ` vanishes (the left side does not depend on θ).
///
/// ```
/// use kinplan_core::ik::analytic::sp4;
/// use nalgebra::Vector3;
/// // rotate x about z until its y component is 0.5: θ = 30° or 150°
/// let a = sp4(&Vector3::y(), &Vector3::z(), &Vector3::x(), 0.5, 1e-9);
/// assert_eq!(a.count, 2);
/// let deg: Vec<f64> = a.as_slice().iter().map(|t| t.to_degrees()).collect();
/// assert!(deg.iter().any(|t| (t - 30.0).abs() < 1e-12) && deg.iter().any(|t| (t - 150.0).abs() < 1e-12));
/// ```
pub fn sp4(h: &Vector3<f64>, k: &Vector3<f64>, p: &Vector3<f64>, d: f64, tol: f64) -> Angles {
    sp4_cs(h, k, p, d, tol).angles
}

/// [`sp4`] with each angle's cosine and sine, from `cos φ = A/ρ`,
/// `sin φ = B/ρ`, `cos α = C/ρ`, `sin α = S/ρ` with `S = √((ρ − |C|)(ρ + |C|))`:
/// `cos(φ ± α) = (AC ∓ BS)/ρ²`, `sin(φ ± α) = (BC ± AS)/ρ²`, and the angles by
/// `atan2` of those (no `acos`, no wrapping).
#[inline]
pub(crate) fn sp4_cs(h: &Vector3<f64>, k: &Vector3<f64>, p: &Vector3<f64>, d: f64, tol: f64) -> AnglesCs {
    let kp = k.dot(p);
    let perp = p - k * kp;
    let a = h.dot(&perp);
    let b = h.dot(&k.cross(p));
    let c = d - h.dot(k) * kp;
    // √ rather than hypot: the terms are lengths of a robot's size
    let rho2 = a * a + b * b;
    let rho = rho2.sqrt();
    if rho <= DEGENERATE * (1.0 + h.norm() * p.norm()) {
        return AnglesCs::of(Angles::free(c.abs() <= tol));
    }
    let ratio = c / rho;
    if ratio.abs() >= 1.0 - TANGENT {
        // tangent (the two roots closer than ≈ √(2·TANGENT) rad merge into one,
        // so that a singular pose gives its exact singular angle), or out of
        // range: the nearest angle, φ or φ + π
        let exact = (c.abs() - rho) <= tol;
        let sign = if ratio > 0.0 { 1.0 } else { -1.0 };
        let (cp, sp) = (sign * a / rho, sign * b / rho);
        return AnglesCs::one(atan2_half_open(sp, cp), (cp, sp), exact);
    }
    let sa = ((rho - c.abs()) * (rho + c.abs())).sqrt();
    let inv = 1.0 / rho2;
    let plus = ((a * c - b * sa) * inv, (b * c + a * sa) * inv);
    let minus = ((a * c + b * sa) * inv, (b * c - a * sa) * inv);
    AnglesCs {
        angles: Angles {
            angles: [atan2_half_open(plus.1, plus.0), atan2_half_open(minus.1, minus.0)],
            count: 2,
            exact: true,
            free: false,
        },
        cs: [plus, minus],
    }
}

/// Subproblem 3: the angles `θ` about unit axis `k` with
/// `‖rot(k, θ) p − q‖ = δ`.
///
/// Expanding the square, `‖p‖² + ‖q‖² − 2 qᵀ rot(k, θ) p = δ²`, i.e.
/// subproblem 4 with `h = q` and `d = (‖p‖² + ‖q‖² − δ²) / 2`. Out of range
/// (`δ` beyond the reachable distances) returns the nearest angle with
/// `exact = false`; free when `p` or `q` lies on the axis.
///
/// ```
/// use kinplan_core::ik::analytic::sp3;
/// use nalgebra::Vector3;
/// // a unit arm about z from the origin, target (2, 0, 0), distance 1: θ = 0 only
/// let a = sp3(&Vector3::z(), &Vector3::x(), &Vector3::new(2.0, 0.0, 0.0), 1.0, 1e-9);
/// assert!(a.exact && a.count == 1 && a.angles[0].abs() < 1e-12);
/// ```
pub fn sp3(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, delta: f64, tol: f64) -> Angles {
    sp3_cs(k, p, q, delta, tol).angles
}

/// [`sp3`] with each angle's cosine and sine (see [`sp4_cs`]).
#[inline]
pub(crate) fn sp3_cs(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, delta: f64, tol: f64) -> AnglesCs {
    let d = 0.5 * (p.norm_squared() + q.norm_squared() - delta * delta);
    // tolerance on the distance δ becomes ≈ δ·tol on δ²/2
    sp4_cs(q, k, p, d, tol * (1.0 + delta))
}

/// Subproblem 2: the angle pairs `(θ₁, θ₂)` about unit axes `k₁`, `k₂` (through
/// a common point) with `rot(k₁, θ₁) rot(k₂, θ₂) p = q`.
///
/// Since `k₁ᵀ rot(k₁, θ₁) = k₁ᵀ`, `θ₂` solves subproblem 4
/// `k₁ᵀ rot(k₂, θ₂) p = k₁ᵀ q`; each `θ₂` then gives `θ₁` by subproblem 1,
/// `rot(k₁, θ₁) (rot(k₂, θ₂) p) = q`. Returns up to two pairs, `exact` and
/// the `free` flags of the two stages (`free.0`: θ₁ arbitrary, `q` on `k₁`;
/// `free.1`: θ₂ arbitrary).
///
/// ```
/// use kinplan_core::ik::analytic::sp2;
/// use nalgebra::Vector3;
/// // x → z: about y by −90° (θ₁ = 0), or about y by +90° then about x by 180°
/// let s = sp2(&Vector3::x(), &Vector3::y(), &Vector3::x(), &Vector3::z(), 1e-9);
/// assert_eq!(s.count, 2);
/// ```
pub fn sp2(k1: &Vector3<f64>, k2: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>, tol: f64) -> Pairs {
    let t2 = sp4(k1, k2, p, k1.dot(q), tol);
    let mut out = Pairs {
        pairs: [(0.0, 0.0); 2],
        count: t2.count,
        exact: t2.exact,
        free: (false, t2.free),
    };
    for (i, &b) in t2.as_slice().iter().enumerate() {
        let t1 = sp1(k1, &(rot(k2, b) * p), q, tol);
        out.pairs[i] = (t1.angles[0], b);
        out.exact &= t1.exact;
        out.free.0 |= t1.free;
    }
    out
}

/// Answer of [`sp2`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pairs {
    /// `(θ₁, θ₂)` in (−π, π]; the first `count` are meaningful.
    pub pairs: [(f64, f64); 2],
    pub count: usize,
    pub exact: bool,
    /// (θ₁ arbitrary, θ₂ arbitrary).
    pub free: (bool, bool),
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_4, PI};

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }
    fn has(a: &[f64], x: f64) -> bool {
        a.iter().any(|t| wrap(t - x).abs() < 1e-12)
    }

    #[test]
    fn rot_matches_hand_rotations() {
        // 90° about x takes y to z; 120° about (1,1,1)/√3 cycles x → y → z
        assert!((rot(&Vector3::x(), FRAC_PI_2) * Vector3::y() - Vector3::z()).norm() < 1e-15);
        let k = v(1.0, 1.0, 1.0).normalize();
        assert!((rot(&k, 2.0 * PI / 3.0) * Vector3::x() - Vector3::y()).norm() < 1e-15);
        assert!((rot(&k, 2.0 * PI / 3.0) * Vector3::y() - Vector3::z()).norm() < 1e-15);
    }

    #[test]
    fn floating_floor_ceil_round_match_the_c_library() {
        let mut xs = vec![
            -3.5f64,
            -3.0,
            -2.7,
            -0.5,
            -0.2,
            -0.0,
            0.0,
            0.2,
            0.5,
            0.7,
            1.0,
            2.5,
            3.2,
            1e15 + 0.5,
            -1e15 - 0.5,
            2.0f64.powi(51) - 0.5,
            -(2.0f64.powi(51) - 0.5),
            2.0f64.powi(51) + 0.5,
            2.0f64.powi(52) - 0.5,
            -(2.0f64.powi(52) - 0.5),
            2.0f64.powi(52),
            1e17,
            -1e17,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        // every value next to an integer, both sides
        for k in -40..=40 {
            let k = f64::from(k) * 0.5;
            xs.extend([k, k.next_up(), k.next_down()]);
        }
        for x in xs {
            assert_eq!(floor_f(x), x.floor(), "{x}");
            assert_eq!(ceil_f(x), x.ceil(), "{x}");
            assert_eq!(round_f(x), (x + 0.5).floor(), "{x}");
        }
        assert!(floor_f(f64::NAN).is_nan() && ceil_f(f64::NAN).is_nan() && round_f(f64::NAN).is_nan());
    }

    #[test]
    fn wrap_is_half_open() {
        assert_eq!(wrap(PI), PI);
        assert!((wrap(-PI) - PI).abs() < 1e-15);
        assert!((wrap(3.0 * PI / 2.0) + FRAC_PI_2).abs() < 1e-15);
        assert!((wrap(7.0) - (7.0 - 2.0 * PI)).abs() < 1e-15);
    }

    #[test]
    fn sp1_hand_cases() {
        // (1,0,0) → (cos60°, sin60°, 0) about z: 60°
        let a = sp1(
            &Vector3::z(),
            &Vector3::x(),
            &v(0.5, 3f64.sqrt() / 2.0, 0.0),
            1e-9,
        );
        assert!(a.exact && !a.free && (a.angles[0] - FRAC_PI_3).abs() < 1e-15);
        // about −z the same rotation is −60°
        let a = sp1(
            &-Vector3::z(),
            &Vector3::x(),
            &v(0.5, 3f64.sqrt() / 2.0, 0.0),
            1e-9,
        );
        assert!((a.angles[0] + FRAC_PI_3).abs() < 1e-15);
        // mismatched heights: least squares angle, not exact
        let a = sp1(&Vector3::z(), &Vector3::x(), &v(0.0, 2.0, 1.0), 1e-9);
        assert!(!a.exact && (a.angles[0] - FRAC_PI_2).abs() < 1e-15);
        // vector on the axis: free, no NaN
        let a = sp1(&Vector3::z(), &v(0.0, 0.0, 1.0), &v(0.0, 0.0, 1.0), 1e-9);
        assert!(a.free && a.exact && a.angles[0] == 0.0);
    }

    #[test]
    fn sp4_hand_cases() {
        // z-component of rot(x, θ) y equals sin θ: = 1 only at 90° (tangent)
        let a = sp4(&Vector3::z(), &Vector3::x(), &Vector3::y(), 1.0, 1e-9);
        assert!(a.exact && a.count == 1 && (a.angles[0] - FRAC_PI_2).abs() < 1e-12);
        // = 2 is out of reach: nearest is 90°, not exact
        let a = sp4(&Vector3::z(), &Vector3::x(), &Vector3::y(), 2.0, 1e-9);
        assert!(!a.exact && (a.angles[0] - FRAC_PI_2).abs() < 1e-12);
        // = −1/√2: −45° and −135°
        let a = sp4(
            &Vector3::z(),
            &Vector3::x(),
            &Vector3::y(),
            -FRAC_PI_4.sin(),
            1e-9,
        );
        assert_eq!(a.count, 2);
        assert!(has(a.as_slice(), -FRAC_PI_4) && has(a.as_slice(), -3.0 * FRAC_PI_4));
        // h along the axis: constant kᵀp part only → free (exact when d matches)
        let a = sp4(&Vector3::z(), &Vector3::z(), &v(1.0, 0.0, 0.3), 0.3, 1e-9);
        assert!(a.free && a.exact);
        let a = sp4(&Vector3::z(), &Vector3::z(), &v(1.0, 0.0, 0.3), 0.5, 1e-9);
        assert!(a.free && !a.exact);
    }

    #[test]
    fn sp3_hand_cases() {
        // arm of length 1 about z at the origin, target (1,1,0) at distance 1: θ = 0 or 90°
        let a = sp3(&Vector3::z(), &Vector3::x(), &v(1.0, 1.0, 0.0), 1.0, 1e-9);
        assert_eq!(a.count, 2);
        assert!(has(a.as_slice(), 0.0) && has(a.as_slice(), FRAC_PI_2));
        // with a height difference of 1 along the axis the planar distance is √(δ²−1)
        let a = sp3(
            &Vector3::z(),
            &v(1.0, 0.0, 0.0),
            &v(1.0, 1.0, 1.0),
            2f64.sqrt(),
            1e-9,
        );
        assert!(has(a.as_slice(), 0.0) && has(a.as_slice(), FRAC_PI_2));
        // too far: nearest angle points the arm at the target
        let a = sp3(&Vector3::z(), &Vector3::x(), &v(0.0, 3.0, 0.0), 0.5, 1e-9);
        assert!(!a.exact && a.count == 1 && (a.angles[0] - FRAC_PI_2).abs() < 1e-12);
        // p on the axis: the distance cannot change, free
        let a = sp3(
            &Vector3::z(),
            &v(0.0, 0.0, 1.0),
            &v(1.0, 0.0, 0.0),
            2f64.sqrt(),
            1e-9,
        );
        assert!(a.free && a.exact);
    }

    #[test]
    fn sp2_hand_cases() {
        let s = sp2(&Vector3::x(), &Vector3::y(), &Vector3::x(), &Vector3::z(), 1e-9);
        assert!(s.exact && s.count == 2);
        for &(t1, t2) in &s.pairs[..s.count] {
            let r = rot(&Vector3::x(), t1) * rot(&Vector3::y(), t2) * Vector3::x();
            assert!((r - Vector3::z()).norm() < 1e-12, "{t1} {t2}");
        }
        // the pairs by hand: (0, −90°) and (180°, 90°)
        let got: Vec<(f64, f64)> = s.pairs.to_vec();
        assert!(
            got.iter()
                .any(|&(a, b)| wrap(a).abs() < 1e-12 && (b + FRAC_PI_2).abs() < 1e-12)
        );
        assert!(
            got.iter()
                .any(|&(a, b)| (wrap(a - PI)).abs() < 1e-12 && (b - FRAC_PI_2).abs() < 1e-12)
        );
        // q on k₁: θ₁ free, θ₂ tangent
        let s = sp2(&Vector3::x(), &Vector3::y(), &Vector3::x(), &-Vector3::x(), 1e-9);
        assert!(s.exact && s.free.0 && s.count == 1 && wrap(s.pairs[0].1 - PI).abs() < 1e-12);
        // different lengths: not exact, still finite
        let s = sp2(
            &Vector3::x(),
            &Vector3::y(),
            &Vector3::x(),
            &v(0.0, 0.0, 3.0),
            1e-9,
        );
        assert!(!s.exact && s.pairs.iter().all(|&(a, b)| a.is_finite() && b.is_finite()));
    }
}
