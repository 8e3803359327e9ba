//! kinplan's gRPC contract, generated from `proto/kinplan/v1` (see
//! `build.rs`): every message, the client stubs (`*_service_client`), the
//! server traits (`*_service_server`) and [`FILE_DESCRIPTOR_SET`] for gRPC
//! reflection. The server, the Rust client and the fuzz targets all use these
//! types, so the contract is compiled once.
// The comments come from the .proto files, where `<limit>` is URDF, not HTML.
#![allow(missing_docs, clippy::all, clippy::pedantic, rustdoc::invalid_html_tags)]

tonic::include_proto!("kinplan.v1");

/// Encoded descriptor set of the kinplan protos, for gRPC reflection.
pub const FILE_DESCRIPTOR_SET: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/kinplan_descriptor.bin"));

/// The protobuf runtime the messages are built on (`prost::Message` encodes
/// and decodes them), for users that handle raw bytes.
pub use prost;

/// The canonical upper-case name of a gRPC status code (`DEADLINE_EXCEEDED`),
/// as the server's metrics and the load test's report label it.
pub fn code_name(code: i32) -> &'static str {
    const NAMES: [&str; 17] = [
        "OK",
        "CANCELLED",
        "UNKNOWN",
        "INVALID_ARGUMENT",
        "DEADLINE_EXCEEDED",
        "NOT_FOUND",
        "ALREADY_EXISTS",
        "PERMISSION_DENIED",
        "RESOURCE_EXHAUSTED",
        "FAILED_PRECONDITION",
        "ABORTED",
        "OUT_OF_RANGE",
        "UNIMPLEMENTED",
        "INTERNAL",
        "UNAVAILABLE",
        "DATA_LOSS",
        "UNAUTHENTICATED",
    ];
    usize::try_from(code)
        .ok()
        .and_then(|i| NAMES.get(i))
        .copied()
        .unwrap_or("UNKNOWN")
}
