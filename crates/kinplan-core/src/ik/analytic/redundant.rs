//! 7-joint arms: one joint held at the seed's value leaves a 6-joint arm of a
//! covered family (the iiwa with joint 3 held is a spherical shoulder and wrist).

use super::family::{AnalyticArm, NotAnalytic};
use super::params::AnalyticParams;
use crate::robot::Chain;

/// Joints tried, in order, when [`AnalyticParams::redundant_joint`] is unset:
/// the middle joints first (0-based chain indices).
const HOLD_ORDER: [usize; 7] = [2, 3, 4, 1, 5, 0, 6];

/// The analytic arm of a chain: the chain itself (6 joints), or the chain with
/// one joint held (7 joints).
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedArm {
    pub arm: AnalyticArm,
    /// `(chain index, value)` of the held joint (rad or m) for a 7-joint chain.
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
/// first of joints 3, 4, 5, 2, 6, 1, 7 whose holding leaves a covered arm
/// (the family is read at that value).
///
/// ```
/// use kinplan_core::ik::analytic::{AnalyticParams, Family, analyse};
/// let iiwa = kinplan_core::robot::builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
/// let seed = [0.1, 0.5, 0.3, -1.2, 0.2, 0.9, 0.0];
/// let r = analyse(&iiwa, &AnalyticParams::default(), Some(&seed)).unwrap();
/// assert_eq!(r.held, Some((2, 0.3)));
/// assert_eq!(r.arm.family(), Family::SphericalTwoIntersecting);
/// ```
pub fn analyse(
    chain: &Chain,
    params: &AnalyticParams,
    seed: Option<&[f64]>,
) -> Result<ReducedArm, NotAnalytic> {
    let tol = params.geometry_tolerance;
    if chain.dof() != 7 {
        return AnalyticArm::new(chain, tol).map(|arm| ReducedArm { arm, held: None });
    }
    let value = |j: usize| match seed {
        Some(s) if s.len() == 7 => s[j],
        _ => {
            let joint = &chain.joints()[j];
            if joint.lower.is_finite() && joint.upper.is_finite() {
                0.5 * (joint.lower + joint.upper)
            } else {
                0.0
            }
        }
    };
    let hold = |j: usize| -> Result<ReducedArm, NotAnalytic> {
        let v = value(j);
        let six = chain.with_joint_fixed(j, v).expect("index below 7");
        AnalyticArm::new(&six, tol).map(|arm| ReducedArm {
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
        None => HOLD_ORDER
            .iter()
            .find_map(|&j| hold(j).ok())
            .ok_or_else(|| NotAnalytic {
                reason:
                    "it has 7 joints and holding any one of them leaves no covered 6-joint arm (a general \
                     6-joint arm needs a 1-D search, not implemented)"
                        .into(),
            }),
    }
}
