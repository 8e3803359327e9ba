//! Geometric analysis of a chain at load: its joint axes and points in the
//! zero configuration (base frame) and which closed-form family it belongs to.

use std::fmt;

use nalgebra::{Isometry3, Point3, Vector3};

use super::subproblems::sp1;
use crate::robot::{Chain, JointKind};

/// The closed-form families the analytic solvers cover (6 revolute joints).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Axes 4, 5, 6 meet in one point (the wrist centre) and axes 2, 3 are
    /// parallel (KUKA, ABB, Fanuc … arms; shoulder offsets allowed). Up to 8
    /// solutions.
    SphericalWrist,
    /// Axes 2, 3, 4 are parallel and axes 5, 6 meet (Universal Robots arms).
    /// Up to 8 solutions.
    ThreeParallel,
    /// Axes 4, 5, 6 meet (the wrist centre) and axes 1, 2 meet (a spherical
    /// shoulder): a 7-joint S-R-S arm such as the iiwa with its third joint
    /// held. Up to 8 solutions.
    SphericalTwoIntersecting,
    /// None of the above from either end, but joints 1–3 place a point in
    /// closed form (axes 2, 3 parallel, or axes 1, 2 or 2, 3 meeting) and two
    /// consecutive wrist axes (4, 5 or 5, 6) meet: the third wrist joint is
    /// searched (an offset wrist). Up to 16 solutions.
    Searched6R,
}

impl Family {
    /// The family's name on the wire ("spherical_wrist", "three_parallel").
    pub fn name(self) -> &'static str {
        match self {
            Family::SphericalWrist => "spherical_wrist",
            Family::ThreeParallel => "three_parallel",
            Family::SphericalTwoIntersecting => "spherical_two_intersecting",
            Family::Searched6R => "searched_6r",
        }
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a chain has no closed-form solver here.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("chain is not analytic: {reason}")]
pub struct NotAnalytic {
    pub reason: String,
}

fn not(reason: impl Into<String>) -> NotAnalytic {
    NotAnalytic {
        reason: reason.into(),
    }
}

/// Joint axes of a chain in the zero configuration, base frame: unit
/// directions `h[i]`, a point `p[i]` on each axis (the joint frame's origin),
/// and the tool pose `m` at zero. Forward kinematics is then the product of
/// exponentials `T(q) = E₁(q₁) ⋯ Eₙ(qₙ) M` with `Eᵢ(θ) x = rot(hᵢ, θ)(x − pᵢ) + pᵢ`
/// (Murray, Li & Sastry 1994, §3.2).
#[derive(Debug, Clone, PartialEq)]
pub struct ZeroAxes {
    pub h: Vec<Vector3<f64>>,
    pub p: Vec<Vector3<f64>>,
    pub m: Isometry3<f64>,
}

impl ZeroAxes {
    /// Reads the axes of `chain` (every joint, prismatic ones included).
    pub fn of(chain: &Chain) -> Self {
        let mut t = Isometry3::identity();
        let mut h = Vec::with_capacity(chain.dof());
        let mut p = Vec::with_capacity(chain.dof());
        for j in chain.joints() {
            t *= j.origin;
            h.push(t.rotation * j.axis.into_inner());
            p.push(t.translation.vector);
        }
        Self {
            h,
            p,
            m: t * chain.tip_offset(),
        }
    }
}

/// Distance from point `x` to the line through `p` along unit `h`.
pub(crate) fn point_line_distance(x: &Vector3<f64>, p: &Vector3<f64>, h: &Vector3<f64>) -> f64 {
    let d = x - p;
    (d - h * h.dot(&d)).norm()
}

/// The point where two non-parallel lines meet (the midpoint of their common
/// normal) and their distance; `None` when parallel within `tol`.
pub(crate) fn meet(
    pa: &Vector3<f64>,
    ha: &Vector3<f64>,
    pb: &Vector3<f64>,
    hb: &Vector3<f64>,
    tol: f64,
) -> Option<(Vector3<f64>, f64)> {
    let n = ha.cross(hb);
    let nn = n.norm_squared();
    if nn.sqrt() <= tol {
        return None;
    }
    let d = pb - pa;
    let ta = d.cross(hb).dot(&n) / nn;
    let tb = d.cross(ha).dot(&n) / nn;
    let xa = pa + ha * ta;
    let xb = pb + hb * tb;
    Some(((xa + xb) * 0.5, (xa - xb).norm()))
}

pub(crate) fn parallel(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    a.cross(b).norm() <= tol
}

/// A chain analysed for the closed-form solvers: its family, zero-configuration
/// axes and the reference angles its configuration flags are measured from.
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyticArm {
    pub(super) family: Family,
    pub(super) h: [Vector3<f64>; 6],
    pub(super) p: [Vector3<f64>; 6],
    /// Inverse of the tool pose at zero, `M⁻¹`.
    pub(super) m_inv: Isometry3<f64>,
    /// Spherical wrist: the wrist centre; three parallel: where axes 5 and 6 meet.
    pub(super) wrist: Vector3<f64>,
    /// Where axes 1 and 2 meet (spherical two intersecting only; else zero).
    pub(super) shoulder: Vector3<f64>,
    /// Unit `h₂ × h₁`, signed to point from axis 1 towards the wrist at zero.
    pub(super) forward: Vector3<f64>,
    /// Joint-3 angle at which the arm from axis 2 to the wrist (spherical) or
    /// to axis 4 (three parallel) is stretched.
    pub(super) q3_stretched: f64,
    /// Joint-5 angle at which axis 6 lines up with axis 4 (spherical) or with
    /// axis 2 (three parallel): the wrist singularity.
    pub(super) q5_singular: f64,
    /// A unit vector normal to `h₆` and one normal to `h₂`.
    pub(super) x6: Vector3<f64>,
    pub(super) x2: Vector3<f64>,
    /// `±1`: `h₃·h₂` and `h₄·h₂` signs (three parallel only).
    pub(super) s3: f64,
    pub(super) s4: f64,
    /// Limits and whether each joint is continuous, in chain order (also when
    /// the arm is solved reversed).
    pub(super) limits: [(f64, f64); 6],
    pub(super) continuous: [bool; 6],
    /// The family is that of the chain read from the tool end (see
    /// [`Axes6::reversed`]): the solvers invert the pose and reverse the joints.
    pub(super) reversed: bool,
    /// The searched family's geometry ([`Family::Searched6R`] only).
    pub(super) search: Option<super::general::SearchGeometry>,
}

/// The six joints an analytic arm solves for: unit axes `h`, points `p` on
/// them and the tool pose `m`, in the zero configuration and base frame, with
/// the joints' limits (rad) and whether each is continuous.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Axes6 {
    pub h: [Vector3<f64>; 6],
    pub p: [Vector3<f64>; 6],
    pub m: Isometry3<f64>,
    pub limits: [(f64, f64); 6],
    pub continuous: [bool; 6],
}

impl Axes6 {
    /// The same arm read from the tool end. With `T(q) = E₁(q₁)⋯E₆(q₆) M`,
    /// `T⁻¹ = M⁻¹ E₆(−q₆)⋯E₁(−q₁) = E′₁(q₆)⋯E′₆(q₁) M⁻¹`, where `E′ₖ` turns
    /// about `h′ₖ = −R_Mᵀ h₇₋ₖ` through `p′ₖ = M⁻¹ p₇₋ₖ` (conjugation by `M`
    /// moves a screw axis; the sign makes the angle the original joint's).
    /// So the reversed arm, with tool pose `M⁻¹`, reaches `T⁻¹` at the joint
    /// values of `T` in reverse order.
    pub fn reversed(&self) -> Self {
        let mi = self.m.inverse();
        Self {
            h: std::array::from_fn(|k| -(mi.rotation * self.h[5 - k])),
            p: std::array::from_fn(|k| (mi * Point3::from(self.p[5 - k])).coords),
            m: mi,
            limits: std::array::from_fn(|k| self.limits[5 - k]),
            continuous: std::array::from_fn(|k| self.continuous[5 - k]),
        }
    }
}

pub(crate) fn normal_to(h: &Vector3<f64>) -> Vector3<f64> {
    let a = if h.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (a - h * h.dot(&a)).normalize()
}

impl AnalyticArm {
    /// Analyses `chain`: 6 revolute joints in one of the [`Family`] geometries
    /// within `tol` (rad for directions, m for distances), or why not.
    ///
    /// ```
    /// use kinplan_core::ik::analytic::{AnalyticArm, Family};
    /// let kr = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra").unwrap();
    /// assert_eq!(AnalyticArm::new(&kr, 1e-9).unwrap().family(), Family::SphericalWrist);
    /// let panda = kinplan_core::robot::builtin_chain("franka_panda").unwrap();
    /// assert!(AnalyticArm::new(&panda, 1e-9).unwrap_err().to_string().contains("7 joints"));
    /// ```
    pub fn new(chain: &Chain, tol: f64) -> Result<Self, NotAnalytic> {
        let n = chain.dof();
        if n != 6 {
            return Err(not(format!(
                "it has {n} joints; the analytic solvers cover 6-joint arms{}",
                if n == 7 {
                    " (hold one of a 7-joint arm's joints: ik::analytic::analyse)"
                } else {
                    ""
                }
            )));
        }
        if let Some(j) = chain.joints().iter().find(|j| j.kind == JointKind::Prismatic) {
            return Err(not(format!("joint {} is prismatic", j.name)));
        }
        let z = ZeroAxes::of(chain);
        let axes = Axes6 {
            h: std::array::from_fn(|i| z.h[i].normalize()),
            p: std::array::from_fn(|i| z.p[i]),
            m: z.m,
            limits: std::array::from_fn(|i| {
                let j = &chain.joints()[i];
                (j.lower, j.upper)
            }),
            continuous: std::array::from_fn(|i| {
                let j = &chain.joints()[i];
                j.kind == JointKind::Continuous || !(j.upper - j.lower).is_finite()
            }),
        };
        Self::from_axes6(&axes, tol)
    }

    /// The family of a 6-joint chain: a closed-form one ([`Self::from_axes`]),
    /// else the searched one read from the base, else from the tool end.
    pub(crate) fn from_axes6(axes: &Axes6, tol: f64) -> Result<Self, NotAnalytic> {
        let closed = match Self::from_axes(axes, tol) {
            Ok(arm) => return Ok(arm),
            Err(e) => e,
        };
        let forward = match Self::classify_searched(axes, tol) {
            Ok(arm) => return Ok(arm),
            Err(e) => e,
        };
        match Self::classify_searched(&axes.reversed(), tol) {
            Ok(mut arm) => {
                arm.reversed = true;
                arm.limits = axes.limits;
                arm.continuous = axes.continuous;
                Ok(arm)
            }
            Err(back) => Err(NotAnalytic {
                reason: format!(
                    "{}; for a 1-D search: {}; read from the tool end, {}",
                    closed.reason, forward.reason, back.reason
                ),
            }),
        }
    }

    /// The family of six revolute joints given by their axes: read from the
    /// base, or else from the tool end ([`Axes6::reversed`]; the Panda with
    /// joint 7 held is a spherical shoulder at the base and two meeting axes
    /// near the tool, i.e. `spherical_two_intersecting` reversed).
    pub(crate) fn from_axes(axes: &Axes6, tol: f64) -> Result<Self, NotAnalytic> {
        let forward = match Self::classify(axes, tol) {
            Ok(arm) => return Ok(arm),
            Err(e) => e,
        };
        match Self::classify(&axes.reversed(), tol) {
            Ok(mut arm) => {
                arm.reversed = true;
                arm.limits = axes.limits;
                arm.continuous = axes.continuous;
                Ok(arm)
            }
            Err(back) if back.reason == forward.reason => Err(forward),
            Err(back) => Err(not(format!(
                "{}; read from the tool end, {}",
                forward.reason, back.reason
            ))),
        }
    }

    fn classify(a: &Axes6, tol: f64) -> Result<Self, NotAnalytic> {
        let (h, p) = (a.h, a.p);
        if parallel(&h[0], &h[1], tol) {
            return Err(not("axes 1 and 2 are parallel"));
        }
        let spherical = meet(&p[3], &h[3], &p[4], &h[4], tol)
            .filter(|(w, d)| *d <= tol && point_line_distance(w, &p[5], &h[5]) <= tol)
            .map(|(w, _)| w);
        let mut shoulder = Vector3::zeros();
        let (family, wrist) = if let Some(w) = spherical {
            if parallel(&h[4], &h[5], tol) {
                return Err(not("wrist axes 5 and 6 are parallel"));
            }
            if point_line_distance(&w, &p[2], &h[2]) <= tol {
                return Err(not("the wrist centre lies on axis 3"));
            }
            if parallel(&h[1], &h[2], tol) {
                (Family::SphericalWrist, w)
            } else if let Some((s, d)) = meet(&p[0], &h[0], &p[1], &h[1], tol)
                && d <= tol
            {
                if point_line_distance(&s, &p[2], &h[2]) <= tol {
                    return Err(not("the shoulder (where axes 1 and 2 meet) lies on axis 3"));
                }
                shoulder = s;
                (Family::SphericalTwoIntersecting, w)
            } else {
                return Err(not(
                    "it has a spherical wrist, but axes 2 and 3 are not parallel and axes 1 and 2 do \
                     not meet (a general 3-joint position problem is not implemented)",
                ));
            }
        } else if parallel(&h[1], &h[2], tol) && parallel(&h[1], &h[3], tol) {
            let Some((w, d)) = meet(&p[4], &h[4], &p[5], &h[5], tol) else {
                return Err(not(
                    "axes 2, 3, 4 are parallel, but axes 5 and 6 are parallel too",
                ));
            };
            if d > tol {
                return Err(not(format!(
                    "axes 2, 3, 4 are parallel, but axes 5 and 6 do not meet (they are {d:.3e} m apart)"
                )));
            }
            if parallel(&h[4], &h[1], tol) {
                return Err(not("axes 2, 3, 4 are parallel, and axis 5 is parallel to them"));
            }
            if point_line_distance(&p[3], &p[2], &h[2]) <= tol {
                return Err(not("axes 3 and 4 coincide"));
            }
            (Family::ThreeParallel, w)
        } else {
            return Err(not(
                "axes 4, 5, 6 do not meet in a point and axes 2, 3, 4 are not parallel",
            ));
        };
        let mut forward = h[1].cross(&h[0]).normalize();
        if forward.dot(&(wrist - p[0])) < 0.0 {
            forward = -forward;
        }
        // the arm from axis 2 through joint 3 to `far` is stretched when
        // rot(h₃, q₃)(far − p₃) points along (p₃ − p₂) in the plane normal to h₃
        let (far, near) = match family {
            Family::SphericalWrist => (wrist, p[1]),
            Family::ThreeParallel => (p[3], p[1]),
            Family::SphericalTwoIntersecting | Family::Searched6R => (wrist, shoulder),
        };
        let q3_stretched = sp1(&h[2], &(far - p[2]), &(p[2] - near), 1.0).angles[0];
        let singular_with = match family {
            Family::SphericalWrist | Family::SphericalTwoIntersecting | Family::Searched6R => h[3],
            Family::ThreeParallel => h[1],
        };
        let q5_singular = sp1(&h[4], &h[5], &singular_with, 1.0).angles[0];
        Ok(Self {
            family,
            h,
            p,
            m_inv: a.m.inverse(),
            wrist,
            shoulder,
            forward,
            q3_stretched,
            q5_singular,
            x6: normal_to(&h[5]),
            x2: normal_to(&h[1]),
            s3: h[2].dot(&h[1]).signum(),
            s4: h[3].dot(&h[1]).signum(),
            limits: a.limits,
            continuous: a.continuous,
            reversed: false,
            search: None,
        })
    }

    /// The chain's closed-form family.
    pub fn family(&self) -> Family {
        self.family
    }

    /// Base frame, zero configuration (m): the wrist centre (spherical wrist) or
    /// the point where axes 5 and 6 meet (three parallel); for a reversed arm,
    /// that point of the reversed chain (where the chain's first axes meet).
    pub fn wrist_point(&self) -> Vector3<f64> {
        if self.reversed {
            // the reversed arm's frame is the tool frame at zero; its m_inv is M
            (self.m_inv * Point3::from(self.wrist)).coords
        } else {
            self.wrist
        }
    }

    /// True when the family holds for the chain read from the tool end: the
    /// configuration flags then name the reversed chain's shoulder, elbow and
    /// wrist (the chain's wrist, elbow and shoulder).
    pub fn is_reversed(&self) -> bool {
        self.reversed
    }
}
