//! A ladder graph over tool offsets inside CCSTOMP's tolerance tube: the
//! search behind a Cartesian detour when no single smooth detour is valid
//! (docs/planning.md#ccstomp).

use nalgebra::{Isometry3, Translation3, Vector3};

use super::cartesian::CartesianLine;
use super::clock::Clock;
use super::costs::{interior_valid, resolution_of};
use crate::collision::StateChecker;
use crate::ik::{IkParams, IkSolver, IkStatus, IkTarget};

/// Ring radii of the offsets, as fractions of `t_t`.
const RINGS: [f64; 6] = [0.06, 0.12, 0.2, 0.3, 0.5, 0.9];
/// Directions per ring, evenly spaced about the line.
const DIRECTIONS: usize = 12;
/// Parents tried per node, cheapest first.
const PARENTS_TRIED: usize = 2;

/// Node `k` of a layer: 0 is the line itself, `1 + r·DIRECTIONS + d` ring
/// `r` (0-based) in direction `d`. Returns (ring 0 = centre, 1-based rings;
/// direction).
fn ring_and_direction(k: usize) -> (usize, usize) {
    if k == 0 {
        (0, 0)
    } else {
        (1 + (k - 1) / DIRECTIONS, (k - 1) % DIRECTIONS)
    }
}

/// Two nodes are neighbours when their rings differ by at most `ring_step`
/// and, off the centre, their directions by at most one step (cyclically).
fn adjacent(a: usize, b: usize, ring_step: usize) -> bool {
    let ((ra, da), (rb, db)) = (ring_and_direction(a), ring_and_direction(b));
    if ra.abs_diff(rb) > ring_step {
        return false;
    }
    if ra == 0 || rb == 0 {
        return true;
    }
    let dd = da.abs_diff(db);
    dd <= 1 || dd == DIRECTIONS - 1
}

/// Searches a **ladder graph** (Descartes' planning graph: one layer of
/// candidate joint states per waypoint, edges between consecutive layers,
/// the cheapest chain kept; ros-industrial-consortium/descartes) whose
/// nodes are tool poses `PL_i` displaced perpendicular to the line by
/// `0` or `ρ·t_t` (ρ ∈ {0.06, 0.12, 0.2, 0.3, 0.5, 0.9}) in one of 12 directions
/// about it, at the slerped orientation. A node is reached from a
/// neighbouring node (ring ±s, direction ±1) of the previous layer by IK
/// warm-started at that node's joints (Levenberg–Marquardt, no restarts;
/// the two cheapest parents are tried) when the step stays within
/// `max_step` (rad or m, max-norm), the state is valid and so is the motion.
/// A node's cost is its parent's plus its offset (m); rings beyond what the
/// remaining waypoints can ramp down from are skipped. The chain ends at
/// `goal` through a node at most `s` rings out. The ring step
/// `s = max(1, ⌈6 / ((n − 1)/2)⌉)` lets a short trajectory (S0's 10
/// waypoints) reach the outer rings halfway along.
///
/// Returns the cheapest chain (`n × dof`, row-major), or `None` when none
/// reaches the goal or `clock` was interrupted (checked per layer).
#[allow(clippy::too_many_arguments)]
pub(crate) fn ladder_path<C: StateChecker + ?Sized>(
    solver: &mut IkSolver<'_>,
    checker: &C,
    line: &CartesianLine,
    translation_tolerance: f64,
    start: &[f64],
    goal: &[f64],
    n: usize,
    ik: &IkParams,
    max_step: f64,
    clock: &Clock<'_>,
) -> Option<Vec<f64>> {
    let dof = start.len();
    let nodes = 1 + RINGS.len() * DIRECTIONS;
    let u = line.goal.translation.vector - line.start.translation.vector;
    let (up, side) = super::detour::perpendicular_frame(&u);
    let offsets: Vec<Vector3<f64>> = (0..nodes)
        .map(|k| {
            let (r, d) = ring_and_direction(k);
            if r == 0 {
                return Vector3::zeros();
            }
            let a = std::f64::consts::TAU * d as f64 / DIRECTIONS as f64;
            (up * a.cos() + side * a.sin()) * (RINGS[r - 1] * translation_tolerance)
        })
        .collect();
    // per layer and node: cost (∞ = unreached), parent, joints
    let mut cost = vec![f64::INFINITY; n * nodes];
    let mut parent = vec![usize::MAX; n * nodes];
    let mut q = vec![0.0; n * nodes * dof];
    cost[0] = 0.0;
    q[..dof].copy_from_slice(start);
    let mut buf = vec![0.0; dof];
    let mut order: Vec<usize> = Vec::with_capacity(nodes);
    let ring_step = ((RINGS.len() as f64 / ((n - 1) as f64 / 2.0)).ceil() as usize).max(1);
    let step = super::detour::joint_step;
    let res = resolution_of(checker);
    for i in 1..n - 1 {
        if clock.interrupted().is_some() {
            return None;
        }
        let pose = line.pose_at_waypoint(i, n);
        let reach_back = n - 1 - i; // layers left to come back to the line
        for (v, offset) in offsets.iter().enumerate() {
            let ring = ring_and_direction(v).0;
            if ring > i * ring_step || ring > reach_back * ring_step {
                continue;
            }
            order.clear();
            order.extend(
                (0..nodes).filter(|&p| cost[(i - 1) * nodes + p].is_finite() && adjacent(p, v, ring_step)),
            );
            order.sort_by(|&a, &b| cost[(i - 1) * nodes + a].total_cmp(&cost[(i - 1) * nodes + b]));
            let target = IkTarget::Pose(Isometry3::from_parts(
                Translation3::from(pose.translation.vector + offset),
                pose.rotation,
            ));
            for &p in order.iter().take(PARENTS_TRIED) {
                let from = (i - 1) * nodes + p;
                let seed = &q[from * dof..(from + 1) * dof];
                let Ok(r) = solver.solve(&target, Some(seed), ik, i as u64, clock.deadline) else {
                    continue;
                };
                let Some(s) = r
                    .solutions
                    .first()
                    .filter(|_| r.stop_reason == IkStatus::Converged)
                else {
                    continue;
                };
                if step(seed, &s.joints) > max_step || !checker.is_valid(&s.joints) {
                    continue;
                }
                if interior_valid(checker, seed, &s.joints, res, &mut buf, clock) != Some(true) {
                    continue;
                }
                let at = i * nodes + v;
                cost[at] = cost[from] + offset.norm();
                parent[at] = p;
                q[at * dof..(at + 1) * dof].copy_from_slice(&s.joints);
                break;
            }
        }
    }
    // the goal, reached from a node at most `ring_step` rings out
    let last = n - 2;
    order.clear();
    order.extend((0..nodes).filter(|&p| cost[last * nodes + p].is_finite() && adjacent(p, 0, ring_step)));
    order.sort_by(|&a, &b| cost[last * nodes + a].total_cmp(&cost[last * nodes + b]));
    let end = order.iter().copied().find(|&p| {
        let from = &q[(last * nodes + p) * dof..(last * nodes + p + 1) * dof];
        step(from, goal) <= max_step
            && interior_valid(checker, from, goal, res, &mut buf, clock) == Some(true)
    })?;
    let mut out = vec![0.0; n * dof];
    out[(n - 1) * dof..].copy_from_slice(goal);
    let mut k = end;
    for i in (1..n - 1).rev() {
        let at = i * nodes + k;
        out[i * dof..(i + 1) * dof].copy_from_slice(&q[at * dof..(at + 1) * dof]);
        k = parent[at];
    }
    out[..dof].copy_from_slice(start);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_are_numbered_centre_then_ring_by_ring() {
        assert_eq!(ring_and_direction(0), (0, 0));
        assert_eq!(ring_and_direction(1), (1, 0));
        let d = DIRECTIONS;
        assert_eq!(ring_and_direction(d), (1, d - 1));
        assert_eq!(ring_and_direction(d + 1), (2, 0));
        // the centre neighbours the first ring only; directions wrap around
        assert!(adjacent(0, 5, 1) && !adjacent(0, d + 1, 1));
        assert!(
            adjacent(1, d, 1) && adjacent(1, d + 1, 1) && adjacent(1, d + 2, 1) && !adjacent(1, d + 3, 1)
        );
        assert!(!adjacent(1, 2 * d + 1, 1));
        // two rings per step: the centre reaches the second ring
        assert!(adjacent(0, d + 1, 2) && adjacent(1, 2 * d + 1, 2) && !adjacent(0, 2 * d + 1, 2));
    }
}
