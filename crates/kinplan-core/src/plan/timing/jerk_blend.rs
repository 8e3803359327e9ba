//! The jerk-limited method: straight segments at constant joint velocity,
//! joined at every waypoint by a blend in time whose acceleration is a
//! trapezoid, so the motion passes the waypoints without stopping.

use super::TimedTrajectory;
use super::scurve::SCurve;
use super::waypoint::MIN_SEGMENT_TIME;
use crate::Deadline;

/// Where the segments are split, as fractions of their length, in the order
/// tried: at the midpoint (a segment speeds up towards it and slows down
/// into the next corner; finer splits leave less room for the blends and
/// come out slower), then finer ones should the midpoint not keep a moving
/// start. The unsplit timing is tried beside the first that does, the
/// faster kept.
const SPLITS: [&[f64]; 3] = [&[0.5], &[0.25, 0.5, 0.75], &[0.15, 0.5, 0.85]];

/// Sweeps of the local stretching before the uniform one.
const SWEEPS: usize = 12;

/// What one jerk-limited timing keeps.
#[derive(Debug, Clone, Copy)]
pub(super) struct Limits<'a> {
    /// Velocity, acceleration and jerk limit per joint (finite, > 0).
    pub v: &'a [f64],
    pub a: &'a [f64],
    pub j: &'a [f64],
    /// Largest distance at which an interior waypoint is passed (> 0).
    pub tolerance: f64,
    /// Joint velocity at the start, within `v` (empty: at rest); the
    /// acceleration there is zero.
    pub start: &'a [f64],
}

/// One blend: half-duration `h` and ramp time `r` (0 < r ≤ h) of the
/// normalised acceleration `g` on `[−h, h]`: a trapezoid rising linearly over
/// `r`, flat at `1/(2h − r)`, falling over `r`, so that `∫g = 1`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Shape {
    h: f64,
    r: f64,
    /// `1/((2h − r) r)`, the jerk of `g`: set by [`Shape::finish`] once the
    /// shape is final (0 until then).
    jerk: f64,
}

impl Shape {
    /// The shortest blend that changes the joint velocities by `dv` with
    /// `|q̈_j| ≤ a_j` and `|q⃛_j| ≤ j_j`, every joint on the same shape
    /// (`q̈ = Δv g`), from `D_a = max_j |Δv_j|/a_j` and
    /// `D_j = max_j |Δv_j|/j_j` ([`Shape::from_bounds`]).
    #[cfg(test)]
    fn for_change(dv: &[f64], a: &[f64], j: &[f64]) -> Shape {
        let (mut da, mut dj) = (0.0f64, 0.0f64);
        for k in 0..dv.len() {
            let m = dv[k].abs();
            da = da.max(m / a[k]);
            dj = dj.max(m / j[k]);
        }
        Shape::from_bounds(da, dj)
    }

    /// The shortest blend of every joint on one shape, from
    /// `D_a = max_j |Δv_j|/a_j` and `D_j = max_j |Δv_j|/j_j`: with
    /// `w = 2h − r`, the peak acceleration is `|Δv_j|/w` and the jerk
    /// `|Δv_j|/(r w)`; the least `2h = w + r` with `w ≥ D_a`, `r w ≥ D_j`,
    /// `r ≤ w` is `w = D_a, r = D_j/D_a` when `D_a² ≥ D_j`, else
    /// `w = r = √D_j` — the velocity change of a seven-phase S-curve
    /// (Biagiotti & Melchiorri, "Trajectory Planning for Automatic Machines
    /// and Robots", Springer 2008, §3.4).
    fn from_bounds(da: f64, dj: f64) -> Shape {
        if dj == 0.0 {
            return Shape::default();
        }
        let (w, r) = if da * da >= dj {
            (da, dj / da)
        } else {
            let s = dj.sqrt();
            (s, s)
        };
        Shape {
            h: (w + r) / 2.0,
            r,
            jerk: 0.0,
        }
    }

    /// `∫_{−h}^{0} (−s) g(s) ds`: the distance by which the blend passes its
    /// corner, per unit of `|Δv|`,
    /// `((h − r)²/2 + h r/2 − r²/3) / (2h − r) = w/8 + r²/(24 w)` with
    /// `w = 2h − r` (`h/6` for a triangle, `h/4` for a rectangle).
    #[cfg(test)]
    fn offset(&self) -> f64 {
        let (h, r) = (self.h, self.r);
        if h <= 0.0 {
            return 0.0;
        }
        ((h - r).powi(2) / 2.0 + h * r / 2.0 - r * r / 3.0) / (2.0 * h - r)
    }

    /// Sets the jerk of `g` for [`Shape::at`].
    fn finish(&mut self) {
        let w = 2.0 * self.h - self.r;
        self.jerk = if self.h > 0.0 { 1.0 / (w * self.r) } else { 0.0 };
    }

    /// `[G₂, G₁, g]` at `s`: `G₁ = ∫_{−h}^{s} g`, `G₂ = ∫_{−h}^{s} G₁`
    /// (0 before the blend; `[s, 1, 0]` after it, as `G₂(h) = h` for an
    /// even `g`). With `x = s + h` and `J` the jerk, on the ramp (`x ≤ r`)
    /// `[J x³/6, J x²/2, J x]`; on the flat part, `y = x − r`,
    /// `[J r³/6 + J r²/2 y + J r y²/2, J r²/2 + J r y, J r]`; after the middle
    /// by symmetry, `G₁(s) = 1 − G₁(−s)` and `G₂(s) = s + G₂(−s)`.
    /// [`Shape::finish`] must have run.
    fn at(&self, s: f64) -> [f64; 3] {
        let h = self.h;
        if s >= h {
            return [s, 1.0, 0.0];
        }
        if s <= -h {
            return [0.0, 0.0, 0.0];
        }
        let (r, jk) = (self.r, self.jerk);
        let x = h - s.abs();
        let [p, v, a] = if x <= r {
            [jk * x * x * x / 6.0, jk * x * x * 0.5, jk * x]
        } else {
            let y = x - r;
            let a = jk * r;
            [
                a * r * r / 6.0 + a * r * 0.5 * y + a * y * y * 0.5,
                a * r * 0.5 + a * y,
                a,
            ]
        };
        if s <= 0.0 { [p, v, a] } else { [s + p, 1.0 - v, a] }
    }
}

/// One joint's limits in the forms its blends use.
#[derive(Debug, Clone, Copy)]
struct JointConst {
    /// `1/a`, `1/j`.
    inv_a: f64,
    inv_j: f64,
    /// `a/j`: the ramp time once the acceleration limit is reached.
    ramp: f64,
    /// `a²/j`: the least velocity change that reaches it.
    knee: f64,
    /// `ramp² a / 24`.
    tail: f64,
}

impl JointConst {
    fn new(a: f64, j: f64) -> Self {
        let ramp = a / j;
        Self {
            inv_a: 1.0 / a,
            inv_j: 1.0 / j,
            ramp,
            knee: a * ramp,
            tail: ramp * ramp * a / 24.0,
        }
    }

    /// The shortest blend changing this joint's velocity by `dv` (the shape
    /// of [`Shape::from_bounds`] for the joint alone) and how far it passes
    /// its corner, `|Δv| · offset`: with `m = |Δv|`, when `m ≥ a²/j`,
    /// `w = m/a`, `r = a/j` and `m (w/8 + r²/(24 w)) = m²/(8a) + r² a/24`;
    /// else `w = r = √(m/j)` and `m w/6`. No division.
    fn blend(&self, dv: f64) -> (Shape, f64) {
        let m = dv.abs();
        if m == 0.0 {
            return (Shape::default(), 0.0);
        }
        if m >= self.knee {
            let w = m * self.inv_a;
            let r = self.ramp;
            let e = m * w * 0.125 + self.tail;
            let h = (w + r) * 0.5;
            (Shape { h, r, jerk: 0.0 }, e)
        } else {
            let w = (m * self.inv_j).sqrt();
            (
                Shape {
                    h: w,
                    r: w,
                    jerk: 0.0,
                },
                m * w / 6.0,
            )
        }
    }
}

/// Straight segments between the waypoints `w_0 … w_m`, segment `k` run at
/// the constant velocity `V_k = (w_{k+1} − w_k)/T_k`, with a blend at every
/// waypoint `i` centred on its nominal time `τ_i` (`τ_{i+1} = τ_i + T_i`)
/// that changes the velocity from `V_{i−1}` to `V_i` (rest before the first
/// waypoint and after the last) with the acceleration of joint `c`
/// `q̈_c = (V_{i,c} − V_{i−1,c}) g_{i,c}(t − τ_i)`. At an interior waypoint
/// each joint has its own trapezoid `g_{i,c}` ([`JointConst::blend`]: a joint
/// whose velocity changes little blends over a short window); at the ends
/// and at the points splitting a segment, where `Δv_i` runs along the line,
/// every joint shares the trapezoid of [`Shape::from_bounds`], so the motion
/// stays on the line. This is the
/// linear-segments-with-blends scheme (Paul, "Manipulator Cartesian path
/// control", IEEE SMC 9(11), 1979; Taylor, "Planning and execution of
/// straight line manipulator trajectories", IBM J. R&D 23(4), 1979) with
/// S-curve blends in place of parabolic ones.
///
/// Because every `g_{i,c}` is even, each joint leaves the line of segment
/// `i − 1` and joins that of segment `i` exactly; the motion starts `h_0`
/// before `τ_0` at rest on `w_0` and ends `h_m` after `τ_m` at rest on
/// `w_m`. Every limit holds in closed form as long as the windows of one
/// joint do not overlap (`h_{k,c} + h_{k+1,c} ≤ T_k`): the velocity of joint
/// `c` during a blend is a convex combination of `V_{i−1,c}` and `V_{i,c}`,
/// its acceleration and jerk are those of its shape. Measured from the
/// point `w_k + V_k (t − τ_k)` of the polyline, joint `c` is off by at most
/// `e_{i,c} = |Δv_{i,c}| · offset_{i,c}` during blend `i` (`G₂` is monotone),
/// so the motion passes waypoint `i` at `e_i = |(e_{i,c})_c|` and keeps
/// within it of the polyline; where the windows of blends `k` and `k + 1`
/// overlap in time (different joints in different blends) the bound on
/// segment `k` is `b_k = (Σ_c max(e_{k,c}, e_{k+1,c})²)^½`.
///
/// Each segment may be split at points along it (a blend there changes the
/// speed along the line and leaves it nowhere), so the motion can speed up
/// between two corners and slow down into the next: every segment alike,
/// at the fractions of [`SPLITS`], or not at all — the faster kept.
///
/// Durations: first `T_k = max_j |Δq_{k,j}|/v_j`; then, in sweeps, every
/// segment is scaled by `√w_k`, `w_k` the largest ratio its velocity enters
/// — `ρ_l = max_c (h_{l,c} + h_{l+1,c})/T_l` (the two half-blends of each
/// joint must fit in segment `l`) and, where windows overlap, `b_l/δ`, for
/// `l = k − 1, k, k + 1`, and `e_i/δ` (the passing distance over the
/// tolerance) at both its ends — never below the first `T_k`: segments
/// stretch where a ratio exceeds 1 and shrink where all have room. Once the
/// sweeps settle (or run out), every segment is stretched by the worst
/// ratio left until none exceeds 1 (both kinds fall at least as `1/f` under
/// a uniform stretch `f`).
struct JerkBlends {
    dof: usize,
    /// Waypoints `w_0 … w_m` with repeats removed (`(m + 1) × dof`).
    points: Vec<f64>,
    /// `V_k` (`m × dof`).
    vel: Vec<f64>,
    /// `Δv_i = V_i − V_{i−1}` (`(m + 1) × dof`).
    dv: Vec<f64>,
    /// Blend shape per point and joint (`(m + 1) × dof`).
    shapes: Vec<Shape>,
    /// `e_{i,c}` per point and joint (`(m + 1) × dof`; 0 but at interior
    /// waypoints).
    err: Vec<f64>,
    /// Half-width of each blend's window: the largest `h` of its joints.
    hmax: Vec<f64>,
    /// Velocity before the first blend (the start velocity; zeros at rest).
    start: Vec<f64>,
    /// Whether point `i` is a waypoint (else a point inserted on a segment).
    corner: Vec<bool>,
    /// Nominal waypoint times `τ_i`, `τ_0 = hmax_0`.
    tau: Vec<f64>,
}

impl JerkBlends {
    /// Times the path through `waypoints` (`n × dof`, finite, n ≥ 1) within
    /// `lim`: unsplit and split at the first of [`SPLITS`] that keeps a
    /// moving start, the faster kept. `None` when none keeps it (see
    /// [`JerkBlends::with_splits`]).
    fn new(waypoints: &[f64], dof: usize, lim: Limits<'_>) -> Option<Self> {
        let mut merged: Vec<f64> = Vec::with_capacity(waypoints.len());
        for row in waypoints.chunks_exact(dof) {
            let n = merged.len();
            if n == 0 || merged[n - dof..] != *row {
                merged.extend_from_slice(row);
            }
        }
        let whole = Self::with_splits(&merged, dof, &[], lim);
        let split = SPLITS
            .iter()
            .find_map(|fracs| Self::with_splits(&merged, dof, fracs, lim));
        match (whole, split) {
            (Some(a), Some(b)) => Some(if a.duration() < b.duration() { a } else { b }),
            (a, b) => a.or(b),
        }
    }

    /// The timing with every segment split at `fracs` (increasing, in
    /// (0, 1)) of its length; `merged` has no repeated rows.
    ///
    /// A moving start `v₀` enters as the velocity before the first blend,
    /// whose corner is then placed at `w₀ + v₀ h₀` (and the first segment
    /// runs from there), so that the motion starts on `w₀` at `v₀`; `h₀`
    /// depends on the corner, which is iterated to a fixed point. `None`
    /// when it does not settle (the start is then not kept) or the path has
    /// no length to move along.
    fn with_splits(merged: &[f64], dof: usize, fracs: &[f64], lim: Limits<'_>) -> Option<Self> {
        let Limits {
            v,
            a,
            j,
            tolerance,
            start,
        } = lim;
        let moving = start.iter().any(|x| *x != 0.0);
        let mut points: Vec<f64> = Vec::with_capacity(merged.len() * (fracs.len() + 1));
        let mut corner = vec![true];
        points.extend_from_slice(&merged[..dof]);
        for w in merged.windows(2 * dof).step_by(dof) {
            let (from, to) = w.split_at(dof);
            for f in fracs {
                points.extend((0..dof).map(|c| from[c] + f * (to[c] - from[c])));
                corner.push(false);
            }
            points.extend_from_slice(to);
            corner.push(true);
        }
        let m = points.len() / dof - 1;
        let mut tb = JerkBlends {
            dof,
            vel: vec![0.0; m * dof],
            dv: vec![0.0; (m + 1) * dof],
            shapes: vec![Shape::default(); (m + 1) * dof],
            err: vec![0.0; (m + 1) * dof],
            hmax: vec![0.0; m + 1],
            tau: vec![0.0; m + 1],
            start: if moving { start.to_vec() } else { vec![0.0; dof] },
            points,
            corner,
        };
        if m == 0 {
            return (!moving).then_some(tb);
        }
        let w0 = merged[..dof].to_vec();
        let scale = 1.0 + w0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        // the first waypoint's segment: points 0 ..= first
        let first = fracs.len() + 1;
        let delta = |k: usize, c: usize| tb.points[(k + 1) * dof + c] - tb.points[k * dof + c];
        let mut dur: Vec<f64> = (0..m)
            .map(|k| {
                (0..dof)
                    .map(|c| delta(k, c).abs() / v[c])
                    .fold(MIN_SEGMENT_TIME, f64::max)
            })
            .collect();
        let mut tmin = dur.clone();
        let consts: Vec<JointConst> = (0..dof).map(|c| JointConst::new(a[c], j[c])).collect();
        let mut rho = vec![0.0; m];
        let mut dev = vec![0.0; m + 1];
        for _ in 0..SWEEPS {
            if moving {
                tb.place_start(&w0, fracs, first, v, &mut tmin, &mut dur);
            }
            tb.shape(&dur, &consts);
            tb.ratios(&dur, tolerance, &mut rho, &mut dev);
            // settled once no segment changes by more than a part in 10³ (the
            // uniform stretch below takes what ratios stay above 1)
            let mut settled = true;
            for k in 0..m {
                // every ratio segment k's velocity enters
                let mut w = rho[k].max(dev[k]).max(dev[k + 1]);
                if k > 0 {
                    w = w.max(rho[k - 1]);
                }
                if k + 1 < m {
                    w = w.max(rho[k + 1]);
                }
                let next = (dur[k] * w.sqrt()).max(tmin[k]);
                if (next - dur[k]).abs() > 1e-3 * dur[k] {
                    settled = false;
                }
                dur[k] = next;
            }
            // a moving start moves the first corner: settled once it stays
            if settled && (!moving || tb.start_gap(&w0) <= 1e-12 * scale) {
                break;
            }
        }
        // one stretch settles it in exact arithmetic; the growing margin
        // bounds the loop whatever the rounding
        let mut stretches = 0;
        for _ in 0..64 {
            if moving {
                tb.place_start(&w0, fracs, first, v, &mut tmin, &mut dur);
            }
            tb.shape(&dur, &consts);
            let worst = tb.worst(&dur, tolerance, &mut rho, &mut dev);
            if worst > 1.0 {
                let f = worst * (1.0 + 1e-12) * 1.5f64.powi(stretches / 8);
                dur.iter_mut().for_each(|d| *d *= f);
                stretches += 1;
            } else if tb.start_gap(&w0) <= 1e-12 * scale {
                break;
            }
        }
        tb.shape(&dur, &consts);
        if tb.worst(&dur, tolerance, &mut rho, &mut dev) > 1.0 || tb.start_gap(&w0) > 1e-9 * scale {
            return None;
        }
        tb.shapes.iter_mut().for_each(Shape::finish);
        tb.tau[0] = tb.hmax[0];
        for (k, d) in dur.iter().enumerate() {
            tb.tau[k + 1] = tb.tau[k] + d;
        }
        Some(tb)
    }

    /// Puts the first blend's corner at `w₀ + v₀ h₀` (the current `h₀`) and
    /// the split points of the first segment between it and the next
    /// waypoint; their shortest durations follow.
    fn place_start(
        &mut self,
        w0: &[f64],
        fracs: &[f64],
        first: usize,
        v: &[f64],
        tmin: &mut [f64],
        dur: &mut [f64],
    ) {
        let dof = self.dof;
        let h0 = self.hmax[0];
        for (c, w) in w0.iter().enumerate() {
            let corner = w + self.start[c] * h0;
            let next = self.points[first * dof + c];
            self.points[c] = corner;
            for (p, f) in fracs.iter().enumerate() {
                self.points[(p + 1) * dof + c] = corner + f * (next - corner);
            }
        }
        for k in 0..first {
            tmin[k] = (0..dof)
                .map(|c| (self.points[(k + 1) * dof + c] - self.points[k * dof + c]).abs() / v[c])
                .fold(MIN_SEGMENT_TIME, f64::max);
            dur[k] = dur[k].max(tmin[k]);
        }
    }

    /// How far the motion's start, `corner − v₀ h₀`, is from `w₀`.
    fn start_gap(&self, w0: &[f64]) -> f64 {
        let h0 = self.hmax[0];
        (0..self.dof)
            .map(|c| (self.points[c] - self.start[c] * h0 - w0[c]).abs())
            .fold(0.0, f64::max)
    }

    /// Velocities, velocity changes and blend shapes for the durations
    /// `dur`.
    fn shape(&mut self, dur: &[f64], consts: &[JointConst]) {
        let dof = self.dof;
        let m = dur.len();
        for (k, d) in dur.iter().enumerate() {
            let inv = 1.0 / d;
            for c in 0..dof {
                self.vel[k * dof + c] = (self.points[(k + 1) * dof + c] - self.points[k * dof + c]) * inv;
            }
        }
        for i in 0..=m {
            for c in 0..dof {
                let after = if i < m { self.vel[i * dof + c] } else { 0.0 };
                let before = if i > 0 {
                    self.vel[(i - 1) * dof + c]
                } else {
                    self.start[c]
                };
                self.dv[i * dof + c] = after - before;
            }
            let own = self.interior_corner(i);
            let dv = &self.dv[i * dof..(i + 1) * dof];
            let shapes = &mut self.shapes[i * dof..(i + 1) * dof];
            if own {
                let err = &mut self.err[i * dof..(i + 1) * dof];
                for c in 0..dof {
                    (shapes[c], err[c]) = consts[c].blend(dv[c]);
                }
            } else {
                // one shape for all, from the limits' inverses
                let (mut da, mut dj) = (0.0f64, 0.0f64);
                for c in 0..dof {
                    let x = dv[c].abs();
                    da = da.max(x * consts[c].inv_a);
                    dj = dj.max(x * consts[c].inv_j);
                }
                shapes.fill(Shape::from_bounds(da, dj));
            }
            self.hmax[i] = shapes.iter().fold(0.0, |h, s| h.max(s.h));
        }
    }

    /// Whether point `i` is a waypoint other than the first and last.
    fn interior_corner(&self, i: usize) -> bool {
        i > 0 && i + 1 < self.hmax.len() && self.corner[i]
    }

    /// How far the motion passes from waypoint `i`: `e_i = |(e_{i,c})_c|`
    /// (0 but at interior waypoints: the blend there runs along the line).
    fn passing(&self, i: usize) -> f64 {
        if !self.interior_corner(i) {
            return 0.0;
        }
        let err = &self.err[i * self.dof..(i + 1) * self.dof];
        err.iter().map(|e| e * e).sum::<f64>().sqrt()
    }

    /// Into `seg[k]`: `ρ_k`, or `b_k/δ` where larger and the windows of
    /// blends `k` and `k + 1` overlap; into `pt[i]`: `e_i/δ`.
    fn ratios(&self, dur: &[f64], tolerance: f64, seg: &mut [f64], pt: &mut [f64]) {
        let dof = self.dof;
        for (i, p) in pt.iter_mut().enumerate() {
            *p = self.passing(i) / tolerance;
        }
        for (k, d) in dur.iter().enumerate() {
            let (here, next) = (k * dof, (k + 1) * dof);
            let fit = (0..dof)
                .map(|c| self.shapes[here + c].h + self.shapes[next + c].h)
                .fold(0.0, f64::max);
            let mut r = fit / d;
            if self.hmax[k] + self.hmax[k + 1] > *d && pt[k] > 0.0 && pt[k + 1] > 0.0 {
                let (e1, e2) = (&self.err[here..next], &self.err[next..next + dof]);
                let b = (0..dof).map(|c| e1[c].max(e2[c]).powi(2)).sum::<f64>().sqrt();
                r = r.max(b / tolerance);
            }
            seg[k] = r;
        }
    }

    /// The largest of every `ρ_k`, `b_k/δ` and `e_i/δ` (`seg`, `pt`: scratch
    /// of [`JerkBlends::ratios`]).
    fn worst(&self, dur: &[f64], tolerance: f64, seg: &mut [f64], pt: &mut [f64]) -> f64 {
        self.ratios(dur, tolerance, seg, pt);
        seg.iter().chain(pt.iter()).fold(0.0, |w, x| w.max(*x))
    }

    /// Duration, s.
    pub fn duration(&self) -> f64 {
        let m = self.hmax.len() - 1;
        if m == 0 {
            return 0.0;
        }
        self.tau[m] + self.hmax[m]
    }

    /// How far the motion passes from each waypoint, rad (m): 0 at the ends.
    #[cfg(test)]
    pub fn passing_distances(&self) -> Vec<f64> {
        let m = self.hmax.len() - 1;
        (0..=m)
            .filter(|&i| self.corner[i])
            .map(|i| if i == 0 || i == m { 0.0 } else { self.passing(i) })
            .collect()
    }

    /// The motion at `times` (sorted, s from this piece's start) into the
    /// rows of `q`, `q̇` and `q̈` (`times.len() × dof` each): on segment `k`
    /// (`τ_k ≤ t ≤ τ_{k+1}`, extended before `τ_0` and after `τ_m`), with
    /// `s = t − τ_k`, `s' = t − τ_{k+1}`, for each joint
    /// `q = w_k + V_k s + Δv_k (G₂,k(s) − s) + Δv_{k+1} G₂,k+1(s')`,
    /// `q̇ = V_k + Δv_k (G₁,k(s) − 1) + Δv_{k+1} G₁,k+1(s')`,
    /// `q̈ = Δv_k g_k(s) + Δv_{k+1} g_{k+1}(s')` (each term 0 outside its
    /// window). `None` once the deadline passes or the caller cancels
    /// (looked at every 4096 samples).
    fn sample_into(
        &self,
        times: &[f64],
        [q, qd, qdd]: [&mut [f64]; 3],
        deadline: Deadline<'_>,
    ) -> Option<()> {
        let dof = self.dof;
        let m = self.hmax.len() - 1;
        let mut k = 0;
        for (n, &t) in times.iter().enumerate() {
            if n % 4096 == 0 && deadline.expired() {
                return None;
            }
            let row = n * dof..(n + 1) * dof;
            let (q, qd, qdd) = (&mut q[row.clone()], &mut qd[row.clone()], &mut qdd[row]);
            if m == 0 {
                q.copy_from_slice(&self.points[..dof]);
                qd.fill(0.0);
                qdd.fill(0.0);
                continue;
            }
            while k + 1 < m && self.tau[k + 1] <= t {
                k += 1;
            }
            let s = t - self.tau[k];
            let s2 = t - self.tau[k + 1];
            let (here, next) = (k * dof, (k + 1) * dof);
            for c in 0..dof {
                let vk = self.vel[here + c];
                let (mut x, mut v, mut a) = (self.points[here + c] + vk * s, vk, 0.0);
                let (b1, b2) = (&self.shapes[here + c], &self.shapes[next + c]);
                if s < b1.h {
                    let [p1, v1, a1] = b1.at(s);
                    let d1 = self.dv[here + c];
                    x += d1 * (p1 - s);
                    v += d1 * (v1 - 1.0);
                    a += d1 * a1;
                }
                if s2 > -b2.h {
                    let [p2, v2, a2] = b2.at(s2);
                    let d2 = self.dv[next + c];
                    x += d2 * p2;
                    v += d2 * v2;
                    a += d2 * a2;
                }
                (q[c], qd[c], qdd[c]) = (x, v, a);
            }
        }
        Some(())
    }

    /// [`JerkBlends::sample_into`] a new trajectory.
    #[cfg(test)]
    fn sample(&self, times: &[f64], deadline: Deadline<'_>) -> Option<TimedTrajectory> {
        let n = times.len() * self.dof;
        let mut out = TimedTrajectory {
            dof: self.dof,
            t: times.to_vec(),
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
        };
        self.sample_into(times, [&mut out.q, &mut out.qd, &mut out.qdd], deadline)?;
        Some(out)
    }
}

/// Corners turning the path by more than this, rad (the angle between the
/// incoming and outgoing directions), are stopped at rather than passed:
/// near a reversal a blend within the tolerance must crawl, and stopping on
/// the waypoint is faster.
const STOP_ANGLE: f64 = 2.0;

/// The jerk-limited trajectory: the path cut at its sharp corners (turning
/// by more than [`STOP_ANGLE`]) into pieces, each a [`JerkBlends`] from rest
/// to rest, run one after another — or cut at every waypoint, when the
/// rest-to-rest S-curves of the segments ([`SCurve`]) add up to less.
pub(super) struct JerkPath {
    dof: usize,
    pieces: Vec<JerkBlends>,
    /// Start time of each piece, s.
    starts: Vec<f64>,
}

impl JerkPath {
    /// Times the path through `waypoints` (`n × dof`, finite, n ≥ 1) within
    /// `lim`, passing every interior waypoint it does not stop at within the
    /// tolerance. `None` when a moving start cannot be kept (no length to
    /// move along, or no fixed point for the first blend).
    pub fn new(waypoints: &[f64], dof: usize, lim: Limits<'_>) -> Option<Self> {
        let Limits { v, a, j, .. } = lim;
        let mut rows: Vec<&[f64]> = Vec::with_capacity(waypoints.len() / dof);
        for row in waypoints.chunks_exact(dof) {
            if rows.last().is_none_or(|last| *last != row) {
                rows.push(row);
            }
        }
        let unit = |from: &[f64], to: &[f64]| -> Vec<f64> {
            let d: Vec<f64> = (0..dof).map(|c| to[c] - from[c]).collect();
            let n = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            d.iter().map(|x| x / n).collect()
        };
        let mut cuts = vec![0];
        for i in 1..rows.len().saturating_sub(1) {
            let (din, dout) = (unit(rows[i - 1], rows[i]), unit(rows[i], rows[i + 1]));
            let cos: f64 = din.iter().zip(&dout).map(|(x, y)| x * y).sum();
            if cos.clamp(-1.0, 1.0).acos() > STOP_ANGLE {
                cuts.push(i);
            }
        }
        cuts.push(rows.len() - 1);
        let path = Self::with_cuts(&rows, &cuts, dof, lim)?;
        // where the corners force a crawl on long segments, stopping at
        // every waypoint (rest-to-rest S-curves, closed form) can be faster
        let stops: f64 = rows
            .windows(2)
            .map(|w| {
                let lim = |l: &[f64]| {
                    (0..dof)
                        .filter(|&c| w[1][c] != w[0][c])
                        .map(|c| l[c] / (w[1][c] - w[0][c]).abs())
                        .fold(f64::INFINITY, f64::min)
                };
                SCurve::rest_to_rest(1.0, lim(v), lim(a), lim(j)).duration()
            })
            .sum();
        if rows.len() > 2 && stops < path.duration() {
            let every: Vec<usize> = (0..rows.len()).collect();
            if let Some(stopping) = Self::with_cuts(&rows, &every, dof, lim)
                && stopping.duration() < path.duration()
            {
                return Some(stopping);
            }
        }
        Some(path)
    }

    /// One [`JerkBlends`] between consecutive `cuts` (indices into `rows`,
    /// first and last included), from rest to rest but the first, which
    /// starts at `lim.start`.
    fn with_cuts(rows: &[&[f64]], cuts: &[usize], dof: usize, lim: Limits<'_>) -> Option<Self> {
        let mut path = JerkPath {
            dof,
            pieces: Vec::with_capacity(cuts.len()),
            starts: Vec::with_capacity(cuts.len()),
        };
        let mut t = 0.0;
        for (n, w) in cuts.windows(2).enumerate() {
            let flat: Vec<f64> = rows[w[0]..=w[1]].concat();
            let piece_lim = Limits {
                start: if n == 0 { lim.start } else { &[] },
                ..lim
            };
            let piece = JerkBlends::new(&flat, dof, piece_lim)?;
            path.starts.push(t);
            t += piece.duration();
            path.pieces.push(piece);
        }
        if path.pieces.is_empty() {
            // a single waypoint: one piece at rest
            path.starts.push(0.0);
            path.pieces.push(JerkBlends::new(rows[0], dof, lim)?);
        }
        Some(path)
    }

    /// Duration, s.
    pub fn duration(&self) -> f64 {
        match (self.starts.last(), self.pieces.last()) {
            (Some(t), Some(p)) => t + p.duration(),
            _ => 0.0,
        }
    }

    /// The motion at `times` (sorted), each piece from its own start time;
    /// `None` once the deadline passes or the caller cancels.
    pub fn sample(&self, times: &[f64], deadline: Deadline<'_>) -> Option<TimedTrajectory> {
        let dof = self.dof;
        let n = times.len() * dof;
        let mut out = TimedTrajectory {
            dof,
            t: times.to_vec(),
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
        };
        let mut from = 0;
        // the piece's own clock, reused across pieces
        let mut local = Vec::with_capacity(times.len());
        for (p, piece) in self.pieces.iter().enumerate() {
            let start = self.starts[p];
            let to = match self.starts.get(p + 1) {
                Some(next) => from + times[from..].partition_point(|t| t < next),
                None => times.len(),
            };
            local.clear();
            local.extend(times[from..to].iter().map(|t| t - start));
            let rows = from * dof..to * dof;
            let out_rows = [
                &mut out.q[rows.clone()],
                &mut out.qd[rows.clone()],
                &mut out.qdd[rows],
            ];
            piece.sample_into(&local, out_rows, deadline)?;
            from = to;
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shape_integrates_to_one_and_its_offset_matches_the_integral() {
        for (h, r) in [(0.35, 0.2), (0.3, 0.3), (0.5, 0.01)] {
            let mut s = Shape { h, r, jerk: 0.0 };
            s.finish();
            // G₁(h) = 1, G₂(h) = h (g even), g(±h) = 0
            let [p, v, a] = s.at(h - 1e-15);
            assert!((v - 1.0).abs() < 1e-9 && (p - h).abs() < 1e-9 && a.abs() < 1e-9);
            // offset = ∫_{−h}^{0} (−σ) g(σ) dσ by the midpoint rule
            let n = 200_000;
            let step = h / n as f64;
            let integral: f64 = (0..n)
                .map(|i| {
                    let sigma = -h + (i as f64 + 0.5) * step;
                    -sigma * s.at(sigma)[2] * step
                })
                .sum();
            assert!(
                (integral - s.offset()).abs() < 1e-8,
                "{integral} vs {}",
                s.offset()
            );
            // and G₂(0) is that offset too: ∫_{−h}^{0} G₁ = ∫ (0 − σ) g
            assert!((s.at(0.0)[0] - s.offset()).abs() < 1e-12);
        }
        // hand-derived: a velocity change of 1 at a = 2, j = 10: w = 0.5,
        // r = 0.2, h = 0.35
        let s = Shape::for_change(&[1.0, -0.5], &[2.0, 2.0], &[10.0, 10.0]);
        assert!((s.h - 0.35).abs() < 1e-15 && (s.r - 0.2).abs() < 1e-15);
        // at j = 1 the jerk binds: w = r = 1, h = 1
        let s = Shape::for_change(&[1.0], &[2.0], &[1.0]);
        assert!((s.h - 1.0).abs() < 1e-15 && (s.r - 1.0).abs() < 1e-15);
        // one joint's blend is the shape of that joint alone, passing its
        // corner at |Δv| times the integral's offset, on both sides of the
        // knee a²/j (= 0.4 at a = 2, j = 10)
        let k = JointConst::new(2.0, 10.0);
        for dv in [-1.0, 0.7, 0.4, -0.25, 1e-3] {
            let (s, e) = k.blend(dv);
            let alone = Shape::for_change(&[dv], &[2.0], &[10.0]);
            assert!((s.h - alone.h).abs() < 1e-15 && (s.r - alone.r).abs() < 1e-15);
            assert!((e - dv.abs() * alone.offset()).abs() < 1e-15, "{dv}");
        }
    }

    #[test]
    fn a_right_angle_is_blended_at_the_hand_derived_distance_and_time() {
        // (0,0) → (2,0) → (2,2) at v = 1, a = 2, j = 10: each segment runs at
        // 1 rad/s for 2 s; every blend changes one or two joints by 1 rad/s,
        // so h = 0.35, r = 0.2 (see above) and the total is 2 + 2 + 0.35 +
        // 0.35 = 4.7 s. At the corner the offset is
        // ((0.15)²/2 + 0.35·0.2/2 − 0.2²/3)/0.5 = 0.0658333…, along
        // Δv = (−1, 1): the motion passes at √2 · 0.0658333 from (2, 0).
        let w = [0.0, 0.0, 2.0, 0.0, 2.0, 2.0];
        let lim = [1.0, 1.0];
        let limits = |tolerance| Limits {
            v: &lim,
            a: &[2.0, 2.0],
            j: &[10.0, 10.0],
            tolerance,
            start: &[],
        };
        let tb = JerkBlends::new(&w, 2, limits(0.1)).unwrap();
        assert!((tb.duration() - 4.7).abs() < 1e-12, "{}", tb.duration());
        let off = (0.15f64.powi(2) / 2.0 + 0.35 * 0.2 / 2.0 - 0.04 / 3.0) / 0.5;
        let tr = tb.sample(&[0.35 + 2.0], Deadline::none()).unwrap();
        assert!(
            (tr.q[0] - (2.0 - off)).abs() < 1e-12 && (tr.q[1] - off).abs() < 1e-12,
            "{:?}",
            tr.q
        );
        assert!((tb.passing_distances()[1] - 2f64.sqrt() * off).abs() < 1e-12);
        // half-way along the blend the velocity is the mean of the two lines
        assert!((tr.qd[0] - 0.5).abs() < 1e-12 && (tr.qd[1] - 0.5).abs() < 1e-12);
        // a tolerance of 0.05 is tighter: the corner is slowed until it fits
        let tight = JerkBlends::new(&w, 2, limits(0.05)).unwrap();
        assert!(tight.passing_distances()[1] <= 0.05 + 1e-12);
        assert!(tight.duration() > 4.7);
    }

    #[test]
    fn each_joint_blends_a_corner_over_its_own_window() {
        // the right angle above with joint 1 at a = 8, j = 40: at the corner
        // joint 0 still needs h = 0.35, r = 0.2, while joint 1 changes by
        // 1 rad/s in a triangle: D_a = 1/8, D_j = 1/40 > D_a², so
        // w = r = √(1/40), h = √(1/40) and its offset is h/6. The start
        // blend (joint 0 alone) takes h = 0.35, the end blend (joint 1
        // alone) h = √(1/40): 0.35 + 2 + 2 + √(1/40) s in all, where one
        // shape for both joints would take the 0.35 of joint 0 at the corner.
        let w = [0.0, 0.0, 2.0, 0.0, 2.0, 2.0];
        let lim = Limits {
            v: &[1.0, 1.0],
            a: &[2.0, 8.0],
            j: &[10.0, 40.0],
            tolerance: 0.1,
            start: &[],
        };
        let tb = JerkBlends::new(&w, 2, lim).unwrap();
        let h1 = (1.0f64 / 40.0).sqrt();
        assert!((tb.duration() - (4.35 + h1)).abs() < 1e-12, "{}", tb.duration());
        let off0 = (0.15f64.powi(2) / 2.0 + 0.35 * 0.2 / 2.0 - 0.04 / 3.0) / 0.5;
        let off1 = h1 / 6.0;
        let tr = tb
            .sample(&[0.35 + 2.0 - h1, 0.35 + 2.0], Deadline::none())
            .unwrap();
        // joint 1 still at rest where its window opens, joint 0 already
        // slowing down
        assert!(tr.q[1].abs() < 1e-12 && tr.qd[1].abs() < 1e-12);
        assert!(tr.qd[0] < 1.0 - 1e-3);
        // at the corner time: each joint off by its own offset
        assert!(
            (tr.q[2] - (2.0 - off0)).abs() < 1e-12 && (tr.q[3] - off1).abs() < 1e-12,
            "{:?}",
            tr.q
        );
        assert!((tb.passing_distances()[1] - off0.hypot(off1)).abs() < 1e-12);
    }

    /// Distance from `p` to the polyline through the rows of `w`.
    fn polyline_distance(w: &[f64], dof: usize, p: &[f64]) -> f64 {
        let mut best = f64::INFINITY;
        for seg in w.chunks_exact(dof).collect::<Vec<_>>().windows(2) {
            let d: Vec<f64> = (0..dof).map(|c| seg[1][c] - seg[0][c]).collect();
            let dd: f64 = d.iter().map(|x| x * x).sum();
            let t = if dd > 0.0 {
                ((0..dof).map(|c| (p[c] - seg[0][c]) * d[c]).sum::<f64>() / dd).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let e: f64 = (0..dof).map(|c| (seg[0][c] + t * d[c] - p[c]).powi(2)).sum();
            best = best.min(e.sqrt());
        }
        best
    }

    #[test]
    fn overlapping_windows_of_two_corners_keep_the_motion_within_the_tolerance() {
        // unsplit segments between corners of a random walk, joints with
        // different limits: on some segments one joint is still leaving one
        // corner while another has started into the next; every 1 ms sample
        // stays within the tolerance of the polyline and within the limits
        use rand::{Rng, SeedableRng};
        let dof = 4;
        let (v, a, j) = (
            [1.0, 2.0, 1.5, 2.5],
            [2.0, 9.0, 4.0, 12.0],
            [20.0, 300.0, 60.0, 500.0],
        );
        let tolerance = 0.02;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut overlaps = 0;
        for case in 0..20 {
            let mut q = [0.0; 4];
            let mut w = Vec::new();
            for _ in 0..10 {
                w.extend_from_slice(&q);
                q.iter_mut().for_each(|x| *x += rng.random_range(-0.3..0.3));
            }
            let lim = Limits {
                v: &v,
                a: &a,
                j: &j,
                tolerance,
                start: &[],
            };
            let tb = JerkBlends::with_splits(&w, dof, &[], lim).unwrap();
            let m = tb.hmax.len() - 1;
            for k in 1..m - 1 {
                if tb.hmax[k] + tb.hmax[k + 1] > tb.tau[k + 1] - tb.tau[k] {
                    overlaps += 1;
                }
            }
            let times: Vec<f64> = (0..=(tb.duration() / 1e-3) as usize)
                .map(|i| i as f64 * 1e-3)
                .collect();
            let tr = tb.sample(&times, Deadline::none()).unwrap();
            for (p, (qd, qdd)) in
                tr.q.chunks_exact(dof)
                    .zip(tr.qd.chunks_exact(dof).zip(tr.qdd.chunks_exact(dof)))
            {
                let d = polyline_distance(&w, dof, p);
                assert!(d <= tolerance + 1e-9, "case {case}: {d}");
                for c in 0..dof {
                    assert!(qd[c].abs() <= v[c] * (1.0 + 1e-9), "case {case}: v");
                    assert!(qdd[c].abs() <= a[c] * (1.0 + 1e-9), "case {case}: a");
                }
            }
        }
        assert!(overlaps > 0, "no overlapping windows: the test misses its case");
    }
}
