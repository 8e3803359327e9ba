//! [`Curve`]: a joint-space path as TOPP-RA sees it — pieces on which the
//! path is smooth, evaluated with its first two derivatives.

/// A path `q(s)`, `s` from 0 to the end of the last piece, made of pieces
/// with smooth derivatives inside (they may jump between pieces).
pub trait Curve {
    /// Joints.
    fn dof(&self) -> usize;
    /// Number of pieces.
    fn pieces(&self) -> usize;
    /// Where piece `k` starts and ends along `s`.
    fn span(&self, k: usize) -> (f64, f64);
    /// How far the tangent turns along piece `k`, rad (sets the grid density).
    fn turn(&self, k: usize) -> f64;
    /// The path must be at rest where piece `k` ends (a corner it cannot round).
    fn stop_after(&self, k: usize) -> bool;
    /// `q(s)`, `q'(s)` and `q''(s)` on piece `k` (one-sided at its ends).
    fn eval(&self, k: usize, s: f64, q: &mut [f64], d1: &mut [f64], d2: &mut [f64]);
    /// `q'` and `q''` halfway between `s_a` and `s_b` on piece `k`, given
    /// their values at both (`a1`, `a2` at `s_a`; `b1`, `b2` at `s_b`).
    /// By default an [`eval`](Curve::eval) at the midpoint; a curve whose
    /// pieces are lines and circular arcs can combine the ends instead.
    #[allow(clippy::too_many_arguments)]
    fn eval_mid(
        &self,
        k: usize,
        s_a: f64,
        s_b: f64,
        _ends: [&[f64]; 4],
        d1: &mut [f64],
        d2: &mut [f64],
        q: &mut [f64],
    ) {
        self.eval(k, (s_a + s_b) / 2.0, q, d1, d2);
    }
}
