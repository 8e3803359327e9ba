//! The generated messages and client stubs of `proto/kinplan/v1` (see `build.rs`),
//! for calls this crate does not wrap (`Client::channel` connects them).
#![allow(missing_docs, clippy::all, clippy::pedantic)]

tonic::include_proto!("kinplan.v1");
