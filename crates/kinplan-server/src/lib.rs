//! kinplan-server: the gRPC service over the `kinplan-core` domain crate.
//!
//! `service` holds one thin adapter per gRPC service (validate and convert
//! proto → domain, run the work on the CPU pool, map domain errors to
//! `tonic::Status`); the `kinplan` binary (`main.rs`) runs it, and
//! `loadtest` drives a running server at high rate (`kinplan loadtest`). Only this crate
//! knows about tonic, prost and tokio.

pub mod loadtest;
pub mod service;
