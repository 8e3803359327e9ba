//! `ExplorationService.Explore`: the exploration loop of the explore room,
//! streamed one message per iteration, then a summary with the final tree.
//!
//! Per request: admission and the robot (cached), the scene, the robot's
//! collision setup (cached per chain, shared with PlanningService), then on
//! the CPU pool the loop itself with the request's deadline (less a reply
//! reserve, or `time_budget` when that ends first) and cancellation; a
//! client that goes away cancels it.

use std::sync::Arc;
use std::time::Instant;

use tokio_stream::wrappers::ReceiverStream;
use tonic::{Request, Status};

use crate::api::exploration::convert::octree_out;
use crate::api::scene::scene_in;
use crate::pb;
use crate::runtime::Shared;
use crate::runtime::collision_models::collision_setup;
use crate::status::collision::collision_error;
use crate::status::explore::explore_error;
use crate::status::invalid;
use convert::{explore_params_in, iteration_out, summary_out};
use kinplan_core::collision::{SceneGeometry, SceneLimits};
use kinplan_core::explore::{ExploreControl, ExploreStep, ExploreWorld, explore};

pub(crate) mod convert;

pub type ExploreStream = ReceiverStream<Result<pb::ExploreResponse, Status>>;

/// Starts the loop and returns the stream of its messages.
pub async fn explore_stream(
    shared: &Shared,
    request: Request<pb::ExploreRequest>,
) -> Result<ExploreStream, Status> {
    let started = Instant::now();
    let (permit, budget, robot) = shared
        .admit_robot(&request, request.get_ref().robot.as_ref())
        .await?;
    let req = request.into_inner();
    let (params, time_budget) = explore_params_in(&req, &robot.chain)?;
    let scene = scene_in("scene", req.scene.as_ref(), &SceneLimits::default())?;
    if scene.is_empty() {
        return Err(invalid("scene", "is empty: the camera would see nothing"));
    }
    let setup = collision_setup(shared, &robot, &budget).await?;
    let (tx, rx) = tokio::sync::mpsc::channel(16);
    let compute = shared.compute.clone();
    tokio::spawn(async move {
        let _permit = permit;
        let step_tx = tx.clone();
        let run_budget = budget.clone();
        let outcome = compute
            .run(&run_budget, move |b| -> Result<pb::ExploreResponse, Status> {
                let truth = Arc::new(SceneGeometry::build(&scene).map_err(|e| collision_error("scene", e))?);
                let chain = robot.chain.clone();
                let world = ExploreWorld {
                    chain: &chain,
                    model: &setup.model,
                    acm: &setup.acm,
                    truth: &truth,
                };
                // Iterations are few and each is worth keeping: wait for
                // room in the channel rather than drop one.
                let mut send = |s: &ExploreStep| {
                    let _ = step_tx.blocking_send(Ok(pb::ExploreResponse {
                        event: Some(pb::explore_response::Event::Iteration(iteration_out(&chain, s))),
                    }));
                };
                let gone = || b.cancelled() || step_tx.is_closed();
                let ctl = ExploreControl {
                    deadline: b.deadline().with_cancel(&gone).min_with_budget(time_budget),
                    on_step: Some(&mut send),
                };
                let out = explore(&world, &req.start, &params, ctl).map_err(explore_error)?;
                let tree = octree_out(&out.tree, true);
                Ok(pb::ExploreResponse {
                    event: Some(pb::explore_response::Event::Summary(summary_out(
                        &out,
                        tree,
                        started.elapsed(),
                    ))),
                })
            })
            .await;
        let message = match outcome {
            Ok(r) => r,
            Err(status) => Err(status),
        };
        let _ = tx.send(message).await;
    });
    Ok(ReceiverStream::new(rx))
}
