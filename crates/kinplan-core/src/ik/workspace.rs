//! Preallocated buffers of a solve, sized for one chain and reused across
//! attempts, requests and path steps, and the joint-limit rules applied to them.

use nalgebra::{DMatrix, DVector, Isometry3, Matrix6xX};

use super::{IkParams, JointLimitMode, PoseError};
use crate::linalg::{RlxaWorkspace, SvdWorkspace};
use crate::robot::Chain;

/// Preallocated buffers for every method, sized for one chain and reused across
/// attempts, requests and path steps.
#[derive(Debug, Clone)]
pub struct IkWorkspace {
    pub(crate) q: Vec<f64>,
    pub(crate) q_trial: Vec<f64>,
    pub(crate) q_best: Vec<f64>,
    pub(crate) limits: Vec<(f64, f64)>,
    /// Per joint: rotational with a range of at least one full turn (such a joint can
    /// leave its range by whole turns without changing the pose).
    pub(crate) wraps: Vec<bool>,
    pub(crate) jac: Matrix6xX<f64>,
    pub(crate) jac_trial: Matrix6xX<f64>,
    pub(crate) a: DMatrix<f64>,
    pub(crate) b: DVector<f64>,
    pub(crate) x: DVector<f64>,
    pub(crate) svd: SvdWorkspace,
    pub(crate) rlxa: RlxaWorkspace,
    pub(crate) frames: Vec<Isometry3<f64>>,
    pub(crate) points: super::point_chain::PointWorkspace,
    /// Error history of the current attempt (only with `IkParams::record_history`).
    pub(crate) history: Vec<(f64, f64)>,
}

impl IkWorkspace {
    /// Buffers for `chain` (the only allocation of a solve).
    pub fn new(chain: &Chain) -> Self {
        let n = chain.dof();
        Self {
            q: vec![0.0; n],
            q_trial: vec![0.0; n],
            q_best: vec![0.0; n],
            limits: chain.limits().collect(),
            wraps: chain
                .joints()
                .iter()
                .map(|j| j.is_rotational() && j.upper - j.lower >= std::f64::consts::TAU)
                .collect(),
            jac: Matrix6xX::zeros(n),
            jac_trial: Matrix6xX::zeros(n),
            a: DMatrix::zeros(6, n),
            b: DVector::zeros(6),
            x: DVector::zeros(n),
            svd: SvdWorkspace::new(6, n),
            rlxa: RlxaWorkspace::new(6, n),
            frames: Vec::with_capacity(n),
            points: super::point_chain::PointWorkspace::default(),
            history: Vec::new(),
        }
    }

    /// Appends one iteration's error to the history when the request asked for it.
    #[inline]
    pub(crate) fn record(&mut self, params: &IkParams, err: &PoseError) {
        if params.record_history {
            self.history.push((err.position, err.orientation));
        }
    }

    /// Makes the history end with the error the attempt returns.
    pub(crate) fn finish_history(&mut self, params: &IkParams, err: &PoseError) {
        if params.record_history && self.history.last() != Some(&(err.position, err.orientation)) {
            self.history.push((err.position, err.orientation));
        }
    }

    pub(crate) fn ensure_system(&mut self, rows: usize, cols: usize) {
        if self.a.shape() != (rows, cols) {
            self.a = DMatrix::zeros(rows, cols);
            self.b = DVector::zeros(rows);
        }
        if self.x.len() != cols {
            self.x = DVector::zeros(cols);
        }
    }

    /// Clamps `q` into the limits when `mode` is `Clamp` (unlimited joints untouched).
    pub(crate) fn apply_limits(limits: &[(f64, f64)], mode: JointLimitMode, q: &mut [f64]) {
        if mode == JointLimitMode::Clamp {
            for (v, &(lo, hi)) in q.iter_mut().zip(limits) {
                if *v < lo {
                    *v = lo;
                } else if *v > hi {
                    *v = hi;
                }
            }
        }
    }

    /// Like [`apply_limits`](Self::apply_limits), but a joint flagged in `wraps` that left
    /// its range is first moved back by whole turns (same pose, so the error is unchanged
    /// and the iterate does not stick to a limit it crossed only by turning past it).
    pub(crate) fn apply_limits_wrapping(
        limits: &[(f64, f64)],
        wraps: &[bool],
        mode: JointLimitMode,
        q: &mut [f64],
    ) {
        if mode == JointLimitMode::Clamp {
            for ((v, &(lo, hi)), &w) in q.iter_mut().zip(limits).zip(wraps) {
                if *v < lo || *v > hi {
                    *v = wrap_into_limits(*v, lo, hi, w, mode);
                }
            }
        }
    }
}

/// Puts a rotational joint value into `[lo, hi]` by adding whole turns when that is
/// possible, otherwise clamps (or leaves it, when `mode` is `Ignore`).
#[inline]
pub(crate) fn wrap_into_limits(v: f64, lo: f64, hi: f64, rotational: bool, mode: JointLimitMode) -> f64 {
    use std::f64::consts::TAU;
    if (lo..=hi).contains(&v) {
        return v;
    }
    if rotational && v.is_finite() {
        let k = if v > hi {
            ((v - hi) / TAU).ceil()
        } else {
            -((lo - v) / TAU).ceil()
        };
        let w = v - k * TAU;
        if (lo..=hi).contains(&w) {
            return w;
        }
    }
    if mode == JointLimitMode::Clamp {
        v.clamp(lo, hi)
    } else {
        v
    }
}
