//! Closed-form toy worlds for the planner tests: a planar arm among circles
//! (exact segment–circle distances) and joint-space boxes.

use crate::collision::{MotionCheck, StateChecker};

/// A planar arm of equal links (length `link` m, capsule radius `radius`)
/// turning about z, among circular obstacles `(x, y, r)`; joint limits ±`limit`.
pub(crate) struct PlanarWorld {
    pub links: usize,
    pub link: f64,
    pub radius: f64,
    pub limit: f64,
    pub circles: Vec<(f64, f64, f64)>,
    /// Busy work per `is_valid`, to make a checker slow (iterations).
    pub spin: u32,
}

/// Distance from point `p` to the segment `a–b`.
pub(crate) fn point_segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (cx, cy) = (a.0 + t * dx - p.0, a.1 + t * dy - p.1);
    (cx * cx + cy * cy).sqrt()
}

impl PlanarWorld {
    /// The 3-link, 1 m-reach arm of `planar_3` with one circle on the x axis.
    pub fn planar3_blocked() -> Self {
        Self {
            links: 3,
            link: 1.0 / 3.0,
            radius: 0.02,
            limit: std::f64::consts::PI,
            circles: vec![(0.75, 0.0, 0.12)],
            spin: 0,
        }
    }

    /// The same world with every circle's radius reduced by `margin` (m), for
    /// independent re-checks: a motion checked at resolution r rad can only
    /// miss penetrations shallower than r × (sum of the joint-to-tip
    /// distances), 2·r m for this 1 m arm (0.02 m at its 0.01 rad).
    pub fn shrunk(&self, margin: f64) -> Self {
        Self {
            circles: self.circles.iter().map(|&(x, y, r)| (x, y, r - margin)).collect(),
            spin: 0,
            ..*self
        }
    }

    /// Smallest surface distance between a link and a circle (m).
    pub fn distance(&self, q: &[f64]) -> f64 {
        let mut acc = 0.0;
        let mut a = (0.0, 0.0);
        let mut best = f64::INFINITY;
        for &qi in q.iter().take(self.links) {
            acc += qi;
            let b = (a.0 + self.link * acc.cos(), a.1 + self.link * acc.sin());
            for &(x, y, r) in &self.circles {
                best = best.min(point_segment_distance((x, y), a, b) - r - self.radius);
            }
            a = b;
        }
        best
    }
}

impl StateChecker for PlanarWorld {
    fn dof(&self) -> usize {
        self.links
    }
    fn motion_check(&self) -> MotionCheck {
        MotionCheck::Interpolated { resolution: 0.01 }
    }
    fn is_valid(&self, q: &[f64]) -> bool {
        let mut x = 0u64;
        for i in 0..self.spin {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(i as u64));
        }
        std::hint::black_box(x);
        q.len() == self.links && q.iter().all(|v| v.abs() <= self.limit) && self.distance(q) > 0.0
    }
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
        self.distance(q).min(max_distance)
    }
}

/// A joint-space world: axis-aligned boxes `(lo, hi)` are obstacles; the
/// limits are `[-limit, limit]` on every joint.
pub(crate) struct JointBoxes {
    pub dof: usize,
    pub limit: f64,
    pub boxes: Vec<(Vec<f64>, Vec<f64>)>,
}

impl JointBoxes {
    /// The same world with every box shrunk by `margin` per side: a motion
    /// checked at resolution r (max-norm) can only clip boxes by less than
    /// r/2 per side, so it is valid in the world shrunk by r/2.
    pub fn shrunk(&self, margin: f64) -> Self {
        Self {
            dof: self.dof,
            limit: self.limit,
            boxes: self
                .boxes
                .iter()
                .map(|(lo, hi)| {
                    (
                        lo.iter().map(|v| v + margin).collect(),
                        hi.iter().map(|v| v - margin).collect(),
                    )
                })
                .collect(),
        }
    }
}

impl StateChecker for JointBoxes {
    fn dof(&self) -> usize {
        self.dof
    }
    fn is_valid(&self, q: &[f64]) -> bool {
        q.len() == self.dof
            && q.iter().all(|v| v.abs() <= self.limit)
            && !self
                .boxes
                .iter()
                .any(|(lo, hi)| q.iter().zip(lo).zip(hi).all(|((v, l), h)| v > l && v < h))
    }
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
        let mut best = max_distance;
        for (lo, hi) in &self.boxes {
            let mut out = 0.0_f64;
            let mut inside = f64::INFINITY;
            for ((v, l), h) in q.iter().zip(lo).zip(hi) {
                let d = (l - v).max(v - h);
                if d > 0.0 {
                    out += d * d;
                }
                inside = inside.min(-d);
            }
            best = best.min(if out > 0.0 { out.sqrt() } else { -inside });
        }
        best
    }
    fn motion_check(&self) -> MotionCheck {
        MotionCheck::Interpolated { resolution: 0.02 }
    }
}

/// Independent re-check: every state along every segment at `step` (max-norm).
pub(crate) fn fine_valid<C: StateChecker>(checker: &C, q: &[f64], dof: usize, step: f64) -> bool {
    let rows: Vec<&[f64]> = q.chunks_exact(dof).collect();
    rows.windows(2).all(|w| {
        let span = w[0]
            .iter()
            .zip(w[1])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let k = (span / step).ceil().max(1.0) as usize;
        (0..=k).all(|i| {
            let s = i as f64 / k as f64;
            let p: Vec<f64> = w[0].iter().zip(w[1]).map(|(a, b)| a + s * (b - a)).collect();
            checker.is_valid(&p)
        })
    })
}
