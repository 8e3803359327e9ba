//! CCSTOMP's start and repair inside the tolerance tube around the tool's
//! straight line (docs/planning.md#ccstomp): the line itself or a Cartesian
//! detour around what blocks it, both at the slerped orientation and solved
//! by warm-started IK, and the projection of a waypoint back into the tube.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::CartesianParams;
use super::cartesian::CartesianLine;
use super::clock::Clock;
use super::costs::{interior_valid, resolution_of};
use super::ladder::ladder_path;
use crate::Deadline;
use crate::collision::StateChecker;
use crate::ik::{IkParams, IkSolver, IkStatus, IkTarget};
use crate::robot::Chain;

/// Largest joint change (rad or m, max-norm) between consecutive waypoints
/// of a tool path solved by IK; a larger jump means IK switched branch.
const MAX_CARTESIAN_STEP: f64 = 0.5;

/// Detour heights tried, as fractions of `t_t` (smallest first): the
/// smallest detour that clears the obstacle costs least under S0 eq. 3.3.
const DETOUR_FRACTIONS: [f64; 4] = [0.15, 0.3, 0.55, 0.9];

/// Directions around the line, in the order tried (degrees from "up", the
/// world z axis made perpendicular to the line, about the line direction):
/// over first, then either side, the diagonals, under last.
const DETOUR_ANGLES_DEG: [f64; 8] = [0.0, 90.0, -90.0, 45.0, -45.0, 135.0, -135.0, 180.0];

/// A point inside the tube is aimed at this fraction of the tolerance when
/// projected, so that the repaired waypoint is not left on the boundary.
const PROJECTION_MARGIN: f64 = 0.8;

/// Largest joint change between `a` and `b` (rad or m, max-norm).
pub(super) fn joint_step(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// IK of tool paths: Levenberg–Marquardt from the previous waypoint, no
/// restarts (a restart would jump to another branch).
fn path_ik() -> IkParams {
    IkParams {
        max_restarts: 0,
        num_solutions: 1,
        position_tolerance: 1e-5,
        orientation_tolerance: 1e-5,
        ..IkParams::default()
    }
}

/// Joints for the tool poses `pose(i)`, `i = 1 … n−2`, each solved by IK
/// warm-started at waypoint `i − 1`; the ends are `start` and `goal`
/// exactly. Written into `out` (`n × dof`, row-major). With `checker`, a
/// colliding waypoint ends the solve early. `Err(i)`: waypoint `i` failed
/// (IK did not converge, it collides, or the step to it — or from it to the
/// goal — exceeds [`MAX_CARTESIAN_STEP`]); `Err(0)` after an interruption.
#[allow(clippy::too_many_arguments)]
fn solve_tool_path<C: StateChecker + ?Sized>(
    solver: &mut IkSolver<'_>,
    checker: Option<&C>,
    start: &[f64],
    goal: &[f64],
    n: usize,
    pose: &dyn Fn(usize) -> Isometry3<f64>,
    out: &mut Vec<f64>,
    clock: &Clock<'_>,
) -> Result<(), usize> {
    let dof = start.len();
    let params = path_ik();
    out.clear();
    out.extend_from_slice(start);
    let step = joint_step;
    for i in 1..n - 1 {
        if clock.interrupted().is_some() {
            return Err(0);
        }
        let prev = &out[(i - 1) * dof..i * dof];
        let r = solver
            .solve(
                &IkTarget::Pose(pose(i)),
                Some(prev),
                &params,
                i as u64,
                clock.deadline,
            )
            .map_err(|_| i)?;
        let q = match r.solutions.first() {
            Some(s) if r.stop_reason == IkStatus::Converged => &s.joints,
            _ => return Err(i),
        };
        if step(prev, q) > MAX_CARTESIAN_STEP || checker.is_some_and(|c| !c.is_valid(q)) {
            return Err(i);
        }
        out.extend_from_slice(q);
    }
    if step(&out[(n - 2) * dof..], goal) > MAX_CARTESIAN_STEP {
        return Err(n - 2);
    }
    out.extend_from_slice(goal);
    Ok(())
}

/// Per waypoint: true where the state collides or a motion to a neighbour
/// does; the ends (the request's start and goal, already valid) are not
/// checked again. `None` when `clock` was interrupted.
fn blocked_waypoints<C: StateChecker + ?Sized>(
    checker: &C,
    q: &[f64],
    dof: usize,
    clock: &Clock<'_>,
) -> Option<Vec<bool>> {
    let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
    let last = rows.len() - 1;
    let mut bad: Vec<bool> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| i > 0 && i < last && !checker.is_valid(r))
        .collect();
    let mut buf = vec![0.0; dof];
    for s in 0..rows.len() - 1 {
        if bad[s] || bad[s + 1] {
            continue;
        }
        if !interior_valid(
            checker,
            rows[s],
            rows[s + 1],
            resolution_of(checker),
            &mut buf,
            clock,
        )? {
            bad[s] = true;
            bad[s + 1] = true;
        }
    }
    Some(bad)
}

/// Whether every motion between consecutive waypoints of `q` is valid (its
/// interior states; the waypoints themselves are the caller's), stopping at
/// the first that is not. `None` when `clock` was interrupted.
fn motions_valid<C: StateChecker + ?Sized>(
    checker: &C,
    q: &[f64],
    dof: usize,
    clock: &Clock<'_>,
) -> Option<bool> {
    let mut buf = vec![0.0; dof];
    let resolution = resolution_of(checker);
    for s in 0..q.len() / dof - 1 {
        let (a, b) = (&q[s * dof..(s + 1) * dof], &q[(s + 1) * dof..(s + 2) * dof]);
        if !interior_valid(checker, a, b, resolution, &mut buf, clock)? {
            return Some(false);
        }
    }
    Some(true)
}

/// The detour's height profile `b(i) ∈ [0, 1]` over waypoints `0 … n−1`:
/// 1 on the plateau `lo ..= hi` (waypoints), half-cosine ramps
/// `(1 − cos(π x))/2` from 0 at the fixed ends.
fn profile(i: usize, n: usize, lo: usize, hi: usize) -> f64 {
    let ramp = |x: f64| 0.5 * (1.0 - (std::f64::consts::PI * x.clamp(0.0, 1.0)).cos());
    if i < lo {
        ramp(i as f64 / lo as f64)
    } else if i > hi {
        ramp((n - 1 - i) as f64 / (n - 1 - hi) as f64)
    } else {
        1.0
    }
}

/// Two unit vectors perpendicular to the line direction `u` and to each
/// other: `up` (world z with its component along `u` removed; world x when
/// the line is vertical) and `u × up`. A zero-length line uses world z's
/// complement as `u`.
pub(super) fn perpendicular_frame(u: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let u = u.try_normalize(1e-9).unwrap_or_else(Vector3::x);
    let mut up = Vector3::z() - u * u.z;
    if up.norm() < 1e-6 {
        up = Vector3::x() - u * u.x;
    }
    let up = up.normalize();
    (up, u.cross(&up))
}

/// The joint path CCSTOMP starts from: the tool's straight line
/// (`PL_i`, S0 §3.2) when it solves by IK and is valid; otherwise the first
/// valid **Cartesian detour** of the tolerance tube.
///
/// A detour keeps the slerped orientation of every `PL_i` and moves the
/// position off the line by `h · b(i) · d`: `d` one of eight directions
/// perpendicular to the line (over, the sides, the diagonals, under), `h` a
/// fraction of `t_t` (0.15, 0.3, 0.55, 0.9; smallest first), `b` a profile
/// that is 1 over the waypoints the straight line found blocked (widened by
/// `max(1, ⌈0.05 (n−1)⌉)` waypoints each side) and ramps by half-cosines to
/// 0 at the fixed ends. Each candidate is solved waypoint by waypoint by
/// warm-started IK, abandoned at its first failing or colliding waypoint,
/// and kept when every motion is valid too. Every waypoint of the result is
/// within `t_t` and `t_r` by construction (to the IK tolerance), so STOMP
/// starts from a trajectory that is valid under CCSTOMP's own test.
///
/// This is the Descartes-style way of planning a Cartesian path (a sampled
/// tool path, joint states by IK, the first collision-free chain kept;
/// ros-industrial-consortium/descartes) applied to S0 §3's tube instead of a
/// fixed line. `start` and `goal` must be valid states (the planner checks
/// them first); every other state is checked once. `None` when no
/// candidate is valid or `clock` was interrupted.
#[allow(clippy::too_many_arguments)]
pub(crate) fn tube_start<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    n: usize,
    tube: Option<&CartesianParams>,
    clock: &Clock<'_>,
) -> Option<Vec<f64>> {
    let dof = start.len();
    let line = CartesianLine::between(chain, start, goal);
    let mut solver = IkSolver::new(chain);
    let mut q = Vec::with_capacity(n * dof);
    let on_line = |i: usize| line.pose_at_waypoint(i, n);
    let blocked = match solve_tool_path(&mut solver, None::<&C>, start, goal, n, &on_line, &mut q, clock) {
        Ok(()) => {
            let bad = blocked_waypoints(checker, &q, dof, clock)?;
            if !bad.contains(&true) {
                return Some(q);
            }
            bad
        }
        Err(0) => return None,
        // IK broke down on the line itself: the whole interior is suspect
        Err(_) => (0..n).map(|i| i > 0 && i + 1 < n).collect(),
    };
    let tube = tube?;
    let first = blocked.iter().position(|&b| b)?;
    let last = blocked.iter().rposition(|&b| b)?;
    let widen = ((0.05 * (n - 1) as f64).ceil() as usize).max(1);
    let lo = first.saturating_sub(widen).max(1);
    let hi = (last + widen).min(n - 2);
    if lo > hi {
        return None;
    }
    let u = line.goal.translation.vector - line.start.translation.vector;
    let (up, side) = perpendicular_frame(&u);
    for frac in DETOUR_FRACTIONS {
        let h = frac * tube.translation_tolerance;
        for deg in DETOUR_ANGLES_DEG {
            let a = deg.to_radians();
            let d = (up * a.cos() + side * a.sin()) * h;
            let pose = |i: usize| {
                let p = line.pose_at_waypoint(i, n);
                Isometry3::from_parts(
                    Translation3::from(p.translation.vector + d * profile(i, n, lo, hi)),
                    p.rotation,
                )
            };
            // the solve checks every interior waypoint as it goes and the
            // ends are valid: only the motions remain
            match solve_tool_path(&mut solver, Some(checker), start, goal, n, &pose, &mut q, clock) {
                Ok(()) => {
                    if motions_valid(checker, &q, dof, clock)? {
                        return Some(q);
                    }
                }
                Err(0) => return None,
                Err(_) => {}
            }
        }
    }
    ladder_path(
        &mut solver,
        checker,
        &line,
        tube.translation_tolerance,
        start,
        goal,
        n,
        &path_ik(),
        MAX_CARTESIAN_STEP,
        clock,
    )
}

/// The pose inside the tube nearest `actual` (per part): its position pulled
/// towards the reference position until within `margin · t_t`, its rotation
/// turned towards the reference rotation, about the same axis, until within
/// `margin · t_r`.
fn nearest_in_tube(
    reference: &Isometry3<f64>,
    actual: &Isometry3<f64>,
    tube: &CartesianParams,
    margin: f64,
) -> Isometry3<f64> {
    let dp = actual.translation.vector - reference.translation.vector;
    let max_t = margin * tube.translation_tolerance;
    let dp = if dp.norm() > max_t {
        dp * (max_t / dp.norm())
    } else {
        dp
    };
    let rel = reference.rotation.inverse() * actual.rotation;
    let max_r = margin * tube.rotation_tolerance;
    let rel = match rel.axis_angle() {
        Some((axis, angle)) if angle > max_r => UnitQuaternion::from_axis_angle(&axis, max_r),
        _ => rel,
    };
    Isometry3::from_parts(
        Translation3::from(reference.translation.vector + dp),
        reference.rotation * rel,
    )
}

/// Projects joint state `q` of waypoint `i` of `n` into the tolerance tube
/// when its tool pose lies outside it: IK (Levenberg–Marquardt, warm-started
/// at `q`, no restarts, `ik_iterations` iterations) to the nearest pose inside
/// the tube ([`nearest_in_tube`], aiming at 0.8 of each tolerance). This is
/// the projection step of projection-based constrained planning (Kingston,
/// Moll and Kavraki, "Exploring Implicit Spaces for Constrained
/// Sampling-Based Planning", IJRR 2019; OMPL's `ProjectedStateSpace`, which
/// MoveIt's constrained planning uses), with the tube as the constraint and
/// IK as the projection. Returns whether `q` was changed; `q` is left as it
/// was when it is inside already or IK does not converge.
pub(crate) fn project_into_tube(
    solver: &mut IkSolver<'_>,
    line: &CartesianLine,
    tube: &CartesianParams,
    i: usize,
    n: usize,
    q: &mut [f64],
    deadline: Deadline<'_>,
) -> bool {
    let reference = line.pose_at_waypoint(i, n);
    let actual = solver.chain().fk(q);
    let d = super::cartesian::deviation(&reference, &actual);
    if !super::cartesian::violates(&d, tube) {
        return false;
    }
    let target = nearest_in_tube(&reference, &actual, tube, PROJECTION_MARGIN);
    let params = IkParams {
        max_iterations: tube.ik_iterations,
        ..path_ik()
    };
    match solver.solve(&IkTarget::Pose(target), Some(q), &params, i as u64, deadline) {
        Ok(r) if r.stop_reason == IkStatus::Converged => match r.solutions.first() {
            Some(s) => {
                q.copy_from_slice(&s.joints);
                true
            }
            None => false,
        },
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profile_is_zero_at_the_ends_and_one_on_the_plateau() {
        let n = 10;
        assert_eq!(profile(0, n, 3, 6), 0.0);
        assert_eq!(profile(9, n, 3, 6), 0.0);
        for i in 3..=6 {
            assert_eq!(profile(i, n, 3, 6), 1.0);
        }
        // half-cosine: halfway up the ramp is one half
        assert!((profile(1, 5, 2, 2) - 0.5).abs() < 1e-12);
        assert!((profile(3, 5, 2, 2) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_perpendicular_frame_is_orthonormal_and_up_points_up() {
        for u in [
            Vector3::new(0.0, 2.1, 0.0),
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::new(0.0, 0.0, -3.0),
            Vector3::zeros(),
        ] {
            let (up, side) = perpendicular_frame(&u);
            assert!((up.norm() - 1.0).abs() < 1e-12 && (side.norm() - 1.0).abs() < 1e-12);
            assert!(up.dot(&side).abs() < 1e-12);
            if u.norm() > 0.0 {
                assert!(up.dot(&u).abs() < 1e-12 && side.dot(&u).abs() < 1e-12);
            }
        }
        let (up, _) = perpendicular_frame(&Vector3::new(0.0, 2.1, 0.0));
        assert!((up - Vector3::z()).norm() < 1e-12);
    }

    #[test]
    fn the_nearest_pose_in_the_tube_is_clamped_along_the_same_offset_and_axis() {
        let tube = CartesianParams {
            translation_tolerance: 0.5,
            rotation_tolerance: 0.2,
            ..CartesianParams::default()
        };
        let reference = Isometry3::new(Vector3::new(1.0, 0.0, 0.0), Vector3::zeros());
        // 2 m off along y, turned 0.6 rad about x
        let actual = Isometry3::new(Vector3::new(1.0, 2.0, 0.0), Vector3::new(0.6, 0.0, 0.0));
        let p = nearest_in_tube(&reference, &actual, &tube, 0.8);
        // hand-derived: 0.8 × 0.5 m along +y, 0.8 × 0.2 rad about +x
        assert!((p.translation.vector - Vector3::new(1.0, 0.4, 0.0)).norm() < 1e-12);
        let (axis, angle) = p.rotation.axis_angle().unwrap();
        assert!((angle - 0.16).abs() < 1e-12 && (axis.into_inner() - Vector3::x()).norm() < 1e-12);
        // a pose inside is its own nearest
        let inside = Isometry3::new(Vector3::new(1.1, 0.1, 0.0), Vector3::new(0.0, 0.05, 0.0));
        let q = nearest_in_tube(&reference, &inside, &tube, 0.8);
        assert!((q.translation.vector - inside.translation.vector).norm() < 1e-12);
        assert!(q.rotation.angle_to(&inside.rotation) < 1e-12);
    }
}
