//! CCSTOMP's two extensions (docs/planning.md#ccstomp, S0 §3.1–3.2): the straight
//! Cartesian reference line with the per-waypoint deviation and cost, and the
//! Cartesian normal-distribution noise generator.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::CartesianParams;
use super::noise::standard_normal;
use crate::Deadline;
use crate::ik::{IkParams, IkSolver, IkStatus, IkTarget};
use crate::robot::Chain;

/// Deviation of one waypoint's tool pose from the reference line:
/// `Diff = PL⁻¹ · PR`, translation `‖t(Diff)‖` (m) and rotation angle of
/// `R(Diff)` (rad).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// e_t, m.
    pub translation: f64,
    /// e_r, rad.
    pub rotation: f64,
}

/// The straight Cartesian line between two tool poses (S0 §3.2): position
/// interpolated linearly, orientation by slerp, sampled at `s ∈ [0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CartesianLine {
    pub start: Isometry3<f64>,
    pub goal: Isometry3<f64>,
}

impl CartesianLine {
    /// The line from `FK(start)` to `FK(goal)`.
    pub fn between(chain: &Chain, start: &[f64], goal: &[f64]) -> Self {
        Self {
            start: chain.fk(start),
            goal: chain.fk(goal),
        }
    }

    /// `PL(s)`: `p = (1−s)·p₀ + s·p₁`, `R = slerp(R₀, R₁, s)` (the shorter
    /// arc; antipodal orientations fall back to the start's).
    pub fn pose_at(&self, s: f64) -> Isometry3<f64> {
        let p = self
            .start
            .translation
            .vector
            .lerp(&self.goal.translation.vector, s);
        let r = self
            .start
            .rotation
            .try_slerp(&self.goal.rotation, s, 1e-12)
            .unwrap_or(self.start.rotation);
        Isometry3::from_parts(Translation3::from(p), r)
    }

    /// `PL` at waypoint `i` of `n` (`s = i/(n−1)`).
    pub fn pose_at_waypoint(&self, i: usize, n: usize) -> Isometry3<f64> {
        let s = if n > 1 { i as f64 / (n - 1) as f64 } else { 0.0 };
        self.pose_at(s)
    }
}

/// `Diff = PL⁻¹ · PR` split into its translation length and rotation angle.
///
/// ```
/// use kinplan_core::plan::deviation;
/// use nalgebra::{Isometry3, Vector3};
/// let pl = Isometry3::translation(1.0, 0.0, 0.0);
/// let pr = Isometry3::new(Vector3::new(1.0, 0.3, 0.4), Vector3::new(0.0, 0.0, 0.25));
/// let d = deviation(&pl, &pr);
/// assert!((d.translation - 0.5).abs() < 1e-12 && (d.rotation - 0.25).abs() < 1e-12);
/// ```
pub fn deviation(reference: &Isometry3<f64>, actual: &Isometry3<f64>) -> Deviation {
    let diff = reference.inv_mul(actual);
    Deviation {
        translation: diff.translation.vector.norm(),
        rotation: diff.rotation.angle(),
    }
}

/// S0 eq. 3.3 term of one waypoint: `w_t·e_t/t_t + w_r·e_r/t_r`, plus
/// `violation_penalty` when `e_t > t_t` or `e_r > t_r` (so rollouts outside
/// the tolerance rank below those inside).
pub fn cartesian_cost(d: &Deviation, p: &CartesianParams) -> f64 {
    let mut c = p.translation_weight * d.translation / p.translation_tolerance
        + p.rotation_weight * d.rotation / p.rotation_tolerance;
    if violates(d, p) {
        c += p.violation_penalty;
    }
    c
}

/// True when the waypoint is beyond `t_t` or `t_r`.
pub fn violates(d: &Deviation, p: &CartesianParams) -> bool {
    d.translation > p.translation_tolerance || d.rotation > p.rotation_tolerance
}

/// IK options of the noise generator: Levenberg–Marquardt from the sample,
/// no restarts (a restart would jump to another branch), 0.1 mm / 1 mrad.
pub(crate) fn noise_ik_params(p: &CartesianParams) -> IkParams {
    IkParams {
        max_iterations: p.ik_iterations,
        max_restarts: 0,
        num_solutions: 1,
        position_tolerance: 1e-4,
        orientation_tolerance: 1e-3,
        ..IkParams::default()
    }
}

/// The noisy pose of S0 eq. 3.1:
/// `P' = P · T_xyz(r1, r2, r3) · R_x(r4) · R_y(r5) · R_z(r6)` — the noise is
/// applied in the tool frame. Translations in m, angles in rad.
pub fn perturb_pose(p: &Isometry3<f64>, r: &[f64; 6]) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), r[3])
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), r[4])
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), r[5]);
    p * Isometry3::from_parts(Translation3::new(r[0], r[1], r[2]), rot)
}

/// Cartesian normal-distribution noise for one waypoint (S0 §3.1): tool
/// pose `P = FK(q)`, `r_k ~ N(0, σ_k)` (σ_t for r1–r3, σ_r for r4–r6), the
/// noisy pose of [`perturb_pose`], `q' = IK(P')` warm-started at `q`. Writes
/// `q' − q` into `eps` when IK converged, zeros otherwise (the sample keeps
/// `q`). Returns whether IK converged.
pub(crate) fn cartesian_noise<R: Rng>(
    solver: &mut IkSolver<'_>,
    q: &[f64],
    params: &CartesianParams,
    ik: &IkParams,
    rng: &mut R,
    deadline: Deadline<'_>,
    eps: &mut [f64],
) -> bool {
    let chain = solver.chain();
    let mut r = [0.0; 6];
    for (k, v) in r.iter_mut().enumerate() {
        let s = if k < 3 {
            params.translation_stddev
        } else {
            params.rotation_stddev
        };
        *v = s * standard_normal(rng);
    }
    let ik_seed: u64 = rng.random();
    let target = IkTarget::Pose(perturb_pose(&chain.fk(q), &r));
    eps.iter_mut().for_each(|e| *e = 0.0);
    match solver.solve(&target, Some(q), ik, ik_seed, deadline) {
        Ok(res) if res.stop_reason == IkStatus::Converged => {
            if let Some(s) = res.solutions.first() {
                for ((e, a), b) in eps.iter_mut().zip(&s.joints).zip(q) {
                    *e = a - b;
                }
                return true;
            }
            false
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_interpolates_position_linearly_and_rotation_by_slerp() {
        let a = Isometry3::new(Vector3::new(0.0, 0.0, 0.0), Vector3::zeros());
        let b = Isometry3::new(Vector3::new(2.0, -4.0, 6.0), Vector3::new(0.0, 0.0, 1.0));
        let line = CartesianLine { start: a, goal: b };
        let m = line.pose_at(0.25);
        assert!((m.translation.vector - Vector3::new(0.5, -1.0, 1.5)).norm() < 1e-12);
        assert!((m.rotation.angle() - 0.25).abs() < 1e-12);
        assert!(deviation(&line.pose_at_waypoint(3, 4), &b).translation < 1e-12);
    }

    #[test]
    fn perturbation_is_applied_in_the_tool_frame() {
        // Tool turned 90° about z: a +x step in the tool frame is +y in the base.
        let p = Isometry3::new(
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let q = perturb_pose(&p, &[0.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert!((q.translation.vector - Vector3::new(1.0, 0.5, 0.0)).norm() < 1e-12);
        let d = deviation(&p, &perturb_pose(&p, &[0.0, 0.0, 0.0, 0.1, 0.0, 0.0]));
        assert!(d.translation < 1e-12 && (d.rotation - 0.1).abs() < 1e-12);
    }

    #[test]
    fn the_cost_is_s0_eq_3_3_with_a_penalty_beyond_tolerance() {
        let p = CartesianParams {
            translation_weight: 2.0,
            rotation_weight: 3.0,
            ..CartesianParams::default()
        };
        let d = Deviation {
            translation: 0.5,
            rotation: 0.1,
        };
        assert!((cartesian_cost(&d, &p) - (2.0 * 0.5 / 1.0 + 3.0 * 0.1 / 0.2)).abs() < 1e-12);
        let far = Deviation {
            translation: 0.5,
            rotation: 0.3,
        };
        assert!(violates(&far, &p));
        assert!(cartesian_cost(&far, &p) > 10.0);
    }
}
