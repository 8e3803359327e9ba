//! Hand-computed cases: every criterion on trajectories small enough to score on paper.

use super::*;

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
