//! Synchronized point-to-point (PTP) cycle time and the "time potential" of
//! intermediate waypoints (S2 §3.3).

use super::error::{ScoreError, ScoreParam};
use super::input::{JointLimits, Rows, validate_joint_rows};

/// Options of the time-potential search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleTimeParams {
    /// A waypoint has time potential only when the detour through it is slower
    /// than the direct move by more than this, seconds. It keeps round-off
    /// (~1e-16 s) of a waypoint lying on the direct joint-space segment from
    /// being reported. Default 1e-9 s; finite and ≥ 0.
    pub potential_tolerance: f64,
}

impl Default for CycleTimeParams {
    fn default() -> Self {
        Self {
            potential_tolerance: 1e-9,
        }
    }
}

impl CycleTimeParams {
    /// `potential_tolerance` finite and ≥ 0.
    pub fn validate(&self) -> Result<(), ScoreError> {
        let value = self.potential_tolerance;
        if !(value.is_finite() && value >= 0.0) {
            return Err(ScoreError::InvalidParam {
                name: ScoreParam::PotentialTolerance,
                value,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }
}

/// Time for one joint to travel `|dq|` from rest to rest.
///
/// Without `a_max` (S2 §3.3, ramps neglected): `t = |Δq| / v`.
/// With a trapezoidal velocity profile (accelerate at `a`, cruise at `v`,
/// decelerate at `a`): `t = |Δq|/v + v/a` when `|Δq| ≥ v²/a` (the cruise speed
/// is reached), else the triangular profile `t = 2·√(|Δq|/a)`.
/// `a = +∞` gives the ramp-free time. Units: rad (m), rad/s (m/s), rad/s² (m/s²), s.
///
/// ```
/// use kinplan_core::score::ptp_joint_time;
/// assert_eq!(ptp_joint_time(1.0, 2.0, None), 0.5);
/// assert_eq!(ptp_joint_time(4.0, 1.0, Some(1.0)), 5.0); // 4/1 + 1/1
/// assert_eq!(ptp_joint_time(0.25, 1.0, Some(1.0)), 1.0); // 2·√0.25
/// ```
#[inline]
pub fn ptp_joint_time(dq: f64, v_max: f64, a_max: Option<f64>) -> f64 {
    let d = dq.abs();
    match a_max {
        None => d / v_max,
        Some(a) => {
            if d >= v_max * v_max / a {
                d / v_max + v_max / a
            } else {
                2.0 * (d / a).sqrt()
            }
        }
    }
}

/// Duration of one synchronized PTP segment and the joint that sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentTime {
    /// Seconds.
    pub duration: f64,
    /// The slowest joint (the others are slowed to arrive with it); `None`
    /// when no joint moves.
    pub limiting_joint: Option<usize>,
}

/// Synchronized PTP time between two joint vectors: every joint is slowed to
/// finish with the slowest, so `t = max_j t_j(|to_j − from_j|)` with `t_j` of
/// [`ptp_joint_time`] (S2 §3.3: `Δφ = ω·t`, the slowest axis decides).
/// Joints are zipped: entries beyond the shortest of `from`, `to`, `v_max` are
/// ignored, and a joint without an `a_max` entry gets no ramp (`cycle_time`
/// and `score` validate the lengths, so this only matters when calling it
/// directly).
///
/// ```
/// use kinplan_core::score::{ptp_segment_time, JointLimits};
/// let lim = JointLimits { v_max: &[2.0, 0.25], a_max: None };
/// let s = ptp_segment_time(&[0.0, 0.0], &[1.0, 0.5], &lim);
/// assert_eq!(s.duration, 2.0); // joint 1: 0.5 / 0.25
/// assert_eq!(s.limiting_joint, Some(1));
/// ```
pub fn ptp_segment_time(from: &[f64], to: &[f64], limits: &JointLimits<'_>) -> SegmentTime {
    let mut best = SegmentTime {
        duration: 0.0,
        limiting_joint: None,
    };
    for (j, ((&a, &b), &v)) in from.iter().zip(to).zip(limits.v_max).enumerate() {
        let acc = limits.a_max.and_then(|am| am.get(j).copied());
        let t = ptp_joint_time(b - a, v, acc);
        if t > best.duration {
            best = SegmentTime {
                duration: t,
                limiting_joint: Some(j),
            };
        }
    }
    best
}

/// Whether routing through waypoint `index` costs time (S2 §3.3, Fig. 19):
/// `via = t(P_{k−1}→P_k) + t(P_k→P_{k+1})` against `direct = t(P_{k−1}→P_{k+1})`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimePotential {
    /// Waypoint `k` (1 ≤ k ≤ n−2).
    pub index: usize,
    /// Through the waypoint, seconds.
    pub via: f64,
    /// Straight from its predecessor to its successor, seconds.
    pub direct: f64,
    /// `via − direct`, seconds (≥ 0 up to round-off: the PTP time is
    /// subadditive).
    pub gain: f64,
    /// `gain > potential_tolerance`.
    pub has_potential: bool,
}

/// PTP cycle time of a whole joint trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleTime {
    /// One entry per segment `i → i+1` (`n − 1`).
    pub segments: Vec<SegmentTime>,
    /// Sum of the segment durations, seconds: every waypoint is an exact stop
    /// (PTP without blending).
    pub total: f64,
    /// One entry per intermediate waypoint `k = 1 … n−2`.
    pub potentials: Vec<TimePotential>,
}

impl CycleTime {
    /// The waypoint whose removal alone saves the most time (gains of
    /// neighbouring waypoints do not add up: removing one changes the other's
    /// neighbours).
    pub fn best_potential(&self) -> Option<&TimePotential> {
        self.potentials
            .iter()
            .filter(|p| p.has_potential)
            .max_by(|a, b| a.gain.total_cmp(&b.gain))
    }
}

/// PTP cycle time of `joints` under `limits` (S2 §3.3): per-segment
/// synchronized times ([`ptp_segment_time`]), their sum, and for each
/// intermediate waypoint its time potential. Fewer than 2 waypoints: no
/// segments, total 0; fewer than 3: no potentials.
///
/// ```
/// use kinplan_core::score::{cycle_time, CycleTimeParams, JointLimits, Rows};
/// // a detour in joint 1 between two points that differ only in joint 0
/// let q = [0.0, 0.0, 0.5, 1.0, 1.0, 0.0];
/// let lim = JointLimits { v_max: &[1.0, 1.0], a_max: None };
/// let ct = cycle_time(Rows::Flat { values: &q, width: 2 }, &lim, &CycleTimeParams::default()).unwrap();
/// assert_eq!(ct.total, 2.0);
/// assert_eq!(ct.potentials[0].gain, 1.0);
/// ```
pub fn cycle_time(
    joints: Rows<'_, f64>,
    limits: &JointLimits<'_>,
    params: &CycleTimeParams,
) -> Result<CycleTime, ScoreError> {
    params.validate()?;
    let m = validate_joint_rows(&joints, None)?;
    if let Some(m) = m {
        limits.validate(m)?;
    }
    Ok(cycle_time_unchecked(&joints, limits, params))
}

/// [`cycle_time`] on validated input.
pub(crate) fn cycle_time_unchecked(
    joints: &Rows<'_, f64>,
    limits: &JointLimits<'_>,
    params: &CycleTimeParams,
) -> CycleTime {
    let n = joints.len();
    let mut segments = Vec::with_capacity(n.saturating_sub(1));
    let mut total = 0.0;
    for i in 1..n {
        let s = ptp_segment_time(joints.row(i - 1), joints.row(i), limits);
        total += s.duration;
        segments.push(s);
    }
    let mut potentials = Vec::with_capacity(n.saturating_sub(2));
    for k in 1..n.saturating_sub(1) {
        let via = segments[k - 1].duration + segments[k].duration;
        let direct = ptp_segment_time(joints.row(k - 1), joints.row(k + 1), limits).duration;
        let gain = via - direct;
        potentials.push(TimePotential {
            index: k,
            via,
            direct,
            gain,
            has_potential: gain > params.potential_tolerance,
        });
    }
    CycleTime {
        segments,
        total,
        potentials,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::ScoreField;

    fn flat(q: &[f64], m: usize) -> Rows<'_, f64> {
        Rows::Flat { values: q, width: m }
    }

    #[test]
    fn synchronized_time_by_hand() {
        // Δq = (1, 0.5), v = (2, 0.25): joint 0 needs 0.5 s, joint 1 needs 2 s.
        let lim = JointLimits {
            v_max: &[2.0, 0.25],
            a_max: None,
        };
        let s = ptp_segment_time(&[0.0, 0.0], &[1.0, 0.5], &lim);
        assert_eq!(
            s,
            SegmentTime {
                duration: 2.0,
                limiting_joint: Some(1)
            }
        );
        // negative motion counts by magnitude
        let s = ptp_segment_time(&[1.0, 0.5], &[0.0, 0.0], &lim);
        assert_eq!(s.duration, 2.0);
        // no motion
        let s = ptp_segment_time(&[1.0, 0.5], &[1.0, 0.5], &lim);
        assert_eq!(
            s,
            SegmentTime {
                duration: 0.0,
                limiting_joint: None
            }
        );
    }

    #[test]
    fn ramps_by_hand() {
        // v = 1, a = 2: cruise reached from |Δq| ≥ v²/a = 0.5
        assert_eq!(ptp_joint_time(2.0, 1.0, Some(2.0)), 2.5); // 2/1 + 1/2
        assert_eq!(ptp_joint_time(0.5, 1.0, Some(2.0)), 1.0); // boundary: both branches = 1
        assert_eq!(ptp_joint_time(0.125, 1.0, Some(2.0)), 0.5); // 2·√(0.125/2) = 2·0.25
        assert_eq!(ptp_joint_time(-2.0, 1.0, Some(2.0)), 2.5);
        assert_eq!(ptp_joint_time(2.0, 1.0, Some(f64::INFINITY)), 2.0);
        assert_eq!(ptp_joint_time(0.0, 1.0, Some(2.0)), 0.0);
        // Δq = (1, 0.5), v = (2, 0.25), a = (1, 1): joint 0: 1 < v²/a = 4 →
        // triangular 2·√(1/1) = 2 s; joint 1: 0.5 ≥ 0.0625 → 0.5/0.25 + 0.25/1
        // = 2.25 s. Max: 2.25 s by joint 1.
        let lim = JointLimits {
            v_max: &[2.0, 0.25],
            a_max: Some(&[1.0, 1.0]),
        };
        let s = ptp_segment_time(&[0.0, 0.0], &[1.0, 0.5], &lim);
        assert_eq!(
            s,
            SegmentTime {
                duration: 2.25,
                limiting_joint: Some(1)
            }
        );
    }

    #[test]
    fn profile_is_continuous_at_the_switch() {
        let (v, a) = (1.3, 0.7);
        let d = v * v / a;
        let lo = ptp_joint_time(d * (1.0 - 1e-12), v, Some(a));
        let hi = ptp_joint_time(d, v, Some(a));
        assert!((lo - hi).abs() < 1e-9);
    }

    #[test]
    fn total_and_segments() {
        let q = [0.0, 0.0, 1.0, 0.5, 1.0, 1.5];
        let lim = JointLimits {
            v_max: &[2.0, 0.25],
            a_max: None,
        };
        let ct = cycle_time(flat(&q, 2), &lim, &CycleTimeParams::default()).unwrap();
        assert_eq!(ct.segments.len(), 2);
        assert_eq!(ct.segments[0].duration, 2.0);
        assert_eq!(ct.segments[1].duration, 4.0);
        assert_eq!(ct.total, 6.0);
        assert_eq!(ct.potentials.len(), 1);
    }

    #[test]
    fn detour_has_potential_straight_point_has_none() {
        let lim = JointLimits {
            v_max: &[1.0, 0.5],
            a_max: None,
        };
        let p = CycleTimeParams::default();
        // detour: P0 = (0,0), P1 = (1, 1), P2 = (2, 0)
        // via: max(1/1, 1/0.5) + max(1/1, 1/0.5) = 4 s; direct: 2/1 = 2 s
        let q = [0.0, 0.0, 1.0, 1.0, 2.0, 0.0];
        let ct = cycle_time(flat(&q, 2), &lim, &p).unwrap();
        let tp = ct.potentials[0];
        assert_eq!((tp.index, tp.via, tp.direct, tp.gain), (1, 4.0, 2.0, 2.0));
        assert!(tp.has_potential);
        assert_eq!(ct.best_potential().map(|t| t.index), Some(1));
        // on the segment: P1 = 0.3·P2
        let q = [0.0, 0.0, 0.3, 0.15, 1.0, 0.5];
        let ct = cycle_time(flat(&q, 2), &lim, &p).unwrap();
        let tp = ct.potentials[0];
        assert!((tp.gain).abs() < 1e-12, "{tp:?}");
        assert!(!tp.has_potential);
        assert!(ct.best_potential().is_none());
        // S2: a point off the segment need not cost time when the slowest axis
        // is unchanged: joint 0 dominates both halves
        let q = [0.0, 0.0, 1.0, 0.1, 2.0, 0.0];
        let ct = cycle_time(flat(&q, 2), &lim, &p).unwrap();
        assert!(!ct.potentials[0].has_potential);
    }

    #[test]
    fn with_ramps_every_stop_costs_time() {
        // on the segment, but every stop costs a ramp (v = 1, a = 1):
        // direct |Δq| = 1 ≥ v²/a → 1/1 + 1/1 = 2 s;
        let lim = JointLimits {
            v_max: &[1.0],
            a_max: Some(&[1.0]),
        };
        let q = [0.0, 0.5, 1.0];
        let ct = cycle_time(flat(&q, 1), &lim, &CycleTimeParams::default()).unwrap();
        // via: each half 0.5 < v²/a → triangular 2·√0.5 s, twice
        let via = 2.0 * 2.0 * 0.5f64.sqrt();
        assert!((ct.potentials[0].via - via).abs() < 1e-12);
        assert_eq!(ct.potentials[0].direct, 2.0);
        assert!(ct.potentials[0].has_potential);
    }

    #[test]
    fn short_trajectories() {
        let lim = JointLimits {
            v_max: &[1.0],
            a_max: None,
        };
        let p = CycleTimeParams::default();
        let ct = cycle_time(flat(&[0.3], 1), &lim, &p).unwrap();
        assert_eq!((ct.segments.len(), ct.total, ct.potentials.len()), (0, 0.0, 0));
        let ct = cycle_time(flat(&[], 1), &lim, &p).unwrap();
        assert_eq!(ct.total, 0.0);
        let ct = cycle_time(flat(&[0.0, 2.0], 1), &lim, &p).unwrap();
        assert_eq!((ct.total, ct.potentials.len()), (2.0, 0));
    }

    #[test]
    fn bad_limits_rejected() {
        let q = [0.0, 0.0, 1.0, 1.0];
        let p = CycleTimeParams::default();
        let lim = JointLimits {
            v_max: &[1.0],
            a_max: None,
        };
        assert!(matches!(
            cycle_time(flat(&q, 2), &lim, &p),
            Err(ScoreError::LengthMismatch {
                field: ScoreField::VMax,
                expected: 2,
                found: 1
            })
        ));
        let lim = JointLimits {
            v_max: &[1.0, 0.0],
            a_max: None,
        };
        assert!(matches!(
            cycle_time(flat(&q, 2), &lim, &p),
            Err(ScoreError::InvalidValue {
                field: ScoreField::VMax,
                index: 1,
                ..
            })
        ));
        let lim = JointLimits {
            v_max: &[1.0, 1.0],
            a_max: Some(&[f64::NAN, 1.0]),
        };
        assert!(matches!(
            cycle_time(flat(&q, 2), &lim, &p),
            Err(ScoreError::InvalidValue {
                field: ScoreField::AMax,
                index: 0,
                ..
            })
        ));
        let lim = JointLimits {
            v_max: &[1.0, 1.0],
            a_max: None,
        };
        let bad = CycleTimeParams {
            potential_tolerance: -1.0,
        };
        assert!(matches!(
            cycle_time(flat(&q, 2), &lim, &bad),
            Err(ScoreError::InvalidParam { .. })
        ));
        let q = [0.0, f64::INFINITY];
        assert!(matches!(
            cycle_time(flat(&q, 2), &lim, &p),
            Err(ScoreError::NonFinite {
                field: ScoreField::Joints,
                index: 0,
                component: 1,
                ..
            })
        ));
    }
}
