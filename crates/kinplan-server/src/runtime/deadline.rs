//! Deadlines: the `grpc-timeout` header, the server's default, the instant a
//! call must be answered by, the earlier "soft" deadline that leaves time
//! for the reply, and the one derivation of the [`Deadline`] the domain
//! sees ([`Budget::deadline`]: the soft deadline and the cancellation raised
//! when the caller goes away). Shared by the transport (the guard layer sets
//! a call's deadline) and the handlers (admission and the domain's work).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kinplan_core::Deadline;
use kinplan_core::deadline::earliest;

/// The instant a call must be answered by (`None`: no deadline), set by the
/// guard from `grpc-timeout` and the server's default, read by admission.
#[derive(Debug, Clone, Copy)]
pub struct RequestDeadline(pub Option<Instant>);

/// The deadline for a timeout starting now, a little early so this server's
/// DEADLINE_EXCEEDED beats tonic's own timer (which started first and answers
/// CANCELLED). A timeout too large for `Instant` means no deadline.
pub fn deadline_after(timeout: Duration) -> Option<Instant> {
    Instant::now().checked_add(timeout - answer_reserve(timeout))
}

/// How much earlier than a call's timeout this server answers it:
/// `min(timeout / 20, 2 ms)`.
pub fn answer_reserve(timeout: Duration) -> Duration {
    (timeout / 20).min(Duration::from_millis(2))
}

/// The call's timeout: the shorter of `grpc-timeout` and the server's default.
pub fn effective_timeout(header: Option<Duration>, default: Option<Duration>) -> Option<Duration> {
    earliest(header, default)
}

/// The instant a call starting now must be answered by: its
/// [`effective_timeout`] from now, less [`deadline_after`]'s margin; `None`
/// without a timeout (or one too large for `Instant`). The one derivation
/// behind the guard layer, the in-process transport, admission outside a
/// server and `StreamIk` (which takes no default).
pub fn call_deadline(header: Option<Duration>, default: Option<Duration>) -> Option<Instant> {
    effective_timeout(header, default).and_then(deadline_after)
}

/// What a request's work may spend: the call's deadline and a cancellation
/// flag raised when the caller goes away (the request's future is dropped).
/// The work sees them as one [`Deadline`] ([`Budget::deadline`]); a client's
/// own budget (`options.time_budget`) is folded in with
/// [`Deadline::min_with_budget`].
#[derive(Debug, Clone)]
pub struct Budget {
    /// When the call must be answered (`None`: never).
    call: Option<Instant>,
    /// `call` less the reply reserve ([`soft_deadline`]), taken when the
    /// budget was made.
    soft: Option<Instant>,
    cancelled: Arc<AtomicBool>,
}

impl Budget {
    /// The budget of a call to be answered by `call`.
    pub fn new(call: Option<Instant>) -> Self {
        Self {
            call,
            soft: soft_deadline(call),
            cancelled: Arc::new(AtomicBool::new(false)),
        }
    }

    /// When the call must be answered (the pool's timer answers
    /// DEADLINE_EXCEEDED then).
    pub fn call_deadline(&self) -> Option<Instant> {
        self.call
    }

    /// The request's deadline as the domain sees it: the soft deadline (the
    /// call's, less a reply reserve, so that an answer cut short still
    /// arrives) and the caller's cancellation.
    pub fn deadline(&self) -> Deadline<'_> {
        Deadline::at_opt(self.soft).with_cancel(&*self.cancelled)
    }

    /// True once the caller has gone.
    pub fn cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    /// True once the call's deadline has passed or the caller has gone:
    /// work not yet started is not started.
    pub fn expired(&self) -> bool {
        self.cancelled() || self.call.is_some_and(|d| Instant::now() >= d)
    }

    /// The flag raised when the caller goes away.
    pub(crate) fn cancel_flag(&self) -> &Arc<AtomicBool> {
        &self.cancelled
    }
}

/// Parses the `grpc-timeout` header: digits and a unit (H M S m u n),
/// saturating (the spec allows 8 digits; more are read, not trusted).
pub(crate) fn grpc_timeout(headers: &http::HeaderMap) -> Option<Duration> {
    let value = headers.get("grpc-timeout")?.to_str().ok()?;
    let (digits, unit) = value.split_at(value.len().checked_sub(1)?);
    let n: u64 = digits.parse().ok()?;
    Some(match unit {
        "H" => Duration::from_secs(n.saturating_mul(3600)),
        "M" => Duration::from_secs(n.saturating_mul(60)),
        "S" => Duration::from_secs(n),
        "m" => Duration::from_millis(n),
        "u" => Duration::from_micros(n),
        "n" => Duration::from_nanos(n),
        _ => return None,
    })
}

/// The request's deadline less a reply reserve (a tenth of the remaining
/// time, 0.2–100 ms, at most half of it), so that an answer cut by the budget
/// still reaches the caller before its deadline.
pub fn soft_deadline(deadline: Option<Instant>) -> Option<Instant> {
    let deadline = deadline?;
    let remaining = deadline.saturating_duration_since(Instant::now());
    Some(deadline - reply_reserve(remaining))
}

/// The reply reserve taken from `remaining`: `min(clamp(remaining / 10,
/// 200 µs, 100 ms), remaining / 2)`.
pub fn reply_reserve(remaining: Duration) -> Duration {
    (remaining / 10)
        .clamp(Duration::from_micros(200), Duration::from_millis(100))
        .min(remaining / 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grpc_timeout_units() {
        let mut md = http::HeaderMap::new();
        md.insert("grpc-timeout", "250m".parse().unwrap());
        assert_eq!(grpc_timeout(&md), Some(Duration::from_millis(250)));
        md.insert("grpc-timeout", "3S".parse().unwrap());
        assert_eq!(grpc_timeout(&md), Some(Duration::from_secs(3)));
        md.insert("grpc-timeout", "x".parse().unwrap());
        assert_eq!(grpc_timeout(&md), None);
        // Regression: the legal-looking maximum overflowed `Instant` arithmetic.
        md.insert("grpc-timeout", "18446744073709551615S".parse().unwrap());
        assert_eq!(grpc_timeout(&md), Some(Duration::from_secs(u64::MAX)));
        assert_eq!(deadline_after(Duration::from_secs(u64::MAX)), None);
    }

    #[test]
    fn the_shorter_timeout_applies_and_none_is_no_limit() {
        let ms = Duration::from_millis;
        assert_eq!(effective_timeout(Some(ms(10)), Some(ms(60_000))), Some(ms(10)));
        assert_eq!(effective_timeout(None, Some(ms(60_000))), Some(ms(60_000)));
        assert_eq!(call_deadline(None, None), None);
        assert_eq!(call_deadline(Some(Duration::MAX), None), None);
        let before = Instant::now();
        let d = call_deadline(Some(ms(10)), Some(ms(60_000))).unwrap();
        // 10 ms less the margin of a twentieth (0.5 ms)
        assert!(
            d >= before + ms(9) && d <= Instant::now() + ms(10),
            "{:?}",
            d - before
        );
    }

    /// The domain's deadline is the soft deadline with the caller's
    /// cancellation; an explicit budget shorter than it applies from now, a
    /// longer one (or one too large for `Instant`) gives way to it.
    #[test]
    fn the_work_deadline_is_the_earlier_of_budget_and_soft_deadline() {
        let ms = Duration::from_millis;
        let call = Instant::now() + ms(60_000);
        let budget = Budget::new(Some(call));
        let soft = budget.deadline().instant().unwrap();
        // a 60 s call keeps the 100 ms reserve ceiling
        assert_eq!(call - soft, ms(100));
        assert_eq!(budget.call_deadline(), Some(call));
        let before = Instant::now();
        let short = budget.deadline().min_with_budget(Some(ms(5))).instant().unwrap();
        assert!(short >= before + ms(5) && short < soft);
        let long = budget.deadline().min_with_budget(Some(ms(120_000)));
        assert_eq!(long.instant(), Some(soft));
        let huge = budget.deadline().min_with_budget(Some(Duration::MAX));
        assert_eq!(huge.instant(), Some(soft));
        let none = Budget::new(None);
        assert_eq!(
            none.deadline().min_with_budget(Some(Duration::MAX)).instant(),
            None
        );
        assert_eq!(none.deadline().instant(), None);
        assert!(none.deadline().min_with_budget(Some(ms(5))).instant().unwrap() >= before + ms(5));
    }

    /// The caller going away stops the work through every deadline derived
    /// from the budget, clones included; the call's deadline ends it too.
    #[test]
    fn cancellation_reaches_the_domain_deadline() {
        let budget = Budget::new(Some(Instant::now() + Duration::from_secs(60)));
        let clone = budget.clone();
        assert!(!budget.expired() && !budget.deadline().expired());
        budget.cancel_flag().store(true, Ordering::Relaxed);
        assert!(clone.cancelled() && clone.expired());
        assert_eq!(clone.deadline().stop(), Some(kinplan_core::Stop::Cancelled));
        let past = Budget::new(Some(Instant::now() - Duration::from_millis(1)));
        assert!(past.expired() && !past.cancelled());
        assert_eq!(past.deadline().stop(), Some(kinplan_core::Stop::Deadline));
    }

    #[test]
    fn the_deadline_leaves_a_reply_reserve() {
        let now = Instant::now();
        let soft = soft_deadline(Some(now + Duration::from_millis(12))).unwrap();
        let reserve = (now + Duration::from_millis(12)) - soft;
        assert!(reserve >= Duration::from_micros(1100) && reserve <= Duration::from_micros(1200));
        let soft = soft_deadline(Some(now + Duration::from_secs(60))).unwrap();
        assert_eq!((now + Duration::from_secs(60)) - soft, Duration::from_millis(100));
    }

    /// The reserve on exact durations (no clock involved): a tenth of the time
    /// left, at least 200 µs, at most 100 ms, and never more than half of it.
    #[test]
    fn the_reply_reserve_is_a_clamped_tenth_and_at_most_half() {
        let us = Duration::from_micros;
        // the long branch: a tenth, then the 100 ms ceiling
        assert_eq!(reply_reserve(us(12_000)), us(1_200));
        assert_eq!(reply_reserve(Duration::from_secs(60)), Duration::from_millis(100));
        // the 200 µs floor while it is below half the time left
        assert_eq!(reply_reserve(us(1_000)), us(200));
        assert_eq!(reply_reserve(us(401)), us(200));
        // the short-deadline branch: half the time left, below the floor
        assert_eq!(reply_reserve(us(400)), us(200));
        assert_eq!(reply_reserve(us(300)), us(150));
        assert_eq!(reply_reserve(us(2)), us(1));
        assert_eq!(reply_reserve(Duration::ZERO), Duration::ZERO);
    }

    /// Short deadlines: the reserve is at most half the time left (the
    /// 200 µs floor would otherwise eat a 300 µs deadline's whole budget).
    #[test]
    fn a_short_deadline_keeps_half_for_the_work() {
        let deadline = Instant::now() + Duration::from_micros(300);
        let reserve = deadline - soft_deadline(Some(deadline)).unwrap();
        assert!(reserve <= Duration::from_micros(150), "{reserve:?}");
        assert!(reserve >= Duration::from_micros(50), "{reserve:?}");
        // A deadline already passed leaves no reserve and no overflow.
        let past = Instant::now() - Duration::from_millis(1);
        assert_eq!(soft_deadline(Some(past)), Some(past));
    }
}
