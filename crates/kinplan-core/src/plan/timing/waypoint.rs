//! The waypoint method: timestamps for the waypoints of a path followed as
//! straight joint segments, within per-joint velocity (and optionally
//! acceleration) limits.

/// Shortest segment duration (s), so timestamps strictly increase.
pub const MIN_SEGMENT_TIME: f64 = 1e-6;

/// Timestamps (s, from 0) for `waypoints` (`n × dof`, row-major), the path
/// followed as straight joint-space segments.
///
/// Segment `s` first takes `T_s = max_j |Δq_{s,j}| / v_j` (the synchronised
/// motion of S2 §3.3: the slowest joint at its limit, so no joint exceeds
/// its speed). With acceleration limits, the acceleration at waypoint `i`
/// is the velocity change over the mean of the adjacent durations,
/// `a_i = (Δq_i/T_i − Δq_{i−1}/T_{i−1}) / ((T_{i−1} + T_i)/2)`, starting and
/// ending at rest (`a_0 = v_0/(T_0/2)`, likewise at the end). A waypoint with
/// `r = max_j |a_{i,j}|/a_j > 1` stretches both adjacent segments by `√r`
/// (which divides its acceleration by r and never raises a speed); after 100
/// sweeps any remaining excess `R` stretches every segment by `√R`, which
/// scales every acceleration by `1/R` — so the result always satisfies both
/// limits. Limits must be finite and > 0 (`+∞` accelerations allowed).
///
/// ```
/// use kinplan_core::plan::time_parameterize;
/// let q = [0.0, 0.0, 1.0, 0.5]; // two waypoints of a 2-joint arm
/// let t = time_parameterize(&q, 2, &[0.5, 1.0], None);
/// assert_eq!(t, vec![0.0, 2.0]); // joint 0 moves 1 rad at 0.5 rad/s
/// ```
pub fn time_parameterize(waypoints: &[f64], dof: usize, v_max: &[f64], a_max: Option<&[f64]>) -> Vec<f64> {
    let n = waypoints.len().checked_div(dof).unwrap_or(0);
    if n == 0 {
        return Vec::new();
    }
    let delta = |s: usize, j: usize| waypoints[(s + 1) * dof + j] - waypoints[s * dof + j];
    let mut dur: Vec<f64> = (0..n - 1)
        .map(|s| {
            (0..dof)
                .map(|j| delta(s, j).abs() / v_max[j])
                .fold(MIN_SEGMENT_TIME, f64::max)
        })
        .collect();
    if let Some(a_max) = a_max
        && n > 1
    {
        let ratio = |dur: &[f64], i: usize| -> f64 {
            (0..dof)
                .map(|j| {
                    let v_in = if i > 0 { delta(i - 1, j) / dur[i - 1] } else { 0.0 };
                    let v_out = if i + 1 < n { delta(i, j) / dur[i] } else { 0.0 };
                    let span = if i == 0 {
                        dur[0] / 2.0
                    } else if i + 1 == n {
                        dur[n - 2] / 2.0
                    } else {
                        (dur[i - 1] + dur[i]) / 2.0
                    };
                    (v_out - v_in).abs() / span / a_max[j]
                })
                .fold(0.0, f64::max)
        };
        for _ in 0..100 {
            let mut changed = false;
            for i in 0..n {
                let r = ratio(&dur, i);
                if r > 1.0 {
                    let f = r.sqrt() * (1.0 + 1e-12);
                    if i > 0 {
                        dur[i - 1] *= f;
                    }
                    if i + 1 < n {
                        dur[i] *= f;
                    }
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        let worst = (0..n).map(|i| ratio(&dur, i)).fold(0.0, f64::max);
        if worst > 1.0 {
            let f = worst.sqrt() * (1.0 + 1e-12);
            dur.iter_mut().for_each(|d| *d *= f);
        }
    }
    let mut t = Vec::with_capacity(n);
    t.push(0.0);
    for d in dur {
        let last = *t.last().unwrap_or(&0.0);
        t.push(last + d);
    }
    t
}

/// Velocities and accelerations at the waypoints of a path timed by
/// [`time_parameterize`] (`n × dof` each, row-major).
///
/// With segment velocities `v_s = Δq_s / T_s` (rest before the first and
/// after the last waypoint), waypoint `i` gets the mean of the adjacent
/// segment velocities, `q̇_i = (v_{i−1} + v_i)/2`, and the acceleration the
/// method bounds, `q̈_i = (v_i − v_{i−1}) / ((T_{i−1} + T_i)/2)` (one half
/// segment at either end). Both are within the limits `time_parameterize`
/// was given: a mean of two speeds within a limit is within it.
pub fn waypoint_rates(waypoints: &[f64], dof: usize, t: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = t.len();
    let mut qd = vec![0.0; n * dof];
    let mut qdd = vec![0.0; n * dof];
    if n < 2 {
        return (qd, qdd);
    }
    let seg_v =
        |s: usize, j: usize| (waypoints[(s + 1) * dof + j] - waypoints[s * dof + j]) / (t[s + 1] - t[s]);
    for i in 0..n {
        let span = if i == 0 {
            (t[1] - t[0]) / 2.0
        } else if i + 1 == n {
            (t[n - 1] - t[n - 2]) / 2.0
        } else {
            (t[i + 1] - t[i - 1]) / 2.0
        };
        for j in 0..dof {
            let v_in = if i > 0 { seg_v(i - 1, j) } else { 0.0 };
            let v_out = if i + 1 < n { seg_v(i, j) } else { 0.0 };
            if i > 0 && i + 1 < n {
                qd[i * dof + j] = (v_in + v_out) / 2.0;
            }
            qdd[i * dof + j] = (v_out - v_in) / span;
        }
    }
    (qd, qdd)
}
