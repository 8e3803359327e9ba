//! [`Deadline`]: the one shape in which every long computation of the core
//! receives its time limit — an optional instant and an optional
//! cancellation — and the one place where two limits are combined ("the
//! earlier of the two applies").
//!
//! A computation polls [`Deadline::expired`] (or [`Deadline::stop`] when it
//! reports *why* it stopped) at a cadence it documents; the poll is a clock
//! read and, with a cancellation, one call through a reference, so it does
//! not allocate and is cheap enough for inner loops polled every few hundred
//! iterations.
//!
//! Domain parameters that are a client's own per-solve budget (such as
//! `IkParams::time_budget`) stay durations in their `…Params`; a solver
//! folds them into its deadline once, at its start, with
//! [`Deadline::min_with_budget`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Something a caller raises to stop a running computation (the caller went
/// away, a stream's reader closed). Polled from worker threads, so `Sync`.
///
/// Implemented for an [`AtomicBool`] (raised when `true`) and for any
/// `Fn() -> bool + Sync` closure (raised when it returns `true`).
pub trait Cancel: Sync {
    /// True once the computation should stop.
    fn is_cancelled(&self) -> bool;
}

impl Cancel for AtomicBool {
    #[inline]
    fn is_cancelled(&self) -> bool {
        self.load(Ordering::Relaxed)
    }
}

impl<F: Fn() -> bool + Sync> Cancel for F {
    #[inline]
    fn is_cancelled(&self) -> bool {
        self()
    }
}

/// Why a [`Deadline`] says stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The instant has passed.
    Deadline,
    /// The cancellation was raised.
    Cancelled,
}

/// A computation's time limit: an optional instant after which it should
/// stop, and an optional cancellation the caller may raise at any time.
///
/// `Copy` (an instant and a reference), `Send + Sync`; the default is no
/// limit at all ([`Deadline::none`]).
///
/// ```
/// use std::sync::atomic::{AtomicBool, Ordering};
/// use std::time::{Duration, Instant};
/// use kinplan_core::{Deadline, Stop};
///
/// let gone = AtomicBool::new(false);
/// let d = Deadline::after(Duration::from_secs(60)).with_cancel(&gone);
/// assert_eq!(d.stop(), None);
/// gone.store(true, Ordering::Relaxed);
/// assert_eq!(d.stop(), Some(Stop::Cancelled));
///
/// // The earlier of two limits applies; `None` is no limit.
/// let soon = Instant::now() + Duration::from_millis(5);
/// assert_eq!(Deadline::none().earlier(Some(soon)).instant(), Some(soon));
/// assert_eq!(Deadline::at(soon).min_with_budget(Some(Duration::from_secs(9))).instant(), Some(soon));
/// ```
#[derive(Clone, Copy, Default)]
pub struct Deadline<'a> {
    at: Option<Instant>,
    cancel: Option<&'a dyn Cancel>,
}

impl std::fmt::Debug for Deadline<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Deadline")
            .field("at", &self.at)
            .field("cancel", &self.cancel.is_some())
            .finish()
    }
}

/// The earlier (or smaller) of two optional limits, `None` meaning no limit.
///
/// ```
/// use kinplan_core::deadline::earliest;
/// assert_eq!(earliest(Some(3), Some(5)), Some(3));
/// assert_eq!(earliest(None, Some(5)), Some(5));
/// assert_eq!(earliest::<u8>(None, None), None);
/// ```
pub fn earliest<T: Ord>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

impl<'a> Deadline<'a> {
    /// No instant and no cancellation: never expires.
    pub const fn none() -> Self {
        Self {
            at: None,
            cancel: None,
        }
    }

    /// Expires at `at`.
    pub const fn at(at: Instant) -> Self {
        Self {
            at: Some(at),
            cancel: None,
        }
    }

    /// Expires at `at` when it is `Some`; never otherwise.
    pub const fn at_opt(at: Option<Instant>) -> Self {
        Self { at, cancel: None }
    }

    /// Expires `budget` from now (no limit if that instant cannot be
    /// represented).
    pub fn after(budget: Duration) -> Self {
        Self::at_opt(Instant::now().checked_add(budget))
    }

    /// This deadline, also stopped by `cancel` (replacing any cancellation
    /// it had).
    pub fn with_cancel(self, cancel: &'a dyn Cancel) -> Self {
        Self {
            cancel: Some(cancel),
            ..self
        }
    }

    /// This deadline's cancellation alone, without its instant.
    pub fn without_instant(self) -> Self {
        Self { at: None, ..self }
    }

    /// The earlier of this deadline's instant and `other` (`None`: no
    /// limit), keeping the cancellation.
    pub fn earlier(self, other: Option<Instant>) -> Self {
        Self {
            at: earliest(self.at, other),
            ..self
        }
    }

    /// The earlier of this deadline and `budget` from now (`None`, or a
    /// budget too large for `Instant`: no limit), keeping the cancellation:
    /// how a solver combines its caller's deadline with a per-solve budget
    /// given in its parameters.
    pub fn min_with_budget(self, budget: Option<Duration>) -> Self {
        self.earlier(budget.and_then(|b| Instant::now().checked_add(b)))
    }

    /// The instant, if any.
    pub fn instant(&self) -> Option<Instant> {
        self.at
    }

    /// Time left until the instant, zero once passed; `None` without an
    /// instant. The cancellation is not consulted.
    pub fn remaining(&self) -> Option<Duration> {
        self.at.map(|at| at.saturating_duration_since(Instant::now()))
    }

    /// Whether the computation should stop, and why: [`Stop::Deadline`] once
    /// the instant has passed (looked at first), [`Stop::Cancelled`] once the
    /// cancellation is raised.
    #[inline]
    pub fn stop(&self) -> Option<Stop> {
        if let Some(at) = self.at
            && Instant::now() >= at
        {
            return Some(Stop::Deadline);
        }
        if let Some(c) = self.cancel
            && c.is_cancelled()
        {
            return Some(Stop::Cancelled);
        }
        None
    }

    /// True once the instant has passed or the cancellation is raised.
    #[inline]
    pub fn expired(&self) -> bool {
        self.stop().is_some()
    }

    /// True once the cancellation is raised (the instant is not consulted).
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.is_cancelled())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync<T: Send + Sync + Copy>() {}

    #[test]
    fn is_copy_send_and_sync() {
        assert_send_sync::<Deadline<'static>>();
    }

    #[test]
    fn none_never_expires_and_has_no_remaining_time() {
        let d = Deadline::none();
        assert!(!d.expired());
        assert_eq!(d.stop(), None);
        assert_eq!(d.remaining(), None);
        assert_eq!(d.instant(), None);
        assert!(!Deadline::default().expired());
    }

    #[test]
    fn a_passed_instant_is_a_deadline_stop() {
        let past = Instant::now() - Duration::from_millis(1);
        assert_eq!(Deadline::at(past).stop(), Some(Stop::Deadline));
        assert_eq!(Deadline::at(past).remaining(), Some(Duration::ZERO));
        let later = Deadline::at(Instant::now() + Duration::from_secs(60));
        assert_eq!(later.stop(), None);
        let left = later.remaining().unwrap();
        assert!(left > Duration::from_secs(59) && left <= Duration::from_secs(60));
    }

    /// The instant is looked at before the cancellation, so a computation
    /// cut by both reports its deadline.
    #[test]
    fn a_deadline_is_reported_before_a_cancellation() {
        let flag = AtomicBool::new(true);
        let past = Instant::now() - Duration::from_millis(1);
        assert_eq!(Deadline::at(past).with_cancel(&flag).stop(), Some(Stop::Deadline));
        assert_eq!(Deadline::none().with_cancel(&flag).stop(), Some(Stop::Cancelled));
        assert!(Deadline::at(past).with_cancel(&flag).is_cancelled());
        assert!(!Deadline::at(past).is_cancelled());
    }

    #[test]
    fn a_flag_or_a_closure_cancels() {
        let flag = AtomicBool::new(false);
        let d = Deadline::none().with_cancel(&flag);
        assert!(!d.expired());
        flag.store(true, Ordering::Relaxed);
        assert!(d.expired());
        let count = std::sync::atomic::AtomicUsize::new(0);
        let closure = || count.fetch_add(1, Ordering::Relaxed) >= 2;
        let d = Deadline::none().with_cancel(&closure);
        assert!(!d.expired());
        assert!(!d.expired());
        assert!(d.expired());
        // the instant is dropped, the cancellation kept
        let past = Instant::now() - Duration::from_millis(1);
        let kept = Deadline::at(past).with_cancel(&flag).without_instant();
        assert_eq!(kept.instant(), None);
        assert_eq!(kept.stop(), Some(Stop::Cancelled));
    }

    #[test]
    fn the_earlier_limit_applies_and_none_is_no_limit() {
        assert_eq!(earliest(Some(3), Some(5)), Some(3));
        assert_eq!(earliest(Some(5), Some(3)), Some(3));
        assert_eq!(earliest(Some(5), None), Some(5));
        assert_eq!(earliest(None, Some(3)), Some(3));
        assert_eq!(earliest::<u32>(None, None), None);
        let now = Instant::now();
        let (a, b) = (now + Duration::from_millis(3), now + Duration::from_millis(5));
        assert_eq!(Deadline::at(a).earlier(Some(b)).instant(), Some(a));
        assert_eq!(Deadline::at(b).earlier(Some(a)).instant(), Some(a));
        assert_eq!(Deadline::at(b).earlier(None).instant(), Some(b));
        assert_eq!(Deadline::none().earlier(Some(a)).instant(), Some(a));
        // the cancellation survives the combination
        let flag = AtomicBool::new(true);
        assert!(
            Deadline::none()
                .with_cancel(&flag)
                .earlier(Some(b))
                .is_cancelled()
        );
    }

    /// A budget shorter than the deadline applies from now; a longer one, one
    /// too large for `Instant` or none leaves the deadline as it was.
    #[test]
    fn a_budget_applies_from_now_when_it_ends_first() {
        let ms = Duration::from_millis;
        let far = Instant::now() + ms(60_000);
        let before = Instant::now();
        let short = Deadline::at(far).min_with_budget(Some(ms(5))).instant().unwrap();
        let after = Instant::now();
        assert!(short >= before + ms(5) && short <= after + ms(5));
        assert_eq!(
            Deadline::at(far).min_with_budget(Some(ms(120_000))).instant(),
            Some(far)
        );
        assert_eq!(
            Deadline::at(far).min_with_budget(Some(Duration::MAX)).instant(),
            Some(far)
        );
        assert_eq!(Deadline::at(far).min_with_budget(None).instant(), Some(far));
        assert_eq!(
            Deadline::none().min_with_budget(Some(Duration::MAX)).instant(),
            None
        );
        assert_eq!(Deadline::after(Duration::MAX).instant(), None);
        assert!(Deadline::none().min_with_budget(Some(Duration::ZERO)).expired());
    }

    /// Polling from another thread sees a cancellation raised here.
    #[test]
    fn a_worker_thread_sees_the_cancellation() {
        let flag = AtomicBool::new(false);
        let d = Deadline::after(Duration::from_secs(30)).with_cancel(&flag);
        let polls = std::thread::scope(|s| {
            let worker = s.spawn(move || {
                let mut polls = 0u64;
                while !d.expired() {
                    polls += 1;
                    std::hint::spin_loop();
                }
                (polls, d.stop())
            });
            std::thread::sleep(Duration::from_millis(5));
            flag.store(true, Ordering::Relaxed);
            worker.join().unwrap()
        });
        assert_eq!(polls.1, Some(Stop::Cancelled));
    }
}
