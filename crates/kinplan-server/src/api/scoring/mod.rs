//! `ScoringService`: the S0 trajectory criteria, the S2 PTP cycle time and
//! per-set statistics (docs/scoring.md) for joint trajectories.
//!
//! Thin adapter: admit → resolve the robot → proto options and trajectories
//! into domain values → FK ([`score::sample_chain`]) and [`score::score`] →
//! reply; [`ScoreError`]s become INVALID_ARGUMENT naming the request field.
//! Requests with many waypoints run on the CPU pool.

use tonic::{Request, Response, Status};

use crate::pb::{self, scoring_service_server::ScoringService};
use crate::runtime::Budget;
use crate::runtime::Shared;
use crate::status::score::{TrajectoryAt, score_error};
use crate::status::{invalid, too_large};
use kinplan_core::robot::Chain;
use kinplan_core::score::{
    self, LabelledSet, OwnedLimits, PointSet, Rows, ScoreError, ScoreInput, ScoreParams, ScoreReport,
    TrajectoryData,
};

mod convert;

pub use convert::{MAX_TIME, MIN_RATE_LIMIT, MIN_TIME_STEP};
use convert::{Options, Trajectory, criteria_out, score_reply};

/// Requests whose estimated cost (waypoints × (1 + robot points per
/// waypoint), all trajectories together) is below this are scored inline on
/// the async runtime, others on the CPU pool: about 500 waypoints of a 6-joint
/// arm with its 64 collision-vertex points (timings in `benches/RESULTS.md`).
/// The estimate counts points, not waypoints alone, so a model with thousands
/// of collision shapes never runs inline.
const INLINE_COST: usize = 32_000;
/// Most robot points sampled over a whole request (points per waypoint ×
/// waypoints): 24 bytes each, so at most ~96 MB, refused up front beyond.
pub const MAX_ROBOT_POINT_SAMPLES: usize = 4_000_000;

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
            if budget.deadline().expired() {
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
