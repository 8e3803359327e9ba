//! Tests of `score`: hand-computed cases, bad inputs and invariances, one file each.

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

mod bad_input;
mod by_hand;
mod invariance;
