//! A serial kinematic chain: forward kinematics and the geometric Jacobian.

use nalgebra::{Isometry3, Matrix6xX, Translation3, Unit, UnitQuaternion, Vector3};

use std::sync::OnceLock;

use super::{LinkCollision, RobotError};
use crate::ik::analytic::ChainModel;

/// How a joint moves its child link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, within `[lower, upper]` radians.
    Revolute,
    /// Rotation about the axis without limits.
    Continuous,
    /// Translation along the axis, within `[lower, upper]` metres.
    Prismatic,
}

/// One moving joint of a chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Pose of this joint's frame in the frame of the previous moving joint
    /// (after that joint's motion), or in the base frame for the first joint.
    /// Fixed joints between the two are folded in.
    pub origin: Isometry3<f64>,
    /// Unit axis in this joint's frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower limit (rad or m); `-inf` when unlimited.
    pub lower: f64,
    /// Upper limit (rad or m); `+inf` when unlimited.
    pub upper: f64,
    /// Speed limit (rad/s or m/s), when the model gives one.
    pub max_velocity: Option<f64>,
}

impl Joint {
    /// The joint's own motion for position `q`: a rotation about, or a
    /// translation along, its axis.
    #[inline]
    pub fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&self.axis, q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(self.axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
        }
    }

    /// True for revolute and continuous joints.
    pub fn is_rotational(&self) -> bool {
        !matches!(self.kind, JointKind::Prismatic)
    }
}

/// A link on the chain and where it sits: `offset` in the frame of the moving
/// joint it hangs from (`after_joint`), or in the base frame when `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkFrame {
    pub name: String,
    pub after_joint: Option<usize>,
    pub offset: Isometry3<f64>,
}

/// An immutable serial chain from a base link to a tip link.
///
/// Forward kinematics (frames in the base frame, metres):
/// `T_tip(q) = Π_i (O_i · M_i(q_i)) · T_tip_offset`, with `O_i` the joint
/// origin and `M_i` its motion. Shared as `Arc<Chain>`; joint values are
/// slices passed in.
#[derive(Debug, Clone)]
pub struct Chain {
    pub(super) name: String,
    pub(super) base_link: String,
    pub(super) tip_link: String,
    pub(super) joints: Vec<Joint>,
    pub(super) tip_offset: Isometry3<f64>,
    pub(super) links: Vec<LinkFrame>,
    pub(super) collision: Vec<LinkCollision>,
    /// The analytic IK method's reading of the chain, made on first use and
    /// kept with the model (empty in a changed copy).
    pub(super) analytic: OnceLock<ChainModel>,
}

impl Chain {
    /// Robot name as given in the URDF.
    pub fn name(&self) -> &str {
        &self.name
    }
    pub fn base_link(&self) -> &str {
        &self.base_link
    }
    pub fn tip_link(&self) -> &str {
        &self.tip_link
    }
    /// Number of moving joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }
    /// Pose of the tip link in the frame of the last moving joint.
    pub fn tip_offset(&self) -> &Isometry3<f64> {
        &self.tip_offset
    }
    /// Every link from base to tip, in order.
    pub fn links(&self) -> &[LinkFrame] {
        &self.links
    }
    /// Collision shapes of the links on the chain.
    pub fn collision(&self) -> &[LinkCollision] {
        &self.collision
    }
    /// Where the analytic IK method keeps its reading of this chain.
    pub(crate) fn analytic_cache(&self) -> &OnceLock<ChainModel> {
        &self.analytic
    }

    /// Lower and upper limits, in joint order.
    pub fn limits(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.joints.iter().map(|j| (j.lower, j.upper))
    }

    /// Checks that `q` has one finite value per joint.
    pub fn check_joints(&self, q: &[f64]) -> Result<(), RobotError> {
        if q.len() != self.dof() {
            return Err(RobotError::WrongJointCount {
                expected: self.dof(),
                got: q.len(),
            });
        }
        if let Some(index) = q.iter().position(|v| !v.is_finite()) {
            return Err(RobotError::NonFiniteJoint { index });
        }
        // Bounded joint values (and bounded origins, see `parse_chain`) keep
        // forward kinematics finite.
        match q.iter().position(|v| v.abs() > super::urdf::MAX_LIMIT) {
            Some(index) => Err(RobotError::JointOutOfRange {
                index,
                value: q[index],
                limit: super::urdf::MAX_LIMIT,
            }),
            None => Ok(()),
        }
    }

    /// Tool (tip link) pose in the base frame. `q.len()` must equal
    /// [`Chain::dof`] (see [`Chain::check_joints`]); extra values are ignored.
    ///
    /// ```
    /// let chain = kinplan_core::robot::builtin_chain("planar_2").unwrap();
    /// let tip = chain.fk(&[0.0, std::f64::consts::FRAC_PI_2]);
    /// assert!((tip.translation.vector - nalgebra::Vector3::new(0.5, 0.5, 0.0)).norm() < 1e-12);
    /// ```
    pub fn fk(&self, q: &[f64]) -> Isometry3<f64> {
        let mut t = Isometry3::identity();
        for (joint, &qi) in self.joints.iter().zip(q) {
            t = t * joint.origin * joint.motion(qi);
        }
        t * self.tip_offset
    }

    /// Like [`Chain::fk`], validating `q` first.
    pub fn try_fk(&self, q: &[f64]) -> Result<Isometry3<f64>, RobotError> {
        self.check_joints(q)?;
        Ok(self.fk(q))
    }

    /// Frame of every moving joint (after its motion), written into `out`
    /// (resized to `dof()`), and the tip pose returned.
    pub fn joint_frames_into(&self, q: &[f64], out: &mut Vec<Isometry3<f64>>) -> Isometry3<f64> {
        out.clear();
        let mut t = Isometry3::identity();
        for (joint, &qi) in self.joints.iter().zip(q) {
            t = t * joint.origin * joint.motion(qi);
            out.push(t);
        }
        t * self.tip_offset
    }

    /// Pose of every link in [`Chain::links`] order, in the base frame.
    pub fn link_frames_into(&self, q: &[f64], out: &mut Vec<Isometry3<f64>>) {
        out.clear();
        let mut t = Isometry3::identity();
        let mut applied = 0;
        for link in &self.links {
            if let Some(j) = link.after_joint {
                while applied <= j && applied < self.joints.len() {
                    let joint = &self.joints[applied];
                    t = t * joint.origin * joint.motion(q.get(applied).copied().unwrap_or(0.0));
                    applied += 1;
                }
            }
            out.push(t * link.offset);
        }
    }

    /// Geometric Jacobian of the tip in the base frame, 6 × dof: rows 0–2 the
    /// linear velocity of the tip origin, rows 3–5 the angular velocity.
    /// Column i is `[z_i × (p_tip − p_i); z_i]` for a rotational joint and
    /// `[z_i; 0]` for a prismatic one, with `z_i` the joint axis and `p_i`
    /// the joint origin in the base frame. `out` is resized only when its
    /// shape differs, so a reused matrix makes the call allocation-free.
    pub fn jacobian_into(&self, q: &[f64], out: &mut Matrix6xX<f64>) -> Isometry3<f64> {
        if out.ncols() != self.dof() {
            *out = Matrix6xX::zeros(self.dof());
        }
        // First pass: store p_i in rows 0–2 and z_i in rows 3–5.
        let mut t = Isometry3::identity();
        for (i, (joint, &qi)) in self.joints.iter().zip(q).enumerate() {
            t *= joint.origin;
            let z = t.rotation * joint.axis.into_inner();
            out.fixed_view_mut::<3, 1>(0, i).copy_from(&t.translation.vector);
            out.fixed_view_mut::<3, 1>(3, i).copy_from(&z);
            t *= joint.motion(qi);
        }
        let tip = t * self.tip_offset;
        let p_tip = tip.translation.vector;
        for (i, joint) in self.joints.iter().enumerate() {
            let z: Vector3<f64> = out.fixed_view::<3, 1>(3, i).into_owned();
            if joint.is_rotational() {
                let p: Vector3<f64> = out.fixed_view::<3, 1>(0, i).into_owned();
                out.fixed_view_mut::<3, 1>(0, i).copy_from(&z.cross(&(p_tip - p)));
            } else {
                out.fixed_view_mut::<3, 1>(0, i).copy_from(&z);
                out.fixed_view_mut::<3, 1>(3, i).fill(0.0);
            }
        }
        tip
    }

    /// Allocating convenience wrapper of [`Chain::jacobian_into`].
    pub fn jacobian(&self, q: &[f64]) -> Matrix6xX<f64> {
        let mut j = Matrix6xX::zeros(self.dof());
        self.jacobian_into(q, &mut j);
        j
    }

    /// The chain with joint `index` held at `value` (rad or m): its motion is
    /// folded into the next joint's origin (or the tip offset), and the links
    /// hanging from it move to the joint before. Forward kinematics of the
    /// result at `q` equals this chain's at `q` with `value` inserted at `index`.
    /// `None` when `index` is out of range.
    ///
    /// ```
    /// let iiwa = kinplan_core::robot::builtin_chain("kuka_lbr_iiwa14_r820").unwrap();
    /// let six = iiwa.with_joint_fixed(2, 0.4).unwrap();
    /// let q6 = [0.1, 0.2, -0.3, 0.4, 0.5, 0.6];
    /// let q7 = [0.1, 0.2, 0.4, -0.3, 0.4, 0.5, 0.6];
    /// let (a, b) = (six.fk(&q6), iiwa.fk(&q7));
    /// assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
    /// ```
    pub fn with_joint_fixed(&self, index: usize, value: f64) -> Option<Chain> {
        let removed = self.joints.get(index)?;
        let fold = removed.origin * removed.motion(value);
        let mut out = self.clone();
        out.analytic = OnceLock::new();
        out.joints.remove(index);
        match out.joints.get_mut(index) {
            Some(next) => next.origin = fold * next.origin,
            None => out.tip_offset = fold * out.tip_offset,
        }
        for link in &mut out.links {
            match link.after_joint {
                Some(j) if j == index => {
                    link.offset = fold * link.offset;
                    link.after_joint = index.checked_sub(1);
                }
                Some(j) if j > index => link.after_joint = Some(j - 1),
                _ => {}
            }
        }
        Some(out)
    }

    /// The middle of each joint's range (0 for unlimited joints).
    pub fn mid_limits(&self) -> Vec<f64> {
        self.joints
            .iter()
            .map(|j| {
                if j.lower.is_finite() && j.upper.is_finite() {
                    0.5 * (j.lower + j.upper)
                } else {
                    0.0
                }
            })
            .collect()
    }
}
