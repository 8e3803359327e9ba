//! Runs the point-based heuristics (FABRIK, length relaxation) on a robot chain:
//! joint origins and the tool point become a point chain (plus virtual axis points for
//! 3-D length relaxation, S2 Fig. 27), the points are relaxed, and the joint angles are
//! read back from them; repeated until the true forward kinematics meets the tolerance.
//!
//! Reading back (root to tip): joint `i` (world axis `z`, origin `o`) is turned by the
//! angle that best maps the current distal points `aₖ` onto their relaxed positions `bₖ`,
//! `θ = atan2(Σ z·(aₖ × bₖ), Σ (aₖ·bₖ − (z·aₖ)(z·bₖ)))` (relative to `o`), clamped into
//! the limits. For a planar chain whose relaxation met the length tolerance this
//! reproduces the relaxed points exactly.

use nalgebra::{Isometry3, Vector3};

use super::attempt::{Attempt, Clock, Progress, stop_before_iteration};
use super::fabrik::{PointChainReport, fabrik_core};
use super::length_relaxation::{RelaxationGraph, length_relaxation_core};
use super::workspace::{IkWorkspace, wrap_into_limits};
use super::{IkError, IkMethod, IkParams, IkStatus, IkTarget, pose_error};
use crate::robot::Chain;

/// 3-D length relaxation: one sweep pair, then the angles are read back and the points
/// rebuilt from the true pose (relax, then project onto the revolute chain). Relaxing the
/// rigid construction ([`build_virtual_graph`]) to convergence before reading back, as S2
/// describes it, converges too slowly: the lengths need hundreds of sweeps. One sweep
/// per read-back solves the most targets; more sweeps per read-back solve far fewer,
/// even without an iteration cap (`benches/IK_RESULTS.md`).
const VIRTUAL_SWEEPS_PER_READ_BACK: usize = 1;
/// Outer iterations (read-backs) without 1 % progress before the attempt is abandoned.
const STALL_OUTER: usize = 10;

/// Buffers of the point-based heuristics.
#[derive(Debug, Clone, Default)]
pub struct PointWorkspace {
    pts: Vec<Vector3<f64>>,
    lengths: Vec<f64>,
    desired: Vec<Vector3<f64>>,
    graph: RelaxationGraph,
}

/// Refuses what FABRIK / length relaxation cannot do: orientation targets, prismatic joints.
pub(crate) fn check_servable(chain: &Chain, target: &IkTarget, method: IkMethod) -> Result<(), IkError> {
    if !target.is_position_only() {
        return Err(IkError::MethodCannotServe {
            method,
            reason: "it solves position targets only: set position_only (or give a 3-vector target), \
                     or use \"ccd\" or a Jacobian method (\"lm\", \"jacobian_inverse\", \"newton\") for an orientation target"
                .into(),
        });
    }
    if let Some(j) = chain.joints().iter().find(|j| !j.is_rotational()) {
        return Err(IkError::MethodCannotServe {
            method,
            reason: format!(
                "joint `{}` is prismatic; the point-based heuristics need revolute joints",
                j.name
            ),
        });
    }
    Ok(())
}

/// True when every joint axis is parallel to the first and every joint origin, the tool
/// and the target lie in one plane perpendicular to it.
fn is_planar(
    frames: &[Isometry3<f64>],
    chain: &Chain,
    tip: &Isometry3<f64>,
    target: &Vector3<f64>,
    tol: f64,
) -> bool {
    let z0 = frames[0].rotation * chain.joints()[0].axis.into_inner();
    let o0 = frames[0].translation.vector;
    for (f, j) in frames.iter().zip(chain.joints()) {
        let z = f.rotation * j.axis.into_inner();
        if z.cross(&z0).norm() > 1e-9 || z0.dot(&(f.translation.vector - o0)).abs() > 1e-9 {
            return false;
        }
    }
    z0.dot(&(tip.translation.vector - o0)).abs() <= 1e-9 && z0.dot(&(target - o0)).abs() <= tol
}

pub(crate) fn run(
    chain: &Chain,
    target: &IkTarget,
    params: &IkParams,
    ws: &mut IkWorkspace,
    clock: &Clock<'_>,
) -> Attempt {
    let n = chain.dof();
    let goal = target.position();
    IkWorkspace::apply_limits(&ws.limits, params.joint_limits, &mut ws.q);
    let tip0 = chain.joint_frames_into(&ws.q, &mut ws.frames);
    let planar = is_planar(&ws.frames, chain, &tip0, &goal, params.position_tolerance);
    let use_virtual = !planar && params.method == IkMethod::LengthRelaxation;
    // Virtual point offset h along each axis: the mean link length (S2 Fig. 27, any h works).
    let h = {
        let mut total = 0.0;
        for i in 1..n {
            total += (ws.frames[i].translation.vector - ws.frames[i - 1].translation.vector).norm();
        }
        total += (tip0.translation.vector - ws.frames[n - 1].translation.vector).norm();
        (total / n as f64).max(0.05)
    };
    let inner_tol = params.position_tolerance / (2.0 * n as f64 + 2.0);
    let mut it = 0;
    let mut best_sq = f64::INFINITY;
    let mut progress = Progress::new(0.99, STALL_OUTER, f64::INFINITY);
    let (status, err) = loop {
        let tip = chain.joint_frames_into(&ws.q, &mut ws.frames);
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
        let budget = params.max_iterations - it;
        let mut keep_going = || clock.interrupted().is_none();
        let pw = &mut ws.points;
        pw.pts.clear();
        for f in ws.frames.iter() {
            pw.pts.push(f.translation.vector);
        }
        pw.pts.push(tip.translation.vector);
        pw.lengths.clear();
        for i in 0..n {
            pw.lengths.push((pw.pts[i + 1] - pw.pts[i]).norm());
        }
        let rep: PointChainReport;
        if use_virtual {
            let g = &mut pw.graph;
            build_virtual_graph(chain, &ws.frames, &pw.pts, h, g);
            let v = |i: usize| n + 1 + i;
            g.points[n] = goal;
            let mut sweeps = 0;
            let mut viol = g.max_violation();
            // A few sweeps, then read the angles back and relax again from the true pose.
            let cap = budget.min(VIRTUAL_SWEEPS_PER_READ_BACK);
            while viol > inner_tol && sweeps < cap && keep_going() {
                sweeps += 1;
                g.sweep_from(&[0, v(0)]);
                g.sweep_from(&[n]);
                viol = g.max_violation();
            }
            rep = PointChainReport {
                iterations: sweeps,
                error: viol,
                converged: viol <= inner_tol,
                out_of_reach: false,
            };
            pw.desired.clear();
            pw.desired.extend_from_slice(&g.points);
        } else {
            rep = match params.method {
                IkMethod::Fabrik => fabrik_core(
                    &mut pw.pts,
                    &pw.lengths,
                    &goal,
                    inner_tol,
                    budget,
                    &mut keep_going,
                ),
                _ => length_relaxation_core(
                    &mut pw.pts,
                    &pw.lengths,
                    &goal,
                    inner_tol,
                    budget,
                    &mut keep_going,
                ),
            };
            pw.desired.clear();
            pw.desired.extend_from_slice(&pw.pts);
        }
        it += rep.iterations.max(1);
        read_back(chain, params, ws, use_virtual, h);
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

/// The S2 Fig. 27 construction for a 3-D revolute chain: joint origins `pᵢ` (`points[i]`,
/// `i < n`), the tool point `pₙ`, and a virtual point `vᵢ = pᵢ + h zᵢ` on every joint
/// axis (index `n + 1 + i`). Links, with their current lengths: `pᵢ–pᵢ₊₁`, `pᵢ–vᵢ` (h),
/// `vᵢ–pᵢ₋₁` and `vᵢ–pᵢ₊₁` (S2's "both neighbours", Pythagoras), and `vᵢ₋₁–vᵢ`.
/// The last one makes `{pᵢ₋₁, vᵢ₋₁, pᵢ, vᵢ}` a tetrahedron with all six edges fixed —
/// one rigid link body hinged on the axis `pᵢ–vᵢ` it shares with the next — so the
/// structure keeps exactly the `n` joint rotations as its motions (checked by the rank
/// of its rigidity matrix in the tests); without it every `vᵢ` could also spin about
/// `pᵢ₋₁–pᵢ`. `p₀`, `v₀` (the base axis) and `pₙ` are fixed.
pub(crate) fn build_virtual_graph(
    chain: &Chain,
    frames: &[Isometry3<f64>],
    points: &[Vector3<f64>],
    h: f64,
    g: &mut RelaxationGraph,
) {
    let n = chain.dof();
    g.clear();
    for (i, p) in points.iter().enumerate() {
        g.add_point(*p, i == 0 || i == n);
    }
    for (i, f) in frames.iter().enumerate().take(n) {
        let z = f.rotation * chain.joints()[i].axis.into_inner();
        g.add_point(f.translation.vector + z * h, i == 0);
    }
    let v = |i: usize| n + 1 + i;
    for i in 0..n {
        g.link_current(i, i + 1);
        g.link_current(i, v(i));
        if i > 0 {
            g.link_current(v(i), i - 1);
            g.link_current(v(i), v(i - 1));
        }
        g.link_current(v(i), i + 1);
    }
}

/// Turns each joint, root to tip, to map its distal points onto `ws.points.desired`.
fn read_back(chain: &Chain, params: &IkParams, ws: &mut IkWorkspace, with_virtual: bool, h: f64) {
    let n = chain.dof();
    for i in 0..n {
        let tip = chain.joint_frames_into(&ws.q, &mut ws.frames);
        let f = &ws.frames[i];
        let z = f.rotation * chain.joints()[i].axis.into_inner();
        let o = f.translation.vector;
        let (mut num, mut den) = (0.0, 0.0);
        let mut add = |cur: Vector3<f64>, want: Vector3<f64>| {
            let a = cur - o;
            let b = want - o;
            num += z.dot(&a.cross(&b));
            den += a.dot(&b) - z.dot(&a) * z.dot(&b);
        };
        let desired = &ws.points.desired;
        for k in (i + 1)..n {
            add(ws.frames[k].translation.vector, desired[k]);
            if with_virtual {
                let zk = ws.frames[k].rotation * chain.joints()[k].axis.into_inner();
                add(ws.frames[k].translation.vector + zk * h, desired[n + 1 + k]);
            }
        }
        add(tip.translation.vector, desired[n]);
        if num == 0.0 && den == 0.0 {
            continue;
        }
        let (lo, hi) = ws.limits[i];
        ws.q[i] = wrap_into_limits(ws.q[i] + num.atan2(den), lo, hi, true, params.joint_limits);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::{ChainSpec, UrdfLimits, parse_chain};
    use nalgebra::DMatrix;

    /// Five revolute joints with skew axes and offsets, and a tool point off the last
    /// axis: no two consecutive axes are parallel or intersecting, so every link
    /// tetrahedron is non-degenerate.
    const SKEW_URDF: &str = r#"<robot name="skew">
  <link name="l0"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.05 0.1 0.3" rpy="0.3 0 0.2"/><axis xyz="1 0.2 0"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.25 -0.05 0.1" rpy="0 0.4 0"/><axis xyz="0 1 0.3"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0.2 0.1 -0.05" rpy="0.2 0.1 0"/><axis xyz="0.3 0 1"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/>
    <origin xyz="0.1 0.15 0.05" rpy="0 0 0.5"/><axis xyz="1 0 0.4"/><limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
  <link name="tool"/>
  <joint name="flange" type="fixed"><parent link="l5"/><child link="tool"/><origin xyz="0.1 0.05 0.08"/></joint>
</robot>"#;

    /// Graph of the chain at `q`, tool point free (to count the chain's own motions).
    fn graph_at(chain: &Chain, q: &[f64], with_vv: bool) -> RelaxationGraph {
        let mut frames = Vec::new();
        let tip = chain.joint_frames_into(q, &mut frames);
        let mut pts: Vec<Vector3<f64>> = frames.iter().map(|f| f.translation.vector).collect();
        pts.push(tip.translation.vector);
        let mut g = RelaxationGraph::default();
        build_virtual_graph(chain, &frames, &pts, 0.2, &mut g);
        let n = chain.dof();
        g.fixed[n] = false;
        if !with_vv {
            for i in 1..n {
                let (a, b) = (n + 1 + i, n + i);
                g.adjacency[a].retain(|&(k, _)| k != b);
                g.adjacency[b].retain(|&(k, _)| k != a);
            }
        }
        g
    }

    /// Dimension of the infinitesimal motions that keep every link length (free points
    /// only): `3 · free − rank(R)` for the rigidity matrix `R` (one row per link,
    /// `(pᵢ − pⱼ)ᵀ` in `i`'s columns and `(pⱼ − pᵢ)ᵀ` in `j`'s).
    fn motions(g: &RelaxationGraph) -> usize {
        let np = g.points.len();
        let col: Vec<Option<usize>> = {
            let mut next = 0;
            (0..np)
                .map(|i| {
                    (!g.fixed[i]).then(|| {
                        next += 1;
                        next - 1
                    })
                })
                .collect()
        };
        let free = col.iter().flatten().count();
        let mut rows = Vec::new();
        for i in 0..np {
            for &(j, _) in &g.adjacency[i] {
                if j > i {
                    let mut r = vec![0.0; 3 * free];
                    let d = g.points[i] - g.points[j];
                    for (p, sign) in [(i, 1.0), (j, -1.0)] {
                        if let Some(c) = col[p] {
                            for k in 0..3 {
                                r[3 * c + k] = sign * d[k];
                            }
                        }
                    }
                    rows.push(r);
                }
            }
        }
        let m = DMatrix::from_fn(rows.len(), 3 * free, |r, c| rows[r][c]);
        3 * free - m.rank(1e-9)
    }

    #[test]
    fn virtual_joint_construction_keeps_exactly_the_joint_rotations() {
        let chain = parse_chain(SKEW_URDF, &ChainSpec::default(), UrdfLimits::default()).unwrap();
        for q in [[0.0; 5], [0.4, -0.7, 1.1, 0.3, -1.4], [2.0, 1.0, -2.5, 0.9, 0.2]] {
            assert_eq!(motions(&graph_at(&chain, &q, true)), chain.dof(), "q = {q:?}");
            // without the vᵢ₋₁–vᵢ links each inner axis point can also spin
            assert!(motions(&graph_at(&chain, &q, false)) > chain.dof(), "q = {q:?}");
        }
    }

    /// Every link length of the construction is the same in any pose of the chain: the
    /// joint motions are motions of the structure (so relaxing it cannot rule out a
    /// reachable pose).
    #[test]
    fn link_lengths_are_invariant_under_joint_motion() {
        let chain = parse_chain(SKEW_URDF, &ChainSpec::default(), UrdfLimits::default()).unwrap();
        let g0 = graph_at(&chain, &[0.0; 5], true);
        let moved = graph_at(&chain, &[0.9, -1.3, 0.4, 2.2, -0.6], true);
        let mut g = g0.clone();
        g.points.clone_from(&moved.points);
        assert!(g.max_violation() < 1e-12, "{}", g.max_violation());
    }
}
