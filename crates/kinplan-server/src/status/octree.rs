//! `octree` room errors into statuses: the request field holding the tree or
//! scan is named by the caller; size limits answer RESOURCE_EXHAUSTED.

use tonic::Status;

use super::{invalid, too_large};
use kinplan_core::octree::OctreeError;

/// INVALID_ARGUMENT (RESOURCE_EXHAUSTED for a tree or scan over the server's
/// limits) naming `field`, the request field the octree input came from.
pub fn octree_error(field: &str, e: OctreeError) -> Status {
    match e {
        OctreeError::TooManyNodes { .. }
        | OctreeError::ScanTooLarge { .. }
        | OctreeError::ScanTooManyCells { .. }
        | OctreeError::TreeGrewTooLarge { .. } => too_large(field, e.to_string()),
        _ => invalid(field, e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_resource_exhausted_and_bad_data_invalid() {
        let big = octree_error("tree", OctreeError::TooManyNodes { limit: 1, offset: 9 });
        assert_eq!(big.code(), tonic::Code::ResourceExhausted);
        assert!(big.message().starts_with("tree: "));
        let bad = octree_error("scan", OctreeError::BadResolution(f64::NAN));
        assert_eq!(bad.code(), tonic::Code::InvalidArgument);
        assert!(bad.message().starts_with("scan: "));
    }
}
