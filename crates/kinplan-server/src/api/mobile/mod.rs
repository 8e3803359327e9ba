//! `MobileService`: chassis wheel kinematics, one controller step, and simulated path
//! following and navigation (docs/mobile.md, [`kinplan_core::mobile`]).
//!
//! Thin adapter: admit → proto messages into domain values (unset fields: the domain's
//! defaults; sizes bounded) → the domain function → reply. Simulations run on the CPU pool and
//! stop when the request's budget says so; domain errors become INVALID_ARGUMENT naming the
//! request field (`status::mobile`). The service keeps no state: a controller's memory between
//! `ControlStep` calls travels to the caller and back as an opaque token (the domain's
//! [`kinplan_core::mobile::control_step`] decodes and encodes it). Conversions: `convert`.

use tonic::{Request, Response, Status};

use crate::pb::{self, mobile_service_server::MobileService};
use crate::runtime::Shared;
use crate::status::invalid;
use crate::status::mobile::mobile_error;
use kinplan_core::Deadline;
use kinplan_core::mobile::{
    GRID_PATH_CONTROLLER, NavigateParams, PathFollowParams, Saturation, StepController, StepOptions,
    follow_path, navigate, navigate_astar,
};

mod convert;

pub use convert::{
    MAX_OBSTACLES, MAX_PATH_NODES, MAX_POLYGON_VERTICES, MAX_RAYS_PER_BEAM, MAX_SENSORS,
    MAX_STEERING_CANDIDATES, MAX_STEPS, MAX_WORLD_VERTICES,
};

use convert::{
    astar_in, chassis_in, follow_in, path_in, point_in, pose_in, run_out, saturation_out, sensors_in, sim_in,
    step_out, twist_in, twist_out, vdf_in, wheels_in, wheels_out, world_in,
};

/// Largest state token accepted, bytes.
pub const MAX_TOKEN_BYTES: usize = 1 << 20;

pub struct MobileApi {
    shared: Shared,
}

impl MobileApi {
    pub fn new(shared: Shared) -> Self {
        Self { shared }
    }
}

#[tonic::async_trait]
impl MobileService for MobileApi {
    async fn wheel_kinematics(
        &self,
        request: Request<pb::WheelKinematicsRequest>,
    ) -> Result<Response<pb::WheelKinematicsResponse>, Status> {
        let _admitted = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        let chassis = chassis_in(req.chassis.as_ref());
        use pb::wheel_kinematics_request::Input;
        let reply = match req.input {
            None => {
                return Err(invalid(
                    "input",
                    "give either twist (inverse) or wheels (forward)",
                ));
            }
            Some(Input::Twist(t)) => {
                let (wheels, sat) = chassis.inverse_kinematics(twist_in(&t)).map_err(mobile_error)?;
                let (applied, _) = chassis.saturate(twist_in(&t));
                pb::WheelKinematicsResponse {
                    twist: Some(twist_out(applied)),
                    wheels: Some(wheels_out(&wheels)),
                    saturation: Some(saturation_out(sat)),
                }
            }
            Some(Input::Wheels(w)) => {
                let wheels = wheels_in(&w)?;
                let twist = chassis.forward_kinematics(&wheels).map_err(mobile_error)?;
                pb::WheelKinematicsResponse {
                    twist: Some(twist_out(twist)),
                    wheels: Some(w),
                    saturation: Some(saturation_out(Saturation::NONE)),
                }
            }
        };
        Ok(Response::new(reply))
    }

    async fn control_step(
        &self,
        request: Request<pb::ControlStepRequest>,
    ) -> Result<Response<pb::ControlStepResponse>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        if req.state_token.len() > MAX_TOKEN_BYTES {
            return Err(invalid(
                "state_token",
                format!("{} bytes, at most {MAX_TOKEN_BYTES}", req.state_token.len()),
            ));
        }
        // Sensing a world costs up to obstacles × rays: the CPU pool; the rest inline.
        if req.world.is_empty() {
            control_step(req, Deadline::none()).map(Response::new)
        } else {
            self.shared
                .compute
                .run(&budget, move |b| control_step(req, b.deadline()))
                .await?
                .map(Response::new)
        }
    }

    async fn follow_path(
        &self,
        request: Request<pb::FollowPathRequest>,
    ) -> Result<Response<pb::MobileRun>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        let chassis = chassis_in(req.chassis.as_ref());
        let start = pose_in(req.start.as_ref());
        let path = path_in(&req.path)?;
        let follow = follow_in(
            req.controller,
            req.follow.as_ref(),
            PathFollowParams::default().controller,
        )?;
        let world = if req.world.is_empty() {
            None
        } else {
            Some(world_in(&req.world)?)
        };
        let sim = sim_in(req.sim.as_ref())?;
        let run = self
            .shared
            .compute
            .run(&budget, move |b| {
                follow_path(
                    &chassis,
                    start,
                    &path,
                    world.as_ref(),
                    &follow,
                    &sim,
                    b.deadline(),
                )
            })
            .await?
            .map_err(mobile_error)?;
        Ok(Response::new(run_out(run)))
    }

    async fn navigate(
        &self,
        request: Request<pb::NavigateRequest>,
    ) -> Result<Response<pb::MobileRun>, Status> {
        let (_permit, budget) = self.shared.compute.admit(&request)?;
        let req = request.into_inner();
        let chassis = chassis_in(req.chassis.as_ref());
        let start = pose_in(req.start.as_ref());
        let goal = point_in(req.goal.as_ref());
        let world = world_in(&req.world)?;
        let sim = sim_in(req.sim.as_ref())?;
        let navigator = pb::Navigator::try_from(req.navigator)
            .map_err(|_| invalid("navigator", format!("unknown navigator {}", req.navigator)))?;
        let run = match navigator {
            pb::Navigator::Unspecified | pb::Navigator::VectorDistance => {
                let params = NavigateParams {
                    sim,
                    sensors: sensors_in(req.sensors.as_ref())?,
                    vdf: vdf_in(req.vdf.as_ref())?,
                    seed: req.seed,
                };
                self.shared
                    .compute
                    .run(&budget, move |b| {
                        navigate(&chassis, start, goal, &world, &params, b.deadline())
                    })
                    .await?
            }
            pb::Navigator::GridAstar => {
                let follow = follow_in(req.controller, req.follow.as_ref(), GRID_PATH_CONTROLLER)?;
                let astar = astar_in(req.astar.as_ref())?;
                self.shared
                    .compute
                    .run(&budget, move |b| {
                        navigate_astar(&chassis, start, goal, &world, &astar, &follow, &sim, b.deadline())
                    })
                    .await?
            }
        }
        .map_err(mobile_error)?;
        Ok(Response::new(run_out(run)))
    }
}

/// One controller step: the request into the domain's [`StepController`], the domain's
/// [`control_step`] (token decoding, sensing, stepping, saturation, token encoding), the reply.
fn control_step(
    req: pb::ControlStepRequest,
    deadline: Deadline<'_>,
) -> Result<pb::ControlStepResponse, Status> {
    let chassis = chassis_in(req.chassis.as_ref());
    let state = pose_in(req.state.as_ref());
    let d = StepOptions::default();
    let options = StepOptions {
        dt: req.dt.unwrap_or(d.dt),
        robot_radius: req.robot_radius.unwrap_or(d.robot_radius),
        seed: req.seed,
    };
    let world;
    let path;
    let controller = if req.controller == pb::Controller::VectorDistance as i32 {
        world = if req.world.is_empty() {
            None
        } else {
            Some(world_in(&req.world)?)
        };
        StepController::VectorDistance {
            goal: point_in(req.goal.as_ref()),
            sensors: sensors_in(req.sensors.as_ref())?,
            vdf: vdf_in(req.vdf.as_ref())?,
            readings: &req.readings,
            world: world.as_ref(),
        }
    } else {
        path = path_in(&req.path)?;
        StepController::FollowPath {
            path: &path,
            follow: follow_in(
                req.controller,
                req.follow.as_ref(),
                PathFollowParams::default().controller,
            )?,
        }
    };
    let Some(step) = kinplan_core::mobile::control_step(
        &chassis,
        state,
        &req.state_token,
        &controller,
        &options,
        deadline,
    )
    .map_err(mobile_error)?
    else {
        return Err(Status::deadline_exceeded(
            "the request's deadline passed before the work finished",
        ));
    };
    Ok(step_out(step))
}
