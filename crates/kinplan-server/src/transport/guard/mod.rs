//! The tower layer around every call (kinplan services, health, reflection):
//! it turns the request's deadline into a [`RequestDeadline`] the handlers
//! share, answers DEADLINE_EXCEEDED itself when a handler misses it, turns a
//! panic anywhere in a handler or its reply stream into INTERNAL with a log
//! line (never a reset connection), ends open streams with UNAVAILABLE once
//! shutdown's drain timeout passes, and records `grpc_server_handled_total` /
//! `grpc_server_handling_seconds` with the status the client sees, streams
//! included (read from the trailers).

use std::future::Future;
use std::panic::AssertUnwindSafe;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use tokio::sync::watch;
use tonic::Status;
use tonic::body::Body;

use crate::runtime::catch_unwind;
use crate::runtime::deadline::{
    RequestDeadline, answer_reserve, call_deadline, effective_timeout, grpc_timeout,
};
use crate::status::code_name;
use crate::transport::auth::{Tokens, admits};

/// Histogram bucket bounds, seconds: 50 µs to 10 s.
pub const HANDLING_BUCKETS: &[f64] = &[
    0.00005, 0.0001, 0.00025, 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0,
    10.0,
];

/// Whether the CPU pool admits no more work: a call that would be shed is
/// answered RESOURCE_EXHAUSTED before its request is decoded.
pub type Saturated = Arc<dyn Fn() -> bool + Send + Sync>;

#[derive(Clone)]
pub struct GuardLayer {
    /// Becomes true when shutdown's drain timeout has passed.
    cut: watch::Receiver<bool>,
    default_timeout: Option<Duration>,
    saturated: Option<Saturated>,
    tokens: Option<Tokens>,
}

impl GuardLayer {
    pub fn new(cut: watch::Receiver<bool>, default_timeout: Option<Duration>) -> Self {
        Self {
            cut,
            default_timeout,
            saturated: None,
            tokens: None,
        }
    }

    /// Sheds unary and server-streaming kinplan calls at the door while
    /// `saturated()` holds (the handlers' own admission stays the rule; this
    /// only answers a burst's extra calls without reading them).
    pub fn shedding_when(mut self, saturated: Saturated) -> Self {
        self.saturated = Some(saturated);
        self
    }

    /// Sheds only calls that pass authentication with `tokens` (the
    /// authentication layer inside answers the others UNAUTHENTICATED).
    pub fn authenticating_with(mut self, tokens: Option<Tokens>) -> Self {
        self.tokens = tokens;
        self
    }
}

impl<S> tower::Layer<S> for GuardLayer {
    type Service = Guard<S>;
    fn layer(&self, inner: S) -> Self::Service {
        Guard {
            inner,
            cut: self.cut.clone(),
            default_timeout: self.default_timeout,
            saturated: self.saturated.clone(),
            tokens: self.tokens.clone(),
        }
    }
}

#[derive(Clone)]
pub struct Guard<S> {
    inner: S,
    cut: watch::Receiver<bool>,
    default_timeout: Option<Duration>,
    saturated: Option<Saturated>,
    tokens: Option<Tokens>,
}

/// The calls admitted stream by stream (their messages are admitted one by
/// one), which shedding at the door leaves alone.
const ADMITTED_PER_MESSAGE: &[&str] = &["/kinplan.v1.KinematicsService/StreamIk"];

type BoxFuture<T> = Pin<Box<dyn Future<Output = T> + Send>>;

/// What a finished call is recorded under, and the instant its client gives
/// up (its timeout from when the call arrived; `None`: no timeout).
#[derive(Clone)]
pub(crate) struct CallLabels {
    service: String,
    method: String,
    started: Instant,
    client_deadline: Option<Instant>,
}

impl CallLabels {
    /// The labels of a call to `path` ("/package.Service/Method"), started now.
    pub(crate) fn for_path(path: &str) -> CallLabels {
        let (service, method) = path
            .trim_start_matches('/')
            .split_once('/')
            .map_or(("unknown".into(), "unknown".into()), |(s, m)| {
                (s.to_string(), m.to_string())
            });
        CallLabels {
            service,
            method,
            started: Instant::now(),
            client_deadline: None,
        }
    }

    /// The same labels, for a call whose client gives up `timeout` after it arrived.
    pub(crate) fn with_timeout(mut self, timeout: Option<Duration>) -> CallLabels {
        self.client_deadline = timeout.and_then(|t| self.started.checked_add(t));
        self
    }

    /// Records a call whose client went away before it was answered (the
    /// stream was reset): DEADLINE_EXCEEDED when that happened at the
    /// client's deadline (within the reserve [`answer_reserve`] keeps, since
    /// the client's clock started a little before ours), CANCELLED otherwise.
    pub(crate) fn record_abandoned(&self) {
        let timed_out = self.client_deadline.is_some_and(|d| {
            let timeout = d.saturating_duration_since(self.started);
            Instant::now() + answer_reserve(timeout) >= d
        });
        self.record(if timed_out {
            "DEADLINE_EXCEEDED"
        } else {
            "CANCELLED"
        });
    }

    /// Records the call as finished with `code` (a gRPC code name, the one
    /// sent). An answer written once the call's timeout has passed is also
    /// counted in `kinplan_answers_after_deadline_total`: its client has
    /// given up or is about to (whether it still reads the answer depends
    /// on how promptly its own timer fires).
    pub(crate) fn record(&self, code: &'static str) {
        let late = self.client_deadline.is_some_and(|d| Instant::now() >= d);
        let labels = [
            ("grpc_service", self.service.clone()),
            ("grpc_method", self.method.clone()),
        ];
        metrics::histogram!("grpc_server_handling_seconds", &labels)
            .record(self.started.elapsed().as_secs_f64());
        if late {
            metrics::counter!("kinplan_answers_after_deadline_total", &labels).increment(1);
        }
        let mut with_code = labels.to_vec();
        with_code.push(("grpc_code", code.to_owned()));
        metrics::counter!("grpc_server_handled_total", &with_code).increment(1);
    }
}

pub(crate) fn panic_status(labels: &CallLabels, payload: &(dyn std::any::Any + Send)) -> Status {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    tracing::error!(
        service = %labels.service,
        method = %labels.method,
        panic = %what,
        "a handler panicked; answering INTERNAL"
    );
    Status::internal("the server failed unexpectedly while handling this call")
}

/// INTERNAL for an OK reply that carried a non-finite number, logged with
/// the call and the field numbers that lead to it.
pub(crate) fn non_finite_status(
    labels: Option<&CallLabels>,
    at: &crate::transport::finite::NonFinite,
) -> Status {
    let (service, method) = labels.map_or(("?", "?"), |l| (l.service.as_str(), l.method.as_str()));
    tracing::error!(
        service,
        method,
        field_numbers = ?at.0,
        "an OK reply carried a non-finite number; answering INTERNAL"
    );
    Status::internal("the server computed a non-finite number; this is a bug")
}

pub(crate) fn deadline_status() -> Status {
    Status::deadline_exceeded("the request's deadline passed before the work finished")
}

impl<S, B> tower::Service<http::Request<B>> for Guard<S>
where
    S: tower::Service<http::Request<B>, Response = http::Response<Body>>,
    S::Future: Send + 'static,
    S::Error: Send + 'static,
{
    type Response = http::Response<Body>;
    type Error = S::Error;
    type Future = BoxFuture<Result<http::Response<Body>, S::Error>>;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Self::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, mut request: http::Request<B>) -> Self::Future {
        let header = grpc_timeout(request.headers());
        let timeout = effective_timeout(header, self.default_timeout);
        let labels = CallLabels::for_path(request.uri().path()).with_timeout(timeout);
        let deadline = call_deadline(header, self.default_timeout);
        request.extensions_mut().insert(RequestDeadline(deadline));
        let cut = self.cut.clone();
        let reply_type = crate::transport::finite::reply_type(request.uri().path());
        if reply_type.is_some()
            && !ADMITTED_PER_MESSAGE.contains(&request.uri().path())
            && self.saturated.as_ref().is_some_and(|busy| busy())
            && admits(self.tokens.as_ref(), &request)
        {
            metrics::counter!("kinplan_requests_shed_total").increment(1);
            let status = crate::runtime::compute::shed_status();
            labels.record(code_name(status.code() as i32));
            return Box::pin(std::future::ready(Ok(status.into_http())));
        }
        let call = std::panic::catch_unwind(AssertUnwindSafe(|| self.inner.call(request)));
        Box::pin(async move {
            let future = match call {
                Ok(future) => future,
                Err(panic) => {
                    let status = panic_status(&labels, &*panic);
                    labels.record(code_name(status.code() as i32));
                    return Ok(status.into_http());
                }
            };
            // Until the handler answers: recorded as abandoned if the client
            // resets the call first (this future is then dropped).
            let waiting = Unanswered(Some(labels));
            let guarded = catch_unwind(future);
            let outcome = match deadline {
                Some(d) => tokio::time::timeout_at(d.into(), guarded).await.ok(),
                None => Some(guarded.await),
            };
            let labels = waiting.answered();
            let response = match outcome {
                None => Ok(deadline_status().into_http()),
                Some(Err(panic)) => Ok(panic_status(&labels, &*panic).into_http()),
                Some(Ok(result)) => result,
            };
            match response {
                Ok(response) => Ok(observe(response, labels, cut, reply_type)),
                Err(e) => {
                    labels.record("UNKNOWN");
                    Err(e)
                }
            }
        })
    }
}

/// A call not yet answered; dropped so, it is recorded as abandoned.
pub(crate) struct Unanswered(pub(crate) Option<CallLabels>);

impl Unanswered {
    /// The call's labels while it waits.
    pub(crate) fn labels(&self) -> &CallLabels {
        self.0.as_ref().expect("labels are taken only by `answered`")
    }

    /// The call's labels, now that it is answered (no longer recorded on drop).
    pub(crate) fn answered(mut self) -> CallLabels {
        self.0
            .take()
            .unwrap_or_else(|| CallLabels::for_path("/unknown/unknown"))
    }
}

impl Drop for Unanswered {
    fn drop(&mut self) {
        if let Some(labels) = self.0.take() {
            labels.record_abandoned();
        }
    }
}

mod body;

use body::observe;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::deadline::deadline_after;
    use bytes::Bytes;
    use http_body::Frame;
    use http_body_util::BodyExt;
    use tower::{Layer, ServiceExt};

    fn layer() -> (watch::Sender<bool>, GuardLayer) {
        let (tx, rx) = watch::channel(false);
        (tx, GuardLayer::new(rx, None))
    }

    fn status_of(response: &http::Response<Body>) -> Option<i32> {
        response.headers().get("grpc-status")?.to_str().ok()?.parse().ok()
    }

    /// A handler that panics while building its answer gets INTERNAL, not a reset.
    #[tokio::test]
    async fn a_panicking_handler_answers_internal() {
        let (_tx, layer) = layer();
        let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
            if std::hint::black_box(true) {
                panic!("deliberate test panic");
            }
            Ok::<_, std::convert::Infallible>(http::Response::new(Body::empty()))
        }));
        let response = svc.oneshot(http::Request::new(Body::empty())).await.unwrap();
        assert_eq!(status_of(&response), Some(tonic::Code::Internal as i32));
        // A panic in the synchronous part of `call` too.
        let (_tx, layer) = self::layer();
        let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| {
            if std::hint::black_box(true) {
                panic!("deliberate test panic in call");
            }
            std::future::ready(Ok::<_, std::convert::Infallible>(http::Response::new(
                Body::empty(),
            )))
        }));
        let response = svc.oneshot(http::Request::new(Body::empty())).await.unwrap();
        assert_eq!(status_of(&response), Some(tonic::Code::Internal as i32));
    }

    /// While the pool is saturated a kinplan call is shed at the door: the
    /// handler never runs (nor is its request decoded); StreamIk, whose
    /// messages are admitted one by one, and other services pass.
    #[tokio::test]
    async fn a_saturated_pool_sheds_at_the_door() {
        let (_tx, layer) = layer();
        let layer = layer.shedding_when(Arc::new(|| true));
        let reached = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let seen = reached.clone();
        let svc = layer.layer(tower::service_fn(move |_req: http::Request<Body>| {
            seen.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            std::future::ready(Ok::<_, std::convert::Infallible>(http::Response::new(
                Body::empty(),
            )))
        }));
        let call = |path: &str| {
            let mut request = http::Request::new(Body::empty());
            *request.uri_mut() = path.parse().unwrap();
            svc.clone().oneshot(request)
        };
        let shed = call("/kinplan.v1.RobotService/ForwardKinematics").await.unwrap();
        assert_eq!(status_of(&shed), Some(tonic::Code::ResourceExhausted as i32));
        assert_eq!(reached.load(std::sync::atomic::Ordering::SeqCst), 0);
        for passes in [
            "/kinplan.v1.KinematicsService/StreamIk",
            "/grpc.health.v1.Health/Check",
        ] {
            call(passes).await.unwrap();
        }
        assert_eq!(reached.load(std::sync::atomic::Ordering::SeqCst), 2);
    }

    /// With tokens configured, a saturated server sheds only authenticated
    /// calls: a caller without a valid token reaches the authentication
    /// layer and is told UNAUTHENTICATED, not RESOURCE_EXHAUSTED.
    #[tokio::test]
    async fn a_saturated_pool_sheds_only_authenticated_calls() {
        let (_tx, layer) = layer();
        let tokens = Tokens::new(["secret".to_string()]);
        let guard = layer
            .shedding_when(Arc::new(|| true))
            .authenticating_with(tokens.clone());
        let svc = guard.layer(
            crate::transport::auth::AuthLayer::new(tokens).layer(tower::service_fn(
                |_req: http::Request<Body>| {
                    std::future::ready(Ok::<_, std::convert::Infallible>(http::Response::new(
                        Body::empty(),
                    )))
                },
            )),
        );
        let call = |token: Option<&str>| {
            let mut request = http::Request::new(Body::empty());
            *request.uri_mut() = "/kinplan.v1.RobotService/ForwardKinematics".parse().unwrap();
            if let Some(t) = token {
                request
                    .headers_mut()
                    .insert(http::header::AUTHORIZATION, t.parse().unwrap());
            }
            svc.clone().oneshot(request)
        };
        for anonymous in [None, Some("Bearer wrong")] {
            let answer = call(anonymous).await.unwrap();
            assert_eq!(
                status_of(&answer),
                Some(tonic::Code::Unauthenticated as i32),
                "{anonymous:?}"
            );
        }
        let shed = call(Some("Bearer secret")).await.unwrap();
        assert_eq!(status_of(&shed), Some(tonic::Code::ResourceExhausted as i32));
    }

    struct PanickingBody;
    impl http_body::Body for PanickingBody {
        type Data = Bytes;
        type Error = Status;
        fn poll_frame(
            self: Pin<&mut Self>,
            _: &mut Context<'_>,
        ) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
            panic!("deliberate test panic in a stream")
        }
    }

    /// A reply stream that panics ends with INTERNAL trailers.
    #[tokio::test]
    async fn a_panicking_stream_ends_with_internal() {
        let (_tx, layer) = layer();
        let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
            Ok::<_, std::convert::Infallible>(http::Response::new(Body::new(PanickingBody)))
        }));
        let response = svc.oneshot(http::Request::new(Body::empty())).await.unwrap();
        let collected = response.into_body().collect().await.unwrap();
        let trailers = collected.trailers().cloned().unwrap();
        assert_eq!(trailers.get("grpc-status").unwrap(), "13");
    }

    struct Forever;
    impl http_body::Body for Forever {
        type Data = Bytes;
        type Error = Status;
        fn poll_frame(
            self: Pin<&mut Self>,
            _: &mut Context<'_>,
        ) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
            Poll::Pending
        }
    }

    /// Once shutdown cuts streams, an endless reply ends with UNAVAILABLE.
    #[tokio::test]
    async fn a_cut_ends_open_streams_with_unavailable() {
        let (tx, layer) = layer();
        let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
            Ok::<_, std::convert::Infallible>(http::Response::new(Body::new(Forever)))
        }));
        let response = svc.oneshot(http::Request::new(Body::empty())).await.unwrap();
        tokio::spawn(async move {
            tokio::time::sleep(Duration::from_millis(20)).await;
            tx.send(true).unwrap();
        });
        let collected = tokio::time::timeout(Duration::from_secs(5), response.into_body().collect())
            .await
            .expect("the cut ends the stream")
            .unwrap();
        assert_eq!(collected.trailers().unwrap().get("grpc-status").unwrap(), "14");
    }

    /// A deadline missed by the handler is DEADLINE_EXCEEDED from this layer,
    /// and a timeout too large for `Instant` means no deadline (no overflow).
    #[tokio::test]
    async fn deadlines_answer_deadline_exceeded_and_never_overflow() {
        let (_tx, layer) = layer();
        let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
            tokio::time::sleep(Duration::from_secs(30)).await;
            Ok::<_, std::convert::Infallible>(http::Response::new(Body::empty()))
        }));
        let mut request = http::Request::new(Body::empty());
        request
            .headers_mut()
            .insert("grpc-timeout", "20m".parse().unwrap());
        let response = svc.clone().oneshot(request).await.unwrap();
        assert_eq!(status_of(&response), Some(tonic::Code::DeadlineExceeded as i32));
        assert_eq!(deadline_after(Duration::MAX), None);
        assert_eq!(deadline_after(Duration::from_secs(u64::MAX)), None);
        let svc = layer.layer(tower::service_fn(|req: http::Request<Body>| async move {
            let deadline = req.extensions().get::<RequestDeadline>().copied();
            assert!(matches!(deadline, Some(RequestDeadline(None))));
            Ok::<_, std::convert::Infallible>(http::Response::new(Body::empty()))
        }));
        let mut request = http::Request::new(Body::empty());
        request
            .headers_mut()
            .insert("grpc-timeout", "18446744073709551615S".parse().unwrap());
        svc.oneshot(request).await.unwrap();
    }

    fn framed(message: &impl prost::Message) -> Bytes {
        let body = message.encode_to_vec();
        let mut out = vec![0u8];
        out.extend_from_slice(&(body.len() as u32).to_be_bytes());
        out.extend_from_slice(&body);
        Bytes::from(out)
    }

    /// A reply body of data frames then OK trailers.
    struct Reply(Vec<Bytes>, Option<http::HeaderMap>);
    impl http_body::Body for Reply {
        type Data = Bytes;
        type Error = Status;
        fn poll_frame(
            mut self: Pin<&mut Self>,
            _: &mut Context<'_>,
        ) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
            if !self.0.is_empty() {
                let data = self.0.remove(0);
                return Poll::Ready(Some(Ok(Frame::data(data))));
            }
            Poll::Ready(self.1.take().map(|t| Ok(Frame::trailers(t))))
        }
    }

    fn trailers(code: i32) -> http::HeaderMap {
        let mut t = http::HeaderMap::new();
        t.insert("grpc-status", code.to_string().parse().unwrap());
        t
    }

    async fn call_with(path: &str, frames: Vec<Bytes>, code: i32) -> http_body_util::Collected<Bytes> {
        let (_tx, layer) = layer();
        let reply = std::sync::Mutex::new(Some(Reply(frames, Some(trailers(code)))));
        let svc = layer.layer(tower::service_fn(move |_req: http::Request<Body>| {
            let body = reply.lock().unwrap().take().unwrap();
            async move { Ok::<_, std::convert::Infallible>(http::Response::new(Body::new(body))) }
        }));
        let request = http::Request::builder().uri(path).body(Body::empty()).unwrap();
        let response = svc.oneshot(request).await.unwrap();
        response.into_body().collect().await.unwrap()
    }

    /// The one reply check: an OK reply with a non-finite number becomes
    /// INTERNAL; a finite one passes unchanged, even split across frames.
    #[tokio::test]
    async fn non_finite_replies_become_internal() {
        use crate::pb;
        let path = "/kinplan.v1.RobotService/ForwardKinematics";
        let mut reply = pb::ForwardKinematicsResponse {
            tool_pose: Some(pb::Pose {
                position: Some(pb::Vec3 {
                    x: 1.0,
                    y: 2.0,
                    z: 3.0,
                }),
                orientation: None,
            }),
            ..Default::default()
        };
        let good = framed(&reply);
        let (a, b) = (good.slice(..7), good.slice(7..));
        let collected = call_with(path, vec![a, b], 0).await;
        assert_eq!(collected.trailers().unwrap().get("grpc-status").unwrap(), "0");
        assert_eq!(collected.to_bytes(), good);
        reply.tool_pose.as_mut().unwrap().position.as_mut().unwrap().z = f64::INFINITY;
        let collected = call_with(path, vec![framed(&reply)], 0).await;
        assert_eq!(collected.trailers().unwrap().get("grpc-status").unwrap(), "13");
        assert!(collected.to_bytes().is_empty());
    }

    /// A body that ends with OK trailers after `delay`.
    struct LateOk(Pin<Box<tokio::time::Sleep>>);
    impl http_body::Body for LateOk {
        type Data = Bytes;
        type Error = Status;
        fn poll_frame(
            mut self: Pin<&mut Self>,
            cx: &mut Context<'_>,
        ) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
            match self.0.as_mut().poll(cx) {
                Poll::Ready(()) => Poll::Ready(Some(Ok(Frame::trailers(trailers(0))))),
                Poll::Pending => Poll::Pending,
            }
        }
    }

    fn handled(text: &str, method: &str, code: &str) -> u64 {
        text.lines()
            .filter(|l| {
                l.starts_with("grpc_server_handled_total")
                    && l.contains(&format!("grpc_method=\"{method}\""))
                    && l.contains(&format!("grpc_code=\"{code}\""))
            })
            .filter_map(|l| l.rsplit(' ').next()?.parse::<u64>().ok())
            .sum()
    }

    /// Calls the client ends are recorded as the client saw them: a reply
    /// stream it resets before the call's timeout is CANCELLED, after it
    /// DEADLINE_EXCEEDED (its own timer ended the call); a unary call reset
    /// before its answer is counted, not lost; an answer written after the
    /// timeout keeps its code and is counted as late.
    #[test]
    fn calls_the_client_ends_are_recorded_as_it_saw_them() {
        let recorder = metrics_exporter_prometheus::PrometheusBuilder::new().build_recorder();
        let handle = recorder.handle();
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        let request = |method: &str, timeout: &str| {
            let mut request = http::Request::builder()
                .uri(format!("/kinplan.v1.KinematicsService/{method}"))
                .body(Body::empty())
                .unwrap();
            request
                .headers_mut()
                .insert("grpc-timeout", timeout.parse().unwrap());
            request
        };
        metrics::with_local_recorder(&recorder, || {
            runtime.block_on(async {
                let (_tx, layer) = layer();
                let streaming = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
                    Ok::<_, std::convert::Infallible>(http::Response::new(Body::new(Forever)))
                }));
                // Reset 10 ms into a 1 s call: the client cancelled.
                let response = streaming
                    .clone()
                    .oneshot(request("StreamIk", "1S"))
                    .await
                    .unwrap();
                let body = response.into_body();
                tokio::time::sleep(Duration::from_millis(10)).await;
                drop(body);
                // Reset once a 30 ms timeout has passed: the client's deadline.
                let response = streaming.oneshot(request("TrackPath", "30m")).await.unwrap();
                let body = response.into_body();
                tokio::time::sleep(Duration::from_millis(40)).await;
                drop(body);
                // OK written 40 ms into a 20 ms call: kept as sent, counted as late.
                let late = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
                    let body = LateOk(Box::pin(tokio::time::sleep(Duration::from_millis(40))));
                    Ok::<_, std::convert::Infallible>(http::Response::new(Body::new(body)))
                }));
                let response = late.oneshot(request("SolveIk", "20m")).await.unwrap();
                response.into_body().collect().await.unwrap();
                // A unary call reset before its answer.
                let slow = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
                    tokio::time::sleep(Duration::from_secs(30)).await;
                    Ok::<_, std::convert::Infallible>(http::Response::new(Body::empty()))
                }));
                let call = slow.oneshot(request("SolveIkBatch", "1S"));
                assert!(
                    tokio::time::timeout(Duration::from_millis(10), call)
                        .await
                        .is_err()
                );
            })
        });
        let text = handle.render();
        assert_eq!(handled(&text, "StreamIk", "CANCELLED"), 1, "{text}");
        assert_eq!(handled(&text, "TrackPath", "DEADLINE_EXCEEDED"), 1, "{text}");
        assert_eq!(handled(&text, "SolveIk", "OK"), 1, "{text}");
        assert!(
            text.lines()
                .any(|l| l.starts_with("kinplan_answers_after_deadline_total")
                    && l.contains("grpc_method=\"SolveIk\"")
                    && l.ends_with(" 1")),
            "{text}"
        );
        assert_eq!(handled(&text, "SolveIkBatch", "CANCELLED"), 1, "{text}");
    }

    /// Metrics count the status the client sees: a stream's trailers, and a
    /// deadline this layer answered.
    #[test]
    fn metrics_count_the_final_status() {
        let recorder = metrics_exporter_prometheus::PrometheusBuilder::new().build_recorder();
        let handle = recorder.handle();
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        metrics::with_local_recorder(&recorder, || {
            runtime.block_on(async {
                call_with("/kinplan.v1.KinematicsService/StreamIk", vec![], 3).await;
                let (_tx, layer) = layer();
                let svc = layer.layer(tower::service_fn(|_req: http::Request<Body>| async {
                    tokio::time::sleep(Duration::from_secs(30)).await;
                    Ok::<_, std::convert::Infallible>(http::Response::new(Body::empty()))
                }));
                let mut request = http::Request::builder()
                    .uri("/kinplan.v1.KinematicsService/SolveIkBatch")
                    .body(Body::empty())
                    .unwrap();
                request
                    .headers_mut()
                    .insert("grpc-timeout", "10m".parse().unwrap());
                svc.oneshot(request).await.unwrap();
            })
        });
        let text = handle.render();
        assert!(
            text.lines().any(|l| l.starts_with("grpc_server_handled_total")
                && l.contains("grpc_method=\"StreamIk\"")
                && l.contains("grpc_code=\"INVALID_ARGUMENT\"")),
            "{text}"
        );
        assert!(
            text.lines().any(|l| l.starts_with("grpc_server_handled_total")
                && l.contains("grpc_method=\"SolveIkBatch\"")
                && l.contains("grpc_code=\"DEADLINE_EXCEEDED\"")),
            "{text}"
        );
    }
}
