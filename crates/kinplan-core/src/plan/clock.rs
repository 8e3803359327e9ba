//! Deadline and cancellation, checked by every planner loop.

use std::time::Instant;

use crate::Deadline;

/// Why a planner stopped early.
pub(crate) use crate::Stop as Interrupt;

/// The caller's [`Deadline`] and the request's start.
#[derive(Clone, Copy)]
pub(crate) struct Clock<'a> {
    pub start: Instant,
    pub deadline: Deadline<'a>,
}

impl Clock<'_> {
    /// `Some` once the deadline has passed or the caller asked to stop.
    #[inline]
    pub fn interrupted(&self) -> Option<Interrupt> {
        self.deadline.stop()
    }

    /// Microseconds since the request started.
    pub fn elapsed_us(&self) -> u64 {
        self.start.elapsed().as_micros().min(u64::MAX as u128) as u64
    }
}
