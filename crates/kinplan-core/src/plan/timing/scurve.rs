//! The time-optimal rest-to-rest S-curve: a seven-phase profile of piecewise
//! constant jerk within velocity, acceleration and jerk limits.

/// A rest-to-rest motion over a distance `d ≥ 0` with `|ṗ| ≤ v`, `|p̈| ≤ a`,
/// `|p⃛| ≤ j`: jerk `+j, 0, −j, 0, −j, 0, +j` over the phases
/// `T_j, T_a, T_j, T_v, T_j, T_a, T_j` (Biagiotti & Melchiorri,
/// "Trajectory Planning for Automatic Machines and Robots", Springer 2008,
/// §3.4, "double S" profile with zero boundary velocities).
///
/// ```text
/// v·j ≥ a²:  T_j = a/j,  T_a = v/a − a/j     (the acceleration limit is reached)
/// else:      T_j = √(v/j), T_a = 0
/// d_acc = v (2T_j + T_a) / 2                  (distance from rest to v)
/// d ≥ 2 d_acc:  T_v = (d − 2 d_acc) / v       (cruise at v)
/// otherwise the peak speed v_p < v:
///   v_p = (−a²/j + √(a⁴/j² + 4 a d)) / 2  if v_p ≥ a²/j:  T_j = a/j, T_a = v_p/a − a/j
///   else                                   T_j = (d / (2j))^(1/3), T_a = 0
/// ```
///
/// ```
/// use kinplan_core::plan::SCurve;
/// // 1 rad at v = 1, a = 2, j = 10: T_j = 0.2, T_a = 0.3, d_acc = 0.35, T_v = 0.3
/// let s = SCurve::rest_to_rest(1.0, 1.0, 2.0, 10.0);
/// assert!((s.duration() - 1.7).abs() < 1e-12);
/// let (p, v, a, _) = s.at(0.85);
/// assert!((p - 0.5).abs() < 1e-12 && (v - 1.0).abs() < 1e-12 && a.abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SCurve {
    /// Phase durations, s.
    pub phases: [f64; 7],
    /// The jerk limit, units of the distance per s³.
    pub jerk: f64,
    /// Position, velocity and acceleration where each phase starts.
    starts: [[f64; 3]; 7],
}

const SIGNS: [f64; 7] = [1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0];

impl SCurve {
    /// The shortest rest-to-rest profile over `d` (≥ 0) within `v`, `a`, `j`
    /// (finite, > 0).
    pub fn rest_to_rest(d: f64, v: f64, a: f64, j: f64) -> Self {
        let (tj, ta, tv) = if d <= 0.0 {
            (0.0, 0.0, 0.0)
        } else {
            let (tj, ta) = if v * j >= a * a {
                (a / j, v / a - a / j)
            } else {
                ((v / j).sqrt(), 0.0)
            };
            let d_acc = v * (2.0 * tj + ta) / 2.0;
            if d >= 2.0 * d_acc {
                (tj, ta, (d - 2.0 * d_acc) / v)
            } else {
                let r = a * a / j;
                let vp = (-r + (r * r + 4.0 * a * d).sqrt()) / 2.0;
                if vp >= r {
                    (a / j, (vp / a - a / j).max(0.0), 0.0)
                } else {
                    ((d / (2.0 * j)).cbrt(), 0.0, 0.0)
                }
            }
        };
        let phases = [tj, ta, tj, tv, tj, ta, tj];
        let mut starts = [[0.0; 3]; 7];
        let mut state = [0.0; 3];
        for k in 0..7 {
            starts[k] = state;
            state = advance(state, SIGNS[k] * j, phases[k]);
        }
        Self {
            phases,
            jerk: j,
            starts,
        }
    }

    /// Total time, s.
    pub fn duration(&self) -> f64 {
        self.phases.iter().sum()
    }

    /// Position, velocity, acceleration and jerk at time `t` (clamped to
    /// `[0, duration]`).
    pub fn at(&self, t: f64) -> (f64, f64, f64, f64) {
        let mut rest = t.max(0.0);
        for (k, (&len, &sign)) in self.phases.iter().zip(&SIGNS).enumerate() {
            if rest <= len || k == 6 {
                let jk = sign * self.jerk;
                let [p, v, a] = advance(self.starts[k], jk, rest.min(len));
                return (p, v, a, jk);
            }
            rest -= len;
        }
        unreachable!("the loop returns at the last phase")
    }
}

/// State after `dt` of constant jerk `jk` from `[p, v, a]`.
fn advance([p, v, a]: [f64; 3], jk: f64, dt: f64) -> [f64; 3] {
    [
        p + v * dt + a * dt * dt / 2.0 + jk * dt * dt * dt / 6.0,
        v + a * dt + jk * dt * dt / 2.0,
        a + jk * dt,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-derived cases (distance, v, a, j) → (T_j, T_a, T_v, duration).
    #[test]
    fn durations_match_the_hand_derived_s_curves() {
        let cases = [
            // cruise: T_j = a/j = 0.2, T_a = v/a − a/j = 0.3, d_acc = 1·0.7/2
            (1.0, 1.0, 2.0, 10.0, 0.2, 0.3, 0.3, 1.7),
            // no cruise, acceleration limit reached: a²/j = 0.4,
            // v_p = (−0.4 + √(0.16 + 4·2·0.5))/2 = 0.8198039, T_a = v_p/2 − 0.2
            (
                0.5,
                1.0,
                2.0,
                10.0,
                0.2,
                0.2099019513592785,
                0.0,
                1.219803902718557,
            ),
            // no cruise, acceleration limit not reached: T_j = (0.05/20)^(1/3)
            (
                0.05,
                1.0,
                2.0,
                10.0,
                0.1357208808297453,
                0.0,
                0.0,
                0.5428835233189812,
            ),
            // a² > v·j: T_j = √(v/j) = 0.5, T_a = 0; d_acc = 1·1/2 = 0.5; T_v = 1
            (2.0, 1.0, 10.0, 4.0, 0.5, 0.0, 1.0, 3.0),
        ];
        for (d, v, a, j, tj, ta, tv, total) in cases {
            let s = SCurve::rest_to_rest(d, v, a, j);
            let [p0, p1, _, p3, ..] = s.phases;
            assert!((p0 - tj).abs() < 1e-12, "{d}: T_j {p0} vs {tj}");
            assert!((p1 - ta).abs() < 1e-12, "{d}: T_a {p1} vs {ta}");
            assert!((p3 - tv).abs() < 1e-12, "{d}: T_v {p3} vs {tv}");
            assert!(
                (s.duration() - total).abs() < 1e-12,
                "{d}: {} vs {total}",
                s.duration()
            );
            let (pe, ve, ae, _) = s.at(s.duration());
            assert!((pe - d).abs() < 1e-12 && ve.abs() < 1e-12 && ae.abs() < 1e-12);
        }
    }

    #[test]
    fn finite_differences_at_1_khz_stay_within_the_limits() {
        let (v, a, j) = (1.3, 2.1, 7.0);
        for d in [0.01, 0.2, 0.9, 5.0] {
            let s = SCurve::rest_to_rest(d, v, a, j);
            let h = 1e-3;
            let p: Vec<f64> = (0..=(s.duration() / h).ceil() as usize + 3)
                .map(|k| s.at(k as f64 * h).0)
                .collect();
            for w in p.windows(4) {
                let vel = (w[1] - w[0]) / h;
                let acc = (w[2] - 2.0 * w[1] + w[0]) / (h * h);
                let jerk = (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / (h * h * h);
                assert!(vel.abs() <= v * (1.0 + 1e-9), "{d}: v {vel}");
                assert!(acc.abs() <= a * (1.0 + 1e-6), "{d}: a {acc}");
                assert!(jerk.abs() <= j * (1.0 + 1e-3), "{d}: j {jerk}");
            }
        }
    }
}
