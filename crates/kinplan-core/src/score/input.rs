//! Input model: a trajectory's waypoints (joints, tool poses, robot points,
//! timestamps) plus per-joint weights and limits, and its validation.

use nalgebra::{Isometry3, Point3};

use super::error::{ScoreError, ScoreField};

/// Tolerance on `|‖quaternion‖ − 1|` accepted by validation.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-6;

/// Rows of equal width, either nested (one `Vec` per waypoint, as a decoded
/// `JointTrajectory` gives them) or one flat row-major buffer (as an `n × m`
/// array gives it). Validation rejects ragged nested rows and flat buffers
/// that do not split into whole rows.
#[derive(Debug, Clone, Copy)]
pub enum Rows<'a, T> {
    /// One row per waypoint.
    Nested(&'a [Vec<T>]),
    /// Row-major `len / width` rows of `width` values.
    Flat {
        /// All values, row after row.
        values: &'a [T],
        /// Values per row.
        width: usize,
    },
}

impl<'a, T> Rows<'a, T> {
    /// Number of rows (a flat buffer with zero width has none).
    pub fn len(&self) -> usize {
        match self {
            Rows::Nested(rows) => rows.len(),
            Rows::Flat { values, width } => values.len().checked_div(*width).unwrap_or(0),
        }
    }

    /// `true` without rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `i`, or `None` past the end.
    pub fn get(&self, i: usize) -> Option<&'a [T]> {
        match self {
            Rows::Nested(rows) => rows.get(i).map(Vec::as_slice),
            Rows::Flat { values, width } => {
                if i >= self.len() {
                    return None;
                }
                let start = i.checked_mul(*width)?;
                values.get(start..start.checked_add(*width)?)
            }
        }
    }

    /// Row `i` of validated rows (callers index only below `len()`).
    #[inline]
    pub(crate) fn row(&self, i: usize) -> &'a [T] {
        match self {
            Rows::Nested(rows) => &rows[i],
            Rows::Flat { values, width } => &values[i * width..(i + 1) * width],
        }
    }

    /// Checks the shape: flat buffers split into whole rows, nested rows all
    /// as long as row 0. Returns the row width (`None` without rows).
    fn check_shape(&self, field: ScoreField) -> Result<Option<usize>, ScoreError> {
        match self {
            Rows::Flat { values, width } => {
                if *width == 0 {
                    if values.is_empty() {
                        return Ok(None);
                    }
                    return Err(ScoreError::FlatShape {
                        field,
                        len: values.len(),
                        width: 0,
                    });
                }
                if values.len() % width != 0 {
                    return Err(ScoreError::FlatShape {
                        field,
                        len: values.len(),
                        width: *width,
                    });
                }
                Ok((!values.is_empty()).then_some(*width))
            }
            Rows::Nested(rows) => {
                let Some(first) = rows.first() else {
                    return Ok(None);
                };
                let expected = first.len();
                for (index, row) in rows.iter().enumerate() {
                    if row.len() != expected {
                        return Err(ScoreError::RaggedRow {
                            field,
                            index,
                            expected,
                            found: row.len(),
                        });
                    }
                }
                Ok(Some(expected))
            }
        }
    }
}

/// One trajectory: `n` waypoints, each with a joint vector, the tool pose and
/// optionally points on the robot, plus optional timestamps.
///
/// Frames and units: poses and points in the robot base frame, metres;
/// joints in rad (revolute) or m (prismatic); timestamps in seconds, strictly
/// increasing.
#[derive(Debug, Clone, Copy)]
pub struct TrajectoryData<'a> {
    /// Joint vector per waypoint (`n` rows of `m`).
    pub joints: Rows<'a, f64>,
    /// Tool pose per waypoint (`n`), FK of `joints`.
    pub poses: &'a [Isometry3<f64>],
    /// Points on the robot per waypoint for RDM (`n` rows, the same points in
    /// the same order in every row: link-frame origins, collision-shape
    /// vertices …). `None`: RDM is not computed.
    pub robot_points: Option<Rows<'a, Point3<f64>>>,
    /// Time of each waypoint (`n`, strictly increasing), seconds. Used only for
    /// the time-scaled jerk; the named criteria follow S0 with unit steps.
    pub timestamps: Option<&'a [f64]>,
}

impl<'a> TrajectoryData<'a> {
    /// A trajectory from joints and poses only.
    pub fn new(joints: Rows<'a, f64>, poses: &'a [Isometry3<f64>]) -> Self {
        Self {
            joints,
            poses,
            robot_points: None,
            timestamps: None,
        }
    }

    /// Number of waypoints `n`.
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// `true` without waypoints.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Checks shapes, finiteness, unit quaternions and timestamp order.
    /// `dof`: when set, every joint row must have exactly this many joints.
    ///
    /// ```
    /// use kinplan_core::score::{Rows, ScoreError, TrajectoryData};
    /// use nalgebra::Isometry3;
    /// let q = vec![vec![0.0, 1.0], vec![0.5]];
    /// let poses = [Isometry3::identity(); 2];
    /// let t = TrajectoryData::new(Rows::Nested(&q), &poses);
    /// assert!(matches!(t.validate(None), Err(ScoreError::RaggedRow { index: 1, .. })));
    /// ```
    pub fn validate(&self, dof: Option<usize>) -> Result<Shape, ScoreError> {
        let n = self.joints.len();
        let joints = validate_joint_rows(&self.joints, dof)?;

        if self.poses.len() != n {
            return Err(ScoreError::LengthMismatch {
                field: ScoreField::Poses,
                expected: n,
                found: self.poses.len(),
            });
        }
        // Fast branch-free scan first; the detailed scan only names the culprit.
        let poses_ok = self.poses.iter().fold(true, |ok, p| {
            let (t, c) = (&p.translation.vector, &p.rotation.coords);
            let n2 = c.norm_squared();
            ok & t.x.is_finite()
                & t.y.is_finite()
                & t.z.is_finite()
                & n2.is_finite()
                & ((n2 - 1.0).abs() <= QUATERNION_NORM_TOLERANCE)
        });
        if !poses_ok {
            for (i, pose) in self.poses.iter().enumerate() {
                let t = pose.translation.vector;
                let c = pose.rotation.coords; // i, j, k, w
                check_finite(ScoreField::Poses, i, t.iter().chain(c.iter()).copied())?;
                let norm = c.norm();
                if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                    return Err(ScoreError::NonUnitQuaternion { index: i, norm });
                }
            }
        }

        let mut points = None;
        if let Some(rp) = &self.robot_points {
            if rp.len() != n {
                return Err(ScoreError::LengthMismatch {
                    field: ScoreField::RobotPoints,
                    expected: n,
                    found: rp.len(),
                });
            }
            points = rp.check_shape(ScoreField::RobotPoints)?;
            let points_ok = match rp {
                Rows::Flat { values, .. } => all_points_finite(values),
                Rows::Nested(rows) => rows.iter().fold(true, |ok, r| ok & all_points_finite(r)),
            };
            if !points_ok {
                for i in 0..n {
                    let row = rp.row(i);
                    check_finite(
                        ScoreField::RobotPoints,
                        i,
                        row.iter().flat_map(|p| p.coords.iter().copied()),
                    )?;
                }
            }
        }

        if let Some(ts) = self.timestamps {
            if ts.len() != n {
                return Err(ScoreError::LengthMismatch {
                    field: ScoreField::Timestamps,
                    expected: n,
                    found: ts.len(),
                });
            }
            for (index, &value) in ts.iter().enumerate() {
                if !value.is_finite() {
                    return Err(ScoreError::NonFinite {
                        field: ScoreField::Timestamps,
                        index,
                        component: 0,
                        value,
                    });
                }
            }
            for (index, w) in ts.windows(2).enumerate() {
                if w[1] <= w[0] {
                    return Err(ScoreError::NonIncreasingTimestamp {
                        index: index + 1,
                        previous: w[0],
                        value: w[1],
                    });
                }
            }
        }

        Ok(Shape {
            waypoints: n,
            joints: joints.unwrap_or(0),
            points: points.unwrap_or(0),
        })
    }
}

/// Validated sizes of a trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    /// Waypoints `n`.
    pub waypoints: usize,
    /// Joints `m` (0 for an empty trajectory without `dof`).
    pub joints: usize,
    /// Robot points per waypoint (0 without `robot_points`).
    pub points: usize,
}

/// Per-joint limits for the PTP cycle time (S2 §3.3).
#[derive(Debug, Clone, Copy)]
pub struct JointLimits<'a> {
    /// Maximum speed per joint, rad/s or m/s, finite and > 0.
    pub v_max: &'a [f64],
    /// Maximum acceleration per joint, rad/s² or m/s², > 0 (`+∞` allowed: no
    /// ramp). `None`: ramps are neglected, as S2 does.
    pub a_max: Option<&'a [f64]>,
}

impl JointLimits<'_> {
    /// Checks the lengths (`joints`) and ranges of both limit vectors.
    pub fn validate(&self, joints: usize) -> Result<(), ScoreError> {
        check_per_joint(
            ScoreField::VMax,
            self.v_max,
            joints,
            |v| v.is_finite() && v > 0.0,
            "must be finite and > 0",
        )?;
        if let Some(a) = self.a_max {
            check_per_joint(
                ScoreField::AMax,
                a,
                joints,
                |v| v > 0.0,
                "must be > 0 (+inf allowed)",
            )?;
        }
        Ok(())
    }
}

/// Everything `score` needs: the trajectory, per-joint weights for CPC and
/// optionally joint limits for the cycle time.
#[derive(Debug, Clone, Copy)]
pub struct ScoreInput<'a> {
    /// The trajectory.
    pub trajectory: TrajectoryData<'a>,
    /// The robot's joint count; when set every joint row must match it.
    pub dof: Option<usize>,
    /// CPC weight per joint (`m`, finite, ≥ 0). `None`: all 1.
    pub joint_weights: Option<&'a [f64]>,
    /// Joint limits; when set the report includes the PTP cycle time.
    pub limits: Option<JointLimits<'a>>,
}

impl<'a> ScoreInput<'a> {
    /// Input with default weights and no limits.
    pub fn new(trajectory: TrajectoryData<'a>) -> Self {
        Self {
            trajectory,
            dof: None,
            joint_weights: None,
            limits: None,
        }
    }

    /// Validates the trajectory, the weights and the limits.
    pub fn validate(&self) -> Result<Shape, ScoreError> {
        let shape = self.trajectory.validate(self.dof)?;
        // Per-joint vectors can be checked only once the joint count is known.
        if shape.waypoints > 0 || self.dof.is_some() {
            if let Some(w) = self.joint_weights {
                check_per_joint(
                    ScoreField::JointWeights,
                    w,
                    shape.joints,
                    |v| v.is_finite() && v >= 0.0,
                    "must be finite and >= 0",
                )?;
            }
            if let Some(l) = &self.limits {
                l.validate(shape.joints)?;
            }
        }
        Ok(shape)
    }
}

/// Shape, joint count and finiteness of joint rows; returns the joint count
/// (`None` for no rows and no `dof`).
pub(crate) fn validate_joint_rows(
    joints: &Rows<'_, f64>,
    dof: Option<usize>,
) -> Result<Option<usize>, ScoreError> {
    let n = joints.len();
    if let (Some(expected), Rows::Nested(rows)) = (dof, joints) {
        // With a known robot, a bad row is a wrong joint count, not raggedness.
        for (index, row) in rows.iter().enumerate() {
            if row.len() != expected {
                return Err(ScoreError::WrongJointCount {
                    index,
                    expected,
                    found: row.len(),
                });
            }
        }
    }
    let width = joints.check_shape(ScoreField::Joints)?;
    let m = match (dof, width) {
        (Some(d), Some(w)) if d != w => {
            return Err(ScoreError::WrongJointCount {
                index: 0,
                expected: d,
                found: w,
            });
        }
        (Some(d), _) => Some(d),
        (None, w) => w,
    };
    if n > 0 && m == Some(0) {
        return Err(ScoreError::NoJoints);
    }
    let ok = match joints {
        Rows::Flat { values, .. } => all_finite(values),
        Rows::Nested(rows) => rows.iter().fold(true, |ok, r| ok & all_finite(r)),
    };
    if !ok {
        for i in 0..n {
            check_finite(ScoreField::Joints, i, joints.row(i).iter().copied())?;
        }
    }
    Ok(m)
}

/// Branch-free (vectorizable) "every value is finite".
#[inline]
fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |ok, v| ok & v.is_finite())
}

#[inline]
fn all_points_finite(points: &[Point3<f64>]) -> bool {
    points.iter().fold(true, |ok, p| {
        ok & p.x.is_finite() & p.y.is_finite() & p.z.is_finite()
    })
}

fn check_finite(
    field: ScoreField,
    index: usize,
    values: impl Iterator<Item = f64>,
) -> Result<(), ScoreError> {
    for (component, value) in values.enumerate() {
        if !value.is_finite() {
            return Err(ScoreError::NonFinite {
                field,
                index,
                component,
                value,
            });
        }
    }
    Ok(())
}

fn check_per_joint(
    field: ScoreField,
    values: &[f64],
    joints: usize,
    ok: impl Fn(f64) -> bool,
    reason: &'static str,
) -> Result<(), ScoreError> {
    if values.len() != joints {
        return Err(ScoreError::LengthMismatch {
            field,
            expected: joints,
            found: values.len(),
        });
    }
    for (index, &value) in values.iter().enumerate() {
        if !ok(value) {
            return Err(ScoreError::InvalidValue {
                field,
                index,
                value,
                reason,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_get_and_len_agree() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let r = Rows::Flat { values: &v, width: 3 };
        assert_eq!((r.len(), r.get(1), r.get(2)), (2, Some(&v[3..6]), None));
        let r = Rows::Flat { values: &v, width: 0 };
        assert_eq!((r.len(), r.get(0)), (0, None));
        let nested = vec![vec![1.0], vec![2.0, 3.0]];
        let r = Rows::Nested(&nested);
        assert_eq!((r.len(), r.get(1), r.get(9)), (2, Some(&[2.0, 3.0][..]), None));
        assert!(Rows::<f64>::Nested(&[]).is_empty());
    }

    #[test]
    fn empty_trajectory_is_valid() {
        let t = TrajectoryData::new(
            Rows::Flat {
                values: &[],
                width: 6,
            },
            &[],
        );
        assert_eq!(
            t.validate(Some(6)),
            Ok(Shape {
                waypoints: 0,
                joints: 6,
                points: 0
            })
        );
        assert_eq!(
            t.validate(None),
            Ok(Shape {
                waypoints: 0,
                joints: 0,
                points: 0
            })
        );
    }

    #[test]
    fn slightly_denormalized_quaternion_passes_then_fails() {
        let mut p = [Isometry3::identity()];
        let q = [0.0];
        p[0].rotation =
            nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(1.0 + 0.9e-6, 0.0, 0.0, 0.0));
        let t = TrajectoryData::new(Rows::Flat { values: &q, width: 1 }, &p);
        assert!(t.validate(None).is_ok());
        p[0].rotation =
            nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(1.0 + 2e-6, 0.0, 0.0, 0.0));
        let t = TrajectoryData::new(Rows::Flat { values: &q, width: 1 }, &p);
        assert!(matches!(
            t.validate(None),
            Err(ScoreError::NonUnitQuaternion { index: 0, .. })
        ));
    }

    #[test]
    fn limits_validate_alone() {
        let l = JointLimits {
            v_max: &[1.0, 2.0],
            a_max: Some(&[f64::INFINITY, 3.0]),
        };
        assert!(l.validate(2).is_ok());
        assert!(matches!(
            l.validate(3),
            Err(ScoreError::LengthMismatch {
                field: ScoreField::VMax,
                ..
            })
        ));
        let l = JointLimits {
            v_max: &[1.0, 2.0],
            a_max: Some(&[0.0, 3.0]),
        };
        assert!(matches!(
            l.validate(2),
            Err(ScoreError::InvalidValue {
                field: ScoreField::AMax,
                index: 0,
                ..
            })
        ));
    }
}
