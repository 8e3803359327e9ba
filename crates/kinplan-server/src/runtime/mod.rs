//! What the handlers run on: the shared context, deadlines, the CPU pool with
//! admission control, and the model caches. Uses no handler and no transport.

pub mod collision_models;
pub mod compute;
pub mod deadline;
pub mod memory;
pub mod models;
pub mod priority;
pub mod request_numbers;
mod shared;
pub mod wire;

pub use compute::{Budget, Compute, catch_unwind};
pub use models::ModelStore;
pub use shared::Shared;
