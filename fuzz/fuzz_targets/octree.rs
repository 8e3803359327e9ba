//! OctoMap .bt / .ot files and ROS message payloads → octree: errors, never
//! panics; a tree that parses writes back and parses again to the same tree.
#![no_main]

use kinplan_core::octree::{Octree, OctreeLimits};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = OctreeLimits { max_nodes: 200_000 };
    if let Ok(t) = Octree::read_bt(data, &limits) {
        let again = Octree::read_bt(&t.write_bt(), &limits).expect("a written tree parses");
        assert_eq!(again.write_bt(), t.write_bt());
    }
    let _ = Octree::read_ot(data, &limits);
    if let Some((&flags, rest)) = data.split_first() {
        let _ = Octree::from_message_data(flags & 1 == 1, "OcTree", 0.05, rest, &limits);
    }
});
