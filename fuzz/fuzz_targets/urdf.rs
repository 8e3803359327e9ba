//! URDF text → chain, with the server's limits: errors, never panics.
#![no_main]

use kinplan_core::robot::{ChainSpec, UrdfLimits, parse_chain};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_chain(text, &ChainSpec::default(), UrdfLimits::default());
    }
});
