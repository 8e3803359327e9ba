//! The gRPC edge: one thin adapter per service that validates and converts
//! proto messages into domain values, runs the work and maps errors to
//! `tonic::Status`. Only this layer (and `main.rs`) knows about tonic.

/// The generated contract (the `kinplan-proto` crate).
pub use kinplan_proto as pb;

mod auth;
mod collision_models;
mod compute;
mod convert;
mod exploration;
mod exploration_convert;
mod explore;
mod explore_convert;
mod finite;
pub mod fuzzing;
mod guard;
mod inprocess;
mod io_threads;
mod kinematics;
mod mobile;
mod models;
mod planning;
mod planning_convert;
mod priority;
mod robot;
mod scene;
mod scoring;
mod server;
mod status;

pub use auth::Tokens;
pub use compute::{Budget, Compute};
pub use guard::HANDLING_BUCKETS;
pub use inprocess::{InProcess, ResponseStream};
pub use models::ModelStore;
pub use server::{ServerConfig, TlsPem, serve};
pub use status::code_name;
