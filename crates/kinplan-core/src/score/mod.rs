//! Trajectory quality: the S0 criteria (CD, JD, OC, CPC, RDM, pseudo-jerk and
//! its peaks), the S2 PTP cycle time with time potentials, and set comparison.
//!
//! Pure functions over already computed data (joints, tool poses, robot
//! points); `robot_points` alone turns a robot model into those data. No
//! transport types. Spec: docs/scoring.md.

mod compare;
mod criteria;
mod cycle_time;
mod error;
mod input;
mod jerk;
mod limits;
mod robot_points;
mod scoring;

pub use compare::{Comparison, LabelledSet, SetSummary, Stat, compare, summarize};
pub use criteria::{
    Criterion, Scores, TimeScaledJerk, max_point_displacement, orientation_geodesic_angle,
    orientation_half_angle,
};
pub use cycle_time::{
    CycleTime, CycleTimeParams, SegmentTime, TimePotential, cycle_time, ptp_joint_time, ptp_segment_time,
};
pub use error::{ScoreError, ScoreField, ScoreParam};
pub use input::{JointLimits, QUATERNION_NORM_TOLERANCE, Rows, ScoreInput, Shape, TrajectoryData};
pub use jerk::{
    JerkPeakParams, Peak, cartesian_slowdown, find_peaks, joint_slowdown, third_derivative,
    third_derivative_weights, third_difference,
};
pub use limits::{MissingSpeedLimit, OwnedLimits, limits_for};
pub use robot_points::{ChainSamples, PointSet, robot_link_points, sample_chain, shape_extreme_points};
pub use scoring::{CountedPeak, ScoreParams, ScoreReport, Series, score};
