use super::*;
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

struct PanickingBody;
impl http_body::Body for PanickingBody {
    type Data = Bytes;
    type Error = Status;
    fn poll_frame(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
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
    fn poll_frame(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
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
