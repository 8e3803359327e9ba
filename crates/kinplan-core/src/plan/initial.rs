//! STOMP's initial trajectory: the straight joint line, the straight
//! Cartesian line by warm-started IK, or a resampled RRT-Connect path.

use super::cartesian::CartesianLine;
use super::clock::Clock;
use super::costs::{interior_valid, path_valid, resolution_of};
use super::rrt_connect::{RrtStop, resample, rrt_connect_path};
use super::stomp::straight_line;
use super::{InitialTrajectory, RrtParams};
use crate::collision::StateChecker;
use crate::ik::{IkParams, IkSolver, IkStatus, IkTarget};
use crate::robot::Chain;

/// Largest joint change (rad or m, max-norm) between consecutive waypoints
/// of the Cartesian-line start; a larger jump means IK switched branch.
const MAX_CARTESIAN_STEP: f64 = 0.5;

/// The tool's straight Cartesian line as joints: `PL_i` for the interior
/// waypoints solved by Levenberg–Marquardt IK, each warm-started at the
/// previous waypoint's solution (no restarts, so the branch is kept);
/// the ends are `start` and `goal` exactly. `None` when an IK fails, a step
/// exceeds [`MAX_CARTESIAN_STEP`], or the path is not valid.
fn cartesian_line_joints<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    n: usize,
    clock: &Clock<'_>,
) -> Option<Vec<f64>> {
    let dof = start.len();
    let line = CartesianLine::between(chain, start, goal);
    let params = IkParams {
        max_restarts: 0,
        num_solutions: 1,
        position_tolerance: 1e-5,
        orientation_tolerance: 1e-5,
        ..IkParams::default()
    };
    let mut solver = IkSolver::new(chain);
    let mut out = Vec::with_capacity(n * dof);
    out.extend_from_slice(start);
    for i in 1..n - 1 {
        let prev = out[(i - 1) * dof..].to_vec();
        let target = IkTarget::Pose(line.pose_at_waypoint(i, n));
        let r = solver
            .solve(&target, Some(&prev), &params, i as u64, clock.deadline)
            .ok()?;
        if r.stop_reason != IkStatus::Converged {
            return None;
        }
        out.extend_from_slice(&r.solutions.first()?.joints);
    }
    out.extend_from_slice(goal);
    let jump = out
        .chunks_exact(dof)
        .zip(out.chunks_exact(dof).skip(1))
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    if jump > MAX_CARTESIAN_STEP {
        return None;
    }
    (path_valid(checker, &out, dof, resolution_of(checker), clock) == Some(true)).then_some(out)
}

/// The initial trajectory of `n` waypoints (row-major) and the time spent in
/// RRT-Connect (µs, 0 when it did not run). See [`InitialTrajectory`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_trajectory<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    n: usize,
    kind: InitialTrajectory,
    rrt: &RrtParams,
    seed: u64,
    clock: &Clock<'_>,
) -> (Vec<f64>, u64) {
    let dof = start.len();
    if kind == InitialTrajectory::CartesianLine
        && let Some(q) = cartesian_line_joints(chain, checker, start, goal, n, clock)
    {
        return (q, 0);
    }
    let line = straight_line(start, goal, n);
    if kind == InitialTrajectory::StraightLine {
        return (line, 0);
    }
    let mut buf = vec![0.0; dof];
    if interior_valid(checker, start, goal, resolution_of(checker), &mut buf, clock) == Some(true) {
        return (line, 0);
    }
    let t0 = std::time::Instant::now();
    let out = rrt_connect_path(chain, checker, start, goal, rrt, seed, clock);
    let us = t0.elapsed().as_micros() as u64;
    if out.stop == RrtStop::Connected {
        (resample(&out.path, dof, n), us)
    } else {
        (line, us)
    }
}
