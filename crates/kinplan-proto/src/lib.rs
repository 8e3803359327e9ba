//! kinplan's gRPC contract, generated from `proto/kinplan/v1` (see
//! `build.rs`): every message, the client stubs (`*_service_client`), the
//! server traits (`*_service_server`) and [`FILE_DESCRIPTOR_SET`] for gRPC
//! reflection. The server, the Rust client and the fuzz targets all use these
//! types, so the contract is compiled once.
#![allow(missing_docs, clippy::all, clippy::pedantic)]

tonic::include_proto!("kinplan.v1");

/// Encoded descriptor set of the kinplan protos, for gRPC reflection.
pub const FILE_DESCRIPTOR_SET: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/kinplan_descriptor.bin"));

/// The protobuf runtime the messages are built on (`prost::Message` encodes
/// and decodes them), for users that handle raw bytes.
pub use prost;
