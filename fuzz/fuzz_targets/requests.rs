//! Request bytes → proto messages → the service's conversions to domain
//! values (planning, scenes with octrees, next-best-view, exploration).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    kinplan_server::service::fuzzing::convert_requests(data);
});
