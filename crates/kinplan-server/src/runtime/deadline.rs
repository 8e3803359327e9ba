//! Deadlines: the `grpc-timeout` header, the server's default, the instant a
//! call must be answered by, and the earlier "soft" deadline that leaves time
//! for the reply. Shared by the transport (the guard layer sets a call's
//! deadline) and the handlers (admission and the domain's time budgets).

use std::time::{Duration, Instant};

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

/// The earlier (or shorter) of two optional limits, `None` meaning no
/// limit: the one derivation behind every "this or that, whichever comes
/// first" of the server (a call's timeout, a request's time budget against
/// its deadline).
pub fn earlier<T: Ord>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The call's timeout: the shorter of `grpc-timeout` and the server's default.
pub fn effective_timeout(header: Option<Duration>, default: Option<Duration>) -> Option<Duration> {
    earlier(header, default)
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

/// A request's time budget as a duration (for the domain's `time_budget`
/// parameters): the shorter of its `explicit` budget and the time left until
/// `soft` (a [`soft_deadline`]).
pub fn time_budget(explicit: Option<Duration>, soft: Option<Instant>) -> Option<Duration> {
    earlier(explicit, soft.map(kinplan_core::ik::budget_until))
}

/// A request's time budget as an instant (for work that checks a deadline):
/// the earlier of `explicit` from now and the soft deadline of the call's
/// `deadline`. An explicit budget too large for `Instant` is no limit.
pub fn work_deadline(explicit: Option<Duration>, deadline: Option<Instant>) -> Option<Instant> {
    earlier(
        explicit.and_then(|b| Instant::now().checked_add(b)),
        soft_deadline(deadline),
    )
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
    fn the_earlier_limit_applies_and_none_is_no_limit() {
        assert_eq!(earlier(Some(3), Some(5)), Some(3));
        assert_eq!(earlier(Some(5), Some(3)), Some(3));
        assert_eq!(earlier(Some(5), None), Some(5));
        assert_eq!(earlier(None, Some(3)), Some(3));
        assert_eq!(earlier::<u32>(None, None), None);
        let ms = Duration::from_millis;
        assert_eq!(effective_timeout(Some(ms(10)), Some(ms(60_000))), Some(ms(10)));
        assert_eq!(effective_timeout(None, Some(ms(60_000))), Some(ms(60_000)));
    }

    /// An explicit budget shorter than the deadline's applies from now; a
    /// longer one (or one too large for `Instant`) gives way to the soft deadline.
    #[test]
    fn the_work_deadline_is_the_earlier_of_budget_and_soft_deadline() {
        let ms = Duration::from_millis;
        let deadline = Instant::now() + ms(60_000);
        let soft = soft_deadline(Some(deadline)).unwrap();
        let before = Instant::now();
        let short = work_deadline(Some(ms(5)), Some(deadline)).unwrap();
        assert!(short >= before + ms(5) && short < soft);
        assert_eq!(work_deadline(Some(ms(120_000)), Some(deadline)), Some(soft));
        assert_eq!(work_deadline(Some(Duration::MAX), Some(deadline)), Some(soft));
        assert_eq!(work_deadline(Some(Duration::MAX), None), None);
        assert_eq!(work_deadline(None, None), None);
        assert!(work_deadline(Some(ms(5)), None).unwrap() >= before + ms(5));
    }

    #[test]
    fn the_deadline_leaves_a_reply_reserve() {
        let now = Instant::now();
        let soft = soft_deadline(Some(now + Duration::from_millis(12))).unwrap();
        let reserve = (now + Duration::from_millis(12)) - soft;
        assert!(reserve >= Duration::from_micros(1100) && reserve <= Duration::from_micros(1200));
        let soft = soft_deadline(Some(now + Duration::from_secs(60))).unwrap();
        assert_eq!((now + Duration::from_secs(60)) - soft, Duration::from_millis(100));
        assert_eq!(
            time_budget(Some(Duration::from_millis(3)), None),
            Some(Duration::from_millis(3))
        );
        assert!(
            time_budget(
                Some(Duration::from_secs(3)),
                Some(now + Duration::from_millis(10))
            )
            .unwrap()
                <= Duration::from_millis(10)
        );
        assert_eq!(time_budget(None, None), None);
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
