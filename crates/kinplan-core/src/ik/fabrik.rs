//! FABRIK on a point chain (Aristidou & Lasenby 2011; docs/inverse-kinematics.md#heuristics).

use nalgebra::Vector3;

use super::{IkError, IkParam, TargetPart};

/// Outcome of a point-chain solve (FABRIK or length relaxation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointChainReport {
    /// Forward+backward passes done.
    pub iterations: usize,
    /// FABRIK: `‖p_n − t‖` (m). Length relaxation: `maxᵢ |‖pᵢ − pᵢ₋₁‖ − lᵢ|` (m).
    pub error: f64,
    /// `error ≤ tolerance`.
    pub converged: bool,
    /// The target is farther than the total length: the chain was stretched towards it.
    pub out_of_reach: bool,
}

pub(crate) fn check_point_chain(
    points: &[Vector3<f64>],
    lengths: &[f64],
    target: &Vector3<f64>,
    tolerance: f64,
) -> Result<(), IkError> {
    if points.len() < 2 || lengths.len() + 1 != points.len() {
        return Err(IkError::InvalidParam {
            field: IkParam::Lengths,
            value: lengths.len() as f64,
            reason: "need at least 2 points and exactly one length per consecutive pair",
        });
    }
    if points.iter().any(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(IkError::NonFiniteSeed {
            index: points
                .iter()
                .position(|p| p.iter().any(|v| !v.is_finite()))
                .unwrap_or(0),
        });
    }
    if lengths.iter().any(|l| !(l.is_finite() && *l >= 0.0)) {
        return Err(IkError::InvalidParam {
            field: IkParam::Lengths,
            value: f64::NAN,
            reason: "must be finite and >= 0",
        });
    }
    if target.iter().any(|v| !v.is_finite()) {
        return Err(IkError::NonFiniteTarget {
            field: TargetPart::Position,
        });
    }
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(IkError::InvalidParam {
            field: IkParam::PositionTolerance,
            value: tolerance,
            reason: "must be finite and > 0",
        });
    }
    Ok(())
}

/// Unit direction from `from` to `to`, with a fixed fallback for coincident points.
#[inline]
pub(crate) fn direction(from: &Vector3<f64>, to: &Vector3<f64>) -> Vector3<f64> {
    let d = to - from;
    let n = d.norm();
    if n > 1e-300 { d / n } else { Vector3::x() }
}

/// Stretches the chain along the line root → target (target out of reach).
pub(crate) fn stretch(points: &mut [Vector3<f64>], lengths: &[f64], target: &Vector3<f64>) {
    let dir = direction(&points[0], target);
    for i in 0..lengths.len() {
        points[i + 1] = points[i] + dir * lengths[i];
    }
}

/// FABRIK on the point chain `points[0..=n]` with link lengths `lengths[i] = ‖pᵢ₊₁ − pᵢ‖`;
/// `points[0]` is the root, `points[n]` the end effector.
///
/// Forward pass: `pₙ ← t`, then `pᵢ ← pᵢ₊₁ + lᵢ (pᵢ − pᵢ₊₁)/‖pᵢ − pᵢ₊₁‖` for `i = n−1…0`;
/// backward pass: `p₀ ← root`, then `pᵢ₊₁ ← pᵢ + lᵢ (pᵢ₊₁ − pᵢ)/‖pᵢ₊₁ − pᵢ‖`. Repeated
/// until `‖pₙ − t‖ ≤ tolerance` (m) or `max_iterations`. An unreachable target
/// (`‖t − p₀‖ > Σ lᵢ`) stretches the chain towards it.
///
/// ```
/// use nalgebra::Vector3;
/// use kinplan_core::ik::fabrik_points;
/// let mut p = vec![Vector3::zeros(), Vector3::new(0.5, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0)];
/// let r = fabrik_points(&mut p, &[0.5, 0.5], &Vector3::new(0.3, 0.6, 0.0), 1e-8, 1000).unwrap();
/// assert!(r.converged && (p[2] - Vector3::new(0.3, 0.6, 0.0)).norm() <= 1e-8);
/// assert!(((p[1] - p[0]).norm() - 0.5).abs() < 1e-12);
/// ```
pub fn fabrik_points(
    points: &mut [Vector3<f64>],
    lengths: &[f64],
    target: &Vector3<f64>,
    tolerance: f64,
    max_iterations: usize,
) -> Result<PointChainReport, IkError> {
    check_point_chain(points, lengths, target, tolerance)?;
    Ok(fabrik_core(
        points,
        lengths,
        target,
        tolerance,
        max_iterations,
        &mut || true,
    ))
}

pub(crate) fn fabrik_core(
    points: &mut [Vector3<f64>],
    lengths: &[f64],
    target: &Vector3<f64>,
    tolerance: f64,
    max_iterations: usize,
    keep_going: &mut dyn FnMut() -> bool,
) -> PointChainReport {
    let n = lengths.len();
    let root = points[0];
    let total: f64 = lengths.iter().sum();
    if (target - root).norm() > total {
        stretch(points, lengths, target);
        let error = (points[n] - target).norm();
        return PointChainReport {
            iterations: 1,
            error,
            converged: error <= tolerance,
            out_of_reach: true,
        };
    }
    let mut error = (points[n] - target).norm();
    let mut it = 0;
    while error > tolerance && it < max_iterations && keep_going() {
        it += 1;
        points[n] = *target;
        for i in (0..n).rev() {
            let d = direction(&points[i + 1], &points[i]);
            points[i] = points[i + 1] + d * lengths[i];
        }
        points[0] = root;
        for i in 0..n {
            let d = direction(&points[i], &points[i + 1]);
            points[i + 1] = points[i] + d * lengths[i];
        }
        error = (points[n] - target).norm();
    }
    PointChainReport {
        iterations: it,
        error,
        converged: error <= tolerance,
        out_of_reach: false,
    }
}
