//! The waypoint polyline with its corners rounded by circular arcs of bounded
//! deviation (Kunz & Stilman, "Time-Optimal Trajectory Generation for Path
//! Following with Bounded Acceleration and Velocity", RSS 2012), as a
//! [`Curve`] parameterised by joint-space arc length.

use super::curve::Curve;

/// Smallest corner angle that is blended, rad; straighter corners are kept
/// as they are (the direction barely changes).
const MIN_CORNER: f64 = 1e-9;
/// Corners within this of a full reversal (π − angle, rad) cannot be rounded:
/// the path stops there.
const MIN_REVERSAL: f64 = 1e-6;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// `q(σ) = p + σ·d`, `d` a unit vector.
    Line,
    /// `q(θ) = c + r (x cos θ + y sin θ)`, `θ = σ/r`, `x`, `y` orthonormal.
    Arc { radius: f64, angle: f64 },
}

#[derive(Debug, Clone)]
struct Piece {
    kind: Kind,
    /// Arc length where the piece starts.
    s0: f64,
    len: f64,
    /// The speed must be zero where the piece ends (an unrounded reversal).
    stop: bool,
    /// Offset of the piece's vectors in `BlendedPath::data`: line `p, d`;
    /// arc `c, x, y`.
    at: usize,
}

/// Straight segments between the waypoints joined by circular arcs.
///
/// At an interior waypoint `q_i` with unit directions `y_in`, `y_out` and
/// corner angle `α = acos(y_in·y_out)` the arc starts `ℓ` before `q_i` and
/// ends `ℓ` after it, with
///
/// ```text
/// ℓ = min(|q_i − q_{i−1}|/2, |q_{i+1} − q_i|/2, δ sin(α/2) / (1 − cos(α/2)))
/// r = ℓ / tan(α/2),   centre c = q_i + r/cos(α/2) · (y_out − y_in)/|y_out − y_in|
/// ```
///
/// so the arc is tangent to both segments and passes `r(1/cos(α/2) − 1) ≤ δ`
/// from the waypoint (Kunz & Stilman 2012). Consecutive equal
/// waypoints are merged; a reversal (α ≈ π) is not rounded and the path
/// stops there.
#[derive(Debug, Clone)]
pub struct BlendedPath {
    dof: usize,
    pieces: Vec<Piece>,
    data: Vec<f64>,
    len: f64,
}

impl BlendedPath {
    /// The path through `waypoints` (`n × dof` row-major, finite) with blends
    /// at most `tolerance` (> 0) from each waypoint.
    pub fn new(waypoints: &[f64], dof: usize, tolerance: f64) -> Self {
        let mut pts: Vec<&[f64]> = Vec::new();
        for row in waypoints.chunks_exact(dof.max(1)) {
            if pts.last().is_none_or(|p: &&[f64]| dist(p, row) > 1e-12) {
                pts.push(row);
            }
        }
        let mut path = BlendedPath {
            dof,
            pieces: Vec::new(),
            data: Vec::new(),
            len: 0.0,
        };
        if pts.len() < 2 {
            return path;
        }
        let m = pts.len() - 1;
        // at most a line and an arc per segment; one flat buffer of unit
        // directions and one of each per-corner vector, reused
        path.pieces.reserve(2 * m);
        path.data.reserve(5 * m * dof);
        let lens: Vec<f64> = (0..m).map(|k| dist(pts[k], pts[k + 1])).collect();
        let mut dirs = Vec::with_capacity(m * dof);
        for k in 0..m {
            dirs.extend((0..dof).map(|j| (pts[k + 1][j] - pts[k][j]) / lens[k]));
        }
        let (mut start, mut centre, mut x) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
        // where the current line starts
        let mut from: Vec<f64> = pts[0].to_vec();
        for i in 1..m {
            let (yi, yo) = (&dirs[(i - 1) * dof..i * dof], &dirs[i * dof..(i + 1) * dof]);
            let cos = dot(yi, yo).clamp(-1.0, 1.0);
            let alpha = cos.acos();
            if alpha < MIN_CORNER {
                continue;
            }
            let half = alpha / 2.0;
            let l = (lens[i - 1] / 2.0)
                .min(lens[i] / 2.0)
                .min(tolerance * half.sin() / (1.0 - half.cos()));
            let radius = l / half.tan();
            let q = pts[i];
            if std::f64::consts::PI - alpha < MIN_REVERSAL || radius < 1e-12 {
                path.push_line(&from, q, true);
                from.copy_from_slice(q);
                continue;
            }
            for j in 0..dof {
                start[j] = q[j] - l * yi[j];
            }
            path.push_line(&from, &start, false);
            let bn = dist(yo, yi);
            for j in 0..dof {
                centre[j] = q[j] + radius / half.cos() * (yo[j] - yi[j]) / bn;
                x[j] = (start[j] - centre[j]) / radius;
            }
            path.push_arc(&centre, &x, yi, radius, alpha);
            for j in 0..dof {
                from[j] = q[j] + l * yo[j];
            }
        }
        path.push_line(&from, pts[m], false);
        path
    }

    fn push_line(&mut self, a: &[f64], b: &[f64], stop: bool) {
        let len = dist(a, b);
        if len <= 1e-12 {
            if stop && let Some(last) = self.pieces.last_mut() {
                last.stop = true;
            }
            return;
        }
        let at = self.data.len();
        self.data.extend_from_slice(a);
        self.data.extend((0..self.dof).map(|j| (b[j] - a[j]) / len));
        self.pieces.push(Piece {
            kind: Kind::Line,
            s0: self.len,
            len,
            stop,
            at,
        });
        self.len += len;
    }

    fn push_arc(&mut self, centre: &[f64], x: &[f64], y: &[f64], radius: f64, angle: f64) {
        let at = self.data.len();
        self.data.extend_from_slice(centre);
        self.data.extend_from_slice(x);
        self.data.extend_from_slice(y);
        let len = radius * angle;
        self.pieces.push(Piece {
            kind: Kind::Arc { radius, angle },
            s0: self.len,
            len,
            stop: false,
            at,
        });
        self.len += len;
    }

    /// Total arc length, rad (m).
    pub fn length(&self) -> f64 {
        self.len
    }
}

impl Curve for BlendedPath {
    fn dof(&self) -> usize {
        self.dof
    }

    fn pieces(&self) -> usize {
        self.pieces.len()
    }

    fn span(&self, k: usize) -> (f64, f64) {
        let p = &self.pieces[k];
        (p.s0, p.s0 + p.len)
    }

    fn turn(&self, k: usize) -> f64 {
        match self.pieces[k].kind {
            Kind::Line => 0.0,
            Kind::Arc { angle, .. } => angle,
        }
    }

    fn stop_after(&self, k: usize) -> bool {
        self.pieces[k].stop
    }

    fn eval(&self, k: usize, s: f64, q: &mut [f64], d1: &mut [f64], d2: &mut [f64]) {
        let p = &self.pieces[k];
        let n = self.dof;
        let sigma = (s - p.s0).clamp(0.0, p.len);
        let v = &self.data[p.at..];
        match p.kind {
            Kind::Line => {
                for j in 0..n {
                    q[j] = v[j] + sigma * v[n + j];
                    d1[j] = v[n + j];
                    d2[j] = 0.0;
                }
            }
            Kind::Arc { radius, .. } => {
                let (sin, cos) = (sigma / radius).sin_cos();
                for j in 0..n {
                    let (c, x, y) = (v[j], v[n + j], v[2 * n + j]);
                    let radial = x * cos + y * sin;
                    q[j] = c + radius * radial;
                    d1[j] = -x * sin + y * cos;
                    d2[j] = -radial / radius;
                }
            }
        }
    }

    /// On a line the derivatives are constant. On an arc `q'` and `q''` are
    /// linear in `(cos θ, sin θ)`, and the sum of that unit vector at two
    /// angles is `2 cos(Δθ/2)` times the unit vector at their mean; `x`, `y`
    /// orthonormal make `|q'(θ_a) + q'(θ_b)| = 2 cos(Δθ/2)`, so
    /// `q'(θ_m) = (q'_a + q'_b) / |q'_a + q'_b|` and likewise `q''` (no sine
    /// or cosine). `q` is left as it is.
    fn eval_mid(
        &self,
        k: usize,
        s_a: f64,
        s_b: f64,
        ends: [&[f64]; 4],
        d1: &mut [f64],
        d2: &mut [f64],
        q: &mut [f64],
    ) {
        let [a1, a2, b1, b2] = ends;
        let n = self.dof;
        match self.pieces[k].kind {
            Kind::Line => {
                d1[..n].copy_from_slice(&a1[..n]);
                d2[..n].fill(0.0);
            }
            Kind::Arc { .. } => {
                let norm = (0..n).map(|j| (a1[j] + b1[j]).powi(2)).sum::<f64>().sqrt();
                // ends half a turn apart or more: the sum says nothing
                if norm < 0.5 {
                    self.eval(k, (s_a + s_b) / 2.0, q, d1, d2);
                    return;
                }
                let f = 1.0 / norm;
                for j in 0..n {
                    d1[j] = (a1[j] + b1[j]) * f;
                    d2[j] = (a2[j] + b2[j]) * f;
                }
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(path: &BlendedPath, s: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let k = (0..path.pieces())
            .find(|&k| s <= path.span(k).1 + 1e-12)
            .unwrap_or(path.pieces() - 1);
        let n = path.dof();
        let (mut q, mut d1, mut d2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        path.eval(k, s, &mut q, &mut d1, &mut d2);
        (q, d1, d2)
    }

    #[test]
    fn a_right_angle_is_rounded_by_a_quarter_circle_within_the_tolerance() {
        // (0,0) → (1,0) → (1,1): α = π/2, ℓ = δ·sin45°/(1 − cos45°) = δ(1+√2)
        let delta = 0.1;
        let p = BlendedPath::new(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0], 2, delta);
        assert_eq!(p.pieces(), 3);
        let l = delta * (1.0 + 2f64.sqrt());
        assert!((p.span(0).1 - (1.0 - l)).abs() < 1e-12);
        // radius ℓ/tan45° = ℓ, quarter turn
        assert!((p.span(1).1 - p.span(1).0 - l * std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let mid = (p.span(1).0 + p.span(1).1) / 2.0;
        let (q, d1, d2) = at(&p, mid);
        // closest approach to the corner is exactly δ, on the diagonal
        let gap = ((q[0] - 1.0).powi(2) + q[1].powi(2)).sqrt();
        assert!((gap - delta).abs() < 1e-12, "{gap}");
        assert!((d1[0] - d1[1]).abs() < 1e-12 && (d1[0] - 0.5f64.sqrt()).abs() < 1e-12);
        let curvature = (d2[0] * d2[0] + d2[1] * d2[1]).sqrt();
        assert!((curvature - 1.0 / l).abs() < 1e-12);
        // ends where the segment resumes, heading +y
        let (q, d1, _) = at(&p, p.span(1).1);
        assert!((q[0] - 1.0).abs() < 1e-12 && (q[1] - l).abs() < 1e-12);
        assert!(d1[0].abs() < 1e-12 && (d1[1] - 1.0).abs() < 1e-12);
        assert!((p.length() - (2.0 - 2.0 * l + l * std::f64::consts::FRAC_PI_2)).abs() < 1e-12);
    }

    #[test]
    fn the_midpoint_from_the_ends_matches_the_arc_evaluated_there() {
        // a 3-joint corner of 2 rad, and a line piece
        let p = BlendedPath::new(&[0.0, 0.0, 0.0, 1.0, 0.2, 0.0, 0.3, 0.9, 0.4], 3, 0.2);
        let n = p.dof();
        let ev = |k: usize, s: f64| {
            let (mut q, mut d1, mut d2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            p.eval(k, s, &mut q, &mut d1, &mut d2);
            (d1, d2)
        };
        for k in 0..p.pieces() {
            let (a, b) = p.span(k);
            for (fa, fb) in [(0.0, 1.0), (0.1, 0.3), (0.55, 0.6)] {
                let (sa, sb) = (a + (b - a) * fa, a + (b - a) * fb);
                let ((a1, a2), (b1, b2)) = (ev(k, sa), ev(k, sb));
                let (m1, m2) = ev(k, (sa + sb) / 2.0);
                let (mut d1, mut d2, mut q) = (vec![9.0; n], vec![9.0; n], vec![0.0; n]);
                p.eval_mid(k, sa, sb, [&a1, &a2, &b1, &b2], &mut d1, &mut d2, &mut q);
                for j in 0..n {
                    assert!((d1[j] - m1[j]).abs() < 1e-13, "piece {k} q' {j}");
                    assert!((d2[j] - m2[j]).abs() < 1e-12, "piece {k} q'' {j}");
                }
            }
        }
    }

    #[test]
    fn short_segments_limit_the_blend_and_reversals_stop() {
        // legs of 0.2: ℓ = 0.1 whatever δ
        let p = BlendedPath::new(&[0.0, 0.0, 0.2, 0.0, 0.2, 0.2], 2, 10.0);
        assert!((p.span(1).0 - 0.1).abs() < 1e-12);
        let back = BlendedPath::new(&[0.0, 1.0, 0.0, 0.5], 1, 0.1);
        assert_eq!(back.pieces(), 3);
        assert!(back.stop_after(0) && back.stop_after(1) && !back.stop_after(2));
        assert!((back.length() - 2.5).abs() < 1e-12);
        // duplicates and collinear points add nothing
        let line = BlendedPath::new(&[0.0, 0.0, 0.0, 0.5, 1.0], 1, 0.1);
        assert_eq!(line.pieces(), 1);
        assert!((line.length() - 1.0).abs() < 1e-12);
    }
}
