//! TLS, mutual TLS and bearer tokens against the real server, with the
//! throw-away certificates of `tests/certs/` (a test CA, a server
//! certificate for localhost / 127.0.0.1, a client certificate).

use std::path::PathBuf;

use kinplan_server::pb::{self, robot_service_client::RobotServiceClient};
use kinplan_server::{ServerConfig, TlsPem, Tokens};
use tonic::Code;
use tonic::metadata::MetadataValue;
use tonic::transport::{Certificate, Channel, ClientTlsConfig, Identity};
use tonic_health::pb::{HealthCheckRequest, health_client::HealthClient};

use crate::spawn;

fn cert(name: &str) -> Vec<u8> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/certs");
    std::fs::read(dir.join(name)).unwrap()
}

fn server_tls(mutual: bool) -> TlsPem {
    TlsPem {
        cert: cert("server.pem"),
        key: cert("server.key"),
        client_ca: mutual.then(|| cert("ca.pem")),
    }
}

async fn tls_channel(addr: std::net::SocketAddr, identity: bool) -> Result<Channel, tonic::transport::Error> {
    let mut tls = ClientTlsConfig::new()
        .ca_certificate(Certificate::from_pem(cert("ca.pem")))
        .domain_name("localhost");
    if identity {
        tls = tls.identity(Identity::from_pem(cert("client.pem"), cert("client.key")));
    }
    Channel::from_shared(format!("https://{addr}"))
        .unwrap()
        .tls_config(tls)?
        .connect()
        .await
}

async fn list(channel: Channel, token: Option<&str>) -> Result<pb::ListRobotsResponse, tonic::Status> {
    let mut req = tonic::Request::new(pb::ListRobotsRequest {});
    if let Some(t) = token {
        let v: MetadataValue<_> = format!("Bearer {t}").parse().unwrap();
        req.metadata_mut().insert("authorization", v);
    }
    RobotServiceClient::new(channel)
        .list_robots(req)
        .await
        .map(|r| r.into_inner())
}

#[tokio::test]
async fn tls_serves_clients_that_trust_the_ca_and_plaintext_clients_fail() {
    let (addr, _stop, _h) = spawn(ServerConfig {
        tls: Some(server_tls(false)),
        ..ServerConfig::default()
    })
    .await;
    let ch = tls_channel(addr, false).await.unwrap();
    assert!(!list(ch, None).await.unwrap().robots.is_empty());
    // a plaintext client does not get an answer from a TLS port
    let plain = Channel::from_shared(format!("http://{addr}"))
        .unwrap()
        .connect()
        .await;
    match plain {
        Err(_) => {}
        Ok(ch) => assert!(list(ch, None).await.is_err()),
    }
}

#[tokio::test]
async fn mutual_tls_needs_a_client_certificate_signed_by_the_ca() {
    let (addr, _stop, _h) = spawn(ServerConfig {
        tls: Some(server_tls(true)),
        ..ServerConfig::default()
    })
    .await;
    let with_cert = tls_channel(addr, true).await.unwrap();
    assert!(list(with_cert, None).await.is_ok());
    // without a certificate the handshake (or the first call) fails
    match tls_channel(addr, false).await {
        Err(_) => {}
        Ok(ch) => assert!(list(ch, None).await.is_err()),
    }
}

#[tokio::test]
async fn bearer_tokens_guard_every_service_but_health() {
    let (addr, _stop, _h) = spawn(ServerConfig {
        auth_tokens: Tokens::new(["s3cret-one".to_string(), "s3cret-two".to_string()]),
        ..ServerConfig::default()
    })
    .await;
    let ch = Channel::from_shared(format!("http://{addr}"))
        .unwrap()
        .connect()
        .await
        .unwrap();
    for token in [None, Some("wrong"), Some("s3cret-on"), Some("s3cret-one ")] {
        let err = list(ch.clone(), token).await.unwrap_err();
        assert_eq!(err.code(), Code::Unauthenticated, "{token:?}");
    }
    assert!(list(ch.clone(), Some("s3cret-one")).await.is_ok());
    assert!(list(ch.clone(), Some("s3cret-two")).await.is_ok());
    // health checks stay open for load balancers
    let health = HealthClient::new(ch)
        .check(HealthCheckRequest {
            service: String::new(),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(health.status, 1); // SERVING
}
