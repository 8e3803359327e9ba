use super::*;

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

/// Unset options take the domain's defaults; only the restart count of the
/// warm-started calls (TrackPath, StreamIk) is the service's own.
#[test]
fn unset_options_take_the_domain_defaults() {
    let d = IkParams::default();
    let solve = Options::from_proto(None, RESTARTS_SOLVE).unwrap().params;
    assert_eq!(solve, d);
    let warm = Options::from_proto(None, RESTARTS_WARM).unwrap().params;
    assert_eq!(warm.max_restarts, 0);
    assert_eq!(IkParams { max_restarts: 0, ..d }, warm);
    let explicit = pb::IkOptions {
        max_restarts: Some(7),
        ..Default::default()
    };
    let p = Options::from_proto(Some(&explicit), RESTARTS_WARM)
        .unwrap()
        .params;
    assert_eq!(p.max_restarts, 7);
}
