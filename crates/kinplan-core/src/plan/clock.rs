//! Deadline and cancellation, checked by every planner loop.

use std::time::Instant;

/// Why a planner stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Interrupt {
    Deadline,
    Cancelled,
}

/// The caller's deadline and cancellation closure.
#[derive(Clone, Copy)]
pub(crate) struct Clock<'a> {
    pub start: Instant,
    pub deadline: Option<Instant>,
    pub should_stop: &'a (dyn Fn() -> bool + Sync),
}

impl Clock<'_> {
    /// `Some` once the deadline has passed or the caller asked to stop.
    #[inline]
    pub fn interrupted(&self) -> Option<Interrupt> {
        if let Some(d) = self.deadline
            && Instant::now() >= d
        {
            return Some(Interrupt::Deadline);
        }
        if (self.should_stop)() {
            return Some(Interrupt::Cancelled);
        }
        None
    }

    /// Microseconds since the request started.
    pub fn elapsed_us(&self) -> u64 {
        self.start.elapsed().as_micros().min(u64::MAX as u128) as u64
    }
}
