//! Unary calls answered by invoking the service adapter's handler directly:
//! the request is decoded and the reply encoded here, with no HTTP request,
//! router, body or gRPC framing in between. Everything the guard layer does
//! for a call over the network is done here too, with the same functions: the
//! deadline (shared with the handler through [`RequestDeadline`], enforced
//! around it), a panic turned into INTERNAL, the non-finite check of the
//! reply, the message size limits and the `grpc_server_*` metrics.

use std::future::Future;
use std::panic::AssertUnwindSafe;
use std::time::Duration;

use bytes::Bytes;
use prost::Message;
use tonic::Status;

use crate::api::Apis;
use crate::pb::exploration_service_server::ExplorationService;
use crate::pb::kinematics_service_server::KinematicsService;
use crate::pb::mobile_service_server::MobileService;
use crate::pb::planning_service_server::PlanningService;
use crate::pb::robot_service_server::RobotService;
use crate::pb::scoring_service_server::ScoringService;
use crate::runtime::catch_unwind;
use crate::runtime::deadline::{RequestDeadline, call_deadline, effective_timeout};
use crate::status::code_name;
use crate::transport::finite;
use crate::transport::guard::{CallLabels, Unanswered, deadline_status, non_finite_status, panic_status};

/// What a direct call needs besides the handler: the server's limits.
pub(super) struct Limits {
    pub max_message_bytes: usize,
    pub default_timeout: Option<Duration>,
}

/// Answers the unary call to `path` directly, or `None` when `path` is not a
/// unary kinplan method (streams and unknown paths take the routed way).
pub(super) async fn unary(
    apis: &Apis,
    limits: &Limits,
    path: &str,
    message: &[u8],
    timeout: Option<Duration>,
) -> Option<Result<Bytes, Status>> {
    macro_rules! table {
        ($($service:literal / $name:literal => $api:ident . $method:ident via $Trait:ident),* $(,)?) => {
            match path {
                $(concat!("/kinplan.v1.", $service, "/", $name) => Some(
                    call(limits, path, message, timeout, |r| $Trait::$method(&apis.$api, r)).await
                ),)*
                _ => None,
            }
        };
    }
    table! {
        "RobotService" / "ListRobots" => robot.list_robots via RobotService,
        "RobotService" / "DescribeRobot" => robot.describe_robot via RobotService,
        "RobotService" / "ForwardKinematics" => robot.forward_kinematics via RobotService,
        "RobotService" / "Jacobian" => robot.jacobian via RobotService,
        "RobotService" / "ForwardKinematicsBatch" => robot.forward_kinematics_batch via RobotService,
        "KinematicsService" / "SolveIk" => kinematics.solve_ik via KinematicsService,
        "KinematicsService" / "SolveIkBatch" => kinematics.solve_ik_batch via KinematicsService,
        "KinematicsService" / "TrackPath" => kinematics.track_path via KinematicsService,
        "KinematicsService" / "SolveLinearSystem" => kinematics.solve_linear_system via KinematicsService,
        "ScoringService" / "ScoreTrajectory" => scoring.score_trajectory via ScoringService,
        "ScoringService" / "CompareTrajectories" => scoring.compare_trajectories via ScoringService,
        "MobileService" / "WheelKinematics" => mobile.wheel_kinematics via MobileService,
        "MobileService" / "ControlStep" => mobile.control_step via MobileService,
        "MobileService" / "FollowPath" => mobile.follow_path via MobileService,
        "MobileService" / "Navigate" => mobile.navigate via MobileService,
        "PlanningService" / "Plan" => planning.plan via PlanningService,
        "PlanningService" / "CheckState" => planning.check_state via PlanningService,
        "PlanningService" / "Retime" => planning.retime via PlanningService,
        "ExplorationService" / "NextBestView" => exploration.next_best_view via ExplorationService,
        "ExplorationService" / "InsertScan" => exploration.insert_scan via ExplorationService,
        "ExplorationService" / "OctreeInfo" => exploration.octree_info via ExplorationService,
        "ExplorationService" / "ReferenceScene" => exploration.reference_scene via ExplorationService,
    }
}

/// One direct call, recorded in the metrics with the status it answers —
/// or, when the caller drops it before the answer (an asyncio task
/// cancelled, a timeout around it), as abandoned: DEADLINE_EXCEEDED at the
/// call's timeout, CANCELLED before, as the guard records a reset stream.
async fn call<Req, Resp, Fut>(
    limits: &Limits,
    path: &str,
    message: &[u8],
    timeout: Option<Duration>,
    handler: impl FnOnce(tonic::Request<Req>) -> Fut,
) -> Result<Bytes, Status>
where
    Req: Message + Default,
    Resp: Message,
    Fut: Future<Output = Result<tonic::Response<Resp>, Status>>,
{
    let waiting = Unanswered(Some(
        CallLabels::for_path(path).with_timeout(effective_timeout(timeout, limits.default_timeout)),
    ));
    let labels = waiting.labels();
    let answer: Result<Bytes, Status> = async {
        let deadline = call_deadline(timeout, limits.default_timeout);
        within_limit("request", message.len(), limits.max_message_bytes)?;
        let decoded = Req::decode(message)
            .map_err(|e| Status::internal(format!("failed to decode Protobuf message: {e}")))?;
        let mut request = tonic::Request::new(decoded);
        request.extensions_mut().insert(RequestDeadline(deadline));
        let future = std::panic::catch_unwind(AssertUnwindSafe(|| handler(request)))
            .map_err(|panic| panic_status(labels, &*panic))?;
        let guarded = catch_unwind(future);
        let outcome = match deadline {
            Some(d) => tokio::time::timeout_at(d.into(), guarded)
                .await
                .map_err(|_| deadline_status())?,
            None => guarded.await,
        };
        let reply = outcome
            .map_err(|panic| panic_status(labels, &*panic))??
            .into_inner();
        let encoded = reply.encode_to_vec();
        within_limit("reply", encoded.len(), limits.max_message_bytes)?;
        if let Some(reply_type) = finite::reply_type(path) {
            finite::check(reply_type, &encoded).map_err(|at| non_finite_status(Some(labels), &at))?;
        }
        Ok(Bytes::from(encoded))
    }
    .await;
    waiting.answered().record(match &answer {
        Ok(_) => "OK",
        Err(status) => code_name(status.code() as i32),
    });
    answer
}

/// OUT_OF_RANGE for a message over the limit, as tonic's codec answers it.
fn within_limit(what: &str, bytes: usize, limit: usize) -> Result<(), Status> {
    if bytes > limit {
        return Err(Status::out_of_range(format!(
            "the {what} message is {bytes} bytes, over the limit of {limit} bytes"
        )));
    }
    Ok(())
}
