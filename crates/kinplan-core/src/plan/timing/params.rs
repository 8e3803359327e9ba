//! [`TimingParams`]: which method times a path, and the limits it keeps.

use crate::plan::error::{PlanError, PlanField, check_vector, require};
use crate::robot::Chain;

/// How a waypoint path is timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimingMethod {
    /// Timestamps at the waypoints, straight segments between them, each
    /// segment as fast as the slowest joint allows, stretched until the
    /// estimated waypoint accelerations are within the limits
    /// ([`time_parameterize`](super::time_parameterize)). Velocities jump at
    /// the waypoints.
    #[default]
    Waypoint,
    /// Circular blends at the waypoints (Kunz & Stilman 2012) and the
    /// time-optimal speed along that path by TOPP-RA (Pham & Pham 2018),
    /// sampled every `sample_period`.
    TimeOptimal,
    /// Straight segments at constant velocity joined at every waypoint by
    /// a blend in time with trapezoidal acceleration, within velocity,
    /// acceleration and jerk limits, passing each waypoint within
    /// `path_tolerance` without stopping; sampled every `sample_period`.
    JerkLimited,
}

/// Options of [`retime`](super::retime) and of the timing inside
/// [`plan`](crate::plan::plan).
#[derive(Debug, Clone, PartialEq)]
pub struct TimingParams {
    /// The method. Default [`TimingMethod::Waypoint`].
    pub method: TimingMethod,
    /// Speed limit per joint (rad/s or m/s, finite, > 0). `None`: the
    /// chain's `max_velocity`, and `default_velocity` where it has none.
    pub velocity_limits: Option<Vec<f64>>,
    /// Acceleration limit per joint (rad/s² or m/s², > 0; `+∞` = none for
    /// the waypoint method, finite for the others, which require it).
    /// Default `None`.
    pub acceleration_limits: Option<Vec<f64>>,
    /// Jerk limit per joint (rad/s³ or m/s³, finite, > 0); required by
    /// [`TimingMethod::JerkLimited`]. Default `None`.
    pub jerk_limits: Option<Vec<f64>>,
    /// Speed for joints the model gives none (rad/s or m/s, > 0). Default 1.
    pub default_velocity: f64,
    /// Fraction of the velocity limits used (0 < s ≤ 1). Default 1.
    pub velocity_scale: f64,
    /// Largest distance of a blend from the waypoint it rounds, rad (m),
    /// Euclidean in joint space, finite and > 0 ([`TimingMethod::TimeOptimal`]
    /// and [`TimingMethod::JerkLimited`]). Default 0.05.
    pub path_tolerance: f64,
    /// Joint velocity at the start (rad/s or m/s, one per joint); `None`:
    /// at rest. [`TimingMethod::TimeOptimal`] needs it along the path's
    /// first segment; [`TimingMethod::JerkLimited`] takes any within the
    /// speed limits (zero acceleration at the start), its first blend
    /// turning onto the path. The waypoint method starts at rest. The end
    /// is always at rest.
    pub start_velocity: Option<Vec<f64>>,
    /// Time between samples of the time-optimal and jerk-limited
    /// trajectories, s, in [1e-4, 10]. Default 0.01.
    pub sample_period: f64,
    /// Largest step of TOPP-RA's grid along the path, rad (m) of joint-space
    /// arc length, in [1e-4, 1]. Default 0.02.
    pub grid_step: f64,
}

impl Default for TimingParams {
    fn default() -> Self {
        Self {
            method: TimingMethod::Waypoint,
            velocity_limits: None,
            acceleration_limits: None,
            jerk_limits: None,
            default_velocity: 1.0,
            velocity_scale: 1.0,
            path_tolerance: 0.05,
            start_velocity: None,
            sample_period: 0.01,
            grid_step: 0.02,
        }
    }
}

fn positive_per_joint(field: PlanField, values: &[f64], dof: usize, finite: bool) -> Result<(), PlanError> {
    require(
        values.len() == dof,
        field,
        values.len() as f64,
        "needs one value per joint",
    )?;
    for &x in values {
        if finite {
            require(x.is_finite() && x > 0.0, field, x, "must be finite and > 0")?;
        } else {
            require(x > 0.0, field, x, "must be > 0 (+inf allowed)")?;
        }
    }
    Ok(())
}

impl TimingParams {
    /// Checks the ranges and what the method needs; `dof` sizes the limit
    /// vectors.
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
            positive_per_joint(PlanField::VelocityLimits, v, dof, true)?;
        }
        let smooth = self.method != TimingMethod::Waypoint;
        match &self.acceleration_limits {
            Some(a) => positive_per_joint(PlanField::AccelerationLimits, a, dof, smooth)?,
            None => require(
                !smooth,
                PlanField::AccelerationLimits,
                f64::NAN,
                "required by the time-optimal and jerk-limited methods",
            )?,
        }
        match &self.jerk_limits {
            Some(j) => positive_per_joint(PlanField::JerkLimits, j, dof, true)?,
            None => require(
                self.method != TimingMethod::JerkLimited,
                PlanField::JerkLimits,
                f64::NAN,
                "required by the jerk-limited method",
            )?,
        }
        let p = self.path_tolerance;
        require(
            p.is_finite() && p > 0.0,
            PlanField::PathTolerance,
            p,
            "must be finite and > 0",
        )?;
        let dt = self.sample_period;
        require(
            (1e-4..=10.0).contains(&dt),
            PlanField::SamplePeriod,
            dt,
            "must be in [1e-4, 10] s",
        )?;
        let h = self.grid_step;
        require(
            (1e-4..=1.0).contains(&h),
            PlanField::GridStep,
            h,
            "must be in [1e-4, 1]",
        )?;
        if let Some(v0) = &self.start_velocity {
            check_vector(PlanField::StartVelocity, v0, dof)?;
            require(
                self.method != TimingMethod::Waypoint || v0.iter().all(|v| *v == 0.0),
                PlanField::StartVelocity,
                v0.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
                "the waypoint method starts at rest",
            )?;
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
