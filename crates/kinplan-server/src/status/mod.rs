//! Every domain error turned into `tonic::Status`, with `google.rpc.BadRequest`
//! details naming the offending field: the generic constructors here, one
//! submodule per domain room. Only this module turns domain field identifiers
//! into proto field paths.

use tonic::{Code, Status};
use tonic_types::{ErrorDetails, StatusExt};

pub mod collision;
pub mod explore;
pub mod ik;
pub mod linalg;
pub mod mobile;
pub mod nbv;
pub mod octree;
pub mod plan;
mod robot;
pub mod score;

pub use kinplan_proto::code_name;
pub use robot::robot_error;

/// INVALID_ARGUMENT naming `field`, with a BadRequest field violation.
pub fn invalid(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::InvalidArgument, field, description)
}

/// RESOURCE_EXHAUSTED naming `field`: a request that cannot fit the server's
/// limits, refused before any work.
pub fn too_large(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::ResourceExhausted, field, description)
}

/// NOT_FOUND naming `field`, with a BadRequest field violation.
pub fn not_found(field: impl Into<String>, description: impl Into<String>) -> Status {
    field_status(Code::NotFound, field, description)
}

/// Longest description a status carries: values echoed from a request are
/// clipped so a reply never outgrows the client's metadata limit.
pub const MAX_DESCRIPTION_CHARS: usize = 256;

/// At most `max` characters of `text`, with `…` when clipped.
pub fn clip(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

fn field_status(code: Code, field: impl Into<String>, description: impl Into<String>) -> Status {
    let field = clip(&field.into(), 64);
    let description = clip(&description.into(), MAX_DESCRIPTION_CHARS);
    let message = format!("{field}: {description}");
    Status::with_error_details(
        code,
        message,
        ErrorDetails::with_bad_request_violation(field, description),
    )
}
