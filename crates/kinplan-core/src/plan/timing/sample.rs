//! Timed trajectories sampled at a fixed period: the TOPP-RA profile along
//! its curve, and the jerk-limited chain of straight S-curve segments.

use super::TimedTrajectory;
use super::curve::Curve;
use super::scurve::SCurve;
use super::toppra::SpeedProfile;
use crate::Deadline;

/// Most sample values (samples × joints) of one trajectory (memory: three
/// such arrays of f64).
pub const MAX_SAMPLE_VALUES: usize = 2_000_000;

/// Sample times `0, dt, 2dt, …` and the end (when it is more than a
/// microsecond past the last multiple); `None` when there would be more than
/// [`MAX_SAMPLE_VALUES`] values.
pub(super) fn sample_times(duration: f64, dt: f64, dof: usize) -> Option<Vec<f64>> {
    let whole = (duration / dt).floor();
    if !whole.is_finite() || (whole + 2.0) * dof as f64 > MAX_SAMPLE_VALUES as f64 {
        return None;
    }
    let whole = whole as usize;
    let mut t: Vec<f64> = (0..=whole).map(|k| k as f64 * dt).collect();
    if duration - whole as f64 * dt > 1e-6 {
        t.push(duration);
    } else if let Some(last) = t.last_mut() {
        *last = last.max(duration);
    }
    Some(t)
}

/// The profile's motion at `times`: with `x = ṡ²` and constant `u = s̈` on
/// each interval, `s = s_i + ṡ_i τ + u τ²/2`, `q̇ = q' ṡ`, `q̈ = q' u + q'' ṡ²`.
/// `None` once the deadline passes or the caller cancels (looked at every 4096 samples).
pub(super) fn sample_profile<C: Curve + ?Sized>(
    curve: &C,
    p: &SpeedProfile,
    times: &[f64],
    deadline: Deadline<'_>,
) -> Option<TimedTrajectory> {
    let dof = curve.dof();
    let mut out = TimedTrajectory::with_capacity(dof, times.len());
    let (mut q, mut d1, mut d2) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    let last = p.s.len() - 1;
    let mut i = 0;
    for (k, &t) in times.iter().enumerate() {
        if k % 4096 == 0 && deadline.expired() {
            return None;
        }
        while i + 1 < last && p.t[i + 1] <= t {
            i += 1;
        }
        let tau = (t - p.t[i]).max(0.0);
        let sd0 = p.x[i].sqrt();
        let u = p.u[i];
        let s = (p.s[i] + sd0 * tau + u * tau * tau / 2.0).clamp(p.s[i], p.s[i + 1]);
        let sd = (sd0 + u * tau).max(0.0);
        curve.eval(p.piece[i], s, &mut q, &mut d1, &mut d2);
        out.t.push(t);
        out.q.extend_from_slice(&q);
        out.qd.extend((0..dof).map(|j| d1[j] * sd));
        out.qdd.extend((0..dof).map(|j| d1[j] * u + d2[j] * sd * sd));
    }
    Some(out)
}

/// A path of straight segments, each timed by the rest-to-rest [`SCurve`]
/// of its fraction `σ ∈ [0, 1]`: `q = q_k + σ Δq`, so every joint follows
/// the segment exactly. The limits of `σ` are the tightest of the joints',
/// `v_σ = min_j v_j/|Δq_j|` (likewise `a_σ`, `j_σ`), so no joint exceeds its
/// own.
pub(super) struct Segments {
    dof: usize,
    starts: Vec<f64>,
    deltas: Vec<f64>,
    curves: Vec<SCurve>,
    /// Start time of each segment, then the end time.
    times: Vec<f64>,
}

impl Segments {
    pub fn new(waypoints: &[f64], dof: usize, v: &[f64], a: &[f64], j: &[f64]) -> Self {
        let mut seg = Segments {
            dof,
            starts: Vec::new(),
            deltas: Vec::new(),
            curves: Vec::new(),
            times: vec![0.0],
        };
        let rows: Vec<&[f64]> = waypoints.chunks_exact(dof).collect();
        seg.starts.extend_from_slice(rows[0]);
        for w in rows.windows(2) {
            let delta: Vec<f64> = (0..dof).map(|k| w[1][k] - w[0][k]).collect();
            let lim = |l: &[f64]| {
                (0..dof)
                    .filter(|&k| delta[k] != 0.0)
                    .map(|k| l[k] / delta[k].abs())
                    .fold(f64::INFINITY, f64::min)
            };
            if lim(v).is_infinite() {
                continue; // a repeated waypoint
            }
            let c = SCurve::rest_to_rest(1.0, lim(v), lim(a), lim(j));
            seg.deltas.extend_from_slice(&delta);
            seg.starts.extend_from_slice(w[1]);
            let end = seg.times.last().copied().unwrap_or(0.0) + c.duration();
            seg.curves.push(c);
            seg.times.push(end);
        }
        seg
    }

    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The motion at `times` (sorted); `None` once the deadline passes or the caller cancels.
    pub fn sample(&self, times: &[f64], deadline: Deadline<'_>) -> Option<TimedTrajectory> {
        let dof = self.dof;
        let mut out = TimedTrajectory::with_capacity(dof, times.len());
        let mut k = 0;
        for (n, &t) in times.iter().enumerate() {
            if n % 4096 == 0 && deadline.expired() {
                return None;
            }
            out.t.push(t);
            if self.curves.is_empty() {
                out.q.extend_from_slice(&self.starts[..dof]);
                out.qd.extend(std::iter::repeat_n(0.0, dof));
                out.qdd.extend(std::iter::repeat_n(0.0, dof));
                continue;
            }
            while k + 1 < self.curves.len() && self.times[k + 1] <= t {
                k += 1;
            }
            let (s, sd, sdd, _) = self.curves[k].at(t - self.times[k]);
            let q0 = &self.starts[k * dof..(k + 1) * dof];
            let d = &self.deltas[k * dof..(k + 1) * dof];
            out.q.extend((0..dof).map(|j| q0[j] + s * d[j]));
            out.qd.extend((0..dof).map(|j| sd * d[j]));
            out.qdd.extend((0..dof).map(|j| sdd * d[j]));
        }
        Some(out)
    }
}
