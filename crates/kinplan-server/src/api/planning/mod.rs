//! `PlanningService`: Plan, PlanStream, CheckState and Retime over the plan
//! and collision rooms.
//!
//! Per request: admission and the robot (cached), the scene converted and
//! validated, the robot's collision setup (cached per chain), then on the
//! CPU pool the scene's geometry and BVH, and the planner with the request's
//! [`Deadline`] (the call's less a reply reserve, or `options.time_budget`
//! when that ends first) and cancellation.

use std::sync::Arc;
use std::time::Instant;

use tokio_stream::wrappers::ReceiverStream;
use tonic::{Request, Response, Status};

use crate::api::convert::vec3_out;
use crate::api::scene::scene_in;
use crate::pb::{self, planning_service_server::PlanningService};
use crate::runtime::Shared;
use crate::runtime::collision_models::{CollisionSetup, collision_setup};
use crate::runtime::{Budget, models::Resolved};
use crate::status::collision::{checker_error, collision_error, collision_internal};
use crate::status::invalid;
use crate::status::plan::plan_error;
use convert::{PlanInput, colliding_out, pair_name, plan_input, plan_response, trajectory_out};
use kinplan_core::Deadline;
use kinplan_core::collision::{CheckerParams, SceneChecker, SceneGeometry, SceneLimits};
use kinplan_core::plan::{Goal, IterationReport, PlanControl, PlanStatus, plan};
use retime::{retime_input, retime_reply};

pub(crate) mod convert;
mod retime;

/// Most states one CheckState request may ask about.
const MAX_CHECKED_STATES: usize = 100_000;

pub struct PlanningApi {
    shared: Shared,
}

impl PlanningApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }

    /// Everything a plan needs before the planner runs.
    async fn prepare(&self, request: &Request<pb::PlanRequest>) -> Result<Prepared, Status> {
        let (permit, budget, robot) = self
            .shared
            .admit_robot(request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.get_ref();
        let input = plan_input(req)?;
        let scene = scene_in("scene", req.scene.as_ref(), &SceneLimits::default())?;
        let setup = collision_setup(&self.shared, &robot, &budget).await?;
        Ok(Prepared {
            _permit: permit,
            budget,
            robot,
            input,
            scene,
            setup,
        })
    }
}

struct Prepared {
    /// Held for its drop: the admission slot is released when the plan is done.
    _permit: tokio::sync::OwnedSemaphorePermit,
    budget: Budget,
    robot: Resolved,
    input: PlanInput,
    scene: kinplan_core::collision::Scene,
    setup: Arc<CollisionSetup>,
}

/// Builds the world and runs the planner (on a CPU-pool thread) until
/// `deadline` or the request's own time budget, whichever ends first;
/// `progress` sees every STOMP iteration.
fn run_plan<'a>(
    p: &Prepared,
    deadline: Deadline<'a>,
    progress: Option<&'a mut dyn FnMut(&IterationReport<'_>)>,
    started: Instant,
) -> Result<pb::PlanResponse, Status> {
    let world = Arc::new(SceneGeometry::build(&p.scene).map_err(|e| collision_error("scene", e))?);
    let checker = checker_for(&p.setup, world, p.input.checker)?;
    let chain = &p.robot.chain;
    let result = plan(
        chain,
        &checker,
        &p.input.request,
        PlanControl {
            deadline: deadline.min_with_budget(p.input.time_budget),
            progress,
        },
    )
    .map_err(plan_error)?;
    let report = match result.status {
        PlanStatus::InvalidStart => checker.report(&p.input.request.start).ok(),
        PlanStatus::InvalidGoal => match (&result.goal, &p.input.request.goal) {
            (Some(g), _) | (None, Goal::Joints(g)) => checker.report(g).ok(),
            (None, Goal::Pose(_)) => None,
        },
        _ => None,
    };
    Ok(plan_response(
        chain,
        result,
        report,
        p.input.return_cost_history,
        started.elapsed(),
    ))
}

fn checker_for(
    setup: &CollisionSetup,
    world: Arc<SceneGeometry>,
    params: CheckerParams,
) -> Result<SceneChecker, Status> {
    SceneChecker::new(setup.model.clone(), &setup.acm, world, params).map_err(checker_error)
}

#[tonic::async_trait]
impl PlanningService for PlanningApi {
    async fn plan(&self, request: Request<pb::PlanRequest>) -> Result<Response<pb::PlanResponse>, Status> {
        let started = Instant::now();
        let prepared = self.prepare(&request).await?;
        let compute = self.shared.compute.clone();
        let budget = prepared.budget.clone();
        let reply = compute
            // `prepared` (and with it the admission permit) lives until the plan ends.
            .run(&budget, move |b| run_plan(&prepared, b.deadline(), None, started))
            .await??;
        Ok(Response::new(reply))
    }

    type PlanStreamStream = ReceiverStream<Result<pb::PlanStreamResponse, Status>>;

    async fn plan_stream(
        &self,
        request: Request<pb::PlanRequest>,
    ) -> Result<Response<Self::PlanStreamStream>, Status> {
        let started = Instant::now();
        let prepared = self.prepare(&request).await?;
        let (tx, rx) = tokio::sync::mpsc::channel(16);
        let compute = self.shared.compute.clone();
        tokio::spawn(async move {
            let budget = prepared.budget.clone();
            let progress_tx = tx.clone();
            let outcome = compute
                .run(&budget, move |b| {
                    let chain = prepared.robot.chain.clone();
                    let dof = chain.dof();
                    // A frame the client is too slow to take is dropped; the
                    // final message is always sent. A closed stream cancels.
                    let mut send = |r: &IterationReport<'_>| {
                        let _ = progress_tx.try_send(Ok(pb::PlanStreamResponse {
                            iteration: r.iteration.min(u32::MAX as usize) as u32,
                            cost: r.cost,
                            valid: r.valid,
                            trajectory: Some(trajectory_out(&chain, r.trajectory, dof, &[])),
                            result: None,
                        }));
                    };
                    let gone = || b.cancelled() || progress_tx.is_closed();
                    run_plan(
                        &prepared,
                        b.deadline().with_cancel(&gone),
                        Some(&mut send),
                        started,
                    )
                })
                .await;
            let message = match outcome {
                Ok(Ok(result)) => Ok(pb::PlanStreamResponse {
                    iteration: result.iterations,
                    cost: result.cost_history.last().copied().unwrap_or(0.0),
                    valid: result.valid,
                    trajectory: None,
                    result: Some(result),
                }),
                Ok(Err(status)) | Err(status) => Err(status),
            };
            let _ = tx.send(message).await;
        });
        Ok(Response::new(ReceiverStream::new(rx)))
    }

    async fn check_state(
        &self,
        request: Request<pb::CheckStateRequest>,
    ) -> Result<Response<pb::CheckStateResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let req = request.into_inner();
        if req.states.len() > MAX_CHECKED_STATES {
            return Err(invalid(
                "states",
                format!(
                    "{} states exceed the limit of {MAX_CHECKED_STATES}",
                    req.states.len()
                ),
            ));
        }
        let dof = robot.chain.dof();
        for (i, s) in req.states.iter().enumerate() {
            if s.positions.len() != dof {
                return Err(invalid(
                    format!("states[{i}].positions"),
                    format!("has {} values, the robot has {dof} joints", s.positions.len()),
                ));
            }
            if let Some(j) = s.positions.iter().position(|v| !v.is_finite()) {
                return Err(invalid(format!("states[{i}].positions[{j}]"), "must be finite"));
            }
        }
        let max_distance = match req.max_distance {
            None => 1.0,
            Some(d) if d.is_finite() && d > 0.0 => d,
            Some(d) => {
                return Err(invalid(
                    "max_distance",
                    format!("must be finite and > 0, got {d}"),
                ));
            }
        };
        let scene = scene_in("scene", req.scene.as_ref(), &SceneLimits::default())?;
        let setup = collision_setup(&self.shared, &robot, &budget).await?;
        let states = self
            .shared
            .compute
            .run(&budget, move |b| -> Result<Vec<pb::StateCheck>, Status> {
                let world = Arc::new(SceneGeometry::build(&scene).map_err(|e| collision_error("scene", e))?);
                let checker = checker_for(&setup, world, CheckerParams::default())?;
                each_state(&req.states, b.deadline(), |q| {
                    check_one(&checker, q, max_distance)
                })
            })
            .await??;
        Ok(Response::new(pb::CheckStateResponse { states }))
    }

    async fn retime(
        &self,
        request: Request<pb::RetimeRequest>,
    ) -> Result<Response<pb::RetimeResponse>, Status> {
        let (_permit, budget, robot) = self
            .shared
            .admit_robot(&request, request.get_ref().robot.as_ref())
            .await?;
        let input = retime_input(request.get_ref(), robot.chain.dof())?;
        let chain = robot.chain.clone();
        let reply = self
            .shared
            .compute
            .run(&budget, move |b| retime_reply(&chain, &input, b.deadline()))
            .await??;
        Ok(Response::new(reply))
    }
}

/// Validity, clearance and witness points of one state.
/// Answers every state with `check`, looking at the deadline every 64 states.
/// A fault confined to one state (a panic in the geometry code) becomes that
/// state's answer — `valid: false` with `error` set, logged — instead of failing
/// the whole batch.
fn each_state(
    states: &[pb::JointState],
    deadline: Deadline<'_>,
    check: impl Fn(&[f64]) -> Result<pb::StateCheck, Status>,
) -> Result<Vec<pb::StateCheck>, Status> {
    let mut out = Vec::with_capacity(states.len());
    for (i, s) in states.iter().enumerate() {
        if i % 64 == 0 && deadline.expired() {
            return Err(Status::deadline_exceeded(
                "the deadline passed while checking states",
            ));
        }
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(&s.positions))) {
            Ok(answer) => out.push(answer?),
            Err(_) => {
                tracing::error!(state = i, "checking one state panicked; answered as not valid");
                out.push(pb::StateCheck {
                    valid: false,
                    error: "this state could not be checked (a server fault, logged); treat it as not valid"
                        .into(),
                    ..Default::default()
                });
            }
        }
    }
    Ok(out)
}

fn check_one(checker: &SceneChecker, q: &[f64], max_distance: f64) -> Result<pb::StateCheck, Status> {
    let report = checker.report(q).map_err(collision_internal)?;
    let nearest = checker.proximity(q, max_distance).map_err(collision_internal)?;
    let (clearance, robot_point, obstacle_point, closest_pair) = match &nearest {
        Some(p) => (
            p.distance,
            Some(vec3_out(&p.point_on_link.coords)),
            Some(vec3_out(&p.point_on_other.coords)),
            pair_name(&p.link, &p.other),
        ),
        None => (max_distance, None, None, String::new()),
    };
    Ok(pb::StateCheck {
        valid: report.is_valid(),
        within_limits: report.out_of_limits.is_empty(),
        clearance,
        colliding: colliding_out(&report),
        robot_point,
        obstacle_point,
        closest_pair,
        error: String::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_in_one_state_is_that_states_answer() {
        let states: Vec<pb::JointState> = (0..3)
            .map(|i| pb::JointState {
                positions: vec![i as f64],
            })
            .collect();
        let answers = each_state(&states, Deadline::none(), |q| {
            assert!(q[0] != 1.0, "a geometry fault on state 1");
            Ok(pb::StateCheck {
                valid: true,
                ..Default::default()
            })
        })
        .unwrap();
        let valid: Vec<bool> = answers.iter().map(|a| a.valid).collect();
        assert_eq!(valid, [true, false, true]);
        assert!(answers[1].error.contains("could not be checked"));
        assert!(answers[0].error.is_empty() && answers[2].error.is_empty());
    }
}
