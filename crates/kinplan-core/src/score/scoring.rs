//! `score`: all criteria of one trajectory in a single pass over its waypoints.

use super::criteria::{Scores, TimeScaledJerk, max_point_displacement, orientation_half_angle};
use super::cycle_time::{CycleTime, CycleTimeParams, cycle_time_unchecked};
use super::error::ScoreError;
use super::input::{ScoreInput, Shape};
use super::jerk::{
    JerkPeakParams, Peak, PeakDetector, cartesian_slowdown, joint_slowdown, third_derivative_weights,
    third_difference,
};

/// Options of [`score`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScoreParams {
    /// JJP/CJP regressions and peak finding (S0 eq. 2.11–2.14).
    pub peaks: JerkPeakParams,
    /// Time-potential search (S2 §3.3), used when the input has limits.
    pub cycle_time: CycleTimeParams,
    /// Also return the per-waypoint series. Default `false`.
    pub series: bool,
}

impl ScoreParams {
    /// Validates the nested parameter structs.
    pub fn validate(&self) -> Result<(), ScoreError> {
        self.peaks.validate()?;
        self.cycle_time.validate()
    }
}

/// Per-waypoint series, each of length `n` and indexed by waypoint: a step
/// term at `i` belongs to the step `i−1 → i` (entry 0 is 0); a jerk term at
/// `i` is the third difference ending at `i` (entries 0–2 are 0).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// `‖p_i − p_{i−1}‖`, m (CD's terms).
    pub cd: Vec<f64>,
    /// `Σ_j |q_{i,j} − q_{i−1,j}|`, rad (JD's terms).
    pub jd: Vec<f64>,
    /// `acos|⟨q_i, q_{i−1}⟩|`, rad (OC's terms; OC_geodesic's are twice these).
    pub oc: Vec<f64>,
    /// `Σ_j w_j |q_{i,j} − q_{i−1,j}|` (CPC's terms).
    pub cpc: Vec<f64>,
    /// `max_a ‖a(q_i) − a(q_{i−1})‖`, m (RDM's terms); `None` without points.
    pub rdm: Option<Vec<f64>>,
    /// Joint pseudo-jerk `Σ_j |Δ³q_{i,j}|`, rad (JJ's terms).
    pub joint_jerk: Vec<f64>,
    /// Cartesian pseudo-jerk `‖Δ³p_i‖`, m (CJ's terms).
    pub cartesian_jerk: Vec<f64>,
    /// Peaks of `joint_jerk` counted in JJP, with their slowdowns (S0 eq. 2.11).
    pub joint_peaks: Vec<CountedPeak>,
    /// Peaks of `cartesian_jerk` counted in CJP, with their slowdowns (S0 eq. 2.12).
    pub cartesian_peaks: Vec<CountedPeak>,
    /// Time-scaled `Σ_j |q⃛_{i,j}|`, rad/s³; `None` without timestamps.
    pub joint_jerk_rate: Option<Vec<f64>>,
    /// Time-scaled `‖p⃛_i‖`, m/s³; `None` without timestamps.
    pub cartesian_jerk_rate: Option<Vec<f64>>,
}

/// A jerk peak above its minimum height, counted in JJP or CJP, with the
/// slowdown it predicts ([`joint_slowdown`] or [`cartesian_slowdown`] of its
/// height); JJP / CJP are the sums of these slowdowns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CountedPeak {
    /// Waypoint index of the peak.
    pub index: usize,
    /// Peak height `P` (rad summed over joints, or m).
    pub height: f64,
    /// Predicted slowdown at the peak.
    pub slowdown: f64,
}

impl Series {
    fn zeros(n: usize, points: bool, timed: bool) -> Self {
        let z = || vec![0.0; n];
        Self {
            cd: z(),
            jd: z(),
            oc: z(),
            cpc: z(),
            rdm: points.then(z),
            joint_jerk: z(),
            cartesian_jerk: z(),
            joint_peaks: Vec::new(),
            cartesian_peaks: Vec::new(),
            joint_jerk_rate: timed.then(z),
            cartesian_jerk_rate: timed.then(z),
        }
    }
}

/// What [`score`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct ScoreReport {
    /// Validated sizes.
    pub shape: Shape,
    /// The criteria.
    pub scores: Scores,
    /// Per-waypoint series, when `ScoreParams::series` is set.
    pub series: Option<Series>,
    /// Cycle time details, when the input has joint limits.
    pub cycle_time: Option<CycleTime>,
}

/// Scores one trajectory on every criterion of S0 §2 (docs/scoring.md#criteria) and,
/// with joint limits, the PTP cycle time of S2 §3.3.
///
/// With waypoints `i = 0 … n−1`, joints `j`, tool positions `p_i`, tool
/// quaternions `r_i`, robot points `A`, weights `w_j`:
/// - CD  = Σ_{i≥1} ‖p_i − p_{i−1}‖ (S0 eq. 2.1)
/// - JD  = Σ_{i≥1} Σ_j |q_{i,j} − q_{i−1,j}| (S0 eq. 2.2)
/// - OC  = Σ_{i≥1} acos(clamp(|⟨r_i, r_{i−1}⟩|)) — half the step rotation
///   angles, sign-safe (S0 eq. 2.3; see [`super::orientation_half_angle`]);
///   OC_geodesic = 2·OC
/// - CPC = Σ_{i≥1} Σ_j w_j |q_{i,j} − q_{i−1,j}| (S0 eq. 2.4)
/// - RDM = Σ_{i≥1} max_{a∈A} ‖a(q_i) − a(q_{i−1})‖ (S0 eq. 2.5)
/// - JJ = Σ_{i≥3} Σ_j |Δ³q_{i,j}|, CJ = Σ_{i≥3} ‖Δ³p_i‖, JMJ = max_i Σ_j |Δ³q_{i,j}|,
///   CMJ = max_i ‖Δ³p_i‖ (S0 eq. 2.6–2.9; `Δ³` of [`super::third_difference`],
///   unit waypoint spacing, as S0 — timestamps do not change these)
/// - JJP = Σ_peaks a·log10(P) + b over local peaks of `Σ_j |Δ³q_{i,j}|`,
///   CJP = Σ_peaks c·√P + d over local peaks of `‖Δ³p_i‖` (S0 eq. 2.11–2.14,
///   [`JerkPeakParams`])
///
/// With timestamps it adds [`TimeScaledJerk`]. Short trajectories: `n < 2`
/// gives 0 for every distance, `n < 4` gives 0 for every jerk criterion and
/// no peaks. One pass, no allocation per waypoint (the optional series and
/// cycle-time vectors are allocated once).
///
/// ```
/// use kinplan_core::score::{score, Rows, ScoreInput, ScoreParams, TrajectoryData};
/// use nalgebra::{Isometry3, Vector3};
/// // two joints moving 0.1 and −0.2 rad per step; tool moving 0.3 m along x
/// let q: Vec<f64> = (0..5).flat_map(|i| [0.1 * i as f64, -0.2 * i as f64]).collect();
/// let poses: Vec<_> = (0..5).map(|i| Isometry3::translation(0.3 * i as f64, 0.0, 0.0)).collect();
/// let input = ScoreInput::new(TrajectoryData::new(Rows::Flat { values: &q, width: 2 }, &poses));
/// let r = score(&input, &ScoreParams::default()).unwrap();
/// assert!((r.scores.jd - 1.2).abs() < 1e-12);
/// assert!((r.scores.cd - 1.2).abs() < 1e-12);
/// assert!(r.scores.jj < 1e-12 && r.scores.joint_peak_count == 0);
/// ```
pub fn score(input: &ScoreInput<'_>, params: &ScoreParams) -> Result<ScoreReport, ScoreError> {
    params.validate()?;
    let shape = input.validate()?;
    let n = shape.waypoints;
    let traj = &input.trajectory;
    let q = &traj.joints;
    let poses = traj.poses;
    let points = traj.robot_points.as_ref();
    let ts = traj.timestamps;
    let pk = &params.peaks;

    let mut s = Scores {
        waypoints: n,
        rdm: points.map(|_| 0.0),
        time_scaled: ts.map(|_| TimeScaledJerk::default()),
        ..Scores::default()
    };
    let mut series = params
        .series
        .then(|| Series::zeros(n, points.is_some(), ts.is_some()));
    let mut joint_det = PeakDetector::new(pk.edge_peaks);
    let mut cart_det = PeakDetector::new(pk.edge_peaks);

    for i in 1..n {
        // Step terms (S0 eq. 2.1–2.5).
        let (qi, q1) = (q.row(i), q.row(i - 1));
        let mut jd_i = 0.0;
        let cpc_i = match input.joint_weights {
            Some(w) => {
                let mut c = 0.0;
                for ((a, b), w) in qi.iter().zip(q1).zip(w) {
                    let d = (a - b).abs();
                    jd_i += d;
                    c += w * d;
                }
                c
            }
            None => {
                for (a, b) in qi.iter().zip(q1) {
                    jd_i += (a - b).abs();
                }
                jd_i
            }
        };
        let pi = &poses[i].translation.vector;
        let p1 = &poses[i - 1].translation.vector;
        let cd_i = (pi - p1).norm();
        let oc_i = orientation_half_angle(&poses[i - 1].rotation, &poses[i].rotation);
        s.cd += cd_i;
        s.jd += jd_i;
        s.oc += oc_i;
        s.cpc += cpc_i;
        let rdm_i = points.map(|a| max_point_displacement(a.row(i - 1), a.row(i)));
        if let (Some(total), Some(r)) = (s.rdm.as_mut(), rdm_i) {
            *total += r;
        }
        if let Some(se) = series.as_mut() {
            se.cd[i] = cd_i;
            se.jd[i] = jd_i;
            se.oc[i] = oc_i;
            se.cpc[i] = cpc_i;
            if let (Some(v), Some(r)) = (se.rdm.as_mut(), rdm_i) {
                v[i] = r;
            }
        }
        if i < 3 {
            continue;
        }

        // Pseudo-jerk terms (S0 eq. 2.6–2.9).
        let (q2, q3) = (q.row(i - 2), q.row(i - 3));
        let mut jj_i = 0.0;
        for (((a, b), c), d) in q3.iter().zip(q2).zip(q1).zip(qi) {
            jj_i += third_difference([*a, *b, *c, *d]).abs();
        }
        let p2 = &poses[i - 2].translation.vector;
        let p3 = &poses[i - 3].translation.vector;
        let cj_i = (pi - p1 * 3.0 + p2 * 3.0 - p3).norm();
        s.jj += jj_i;
        s.cj += cj_i;
        s.jmj = s.jmj.max(jj_i);
        s.cmj = s.cmj.max(cj_i);

        // Peaks and predicted slowdowns (S0 eq. 2.11–2.14).
        if let Some(p) = joint_det.push(i, jj_i) {
            count_joint_peak(&mut s, series.as_mut(), p, pk);
        }
        if let Some(p) = cart_det.push(i, cj_i) {
            count_cartesian_peak(&mut s, series.as_mut(), p, pk);
        }

        // Time-scaled jerk (not an S0 criterion).
        if let (Some(t), Some(acc)) = (ts, s.time_scaled.as_mut()) {
            let w = third_derivative_weights([t[i - 3], t[i - 2], t[i - 1], t[i]]);
            let mut jr = 0.0;
            for (((a, b), c), d) in q3.iter().zip(q2).zip(q1).zip(qi) {
                jr += (w[0] * a + w[1] * b + w[2] * c + w[3] * d).abs();
            }
            let cr = (p3 * w[0] + p2 * w[1] + p1 * w[2] + pi * w[3]).norm();
            acc.jj += jr;
            acc.cj += cr;
            acc.jmj = acc.jmj.max(jr);
            acc.cmj = acc.cmj.max(cr);
            if let Some(se) = series.as_mut() {
                if let Some(v) = se.joint_jerk_rate.as_mut() {
                    v[i] = jr;
                }
                if let Some(v) = se.cartesian_jerk_rate.as_mut() {
                    v[i] = cr;
                }
            }
        }
        if let Some(se) = series.as_mut() {
            se.joint_jerk[i] = jj_i;
            se.cartesian_jerk[i] = cj_i;
        }
    }
    if let Some(p) = joint_det.finish() {
        count_joint_peak(&mut s, series.as_mut(), p, pk);
    }
    if let Some(p) = cart_det.finish() {
        count_cartesian_peak(&mut s, series.as_mut(), p, pk);
    }
    s.oc_geodesic = 2.0 * s.oc;

    let cycle_time = input
        .limits
        .as_ref()
        .map(|l| cycle_time_unchecked(q, l, &params.cycle_time));
    s.cycle_time = cycle_time.as_ref().map(|c| c.total);
    Ok(ScoreReport {
        shape,
        scores: s,
        series,
        cycle_time,
    })
}

fn count_joint_peak(s: &mut Scores, series: Option<&mut Series>, p: Peak, pk: &JerkPeakParams) {
    if p.height > pk.joint_min_height {
        let slowdown = joint_slowdown(p.height, pk);
        s.jjp += slowdown;
        s.joint_peak_count += 1;
        if let Some(se) = series {
            se.joint_peaks.push(CountedPeak {
                index: p.index,
                height: p.height,
                slowdown,
            });
        }
    }
}

fn count_cartesian_peak(s: &mut Scores, series: Option<&mut Series>, p: Peak, pk: &JerkPeakParams) {
    if p.height > pk.cartesian_min_height {
        let slowdown = cartesian_slowdown(p.height, pk);
        s.cjp += slowdown;
        s.cartesian_peak_count += 1;
        if let Some(se) = series {
            se.cartesian_peaks.push(CountedPeak {
                index: p.index,
                height: p.height,
                slowdown,
            });
        }
    }
}

#[cfg(test)]
mod tests;
