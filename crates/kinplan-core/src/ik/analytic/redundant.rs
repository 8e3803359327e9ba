//! 7-joint arms: one joint held leaves a 6-joint arm of a covered family (the
//! iiwa with joint 3 held is a spherical shoulder and wrist; the Panda with
//! joint 7 held is one read from the tool end). The chain's axes are read
//! once per model ([`ChainModel`], kept with the chain); holding a joint then
//! only turns the axes after it.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::family::{AnalyticArm, Axes6, NotAnalytic, ZeroAxes};
use super::params::AnalyticParams;
use super::subproblems::rot;
use crate::robot::{Chain, JointKind};

/// Joints tried, in order, when [`AnalyticParams::redundant_joint`] is unset
/// (0-based chain indices): the middle joints first, then the end joints
/// (whose holding leaves the arm's geometry unchanged: only the tool or the
/// base moves), then joints 2 and 6.
const HOLD_ORDER: [usize; 7] = [2, 3, 4, 6, 0, 1, 5];

/// The joint axes of a 6- or 7-joint revolute chain in the zero
/// configuration, base frame (see [`ZeroAxes`]), with limits (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChainAxes {
    pub n: usize,
    pub h: [Vector3<f64>; 7],
    pub p: [Vector3<f64>; 7],
    pub m: Isometry3<f64>,
    pub limits: [(f64, f64); 7],
    pub continuous: [bool; 7],
}

impl ChainAxes {
    fn of(chain: &Chain) -> Result<Self, NotAnalytic> {
        let n = chain.dof();
        if n != 6 && n != 7 {
            return Err(NotAnalytic {
                reason: format!(
                    "it has {n} joints; the analytic solvers cover 6-joint arms and 7-joint arms with one \
                     joint held"
                ),
            });
        }
        if let Some(j) = chain.joints().iter().find(|j| j.kind == JointKind::Prismatic) {
            return Err(NotAnalytic {
                reason: format!("joint {} is prismatic", j.name),
            });
        }
        let z = ZeroAxes::of(chain);
        let mut out = Self {
            n,
            h: [Vector3::zeros(); 7],
            p: [Vector3::zeros(); 7],
            m: z.m,
            limits: [(0.0, 0.0); 7],
            continuous: [false; 7],
        };
        for (i, j) in chain.joints().iter().enumerate() {
            out.h[i] = z.h[i].normalize();
            out.p[i] = z.p[i];
            out.limits[i] = (j.lower, j.upper);
            out.continuous[i] = j.kind == JointKind::Continuous || !(j.upper - j.lower).is_finite();
        }
        Ok(out)
    }

    /// The six joints of a 6-joint chain.
    fn six(&self) -> Axes6 {
        Axes6 {
            h: std::array::from_fn(|i| self.h[i]),
            p: std::array::from_fn(|i| self.p[i]),
            m: self.m,
            limits: std::array::from_fn(|i| self.limits[i]),
            continuous: std::array::from_fn(|i| self.continuous[i]),
        }
    }

    /// `Eⱼ(v)`: joint `j`'s motion at `v` as a rigid transform of the base frame.
    pub fn motion(&self, j: usize, v: f64) -> Isometry3<f64> {
        let r = UnitQuaternion::from_axis_angle(&Unit::new_unchecked(self.h[j]), v);
        Isometry3::from_parts(Translation3::from(self.p[j] - r * self.p[j]), r)
    }

    /// The 7-joint chain with joint `j` held at `v`: since
    /// `Eⱼ(v) Eᵢ(θ) = E′ᵢ(θ) Eⱼ(v)` with `E′ᵢ` about `Rⱼ(v) hᵢ` through
    /// `Eⱼ(v) pᵢ`, the joints before `j` keep their axes, those after it turn
    /// with `Eⱼ(v)`, and the tool pose becomes `Eⱼ(v) M`.
    pub fn held(&self, j: usize, v: f64) -> Axes6 {
        let r = rot(&self.h[j], v);
        let pj = self.p[j];
        let idx = |k: usize| if k < j { k } else { k + 1 };
        Axes6 {
            h: std::array::from_fn(|k| {
                let i = idx(k);
                if i < j { self.h[i] } else { r * self.h[i] }
            }),
            p: std::array::from_fn(|k| {
                let i = idx(k);
                if i < j {
                    self.p[i]
                } else {
                    r * (self.p[i] - pj) + pj
                }
            }),
            m: self.motion(j, v) * self.m,
            limits: std::array::from_fn(|k| self.limits[idx(k)]),
            continuous: std::array::from_fn(|k| self.continuous[idx(k)]),
        }
    }

    /// A value of joint `j` special to no geometry: 0.382 of the way across its
    /// limits (0.5 rad when unlimited).
    pub(crate) fn generic(&self, j: usize) -> f64 {
        let (lo, hi) = self.limits[j];
        if lo.is_finite() && hi.is_finite() {
            lo + 0.381_966 * (hi - lo)
        } else {
            0.5
        }
    }

    /// The middle of joint `j`'s limits (0 when unlimited).
    pub fn mid(&self, j: usize) -> f64 {
        let (lo, hi) = self.limits[j];
        if lo.is_finite() && hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            0.0
        }
    }
}

/// What the default analysis (geometry tolerance of
/// [`AnalyticParams::default`]) found.
#[derive(Debug, Clone, PartialEq)]
enum Default6or7 {
    /// A 6-joint chain's arm.
    Six(Box<AnalyticArm>),
    /// A 7-joint chain: the joint held by default (its family read at the
    /// middle of its limits).
    Hold(usize),
}

/// The analytic method's reading of one chain, made on first use and kept
/// with the chain (a model shared by many requests reads it once): the joint
/// axes and the default family or held joint.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainModel {
    axes: Result<ChainAxes, NotAnalytic>,
    default: Result<Default6or7, NotAnalytic>,
}

impl ChainModel {
    fn of(chain: &Chain) -> Self {
        let axes = ChainAxes::of(chain);
        let tol = AnalyticParams::default().geometry_tolerance;
        let default = match &axes {
            Err(e) => Err(e.clone()),
            Ok(a) if a.n == 6 => {
                AnalyticArm::from_axes6(&a.six(), tol).map(|arm| Default6or7::Six(Box::new(arm)))
            }
            Ok(a) => default_hold(a, tol).map(Default6or7::Hold),
        };
        Self { axes, default }
    }

    /// The chain's model, read on first use and then kept with the chain.
    pub(crate) fn of_chain(chain: &Chain) -> &Self {
        chain.analytic_cache().get_or_init(|| Self::of(chain))
    }

    pub(crate) fn axes(&self) -> Result<&ChainAxes, NotAnalytic> {
        self.axes.as_ref().map_err(Clone::clone)
    }
}

const NONE_COVERED: &str = "it has 7 joints and holding any one of them leaves no covered 6-joint arm, read from \
                            either end (the searched 6-joint family is not offered with a held joint)";

/// The first joint of [`HOLD_ORDER`] whose holding leaves a covered arm, read
/// at two values so that a value special to the geometry (the Panda's joint 5
/// at 0 lines axes 4 and 6 up) does not decide.
fn default_hold(a: &ChainAxes, tol: f64) -> Result<usize, NotAnalytic> {
    HOLD_ORDER
        .iter()
        .copied()
        .find(|&j| {
            [a.mid(j), a.generic(j)]
                .iter()
                .all(|&v| AnalyticArm::from_axes(&a.held(j, v), tol).is_ok())
        })
        .ok_or_else(|| NotAnalytic {
            reason: NONE_COVERED.into(),
        })
}

/// The first joint of [`HOLD_ORDER`] whose holding at `value(j)` leaves a
/// covered arm.
fn first_hold(
    axes: &ChainAxes,
    tol: f64,
    value: impl Fn(usize) -> f64,
) -> Result<(usize, AnalyticArm), NotAnalytic> {
    HOLD_ORDER
        .iter()
        .find_map(|&j| {
            AnalyticArm::from_axes(&axes.held(j, value(j)), tol)
                .ok()
                .map(|a| (j, a))
        })
        .ok_or_else(|| NotAnalytic {
            reason: NONE_COVERED.into(),
        })
}

/// The analytic arm of a chain: the chain itself (6 joints), or the chain with
/// one joint held (7 joints).
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedArm {
    pub arm: AnalyticArm,
    /// `(chain index, value)` of the held joint (rad) for a 7-joint chain.
    pub held: Option<(usize, f64)>,
}

impl ReducedArm {
    /// The 6 joints the arm solves for, from a full joint vector.
    pub fn reduce(&self, q: &[f64]) -> Vec<f64> {
        match self.held {
            Some((j, _)) => q
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != j)
                .map(|(_, v)| *v)
                .collect(),
            None => q.to_vec(),
        }
    }

    /// A full joint vector from the arm's 6 joints (the held value inserted).
    pub fn expand(&self, q6: &[f64; 6]) -> Vec<f64> {
        let mut out = q6.to_vec();
        if let Some((j, v)) = self.held {
            out.insert(j, v);
        }
        out
    }
}

/// Analyses `chain` for the analytic method. A 6-joint chain is analysed as it
/// is. A 7-joint chain has its redundant joint held at the seed's value (the
/// middle of its limits without a seed): `params.redundant_joint`, or else the
/// first of joints 3, 4, 5, 7, 1, 2, 6 whose holding leaves a covered arm
/// (read from the base or from the tool end; the family is read at the held
/// value). The chain's axes and the default choice are read once per chain
/// ([`ChainModel`]); each call only turns the axes after the held joint.
///
/// ```
/// use kinplan_core::ik::analytic::{AnalyticParams, Family, analyse};
/// let iiwa = kinplan_core::robot::builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
/// let seed = [0.1, 0.5, 0.3, -1.2, 0.2, 0.9, 0.0];
/// let r = analyse(&iiwa, &AnalyticParams::default(), Some(&seed)).unwrap();
/// assert_eq!(r.held, Some((2, 0.3)));
/// assert_eq!(r.arm.family(), Family::SphericalTwoIntersecting);
/// let panda = kinplan_core::robot::builtin_chain("franka_panda").unwrap();
/// let r = analyse(&panda, &AnalyticParams::default(), None).unwrap();
/// assert_eq!(r.held, Some((6, 0.0)));
/// assert!(r.arm.is_reversed());
/// ```
pub fn analyse(
    chain: &Chain,
    params: &AnalyticParams,
    seed: Option<&[f64]>,
) -> Result<ReducedArm, NotAnalytic> {
    let model = ChainModel::of_chain(chain);
    let axes = model.axes()?;
    let tol = params.geometry_tolerance;
    let cached = tol == AnalyticParams::default().geometry_tolerance;
    if axes.n == 6 {
        return match &model.default {
            Ok(Default6or7::Six(arm)) if cached => Ok(ReducedArm {
                arm: (**arm).clone(),
                held: None,
            }),
            _ => AnalyticArm::from_axes6(&axes.six(), tol).map(|arm| ReducedArm { arm, held: None }),
        };
    }
    let value = |j: usize| match seed {
        Some(s) if s.len() == 7 => s[j],
        _ => axes.mid(j),
    };
    let hold = |j: usize| {
        let v = value(j);
        AnalyticArm::from_axes(&axes.held(j, v), tol).map(|arm| ReducedArm {
            arm,
            held: Some((j, v)),
        })
    };
    match params.redundant_joint {
        Some(j) if j < 7 => hold(j).map_err(|e| NotAnalytic {
            reason: format!("with joint {} held: {}", j + 1, e.reason),
        }),
        Some(j) => Err(NotAnalytic {
            reason: format!("redundant_joint {j} is not a joint of this 7-joint chain"),
        }),
        None => {
            // the default joint, unless this value of it is degenerate
            let j = match &model.default {
                Ok(Default6or7::Hold(j)) if cached => Ok(*j),
                _ => default_hold(axes, tol),
            };
            if let Ok(r) = j.and_then(hold) {
                return Ok(r);
            }
            first_hold(axes, tol, value).map(|(j, arm)| ReducedArm {
                arm,
                held: Some((j, value(j))),
            })
        }
    }
}

/// Joint `j` held at `v` for a chain already analysed with `j` held.
pub(crate) fn hold_at(axes: &ChainAxes, j: usize, v: f64, tol: f64) -> Result<ReducedArm, NotAnalytic> {
    AnalyticArm::from_axes(&axes.held(j, v), tol).map(|arm| ReducedArm {
        arm,
        held: Some((j, v)),
    })
}
