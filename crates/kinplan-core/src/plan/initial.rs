//! STOMP's initial trajectory: the straight joint line, the straight
//! Cartesian line (or a detour inside CCSTOMP's tolerance tube) by
//! warm-started IK, or a resampled RRT-Connect path.

use super::cartesian::CartesianLine;
use super::clock::Clock;
use super::costs::{interior_valid, resolution_of};
use super::detour::{project_into_tube, tube_start};
use super::rrt_connect::{RrtStop, resample, rrt_connect_path};
use super::stomp::straight_line;
use super::{CartesianParams, InitialTrajectory, RrtParams};
use crate::collision::StateChecker;
use crate::ik::IkSolver;
use crate::robot::Chain;

/// The initial trajectory of `n` waypoints (row-major) and the time spent in
/// RRT-Connect (µs, 0 when it did not run). See [`InitialTrajectory`].
///
/// With `tube` (CCSTOMP's tolerances) the Cartesian-line start falls back to
/// a detour inside the tube ([`tube_start`]) before RRT-Connect, and an
/// RRT-Connect path is then projected waypoint by waypoint into the tube
/// ([`project_into_tube`]): S0's cost is measured against the line, and
/// STOMP's noise turns the tool too little per iteration to bring a path
/// that leaves the tube by tenths of a radian back inside.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_trajectory<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    start: &[f64],
    goal: &[f64],
    n: usize,
    kind: InitialTrajectory,
    tube: Option<&CartesianParams>,
    rrt: &RrtParams,
    seed: u64,
    clock: &Clock<'_>,
) -> (Vec<f64>, u64) {
    let dof = start.len();
    let cartesian = kind == InitialTrajectory::CartesianLine;
    if cartesian && let Some(q) = tube_start(chain, checker, start, goal, n, tube, clock) {
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
    if out.stop != RrtStop::Connected {
        return (line, us);
    }
    let mut q = resample(&out.path, dof, n);
    if cartesian && let Some(tube) = tube {
        let reference = CartesianLine::between(chain, start, goal);
        let mut solver = IkSolver::new(chain);
        for (i, row) in q.chunks_exact_mut(dof).enumerate().take(n - 1).skip(1) {
            if clock.interrupted().is_some() {
                break;
            }
            project_into_tube(&mut solver, &reference, tube, i, n, row, clock.deadline);
        }
    }
    (q, us)
}
