//! Optional bearer-token authentication: every call but health checks and
//! reflection must carry `authorization: Bearer <token>` with one of the
//! configured tokens, or it is answered UNAUTHENTICATED before it reaches a
//! service. Tokens are compared in constant time (every configured token,
//! every byte), so the answer's timing does not reveal a prefix.

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};

use tonic::Status;
use tonic::body::Body;

/// Paths that stay open: load balancers and tools need them without a token.
const OPEN_PREFIXES: [&str; 3] = [
    "/grpc.health.v1.Health/",
    "/grpc.reflection.v1.ServerReflection/",
    "/grpc.reflection.v1alpha.ServerReflection/",
];

/// Equality of two byte strings whose running time depends only on their
/// lengths (the token's length is not secret: every token is checked).
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    let mut diff = (a.len() ^ b.len()) as u64;
    for i in 0..a.len().max(b.len()) {
        let x = a.get(i).copied().unwrap_or(0);
        let y = b.get(i).copied().unwrap_or(0);
        diff |= u64::from(x ^ y);
    }
    diff == 0
}

/// The accepted tokens (at least one).
#[derive(Clone)]
pub struct Tokens(Arc<Vec<Vec<u8>>>);

impl std::fmt::Debug for Tokens {
    /// Never prints a token.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Tokens({} configured)", self.0.len())
    }
}

impl Tokens {
    /// `None` when no token is given (authentication off). Blank entries are
    /// ignored; surrounding white space is trimmed.
    pub fn new<I: IntoIterator<Item = String>>(tokens: I) -> Option<Self> {
        let list: Vec<Vec<u8>> = tokens
            .into_iter()
            .map(|t| t.trim().as_bytes().to_vec())
            .filter(|t| !t.is_empty())
            .collect();
        (!list.is_empty()).then(|| Tokens(Arc::new(list)))
    }

    /// True when `header` is `Bearer <token>` with an accepted token.
    fn accepts(&self, header: Option<&[u8]>) -> bool {
        let Some(token) = header.and_then(|h| h.strip_prefix(b"Bearer ")) else {
            return false;
        };
        // check every token so the time does not depend on which matched
        self.0.iter().fold(false, |ok, t| constant_time_eq(t, token) | ok)
    }
}

/// Whether `request` passes authentication: no tokens configured, an open
/// path, or a configured token. The guard asks this too, so that a caller
/// without a token is told UNAUTHENTICATED, never RESOURCE_EXHAUSTED.
pub(crate) fn admits<B>(tokens: Option<&Tokens>, request: &http::Request<B>) -> bool {
    let Some(tokens) = tokens else {
        return true;
    };
    let path = request.uri().path();
    if OPEN_PREFIXES.iter().any(|p| path.starts_with(p)) {
        return true;
    }
    let header = request
        .headers()
        .get(http::header::AUTHORIZATION)
        .map(|v| v.as_bytes());
    tokens.accepts(header)
}

/// The layer: pass-through when `tokens` is `None`.
#[derive(Clone)]
pub struct AuthLayer {
    tokens: Option<Tokens>,
}

impl AuthLayer {
    pub fn new(tokens: Option<Tokens>) -> Self {
        Self { tokens }
    }
}

impl<S> tower::Layer<S> for AuthLayer {
    type Service = Auth<S>;
    fn layer(&self, inner: S) -> Self::Service {
        Auth {
            inner,
            tokens: self.tokens.clone(),
        }
    }
}

#[derive(Clone)]
pub struct Auth<S> {
    inner: S,
    tokens: Option<Tokens>,
}

type BoxFuture<T> = Pin<Box<dyn Future<Output = T> + Send>>;

impl<S, B> tower::Service<http::Request<B>> for Auth<S>
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

    fn call(&mut self, request: http::Request<B>) -> Self::Future {
        if !admits(self.tokens.as_ref(), &request) {
            metrics::counter!("kinplan_unauthenticated_total").increment(1);
            let status = Status::unauthenticated(
                "this server requires `authorization: Bearer <token>` with a configured token",
            );
            return Box::pin(async move { Ok(status.into_http()) });
        }
        Box::pin(self.inner.call(request))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_an_exact_configured_token_after_bearer_is_accepted() {
        let t = Tokens::new(["alpha".to_string(), " beta \n".to_string(), String::new()]).unwrap();
        assert!(t.accepts(Some(b"Bearer alpha")));
        assert!(t.accepts(Some(b"Bearer beta")));
        for bad in [
            &b"Bearer alph"[..],
            b"Bearer alphaa",
            b"Bearer ",
            b"bearer alpha",
            b"alpha",
            b"Bearer  alpha",
            b"Basic alpha",
        ] {
            assert!(!t.accepts(Some(bad)), "{}", String::from_utf8_lossy(bad));
        }
        assert!(!t.accepts(None));
        assert!(Tokens::new([" ".to_string()]).is_none());
    }

    #[test]
    fn constant_time_equality_is_equality() {
        assert!(constant_time_eq(b"", b""));
        assert!(constant_time_eq(b"abc", b"abc"));
        assert!(!constant_time_eq(b"abc", b"abd"));
        assert!(!constant_time_eq(b"abc", b"ab"));
        assert!(!constant_time_eq(b"ab", b"abc"));
        // equal bytes followed by zeros are not equal strings
        assert!(!constant_time_eq(b"ab", b"ab\0"));
    }
}
