//! Bad input: each rejected with the right variant, naming its field and index.

use super::*;

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
