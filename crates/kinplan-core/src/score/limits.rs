//! Which joint limits the S2 PTP cycle time (docs/scoring.md#ptp-cycle-time-and-time-potential) of a robot
//! uses: the limits a caller gives, else the speed limits of the robot model.

use std::fmt;

use super::input::JointLimits;
use crate::robot::Chain;

/// Owned per-joint limits (see [`JointLimits`] for units and ranges).
#[derive(Debug, Clone, PartialEq)]
pub struct OwnedLimits {
    /// Maximum speed per joint.
    pub v_max: Vec<f64>,
    /// Maximum acceleration per joint; `None`: ramps neglected.
    pub a_max: Option<Vec<f64>>,
}

impl OwnedLimits {
    /// The borrowed form [`score`](super::score) takes.
    pub fn as_limits(&self) -> JointLimits<'_> {
        JointLimits {
            v_max: &self.v_max,
            a_max: self.a_max.as_deref(),
        }
    }
}

/// Why a robot's trajectories get no cycle time: no speed limit was given
/// and the model lacks one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissingSpeedLimit {
    /// Name of the first joint without a usable (finite, > 0) model limit.
    pub joint: String,
}

impl fmt::Display for MissingSpeedLimit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "joint {:?} has no speed limit in the model", self.joint)
    }
}

/// The limits for `chain`'s cycle time: `v_max` when it is not empty,
/// otherwise every joint's model speed limit (finite and > 0, else
/// [`MissingSpeedLimit`]); `a_max` when it is not empty. Lengths and
/// ranges of given limits are checked later by [`JointLimits::validate`].
///
/// ```
/// use kinplan_core::robot::builtin_chain;
/// use kinplan_core::score::limits_for;
/// let chain = builtin_chain("planar_2").unwrap();
/// let given = limits_for(&chain, vec![1.0, 2.0], vec![]).unwrap();
/// assert_eq!(given.v_max, [1.0, 2.0]);
/// assert_eq!(given.a_max, None);
/// ```
pub fn limits_for(chain: &Chain, v_max: Vec<f64>, a_max: Vec<f64>) -> Result<OwnedLimits, MissingSpeedLimit> {
    let v_max = if v_max.is_empty() {
        chain
            .joints()
            .iter()
            .map(|j| match j.max_velocity {
                Some(v) if v.is_finite() && v > 0.0 => Ok(v),
                _ => Err(MissingSpeedLimit {
                    joint: j.name.clone(),
                }),
            })
            .collect::<Result<_, _>>()?
    } else {
        v_max
    };
    Ok(OwnedLimits {
        v_max,
        a_max: (!a_max.is_empty()).then_some(a_max),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::{Chain, ChainSpec, UrdfLimits, parse_chain};

    fn chain_with_limits(limits: &[&str]) -> Chain {
        let mut urdf = String::from(r#"<robot name="r"><link name="l0"/>"#);
        for (i, v) in limits.iter().enumerate() {
            urdf += &format!(
                r#"<link name="l{n}"/><joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{n}"/>
                   <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="{v}"/></joint>"#,
                n = i + 1
            );
        }
        urdf += "</robot>";
        parse_chain(&urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap()
    }

    #[test]
    fn model_limits_fill_in_when_none_are_given() {
        let chain = chain_with_limits(&["0.5", "2"]);
        let l = limits_for(&chain, vec![], vec![3.0, 4.0]).unwrap();
        assert_eq!(l.v_max, [0.5, 2.0]);
        assert_eq!(l.a_max.as_deref(), Some(&[3.0, 4.0][..]));
        // given limits win over the model's, unchecked here
        let l = limits_for(&chain, vec![-1.0], vec![]).unwrap();
        assert_eq!(l.v_max, [-1.0]);
    }

    #[test]
    fn a_joint_without_a_model_limit_is_named() {
        let chain = chain_with_limits(&["0.5", "0"]);
        let err = limits_for(&chain, vec![], vec![]).unwrap_err();
        assert_eq!(err.joint, "j1");
        assert_eq!(err.to_string(), "joint \"j1\" has no speed limit in the model");
        assert!(limits_for(&chain, vec![1.0, 1.0], vec![]).is_ok());
    }
}
