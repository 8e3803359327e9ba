//! Time parameterisation: a joint-space waypoint path in, a timed trajectory
//! (positions, velocities, accelerations) out, within per-joint limits, by
//! one of three methods (docs/planning.md#time-parameterisation).

mod blend;
mod curve;
mod jerk_blend;
mod params;
mod sample;
mod scurve;
mod toppra;
mod waypoint;

pub use blend::BlendedPath;
pub use curve::Curve;
pub use params::{TimingMethod, TimingParams};
pub use sample::MAX_SAMPLE_VALUES;
pub use scurve::SCurve;
pub use toppra::{MAX_GRID_POINTS, SpeedProfile, ToppError, topp_ra};
pub use waypoint::{MIN_SEGMENT_TIME, time_parameterize, waypoint_rates};

use super::error::{PlanError, PlanField, check_vector};
use crate::Deadline;

/// A timed joint trajectory: `n` samples of time, positions, velocities and
/// accelerations (`n × dof` row-major; rad, rad/s, rad/s² — m for prismatic
/// joints).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TimedTrajectory {
    pub dof: usize,
    /// Time from the start, s, strictly increasing.
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl TimedTrajectory {
    fn with_capacity(dof: usize, n: usize) -> Self {
        Self {
            dof,
            t: Vec::with_capacity(n),
            q: Vec::with_capacity(n * dof),
            qd: Vec::with_capacity(n * dof),
            qdd: Vec::with_capacity(n * dof),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Time of the last sample, s.
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }
}

/// Times the path through `waypoints` (`n × dof` row-major, finite, n ≥ 1)
/// by `params.method` within the speed limits `v` (rad/s, one per joint —
/// [`TimingParams::velocities`] of the chain) and `params`' acceleration and
/// jerk limits. `params` must have passed [`TimingParams::validate`].
///
/// - [`TimingMethod::Waypoint`]: one sample per waypoint, timed by
///   [`time_parameterize`], rates by [`waypoint_rates`].
/// - [`TimingMethod::TimeOptimal`]: the waypoints joined by a
///   [`BlendedPath`] (no point farther than `path_tolerance` from the
///   polyline), timed by [`topp_ra`], sampled every `sample_period` and at
///   the end. A start velocity must point along the first segment.
/// - [`TimingMethod::JerkLimited`]: straight segments at constant velocity
///   joined at every waypoint by a blend in time of trapezoidal
///   acceleration (an S-curve velocity change, each joint over its own
///   window at an interior waypoint), passing each interior
///   waypoint within `path_tolerance` without stopping (except at corners
///   sharper than about 115°, or everywhere when stopping at every waypoint
///   is faster); every limit holds in closed form. Sampled every
///   `sample_period` and at the end.
///
/// Errors name the field: waypoints malformed, a start velocity off the path
/// or too fast to stop from, a sample period or grid step too fine for the
/// path; [`PlanError::Interrupted`] once the deadline passes or the caller cancels (polled
/// every few thousand grid points and samples).
///
/// ```
/// use kinplan_core::plan::{TimingMethod, TimingParams, retime};
/// let params = TimingParams {
///     method: TimingMethod::TimeOptimal,
///     acceleration_limits: Some(vec![2.0]),
///     ..Default::default()
/// };
/// // 2 rad at v = 1, a = 2 from rest to rest: trapezoid of 2/1 + 1/2 = 2.5 s
/// let r = retime(&[0.0, 2.0], 1, &[1.0], &params, kinplan_core::Deadline::none()).unwrap();
/// assert!((r.duration() - 2.5).abs() < 1e-3);
/// assert!(r.qd.iter().all(|v| *v <= 1.0 + 1e-9));
/// ```
pub fn retime(
    waypoints: &[f64],
    dof: usize,
    v: &[f64],
    params: &TimingParams,
    deadline: Deadline<'_>,
) -> Result<TimedTrajectory, PlanError> {
    if dof == 0 {
        return Err(PlanError::EmptyChain);
    }
    let n = waypoints.len() / dof;
    if n == 0 || !waypoints.len().is_multiple_of(dof) {
        return Err(PlanError::WrongLength {
            field: PlanField::Waypoints,
            expected: dof * n.max(1),
            got: waypoints.len(),
        });
    }
    check_vector(PlanField::Waypoints, waypoints, waypoints.len())?;
    check_vector(PlanField::VelocityLimits, v, dof)?;
    let accel = params.acceleration_limits.as_deref();
    match params.method {
        TimingMethod::Waypoint => {
            let t = time_parameterize(waypoints, dof, v, accel);
            let (qd, qdd) = waypoint_rates(waypoints, dof, &t);
            Ok(TimedTrajectory {
                dof,
                t,
                q: waypoints.to_vec(),
                qd,
                qdd,
            })
        }
        TimingMethod::TimeOptimal => {
            let a = accel.ok_or(missing(PlanField::AccelerationLimits))?;
            time_optimal(waypoints, dof, v, a, params, deadline)
        }
        TimingMethod::JerkLimited => {
            let a = accel.ok_or(missing(PlanField::AccelerationLimits))?;
            let j = params
                .jerk_limits
                .as_deref()
                .ok_or(missing(PlanField::JerkLimits))?;
            let start = params.start_velocity.as_deref().unwrap_or(&[]);
            for (x, lim) in start.iter().zip(v) {
                if x.abs() > *lim {
                    return Err(PlanError::InvalidParam {
                        field: PlanField::StartVelocity,
                        value: *x,
                        reason: "beyond the joint's speed limit",
                    });
                }
            }
            let lim = jerk_blend::Limits {
                v,
                a,
                j,
                tolerance: params.path_tolerance,
                start,
            };
            let blends = jerk_blend::JerkPath::new(waypoints, dof, lim).ok_or(PlanError::InvalidParam {
                field: PlanField::StartVelocity,
                value: start.iter().fold(0.0, |m: f64, x| m.max(x.abs())),
                reason: "cannot be kept: the path has no length to move along, or the first blend finds no start on the first waypoint",
            })?;
            let times = sample::sample_times(blends.duration(), params.sample_period, dof)
                .ok_or(too_many_samples(params.sample_period))?;
            blends.sample(&times, deadline).ok_or(PlanError::Interrupted)
        }
    }
}

fn missing(field: PlanField) -> PlanError {
    PlanError::InvalidParam {
        field,
        value: f64::NAN,
        reason: "required by this timing method",
    }
}

fn too_many_samples(dt: f64) -> PlanError {
    PlanError::InvalidParam {
        field: PlanField::SamplePeriod,
        value: dt,
        reason: "too short for the trajectory's duration: more than 2,000,000 sample values",
    }
}

fn time_optimal(
    waypoints: &[f64],
    dof: usize,
    v: &[f64],
    a: &[f64],
    params: &TimingParams,
    deadline: Deadline<'_>,
) -> Result<TimedTrajectory, PlanError> {
    let path = BlendedPath::new(waypoints, dof, params.path_tolerance);
    let v0 = params.start_velocity.as_deref().unwrap_or(&[]);
    let speed0 = v0.iter().map(|x| x * x).sum::<f64>().sqrt();
    if path.pieces() == 0 {
        if speed0 > 0.0 {
            return Err(PlanError::InvalidParam {
                field: PlanField::StartVelocity,
                value: speed0,
                reason: "the path has no length to move along",
            });
        }
        return Ok(TimedTrajectory {
            dof,
            t: vec![0.0],
            q: waypoints[..dof].to_vec(),
            qd: vec![0.0; dof],
            qdd: vec![0.0; dof],
        });
    }
    let mut x0 = 0.0;
    if speed0 > 0.0 {
        // ṡ₀ = v₀ · q'(0) (q' is a unit vector); the rest of v₀ is off the path
        let (mut q, mut d1, mut d2) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
        path.eval(0, 0.0, &mut q, &mut d1, &mut d2);
        let along: f64 = (0..dof).map(|j| v0[j] * d1[j]).sum();
        let off = (0..dof)
            .map(|j| (v0[j] - along * d1[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        if along <= 0.0 || off > 1e-6 * speed0.max(1.0) {
            return Err(PlanError::InvalidParam {
                field: PlanField::StartVelocity,
                value: speed0,
                reason: "must point along the path's first segment",
            });
        }
        x0 = along * along;
    }
    let profile = topp_ra(&path, v, a, x0, params.grid_step, deadline).map_err(|e| match e {
        ToppError::Interrupted => PlanError::Interrupted,
        ToppError::TooManyGridPoints(_) => PlanError::InvalidParam {
            field: PlanField::GridStep,
            value: params.grid_step,
            reason: "too fine for the path's length: more than 1,000,000 grid points",
        },
        ToppError::StartTooFast { .. } => PlanError::InvalidParam {
            field: PlanField::StartVelocity,
            value: speed0,
            reason: "too fast: beyond a joint speed limit, or the path is too short to stop within the limits",
        },
    })?;
    let mut profile = profile;
    // Between grid points an arc turns the tangent a little further than the
    // grid's checks see; the samples are checked and, should one exceed a
    // limit by a factor k, the whole profile is slowed by 2k − 1 and
    // sampled again.
    for _ in 0..5 {
        let times = sample::sample_times(profile.duration(), params.sample_period, dof)
            .ok_or(too_many_samples(params.sample_period))?;
        let out = sample::sample_profile(&path, &profile, &times, deadline).ok_or(PlanError::Interrupted)?;
        let k = worst_ratio(&out, v, a);
        if k <= 1.0 {
            return Ok(out);
        }
        // resampling moves the samples; overshoot so the next check passes
        profile.slow_down(1.0 + 2.0 * (k - 1.0) + 1e-12);
    }
    Err(PlanError::InvalidParam {
        field: PlanField::GridStep,
        value: params.grid_step,
        reason: "too coarse: the sampled trajectory keeps exceeding a limit",
    })
}

/// `max(|q̇_j|/v_j, √(|q̈_j|/a_j))` over every sample and joint: the factor
/// by which the trajectory must slow down to keep every limit. One running
/// maximum per joint (independent chains), one square root per joint.
fn worst_ratio(tr: &TimedTrajectory, v: &[f64], a: &[f64]) -> f64 {
    let dof = tr.dof;
    let (mut max_v, mut max_a) = ([0.0f64; 16], [0.0f64; 16]);
    let mut worst = 0.0f64;
    // joints in blocks of 16, so the maxima live on the stack
    for base in (0..dof).step_by(16) {
        let w = (dof - base).min(16);
        max_v[..w].fill(0.0);
        max_a[..w].fill(0.0);
        for (qd, qdd) in tr.qd.chunks_exact(dof).zip(tr.qdd.chunks_exact(dof)) {
            for j in 0..w {
                max_v[j] = max_v[j].max(qd[base + j].abs());
                max_a[j] = max_a[j].max(qdd[base + j].abs());
            }
        }
        for j in 0..w {
            worst = worst
                .max(max_v[j] / v[base + j])
                .max((max_a[j] / a[base + j]).sqrt());
        }
    }
    worst
}

#[cfg(test)]
mod tests;
