//! Hand-computed cases, bad inputs and invariances of `score`.

use super::*;
use crate::score::{Criterion, JointLimits, Rows, ScoreField, ScoreParam, TrajectoryData};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

const EPS: f64 = 1e-12;

fn still_poses(n: usize) -> Vec<Isometry3<f64>> {
    vec![Isometry3::identity(); n]
}

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

fn run(input: &ScoreInput<'_>) -> ScoreReport {
    score(
        input,
        &ScoreParams {
            series: true,
            ..Default::default()
        },
    )
    .expect("valid input")
}

fn scores_of(q: &[Vec<f64>], poses: &[Isometry3<f64>]) -> Scores {
    run(&ScoreInput::new(TrajectoryData::new(Rows::Nested(q), poses))).scores
}

#[test]
fn straight_joint_moves_jd_and_cpc_by_hand() {
    // steps (1, 0.5, −1) and (0.5, 0, −2): JD = 2.5 + 2.5
    let q = vec![vec![0.0, 0.0, 0.0], vec![1.0, 0.5, -1.0], vec![1.5, 0.5, -3.0]];
    let poses = still_poses(3);
    let t = TrajectoryData::new(Rows::Nested(&q), &poses);
    let r = run(&ScoreInput::new(t));
    assert_eq!(r.scores.jd, 5.0);
    assert_eq!(r.scores.cpc, 5.0); // default weights 1
    assert_eq!(r.series.as_ref().unwrap().jd, vec![0.0, 2.5, 2.5]);
    // weights (2, 1, 0.5): step 1: 2 + 0.5 + 0.5 = 3; step 2: 1 + 0 + 1 = 2
    let input = ScoreInput {
        joint_weights: Some(&[2.0, 1.0, 0.5]),
        ..ScoreInput::new(t)
    };
    let r = run(&input);
    assert_eq!(r.scores.cpc, 5.0 * 1.0);
    assert_eq!(r.series.unwrap().cpc, vec![0.0, 3.0, 2.0]);
    let input = ScoreInput {
        joint_weights: Some(&[0.0, 0.0, 1.0]),
        ..ScoreInput::new(t)
    };
    assert_eq!(run(&input).scores.cpc, 3.0);
    // no tool motion
    assert_eq!((r.scores.cd, r.scores.oc), (0.0, 0.0));
}

#[test]
fn pure_rotation_about_fixed_axis() {
    // angles about z: steps 0.3, 0.2, 0.7, 0 → geodesic Σ = 1.2, OC = Σ halves = 0.6
    let angles = [0.0, 0.3, 0.1, 0.8, 0.8];
    let mut poses: Vec<_> = angles
        .iter()
        .map(|&a| {
            Isometry3::from_parts(
                Translation3::new(0.2, 0.0, 1.0),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a),
            )
        })
        .collect();
    // the same orientation written as −q must not change anything
    poses[2].rotation = UnitQuaternion::new_unchecked(-poses[2].rotation.into_inner());
    let q = vec![vec![0.0]; 5];
    let s = scores_of(&q, &poses);
    assert!((s.oc - 0.6).abs() < EPS, "{}", s.oc);
    assert!((s.oc_geodesic - 1.2).abs() < EPS);
    assert_eq!(s.cd, 0.0);
    // across ±π about an oblique axis: 3.0 → 3.4 → −2.8 (= 3.483…) are steps 0.4, 0.083…
    let axis = nalgebra::Unit::new_normalize(Vector3::new(1.0, -2.0, 0.5));
    let a = [3.0, 3.4, -2.8];
    let poses: Vec<_> = a
        .iter()
        .map(|&x| {
            Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&axis, x),
            )
        })
        .collect();
    let s = scores_of(&vec![vec![0.0]; 3], &poses);
    let want = 0.4 + (2.0 * std::f64::consts::PI - 2.8 - 3.4);
    assert!(
        (s.oc_geodesic - want).abs() < 1e-12,
        "{} vs {want}",
        s.oc_geodesic
    );
}

#[test]
fn cartesian_straight_line_cd_is_its_length() {
    let dir = Vector3::new(1.0, 2.0, -2.0) / 3.0; // unit
    let ts = [0.0, 0.1, 0.5, 0.55, 2.0];
    let poses: Vec<_> = ts
        .iter()
        .map(|&t| Isometry3::translation(dir.x * t, dir.y * t, dir.z * t))
        .collect();
    let s = scores_of(&vec![vec![0.0]; 5], &poses);
    assert!((s.cd - 2.0).abs() < EPS);
    // back and forth counts both ways
    let poses = [at(0.0, 0.0, 0.0), at(1.0, 0.0, 0.0), at(0.0, 0.0, 0.0)];
    assert_eq!(scores_of(&vec![vec![0.0]; 3], &poses).cd, 2.0);
}

/// Linear series, exact in binary, with waypoint `k` displaced.
fn spike(n: usize, k: usize) -> (Vec<Vec<f64>>, Vec<Isometry3<f64>>) {
    let mut q: Vec<Vec<f64>> = (0..n).map(|i| vec![0.5 * i as f64, -0.25 * i as f64]).collect();
    q[k][0] += 0.5;
    q[k][1] += 0.25;
    let mut poses: Vec<_> = (0..n).map(|i| at(0.25 * i as f64, 0.0, 1.0)).collect();
    poses[k].translation.vector.y += 0.5;
    (q, poses)
}

#[test]
fn jerk_spike_by_hand() {
    let (q, poses) = spike(12, 4);
    let r = run(&ScoreInput::new(TrajectoryData::new(Rows::Nested(&q), &poses)));
    let s = r.scores;
    let se = r.series.unwrap();
    // Δ³ = (1, −3, 3, −1)·d at waypoints 4..7; d = 0.5 and 0.25 → JJ = 8·0.75
    assert_eq!(s.jj, 6.0);
    let mut want = vec![0.0; 12];
    want[4..8].copy_from_slice(&[0.75, 2.25, 2.25, 0.75]);
    assert_eq!(se.joint_jerk, want);
    assert_eq!(s.jmj, 2.25);
    // one peak: the flat top 5–6, reported at its middle rounded down
    assert_eq!(
        se.joint_peaks,
        vec![CountedPeak {
            index: 5,
            height: 2.25,
            slowdown: 3.0 * 2.25f64.log10() + 4.0
        }]
    );
    assert_eq!(s.joint_peak_count, 1);
    assert!((s.jjp - (3.0 * 2.25f64.log10() + 4.0)).abs() < EPS);
    // Cartesian: d = 0.5 m in y → CJ = 4, CMJ = 1.5
    assert_eq!(s.cj, 4.0);
    assert_eq!(s.cmj, 1.5);
    let p = JerkPeakParams::default();
    assert_eq!(
        se.cartesian_peaks,
        vec![CountedPeak {
            index: 5,
            height: 1.5,
            slowdown: p.cartesian_sqrt_gain * 1.5f64.sqrt() + p.cartesian_offset
        }]
    );
    assert!((s.cjp - (p.cartesian_sqrt_gain * 1.5f64.sqrt() + p.cartesian_offset)).abs() < 1e-9);
    // configurable coefficients
    let params = ScoreParams {
        peaks: JerkPeakParams {
            joint_log_gain: 1.0,
            joint_offset: 0.0,
            cartesian_sqrt_gain: 2.0,
            cartesian_offset: 1.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let s = score(
        &ScoreInput::new(TrajectoryData::new(Rows::Nested(&q), &poses)),
        &params,
    )
    .unwrap()
    .scores;
    assert!((s.jjp - 2.25f64.log10()).abs() < EPS);
    assert!((s.cjp - (2.0 * 1.5f64.sqrt() + 1.0)).abs() < EPS);
}

#[test]
fn spike_near_the_start_is_an_edge_peak() {
    // displacement at waypoint 1: Δ³ = 3d at 3, −d at 4 → series starts on its maximum
    let (q, poses) = spike(8, 1);
    let t = TrajectoryData::new(Rows::Nested(&q), &poses);
    let r = run(&ScoreInput::new(t));
    assert_eq!(r.series.unwrap().joint_jerk[3..5], [2.25, 0.75]);
    assert_eq!(r.scores.joint_peak_count, 0);
    assert_eq!(r.scores.jjp, 0.0);
    let params = ScoreParams {
        peaks: JerkPeakParams {
            edge_peaks: true,
            ..Default::default()
        },
        series: true,
        ..Default::default()
    };
    let r = score(&ScoreInput::new(t), &params).unwrap();
    let peaks = r.series.unwrap().joint_peaks;
    assert_eq!(
        peaks.iter().map(|p| (p.index, p.height)).collect::<Vec<_>>(),
        vec![(3, 2.25)]
    );
}

#[test]
fn smooth_path_has_no_peaks_despite_round_off() {
    let n = 200;
    let q: Vec<Vec<f64>> = (0..n)
        .map(|i| vec![0.1 * i as f64, 0.013 * i as f64 + 0.7])
        .collect();
    let poses: Vec<_> = (0..n).map(|i| at(0.01 * i as f64, 0.3, 0.0)).collect();
    let s = scores_of(&q, &poses);
    assert!(s.jj < 1e-9 && s.cj < 1e-9);
    assert_eq!((s.joint_peak_count, s.cartesian_peak_count), (0, 0));
    assert_eq!((s.jjp, s.cjp), (0.0, 0.0));
}

#[test]
fn rdm_with_hand_placed_points() {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let pts = vec![
        vec![p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0)],
        vec![p(0.1, 0.0, 0.0), p(1.0, 0.5, 0.0), p(1.0, 1.0, 0.2)], // 0.1, 0.5, 0.2
        vec![p(0.1, 0.0, 1.0), p(1.0, 0.5, 0.0), p(1.0, 1.3, 0.2)], // 1.0, 0, 0.3
    ];
    let q = vec![vec![0.0]; 3];
    let poses = still_poses(3);
    let t = TrajectoryData {
        robot_points: Some(Rows::Nested(&pts)),
        ..TrajectoryData::new(Rows::Nested(&q), &poses)
    };
    let r = run(&ScoreInput::new(t));
    assert!((r.scores.rdm.unwrap() - 1.5).abs() < EPS);
    let se = r.series.unwrap().rdm.unwrap();
    assert!((se[1] - 0.5).abs() < EPS && (se[2] - 1.0).abs() < EPS);
    // the same points as one flat buffer
    let flat: Vec<_> = pts.concat();
    let t = TrajectoryData {
        robot_points: Some(Rows::Flat {
            values: &flat,
            width: 3,
        }),
        ..t
    };
    assert!((run(&ScoreInput::new(t)).scores.rdm.unwrap() - 1.5).abs() < EPS);
    // without points there is no RDM
    assert_eq!(scores_of(&q, &poses).rdm, None);
}

#[test]
fn short_trajectories_have_documented_answers() {
    for n in 0..4 {
        let q: Vec<Vec<f64>> = (0..n).map(|i| vec![i as f64, 2.0 * i as f64]).collect();
        let poses: Vec<_> = (0..n).map(|i| at(i as f64, 0.0, 0.0)).collect();
        let r = run(&ScoreInput::new(TrajectoryData::new(Rows::Nested(&q), &poses)));
        let s = r.scores;
        assert_eq!(s.waypoints, n);
        assert_eq!(
            (s.jj, s.cj, s.jmj, s.cmj, s.jjp, s.cjp),
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!((s.joint_peak_count, s.cartesian_peak_count), (0, 0));
        let steps = n.saturating_sub(1) as f64;
        assert_eq!((s.cd, s.jd), (steps, 3.0 * steps));
        assert_eq!(r.series.unwrap().joint_jerk.len(), n);
    }
}

#[test]
fn timestamps_scale_only_the_extra_jerk() {
    let (q, poses) = spike(10, 4);
    let ts: Vec<f64> = (0..10).map(|i| 0.5 * i as f64).collect();
    let plain = scores_of(&q, &poses);
    let t = TrajectoryData {
        timestamps: Some(&ts),
        ..TrajectoryData::new(Rows::Nested(&q), &poses)
    };
    let r = run(&ScoreInput::new(t));
    let s = r.scores;
    assert_eq!(
        (s.jj, s.cj, s.jmj, s.jjp),
        (plain.jj, plain.cj, plain.jmj, plain.jjp)
    );
    let ts_j = s.time_scaled.unwrap();
    assert!((ts_j.jj - plain.jj / 0.125).abs() < 1e-9);
    assert!((ts_j.cmj - plain.cmj / 0.125).abs() < 1e-9);
    assert_eq!(r.series.unwrap().joint_jerk_rate.unwrap()[5], 2.25 / 0.125);
    assert!(plain.time_scaled.is_none());
}

#[test]
fn series_sum_to_the_totals() {
    let n = 40;
    let q: Vec<Vec<f64>> = (0..n)
        .map(|i| vec![(0.3 * i as f64).sin(), (0.17 * i as f64).cos()])
        .collect();
    let poses: Vec<_> = (0..n)
        .map(|i| {
            let x = i as f64;
            Isometry3::new(
                Vector3::new(x.sin(), 0.1 * x, x.cos()),
                Vector3::new(0.1 * x, -0.05 * x, 0.3),
            )
        })
        .collect();
    let r = run(&ScoreInput::new(TrajectoryData::new(Rows::Nested(&q), &poses)));
    let se = r.series.unwrap();
    let sum = |v: &[f64]| v.iter().sum::<f64>();
    let s = r.scores;
    assert!((sum(&se.cd) - s.cd).abs() < 1e-9);
    assert!((sum(&se.jd) - s.jd).abs() < 1e-9);
    assert!((sum(&se.oc) - s.oc).abs() < 1e-9);
    assert!((sum(&se.joint_jerk) - s.jj).abs() < 1e-9);
    assert!((sum(&se.cartesian_jerk) - s.cj).abs() < 1e-9);
    assert_eq!(se.joint_jerk.iter().copied().fold(0.0, f64::max), s.jmj);
    let jjp: f64 = se
        .joint_peaks
        .iter()
        .map(|p| {
            let defaults = JerkPeakParams::default();
            let own = defaults.joint_log_gain * p.height.log10() + defaults.joint_offset;
            assert_eq!(p.slowdown, own.max(defaults.slowdown_floor));
            p.slowdown
        })
        .sum();
    assert!((jjp - s.jjp).abs() < 1e-9);
    assert_eq!(se.joint_peaks.len(), s.joint_peak_count);
    assert!(s.joint_peak_count > 0);
    // the peaks are local maxima of the series
    for p in &se.joint_peaks {
        assert!(se.joint_jerk[p.index - 1] <= p.height && se.joint_jerk[p.index + 1] <= p.height);
        assert_eq!(se.joint_jerk[p.index], p.height);
    }
}

#[test]
fn flat_and_nested_joints_agree() {
    let (q, poses) = spike(9, 5);
    let flat: Vec<f64> = q.concat();
    let a = scores_of(&q, &poses);
    let b = run(&ScoreInput::new(TrajectoryData::new(
        Rows::Flat {
            values: &flat,
            width: 2,
        },
        &poses,
    )))
    .scores;
    assert_eq!(a, b);
}

#[test]
fn cycle_time_through_score() {
    let q = vec![vec![0.0, 0.0], vec![1.0, 0.5], vec![1.0, 1.0]];
    let poses = still_poses(3);
    let input = ScoreInput {
        limits: Some(JointLimits {
            v_max: &[2.0, 0.25],
            a_max: None,
        }),
        ..ScoreInput::new(TrajectoryData::new(Rows::Nested(&q), &poses))
    };
    let r = run(&input);
    assert_eq!(r.scores.cycle_time, Some(4.0)); // 2 s + 2 s
    let ct = r.cycle_time.unwrap();
    assert_eq!(ct.potentials.len(), 1);
    // direct: max(1/2, 1/0.25) = 4 s = via → no potential
    assert!(!ct.potentials[0].has_potential);
}

// ---- bad input: each rejected with the right variant ----

fn err(input: &ScoreInput<'_>) -> ScoreError {
    score(input, &ScoreParams::default()).expect_err("must be rejected")
}

#[test]
fn bad_inputs_are_rejected_with_their_variant() {
    let poses = still_poses(3);
    let good = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![2.0, 0.0]];
    let tr = |q| TrajectoryData::new(Rows::Nested(q), &poses);

    let ragged = vec![vec![0.0, 0.0], vec![1.0], vec![2.0, 0.0]];
    assert_eq!(
        err(&ScoreInput::new(tr(&ragged))),
        ScoreError::RaggedRow {
            field: ScoreField::Joints,
            index: 1,
            expected: 2,
            found: 1
        }
    );
    let nan = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![2.0, f64::NAN]];
    assert!(matches!(
        err(&ScoreInput::new(tr(&nan))),
        ScoreError::NonFinite {
            field: ScoreField::Joints,
            index: 2,
            component: 1,
            ..
        }
    ));
    let input = ScoreInput {
        dof: Some(3),
        ..ScoreInput::new(tr(&good))
    };
    assert_eq!(
        err(&input),
        ScoreError::WrongJointCount {
            index: 0,
            expected: 3,
            found: 2
        }
    );
    let input = ScoreInput {
        dof: Some(2),
        ..ScoreInput::new(tr(&ragged))
    };
    assert_eq!(
        err(&input),
        ScoreError::WrongJointCount {
            index: 1,
            expected: 2,
            found: 1
        }
    );
    let flat = [0.0; 5];
    let t = TrajectoryData::new(
        Rows::Flat {
            values: &flat,
            width: 2,
        },
        &poses,
    );
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::FlatShape {
            field: ScoreField::Joints,
            len: 5,
            width: 2
        }
    );
    let t = TrajectoryData::new(
        Rows::Flat {
            values: &flat,
            width: 0,
        },
        &poses,
    );
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::FlatShape { width: 0, .. }
    ));
    let empty_rows = vec![vec![]; 3];
    assert_eq!(err(&ScoreInput::new(tr(&empty_rows))), ScoreError::NoJoints);

    // timestamps
    let ts = [0.0, 1.0, 1.0];
    let t = TrajectoryData {
        timestamps: Some(&ts),
        ..tr(&good)
    };
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::NonIncreasingTimestamp {
            index: 2,
            previous: 1.0,
            value: 1.0
        }
    );
    let ts = [0.0, 2.0, 1.0];
    let t = TrajectoryData {
        timestamps: Some(&ts),
        ..tr(&good)
    };
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::NonIncreasingTimestamp { index: 2, .. }
    ));
    let ts = [0.0, f64::INFINITY, 3.0];
    let t = TrajectoryData {
        timestamps: Some(&ts),
        ..tr(&good)
    };
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::NonFinite {
            field: ScoreField::Timestamps,
            index: 1,
            ..
        }
    ));
    let ts = [0.0, 1.0];
    let t = TrajectoryData {
        timestamps: Some(&ts),
        ..tr(&good)
    };
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::LengthMismatch {
            field: ScoreField::Timestamps,
            expected: 3,
            found: 2
        }
    );

    // poses
    let t = TrajectoryData::new(Rows::Nested(&good), &poses[..2]);
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::LengthMismatch {
            field: ScoreField::Poses,
            expected: 3,
            found: 2
        }
    );
    let mut bad_poses = poses.clone();
    bad_poses[1].translation.vector.z = f64::NAN;
    let t = TrajectoryData::new(Rows::Nested(&good), &bad_poses);
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::NonFinite {
            field: ScoreField::Poses,
            index: 1,
            component: 2,
            ..
        }
    ));
    let mut bad_poses = poses.clone();
    bad_poses[2].rotation = UnitQuaternion::new_unchecked(Quaternion::new(2.0, 0.0, 0.0, 0.0));
    let t = TrajectoryData::new(Rows::Nested(&good), &bad_poses);
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::NonUnitQuaternion { index: 2, norm: 2.0 }
    );
    let mut bad_poses = poses.clone();
    bad_poses[0].rotation = UnitQuaternion::new_unchecked(Quaternion::new(1.0, f64::NAN, 0.0, 0.0));
    let t = TrajectoryData::new(Rows::Nested(&good), &bad_poses);
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::NonFinite {
            field: ScoreField::Poses,
            index: 0,
            component: 3,
            ..
        }
    ));

    // robot points
    let o = Point3::origin();
    let pts = vec![vec![o, o], vec![o], vec![o, o]];
    let t = TrajectoryData {
        robot_points: Some(Rows::Nested(&pts)),
        ..tr(&good)
    };
    assert_eq!(
        err(&ScoreInput::new(t)),
        ScoreError::RaggedRow {
            field: ScoreField::RobotPoints,
            index: 1,
            expected: 2,
            found: 1
        }
    );
    let pts = vec![vec![o], vec![o]];
    let t = TrajectoryData {
        robot_points: Some(Rows::Nested(&pts)),
        ..tr(&good)
    };
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::LengthMismatch {
            field: ScoreField::RobotPoints,
            ..
        }
    ));
    let pts = vec![vec![o], vec![Point3::new(0.0, f64::NEG_INFINITY, 0.0)], vec![o]];
    let t = TrajectoryData {
        robot_points: Some(Rows::Nested(&pts)),
        ..tr(&good)
    };
    assert!(matches!(
        err(&ScoreInput::new(t)),
        ScoreError::NonFinite {
            field: ScoreField::RobotPoints,
            index: 1,
            component: 1,
            ..
        }
    ));

    // weights and limits
    let input = ScoreInput {
        joint_weights: Some(&[1.0]),
        ..ScoreInput::new(tr(&good))
    };
    assert_eq!(
        err(&input),
        ScoreError::LengthMismatch {
            field: ScoreField::JointWeights,
            expected: 2,
            found: 1
        }
    );
    let input = ScoreInput {
        joint_weights: Some(&[1.0, -0.5]),
        ..ScoreInput::new(tr(&good))
    };
    assert!(matches!(
        err(&input),
        ScoreError::InvalidValue {
            field: ScoreField::JointWeights,
            index: 1,
            ..
        }
    ));
    let input = ScoreInput {
        limits: Some(JointLimits {
            v_max: &[1.0, f64::INFINITY],
            a_max: None,
        }),
        ..ScoreInput::new(tr(&good))
    };
    assert!(matches!(
        err(&input),
        ScoreError::InvalidValue {
            field: ScoreField::VMax,
            index: 1,
            ..
        }
    ));
    let input = ScoreInput {
        limits: Some(JointLimits {
            v_max: &[1.0, 1.0],
            a_max: Some(&[1.0]),
        }),
        ..ScoreInput::new(tr(&good))
    };
    assert!(matches!(
        err(&input),
        ScoreError::LengthMismatch {
            field: ScoreField::AMax,
            ..
        }
    ));

    // parameters
    let params = ScoreParams {
        peaks: JerkPeakParams {
            joint_offset: f64::INFINITY,
            ..Default::default()
        },
        ..Default::default()
    };
    assert!(matches!(
        score(&ScoreInput::new(tr(&good)), &params),
        Err(ScoreError::InvalidParam {
            name: ScoreParam::JointOffset,
            ..
        })
    ));
}

#[test]
fn errors_print_the_field_and_index() {
    let e = ScoreError::NonIncreasingTimestamp {
        index: 4,
        previous: 1.5,
        value: 1.0,
    };
    assert_eq!(
        e.to_string(),
        "timestamps[4] = 1 s does not exceed timestamps[3] = 1.5 s"
    );
    let e = ScoreError::RaggedRow {
        field: ScoreField::Joints,
        index: 7,
        expected: 6,
        found: 5,
    };
    assert!(e.to_string().contains("joints[7]"));
}

// ---- invariances ----

/// Joints, poses, robot points, CPC weights.
type Trajectory = (
    Vec<Vec<f64>>,
    Vec<Isometry3<f64>>,
    Vec<Vec<Point3<f64>>>,
    Vec<f64>,
);

fn arb_trajectory() -> impl Strategy<Value = Trajectory> {
    (2usize..25, 1usize..7, 0usize..5).prop_flat_map(|(n, m, k)| {
        (
            prop::collection::vec(prop::collection::vec(-3.0..3.0f64, m), n),
            prop::collection::vec(
                (
                    prop::array::uniform3(-2.0..2.0f64),
                    prop::array::uniform3(-3.0..3.0f64),
                ),
                n,
            ),
            prop::collection::vec(prop::collection::vec(prop::array::uniform3(-1.0..1.0f64), k), n),
            prop::collection::vec(0.0..5.0f64, m),
        )
            .prop_map(|(q, poses, pts, w)| {
                let poses = poses
                    .into_iter()
                    .map(|(t, r)| Isometry3::new(Vector3::from(t), Vector3::from(r)))
                    .collect();
                let pts = pts
                    .into_iter()
                    .map(|row| row.into_iter().map(Point3::from).collect())
                    .collect();
                (q, poses, pts, w)
            })
    })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #[test]
    fn reversing_a_path_keeps_the_criteria((q, poses, pts, w) in arb_trajectory()) {
        let fwd = TrajectoryData { robot_points: Some(Rows::Nested(&pts)), ..TrajectoryData::new(Rows::Nested(&q), &poses) };
        let (mut rq, mut rp, mut rpts) = (q.clone(), poses.clone(), pts.clone());
        rq.reverse();
        rp.reverse();
        rpts.reverse();
        let bwd = TrajectoryData { robot_points: Some(Rows::Nested(&rpts)), ..TrajectoryData::new(Rows::Nested(&rq), &rp) };
        let a = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(fwd) }, &ScoreParams::default()).unwrap().scores;
        let b = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(bwd) }, &ScoreParams::default()).unwrap().scores;
        for c in [Criterion::Cd, Criterion::Jd, Criterion::Oc, Criterion::OcGeodesic, Criterion::Cpc, Criterion::Rdm,
                  Criterion::Jj, Criterion::Cj, Criterion::Jmj, Criterion::Cmj] {
            let (x, y) = (a.get(c).unwrap(), b.get(c).unwrap());
            prop_assert!(close(x, y), "{c}: {x} vs {y}");
        }
    }

    #[test]
    fn quaternion_signs_do_not_matter((q, poses, _pts, _w) in arb_trajectory(), flips in prop::collection::vec(any::<bool>(), 25)) {
        let flipped: Vec<_> = poses.iter().zip(&flips).map(|(p, &f)| {
            let mut p = *p;
            if f { p.rotation = UnitQuaternion::new_unchecked(-p.rotation.into_inner()); }
            p
        }).collect();
        let a = scores_of(&q, &poses);
        let b = scores_of(&q, &flipped);
        prop_assert!(close(a.oc, b.oc));
    }

    #[test]
    fn oc_is_a_half_of_the_geodesic_and_at_most_the_sum_of_pi_halves((q, poses, _pts, _w) in arb_trajectory()) {
        let s = scores_of(&q, &poses);
        prop_assert!(close(s.oc_geodesic, 2.0 * s.oc));
        prop_assert!(s.oc <= (poses.len() - 1) as f64 * std::f64::consts::FRAC_PI_2 + 1e-12);
    }

    #[test]
    fn any_input_is_answered_without_panic(
        rows in prop::collection::vec(prop::collection::vec(prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -1e300..1e300f64], 0..4), 0..8),
        npose in 0usize..8,
        ts in prop::option::of(prop::collection::vec(-1.0..1.0f64, 0..8)),
        dof in prop::option::of(0usize..4),
        w in prop::option::of(prop::collection::vec(-1.0..2.0f64, 0..4)),
        v in prop::collection::vec(-1.0..2.0f64, 0..4),
    ) {
        let poses = still_poses(npose);
        let t = TrajectoryData { timestamps: ts.as_deref(), ..TrajectoryData::new(Rows::Nested(&rows), &poses) };
        let input = ScoreInput { dof, joint_weights: w.as_deref(), limits: Some(JointLimits { v_max: &v, a_max: None }), ..ScoreInput::new(t) };
        let _ = score(&input, &ScoreParams { series: true, ..Default::default() });
    }
}

/// The S0 formulas written out literally (acos of the printed dot product,
/// nested sums over index ranges), to check the single pass against.
#[allow(clippy::needless_range_loop)] // indices on purpose: it mirrors the formulas
fn reference(q: &[Vec<f64>], poses: &[Isometry3<f64>], pts: &[Vec<Point3<f64>>], w: &[f64]) -> [f64; 10] {
    let n = q.len();
    let m = q[0].len();
    let p = |i: usize| poses[i].translation.vector;
    let (mut cd, mut jd, mut oc, mut cpc, mut rdm) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 1..n {
        cd += (p(i) - p(i - 1)).norm();
        for j in 0..m {
            jd += (q[i][j] - q[i - 1][j]).abs();
            cpc += w[j] * (q[i][j] - q[i - 1][j]).abs();
        }
        let (a, b) = (poses[i].rotation.coords, poses[i - 1].rotation.coords);
        let dot = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
        oc += dot.abs().clamp(-1.0, 1.0).acos();
        let mut mx: f64 = 0.0;
        for k in 0..pts[i].len() {
            mx = mx.max((pts[i][k] - pts[i - 1][k]).norm());
        }
        rdm += mx;
    }
    let (mut jj, mut cj, mut jmj, mut cmj) = (0.0, 0.0, 0.0f64, 0.0f64);
    for i in 3..n {
        let mut s = 0.0;
        for j in 0..m {
            s += (q[i][j] - 3.0 * q[i - 1][j] + 3.0 * q[i - 2][j] - q[i - 3][j]).abs();
        }
        let c = (p(i) - 3.0 * p(i - 1) + 3.0 * p(i - 2) - p(i - 3)).norm();
        jj += s;
        cj += c;
        jmj = jmj.max(s);
        cmj = cmj.max(c);
    }
    [cd, jd, oc, 2.0 * oc, cpc, rdm, jj, cj, jmj, cmj]
}

proptest! {
    #[test]
    fn single_pass_matches_the_printed_formulas((q, poses, pts, w) in arb_trajectory()) {
        let t = TrajectoryData { robot_points: Some(Rows::Nested(&pts)), ..TrajectoryData::new(Rows::Nested(&q), &poses) };
        let s = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(t) }, &ScoreParams::default()).unwrap().scores;
        let want = reference(&q, &poses, &pts, &w);
        let got = [s.cd, s.jd, s.oc, s.oc_geodesic, s.cpc, s.rdm.unwrap(), s.jj, s.cj, s.jmj, s.cmj];
        for (k, (g, r)) in got.iter().zip(want).enumerate() {
            // acos near 1 loses digits: the OC terms get a looser bound
            let tol = if k == 2 || k == 3 { 1e-6 } else { 1e-9 };
            prop_assert!((g - r).abs() <= tol * (1.0 + r.abs()), "criterion {k}: {g} vs {r}");
        }
    }

    #[test]
    fn ptp_time_is_subadditive(
        a in prop::collection::vec(-3.0..3.0f64, 3),
        b in prop::collection::vec(-3.0..3.0f64, 3),
        c in prop::collection::vec(-3.0..3.0f64, 3),
        v in prop::collection::vec(0.1..3.0f64, 3),
        acc in prop::option::of(prop::collection::vec(0.1..10.0f64, 3)),
    ) {
        let lim = JointLimits { v_max: &v, a_max: acc.as_deref() };
        let q: Vec<f64> = [a, b, c].concat();
        let ct = crate::score::cycle_time(Rows::Flat { values: &q, width: 3 }, &lim, &Default::default()).unwrap();
        let tp = ct.potentials[0];
        prop_assert!(tp.gain >= -1e-12, "{tp:?}");
        prop_assert!((ct.total - tp.via).abs() < 1e-12);
    }
}
