//! Pseudo-jerk (third finite differences), its local peaks and the S0
//! "slowdown" regressions behind JJP and CJP (S0 eq. 2.6–2.14).

use super::error::{ScoreError, ScoreParam};

/// Third backward difference of four consecutive samples
/// `[x_{i−3}, x_{i−2}, x_{i−1}, x_i]`:
/// `Δ³x_i = x_i − 3·x_{i−1} + 3·x_{i−2} − x_{i−3}` (S0 "pseudo-jerk", eq. 2.6–2.9,
/// unit waypoint spacing; units of `x`).
///
/// ```
/// use kinplan_core::score::third_difference;
/// // a single displaced sample d = 2 seen through the stencil: 1, −3, 3, −1 times d
/// assert_eq!(third_difference([0.0, 0.0, 0.0, 2.0]), 2.0);
/// assert_eq!(third_difference([0.0, 0.0, 2.0, 0.0]), -6.0);
/// assert_eq!(third_difference([1.0, 2.0, 3.0, 4.0]), 0.0); // linear: no jerk
/// ```
#[inline]
pub fn third_difference(x: [f64; 4]) -> f64 {
    x[3] - 3.0 * x[2] + 3.0 * x[1] - x[0]
}

/// Third time derivative estimated from four samples at strictly increasing
/// times `t`: `6 · x[t_0, t_1, t_2, t_3]` (Newton's third divided difference).
/// For a uniform step `h` it equals `Δ³x / h³`; it is exact for cubics.
/// Units: units of `x` per s³. Not an S0 criterion: offered when timestamps are
/// given (see `TimeScaledJerk`).
///
/// ```
/// use kinplan_core::score::third_derivative;
/// // x = t³ has x''' = 6 everywhere, whatever the spacing
/// let t = [0.0, 0.5, 1.7, 2.0];
/// let x = t.map(|t: f64| t.powi(3));
/// assert!((third_derivative(x, t) - 6.0).abs() < 1e-12);
/// ```
#[inline]
pub fn third_derivative(x: [f64; 4], t: [f64; 4]) -> f64 {
    let d01 = (x[1] - x[0]) / (t[1] - t[0]);
    let d12 = (x[2] - x[1]) / (t[2] - t[1]);
    let d23 = (x[3] - x[2]) / (t[3] - t[2]);
    let d012 = (d12 - d01) / (t[2] - t[0]);
    let d123 = (d23 - d12) / (t[3] - t[1]);
    6.0 * (d123 - d012) / (t[3] - t[0])
}

/// Weights `w` with `6 · x[t_0, t_1, t_2, t_3] = Σ_k w_k x_k`:
/// `w_k = 6 / Π_{l≠k} (t_k − t_l)` (Lagrange form of the divided difference).
/// Computing them once per window lets every joint's time-scaled jerk cost
/// four multiply-adds instead of nine divisions.
///
/// ```
/// use kinplan_core::score::{third_derivative, third_derivative_weights};
/// let (t, x) = ([0.0, 0.4, 1.0, 1.9], [0.3, -0.1, 0.8, 2.0]);
/// let w = third_derivative_weights(t);
/// let via_w: f64 = w.iter().zip(x).map(|(w, x)| w * x).sum();
/// assert!((via_w - third_derivative(x, t)).abs() < 1e-12);
/// ```
#[inline]
pub fn third_derivative_weights(t: [f64; 4]) -> [f64; 4] {
    let d = |k: usize| {
        let mut p = 1.0;
        for (l, tl) in t.iter().enumerate() {
            if l != k {
                p *= t[k] - tl;
            }
        }
        6.0 / p
    };
    [d(0), d(1), d(2), d(3)]
}

/// Coefficients of the S0 slowdown regressions and the peak finder.
///
/// Joint space (S0 eq. 2.11, 2.13): `slowdown = a · log10(P) + b`.
/// Cartesian space (S0 eq. 2.12, 2.14): `slowdown = c · √P + d`.
/// The print of eq. 2.12 reads `1000·√2/2·√x + ∛4` (typeset garbled); eq. 2.14
/// repeats it with a trailing `+ 4` that eq. 2.12 lacks — we follow eq. 2.12
/// (docs/scoring.md#criteria); set `cartesian_offset` to `∛4 + 4` for the other reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JerkPeakParams {
    /// `a`, slowdown per decade of joint pseudo-jerk (dimensionless). Default 3.
    pub joint_log_gain: f64,
    /// `b`, joint slowdown at `P = 1` rad (dimensionless). Default 4.
    pub joint_offset: f64,
    /// `c`, Cartesian slowdown per √m of pseudo-jerk. Default `1000·√2/2`.
    pub cartesian_sqrt_gain: f64,
    /// `d`, Cartesian slowdown offset (dimensionless). Default `∛4`.
    pub cartesian_offset: f64,
    /// Joint peaks no higher than this (rad) are ignored. It keeps round-off
    /// ripple (~1e-16) of a smooth path out of JJP, where `log10` would turn
    /// it into large negative slowdowns. Default 1e-9 rad; must be ≥ 0.
    pub joint_min_height: f64,
    /// Cartesian peaks no higher than this (m) are ignored. Default 1e-9 m.
    pub cartesian_min_height: f64,
    /// Whether a series that starts (ends) on its highest run counts that run
    /// as a peak. Default `false`, as `scipy.signal.find_peaks`: a peak needs a
    /// lower neighbour on both sides.
    pub edge_peaks: bool,
    /// Lower bound applied to every predicted slowdown before summing, e.g.
    /// 0 (small peaks add nothing) or 1 (S0's measured slowdown `f(i)` is ≥ 1
    /// by definition, eq. 2.10). Default `−∞`: the regressions as printed, under
    /// which a peak below 10^(−b/a) rad subtracts from JJP. Must not be NaN.
    pub slowdown_floor: f64,
}

impl Default for JerkPeakParams {
    fn default() -> Self {
        Self {
            joint_log_gain: 3.0,
            joint_offset: 4.0,
            cartesian_sqrt_gain: 1000.0 * std::f64::consts::SQRT_2 / 2.0,
            cartesian_offset: 4f64.cbrt(),
            joint_min_height: 1e-9,
            cartesian_min_height: 1e-9,
            edge_peaks: false,
            slowdown_floor: f64::NEG_INFINITY,
        }
    }
}

impl JerkPeakParams {
    /// Coefficients finite, minimum heights finite and ≥ 0.
    pub fn validate(&self) -> Result<(), ScoreError> {
        for (name, value) in [
            (ScoreParam::JointLogGain, self.joint_log_gain),
            (ScoreParam::JointOffset, self.joint_offset),
            (ScoreParam::CartesianSqrtGain, self.cartesian_sqrt_gain),
            (ScoreParam::CartesianOffset, self.cartesian_offset),
        ] {
            if !value.is_finite() {
                return Err(ScoreError::InvalidParam {
                    name,
                    value,
                    reason: "must be finite",
                });
            }
        }
        for (name, value) in [
            (ScoreParam::JointMinHeight, self.joint_min_height),
            (ScoreParam::CartesianMinHeight, self.cartesian_min_height),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ScoreError::InvalidParam {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        if self.slowdown_floor.is_nan() || self.slowdown_floor == f64::INFINITY {
            return Err(ScoreError::InvalidParam {
                name: ScoreParam::SlowdownFloor,
                value: self.slowdown_floor,
                reason: "must be finite or -inf",
            });
        }
        Ok(())
    }
}

/// Predicted joint-space slowdown at a pseudo-jerk peak `p` (rad, > 0):
/// `max(a · log10(p) + b, floor)` (S0 eq. 2.11; `floor` =
/// `slowdown_floor`, `−∞` by default). As printed it is below 1 — and
/// negative — for small peaks (`p < 10^(−b/a)` ≈ 0.046 rad with the defaults).
///
/// ```
/// use kinplan_core::score::{joint_slowdown, JerkPeakParams};
/// let p = JerkPeakParams::default();
/// assert!((joint_slowdown(100.0, &p) - 10.0).abs() < 1e-12); // 3·2 + 4
/// ```
#[inline]
pub fn joint_slowdown(p: f64, params: &JerkPeakParams) -> f64 {
    (params.joint_log_gain * p.log10() + params.joint_offset).max(params.slowdown_floor)
}

/// Predicted Cartesian slowdown at a pseudo-jerk peak `p` (m, ≥ 0):
/// `max(c · √p + d, floor)` (S0 eq. 2.12; `floor` = `slowdown_floor`).
///
/// ```
/// use kinplan_core::score::{cartesian_slowdown, JerkPeakParams};
/// let p = JerkPeakParams::default();
/// let y = cartesian_slowdown(0.0004, &p); // 707.1…·0.02 + ∛4
/// assert!((y - (1000.0 * 0.5f64.sqrt() * 0.02 + 4f64.cbrt())).abs() < 1e-9);
/// ```
#[inline]
pub fn cartesian_slowdown(p: f64, params: &JerkPeakParams) -> f64 {
    (params.cartesian_sqrt_gain * p.sqrt() + params.cartesian_offset).max(params.slowdown_floor)
}

/// A local maximum of a per-waypoint pseudo-jerk series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// Waypoint index (for a flat-topped run of equal values, its middle,
    /// rounded down — the `scipy.signal.find_peaks` convention).
    pub index: usize,
    /// Peak height `P` (rad summed over joints, or m).
    pub height: f64,
}

/// Streaming local-maximum finder: push the series in index order, then
/// `finish`. A peak is a maximal run of equal values whose neighbours on both
/// sides are strictly lower (at the series' ends only with `edge`). No
/// allocation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PeakDetector {
    edge: bool,
    started: bool,
    rising: bool,
    prev: f64,
    run_start: usize,
    last: usize,
}

impl PeakDetector {
    pub(crate) fn new(edge: bool) -> Self {
        Self {
            edge,
            started: false,
            rising: false,
            prev: 0.0,
            run_start: 0,
            last: 0,
        }
    }

    /// Feeds sample `v` at waypoint `i`; returns the peak that `v` closes.
    #[inline]
    pub(crate) fn push(&mut self, i: usize, v: f64) -> Option<Peak> {
        let mut out = None;
        if !self.started {
            self.started = true;
            self.rising = self.edge;
            self.run_start = i;
        } else if v > self.prev {
            self.rising = true;
            self.run_start = i;
        } else if v < self.prev {
            if self.rising {
                out = Some(Peak {
                    index: self.run_start + (self.last - self.run_start) / 2,
                    height: self.prev,
                });
            }
            self.rising = false;
        }
        self.prev = v;
        self.last = i;
        out
    }

    /// The run at the end of the series, when `edge` peaks are counted.
    pub(crate) fn finish(&self) -> Option<Peak> {
        (self.started && self.edge && self.rising).then(|| Peak {
            index: self.run_start + (self.last - self.run_start) / 2,
            height: self.prev,
        })
    }
}

/// Local peaks of a whole series (`series[i]` belongs to waypoint `i`), with
/// the same rules as the scoring pass (heights must exceed `min_height`).
///
/// ```
/// use kinplan_core::score::find_peaks;
/// let s = [0.0, 0.0, 0.0, 1.0, 3.0, 3.0, 1.0, 0.0, 2.0, 0.0];
/// let idx: Vec<usize> = find_peaks(&s, 0.0, false).iter().map(|p| p.index).collect();
/// assert_eq!(idx, vec![4, 8]);
/// ```
pub fn find_peaks(series: &[f64], min_height: f64, edge: bool) -> Vec<Peak> {
    let mut det = PeakDetector::new(edge);
    let mut out = Vec::new();
    for (i, &v) in series.iter().enumerate() {
        out.extend(det.push(i, v).filter(|p| p.height > min_height));
    }
    out.extend(det.finish().filter(|p| p.height > min_height));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn third_difference_of_cubic_is_six() {
        let x = [0.0, 1.0, 8.0, 27.0];
        assert_eq!(third_difference(x), 6.0);
        assert_eq!(third_derivative(x, [0.0, 1.0, 2.0, 3.0]), 6.0);
    }

    #[test]
    fn time_scaled_matches_uniform_step() {
        let x = [0.3, -0.2, 0.9, 0.1];
        let h: f64 = 0.25;
        let t = [0.0, h, 2.0 * h, 3.0 * h];
        let want = third_difference(x) / h.powi(3);
        assert!((third_derivative(x, t) - want).abs() < 1e-9 * want.abs());
    }

    #[test]
    fn default_coefficients() {
        let p = JerkPeakParams::default();
        assert_eq!(joint_slowdown(1.0, &p), 4.0);
        assert!((joint_slowdown(10.0, &p) - 7.0).abs() < 1e-15);
        assert!(
            (cartesian_slowdown(1.0, &p) - (707.106_781_186_547_5 + 1.587_401_051_968_199_4)).abs() < 1e-9
        );
        assert!(p.validate().is_ok());
    }

    #[test]
    fn floor_bounds_small_peaks() {
        let p = JerkPeakParams {
            slowdown_floor: 1.0,
            ..Default::default()
        };
        assert_eq!(joint_slowdown(1e-6, &JerkPeakParams::default()), -14.0);
        assert_eq!(joint_slowdown(1e-6, &p), 1.0);
        assert_eq!(joint_slowdown(1000.0, &p), 13.0);
        let p = JerkPeakParams {
            slowdown_floor: 800.0,
            ..Default::default()
        };
        assert_eq!(cartesian_slowdown(0.0, &p), 800.0);
    }

    #[test]
    fn bad_params_rejected() {
        let p = JerkPeakParams {
            joint_log_gain: f64::NAN,
            ..Default::default()
        };
        assert!(matches!(
            p.validate(),
            Err(ScoreError::InvalidParam {
                name: ScoreParam::JointLogGain,
                ..
            })
        ));
        let p = JerkPeakParams {
            cartesian_min_height: -1.0,
            ..Default::default()
        };
        assert!(matches!(
            p.validate(),
            Err(ScoreError::InvalidParam {
                name: ScoreParam::CartesianMinHeight,
                ..
            })
        ));
    }

    #[test]
    fn plateau_peak_is_its_middle() {
        let s = [0.0, 1.0, 3.0, 3.0, 3.0, 1.0];
        let p = find_peaks(&s, 0.0, false);
        assert_eq!(
            p,
            vec![Peak {
                index: 3,
                height: 3.0
            }]
        );
        let s = [0.0, 1.0, 3.0, 3.0, 1.0];
        assert_eq!(find_peaks(&s, 0.0, false)[0].index, 2);
    }

    #[test]
    fn shoulder_is_not_a_peak() {
        // rising into a plateau then rising again: no peak at the plateau
        let s = [0.0, 2.0, 2.0, 5.0, 1.0];
        let p = find_peaks(&s, 0.0, false);
        assert_eq!(
            p,
            vec![Peak {
                index: 3,
                height: 5.0
            }]
        );
        // falling into a plateau then falling: no peak
        let s = [5.0, 2.0, 2.0, 1.0];
        assert!(find_peaks(&s, 0.0, false).is_empty());
    }

    #[test]
    fn edges_only_on_request() {
        let s = [4.0, 1.0, 2.0, 6.0];
        assert!(find_peaks(&s, 0.0, false).is_empty());
        let idx: Vec<usize> = find_peaks(&s, 0.0, true).iter().map(|p| p.index).collect();
        assert_eq!(idx, vec![0, 3]);
        // a constant series is one edge run
        assert_eq!(
            find_peaks(&[2.0, 2.0, 2.0], 0.0, true),
            vec![Peak {
                index: 1,
                height: 2.0
            }]
        );
        assert!(find_peaks(&[2.0, 2.0, 2.0], 0.0, false).is_empty());
        assert!(find_peaks(&[], 0.0, true).is_empty());
    }

    #[test]
    fn min_height_filters_ripple() {
        let s = [0.0, 1e-16, 0.0, 1e-16, 0.0, 0.5, 0.0];
        let p = find_peaks(&s, 1e-9, false);
        assert_eq!(
            p,
            vec![Peak {
                index: 5,
                height: 0.5
            }]
        );
    }
}
