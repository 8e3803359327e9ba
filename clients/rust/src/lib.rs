//! Typed Rust client of the kinplan gRPC motion-planning service.
//!
//! nalgebra types in and out; a deadline on every call (10 s unless
//! [`Client::with_timeout`] says otherwise); `UNAVAILABLE` retried with
//! backoff (every kinplan call is idempotent); inline URDFs sent once and then
//! named by content hash, resent when a replica does not hold them; a
//! [`IkStream`] session for control loops. Every failure is an [`Error`] with
//! the gRPC code ([`Error::code`]); bad input is `INVALID_ARGUMENT` naming the
//! field.
//!
//! ```no_run
//! # async fn demo() -> kinplan_client::Result<()> {
//! use kinplan_client::{Client, IkOptions};
//! let client = Client::connect("127.0.0.1:50051").await?;
//! let robot = client.robot("ur5");
//! let pose = robot.fk(&[0.1, -1.2, 1.0, 0.3, 0.4, 0.5]).await?;
//! let answer = robot.ik(&pose, &[], &IkOptions::default()).await?;
//! assert!(answer.success);
//! # Ok(()) }
//! ```

mod client;
mod convert;
mod error;
mod ik;
mod plan;
mod robot;
mod stream;

/// The generated messages and client stubs of `proto/kinplan/v1` (the
/// `kinplan-proto` crate), for calls this crate does not wrap
/// (`Client::channel` connects them).
pub use kinplan_proto as pb;

pub use client::{Client, DEFAULT_RETRIES, DEFAULT_TIMEOUT};
pub use error::{Error, Result};
pub use ik::{IkAnswer, IkMethod, IkOptions, IkStatus, LinearSolver};
pub use plan::{Algorithm, Goal, Obstacle, Plan, PlanSettings, PlanStatus, Shape, StateCheck};
pub use robot::{Robot, RobotInfo};
pub use stream::IkStream;
pub use tonic::Code;
