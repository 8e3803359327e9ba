//! Sample times at a fixed period, and the TOPP-RA profile along its curve
//! at those times.

use super::TimedTrajectory;
use super::curve::Curve;
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
