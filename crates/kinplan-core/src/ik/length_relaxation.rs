//! Length relaxation (S2 §4.1, docs/inverse-kinematics.md#length-relaxation): fixed points
//! stay put, the others are moved along their links until every link length holds.

use nalgebra::Vector3;

use super::IkError;
use super::fabrik::{PointChainReport, check_point_chain, direction, stretch};

/// Length relaxation of one point (S2 eq. 38): `p' = l (p − q)/‖p − q‖ + q`.
#[inline]
pub fn relax_length(p: &Vector3<f64>, anchor: &Vector3<f64>, length: f64) -> Vector3<f64> {
    anchor + direction(anchor, p) * length
}

/// Length relaxation on a point chain whose root `points[0]` and end `points[n] = target`
/// are FIXED; the inner points are the approximating chain (S2 Fig. 21–24).
///
/// A forward sweep relaxes `p₁ … pₙ₋₁` against their predecessors (S2 eq. 38), stopping at
/// the fixed end; a backward sweep relaxes `pₙ₋₁ … p₁` against their successors. Repeated
/// until `maxᵢ |‖pᵢ − pᵢ₋₁‖ − lᵢ| ≤ tolerance` (m) or `max_iterations`. Unlike FABRIK the
/// end points are never moved. An unreachable target stretches the chain towards it.
///
/// ```
/// use nalgebra::Vector3;
/// use kinplan_core::ik::length_relaxation_points;
/// let mut p = vec![Vector3::zeros(), Vector3::new(0.5, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0)];
/// let t = Vector3::new(0.3, 0.6, 0.0);
/// let r = length_relaxation_points(&mut p, &[0.5, 0.5], &t, 1e-9, 1000).unwrap();
/// assert!(r.converged && p[2] == t && p[0] == Vector3::zeros());
/// assert!(((p[1] - p[0]).norm() - 0.5).abs() <= 1e-9 && ((p[2] - p[1]).norm() - 0.5).abs() <= 1e-9);
/// ```
pub fn length_relaxation_points(
    points: &mut [Vector3<f64>],
    lengths: &[f64],
    target: &Vector3<f64>,
    tolerance: f64,
    max_iterations: usize,
) -> Result<PointChainReport, IkError> {
    check_point_chain(points, lengths, target, tolerance)?;
    Ok(length_relaxation_core(
        points,
        lengths,
        target,
        tolerance,
        max_iterations,
        &mut || true,
    ))
}

pub(crate) fn max_length_violation(points: &[Vector3<f64>], lengths: &[f64]) -> f64 {
    lengths
        .iter()
        .enumerate()
        .map(|(i, l)| ((points[i + 1] - points[i]).norm() - l).abs())
        .fold(0.0, f64::max)
}

pub(crate) fn length_relaxation_core(
    points: &mut [Vector3<f64>],
    lengths: &[f64],
    target: &Vector3<f64>,
    tolerance: f64,
    max_iterations: usize,
    keep_going: &mut dyn FnMut() -> bool,
) -> PointChainReport {
    let n = lengths.len();
    let total: f64 = lengths.iter().sum();
    if (target - points[0]).norm() > total {
        stretch(points, lengths, target);
        let error = (points[n] - target).norm();
        return PointChainReport {
            iterations: 1,
            error,
            converged: error <= tolerance,
            out_of_reach: true,
        };
    }
    points[n] = *target;
    let mut error = max_length_violation(points, lengths);
    let mut it = 0;
    while error > tolerance && it < max_iterations && keep_going() {
        it += 1;
        for i in 1..n {
            points[i] = relax_length(&points[i], &points[i - 1], lengths[i - 1]);
        }
        for i in (1..n).rev() {
            points[i] = relax_length(&points[i], &points[i + 1], lengths[i]);
        }
        error = max_length_violation(points, lengths);
    }
    PointChainReport {
        iterations: it,
        error,
        converged: error <= tolerance,
        out_of_reach: false,
    }
}

const INNER_CYCLES: usize = 16;

/// A general structure for length relaxation: points, links with lengths, and fixed
/// points (S2 §4.1: branched and parallel structures, and the virtual joints of Fig. 27).
#[derive(Debug, Clone, Default)]
pub struct RelaxationGraph {
    pub points: Vec<Vector3<f64>>,
    pub fixed: Vec<bool>,
    /// `adjacency[i]` = `(j, length)` for every link `i–j`.
    pub adjacency: Vec<Vec<(usize, f64)>>,
    visited: Vec<bool>,
    queue: Vec<usize>,
}

impl RelaxationGraph {
    /// Removes all points and links, keeping the buffers.
    pub fn clear(&mut self) {
        self.points.clear();
        self.fixed.clear();
        for a in &mut self.adjacency {
            a.clear();
        }
    }

    /// Adds a point, returning its index.
    pub fn add_point(&mut self, p: Vector3<f64>, fixed: bool) -> usize {
        self.points.push(p);
        self.fixed.push(fixed);
        let i = self.points.len() - 1;
        if self.adjacency.len() <= i {
            self.adjacency.push(Vec::new());
        }
        i
    }

    /// Adds the link `i–j` with its current length (if not already there).
    pub fn link_current(&mut self, i: usize, j: usize) {
        if i == j || self.adjacency[i].iter().any(|&(k, _)| k == j) {
            return;
        }
        let l = (self.points[i] - self.points[j]).norm();
        self.adjacency[i].push((j, l));
        self.adjacency[j].push((i, l));
    }

    /// `max |‖pᵢ − pⱼ‖ − lᵢⱼ|` over all links (m).
    pub fn max_violation(&self) -> f64 {
        let mut m: f64 = 0.0;
        for (i, adj) in self.adjacency.iter().enumerate().take(self.points.len()) {
            for &(j, l) in adj {
                if j > i {
                    m = m.max(((self.points[i] - self.points[j]).norm() - l).abs());
                }
            }
        }
        m
    }

    /// One breadth-first sweep from `sources` (fixed points): each reached free point is
    /// relaxed (S2 eq. 38) against every neighbour already placed in this sweep; a branch
    /// stops at fixed points.
    pub fn sweep_from(&mut self, sources: &[usize]) {
        let np = self.points.len();
        self.visited.clear();
        self.visited.resize(np, false);
        self.queue.clear();
        for &s in sources {
            if s < np {
                self.visited[s] = true;
                self.queue.push(s);
            }
        }
        let mut head = 0;
        while head < self.queue.len() {
            let u = self.queue[head];
            head += 1;
            for idx in 0..self.adjacency[u].len() {
                let (w, _) = self.adjacency[u][idx];
                if self.visited[w] || self.fixed[w] {
                    continue;
                }
                // Relax against every placed neighbour, cyclically, until they all hold
                // (one pass when there is a single placed neighbour, as in S2's chain).
                let mut p = self.points[w];
                for _ in 0..INNER_CYCLES {
                    let mut worst: f64 = 0.0;
                    for &(k, l) in &self.adjacency[w] {
                        if self.visited[k] || self.fixed[k] {
                            worst = worst.max(((p - self.points[k]).norm() - l).abs());
                            p = relax_length(&p, &self.points[k], l);
                        }
                    }
                    if worst <= 1e-12 {
                        break;
                    }
                }
                self.points[w] = p;
                self.visited[w] = true;
                self.queue.push(w);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S2 Fig. 27 construction (rigid form) on the UR5 (3-D, offsets): the sweeps must shrink the
    /// largest link-length violation by an order of magnitude from the first sweep.
    #[test]
    fn virtual_joint_graph_relaxes_towards_consistent_lengths() {
        let chain = crate::robot::builtin_chain("ur5").unwrap();
        let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
        let goal = chain.fk(&q).translation.vector;
        let q0 = chain.mid_limits();
        let mut frames = Vec::new();
        let tip = chain.joint_frames_into(&q0, &mut frames);
        let n = chain.dof();
        let mut points: Vec<Vector3<f64>> = frames.iter().map(|f| f.translation.vector).collect();
        points.push(tip.translation.vector);
        let mut g = RelaxationGraph::default();
        super::super::point_chain::build_virtual_graph(&chain, &frames, &points, 0.2, &mut g);
        let v = |i: usize| n + 1 + i;
        g.points[n] = goal;
        g.sweep_from(&[0, v(0)]);
        g.sweep_from(&[n]);
        let first = g.max_violation();
        for _ in 0..200 {
            g.sweep_from(&[0, v(0)]);
            g.sweep_from(&[n]);
        }
        assert!(
            g.points[n] == goal && g.points[0] == frames[0].translation.vector,
            "fixed points moved"
        );
        assert!(
            g.max_violation() < first / 10.0,
            "{} vs {}",
            g.max_violation(),
            first
        );
    }

    #[test]
    fn planar_chain_lengths_hold_and_ends_stay() {
        let n = 5;
        let l = 0.2;
        let mut p: Vec<Vector3<f64>> = (0..=n).map(|i| Vector3::new(l * i as f64, 0.0, 0.0)).collect();
        let t = Vector3::new(0.3, 0.5, 0.0);
        let r = length_relaxation_points(&mut p, &vec![l; n], &t, 1e-10, 10_000).unwrap();
        assert!(r.converged);
        assert_eq!(p[0], Vector3::zeros());
        assert_eq!(p[n], t);
        assert!(max_length_violation(&p, &vec![l; n]) <= 1e-10);
    }

    #[test]
    fn out_of_reach_stretches_and_reports() {
        let mut p = vec![
            Vector3::zeros(),
            Vector3::new(0.5, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
        ];
        let t = Vector3::new(0.0, 3.0, 0.0);
        let r = length_relaxation_points(&mut p, &[0.5, 0.5], &t, 1e-6, 100).unwrap();
        assert!(r.out_of_reach && !r.converged);
        assert!((p[2] - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn bad_point_chains_are_errors() {
        let mut p = vec![Vector3::zeros(), Vector3::x()];
        assert!(length_relaxation_points(&mut p, &[1.0, 1.0], &Vector3::y(), 1e-6, 10).is_err());
        assert!(
            length_relaxation_points(&mut p, &[1.0], &Vector3::new(f64::NAN, 0.0, 0.0), 1e-6, 10).is_err()
        );
        assert!(length_relaxation_points(&mut p, &[1.0], &Vector3::y(), 0.0, 10).is_err());
    }
}
