//! Time parameterisation: timestamps for a joint-space waypoint path within
//! per-joint velocity (and optionally acceleration) limits.

use super::error::{PlanError, PlanField, require};
use crate::robot::Chain;

/// Options of [`time_parameterize`].
#[derive(Debug, Clone, PartialEq)]
pub struct TimingParams {
    /// Speed limit per joint (rad/s or m/s, finite, > 0). `None`: the
    /// chain's `max_velocity`, and `default_velocity` where it has none.
    pub velocity_limits: Option<Vec<f64>>,
    /// Acceleration limit per joint (rad/s² or m/s², > 0; `+∞` = none).
    /// `None`: velocity limits only. Default `None`.
    pub acceleration_limits: Option<Vec<f64>>,
    /// Speed for joints the model gives none (rad/s or m/s, > 0). Default 1.
    pub default_velocity: f64,
    /// Fraction of the velocity limits used (0 < s ≤ 1). Default 1.
    pub velocity_scale: f64,
}

impl Default for TimingParams {
    fn default() -> Self {
        Self {
            velocity_limits: None,
            acceleration_limits: None,
            default_velocity: 1.0,
            velocity_scale: 1.0,
        }
    }
}

impl TimingParams {
    /// Checks the ranges; `dof` sizes the limit vectors.
    pub fn validate(&self, dof: usize) -> Result<(), PlanError> {
        let s = self.velocity_scale;
        require(
            s.is_finite() && s > 0.0 && s <= 1.0,
            PlanField::VelocityScale,
            s,
            "must be in (0, 1]",
        )?;
        let d = self.default_velocity;
        require(
            d.is_finite() && d > 0.0,
            PlanField::VelocityLimits,
            d,
            "must be finite and > 0",
        )?;
        if let Some(v) = &self.velocity_limits {
            require(
                v.len() == dof,
                PlanField::VelocityLimits,
                v.len() as f64,
                "needs one value per joint",
            )?;
            for &x in v {
                require(
                    x.is_finite() && x > 0.0,
                    PlanField::VelocityLimits,
                    x,
                    "must be finite and > 0",
                )?;
            }
        }
        if let Some(a) = &self.acceleration_limits {
            require(
                a.len() == dof,
                PlanField::AccelerationLimits,
                a.len() as f64,
                "needs one value per joint",
            )?;
            for &x in a {
                require(
                    x > 0.0,
                    PlanField::AccelerationLimits,
                    x,
                    "must be > 0 (+inf allowed)",
                )?;
            }
        }
        Ok(())
    }

    /// Effective speed limits for `chain` (scaled).
    pub fn velocities(&self, chain: &Chain) -> Vec<f64> {
        let base: Vec<f64> = match &self.velocity_limits {
            Some(v) => v.clone(),
            None => chain
                .joints()
                .iter()
                .map(|j| {
                    j.max_velocity
                        .filter(|v| v.is_finite() && *v > 0.0)
                        .unwrap_or(self.default_velocity)
                })
                .collect(),
        };
        base.iter().map(|v| v * self.velocity_scale).collect()
    }
}

/// Shortest segment duration (s), so timestamps strictly increase.
pub const MIN_SEGMENT_TIME: f64 = 1e-6;

/// Timestamps (s, from 0) for `waypoints` (`n × dof`, row-major), the path
/// followed as straight joint-space segments.
///
/// Segment `s` first takes `T_s = max_j |Δq_{s,j}| / v_j` (the synchronised
/// motion of S2 §3.3: the slowest joint at its limit, so no joint exceeds
/// its speed). With acceleration limits, the acceleration at waypoint `i`
/// is the velocity change over the mean of the adjacent durations,
/// `a_i = (Δq_i/T_i − Δq_{i−1}/T_{i−1}) / ((T_{i−1} + T_i)/2)`, starting and
/// ending at rest (`a_0 = v_0/(T_0/2)`, likewise at the end). A waypoint with
/// `r = max_j |a_{i,j}|/a_j > 1` stretches both adjacent segments by `√r`
/// (which divides its acceleration by r and never raises a speed); after 100
/// sweeps any remaining excess `R` stretches every segment by `√R`, which
/// scales every acceleration by `1/R` — so the result always satisfies both
/// limits. Limits must be finite and > 0 (`+∞` accelerations allowed).
///
/// ```
/// use kinplan_core::plan::time_parameterize;
/// let q = [0.0, 0.0, 1.0, 0.5]; // two waypoints of a 2-joint arm
/// let t = time_parameterize(&q, 2, &[0.5, 1.0], None);
/// assert_eq!(t, vec![0.0, 2.0]); // joint 0 moves 1 rad at 0.5 rad/s
/// ```
pub fn time_parameterize(waypoints: &[f64], dof: usize, v_max: &[f64], a_max: Option<&[f64]>) -> Vec<f64> {
    let n = waypoints.len().checked_div(dof).unwrap_or(0);
    if n == 0 {
        return Vec::new();
    }
    let delta = |s: usize, j: usize| waypoints[(s + 1) * dof + j] - waypoints[s * dof + j];
    let mut dur: Vec<f64> = (0..n - 1)
        .map(|s| {
            (0..dof)
                .map(|j| delta(s, j).abs() / v_max[j])
                .fold(MIN_SEGMENT_TIME, f64::max)
        })
        .collect();
    if let Some(a_max) = a_max
        && n > 1
    {
        let ratio = |dur: &[f64], i: usize| -> f64 {
            (0..dof)
                .map(|j| {
                    let v_in = if i > 0 { delta(i - 1, j) / dur[i - 1] } else { 0.0 };
                    let v_out = if i + 1 < n { delta(i, j) / dur[i] } else { 0.0 };
                    let span = if i == 0 {
                        dur[0] / 2.0
                    } else if i + 1 == n {
                        dur[n - 2] / 2.0
                    } else {
                        (dur[i - 1] + dur[i]) / 2.0
                    };
                    (v_out - v_in).abs() / span / a_max[j]
                })
                .fold(0.0, f64::max)
        };
        for _ in 0..100 {
            let mut changed = false;
            for i in 0..n {
                let r = ratio(&dur, i);
                if r > 1.0 {
                    let f = r.sqrt() * (1.0 + 1e-12);
                    if i > 0 {
                        dur[i - 1] *= f;
                    }
                    if i + 1 < n {
                        dur[i] *= f;
                    }
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        let worst = (0..n).map(|i| ratio(&dur, i)).fold(0.0, f64::max);
        if worst > 1.0 {
            let f = worst.sqrt() * (1.0 + 1e-12);
            dur.iter_mut().for_each(|d| *d *= f);
        }
    }
    let mut t = Vec::with_capacity(n);
    t.push(0.0);
    for d in dur {
        let last = *t.last().unwrap_or(&0.0);
        t.push(last + d);
    }
    t
}
