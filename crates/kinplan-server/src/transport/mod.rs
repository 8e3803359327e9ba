//! How calls reach the handlers: the server assembly (listener, TLS, health,
//! reflection, graceful shutdown), the I/O threads, the guard layer
//! (deadlines, panics, metrics, non-finite replies), bearer-token
//! authentication and the in-process backend. Uses `api` and `runtime`;
//! neither uses it.

mod auth;
mod finite;
mod guard;
mod inprocess;
mod io_threads;
mod server;

pub use auth::Tokens;
pub use guard::HANDLING_BUCKETS;
pub use inprocess::{InProcess, ResponseStream};
pub use server::{ServerConfig, TlsPem, serve};
