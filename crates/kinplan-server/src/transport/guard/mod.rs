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
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use tokio::sync::watch;
use tonic::Status;
use tonic::body::Body;

use crate::runtime::catch_unwind;
use crate::runtime::deadline::{RequestDeadline, deadline_after, effective_timeout, grpc_timeout};
use crate::status::code_name;

/// Histogram bucket bounds, seconds: 50 µs to 10 s.
pub const HANDLING_BUCKETS: &[f64] = &[
    0.00005, 0.0001, 0.00025, 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0,
    10.0,
];

#[derive(Clone)]
pub struct GuardLayer {
    /// Becomes true when shutdown's drain timeout has passed.
    cut: watch::Receiver<bool>,
    default_timeout: Option<Duration>,
}

impl GuardLayer {
    pub fn new(cut: watch::Receiver<bool>, default_timeout: Option<Duration>) -> Self {
        Self { cut, default_timeout }
    }
}

impl<S> tower::Layer<S> for GuardLayer {
    type Service = Guard<S>;
    fn layer(&self, inner: S) -> Self::Service {
        Guard {
            inner,
            cut: self.cut.clone(),
            default_timeout: self.default_timeout,
        }
    }
}

#[derive(Clone)]
pub struct Guard<S> {
    inner: S,
    cut: watch::Receiver<bool>,
    default_timeout: Option<Duration>,
}

type BoxFuture<T> = Pin<Box<dyn Future<Output = T> + Send>>;

/// What a finished call is recorded under.
#[derive(Clone)]
pub(crate) struct CallLabels {
    service: String,
    method: String,
    started: Instant,
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
        }
    }

    /// Records the call as finished with `code` (a gRPC code name).
    pub(crate) fn record(&self, code: &str) {
        let labels = [
            ("grpc_service", self.service.clone()),
            ("grpc_method", self.method.clone()),
        ];
        metrics::histogram!("grpc_server_handling_seconds", &labels)
            .record(self.started.elapsed().as_secs_f64());
        let mut with_code = labels.to_vec();
        with_code.push(("grpc_code", code.to_string()));
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
        let labels = CallLabels::for_path(request.uri().path());
        let header = grpc_timeout(request.headers());
        let deadline = effective_timeout(header, self.default_timeout).and_then(deadline_after);
        request.extensions_mut().insert(RequestDeadline(deadline));
        let cut = self.cut.clone();
        let reply_type = crate::transport::finite::reply_type(request.uri().path());
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
            let guarded = catch_unwind(future);
            let outcome = match deadline {
                Some(d) => tokio::time::timeout_at(d.into(), guarded).await.ok(),
                None => Some(guarded.await),
            };
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

mod body;
#[cfg(test)]
mod tests;

use body::observe;
