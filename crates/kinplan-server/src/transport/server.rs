//! Assembles the gRPC server: kinplan services, health, reflection, the guard
//! layer (deadlines, panics, metrics), message limits and graceful shutdown.

use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio_stream::StreamExt;
use tonic::transport::server::TcpIncoming;
use tonic::transport::{Certificate, Identity, Server, ServerTlsConfig};
use tonic_health::ServingStatus;

use crate::api::Apis;
use crate::pb::exploration_service_server::ExplorationServiceServer;
use crate::pb::kinematics_service_server::KinematicsServiceServer;
use crate::pb::mobile_service_server::MobileServiceServer;
use crate::pb::planning_service_server::PlanningServiceServer;
use crate::pb::{
    self, robot_service_server::RobotServiceServer, scoring_service_server::ScoringServiceServer,
};
use crate::runtime::collision_models::CollisionModels;
use crate::runtime::{Compute, ModelStore, Shared};
use crate::transport::auth::{AuthLayer, Tokens};
use crate::transport::guard::GuardLayer;
use crate::transport::io_threads::{Connections, IoThreads, ServeFn, StopSignal, thread_count};
use kinplan_core::robot::UrdfLimits;

/// Everything the server can be told; `Default` is what `kinplan serve`
/// uses with no flags.
#[derive(Debug, Clone)]
pub struct ServerConfig {
    /// CPU pool threads; 0 means one per core.
    pub cpu_threads: usize,
    /// Nice value of the CPU pool's threads (0–19; default 10, below the
    /// I/O threads; see `runtime/priority.rs`).
    pub cpu_nice: i32,
    /// I/O threads, each with its own single-threaded async runtime serving
    /// the connections handed to it round robin; 0 means one per core.
    pub io_threads: usize,
    /// Largest request or response message, bytes.
    pub max_message_bytes: usize,
    /// Deadline for requests that bring none.
    pub request_timeout: Option<Duration>,
    /// Requests in the server at once; more are shed with RESOURCE_EXHAUSTED.
    pub concurrency_limit: usize,
    /// Largest inline URDF, bytes.
    pub max_urdf_bytes: usize,
    /// Parsed models kept in the cache.
    pub model_cache_entries: usize,
    /// Random states sampled for a robot's allowed-collision matrix (once
    /// per model; MoveIt's setup assistant samples 10,000).
    pub acm_samples: usize,
    /// Bytes of URDF text and parsed models the cache may hold.
    pub model_cache_bytes: usize,
    /// Time between reporting NOT_SERVING and closing the listener on
    /// shutdown, so load balancers stop sending new calls first.
    pub drain_delay: Duration,
    /// After the listener closes, how long calls in flight may finish; then
    /// open streams (`Health.Watch`, `StreamIk`) end with UNAVAILABLE.
    pub drain_timeout: Duration,
    /// A `StreamIk` stream that sends no message for this long is ended
    /// (UNAVAILABLE), so idle streams cannot pile up.
    pub stream_idle_timeout: Duration,
    /// Counts jobs running on the CPU pool (tests watch it to see work stop).
    pub running_jobs: Arc<AtomicUsize>,
    /// Accepted bearer tokens; `None`: no authentication (health checks and
    /// reflection are always open).
    pub auth_tokens: Option<Tokens>,
    /// Certificate, key and optional client CA (PEM); `None`: plaintext.
    pub tls: Option<TlsPem>,
    /// Run each computation on the thread that handles the call instead of
    /// the CPU pool: for the in-process backend, whose caller blocks anyway
    /// and would otherwise pay two thread hand-offs per call. Never for a
    /// network server (it would stall the async runtime).
    pub inline_compute: bool,
}

/// The server's TLS identity (PEM bytes). With `client_ca`, clients must
/// present a certificate that CA signed (mutual TLS).
#[derive(Clone)]
pub struct TlsPem {
    pub cert: Vec<u8>,
    pub key: Vec<u8>,
    pub client_ca: Option<Vec<u8>>,
}

impl std::fmt::Debug for TlsPem {
    /// Never prints the key.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TlsPem")
            .field("cert_bytes", &self.cert.len())
            .field("key", &"<redacted>")
            .field("mutual", &self.client_ca.is_some())
            .finish()
    }
}

impl Default for ServerConfig {
    fn default() -> Self {
        Self {
            cpu_threads: 0,
            io_threads: 0,
            cpu_nice: crate::runtime::priority::CPU_POOL_NICE,
            max_message_bytes: 16 * 1024 * 1024,
            request_timeout: Some(Duration::from_secs(60)),
            concurrency_limit: 256,
            max_urdf_bytes: 2 * 1024 * 1024,
            model_cache_entries: 256,
            acm_samples: 10_000,
            model_cache_bytes: 256 * 1024 * 1024,
            drain_delay: Duration::ZERO,
            drain_timeout: Duration::from_secs(10),
            stream_idle_timeout: Duration::from_secs(60),
            running_jobs: Arc::default(),
            auth_tokens: None,
            tls: None,
            inline_compute: false,
        }
    }
}

type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// Serves on `listener` until `shutdown` resolves, then reports NOT_SERVING,
/// waits `drain_delay`, stops accepting and finishes the calls in flight.
pub async fn serve(
    config: ServerConfig,
    listener: TcpListener,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> Result<(), BoxError> {
    let shared = kinplan_shared(&config);
    let (routes, services) = kinplan_routes(&shared, &config);
    let compute = shared.compute.clone();
    // the contract's schemas (request admission, finite replies), built once
    // before serving instead of on the first call
    tokio::task::spawn_blocking(|| {
        crate::runtime::request_numbers::prepare();
        crate::transport::finite::prepare();
    })
    .await?;
    let (health, health_service) = tonic_health::server::health_reporter();
    for name in services {
        health.set_service_status(name, ServingStatus::Serving).await;
    }
    let reflection_v1 = tonic_reflection::server::Builder::configure()
        .register_encoded_file_descriptor_set(pb::FILE_DESCRIPTOR_SET)
        .register_encoded_file_descriptor_set(tonic_health::pb::FILE_DESCRIPTOR_SET)
        .build_v1()?;
    let reflection_v1alpha = tonic_reflection::server::Builder::configure()
        .register_encoded_file_descriptor_set(pb::FILE_DESCRIPTOR_SET)
        .register_encoded_file_descriptor_set(tonic_health::pb::FILE_DESCRIPTOR_SET)
        .build_v1alpha()?;

    let drain_delay = config.drain_delay;
    let drain_timeout = config.drain_timeout;
    // `cut` turns true when the drain timeout has passed: the guard then ends
    // every open reply stream with UNAVAILABLE, so shutdown cannot hang on them.
    let (cut_tx, cut_rx) = tokio::sync::watch::channel(false);
    let (closed_tx, closed_rx) = tokio::sync::oneshot::channel::<()>();
    let drain = async move {
        shutdown.await;
        tracing::info!(?drain_delay, "shutting down: reporting NOT_SERVING");
        for name in services.into_iter().chain([""]) {
            health.set_service_status(name, ServingStatus::NotServing).await;
        }
        tokio::time::sleep(drain_delay).await;
        tracing::info!(?drain_timeout, "closing the listener; finishing calls in flight");
        let _ = closed_tx.send(());
    };
    let cutter = async move {
        if closed_rx.await.is_err() {
            return std::future::pending().await;
        }
        tokio::time::sleep(drain_timeout).await;
        tracing::warn!("drain timeout passed: ending open streams with UNAVAILABLE");
        let _ = cut_tx.send(true);
        // A last resort if a connection still does not close.
        tokio::time::sleep(Duration::from_secs(2)).await;
        tracing::warn!("connections still open after the drain timeout; stopping anyway");
    };
    tracing::info!(addr = ?listener.local_addr().ok(), "kinplan serving");
    let mut builder = Server::builder();
    if let Some(tls) = &config.tls {
        let mut tls_config = ServerTlsConfig::new().identity(Identity::from_pem(&tls.cert, &tls.key));
        if let Some(ca) = &tls.client_ca {
            tls_config = tls_config.client_ca_root(Certificate::from_pem(ca));
        }
        builder = builder.tls_config(tls_config)?;
    }
    let router = builder
        .layer(
            GuardLayer::new(cut_rx, config.request_timeout)
                .shedding_when(Arc::new(move || compute.saturated()))
                .authenticating_with(config.auth_tokens.clone()),
        )
        .layer(AuthLayer::new(config.auth_tokens.clone()))
        .add_routes(routes)
        .add_service(health_service)
        .add_service(reflection_v1)
        .add_service(reflection_v1alpha);
    let serve_one: Arc<ServeFn> = Arc::new(move |connections: Connections, stop: StopSignal| {
        let router = router.clone();
        Box::pin(async move { router.serve_with_incoming_shutdown(connections, stop).await })
    });
    let mut threads = IoThreads::start(thread_count(config.io_threads), serve_one)?;
    // Small replies must not wait for Nagle + delayed ACK (40 ms on loopback).
    let mut incoming = TcpIncoming::from(listener)
        .with_nodelay(Some(true))
        .with_keepalive(Some(Duration::from_secs(60)));
    tokio::pin!(drain);
    loop {
        tokio::select! {
            () = &mut drain => break,
            failed = threads.finished() => return failed,
            accepted = incoming.next() => match accepted {
                Some(Ok(connection)) => threads.dispatch(connection),
                Some(Err(e)) => tracing::debug!("error accepting a connection: {e}"),
                None => break,
            },
        }
    }
    // Closes the listening socket at once: new clients are refused, not left hanging.
    drop(incoming);
    threads.stop();
    tokio::select! {
        served = threads.finished() => served?,
        () = cutter => {}
    }
    Ok(())
}

/// The state every kinplan service adapter shares (model cache, CPU pool,
/// collision models), built from `config`. `serve` puts the services over
/// it behind a listener; [`crate::transport::InProcess`] calls them without one.
pub(crate) fn kinplan_shared(config: &ServerConfig) -> Shared {
    let mut compute = Compute::with_nice(
        config.cpu_threads,
        config.concurrency_limit,
        config.request_timeout,
        config.cpu_nice,
    )
    .with_running_counter(config.running_jobs.clone());
    compute.stream_idle_timeout = config.stream_idle_timeout;
    compute.inline = config.inline_compute;
    Shared {
        models: Arc::new(ModelStore::new(
            UrdfLimits {
                max_bytes: config.max_urdf_bytes,
                ..UrdfLimits::default()
            },
            config.model_cache_entries,
            config.model_cache_bytes,
        )),
        compute: Arc::new(compute),
        collision: Arc::new(CollisionModels::new(
            config.model_cache_entries,
            config.acm_samples,
        )),
    }
}

/// The kinplan services as routes, with the message size limits, and their names.
pub(crate) fn kinplan_routes(
    shared: &Shared,
    config: &ServerConfig,
) -> (tonic::service::Routes, [&'static str; 6]) {
    let apis = Apis::new(shared);
    let limit = config.max_message_bytes;
    // Each kinplan service: its adapter, with the message size limits.
    macro_rules! service {
        ($server:ident, $api:expr) => {
            $server::new($api)
                .max_decoding_message_size(limit)
                .max_encoding_message_size(limit)
        };
    }
    let robot = service!(RobotServiceServer, apis.robot);
    let scoring = service!(ScoringServiceServer, apis.scoring);
    let mobile = service!(MobileServiceServer, apis.mobile);
    let kinematics = service!(KinematicsServiceServer, apis.kinematics);
    let planning = service!(PlanningServiceServer, apis.planning);
    let exploration = service!(ExplorationServiceServer, apis.exploration);
    let names = [
        name_of(&robot),
        name_of(&scoring),
        name_of(&mobile),
        name_of(&kinematics),
        name_of(&planning),
        name_of(&exploration),
    ];
    let routes = tonic::service::Routes::new(robot)
        .add_service(scoring)
        .add_service(mobile)
        .add_service(kinematics)
        .add_service(planning)
        .add_service(exploration);
    (routes, names)
}

fn name_of<S: tonic::server::NamedService>(_: &S) -> &'static str {
    S::NAME
}
