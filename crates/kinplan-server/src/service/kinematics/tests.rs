use super::*;

#[test]
fn errors_name_request_fields() {
    let cases = [
        (IkError::WrongSeedLength { expected: 6, got: 5 }, "seed"),
        (IkError::NonFiniteSeed { index: 2 }, "seed[2]"),
        (
            IkError::InvalidParam {
                field: "position_tolerance",
                value: 0.0,
                reason: "",
            },
            "options.position_tolerance",
        ),
        (
            IkError::MethodCannotServe {
                method: IkMethod::Fabrik,
                reason: String::new(),
            },
            "options.method",
        ),
        (
            IkError::InvalidPath {
                field: "normal",
                reason: "",
            },
            "circle.normal",
        ),
        (
            IkError::Linalg(LinalgError::InvalidParam {
                field: "max_iterations",
                value: 0.0,
                reason: "",
            }),
            "options.rlxa_max_iterations",
        ),
    ];
    for (err, field) in cases {
        let status = ik_error(err, "targets[1]", "circle");
        assert_eq!(status.code(), tonic::Code::InvalidArgument);
        assert!(status.message().starts_with(field), "{}", status.message());
    }
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
