//! Cyclic coordinate descent for any serial chain (revolute, continuous, prismatic),
//! position or full-pose targets (docs/inverse-kinematics.md#heuristics).
//!
//! One iteration is a sweep from the tip joint to the root. Joint `i` (world axis `z`,
//! origin `o`) is moved to the optimum of `Σₖ ‖Rₖ(θ) aₖ − bₖ‖²` over the tool points
//! `aₖ` (tool origin; for pose targets also the tool origin plus `ρ` times each tool axis,
//! `ρ = 0.2 m`) and their targets `bₖ`, all relative to `o`:
//! revolute `θ = atan2(Σ z·(aₖ × bₖ), Σ (aₖ·bₖ − (z·aₖ)(z·bₖ)))`,
//! prismatic `d = Σ z·(bₖ − aₖ) / K`; then clamped into the limits. The tool pose is
//! updated in place (`T ← Rot(z, θ, o) T`), so a sweep costs one forward kinematics.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use super::attempt::{Attempt, Clock, Progress, stop_before_iteration};
use super::workspace::{IkWorkspace, wrap_into_limits};
use super::{IkParams, IkStatus, IkTarget, pose_error};
use crate::robot::Chain;

const RHO: f64 = 0.2;

fn tool_points(t: &Isometry3<f64>, pose: bool, out: &mut [Vector3<f64>; 4]) -> usize {
    out[0] = t.translation.vector;
    if !pose {
        return 1;
    }
    let r = t.rotation.to_rotation_matrix();
    for k in 0..3 {
        out[k + 1] = t.translation.vector + r.matrix().column(k) * RHO;
    }
    4
}

pub(crate) fn run(
    chain: &Chain,
    target: &IkTarget,
    params: &IkParams,
    ws: &mut IkWorkspace,
    clock: &Clock<'_>,
) -> Attempt {
    let n = chain.dof();
    let pose = !target.is_position_only();
    let mut goal = [Vector3::zeros(); 4];
    let k_pts = match target {
        IkTarget::Pose(t) => tool_points(t, true, &mut goal),
        IkTarget::Position(p) => {
            goal[0] = p.coords;
            1
        }
    };
    IkWorkspace::apply_limits(&ws.limits, params.joint_limits, &mut ws.q);
    let mut best_sq = f64::INFINITY;
    // CCD creeps: 10x the Jacobian methods' patience, and 1 % counts as progress.
    let mut progress = Progress::new(0.99, 10 * params.stall_iterations, f64::INFINITY);
    let mut it = 0;
    let mut cur = [Vector3::zeros(); 4];
    let (status, err) = loop {
        let mut tip = chain.joint_frames_into(&ws.q, &mut ws.frames);
        let err = pose_error(&tip, target);
        ws.record(params, &err);
        if err.squared() < best_sq {
            best_sq = err.squared();
            ws.q_best.copy_from_slice(&ws.q);
        }
        if let Some(s) = stop_before_iteration(&err, target, params, it, clock) {
            break (s, err);
        }
        if progress.stalled(err.squared()) {
            break (IkStatus::Stalled, err);
        }
        it += 1;
        for i in (0..n).rev() {
            let joint = &chain.joints()[i];
            let frame = &ws.frames[i];
            let z = frame.rotation * joint.axis.into_inner();
            let o = frame.translation.vector;
            tool_points(&tip, pose, &mut cur);
            let (lo, hi) = ws.limits[i];
            let rotational = joint.is_rotational();
            let clamp = |v: f64| wrap_into_limits(v, lo, hi, rotational, params.joint_limits);
            if joint.is_rotational() {
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..k_pts {
                    let a = cur[k] - o;
                    let b = goal[k] - o;
                    num += z.dot(&a.cross(&b));
                    den += a.dot(&b) - z.dot(&a) * z.dot(&b);
                }
                if num == 0.0 && den == 0.0 {
                    continue;
                }
                let theta = num.atan2(den);
                let new_q = clamp(ws.q[i] + theta);
                let applied = new_q - ws.q[i];
                ws.q[i] = new_q;
                let rot = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(z), applied);
                tip = Isometry3::from_parts(
                    (o + rot * (tip.translation.vector - o)).into(),
                    rot * tip.rotation,
                );
            } else {
                let mut d = 0.0;
                for k in 0..k_pts {
                    d += z.dot(&(goal[k] - cur[k]));
                }
                d /= k_pts as f64;
                let new_q = clamp(ws.q[i] + d);
                let applied = new_q - ws.q[i];
                ws.q[i] = new_q;
                tip.translation.vector += z * applied;
            }
        }
    };
    if status != IkStatus::Converged && best_sq < err.squared() {
        ws.q.copy_from_slice(&ws.q_best);
        let e = pose_error(&chain.fk(&ws.q), target);
        return Attempt {
            status,
            iterations: it,
            error: e,
        };
    }
    Attempt {
        status,
        iterations: it,
        error: err,
    }
}
