//! TOPP-RA: the time-optimal speed along a [`Curve`] within per-joint
//! velocity and acceleration limits, by reachability analysis (Pham & Pham,
//! "A New Approach to Time-Optimal Path Parameterization Based on
//! Reachability Analysis", IEEE T-RO 34(3), 2018).

use super::curve::Curve;
use crate::Deadline;

/// Most grid points of one profile (memory: about 2·dof + 6 values each).
pub const MAX_GRID_POINTS: usize = 1_000_000;
/// Largest tangent turn between two grid points on a curved piece, rad.
const MAX_TURN_STEP: f64 = 0.2;

/// Why no profile came out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToppError {
    /// The grid would exceed [`MAX_GRID_POINTS`] (it would have this many).
    TooManyGridPoints(usize),
    /// The start speed `ṡ₀²` exceeds the largest the path can stop from
    /// within the limits (`max`, (rad/s)²).
    StartTooFast { max: f64 },
    /// the deadline passed or the caller cancelled.
    Interrupted,
}

/// The squared path speed `x = ṡ²` on a grid `s_0 < … < s_{N−1}`, the
/// constant path acceleration `u_i = s̈` on each interval and the time of
/// each grid point.
#[derive(Debug, Clone)]
pub struct SpeedProfile {
    pub s: Vec<f64>,
    /// The piece grid point `i` and the interval after it belong to.
    pub piece: Vec<usize>,
    pub x: Vec<f64>,
    pub u: Vec<f64>,
    pub t: Vec<f64>,
}

impl SpeedProfile {
    /// Duration, s.
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// The same path `k` (≥ 1) times slower: `x/k²`, `u/k²`, `t·k`, which
    /// divides every joint velocity by `k` and acceleration by `k²`.
    pub fn slow_down(&mut self, k: f64) {
        let f = 1.0 / (k * k);
        self.x.iter_mut().for_each(|v| *v *= f);
        self.u.iter_mut().for_each(|v| *v *= f);
        self.t.iter_mut().for_each(|v| *v *= k);
    }
}

/// Grid, derivatives at the grid points and the left limits at piece starts.
struct Grid {
    s: Vec<f64>,
    piece: Vec<usize>,
    /// `q'`, `q''` at each grid point on its own piece (`N × dof`).
    d1: Vec<f64>,
    d2: Vec<f64>,
    /// `q'`, `q''` at the start of piece `k` seen from piece `k − 1`
    /// (`pieces × dof`; row 0 unused).
    l1: Vec<f64>,
    l2: Vec<f64>,
    /// Upper bound of `x` from the path itself (0 where it must stop).
    cap: Vec<f64>,
}

fn build_grid<C: Curve + ?Sized>(curve: &C, step: f64) -> Result<Grid, ToppError> {
    let (p, dof) = (curve.pieces(), curve.dof());
    let counts: Vec<usize> = (0..p)
        .map(|k| {
            let (a, b) = curve.span(k);
            let by_len = ((b - a) / step).ceil();
            let by_turn = (curve.turn(k) / MAX_TURN_STEP).ceil();
            by_len.max(by_turn).clamp(2.0, MAX_GRID_POINTS as f64 + 1.0) as usize
        })
        .collect();
    let total = counts.iter().fold(1usize, |s, c| s.saturating_add(*c));
    if total > MAX_GRID_POINTS {
        return Err(ToppError::TooManyGridPoints(total));
    }
    let mut g = Grid {
        s: Vec::with_capacity(total),
        piece: Vec::with_capacity(total),
        d1: vec![0.0; total * dof],
        d2: vec![0.0; total * dof],
        l1: vec![0.0; p * dof],
        l2: vec![0.0; p * dof],
        cap: vec![f64::INFINITY; total],
    };
    let mut q = vec![0.0; dof];
    for (k, &n) in counts.iter().enumerate() {
        let (a, b) = curve.span(k);
        if k > 0 {
            let (l1, l2) = (
                &mut g.l1[k * dof..(k + 1) * dof],
                &mut g.l2[k * dof..(k + 1) * dof],
            );
            curve.eval(k - 1, a, &mut q, l1, l2);
            if curve.stop_after(k - 1) {
                g.cap[g.s.len()] = 0.0;
            }
        }
        for i in 0..n {
            g.s.push(a + (b - a) * i as f64 / n as f64);
            g.piece.push(k);
        }
    }
    g.s.push(curve.span(p - 1).1);
    g.piece.push(p - 1);
    g.cap[total - 1] = 0.0;
    for i in 0..total {
        let r = i * dof..(i + 1) * dof;
        curve.eval(g.piece[i], g.s[i], &mut q, &mut g.d1[r.clone()], &mut g.d2[r]);
    }
    Ok(g)
}

/// Bands `βx − w ≤ u ≤ βx + w` of the joint acceleration constraints
/// `|p_j u + q_j x| ≤ a_j` (`w = a_j/|p_j|`, `β = −q_j/p_j`), appended to
/// `bands` as `(w, β)`: each is a lower line `(−w, β)` and an upper line
/// `(w, β)` of the same slope. Where `p_j = 0` the constraint bounds `x`
/// alone (`|q_j| x ≤ a_j`), which lowers `cap`.
fn accel_lines(p: &[f64], q: &[f64], a: &[f64], bands: &mut Vec<(f64, f64)>, cap: &mut f64) {
    for j in 0..p.len() {
        if p[j].abs() > 1e-12 {
            let ip = 1.0 / p[j];
            let slope = -q[j] * ip;
            let w = a[j] * ip.abs();
            bands.push((w, slope));
        } else if q[j].abs() > 1e-12 {
            *cap = cap.min(a[j] / q[j].abs());
        }
    }
}

/// The speed bound of `|q'_j| ṡ ≤ v_j` on `x = ṡ²` at a path point with
/// tangent `d1`: `min_j (v_j / q'_j)²` (∞ where no joint moves).
fn speed_cap(d1: &[f64], v: &[f64]) -> f64 {
    let mut cap = f64::INFINITY;
    for (p, vj) in d1.iter().zip(v) {
        if p.abs() > 1e-12 {
            cap = cap.min((vj / p).powi(2));
        }
    }
    cap
}

/// The largest `x` in `[0, cap]` for which some `u` lies above every lower
/// line and below every upper line, given that `x = 0` is such a point. The
/// lines are the two sides of each band `(w, β)` of [`accel_lines`] and one
/// more of each kind, `lower1` and `upper1` (`(α, β)`: `u = α + βx`).
///
/// `g(x) = min_m u_m(x) − max_l l_l(x)` is concave and piecewise linear with
/// `g(0) ≥ 0`, so the feasible `x` form an interval `[0, x*]`. Newton's
/// method on `g` from `x = cap` moves left monotonically (a concave
/// function lies below its tangents) and lands on `x*` exactly after at most
/// as many steps as `g` has pieces — usually one or two, each O(lines).
fn largest_feasible(bands: &[(f64, f64)], lower1: (f64, f64), upper1: (f64, f64), cap: f64) -> f64 {
    let mut x = cap;
    for _ in 0..64 {
        // one pass: both sides of a band share the product βx
        let (mut lv, mut ls) = (lower1.0 + lower1.1 * x, lower1.1);
        let (mut uv, mut us) = (upper1.0 + upper1.1 * x, upper1.1);
        for &(w, b) in bands {
            let bx = b * x;
            let (l, u) = (-w + bx, w + bx);
            // ties: the smaller slope is the one active just left of x
            if l > lv || (l == lv && b < ls) {
                (lv, ls) = (l, b);
            }
            if u < uv || (u == uv && b > us) {
                (uv, us) = (u, b);
            }
        }
        let g = uv - lv;
        if g >= -1e-12 * (1.0 + uv.abs().max(lv.abs())) {
            return x;
        }
        let slope = us - ls;
        if slope >= 0.0 {
            return 0.0; // cannot happen for a concave g with g(0) ≥ 0
        }
        x = (x - g / slope).max(0.0);
    }
    x
}

/// The time-optimal `x(s)` along `curve` from `ṡ² = x0` to rest.
///
/// Constraints at grid point `i` (`q'`, `q''` there): `|q'_j| √x ≤ v_j` and
/// `−a_j ≤ q'_j u + q''_j x ≤ a_j`, with `x_{i+1} = x_i + 2 Δ_i u_i`
/// (Pham & Pham 2018); on a curved piece the acceleration is
/// also bounded where the interval ends (with `u_i` and `x_{i+1}`, written
/// in `u_i`, `x_i`), so it holds on both sides of a junction. A backward
/// pass computes the controllable sets `K_i = [0, hi_i]` — the `x_i` from
/// which rest at the end remains reachable — each a two-variable LP solved
/// exactly ([`largest_feasible`]); a
/// forward pass then takes the largest `u_i` that keeps `x_{i+1}` in
/// `K_{i+1}` (the paper shows this greedy choice is time-optimal on the
/// grid).
/// Interval times are `2Δ_i / (√x_i + √x_{i+1})`.
///
/// Both ends of every interval are within the limits by construction; the
/// middle of each interval on a curved piece (the derivatives change along
/// an arc) is then checked, and if a limit is exceeded there by a factor,
/// `x` and `u` are divided by `k²` with `k = max(v ratio, √(a ratio))` — a
/// uniform slow-down that makes every checked value feasible.
pub fn topp_ra<C: Curve + ?Sized>(
    curve: &C,
    v: &[f64],
    a: &[f64],
    x0: f64,
    step: f64,
    deadline: Deadline<'_>,
) -> Result<SpeedProfile, ToppError> {
    let dof = curve.dof();
    let g = build_grid(curve, step)?;
    let n = g.s.len();
    let mut bands = Vec::with_capacity(2 * dof);
    let mut end1 = vec![0.0; dof];
    let mut end2 = vec![0.0; dof];
    // q', q'' where interval i ends, on its own piece
    let end_of = |i: usize| -> (&[f64], &[f64]) {
        let k = g.piece[i];
        if g.piece[i + 1] == k || i + 2 == n {
            let r = (i + 1) * dof..(i + 2) * dof;
            (&g.d1[r.clone()], &g.d2[r])
        } else {
            let r = (k + 1) * dof..(k + 2) * dof;
            (&g.l1[r.clone()], &g.l2[r])
        }
    };
    // Constraints of interval i on (u_i, x_i), without the transition lines:
    // at its start, and on a curved piece also at its end, where
    // q'_e u + q''_e (x + 2Δu) = (q'_e + 2Δ q''_e) u + q''_e x.
    let mut stage = |i: usize, bands: &mut Vec<(f64, f64)>| -> f64 {
        bands.clear();
        let r = i * dof..(i + 1) * dof;
        let mut cap = g.cap[i].min(speed_cap(&g.d1[r.clone()], v));
        accel_lines(&g.d1[r.clone()], &g.d2[r], a, bands, &mut cap);
        if curve.turn(g.piece[i]) > 0.0 {
            let delta = g.s[i + 1] - g.s[i];
            let (e1, e2) = end_of(i);
            for j in 0..dof {
                end1[j] = e1[j] + 2.0 * delta * e2[j];
                end2[j] = e2[j];
            }
            accel_lines(&end1, &end2, a, bands, &mut cap);
        }
        cap
    };
    // lo_i = 0 throughout: from x_i = 0, u_i = 0 stays at rest within
    // every limit, and rest at the end stays reachable
    // A straight piece has constant constraints: |u| ≤ A_k, x ≤ C_k
    // (A_k = min_j a_j/|q'_j|, C_k = min_j (v_j/q'_j)²), so its controllable
    // sets follow hi_i = min(C_k, hi_{i+1} + 2Δ A_k) in O(1) per point.
    let pieces = curve.pieces();
    let mut line_acc = vec![f64::INFINITY; pieces];
    let mut line_cap = vec![f64::INFINITY; pieces];
    let mut first = 0;
    for k in 0..pieces {
        while g.piece[first] != k {
            first += 1;
        }
        if curve.turn(k) == 0.0 {
            for j in 0..dof {
                let p = g.d1[first * dof + j].abs();
                if p > 1e-12 {
                    line_acc[k] = line_acc[k].min(a[j] / p);
                    line_cap[k] = line_cap[k].min((v[j] / p).powi(2));
                }
            }
        }
    }
    // the joint lines of curved stages, kept for the forward pass
    let mut kept_upper: Vec<(f64, f64)> = Vec::with_capacity(n * 2 * dof);
    let mut kept_at = vec![(0u32, 0u32); n];
    let mut hi = vec![0.0; n];
    for i in (0..n - 1).rev() {
        if i % 4096 == 0 && deadline.expired() {
            return Err(ToppError::Interrupted);
        }
        let k = g.piece[i];
        let delta = g.s[i + 1] - g.s[i];
        if curve.turn(k) == 0.0 {
            hi[i] = g.cap[i]
                .min(line_cap[k])
                .min(hi[i + 1] + 2.0 * delta * line_acc[k]);
            continue;
        }
        let cap = stage(i, &mut bands);
        kept_at[i] = (kept_upper.len() as u32, (kept_upper.len() + bands.len()) as u32);
        kept_upper.extend_from_slice(&bands);
        let w = 1.0 / (2.0 * delta);
        hi[i] = largest_feasible(&bands, (0.0, -w), (hi[i + 1] * w, -w), cap);
    }
    if x0 > hi[0] * (1.0 + 1e-9) + 1e-12 {
        return Err(ToppError::StartTooFast { max: hi[0] });
    }
    let mut x = vec![0.0; n];
    let mut u = vec![0.0; n - 1];
    x[0] = x0.min(hi[0]);
    for i in 0..n - 1 {
        let k = g.piece[i];
        let delta = g.s[i + 1] - g.s[i];
        let joint_max = if curve.turn(k) == 0.0 {
            line_acc[k]
        } else {
            let (from, to) = kept_at[i];
            kept_upper[from as usize..to as usize]
                .iter()
                .map(|&(al, be)| al + be * x[i])
                .fold(f64::INFINITY, f64::min)
        };
        // u_i = min(joint_max, (hi_{i+1} − x_i)/2Δ), written in x_{i+1} so
        // that no division lies on the chain from one grid point to the next
        x[i + 1] = (x[i] + 2.0 * delta * joint_max).clamp(0.0, hi[i + 1]);
        u[i] = (x[i + 1] - x[i]) / (2.0 * delta);
    }
    // The stages hold every limit where each interval starts and ends (the
    // speed through the next stage's cap, the acceleration through the lines
    // of both ends), and a straight piece's limits are the same all along
    // it; only the middle of an interval on a curved piece is left to check.
    // Should a limit be exceeded there by a factor, slow down uniformly.
    // One running maximum per joint: independent chains, no square roots.
    let (mut max_v, mut max_a) = (vec![0.0f64; dof], vec![0.0f64; dof]);
    let (mut q, mut m1, mut m2) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    for i in 0..n - 1 {
        let k = g.piece[i];
        if curve.turn(k) == 0.0 {
            continue;
        }
        let r = i * dof..(i + 1) * dof;
        let (e1, e2) = end_of(i);
        let ends = [&g.d1[r.clone()], &g.d2[r], e1, e2];
        curve.eval_mid(k, g.s[i], g.s[i + 1], ends, &mut m1, &mut m2, &mut q);
        let xm = (x[i] + x[i + 1]) / 2.0;
        let sd = xm.sqrt();
        for j in 0..dof {
            max_v[j] = max_v[j].max(m1[j].abs() * sd);
            max_a[j] = max_a[j].max((m1[j] * u[i] + m2[j] * xm).abs());
        }
    }
    let mut worst = 1.0f64;
    for j in 0..dof {
        worst = worst.max(max_v[j] / v[j]).max((max_a[j] / a[j]).sqrt());
    }
    if worst > 1.0 {
        let f = 1.0 / (worst * worst * (1.0 + 1e-12));
        x.iter_mut().for_each(|v| *v *= f);
        u.iter_mut().for_each(|v| *v *= f);
    }
    let mut t = vec![0.0; n];
    // one square root per grid point: ṡ at the end of an interval is ṡ at
    // the start of the next
    let mut sd = x[0].sqrt();
    for i in 0..n - 1 {
        let sd_next = x[i + 1].sqrt();
        let speed = sd + sd_next;
        sd = sd_next;
        // both ends at rest means x_{i+1} = x_i + 2Δu = 0 with u = 0: the
        // backward pass keeps every interior hi_i > 0 (braking to rest over
        // one interval is always feasible), so only a rounding-level
        // interval can get here, and it takes no time
        let dt = if speed > 0.0 {
            2.0 * (g.s[i + 1] - g.s[i]) / speed
        } else {
            0.0
        };
        t[i + 1] = t[i] + dt;
    }
    Ok(SpeedProfile {
        s: g.s,
        piece: g.piece,
        x,
        u,
        t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius `r` in joints (0, 1), `laps` times around,
    /// starting at angle 0: `q = r (cos(s/r), sin(s/r))`.
    struct Circle {
        r: f64,
        laps: f64,
    }

    impl Curve for Circle {
        fn dof(&self) -> usize {
            2
        }
        fn pieces(&self) -> usize {
            1
        }
        fn span(&self, _: usize) -> (f64, f64) {
            (0.0, 2.0 * std::f64::consts::PI * self.r * self.laps)
        }
        fn turn(&self, _: usize) -> f64 {
            2.0 * std::f64::consts::PI * self.laps
        }
        fn stop_after(&self, _: usize) -> bool {
            false
        }
        fn eval(&self, _: usize, s: f64, q: &mut [f64], d1: &mut [f64], d2: &mut [f64]) {
            let (sn, cs) = (s / self.r).sin_cos();
            q.copy_from_slice(&[self.r * cs, self.r * sn]);
            d1.copy_from_slice(&[-sn, cs]);
            d2.copy_from_slice(&[-cs / self.r, -sn / self.r]);
        }
    }

    #[test]
    fn the_speed_on_a_circle_meets_the_closed_form_limit_curve() {
        // With |q̈_j| ≤ a on a circle of radius r at angle θ, (s̈, ṡ²/r) is
        // rotated onto the joints, so the largest feasible ṡ² is
        // a r (|cos θ| + |sin θ|): a r at every quarter turn.
        let (r, acc) = (0.5, 2.0);
        let c = Circle { r, laps: 1.0 };
        let p = topp_ra(&c, &[100.0, 100.0], &[acc, acc], 0.0, 1e-3, Deadline::none()).unwrap();
        for (s, x) in p.s.iter().zip(&p.x) {
            let th = s / r;
            let mvc = acc * r * (th.cos().abs() + th.sin().abs());
            assert!(*x <= mvc * (1.0 + 1e-6), "s {s}: {x} > {mvc}");
        }
        // the optimal profile touches the curve's minima at a quarter, half
        // and three quarters of the lap
        for quarter in 1..=3 {
            let s = quarter as f64 * std::f64::consts::FRAC_PI_2 * r;
            let i = p.s.iter().position(|v| *v >= s - 1e-9).unwrap();
            let rel = p.x[i] / (acc * r);
            assert!((rel - 1.0).abs() < 0.01, "quarter {quarter}: x/(a r) = {rel}");
        }
    }

    /// One straight joint-space segment of length `len` along `dir`.
    struct Line {
        dir: Vec<f64>,
        len: f64,
    }

    impl Curve for Line {
        fn dof(&self) -> usize {
            self.dir.len()
        }
        fn pieces(&self) -> usize {
            1
        }
        fn span(&self, _: usize) -> (f64, f64) {
            (0.0, self.len)
        }
        fn turn(&self, _: usize) -> f64 {
            0.0
        }
        fn stop_after(&self, _: usize) -> bool {
            false
        }
        fn eval(&self, _: usize, s: f64, q: &mut [f64], d1: &mut [f64], d2: &mut [f64]) {
            for j in 0..self.dir.len() {
                q[j] = s * self.dir[j];
                d1[j] = self.dir[j];
                d2[j] = 0.0;
            }
        }
    }

    #[test]
    fn a_straight_line_from_rest_to_rest_is_bang_bang() {
        // joint 0 limits: path speed ≤ v/|d0|, path acceleration ≤ a/|d0|
        let dir = vec![0.6, 0.8];
        for (len, v, a) in [(2.0, [1.0, 1.0], [1.0, 1.0]), (0.3, [1.0, 1.0], [2.0, 2.0])] {
            let p = topp_ra(
                &Line {
                    dir: dir.clone(),
                    len,
                },
                &v,
                &a,
                0.0,
                1e-3,
                Deadline::none(),
            )
            .unwrap();
            // joint 1 (0.8) binds both: path limits v/0.8, a/0.8
            let (vs, as_) = (v[1] / 0.8, a[1] / 0.8);
            let expected = if len >= vs * vs / as_ {
                len / vs + vs / as_ // trapezoid
            } else {
                2.0 * (len / as_).sqrt() // triangle
            };
            assert!(
                (p.duration() - expected).abs() < 1e-3 * expected,
                "len {len}: {} vs {expected}",
                p.duration()
            );
            assert!(p.x.iter().all(|x| x.sqrt() <= vs * (1.0 + 1e-9)));
            assert!(p.u.iter().all(|u| u.abs() <= as_ * (1.0 + 1e-9)));
        }
    }

    #[test]
    fn newton_finds_the_same_bound_as_every_pair_of_lines() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..2000 {
            let m = rng.random_range(1..9);
            // bands around a feasible x = 0 (w ≥ 0), one more line of each
            // kind through it: lower α ≤ 0 ≤ upper α
            let bands: Vec<(f64, f64)> = (0..m)
                .map(|_| (rng.random_range(0.0..3.0), rng.random_range(-5.0..5.0)))
                .collect();
            let lower1 = (-rng.random_range(0.0..3.0), rng.random_range(-5.0..5.0));
            let upper1 = (rng.random_range(0.0..3.0), rng.random_range(-5.0..5.0));
            let cap: f64 = rng.random_range(0.1..10.0);
            let lower: Vec<(f64, f64)> = bands.iter().map(|&(w, b)| (-w, b)).chain([lower1]).collect();
            let upper: Vec<(f64, f64)> = bands.iter().copied().chain([upper1]).collect();
            // each pair: (β_l − β_u) x ≤ α_u − α_l
            let mut pairs = cap;
            for &(al, bl) in &lower {
                for &(au, bu) in &upper {
                    if bl - bu > 0.0 {
                        pairs = pairs.min((au - al) / (bl - bu));
                    }
                }
            }
            let newton = largest_feasible(&bands, lower1, upper1, cap);
            assert!(
                (newton - pairs).abs() <= 1e-9 * (1.0 + pairs),
                "{newton} vs {pairs}"
            );
        }
    }

    #[test]
    fn a_start_speed_too_high_to_stop_is_refused() {
        let line = Line {
            dir: vec![1.0],
            len: 0.1,
        };
        // stopping from ṡ within 0.1 at a = 1 needs ṡ² ≤ 0.2
        let p = topp_ra(&line, &[10.0], &[1.0], 0.19, 1e-3, Deadline::none()).unwrap();
        assert!((p.x[0] - 0.19).abs() < 1e-12);
        match topp_ra(&line, &[10.0], &[1.0], 0.3, 1e-3, Deadline::none()) {
            Err(ToppError::StartTooFast { max }) => assert!((max - 0.2).abs() < 1e-9, "{max}"),
            other => panic!("{other:?}"),
        }
    }
}
