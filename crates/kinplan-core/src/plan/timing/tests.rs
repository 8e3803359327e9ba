//! `retime` end to end: closed forms, limits at every sample and by finite
//! differences, path tolerance, start velocities, refusals.

use crate::Deadline;
use rand::{Rng, SeedableRng};

use super::*;

fn params(method: TimingMethod, a: &[f64], j: Option<&[f64]>) -> TimingParams {
    TimingParams {
        method,
        acceleration_limits: Some(a.to_vec()),
        jerk_limits: j.map(<[f64]>::to_vec),
        ..Default::default()
    }
}

fn random_path(rng: &mut rand_chacha::ChaCha8Rng, n: usize, dof: usize) -> Vec<f64> {
    let mut q = vec![0.0; dof];
    let mut out = Vec::with_capacity(n * dof);
    for _ in 0..n {
        out.extend_from_slice(&q);
        for v in q.iter_mut() {
            *v += rng.random_range(-0.6..0.6);
        }
    }
    out
}

/// Distance from `p` to the polyline through `w` (`dof` columns).
fn polyline_distance(w: &[f64], dof: usize, p: &[f64]) -> f64 {
    let rows: Vec<&[f64]> = w.chunks_exact(dof).collect();
    let mut best = f64::INFINITY;
    for s in rows.windows(2) {
        let d: Vec<f64> = (0..dof).map(|j| s[1][j] - s[0][j]).collect();
        let dd: f64 = d.iter().map(|x| x * x).sum();
        let t = if dd > 0.0 {
            ((0..dof).map(|j| (p[j] - s[0][j]) * d[j]).sum::<f64>() / dd).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let e = (0..dof)
            .map(|j| (s[0][j] + t * d[j] - p[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        best = best.min(e);
    }
    best
}

#[test]
fn a_multi_joint_straight_line_takes_the_bang_bang_time_of_its_slowest_joint() {
    // joint 1 moves 1.5 rad with v = 0.8, a = 1: trapezoid 1.5/0.8 + 0.8/1;
    // joint 0 moves 0.5 rad at far looser limits
    let p = params(TimingMethod::TimeOptimal, &[5.0, 1.0], None);
    let r = retime(&[0.0, 0.0, 0.5, 1.5], 2, &[3.0, 0.8], &p, Deadline::none()).unwrap();
    let expected = 1.5 / 0.8 + 0.8;
    assert!((r.duration() - expected).abs() < 2e-3, "{}", r.duration());
    // triangle: 0.2 rad at a = 1 never reaches 0.8 rad/s: 2·√(0.2/1)
    let r = retime(&[0.0, 0.0, 0.0, 0.2], 2, &[3.0, 0.8], &p, Deadline::none()).unwrap();
    assert!(
        (r.duration() - 2.0 * 0.2f64.sqrt()).abs() < 2e-3,
        "{}",
        r.duration()
    );
    let peak = r.qd.chunks_exact(2).map(|v| v[1]).fold(0.0, f64::max);
    assert!((peak - 0.2f64.sqrt()).abs() < 0.02, "{peak}");
}

#[test]
fn time_optimal_trajectories_keep_every_limit_and_stay_near_the_path() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for case in 0..20 {
        let dof = rng.random_range(1..8);
        let n = rng.random_range(2..12);
        let w = random_path(&mut rng, n, dof);
        let v: Vec<f64> = (0..dof).map(|_| rng.random_range(0.5..3.0)).collect();
        let a: Vec<f64> = (0..dof).map(|_| rng.random_range(1.0..10.0)).collect();
        let mut p = params(TimingMethod::TimeOptimal, &a, None);
        p.path_tolerance = 0.05;
        let r = retime(&w, dof, &v, &p, Deadline::none()).unwrap();
        assert!(r.t.windows(2).all(|t| t[1] > t[0]), "case {case}");
        for i in 0..r.len() {
            for j in 0..dof {
                let k = i * dof + j;
                assert!(
                    r.qd[k].abs() <= v[j] * (1.0 + 1e-6),
                    "case {case} v {} {} at {}/{}",
                    r.qd[k],
                    v[j],
                    i,
                    r.len()
                );
                assert!(r.qdd[k].abs() <= a[j] * (1.0 + 1e-6), "case {case} a");
            }
            let e = polyline_distance(&w, dof, &r.q[i * dof..(i + 1) * dof]);
            assert!(e <= 0.05 + 1e-9, "case {case}: {e} from the path");
        }
        assert!(r.qd[..dof].iter().all(|x| *x == 0.0));
        assert!(r.qd[r.qd.len() - dof..].iter().all(|x| x.abs() < 1e-9));
        assert_eq!(&r.q[..dof], &w[..dof]);
        let end = &r.q[r.q.len() - dof..];
        assert!(
            end.iter()
                .zip(&w[w.len() - dof..])
                .all(|(x, y)| (x - y).abs() < 1e-9)
        );
        // the velocities are the derivative of the positions (central
        // differences over the uniform samples)
        let h = p.sample_period;
        for i in 1..r.len().saturating_sub(2) {
            for (j, aj) in a.iter().enumerate() {
                let fd = (r.q[(i + 1) * dof + j] - r.q[(i - 1) * dof + j]) / (2.0 * h);
                let err = (fd - r.qd[i * dof + j]).abs();
                assert!(
                    err <= aj * h * 1.01 + 1e-9,
                    "case {case}: qd {} vs fd {fd}",
                    r.qd[i * dof + j]
                );
            }
        }
    }
}

#[test]
fn jerk_limited_trajectories_match_the_s_curve_and_keep_every_limit_at_1_khz() {
    // one joint, 1 rad at v = 1, a = 2, j = 10: 1.7 s (see SCurve)
    let mut p = params(TimingMethod::JerkLimited, &[2.0], Some(&[10.0]));
    p.sample_period = 1e-3;
    let r = retime(&[0.0, 1.0], 1, &[1.0], &p, Deadline::none()).unwrap();
    assert!((r.duration() - 1.7).abs() < 1e-12);
    // a reversal is stopped at: two rest-to-rest S-curves, durations add
    let r = retime(&[0.0, 1.0, 0.5], 1, &[1.0], &p, Deadline::none()).unwrap();
    let second = SCurve::rest_to_rest(0.5, 1.0, 2.0, 10.0).duration();
    assert!(
        (r.duration() - 1.7 - second).abs() < 2e-3 * second,
        "{}",
        r.duration()
    );
    let top = r.q.iter().copied().fold(f64::MIN, f64::max);
    assert!((top - 1.0).abs() < 1e-6, "{top}");

    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let (mut total, mut total_stops) = (0.0, 0.0);
    for case in 0..10 {
        let dof = rng.random_range(1..8);
        let n = rng.random_range(2..8);
        let w = random_path(&mut rng, n, dof);
        let v: Vec<f64> = (0..dof).map(|_| rng.random_range(0.5..3.0)).collect();
        let a: Vec<f64> = (0..dof).map(|_| rng.random_range(1.0..10.0)).collect();
        let j: Vec<f64> = (0..dof).map(|_| rng.random_range(5.0..50.0)).collect();
        let mut p = params(TimingMethod::JerkLimited, &a, Some(&j));
        p.sample_period = 1e-3;
        let r = retime(&w, dof, &v, &p, Deadline::none()).unwrap();
        let h = 1e-3;
        let uniform = r.len() - 1; // the last sample may be closer
        for i in 0..uniform.saturating_sub(3) {
            for k in 0..dof {
                let x = |m: usize| r.q[(i + m) * dof + k];
                let vel = (x(1) - x(0)) / h;
                let acc = (x(2) - 2.0 * x(1) + x(0)) / (h * h);
                let jerk = (x(3) - 3.0 * x(2) + 3.0 * x(1) - x(0)) / (h * h * h);
                assert!(vel.abs() <= v[k] * (1.0 + 1e-9), "case {case}: v {vel}");
                assert!(acc.abs() <= a[k] * (1.0 + 1e-6), "case {case}: a {acc}");
                assert!(jerk.abs() <= j[k] * (1.0 + 1e-3), "case {case}: j {jerk}");
            }
        }
        // the returned rates are the derivatives of the positions
        for i in 1..uniform.saturating_sub(1) {
            for (k, jk) in j.iter().enumerate() {
                let fd = (r.q[(i + 1) * dof + k] - r.q[(i - 1) * dof + k]) / (2.0 * h);
                assert!(
                    (fd - r.qd[i * dof + k]).abs() <= jk * h * h + 1e-9,
                    "case {case}: qd"
                );
                let fdd =
                    (r.q[(i + 1) * dof + k] - 2.0 * r.q[i * dof + k] + r.q[(i - 1) * dof + k]) / (h * h);
                assert!(
                    (fdd - r.qdd[i * dof + k]).abs() <= jk * h + 1e-6,
                    "case {case}: qdd"
                );
            }
        }
        // every sample within the tolerance of the polyline; rest at both
        // ends, exactly on the first and last waypoint
        for q in r.q.chunks_exact(dof) {
            assert!(
                polyline_distance(&w, dof, q) <= p.path_tolerance + 1e-9,
                "case {case}"
            );
        }
        assert_eq!(&r.q[..dof], &w[..dof]);
        for (x, y) in r.q[r.q.len() - dof..].iter().zip(&w[w.len() - dof..]) {
            assert!((x - y).abs() < 1e-9, "case {case}: end {x} vs {y}");
        }
        assert!(
            r.qd[..dof]
                .iter()
                .chain(&r.qd[r.qd.len() - dof..])
                .all(|x| x.abs() < 1e-9)
        );
        // no stop at most interior waypoints: faster than rest-to-rest
        // S-curves along each segment (the tightest joint's limits)
        let stops: f64 = w
            .chunks_exact(dof)
            .collect::<Vec<_>>()
            .windows(2)
            .map(|s| {
                let lim = |l: &[f64]| {
                    (0..dof)
                        .filter(|&k| s[1][k] != s[0][k])
                        .map(|k| l[k] / (s[1][k] - s[0][k]).abs())
                        .fold(f64::INFINITY, f64::min)
                };
                SCurve::rest_to_rest(1.0, lim(&v), lim(&a), lim(&j)).duration()
            })
            .sum();
        // (a corner sharper than about 115° is stopped at: a path of such
        // corners only may take as long as the S-curves)
        assert!(
            r.duration() <= stops * (1.0 + 1e-3),
            "case {case}: {} vs {stops}",
            r.duration()
        );
        total += r.duration();
        total_stops += stops;
    }
    assert!(total < 0.95 * total_stops, "{total} vs {total_stops}");
}

#[test]
fn jerk_limited_copes_with_repeats_tiny_segments_and_tight_tolerances() {
    let (v, a, j) = ([1.0, 2.0], [2.0, 3.0], [10.0, 40.0]);
    let cases: [(&[f64], f64); 4] = [
        // a single waypoint, and one repeated: at rest
        (&[0.3, 0.4], 0.05),
        (&[0.3, 0.4, 0.3, 0.4], 0.05),
        // repeats and micro-segments between right angles
        (
            &[0.0, 0.0, 0.0, 0.0, 1e-9, 0.0, 1e-9, 1e-9, 1.0, 1e-9, 1.0, 1.0],
            0.05,
        ),
        // a zig-zag with a tolerance far below the corners' natural offset
        (&[0.0, 0.0, 0.5, 0.1, 1.0, 0.0, 1.5, 0.1, 2.0, 0.0], 1e-6),
    ];
    for (case, (w, tol)) in cases.iter().enumerate() {
        let mut p = params(TimingMethod::JerkLimited, &a, Some(&j));
        p.path_tolerance = *tol;
        let r = retime(w, 2, &v, &p, Deadline::none()).unwrap();
        assert!(r.duration().is_finite(), "case {case}");
        for (i, (qd, qdd)) in r.qd.chunks_exact(2).zip(r.qdd.chunks_exact(2)).enumerate() {
            for k in 0..2 {
                assert!(
                    qd[k].abs() <= v[k] * (1.0 + 1e-9),
                    "case {case} sample {i}: v {}",
                    qd[k]
                );
                assert!(
                    qdd[k].abs() <= a[k] * (1.0 + 1e-9),
                    "case {case} sample {i}: a {}",
                    qdd[k]
                );
            }
        }
        for q in r.q.chunks_exact(2) {
            let d = if w.len() > 2 {
                polyline_distance(w, 2, q)
            } else {
                (q[0] - w[0]).hypot(q[1] - w[1])
            };
            assert!(d <= tol + 1e-9, "case {case}: {d}");
        }
        assert_eq!(&r.q[..2], &w[..2]);
        let end = &r.q[r.q.len() - 2..];
        assert!((end[0] - w[w.len() - 2]).abs() < 1e-9 && (end[1] - w[w.len() - 1]).abs() < 1e-9);
    }
}

#[test]
fn jerk_limited_starts_at_the_given_velocity() {
    // one joint, 1 rad from 0.5 rad/s at v = 1, a = 2, j = 10: speed up by
    // 0.5 in 0.5/2 + 2/10 = 0.45 s over (0.5 + 1)/2 · 0.45 = 0.3375 rad,
    // stop from 1 in 0.7 s over 0.35 rad, cruise 0.3125 rad: 1.4625 s
    let mut p = params(TimingMethod::JerkLimited, &[2.0], Some(&[10.0]));
    p.sample_period = 1e-3;
    p.start_velocity = Some(vec![0.5]);
    let r = retime(&[0.0, 1.0], 1, &[1.0], &p, Deadline::none()).unwrap();
    // (the first corner is a fixed point, settled to a few parts in 10⁷)
    assert!((r.duration() - 1.4625).abs() < 1e-5, "{}", r.duration());
    assert!(r.q[0].abs() < 1e-12 && (r.qd[0] - 0.5).abs() < 1e-12 && r.qdd[0].abs() < 1e-12);
    // two joints, moving across the first segment: starts on the first
    // waypoint at that velocity, turns onto the path, keeps every limit
    let (v, a, j) = ([1.0, 1.5], [2.0, 3.0], [10.0, 20.0]);
    let mut p = params(TimingMethod::JerkLimited, &a, Some(&j));
    p.sample_period = 1e-3;
    p.start_velocity = Some(vec![0.0, 0.8]);
    let w = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0];
    let r = retime(&w, 2, &v, &p, Deadline::none()).unwrap();
    assert!(r.q[0].abs() < 1e-9 && r.q[1].abs() < 1e-9, "{:?}", &r.q[..2]);
    assert!(r.qd[0].abs() < 1e-9 && (r.qd[1] - 0.8).abs() < 1e-9);
    let h = 1e-3;
    for i in 0..r.len().saturating_sub(5) {
        for k in 0..2 {
            let x = |m: usize| r.q[(i + m) * 2 + k];
            assert!(((x(1) - x(0)) / h).abs() <= v[k] * (1.0 + 1e-9), "{i}: v");
            assert!(
                ((x(2) - 2.0 * x(1) + x(0)) / (h * h)).abs() <= a[k] * (1.0 + 1e-6),
                "{i}: a"
            );
            let jerk = (x(3) - 3.0 * x(2) + 3.0 * x(1) - x(0)) / (h * h * h);
            assert!(jerk.abs() <= j[k] * (1.0 + 1e-3), "{i}: j {jerk}");
        }
    }
    let end = &r.q[r.q.len() - 2..];
    assert!((end[0] - 1.0).abs() < 1e-9 && (end[1] - 1.0).abs() < 1e-9);
    // refused by field: beyond the speed limit, or nowhere to move
    for (w, v0) in [(&w[..], vec![0.0, 1.6]), (&w[..2], vec![0.0, 0.8])] {
        p.start_velocity = Some(v0);
        let e = retime(w, 2, &v, &p, Deadline::none()).unwrap_err();
        assert!(
            matches!(
                e,
                PlanError::InvalidParam {
                    field: PlanField::StartVelocity,
                    ..
                }
            ),
            "{e}"
        );
    }
}

#[test]
fn a_start_velocity_along_the_path_is_kept_and_one_across_it_is_refused() {
    let mut p = params(TimingMethod::TimeOptimal, &[1.0, 1.0], None);
    p.start_velocity = Some(vec![0.3, 0.4]);
    let w = [0.0, 0.0, 3.0, 4.0];
    let r = retime(&w, 2, &[1.0, 1.0], &p, Deadline::none()).unwrap();
    assert!((r.qd[0] - 0.3).abs() < 1e-12 && (r.qd[1] - 0.4).abs() < 1e-12);
    // joint 1 (0.8 of the direction) binds: path speed ≤ 1.25, path
    // acceleration ≤ 1.25; from ṡ = 0.5 up to 1.25, cruise, brake to rest
    let rest = retime(
        &w,
        2,
        &[1.0, 1.0],
        &params(TimingMethod::TimeOptimal, &[1.0, 1.0], None),
        Deadline::none(),
    )
    .unwrap();
    assert!(r.duration() < rest.duration());
    let vs = 1.25;
    let acc = 1.25;
    let expected =
        (vs - 0.5) / acc + vs / acc + (5.0 - (vs * vs - 0.25) / (2.0 * acc) - vs * vs / (2.0 * acc)) / vs;
    assert!(
        (r.duration() - expected).abs() < 2e-3,
        "{} vs {expected}",
        r.duration()
    );
    p.start_velocity = Some(vec![0.4, 0.3]);
    let e = retime(&w, 2, &[1.0, 1.0], &p, Deadline::none()).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::InvalidParam {
                field: PlanField::StartVelocity,
                ..
            }
        ),
        "{e}"
    );
    // too fast to stop within 0.05 rad
    p.start_velocity = Some(vec![0.6, 0.8]);
    let e = retime(&[0.0, 0.0, 0.03, 0.04], 2, &[1.0, 1.0], &p, Deadline::none()).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::InvalidParam {
                field: PlanField::StartVelocity,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn bad_requests_are_refused_by_field_and_a_stop_interrupts() {
    let p = params(TimingMethod::TimeOptimal, &[1.0], None);
    let e = retime(&[], 1, &[1.0], &p, Deadline::none()).unwrap_err();
    assert!(matches!(
        e,
        PlanError::WrongLength {
            field: PlanField::Waypoints,
            ..
        }
    ));
    let e = retime(&[0.0, f64::NAN], 1, &[1.0], &p, Deadline::none()).unwrap_err();
    assert!(matches!(
        e,
        PlanError::NonFinite {
            field: PlanField::Waypoints,
            index: 1
        }
    ));
    let mut fine = p.clone();
    fine.sample_period = 1e-4;
    let e = retime(&[0.0, 1e4], 1, &[1.0], &fine, Deadline::none()).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::InvalidParam {
                field: PlanField::SamplePeriod,
                ..
            }
        ),
        "{e}"
    );
    let e = retime(
        &[0.0, 1.0],
        1,
        &[1.0],
        &p,
        Deadline::none().with_cancel(&std::sync::atomic::AtomicBool::new(true)),
    )
    .unwrap_err();
    assert_eq!(e, PlanError::Interrupted);
    let mut no_jerk = p.clone();
    no_jerk.method = TimingMethod::JerkLimited;
    let e = no_jerk.validate(1).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::InvalidParam {
                field: PlanField::JerkLimits,
                ..
            }
        ),
        "{e}"
    );
    let off = TimingParams {
        start_velocity: Some(vec![1.0]),
        ..Default::default()
    };
    assert!(off.validate(1).is_err());
    // a single waypoint is one sample at rest
    let r = retime(&[0.25], 1, &[1.0], &p, Deadline::none()).unwrap();
    assert_eq!(
        (r.t.clone(), r.q.clone(), r.qd.clone()),
        (vec![0.0], vec![0.25], vec![0.0])
    );
}
