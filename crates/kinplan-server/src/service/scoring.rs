//! `ScoringService`: the S0 trajectory criteria, the S2 PTP cycle time and
//! per-set statistics (ALGORITHMS.md §3) for joint trajectories.
//!
//! Thin adapter: admit → resolve the robot → proto options and trajectories
//! into domain values → FK ([`score::sample_chain`]) and [`score::score`] →
//! reply; [`ScoreError`]s become INVALID_ARGUMENT naming the request field.
//! Requests with many waypoints run on the CPU pool.

use std::collections::HashMap;

use tonic::{Request, Response, Status};

use super::Budget;
use super::pb::{self, scoring_service_server::ScoringService};
use super::server::Shared;
use super::status::score::{TrajectoryAt, score_error};
use super::status::{invalid, too_large};
use kinplan_core::robot::Chain;
use kinplan_core::score::{
    self, CountedPeak, CycleTime, CycleTimeParams, JerkPeakParams, LabelledSet, OwnedLimits, PointSet, Rows,
    ScoreError, ScoreInput, ScoreParams, ScoreReport, Scores, Series, TrajectoryData,
};

/// Requests whose estimated cost (waypoints × (1 + robot points per
/// waypoint), all trajectories together) is below this are scored inline on
/// the async runtime, others on the CPU pool: 500 waypoints of a 6-joint arm
/// with its ~64 collision-vertex points is ~1 ms (see benches/RESULTS.md).
/// The estimate counts points, not waypoints alone, so a model with thousands
/// of collision shapes never runs inline.
const INLINE_COST: usize = 32_000;
/// Most robot points sampled over a whole request (points per waypoint ×
/// waypoints): 24 bytes each, so at most ~96 MB, refused up front beyond.
pub const MAX_ROBOT_POINT_SAMPLES: usize = 4_000_000;

/// Smallest step between timestamps, s: smaller ones overflow the divided differences.
pub const MIN_TIME_STEP: f64 = 1e-6;
/// Largest timestamp magnitude, s.
pub const MAX_TIME: f64 = 1e9;
/// Smallest positive speed or acceleration limit: a 5e-324 limit made
/// durations infinite.
pub const MIN_RATE_LIMIT: f64 = 1e-6;

/// Robot points per waypoint the request's options ask for.
fn points_per_waypoint(o: Option<&pb::ScoreOptions>, chain: &Chain) -> usize {
    let robot_points = o.map_or(0, |o| o.robot_points);
    match pb::RobotPoints::try_from(robot_points) {
        Ok(pb::RobotPoints::None) => 0,
        Ok(pb::RobotPoints::CollisionVertices) => {
            score::robot_link_points(chain, PointSet::CollisionVertices).len()
        }
        _ => chain.links().len(),
    }
}

/// The estimated cost of scoring `waypoints` with `points` per waypoint, or
/// RESOURCE_EXHAUSTED naming `options.robot_points` when the samples cannot fit.
fn estimate(waypoints: usize, points: usize) -> Result<usize, Status> {
    let samples = waypoints.saturating_mul(points);
    if samples > MAX_ROBOT_POINT_SAMPLES {
        return Err(too_large(
            "options.robot_points",
            format!(
                "{points} robot points x {waypoints} waypoints exceed the limit of \
                 {MAX_ROBOT_POINT_SAMPLES} samples per request"
            ),
        ));
    }
    Ok(waypoints.saturating_add(samples))
}

pub struct ScoringApi {
    shared: Shared,
}

impl ScoringApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }

    /// Runs `work` inline for small requests, on the CPU pool for large ones.
    async fn run<T: Send + 'static>(
        &self,
        budget: &Budget,
        cost: usize,
        work: impl FnOnce(&Budget) -> Result<T, Status> + Send + 'static,
    ) -> Result<T, Status> {
        if cost < INLINE_COST {
            work(budget)
        } else {
            self.shared.compute.run(budget, work).await?
        }
    }
}

#[tonic::async_trait]
impl ScoringService for ScoringApi {
    async fn score_trajectory(
        &self,
        request: Request<pb::ScoreTrajectoryRequest>,
    ) -> Result<Response<pb::ScoreTrajectoryResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        let chain = robot.chain.clone();
        let waypoints = req.trajectory.as_ref().map_or(0, |t| t.points.len());
        let cost = estimate(waypoints, points_per_waypoint(req.options.as_ref(), &chain))?;
        let mut reply = self
            .run(&budget, cost, move |_| {
                let options = Options::from_proto(req.options.as_ref(), &chain)?;
                let at = TrajectoryAt::Single;
                let trajectory = Trajectory::from_proto(req.trajectory, &chain, at)?;
                let report = score_one(&chain, &trajectory, &options, options.series)
                    .map_err(|e| score_error(e, at))?;
                Ok(score_reply(report, &options))
            })
            .await?;
        reply.model_id = robot.model_id;
        Ok(Response::new(reply))
    }

    async fn compare_trajectories(
        &self,
        request: Request<pb::CompareTrajectoriesRequest>,
    ) -> Result<Response<pb::CompareTrajectoriesResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        if req.sets.is_empty() {
            return Err(invalid("sets", "at least one labelled set is required"));
        }
        for (k, set) in req.sets.iter().enumerate() {
            if set.label.is_empty() {
                return Err(invalid(format!("sets[{k}].label"), "must not be empty"));
            }
            if req.sets[..k].iter().any(|s| s.label == set.label) {
                return Err(invalid(
                    format!("sets[{k}].label"),
                    format!("label {:?} is used twice", set.label),
                ));
            }
            if set.trajectories.is_empty() {
                return Err(invalid(
                    format!("sets[{k}].trajectories"),
                    format!("set {:?} has no trajectories", set.label),
                ));
            }
        }
        let chain = robot.chain.clone();
        let waypoints = req
            .sets
            .iter()
            .flat_map(|s| &s.trajectories)
            .map(|t| t.points.len())
            .sum();
        let cost = estimate(waypoints, points_per_waypoint(req.options.as_ref(), &chain))?;
        let mut reply = self
            .run(&budget, cost, move |budget| compare_sets(&chain, req, budget))
            .await?;
        reply.model_id = robot.model_id;
        Ok(Response::new(reply))
    }
}

/// Scoring options in domain form.
struct Options {
    weights: Option<Vec<f64>>,
    series: bool,
    points: Option<PointSet>,
    /// The cycle time's joint limits, or why the cycle time is unavailable.
    limits: Result<OwnedLimits, String>,
    params: ScoreParams,
}

impl Options {
    /// Unset fields take the documented defaults; value ranges are checked by
    /// the domain (`ScoreParams::validate`, `ScoreInput::validate`).
    fn from_proto(o: Option<&pb::ScoreOptions>, chain: &Chain) -> Result<Self, Status> {
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

    fn unavailable(&self) -> String {
        self.limits.as_ref().err().cloned().unwrap_or_default()
    }
}

/// A trajectory's rows (moved out of the request, not copied) and its
/// timestamps when it is timed.
struct Trajectory {
    rows: Vec<Vec<f64>>,
    times: Option<Vec<f64>>,
}

impl Trajectory {
    fn from_proto(t: Option<pb::JointTrajectory>, chain: &Chain, at: TrajectoryAt) -> Result<Self, Status> {
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

/// FK, then every criterion of one trajectory.
fn score_one(
    chain: &Chain,
    t: &Trajectory,
    options: &Options,
    series: bool,
) -> Result<ScoreReport, ScoreError> {
    let joints = Rows::Nested(&t.rows);
    let samples = score::sample_chain(chain, joints, options.points)?;
    let input = ScoreInput {
        trajectory: TrajectoryData {
            joints,
            poses: &samples.poses,
            robot_points: samples.point_rows(),
            timestamps: t.times.as_deref(),
        },
        dof: Some(chain.dof()),
        joint_weights: options.weights.as_deref(),
        limits: options.limits.as_ref().ok().map(OwnedLimits::as_limits),
    };
    let params = ScoreParams {
        series,
        ..options.params
    };
    score::score(&input, &params)
}

fn criteria_out(s: &Scores) -> HashMap<String, f64> {
    s.iter().map(|(c, v)| (c.name().to_string(), v)).collect()
}

fn score_reply(report: ScoreReport, options: &Options) -> pb::ScoreTrajectoryResponse {
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

/// Scores every trajectory of every set, then the per-set statistics.
fn compare_sets(
    chain: &Chain,
    req: pb::CompareTrajectoriesRequest,
    budget: &Budget,
) -> Result<pb::CompareTrajectoriesResponse, Status> {
    let options = Options::from_proto(req.options.as_ref(), chain)?;
    let mut labels = Vec::with_capacity(req.sets.len());
    let mut scores = Vec::with_capacity(req.sets.len());
    for (k, set) in req.sets.into_iter().enumerate() {
        let mut set_scores = Vec::with_capacity(set.trajectories.len());
        for (i, t) in set.trajectories.into_iter().enumerate() {
            if budget.should_stop() {
                return Err(Status::deadline_exceeded(
                    "the request's deadline passed before the work finished",
                ));
            }
            let at = TrajectoryAt::InSet { set: k, index: i };
            let t = Trajectory::from_proto(Some(t), chain, at)?;
            let report = score_one(chain, &t, &options, false).map_err(|e| score_error(e, at))?;
            set_scores.push(report.scores);
        }
        labels.push(set.label);
        scores.push(set_scores);
    }
    let sets: Vec<LabelledSet<'_>> = labels
        .iter()
        .zip(&scores)
        .map(|(label, scores)| LabelledSet { label, scores })
        .collect();
    // Empty sets and repeated labels were rejected before scoring.
    let comparison = score::compare(&sets).map_err(|e| score_error(e, TrajectoryAt::Single))?;
    let criteria = score::Criterion::ALL
        .into_iter()
        .filter(|c| comparison.sets.iter().any(|s| s.get(*c).is_some()))
        .map(|c| c.name().to_string())
        .collect();
    let sets = comparison
        .sets
        .into_iter()
        .zip(&scores)
        .map(|(summary, scores)| pb::SetSummary {
            label: summary.label,
            trajectories: summary.trajectories as u32,
            criteria: summary
                .stats
                .iter()
                .map(|(c, st)| {
                    (
                        c.name().to_string(),
                        pb::CriterionStats {
                            count: st.count as u32,
                            mean: st.mean,
                            variance: st.variance,
                            population_variance: st.population_variance,
                            sum: st.sum,
                            min: st.min,
                            max: st.max,
                        },
                    )
                })
                .collect(),
            scores: scores
                .iter()
                .map(|s| pb::TrajectoryCriteria {
                    criteria: criteria_out(s),
                })
                .collect(),
        })
        .collect();
    Ok(pb::CompareTrajectoriesResponse {
        sets,
        criteria,
        cycle_time_unavailable: options.unavailable(),
        model_id: Vec::new(),
    })
}
