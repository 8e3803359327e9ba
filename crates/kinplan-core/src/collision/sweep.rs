//! How far a robot body can move when the joints move: the bound behind the
//! padded (conservative) motion check, [`super::MotionCheck::Padded`].
//!
//! While joint `j` turns by `|Δq_j|`, a point at distance `r` from its axis
//! moves at most `|Δq_j| · r`; a prismatic joint moves every point after it
//! by `|Δq_j|`. Along a straight joint-space motion the velocities add, so a
//! point of body `b` moves at most
//!
//! ```text
//! δ_b(Δq) = Σ_{j moves b} |Δq_j| · L_{j,b}
//! ```
//!
//! where `L_{j,b}` bounds the distance from joint `j`'s axis of every point
//! of `b` in every configuration: `1` for a prismatic `j`, and for a revolute
//! `j` the distance from its frame origin (on the axis) to the body's bounding
//! sphere, through the chain — `Σ_{i>j} (|t(O_i)| + e_i) + |c_b| + r_b`, with
//! `O_i` the fixed origin of joint `i`, `e_i` a prismatic joint's largest
//! travel `max(|lower|, |upper|)` (0 for a revolute one), `c_b` the bounding
//! sphere's centre in the frame of the last joint moving `b` and `r_b` its
//! radius. Rotations keep lengths, so the bound holds for every `q`.
//!
//! Around a known state `m` the bound tightens ([`SweepBound::pads_at`]):
//! for `|q_j − m_j| ≤ h_j`, a point's distance from revolute joint `j`'s axis
//! changes only through the joints after `j` (the joints before move point
//! and axis together; `j` turns about its own axis), so it stays below
//! `ρ_{j,b}(m) + Σ_{i>j} h_i L_{i,b}`, with `ρ_{j,b}(m)` the distance of the
//! body's bounding sphere from the axis at `m` plus its radius. Hence
//!
//! ```text
//! δ_b ≤ Σ_{j moves b} h_j · min(L_{j,b}, ρ_{j,b}(m) + Σ_{i>j} h_i L_{i,b})
//! ```
//!
//! (a prismatic `j` contributes `h_j`).
//!
//! Along a straight motion `q(s) = m + s·d`, `s ∈ [−1, 1]` (a piece of a
//! motion, `d` its signed half vector), the joints' contributions to a
//! point's velocity add as vectors, not as lengths
//! ([`SweepBound::pad_along`]). For a chain whose joints moving `b` all turn,
//! with `ω_j`, `o_j` joint `j`'s unit axis and a point on it at `m`,
//! `c`, `r` the bounding sphere's centre and radius there, a point `x` of
//! the body moves by
//!
//! ```text
//! |x(s) − x(0)| ≤ |s|·|x'(0)| + s²/2 · max|x''| ≤ |v| + |Ω|·r + A/2,
//! v = Σ_j d_j ω_j × (c − o_j),   Ω = Σ_j d_j ω_j,
//! A = Σ_j |d_j| (2 P_j L_{j,b} + S_j),   P_j = Σ_{i<j} |d_i|,   S_j = Σ_{i≥j} |d_i| L_{i,b}
//! ```
//!
//! (Taylor's theorem with the acceleration bounded everywhere: axis `j`
//! turns at most `P_j` per unit of `s`, and `x − o_j` changes at most
//! `P_j L_{j,b} + S_j`, so `|d/ds (ω_j × (x − o_j))| ≤ 2 P_j L_{j,b} + S_j`).
//! The vector sum is what tightens it: the joints of an arm push a point
//! in different directions, so `|v|` is often well below `Σ_j |d_j| ρ_{j,b}`.
//!
//! In a serial chain the joints moving body `b` are the first ones, `0..=k_b`,
//! so the sums are prefix sums, shared by every body of a piece
//! ([`PieceSums`]): `v = Ω_{k_b} × c − M_{k_b}` with `Ω_k = Σ_{j≤k} d_j ω_j`,
//! `M_k = Σ_{j≤k} d_j ω_j × o_j`, and `A = Σ_{j≤k_b} L_{j,b} w_j` with
//! `w_j = |d_j| (3 P_j + |d_j|)` (the two terms of `A` regrouped by joint).

use nalgebra::{Isometry3, Point3, Vector3};

#[cfg(test)]
use super::model::MAX_BODIES;
use super::model::{JointAxis, RobotModel};
use crate::robot::JointKind;

/// The lever arms `L_{j,b}` of a robot model (see the module doc).
#[derive(Debug, Clone)]
pub struct SweepBound {
    dof: usize,
    /// `levers[b * dof + j] = L_{j,b}`, 0 where joint `j` does not move body `b`.
    levers: Vec<f64>,
    /// Joints that translate instead of turning.
    prismatic: Vec<bool>,
    /// The last joint moving each body (`None`: fixed to the base).
    last: Vec<Option<usize>>,
}

/// Chains up to this many joints (arms have 6 or 7) share their prefix sums ([`PieceSums`]);
/// longer ones bound each body on its own.
const SHARED_SUMS: usize = 8;

/// The prefix sums of one piece `m + s·d` that [`SweepBound::pad_along`]
/// needs for every body (module doc): `Ω_k`, `M_k` and the weights `w_j`.
#[derive(Debug, Clone)]
pub(crate) struct PieceSums {
    omega: [Vector3<f64>; SHARED_SUMS],
    moment: [Vector3<f64>; SHARED_SUMS],
    weight: [f64; SHARED_SUMS],
}

impl SweepBound {
    /// The bound of `model`'s bodies; `None` when a lever is infinite (a
    /// prismatic joint without limits before a revolute one).
    pub fn new(model: &RobotModel) -> Option<SweepBound> {
        let chain = model.chain();
        let (joints, links) = (chain.joints(), chain.links());
        let dof = joints.len();
        let mut levers = vec![0.0; model.bodies.len() * dof];
        for (b, body) in model.bodies.iter().enumerate() {
            let link = &links[body.link];
            let Some(last) = link.after_joint else {
                continue; // fixed to the base: nothing moves it
            };
            let centre = (link.offset * body.offset).transform_point(&Point3::from(body.center));
            // Distance from joint j's origin to the sphere's far side, built
            // from the last joint moving the body back to the first.
            let mut reach = centre.coords.norm() + body.radius;
            for j in (0..=last.min(dof - 1)).rev() {
                let joint = &joints[j];
                levers[b * dof + j] = match joint.kind {
                    JointKind::Prismatic => 1.0,
                    JointKind::Revolute | JointKind::Continuous => reach,
                };
                let travel = match joint.kind {
                    JointKind::Prismatic => joint.lower.abs().max(joint.upper.abs()),
                    JointKind::Revolute | JointKind::Continuous => 0.0,
                };
                reach += travel + joint.origin.translation.vector.norm();
            }
        }
        let prismatic = joints.iter().map(|j| j.kind == JointKind::Prismatic).collect();
        let last = model
            .bodies
            .iter()
            .map(|body| links[body.link].after_joint.map(|j| j.min(dof.max(1) - 1)))
            .collect();
        levers.iter().all(|v| v.is_finite()).then_some(SweepBound {
            dof,
            levers,
            prismatic,
            last,
        })
    }

    /// `δ_b(Δq)` for every body into `pads[..bodies]`, with `Δq = step`
    /// (absolute values are taken).
    pub fn pads(&self, step: &[f64], pads: &mut [f64]) {
        if self.dof == 0 {
            pads.fill(0.0);
            return;
        }
        for (pad, levers) in pads.iter_mut().zip(self.levers.chunks_exact(self.dof)) {
            *pad = levers.iter().zip(step).map(|(l, d)| l * d.abs()).sum();
        }
    }

    /// The tightened bound around state `m` (see the module doc) for every
    /// body into `pads[..bodies]`: `poses` and `axes` are the bodies' poses
    /// and the joints' axes at `m` ([`RobotModel::body_poses_and_axes`]),
    /// `half` the largest joint offsets `h_j ≥ 0` from `m`.
    #[cfg(test)]
    pub(crate) fn pads_at(
        &self,
        model: &RobotModel,
        poses: &[Isometry3<f64>; MAX_BODIES],
        axes: &[JointAxis],
        half: &[f64],
        pads: &mut [f64; MAX_BODIES],
    ) {
        for (b, pad) in pads.iter_mut().take(model.bodies.len()).enumerate() {
            *pad = self.pad_at(model, b, &poses[b], axes, half);
        }
    }

    /// [`SweepBound::pads_at`] for body `b` alone, posed at `pose`.
    pub(crate) fn pad_at(
        &self,
        model: &RobotModel,
        b: usize,
        pose: &Isometry3<f64>,
        axes: &[JointAxis],
        half: &[f64],
    ) -> f64 {
        if self.dof == 0 {
            return 0.0;
        }
        let levers = &self.levers[b * self.dof..(b + 1) * self.dof];
        let body = &model.bodies[b];
        let centre = pose * Point3::from(body.center);
        // Σ_{i>j} h_i L_{i,b}, built from the last joint back
        let mut tail = 0.0;
        let mut sum = 0.0;
        for j in (0..self.dof).rev() {
            let lever = levers[j];
            if lever == 0.0 {
                continue;
            }
            let h = half[j].abs();
            sum += h * if self.prismatic[j] {
                1.0
            } else {
                let axis = &axes[j];
                let r = centre.coords - axis.point;
                let from_axis = (r - axis.direction * r.dot(&axis.direction)).norm() + body.radius;
                lever.min(from_axis + tail)
            };
            tail += h * lever;
        }
        sum
    }

    /// How far any point of body `b` (posed at `pose`, the joints' axes at
    /// `axes`) moves along the straight motion `m + s·d`, `s ∈ [−1, 1]`:
    /// the segment's second-order bound of the module doc when every joint
    /// moving `b` turns, else [`SweepBound::pad_at`] (which holds for the
    /// whole box `|q_j − m_j| ≤ |d_j|`). The global [`SweepBound::pads`]
    /// hold as well; callers may take the smaller. `pad_at` is not asked
    /// besides: on pieces of a few resolutions it is rarely the smaller and
    /// costs a square root per joint. Callers asking for several bodies of one piece
    /// share the sums: [`SweepBound::piece_sums`], [`SweepBound::pad_along_with`].
    pub(crate) fn pad_along(
        &self,
        model: &RobotModel,
        b: usize,
        pose: &Isometry3<f64>,
        axes: &[JointAxis],
        d: &[f64],
    ) -> f64 {
        match self.piece_sums(axes, d) {
            Some(sums) => self.pad_along_with(model, b, pose, axes, d, &sums),
            None => self.pad_along_alone(model, b, pose, axes, d),
        }
    }

    /// The prefix sums of the piece `m + s·d` (joints' axes at `m` in
    /// `axes`); `None` for chains longer than [`SHARED_SUMS`] joints.
    pub(crate) fn piece_sums(&self, axes: &[JointAxis], d: &[f64]) -> Option<PieceSums> {
        if self.dof > SHARED_SUMS || axes.len() < self.dof || d.len() < self.dof {
            return None;
        }
        let mut sums = PieceSums {
            omega: [Vector3::zeros(); SHARED_SUMS],
            moment: [Vector3::zeros(); SHARED_SUMS],
            weight: [0.0; SHARED_SUMS],
        };
        let (mut omega, mut moment, mut prefix) = (Vector3::zeros(), Vector3::zeros(), 0.0);
        for j in 0..self.dof {
            let (dj, axis) = (d[j], &axes[j]);
            let turn = axis.direction * dj;
            omega += turn;
            moment += turn.cross(&axis.point);
            let h = dj.abs();
            (sums.omega[j], sums.moment[j], sums.weight[j]) = (omega, moment, h * (3.0 * prefix + h));
            prefix += h;
        }
        Some(sums)
    }

    /// [`SweepBound::pad_along`] from the piece's shared sums.
    pub(crate) fn pad_along_with(
        &self,
        model: &RobotModel,
        b: usize,
        pose: &Isometry3<f64>,
        axes: &[JointAxis],
        d: &[f64],
        sums: &PieceSums,
    ) -> f64 {
        let Some(k) = self.last[b].filter(|_| self.dof > 0) else {
            return 0.0; // fixed to the base
        };
        if self.prismatic[..=k].iter().any(|&p| p) {
            return self.pad_at(model, b, pose, axes, d);
        }
        let levers = &self.levers[b * self.dof..=b * self.dof + k];
        let body = &model.bodies[b];
        let centre = (pose * Point3::from(body.center)).coords;
        let v = sums.omega[k].cross(&centre) - sums.moment[k];
        let accel: f64 = levers.iter().zip(&sums.weight[..=k]).map(|(l, w)| l * w).sum();
        v.norm() + sums.omega[k].norm() * body.radius + 0.5 * accel
    }

    /// [`SweepBound::pad_along`] summing over the joints for this body alone
    /// (chains longer than [`SHARED_SUMS`] joints).
    pub(crate) fn pad_along_alone(
        &self,
        model: &RobotModel,
        b: usize,
        pose: &Isometry3<f64>,
        axes: &[JointAxis],
        d: &[f64],
    ) -> f64 {
        if self.dof == 0 {
            return 0.0;
        }
        let levers = &self.levers[b * self.dof..(b + 1) * self.dof];
        let body = &model.bodies[b];
        let centre = (pose * Point3::from(body.center)).coords;
        let (mut v, mut omega) = (Vector3::zeros(), Vector3::zeros());
        // A = Σ_j |d_j| (2 P_j L_j + S_j) = Σ_j |d_j| 2 P_j L_j + Σ_i |d_i| L_i Σ_{j≤i} |d_j|
        let (mut prefix, mut accel) = (0.0, 0.0);
        for j in 0..self.dof {
            let lever = levers[j];
            if lever == 0.0 {
                continue;
            }
            if self.prismatic[j] {
                return self.pad_at(model, b, pose, axes, d);
            }
            let (dj, axis) = (d[j], &axes[j]);
            v += axis.direction.cross(&(centre - axis.point)) * dj;
            omega += axis.direction * dj;
            let h = dj.abs();
            // joint j's own term of S_i for every i ≤ j, and 2 P_j L_j
            accel += h * (2.0 * prefix * lever) + h * lever * (prefix + h);
            prefix += h;
        }
        v.norm() + omega.norm() * body.radius + 0.5 * accel
    }

    /// The last joint moving body `b` (`None`: fixed to the base).
    pub(crate) fn last(&self, b: usize) -> Option<usize> {
        self.last[b].filter(|_| self.dof > 0)
    }

    /// `L_{j,b}` (m per rad, or 1 for a prismatic joint).
    pub fn lever(&self, body: usize, joint: usize) -> f64 {
        self.levers[body * self.dof + joint]
    }
}
