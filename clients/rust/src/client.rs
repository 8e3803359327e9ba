//! The connection: one HTTP/2 channel (or a balanced set), a default deadline
//! for every call, and retries of `UNAVAILABLE` with exponential backoff.

use std::future::Future;
use std::time::{Duration, Instant};

use tonic::transport::{Channel, Endpoint};

use crate::error::{Error, Result};
use crate::pb;
use crate::robot::{Robot, RobotSpec};

/// Default deadline of a call.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(10);
/// Default number of retries of a call answered `UNAVAILABLE`.
pub const DEFAULT_RETRIES: u32 = 3;
/// Backoff before the first retry; doubled for each further one.
const FIRST_BACKOFF: Duration = Duration::from_millis(20);

/// A connection to one kinplan server or to several identical replicas.
///
/// Cheap to clone (clones share the channel). Every kinplan call is
/// idempotent, so a call answered `UNAVAILABLE` (a replica restarting or
/// draining) is retried up to [`Client::with_retries`] times, waiting 20, 40,
/// 80 … ms, as long as its deadline allows.
#[derive(Clone, Debug)]
pub struct Client {
    channel: Channel,
    timeout: Duration,
    retries: u32,
}

/// `host:port`, `http://host:port` or `[::1]:port`; a missing port is 50051.
fn endpoint(address: &str) -> Result<Endpoint> {
    let connect_error = |reason: String| Error::Connect {
        address: address.to_owned(),
        reason,
    };
    if address.starts_with("https://") {
        return Err(connect_error(
            "https:// needs TLS, which this client does not configure; use http:// or host:port".into(),
        ));
    }
    let bare = address.strip_prefix("http://").unwrap_or(address);
    let has_port = bare.rsplit_once(':').is_some_and(|(host, port)| {
        port.chars().all(|c| c.is_ascii_digit())
            && !port.is_empty()
            && (!host.contains(':') || host.ends_with(']'))
    });
    let uri = if has_port {
        format!("http://{bare}")
    } else {
        format!("http://{bare}:50051")
    };
    Ok(Endpoint::from_shared(uri)
        .map_err(|e| connect_error(e.to_string()))?
        .tcp_nodelay(true)
        .http2_keep_alive_interval(Duration::from_secs(30))
        .keep_alive_while_idle(true)
        .connect_timeout(Duration::from_secs(5)))
}

impl Client {
    /// Connects to one server, failing at once when it cannot be reached.
    pub async fn connect(address: &str) -> Result<Client> {
        let channel = endpoint(address)?.connect().await.map_err(|e| Error::Connect {
            address: address.to_owned(),
            reason: source_chain(&e),
        })?;
        Ok(Client::from_channel(channel))
    }

    /// Balances calls over identical replicas (connections made lazily, a
    /// replica that goes away is skipped; its calls are retried elsewhere).
    pub fn connect_balanced<'a>(addresses: impl IntoIterator<Item = &'a str>) -> Result<Client> {
        let endpoints = addresses.into_iter().map(endpoint).collect::<Result<Vec<_>>>()?;
        if endpoints.is_empty() {
            return Err(Error::Connect {
                address: String::new(),
                reason: "no address given".into(),
            });
        }
        Ok(Client::from_channel(Channel::balance_list(endpoints.into_iter())))
    }

    /// Wraps a channel made elsewhere (TLS, a custom connector).
    pub fn from_channel(channel: Channel) -> Client {
        Client {
            channel,
            timeout: DEFAULT_TIMEOUT,
            retries: DEFAULT_RETRIES,
        }
    }

    /// The same connection with another default deadline.
    pub fn with_timeout(&self, timeout: Duration) -> Client {
        Client {
            timeout,
            ..self.clone()
        }
    }

    /// The same connection with another retry count (0: no retries).
    pub fn with_retries(&self, retries: u32) -> Client {
        Client {
            retries,
            ..self.clone()
        }
    }

    /// The deadline of each call.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// The channel, to call services this crate does not wrap with the
    /// generated stubs in [`crate::pb`].
    pub fn channel(&self) -> Channel {
        self.channel.clone()
    }

    /// A built-in robot by name (see [`Client::list_robots`]), its default chain.
    pub fn robot(&self, name: &str) -> Robot {
        Robot::new(self.clone(), RobotSpec::builtin(name))
    }

    /// A robot from URDF text sent by this client. The text is sent once; later
    /// calls name the content hash the server returns.
    pub fn robot_from_urdf(&self, urdf: impl Into<String>) -> Robot {
        Robot::new(self.clone(), RobotSpec::urdf(urdf.into(), Vec::new()))
    }

    /// A robot from URDF text and the collision mesh files it names, each
    /// keyed by the URI exactly as the URDF writes it (`package://…`, a
    /// relative path) with the file's bytes (STL or OBJ). The server never
    /// opens a file: the bytes travel with the model, once, and are hashed
    /// into its model id.
    pub fn robot_from_urdf_with_meshes(
        &self,
        urdf: impl Into<String>,
        meshes: impl IntoIterator<Item = (String, Vec<u8>)>,
    ) -> Robot {
        Robot::new(
            self.clone(),
            RobotSpec::urdf(urdf.into(), meshes.into_iter().collect()),
        )
    }

    /// Names of the built-in robots.
    pub async fn list_robots(&self) -> Result<Vec<String>> {
        let reply = self
            .unary(pb::ListRobotsRequest {}, |channel, request| async move {
                pb::robot_service_client::RobotServiceClient::new(channel)
                    .list_robots(request)
                    .await
            })
            .await?;
        Ok(reply.robots.into_iter().map(|r| r.name).collect())
    }

    /// A unary call with this client's deadline and retry policy. `call` sends
    /// one request on the channel (it is called again for each retry).
    pub(crate) async fn unary<Req, Resp, F, Fut>(&self, message: Req, call: F) -> Result<Resp>
    where
        Req: Clone,
        F: Fn(Channel, tonic::Request<Req>) -> Fut,
        Fut: Future<Output = std::result::Result<tonic::Response<Resp>, tonic::Status>>,
    {
        let deadline = Instant::now() + self.timeout;
        let mut backoff = FIRST_BACKOFF;
        let mut retries_left = self.retries;
        loop {
            let mut request = tonic::Request::new(message.clone());
            request.set_timeout(deadline.saturating_duration_since(Instant::now()));
            let status = match call(self.channel.clone(), request).await {
                Ok(reply) => return Ok(reply.into_inner()),
                Err(status) => status,
            };
            let retry = retryable(&status) && retries_left > 0 && Instant::now() + backoff < deadline;
            if !retry {
                return Err(Error::from(status));
            }
            tokio::time::sleep(backoff).await;
            retries_left -= 1;
            backoff *= 2;
        }
    }
}

/// Whether a failed call may be sent again: UNAVAILABLE (no replica took it),
/// or a transport failure under a call in flight (its connection broke: tonic
/// answers UNKNOWN "transport error"). Every kinplan call is idempotent, so a
/// retry cannot do the work twice in a way that matters.
fn retryable(status: &tonic::Status) -> bool {
    match status.code() {
        tonic::Code::Unavailable => true,
        tonic::Code::Unknown => status.message().starts_with("transport error"),
        _ => false,
    }
}

/// An error with its causes, for connection failures whose top line says little.
fn source_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::endpoint;

    #[test]
    fn addresses_get_a_scheme_and_a_default_port() {
        let uri = |a: &str| endpoint(a).unwrap().uri().to_string();
        assert_eq!(uri("localhost"), "http://localhost:50051/");
        assert_eq!(uri("127.0.0.1:7000"), "http://127.0.0.1:7000/");
        assert_eq!(uri("http://10.0.0.2:9"), "http://10.0.0.2:9/");
        assert_eq!(uri("[::1]:8080"), "http://[::1]:8080/");
        assert_eq!(uri("[::1]"), "http://[::1]:50051/");
        assert!(endpoint("https://example.org").is_err());
    }
}
