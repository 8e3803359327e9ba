//! `ScoringService` messages ↔ the score room: options and trajectories in
//! (unset fields take the documented defaults), reports out.

use std::collections::HashMap;

use tonic::Status;

use crate::pb;
use crate::status::invalid;
use crate::status::score::TrajectoryAt;
use kinplan_core::robot::Chain;
use kinplan_core::score::{
    self, CountedPeak, CycleTime, CycleTimeParams, JerkPeakParams, OwnedLimits, PointSet, ScoreParams,
    ScoreReport, Scores, Series,
};

/// Smallest step between timestamps, s: smaller ones overflow the divided differences.
pub const MIN_TIME_STEP: f64 = 1e-6;
/// Largest timestamp magnitude, s.
pub const MAX_TIME: f64 = 1e9;
/// Smallest positive speed or acceleration limit: a 5e-324 limit made
/// durations infinite.
pub const MIN_RATE_LIMIT: f64 = 1e-6;

/// Scoring options in domain form.
pub(super) struct Options {
    pub(super) weights: Option<Vec<f64>>,
    pub(super) series: bool,
    pub(super) points: Option<PointSet>,
    /// The cycle time's joint limits, or why the cycle time is unavailable.
    pub(super) limits: Result<OwnedLimits, String>,
    pub(super) params: ScoreParams,
}

impl Options {
    /// Unset fields take the documented defaults; value ranges are checked by
    /// the domain (`ScoreParams::validate`, `ScoreInput::validate`).
    pub(super) fn from_proto(o: Option<&pb::ScoreOptions>, chain: &Chain) -> Result<Self, Status> {
        let o = o.cloned().unwrap_or_default();
        let points = match pb::RobotPoints::try_from(o.robot_points) {
            Ok(pb::RobotPoints::Unspecified | pb::RobotPoints::LinkOrigins) => Some(PointSet::LinkOrigins),
            Ok(pb::RobotPoints::CollisionVertices) => Some(PointSet::CollisionVertices),
            Ok(pb::RobotPoints::None) => None,
            Err(_) => {
                return Err(invalid(
                    "options.robot_points",
                    format!("unknown value {}", o.robot_points),
                ));
            }
        };
        for (name, values) in [
            ("max_velocity", &o.max_velocity),
            ("max_acceleration", &o.max_acceleration),
        ] {
            if let Some(i) = values
                .iter()
                .position(|v| v.is_finite() && *v > 0.0 && !(MIN_RATE_LIMIT..).contains(v))
            {
                return Err(invalid(
                    format!("options.{name}[{i}]"),
                    format!(
                        "{:e} is below the smallest accepted limit of {MIN_RATE_LIMIT:e}",
                        values[i]
                    ),
                ));
            }
        }
        let limits = score::limits_for(chain, o.max_velocity, o.max_acceleration)
            .map_err(|missing| format!("{missing}; pass options.max_velocity"));
        let d = JerkPeakParams::default();
        let jp = o.jerk_peaks.unwrap_or_default();
        let peaks = JerkPeakParams {
            joint_log_gain: jp.joint_log_gain.unwrap_or(d.joint_log_gain),
            joint_offset: jp.joint_offset.unwrap_or(d.joint_offset),
            cartesian_sqrt_gain: jp.cartesian_sqrt_gain.unwrap_or(d.cartesian_sqrt_gain),
            cartesian_offset: jp.cartesian_offset.unwrap_or(d.cartesian_offset),
            joint_min_height: jp.joint_min_height.unwrap_or(d.joint_min_height),
            cartesian_min_height: jp.cartesian_min_height.unwrap_or(d.cartesian_min_height),
            edge_peaks: jp.edge_peaks,
            slowdown_floor: jp.slowdown_floor.unwrap_or(d.slowdown_floor),
        };
        let cycle_time = CycleTimeParams {
            potential_tolerance: o
                .potential_tolerance
                .unwrap_or(CycleTimeParams::default().potential_tolerance),
        };
        Ok(Self {
            weights: (!o.joint_weights.is_empty()).then_some(o.joint_weights),
            series: o.series,
            points,
            limits,
            params: ScoreParams {
                peaks,
                cycle_time,
                series: false,
            },
        })
    }

    pub(super) fn unavailable(&self) -> String {
        self.limits.as_ref().err().cloned().unwrap_or_default()
    }
}

/// A trajectory's rows (moved out of the request, not copied) and its
/// timestamps when it is timed.
pub(super) struct Trajectory {
    pub(super) rows: Vec<Vec<f64>>,
    pub(super) times: Option<Vec<f64>>,
}

impl Trajectory {
    pub(super) fn from_proto(
        t: Option<pb::JointTrajectory>,
        chain: &Chain,
        at: TrajectoryAt,
    ) -> Result<Self, Status> {
        let field = at.to_string();
        let Some(t) = t else {
            return Err(invalid(field, "is required"));
        };
        if !t.joint_names.is_empty() {
            let expected: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
            if t.joint_names != expected {
                return Err(invalid(
                    format!("{field}.joint_names"),
                    format!(
                        "must be the chain's joints in order {expected:?} (or empty), got {:?}",
                        t.joint_names
                    ),
                ));
            }
        }
        let timed = t.points.iter().any(|p| p.time_from_start != 0.0);
        if timed {
            // Steps of 1e-300 s divided differences into infinities: bound them.
            for (i, w) in t.points.windows(2).enumerate() {
                let step = w[1].time_from_start - w[0].time_from_start;
                if step.is_finite() && step > 0.0 && step < MIN_TIME_STEP {
                    return Err(invalid(
                        format!("{field}.points[{}].time_from_start", i + 1),
                        format!(
                            "steps of {step:e} s are below the smallest accepted step of {MIN_TIME_STEP:e} s"
                        ),
                    ));
                }
            }
            if let Some(i) = t.points.iter().position(|p| p.time_from_start.abs() > MAX_TIME) {
                return Err(invalid(
                    format!("{field}.points[{i}].time_from_start"),
                    format!("magnitude above {MAX_TIME:e} s"),
                ));
            }
        }
        let times = timed.then(|| t.points.iter().map(|p| p.time_from_start).collect());
        let rows = t.points.into_iter().map(|p| p.positions).collect();
        Ok(Self { rows, times })
    }
}

/// Each criterion by its name.
pub(super) fn criteria_out(s: &Scores) -> HashMap<String, f64> {
    s.iter().map(|(c, v)| (c.name().to_string(), v)).collect()
}

/// One trajectory's report as the reply.
pub(super) fn score_reply(report: ScoreReport, options: &Options) -> pb::ScoreTrajectoryResponse {
    let s = &report.scores;
    pb::ScoreTrajectoryResponse {
        criteria: criteria_out(s),
        waypoints: s.waypoints as u32,
        joint_peak_count: s.joint_peak_count as u32,
        cartesian_peak_count: s.cartesian_peak_count as u32,
        robot_points: report.shape.points as u32,
        cycle_time: report.cycle_time.as_ref().map(cycle_time_out),
        cycle_time_unavailable: options.unavailable(),
        time_scaled: s.time_scaled.map(|t| pb::TimeScaledJerk {
            jj: t.jj,
            cj: t.cj,
            jmj: t.jmj,
            cmj: t.cmj,
        }),
        series: report.series.map(series_out),
        model_id: Vec::new(),
    }
}

fn cycle_time_out(c: &CycleTime) -> pb::CycleTime {
    pb::CycleTime {
        total: c.total,
        segments: c
            .segments
            .iter()
            .map(|s| pb::SegmentTime {
                duration: s.duration,
                limiting_joint: s.limiting_joint.map_or(-1, |j| j as i32),
            })
            .collect(),
        potentials: c
            .potentials
            .iter()
            .map(|p| pb::TimePotential {
                index: p.index as u32,
                via: p.via,
                direct: p.direct,
                gain: p.gain,
                has_potential: p.has_potential,
            })
            .collect(),
    }
}

fn peak_out(p: &CountedPeak) -> pb::JerkPeak {
    pb::JerkPeak {
        index: p.index as u32,
        height: p.height,
        slowdown: p.slowdown,
    }
}

fn series_out(s: Series) -> pb::ScoreSeries {
    pb::ScoreSeries {
        cd: s.cd,
        jd: s.jd,
        oc: s.oc,
        cpc: s.cpc,
        rdm: s.rdm.unwrap_or_default(),
        joint_jerk: s.joint_jerk,
        cartesian_jerk: s.cartesian_jerk,
        joint_peaks: s.joint_peaks.iter().map(peak_out).collect(),
        cartesian_peaks: s.cartesian_peaks.iter().map(peak_out).collect(),
        joint_jerk_rate: s.joint_jerk_rate.unwrap_or_default(),
        cartesian_jerk_rate: s.cartesian_jerk_rate.unwrap_or_default(),
    }
}
