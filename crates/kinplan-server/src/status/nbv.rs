//! `nbv` room errors into statuses: a refused next-best-view request names the
//! request message the refused parameters came from (`options`, `camera`).

use tonic::Status;

use super::invalid;
use kinplan_core::nbv::NbvError;

/// INVALID_ARGUMENT naming `field`.
pub fn nbv_error(field: &str, e: NbvError) -> Status {
    invalid(field, e.to_string())
}
