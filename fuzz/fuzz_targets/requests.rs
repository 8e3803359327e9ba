//! Request bytes → proto messages (the `kinplan-proto` contract) → the
//! server's conversions to domain values (planning, scenes with octrees,
//! next-best-view, exploration).
#![no_main]

use kinplan_proto::prost::Message;
use kinplan_proto::{ExploreRequest, NextBestViewRequest, PlanRequest};
use kinplan_server::api::fuzzing;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = PlanRequest::decode(data) {
        fuzzing::convert_plan(&r);
    }
    if let Ok(r) = ExploreRequest::decode(data) {
        fuzzing::convert_explore(&r);
    }
    if let Ok(r) = NextBestViewRequest::decode(data) {
        fuzzing::convert_nbv(&r);
    }
});
