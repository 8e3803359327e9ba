//! The one error type of the `octree` room: input that cannot be served.

/// Why an octree, scan or query was refused. Every parse failure names the byte
/// offset (into the buffer handed in) or the header field that was wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OctreeError {
    #[error("header: {reason} (at byte {offset})")]
    BadHeader { offset: usize, reason: String },
    #[error("tree type '{id}' is not supported for {format}")]
    UnsupportedTreeType { id: String, format: &'static str },
    #[error("resolution {0} m is outside [1e-4, 1e3] m")]
    BadResolution(f64),
    #[error("node data truncated at byte {offset}: {needed} more bytes needed")]
    Truncated { offset: usize, needed: usize },
    #[error("node data invalid at byte {offset}: {reason}")]
    BadNodeData { offset: usize, reason: &'static str },
    #[error("tree has more than {limit} nodes (limit), found at byte {offset}")]
    TooManyNodes { limit: usize, offset: usize },
    #[error("tree nests deeper than 16 levels at byte {offset}")]
    TooDeep { offset: usize },
    #[error("header size {declared} does not match the {actual} nodes read")]
    SizeMismatch { declared: u64, actual: u64 },
    #[error("{extra} bytes after the last node (at byte {offset})")]
    TrailingBytes { offset: usize, extra: usize },
    #[error("invalid parameter {field} = {value}: {reason}")]
    InvalidParam {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("coordinate {field} is outside the octree (|c| < 32768·resolution)")]
    OutOfBounds { field: &'static str },
    #[error("{field} is not finite")]
    NonFinite { field: &'static str },
    #[error("scan beams could cross {cells} cells, more than the limit {limit}")]
    ScanTooLarge { cells: u64, limit: u64 },
    #[error("scan updates at least {cells} distinct cells, more than the tree's limit of {limit} nodes")]
    ScanTooManyCells { cells: u64, limit: usize },
    #[error("the scan grew the tree past its limit of {limit} nodes")]
    TreeGrewTooLarge { limit: usize },
    #[error("{field}: expected {expected} values, got {got}")]
    WrongLength {
        field: &'static str,
        expected: usize,
        got: usize,
    },
}
