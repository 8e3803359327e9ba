//! Code generated from `proto/kinplan/v1` (see `build.rs`).
#![allow(missing_docs, clippy::all, clippy::pedantic)]

tonic::include_proto!("kinplan.v1");

/// Encoded descriptor set of the kinplan protos, for gRPC reflection.
pub const FILE_DESCRIPTOR_SET: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/kinplan_descriptor.bin"));
