//! kinplan-server: the gRPC service over the `kinplan-core` domain crate.
//!
//! Four rooms, each using only the ones before it:
//!
//! - [`status`]: every domain error turned into `tonic::Status` (the one
//!   mapping, with field violations naming the request field);
//! - [`runtime`]: what the handlers run on — the shared context, deadlines,
//!   the CPU pool with admission control, the model and collision caches;
//! - [`api`]: one handler room per gRPC service, `mod.rs` beside its
//!   `convert.rs` (proto ↔ domain);
//! - [`transport`]: how calls reach the handlers — server assembly, I/O
//!   threads, the guard layer, authentication, the in-process backend.
//!
//! `src/README.md` maps each capability to its handler, its conversion and
//! its domain code. The `kinplan` binary (`main.rs`, with `health.rs` for
//! `kinplan health`) runs the server. Only
//! this crate (with `kinplan-proto`) knows about tonic, prost and tokio.

pub mod api;
pub mod runtime;
pub mod status;
pub mod transport;

/// The generated contract (the `kinplan-proto` crate).
pub use kinplan_proto as pb;
pub use runtime::{Budget, Compute, ModelStore};
pub use status::code_name;
pub use transport::{HANDLING_BUCKETS, InProcess, ResponseStream, ServerConfig, TlsPem, Tokens, serve};
