//! IK targets (tool pose or tool position, base frame) and the pose error.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3, Vector6};

use super::{IkError, TargetPart};

/// What the tool should reach, in the chain's base frame (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IkTarget {
    /// Full tool pose: position and orientation.
    Pose(Isometry3<f64>),
    /// Tool origin position only; orientation free.
    Position(Point3<f64>),
}

impl IkTarget {
    /// Builds a pose target from a position (m) and a quaternion `[w, x, y, z]`,
    /// rejecting non-finite values and quaternions whose norm differs from 1 by more
    /// than `1e-6`.
    pub fn from_position_quaternion(p: [f64; 3], wxyz: [f64; 4]) -> Result<Self, IkError> {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(IkError::NonFiniteTarget {
                field: TargetPart::Position,
            });
        }
        if wxyz.iter().any(|v| !v.is_finite()) {
            return Err(IkError::NonFiniteTarget {
                field: TargetPart::Orientation,
            });
        }
        let q = Quaternion::new(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
        let norm = q.norm();
        const TOL: f64 = 1e-6;
        if (norm - 1.0).abs() > TOL {
            return Err(IkError::NonUnitQuaternion { norm, tolerance: TOL });
        }
        Ok(IkTarget::Pose(Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::new_normalize(q),
        )))
    }

    /// Target position (m).
    pub fn position(&self) -> Vector3<f64> {
        match self {
            IkTarget::Pose(t) => t.translation.vector,
            IkTarget::Position(p) => p.coords,
        }
    }

    /// True when only the position is prescribed.
    pub fn is_position_only(&self) -> bool {
        matches!(self, IkTarget::Position(_))
    }

    /// Rows of the task-space error: 3 (position) or 6 (pose).
    pub fn task_dim(&self) -> usize {
        if self.is_position_only() { 3 } else { 6 }
    }

    /// Checks every number is finite and the rotation is a unit quaternion.
    pub fn validate(&self) -> Result<(), IkError> {
        match self {
            IkTarget::Position(p) => {
                if p.coords.iter().any(|v| !v.is_finite()) {
                    return Err(IkError::NonFiniteTarget {
                        field: TargetPart::Position,
                    });
                }
            }
            IkTarget::Pose(t) => {
                if t.translation.vector.iter().any(|v| !v.is_finite()) {
                    return Err(IkError::NonFiniteTarget {
                        field: TargetPart::Position,
                    });
                }
                let q = t.rotation.quaternion();
                if q.coords.iter().any(|v| !v.is_finite()) {
                    return Err(IkError::NonFiniteTarget {
                        field: TargetPart::Orientation,
                    });
                }
                let norm = q.norm();
                if (norm - 1.0).abs() > 1e-6 {
                    return Err(IkError::NonUnitQuaternion {
                        norm,
                        tolerance: 1e-6,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Task-space error of a tool pose, base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseError {
    /// `[p* − p; rotvec(R* Rᵀ)]` (m, rad); the rotation part is zero for position targets.
    pub e: Vector6<f64>,
    /// `‖p* − p‖` (m).
    pub position: f64,
    /// Rotation angle of `R* Rᵀ` (rad, in [0, π]); 0 for position targets.
    pub orientation: f64,
}

impl PoseError {
    /// `‖e_p‖² + ‖e_r‖²` — the scalar the Jacobian methods descend (m² + rad²).
    pub fn squared(&self) -> f64 {
        self.position * self.position + self.orientation * self.orientation
    }
}

/// Pose error of `current` against `target` (docs/inverse-kinematics.md): position difference
/// `p* − p` plus the orientation error as the rotation vector of `R* Rᵀ`, both in the
/// base frame, so that `e ≈ J Δq` for the geometric Jacobian.
///
/// ```
/// use nalgebra::{Isometry3, Point3, Vector3};
/// use kinplan_core::ik::{pose_error, IkTarget};
/// let cur = Isometry3::translation(1.0, 0.0, 0.0);
/// let e = pose_error(&cur, &IkTarget::Position(Point3::new(1.0, 0.5, 0.0)));
/// assert!((e.position - 0.5).abs() < 1e-15 && e.orientation == 0.0);
/// ```
pub fn pose_error(current: &Isometry3<f64>, target: &IkTarget) -> PoseError {
    match target {
        IkTarget::Position(p) => {
            let dp = p.coords - current.translation.vector;
            PoseError {
                e: Vector6::new(dp.x, dp.y, dp.z, 0.0, 0.0, 0.0),
                position: dp.norm(),
                orientation: 0.0,
            }
        }
        IkTarget::Pose(t) => {
            let dp = t.translation.vector - current.translation.vector;
            let dr = (t.rotation * current.rotation.inverse()).scaled_axis();
            PoseError {
                e: Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z),
                position: dp.norm(),
                orientation: dr.norm(),
            }
        }
    }
}
