//! `kinplan health`: one `grpc.health.v1.Health/Check` call, for container
//! smoke tests and exec probes where native gRPC probes are not available.

use std::time::Duration;

use tonic::transport::Endpoint;
use tonic_health::pb::health_check_response::ServingStatus;
use tonic_health::pb::{HealthCheckRequest, health_client::HealthClient};

/// Options of `kinplan health`.
#[derive(clap::Args, Debug, Clone)]
pub struct HealthArgs {
    /// Server address: host:port, or a URI with http://.
    #[arg(long, default_value = "127.0.0.1:50051")]
    pub target: String,
    /// Service to ask about ("" for the whole server, or e.g.
    /// kinplan.v1.RobotService).
    #[arg(long, default_value = "")]
    pub service: String,
    /// Deadline of the call (connection included), seconds.
    #[arg(long, default_value_t = 1.0)]
    pub timeout: f64,
}

/// The serving status the server reports, e.g. "SERVING".
pub async fn check_health(args: &HealthArgs) -> Result<&'static str, String> {
    let timeout = Duration::try_from_secs_f64(args.timeout)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or("--timeout must be a positive number of seconds")?;
    let uri = if args.target.contains("://") {
        args.target.clone()
    } else {
        format!("http://{}", args.target)
    };
    let channel = Endpoint::from_shared(uri)
        .map_err(|e| format!("--target: {e}"))?
        .connect_timeout(timeout)
        .timeout(timeout)
        .connect()
        .await
        .map_err(|e| format!("cannot connect to {}: {e}", args.target))?;
    let reply = HealthClient::new(channel)
        .check(HealthCheckRequest {
            service: args.service.clone(),
        })
        .await
        .map_err(|s| format!("{:?}: {}", s.code(), s.message()))?;
    Ok(match ServingStatus::try_from(reply.into_inner().status) {
        Ok(ServingStatus::Serving) => "SERVING",
        Ok(ServingStatus::NotServing) => "NOT_SERVING",
        Ok(ServingStatus::ServiceUnknown) => "SERVICE_UNKNOWN",
        _ => "UNKNOWN",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinplan_server::{ServerConfig, serve};

    #[tokio::test]
    async fn health_reports_serving_and_unknown_services() {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        let addr = listener.local_addr().unwrap();
        let (_stop, stopped) = tokio::sync::oneshot::channel::<()>();
        tokio::spawn(serve(ServerConfig::default(), listener, async {
            let _ = stopped.await;
        }));
        let mut args = HealthArgs {
            target: addr.to_string(),
            service: String::new(),
            timeout: 2.0,
        };
        assert_eq!(check_health(&args).await.unwrap(), "SERVING");
        args.service = "kinplan.v1.RobotService".into();
        assert_eq!(check_health(&args).await.unwrap(), "SERVING");
        args.service = "no.such.Service".into();
        let err = check_health(&args).await.unwrap_err();
        assert!(err.starts_with("NotFound"), "{err}");
    }
}
