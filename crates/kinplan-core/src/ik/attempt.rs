//! One attempt's bookkeeping, shared by every per-attempt algorithm (Jacobian
//! methods, CCD, FABRIK, length relaxation): the clock, the stop rules checked
//! before each iteration, stall detection, and how an attempt ended.

use std::time::Instant;

use super::{IkParams, IkStatus, IkTarget, PoseError};
use crate::{Deadline, Stop};

/// The request's start and its deadline (the caller's, already combined
/// with `IkParams::time_budget`), checked once per iteration.
pub(crate) struct Clock<'a> {
    pub start: Instant,
    pub deadline: Deadline<'a>,
}

impl Clock<'_> {
    /// `TimeBudget` once the deadline has passed, `Cancelled` once the
    /// caller's cancellation is raised.
    #[inline]
    pub fn interrupted(&self) -> Option<IkStatus> {
        self.deadline.stop().map(|s| match s {
            Stop::Deadline => IkStatus::TimeBudget,
            Stop::Cancelled => IkStatus::Cancelled,
        })
    }
    pub fn elapsed_us(&self) -> u64 {
        self.start.elapsed().as_micros().min(u64::MAX as u128) as u64
    }
}

/// How one attempt ended; the joints are left in `IkWorkspace::q`.
pub(crate) struct Attempt {
    pub status: IkStatus,
    pub iterations: usize,
    pub error: PoseError,
}

/// The stop rules every attempt loop checks before an iteration, in this order:
/// converged (`err` within the tolerances), the iteration cap (`iterations ≥
/// max_iterations`), then the deadline and cancellation. Stall detection
/// ([`Progress`]) stays with each method, which decides where in its iteration
/// progress is measured.
#[inline]
pub(crate) fn stop_before_iteration(
    err: &PoseError,
    target: &IkTarget,
    params: &IkParams,
    iterations: usize,
    clock: &Clock<'_>,
) -> Option<IkStatus> {
    if is_converged(err, target, params) {
        return Some(IkStatus::Converged);
    }
    if iterations >= params.max_iterations {
        return Some(IkStatus::MaxIterations);
    }
    clock.interrupted()
}

/// Stall bookkeeping shared by the iterative methods: an attempt makes progress when
/// its squared error falls below `fraction` × the value at the last progress; after
/// `patience` iterations without progress it has stalled (`patience` 0 never stalls).
pub(crate) struct Progress {
    fraction: f64,
    patience: usize,
    reference: f64,
    since: usize,
}

impl Progress {
    pub(crate) fn new(fraction: f64, patience: usize, initial_squared_error: f64) -> Self {
        Self {
            fraction,
            patience,
            reference: initial_squared_error,
            since: 0,
        }
    }

    /// Records one iteration's squared error; true once the attempt has stalled.
    pub(crate) fn stalled(&mut self, squared_error: f64) -> bool {
        if squared_error < self.fraction * self.reference {
            self.reference = squared_error;
            self.since = 0;
            return false;
        }
        self.since += 1;
        self.patience > 0 && self.since >= self.patience
    }
}

pub(crate) fn is_converged(err: &PoseError, target: &IkTarget, params: &IkParams) -> bool {
    err.position <= params.position_tolerance
        && (target.is_position_only() || err.orientation <= params.orientation_tolerance)
}
