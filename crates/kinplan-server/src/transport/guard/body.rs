//! The reply side of the guard: a reply body that records its final status,
//! checks every message for non-finite numbers, turns a panic while streaming
//! into INTERNAL trailers and ends with UNAVAILABLE when shutdown cuts it.

use std::future::Future;
use std::panic::AssertUnwindSafe;
use std::pin::Pin;
use std::task::{Context, Poll};

use bytes::Bytes;
use http_body::Frame;
use tokio::sync::watch;
use tonic::Status;
use tonic::body::Body;

use super::{CallLabels, non_finite_status, panic_status};
use crate::status::code_name;

/// Records a trailers-only answer now; a reply with a body is recorded when
/// its trailers (or its end) are seen.
pub(super) fn observe(
    response: http::Response<Body>,
    labels: CallLabels,
    cut: watch::Receiver<bool>,
    reply_type: Option<&'static str>,
) -> http::Response<Body> {
    if let Some(code) = response
        .headers()
        .get("grpc-status")
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<i32>().ok())
    {
        labels.record(code_name(code));
        return response;
    }
    let (parts, body) = response.into_parts();
    let cut = Box::pin(async move {
        let mut cut = cut;
        // An error means the server is gone: nothing left to cut.
        if cut.wait_for(|c| *c).await.is_err() {
            std::future::pending::<()>().await;
        }
    });
    let body = GuardedBody {
        inner: body,
        labels: Some(labels),
        cut,
        done: false,
        reply_type,
        pending: bytes::BytesMut::new(),
    };
    http::Response::from_parts(parts, Body::new(body))
}

/// A reply body that reports its final status to metrics, turns a panic while
/// streaming into INTERNAL trailers and ends with UNAVAILABLE when shutdown cuts
/// the streams still open.
struct GuardedBody {
    inner: Body,
    /// `Some` until the call is recorded.
    labels: Option<CallLabels>,
    cut: Pin<Box<dyn Future<Output = ()> + Send>>,
    done: bool,
    /// The reply's message type, when its numbers are checked ([`crate::transport::finite`]).
    reply_type: Option<&'static str>,
    /// Bytes of a reply message not yet complete (held until checked).
    pending: bytes::BytesMut,
}

impl GuardedBody {
    fn finish(&mut self, status: Status) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
        self.done = true;
        if let Some(labels) = self.labels.take() {
            labels.record(code_name(status.code() as i32));
        }
        let mut trailers = http::HeaderMap::new();
        let _ = status.add_header(&mut trailers);
        Poll::Ready(Some(Ok(Frame::trailers(trailers))))
    }
}

impl GuardedBody {
    /// Adds `data` to the pending bytes and releases the complete gRPC
    /// messages (5-byte prefix + body) whose numbers are all finite; `None`
    /// while no message is complete; INTERNAL for a reply that carries a
    /// non-finite number.
    fn checked(&mut self, reply_type: &'static str, data: Bytes) -> Result<Option<Bytes>, Status> {
        self.pending.extend_from_slice(&data);
        let mut complete = 0;
        while let Some(header) = self.pending.get(complete..complete + 5) {
            let len = u32::from_be_bytes([header[1], header[2], header[3], header[4]]) as usize;
            let Some(message) = self.pending.get(complete + 5..complete + 5 + len) else {
                break;
            };
            // Compressed messages (flag 1) are not inspected; kinplan sends none.
            if header[0] == 0
                && let Err(at) = crate::transport::finite::check(reply_type, message)
            {
                self.pending.clear();
                return Err(non_finite_status(self.labels.as_ref(), &at));
            }
            complete += 5 + len;
        }
        if complete == 0 {
            return Ok(None);
        }
        Ok(Some(self.pending.split_to(complete).freeze()))
    }
}

impl Drop for GuardedBody {
    fn drop(&mut self) {
        // Dropped before its trailers: the client went away.
        if let Some(labels) = self.labels.take() {
            labels.record_abandoned();
        }
    }
}

impl http_body::Body for GuardedBody {
    type Data = Bytes;
    type Error = Status;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Status>>> {
        if self.done {
            return Poll::Ready(None);
        }
        if self.cut.as_mut().poll(cx).is_ready() {
            return self.finish(Status::unavailable(
                "the server is shutting down; the stream was ended after the drain timeout",
            ));
        }
        loop {
            let this = &mut *self;
            let polled =
                std::panic::catch_unwind(AssertUnwindSafe(|| Pin::new(&mut this.inner).poll_frame(cx)));
            return match polled {
                Err(panic) => {
                    let labels = self
                        .labels
                        .clone()
                        .unwrap_or_else(|| CallLabels::for_path("/unknown/unknown"));
                    let status = panic_status(&labels, &*panic);
                    self.finish(status)
                }
                Ok(Poll::Pending) => Poll::Pending,
                Ok(Poll::Ready(None)) => {
                    self.done = true;
                    if let Some(labels) = self.labels.take() {
                        labels.record("OK");
                    }
                    Poll::Ready(None)
                }
                Ok(Poll::Ready(Some(Err(e)))) => {
                    self.done = true;
                    if let Some(labels) = self.labels.take() {
                        labels.record(code_name(e.code() as i32));
                    }
                    Poll::Ready(Some(Err(e)))
                }
                Ok(Poll::Ready(Some(Ok(frame)))) => {
                    let frame = match (frame.into_data(), self.reply_type) {
                        (Ok(data), Some(reply_type)) => match self.checked(reply_type, data) {
                            Ok(Some(ready)) => Frame::data(ready),
                            Ok(None) => continue, // a message not yet complete
                            Err(status) => return self.finish(status),
                        },
                        (Ok(data), None) => Frame::data(data),
                        (Err(frame), _) => frame,
                    };
                    if let Some(trailers) = frame.trailers_ref() {
                        self.done = true;
                        let code = trailers
                            .get("grpc-status")
                            .and_then(|v| v.to_str().ok())
                            .and_then(|v| v.parse::<i32>().ok())
                            .unwrap_or(0);
                        if let Some(labels) = self.labels.take() {
                            labels.record(code_name(code));
                        }
                    }
                    Poll::Ready(Some(Ok(frame)))
                }
            };
        }
    }

    fn is_end_stream(&self) -> bool {
        self.done
    }

    fn size_hint(&self) -> http_body::SizeHint {
        http_body::SizeHint::default()
    }
}
