//! The kinplan services called in the caller's own process: no socket, no
//! HTTP/2 framing on a wire, the same handlers, validation, admission,
//! deadlines and panic guard as `kinplan serve`. A request is the encoded
//! protobuf message; so is the answer. The Python package's in-process
//! backend (`kinplan.Client.local()`) is built on it.

use std::sync::Arc;
use std::time::Duration;

use bytes::{Buf, BufMut, Bytes, BytesMut};
use http_body_util::BodyExt;
use tokio::sync::{mpsc, watch};
use tokio_stream::StreamExt;
use tokio_stream::wrappers::ReceiverStream;
use tonic::Status;
use tonic::body::Body;
use tower::{Layer, ServiceExt};

use crate::api::Apis;
use crate::transport::guard::{Guard, GuardLayer};
use crate::transport::server::{ServerConfig, kinplan_routes, kinplan_shared};

mod direct;

/// Length of gRPC's message prefix: a compression flag and a 4-byte length.
const PREFIX: usize = 5;

/// The kinplan services, ready to be called without a server. Clones share them.
#[derive(Clone)]
pub struct InProcess {
    service: Guard<tonic::service::Routes>,
    /// The same adapters over the same shared state, for unary calls made
    /// without the router ([`direct`]).
    apis: Arc<Apis>,
    limits: Arc<direct::Limits>,
    max_message_bytes: usize,
    /// Shutdown never cuts in-process streams; the guard only needs a receiver.
    _cut: Arc<watch::Sender<bool>>,
}

/// The answers of a server-streamed or bidirectional call, in order.
pub struct ResponseStream {
    /// A bidirectional call whose handler has not answered yet (it may wait
    /// for the first request message before it does).
    starting: Option<tokio::task::JoinHandle<Result<ResponseStream, Status>>>,
    body: Body,
    buffer: BytesMut,
    max_message_bytes: usize,
    done: bool,
}

impl InProcess {
    /// The services with `config`'s pool, cache and limits (its network and
    /// TLS settings do not apply). Call from inside a tokio runtime.
    pub fn new(config: &ServerConfig) -> InProcess {
        let shared = kinplan_shared(config);
        let (routes, _) = kinplan_routes(&shared, config);
        let (cut, cut_rx) = watch::channel(false);
        InProcess {
            service: GuardLayer::new(cut_rx, config.request_timeout).layer(routes),
            apis: Arc::new(Apis::new(&shared)),
            limits: Arc::new(direct::Limits {
                max_message_bytes: config.max_message_bytes,
                default_timeout: config.request_timeout,
            }),
            max_message_bytes: config.max_message_bytes,
            _cut: Arc::new(cut),
        }
    }

    /// A unary call: `path` is "/kinplan.v1.RobotService/ForwardKinematics",
    /// `message` the encoded request; answers the encoded response.
    pub async fn unary(
        &self,
        path: &str,
        message: &[u8],
        timeout: Option<Duration>,
    ) -> Result<Bytes, Status> {
        if let Some(answer) = direct::unary(&self.apis, &self.limits, path, message, timeout).await {
            return answer;
        }
        self.routed_unary(path, message, timeout).await
    }

    /// A unary call through the router, the guard layer and tonic's codec,
    /// as over the network.
    pub async fn routed_unary(
        &self,
        path: &str,
        message: &[u8],
        timeout: Option<Duration>,
    ) -> Result<Bytes, Status> {
        let body = Body::new(http_body_util::Full::new(frame(message)));
        let mut answers = self.call(path, body, timeout).await?;
        let answer = answers
            .next()
            .await
            .unwrap_or_else(|| Err(Status::internal("a unary call answered no message")))?;
        match answers.next().await {
            None => Ok(answer),
            Some(Err(status)) => Err(status),
            Some(Ok(_)) => Err(Status::internal("a unary call answered two messages")),
        }
    }

    /// A server-streamed call: one request message, a stream of answers.
    pub async fn server_stream(
        &self,
        path: &str,
        message: &[u8],
        timeout: Option<Duration>,
    ) -> Result<ResponseStream, Status> {
        let body = Body::new(http_body_util::Full::new(frame(message)));
        self.call(path, body, timeout).await
    }

    /// A bidirectional (or client-streamed) call: the sender of request
    /// messages (drop it to end the request stream) and the answers. Returns
    /// at once: the call starts on the runtime, since its handler may wait
    /// for the first message. Call from inside the runtime.
    pub fn stream(&self, path: &str, timeout: Option<Duration>) -> (mpsc::Sender<Bytes>, ResponseStream) {
        let (sender, receiver) = mpsc::channel::<Bytes>(64);
        let frames = ReceiverStream::new(receiver)
            .map(|message| Ok::<_, std::convert::Infallible>(http_body::Frame::data(frame(&message))));
        let body = Body::new(http_body_util::StreamBody::new(frames));
        let call = self.clone();
        let path = path.to_owned();
        let starting = tokio::spawn(async move { call.call(&path, body, timeout).await });
        let answers = ResponseStream {
            starting: Some(starting),
            body: Body::empty(),
            buffer: BytesMut::new(),
            max_message_bytes: self.max_message_bytes,
            done: false,
        };
        (sender, answers)
    }

    async fn call(
        &self,
        path: &str,
        body: Body,
        timeout: Option<Duration>,
    ) -> Result<ResponseStream, Status> {
        let mut request = http::Request::builder()
            .method(http::Method::POST)
            .uri(path)
            .header("content-type", "application/grpc")
            .header("te", "trailers");
        if let Some(timeout) = timeout {
            request = request.header("grpc-timeout", grpc_timeout(timeout));
        }
        let request = request
            .body(body)
            .map_err(|e| Status::invalid_argument(format!("method path: {e}")))?;
        let response = self
            .service
            .clone()
            .oneshot(request)
            .await
            .map_err(|_| Status::internal("the in-process call failed"))?;
        let (parts, body) = response.into_parts();
        // a trailers-only answer carries its status in the headers
        if let Some(status) = Status::from_header_map(&parts.headers)
            && status.code() != tonic::Code::Ok
        {
            return Err(status);
        }
        Ok(ResponseStream {
            starting: None,
            body,
            buffer: BytesMut::new(),
            max_message_bytes: self.max_message_bytes,
            done: false,
        })
    }
}

impl ResponseStream {
    /// The next answer, the call's error status, or `None` after the last one.
    pub async fn next(&mut self) -> Option<Result<Bytes, Status>> {
        if let Some(starting) = self.starting.take() {
            match starting.await {
                Ok(Ok(started)) => *self = started,
                Ok(Err(status)) => {
                    self.done = true;
                    return Some(Err(status));
                }
                Err(_) => {
                    self.done = true;
                    return Some(Err(Status::internal("the in-process call failed")));
                }
            }
        }
        loop {
            if let Some(message) = self.take_message() {
                return Some(message);
            }
            if self.done {
                return None;
            }
            match self.body.frame().await {
                None => {
                    self.done = true;
                    if !self.buffer.is_empty() {
                        return Some(Err(Status::internal("the answer ended inside a message")));
                    }
                }
                Some(Err(status)) => {
                    self.done = true;
                    return Some(Err(status));
                }
                Some(Ok(frame)) => match frame.into_data() {
                    Ok(data) => self.buffer.put(data),
                    Err(frame) => {
                        self.done = true;
                        let status = frame.trailers_ref().and_then(Status::from_header_map);
                        if let Some(status) = status.filter(|s| s.code() != tonic::Code::Ok) {
                            return Some(Err(status));
                        }
                    }
                },
            }
        }
    }

    /// A whole message from the buffer, if one has arrived.
    fn take_message(&mut self) -> Option<Result<Bytes, Status>> {
        if self.buffer.len() < PREFIX {
            return None;
        }
        let length =
            u32::from_be_bytes([self.buffer[1], self.buffer[2], self.buffer[3], self.buffer[4]]) as usize;
        if self.buffer[0] != 0 || length > self.max_message_bytes {
            self.done = true;
            self.buffer.clear();
            return Some(Err(Status::internal("a compressed or oversized answer")));
        }
        if self.buffer.len() < PREFIX + length {
            return None;
        }
        self.buffer.advance(PREFIX);
        Some(Ok(self.buffer.split_to(length).freeze()))
    }
}

/// A message with gRPC's uncompressed length prefix.
fn frame(message: &[u8]) -> Bytes {
    let mut framed = BytesMut::with_capacity(PREFIX + message.len());
    framed.put_u8(0);
    framed.put_u32(message.len() as u32);
    framed.put_slice(message);
    framed.freeze()
}

/// The `grpc-timeout` header: at most 8 digits, in the finest unit that fits.
fn grpc_timeout(timeout: Duration) -> String {
    const MAX: u128 = 99_999_999;
    let micros = timeout.as_micros();
    if micros <= MAX {
        format!("{micros}u")
    } else if timeout.as_millis() <= MAX {
        format!("{}m", timeout.as_millis())
    } else {
        format!("{}S", timeout.as_secs().min(MAX as u64))
    }
}

#[cfg(test)]
mod tests {
    use prost::Message;

    use super::*;
    use crate::pb;

    fn kr210() -> Option<pb::RobotRef> {
        Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Name("kuka_kr210_r2700_extra".into())),
            ..Default::default()
        })
    }

    #[test]
    fn timeouts_are_written_in_the_finest_unit_that_fits() {
        assert_eq!(grpc_timeout(Duration::from_millis(12)), "12000u");
        assert_eq!(grpc_timeout(Duration::from_secs(1000)), "1000000m");
        assert_eq!(grpc_timeout(Duration::from_secs(10_000_000)), "10000000S");
    }

    #[tokio::test]
    async fn unary_calls_answer_the_same_as_the_domain_and_errors_keep_their_code() {
        let local = InProcess::new(&ServerConfig::default());
        let q = vec![0.1, -1.5, 1.4, 0.2, 0.3, 0.4];
        let request = pb::ForwardKinematicsRequest {
            robot: kr210(),
            joint_positions: q.clone(),
            include_links: false,
        };
        let answer = local
            .unary(
                "/kinplan.v1.RobotService/ForwardKinematics",
                &request.encode_to_vec(),
                Some(Duration::from_secs(5)),
            )
            .await
            .unwrap();
        let reply = pb::ForwardKinematicsResponse::decode(answer).unwrap();
        let p = reply.tool_pose.unwrap().position.unwrap();
        let expected = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra")
            .unwrap()
            .fk(&q)
            .translation
            .vector;
        assert!((p.x - expected.x).abs() + (p.y - expected.y).abs() + (p.z - expected.z).abs() < 1e-12);

        let bad = pb::ForwardKinematicsRequest {
            robot: kr210(),
            joint_positions: vec![f64::NAN; 6],
            include_links: false,
        };
        let status = local
            .unary(
                "/kinplan.v1.RobotService/ForwardKinematics",
                &bad.encode_to_vec(),
                None,
            )
            .await
            .unwrap_err();
        assert_eq!(status.code(), tonic::Code::InvalidArgument);
        assert!(status.message().contains("joint_positions"), "{status:?}");
        assert!(
            !status.details().is_empty(),
            "field violations travel in the details"
        );

        let unknown = local
            .unary("/kinplan.v1.RobotService/Nope", &[], None)
            .await
            .unwrap_err();
        assert_eq!(unknown.code(), tonic::Code::Unimplemented);
        let garbage = local
            .unary(
                "/kinplan.v1.RobotService/ForwardKinematics",
                &[0xff, 0xff, 0xff],
                None,
            )
            .await
            .unwrap_err();
        assert_eq!(garbage.code(), tonic::Code::Internal, "{garbage:?}");
    }

    /// Every unary kinplan method, as the proto declares them.
    const UNARY_PATHS: [&str; 22] = [
        "/kinplan.v1.RobotService/ListRobots",
        "/kinplan.v1.RobotService/DescribeRobot",
        "/kinplan.v1.RobotService/ForwardKinematics",
        "/kinplan.v1.RobotService/Jacobian",
        "/kinplan.v1.RobotService/ForwardKinematicsBatch",
        "/kinplan.v1.KinematicsService/SolveIk",
        "/kinplan.v1.KinematicsService/SolveIkBatch",
        "/kinplan.v1.KinematicsService/TrackPath",
        "/kinplan.v1.KinematicsService/SolveLinearSystem",
        "/kinplan.v1.ScoringService/ScoreTrajectory",
        "/kinplan.v1.ScoringService/CompareTrajectories",
        "/kinplan.v1.MobileService/WheelKinematics",
        "/kinplan.v1.MobileService/ControlStep",
        "/kinplan.v1.MobileService/FollowPath",
        "/kinplan.v1.MobileService/Navigate",
        "/kinplan.v1.PlanningService/Plan",
        "/kinplan.v1.PlanningService/CheckState",
        "/kinplan.v1.PlanningService/Retime",
        "/kinplan.v1.ExplorationService/NextBestView",
        "/kinplan.v1.ExplorationService/InsertScan",
        "/kinplan.v1.ExplorationService/OctreeInfo",
        "/kinplan.v1.ExplorationService/ReferenceScene",
    ];

    /// The direct answer and the routed one (the network's path: router,
    /// guard layer, tonic's codec) to the same request.
    async fn both(
        local: &InProcess,
        path: &str,
        message: &[u8],
        timeout: Option<Duration>,
    ) -> (Result<Bytes, Status>, Result<Bytes, Status>) {
        let direct = direct::unary(&local.apis, &local.limits, path, message, timeout)
            .await
            .expect("a unary kinplan method is answered directly");
        (direct, local.routed_unary(path, message, timeout).await)
    }

    #[tokio::test]
    async fn direct_unary_calls_answer_as_the_routed_ones() {
        let local = InProcess::new(&ServerConfig::default());
        // an empty request to every method: the same code and message either way
        for path in UNARY_PATHS {
            let (direct, routed) = both(&local, path, &[], Some(Duration::from_secs(5))).await;
            match (direct, routed) {
                (Ok(a), Ok(b)) => assert_eq!(a, b, "{path}"),
                (Err(a), Err(b)) => {
                    assert_eq!((a.code(), a.message()), (b.code(), b.message()), "{path}");
                    assert_eq!(a.details(), b.details(), "{path}");
                }
                (a, b) => panic!("{path}: direct {a:?}, routed {b:?}"),
            }
        }
        // deterministic answers are byte-identical
        let fk = pb::ForwardKinematicsRequest {
            robot: kr210(),
            joint_positions: vec![0.1, -1.5, 1.4, 0.2, 0.3, 0.4],
            include_links: true,
        }
        .encode_to_vec();
        let jacobian = pb::JacobianRequest {
            robot: kr210(),
            joint_positions: vec![0.1, -1.5, 1.4, 0.2, 0.3, 0.4],
        }
        .encode_to_vec();
        for (path, message) in [
            ("/kinplan.v1.RobotService/ForwardKinematics", fk),
            ("/kinplan.v1.RobotService/Jacobian", jacobian),
        ] {
            let (direct, routed) = both(&local, path, &message, None).await;
            assert_eq!(direct.unwrap(), routed.unwrap(), "{path}");
        }
        // garbage bytes: tonic's codec answers INTERNAL, so does the direct path
        let (direct, routed) = both(
            &local,
            "/kinplan.v1.RobotService/ForwardKinematics",
            &[0xff, 0xff, 0xff],
            None,
        )
        .await;
        assert_eq!(direct.unwrap_err().code(), routed.unwrap_err().code());
        // streams and unknown methods are not answered directly
        for path in [
            "/kinplan.v1.KinematicsService/StreamIk",
            "/kinplan.v1.RobotService/Nope",
        ] {
            assert!(
                direct::unary(&local.apis, &local.limits, path, &[], None)
                    .await
                    .is_none()
            );
        }
    }

    #[tokio::test]
    async fn a_direct_call_keeps_its_deadline_and_the_message_limit() {
        let config = ServerConfig {
            max_message_bytes: 4 << 20,
            ..ServerConfig::default()
        };
        let local = InProcess::new(&config);
        // 40,000 FK states cannot be answered in 200 µs
        let batch = pb::ForwardKinematicsBatchRequest {
            robot: kr210(),
            joint_positions: Some(pb::Matrix {
                rows: 40_000,
                cols: 6,
                data: vec![0.1; 240_000],
            }),
            ..Default::default()
        }
        .encode_to_vec();
        let started = std::time::Instant::now();
        let status = local
            .unary(
                "/kinplan.v1.RobotService/ForwardKinematicsBatch",
                &batch,
                Some(Duration::from_micros(200)),
            )
            .await
            .unwrap_err();
        assert_eq!(status.code(), tonic::Code::DeadlineExceeded, "{status:?}");
        assert!(
            started.elapsed() < Duration::from_millis(500),
            "{:?}",
            started.elapsed()
        );
        // a request over the message limit is refused before decoding
        let status = local
            .unary(
                "/kinplan.v1.RobotService/ForwardKinematics",
                &vec![0u8; (4 << 20) + 1],
                None,
            )
            .await
            .unwrap_err();
        assert_eq!(status.code(), tonic::Code::OutOfRange, "{status:?}");
    }

    /// A direct call its caller drops before the answer (an asyncio task
    /// cancelled) is counted, as CANCELLED, as the guard counts a reset call.
    #[test]
    fn a_direct_call_dropped_before_its_answer_is_recorded_as_cancelled() {
        let recorder = metrics_exporter_prometheus::PrometheusBuilder::new().build_recorder();
        let handle = recorder.handle();
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        let batch = pb::ForwardKinematicsBatchRequest {
            robot: kr210(),
            joint_positions: Some(pb::Matrix {
                rows: 200_000,
                cols: 6,
                data: vec![0.1; 1_200_000],
            }),
            ..Default::default()
        }
        .encode_to_vec();
        let config = ServerConfig {
            max_message_bytes: 16 << 20,
            ..ServerConfig::default()
        };
        metrics::with_local_recorder(&recorder, || {
            runtime.block_on(async {
                let local = InProcess::new(&config);
                let call = local.unary(
                    "/kinplan.v1.RobotService/ForwardKinematicsBatch",
                    &batch,
                    Some(Duration::from_secs(30)),
                );
                assert!(
                    tokio::time::timeout(Duration::from_millis(2), call)
                        .await
                        .is_err(),
                    "200,000 FK states are not answered within 2 ms"
                );
            })
        });
        let text = handle.render();
        let cancelled = text.lines().any(|l| {
            l.starts_with("grpc_server_handled_total")
                && l.contains("grpc_method=\"ForwardKinematicsBatch\"")
                && l.contains("grpc_code=\"CANCELLED\"")
                && l.ends_with(" 1")
        });
        assert!(cancelled, "{text}");
    }

    #[tokio::test]
    async fn a_bidirectional_stream_answers_each_message_in_order() {
        let local = InProcess::new(&ServerConfig::default());
        let chain = kinplan_core::robot::builtin_chain("kuka_kr210_r2700_extra").unwrap();
        let q0 = [0.2, -1.6, 1.7, 0.3, 0.8, -0.2];
        let (sender, mut answers) = local.stream("/kinplan.v1.KinematicsService/StreamIk", None);
        for k in 0..5u32 {
            let mut target = chain.fk(&q0);
            target.translation.vector.z += 0.001 * f64::from(k);
            let (p, r) = (target.translation.vector, target.rotation.quaternion());
            let message = pb::StreamIkRequest {
                sequence: u64::from(k),
                robot: if k == 0 { kr210() } else { None },
                seed: if k == 0 { q0.to_vec() } else { Vec::new() },
                target: Some(pb::Pose {
                    position: Some(pb::Vec3 {
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    }),
                    orientation: Some(pb::Quaternion {
                        x: r.i,
                        y: r.j,
                        z: r.k,
                        w: r.w,
                    }),
                }),
                options: None,
            };
            sender.send(message.encode_to_vec().into()).await.unwrap();
            let answer = pb::StreamIkResponse::decode(answers.next().await.unwrap().unwrap()).unwrap();
            assert_eq!(answer.sequence, u64::from(k));
            let result = answer.result.unwrap();
            assert!(result.success);
            let reached = chain.fk(&result.solutions[0].joints);
            assert!((reached.translation.vector - target.translation.vector).norm() < 1e-5);
        }
        drop(sender);
        assert!(
            answers.next().await.is_none(),
            "the stream ends when the requests do"
        );
    }
}
