use super::*;

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
