//! A 7-joint arm held at a middle joint, re-posed for another held value by
//! turning only the joints after it (no new geometric analysis).

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::family::{AnalyticArm, Family};
use super::redundant::ChainAxes;
use super::subproblems::sp1;

/// The arm of a 7-joint chain with middle joint `j` held, analysed once at a
/// reference value `v₀` and then moved to any held value `v` by the rigid
/// motion `Eⱼ(v − v₀)` of the joints after `j` (see [`ChainAxes::held`]).
///
/// Valid when the analysed arm is [`Family::SphericalTwoIntersecting`] read
/// from the base and the held joint lies between the shoulder pair (the
/// arm's axes 1 and 2) and the wrist triple (axes 4, 5 and 6), i.e. chain
/// joint 3 or 4: a rigid motion of a group of axes keeps where they meet,
/// so the shoulder stays put and the wrist centre turns with its axes, and
/// the family's solver (subproblems 3 and 2 on the shoulder, then the wrist)
/// holds at every `v`. What depends on both groups is recomputed: the
/// forward direction's sign and the stretched-elbow angle `q₃ˢ`.
#[derive(Debug, Clone)]
pub(crate) struct TurnedArm {
    reference: AnalyticArm,
    v0: f64,
    /// First of the arm's six joints that turns with the held one.
    first: usize,
    /// The held joint's axis (unit) and a point on it, base frame.
    hj: Vector3<f64>,
    pj: Vector3<f64>,
    /// `M⁻¹` of the reference arm.
    m_inv0: Isometry3<f64>,
    /// Unsigned `h₂ × h₁` (unit): the forward direction up to its sign.
    forward: Vector3<f64>,
}

impl TurnedArm {
    /// The arm of `axes` with joint `j` held, read at `v0` (a value special
    /// to no geometry); `None` when `j` is not a middle joint of the kind
    /// above or the arm is not of that family there.
    pub fn new(axes: &ChainAxes, j: usize, v0: f64, tol: f64) -> Option<Self> {
        if axes.n != 7 || !(j == 2 || j == 3) {
            return None;
        }
        let reference = AnalyticArm::from_axes(&axes.held(j, v0), tol).ok()?;
        if reference.family != Family::SphericalTwoIntersecting || reference.reversed {
            return None;
        }
        Some(Self {
            v0,
            first: j,
            hj: axes.h[j],
            pj: axes.p[j],
            m_inv0: reference.m_inv,
            forward: reference.h[1].cross(&reference.h[0]).normalize(),
            reference,
        })
    }

    /// The arm with the held joint at `v` (rad).
    pub fn at(&self, v: f64) -> AnalyticArm {
        let q = UnitQuaternion::from_axis_angle(&Unit::new_unchecked(self.hj), v - self.v0);
        let r: Matrix3<f64> = *q.to_rotation_matrix().matrix();
        let a = &self.reference;
        let turn = |x: &Vector3<f64>| r * (x - self.pj) + self.pj;
        let mut out = a.clone();
        for k in self.first..6 {
            out.h[k] = r * a.h[k];
            out.p[k] = turn(&a.p[k]);
        }
        out.wrist = turn(&a.wrist);
        out.x6 = r * a.x6;
        // M(v) = Eⱼ(v − v₀) M(v₀), so M(v)⁻¹ = M(v₀)⁻¹ Eⱼ(v₀ − v)
        let back = q.inverse();
        let e = Isometry3::from_parts(Translation3::from(self.pj - back * self.pj), back);
        out.m_inv = self.m_inv0 * e;
        out.forward = if self.forward.dot(&(out.wrist - out.p[0])) < 0.0 {
            -self.forward
        } else {
            self.forward
        };
        let (h, p) = (&out.h, &out.p);
        out.q3_stretched = sp1(&h[2], &(out.wrist - p[2]), &(p[2] - out.shoulder), 1.0).angles[0];
        out
    }
}
