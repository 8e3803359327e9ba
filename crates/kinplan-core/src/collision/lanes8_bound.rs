//! How far the eight-lane forward kinematics in `f32` (`lanes8`) can place
//! a point from where exact arithmetic puts it: the margin every sphere of
//! the batched check is grown by, so that its verdict "clear" holds for the
//! exact geometry.
//!
//! Model (Higham, *Accuracy and Stability of Numerical Algorithms*, §2–3):
//! every `f32` operation returns the exact result times `(1 + θ)`,
//! `|θ| ≤ u = 2⁻²⁴`; a sum of `n` products evaluated in order is within
//! `γₙ·Σ|terms|` of the exact sum, `γₙ = nu/(1 − nu)`. Stored constants
//! (rotation entries `≤ 1`, offsets) are rounded to `f32`: `|F_jk| ≤ u`
//! per rotation entry (so `‖F‖₂ ≤ ‖F‖_F ≤ 3u`), `|f| ≤ u|p_o|` per offset.
//!
//! Tracked along the chain, for the frame `(R̃, p̃)` the lanes compute
//! against the exact `(R, p)`: `ρ ≥ ‖r̃ᵢ − rᵢ‖₂` for every row `i` of the
//! rotation, `π ≥ |p̃ᵢ − pᵢ|` for every coordinate, and `P ≥ |pᵢ|`.
//!
//! * Fixed origin `(R_o, p_o)`: `R ← R·R_o`, `p ← p + R·p_o`. Row `i` of
//!   the new rotation is `r̃ᵢR̂_o` plus rounding: `‖(r̃ᵢ − rᵢ)R̂_o‖ ≤
//!   ρ(1 + 3u)`, `‖rᵢF‖ ≤ 3u`, and each entry's rounding is at most
//!   `γ₃·‖r̃ᵢ‖‖col_k R̂_o‖ ≤ γ₃(1 + ρ)(1 + 3u)` (Cauchy–Schwarz), so
//!
//!   `ρ' = ρ(1 + 3u) + 3u + √3·γ₃(1 + ρ)(1 + 3u)`,
//!   `π' = π + ρ(1 + u)|p_o| + u|p_o| + γ₄(P + π + (1 + ρ)(1 + u)|p_o|)`,
//!   `P' = P + |p_o|`.
//!
//!   (A signed permutation `R_o` is applied by moving columns, exactly; the
//!   bound above still holds.)
//! * Turn by `q` about `z`: columns `(c₀, c₁) ← (c·c₀ + s·c₁, c·c₁ − s·c₀)`
//!   with `|ŝ − sin q|, |ĉ − cos q| ≤ η` (`trig32`). Per row this is the
//!   plane rotation `G` applied to `(ã, b̃)`: `‖G̃ − G‖₂ ≤ ‖G̃ − G‖_F ≤ 2η`,
//!   `‖(ã, b̃)‖ ≤ 1 + ρ`, rounding `√2·γ₂(1 + 2η)(1 + ρ)`:
//!
//!   `ρ' = ρ + 2η(1 + ρ) + √2·γ₂(1 + 2η)(1 + ρ)`.
//! * Slide by `q` along `z` (`|q| ≤ Q`, `q̂ = q(1 + θ)`): `p ← p + q·c₂`,
//!
//!   `π' = π + ρQ + uQ(1 + ρ) + γ₂(P + π + (1 + ρ)(1 + u)Q)`, `P' = P + Q`.
//! * A sphere centre `c` in a body's frame, placed as `p + R·ĉ`: within
//!   `√3·[π + ρ(1 + u)|c| + u|c| + γ₄(P + π + (1 + ρ)(1 + u)|c|)]` of the
//!   exact point (`√3`: from a bound per coordinate to a distance).
//!
//! To first order, with `n` joints before the body and `L = Σ|p_o| + |c|`
//! (the body's reach from the base): `ρ ≲ n(8.2u + 2η)`, and the centre
//! error is `≲ √3·(Σ_k ρ_k|p_o,k| + 5u·L + 4u·P)`, that is
//! `|error| ≤ c·ε_f32·(reach + max coordinate)` with `c` growing linearly
//! in the chain depth `n` (ε_f32 = 2u). [`Bound`] evaluates the recursion
//! itself, which is tighter than the closed form and as sound; a slack of
//! [`SLACK`] covers the `f64` arithmetic the bound and the layout are
//! computed in.

/// Unit roundoff of `f32`.
pub(crate) const U: f64 = f32::EPSILON as f64 / 2.0;
/// Added to every margin (m): the `f64` rounding of the layout itself.
pub(crate) const SLACK: f64 = 1e-9;

fn gamma(n: f64) -> f64 {
    n * U / (1.0 - n * U)
}

/// The error state of the module doc along a chain.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Bound {
    /// Rotation rows.
    pub rho: f64,
    /// Position coordinates (m).
    pub pi: f64,
    /// Largest position coordinate (m).
    pub reach: f64,
}

impl Bound {
    /// After a fixed origin whose offset has length `offset` (m).
    pub(crate) fn origin(self, offset: f64) -> Self {
        let Bound { rho, pi, reach } = self;
        Bound {
            rho: rho * (1.0 + 3.0 * U) + 3.0 * U + 3f64.sqrt() * gamma(3.0) * (1.0 + rho) * (1.0 + 3.0 * U),
            pi: pi
                + rho * (1.0 + U) * offset
                + U * offset
                + gamma(4.0) * (reach + pi + (1.0 + rho) * (1.0 + U) * offset),
            reach: reach + offset,
        }
    }

    /// After a turn whose sine and cosine are within `eta`.
    pub(crate) fn turn(self, eta: f64) -> Self {
        let rho = self.rho;
        Bound {
            rho: rho + 2.0 * eta * (1.0 + rho) + 2f64.sqrt() * gamma(2.0) * (1.0 + 2.0 * eta) * (1.0 + rho),
            ..self
        }
    }

    /// After a slide of at most `travel` (m).
    pub(crate) fn slide(self, travel: f64) -> Self {
        let Bound { rho, pi, reach } = self;
        Bound {
            rho,
            pi: pi
                + rho * travel
                + U * travel * (1.0 + rho)
                + gamma(2.0) * (reach + pi + (1.0 + rho) * (1.0 + U) * travel),
            reach: reach + travel,
        }
    }

    /// How far (m) a point at distance `c` from the frame's origin can be
    /// placed from its exact position.
    pub(crate) fn point(&self, c: f64) -> f64 {
        let Bound { rho, pi, reach } = *self;
        3f64.sqrt()
            * (pi + rho * (1.0 + U) * c + U * c + gamma(4.0) * (reach + pi + (1.0 + rho) * (1.0 + U) * c))
            + SLACK
    }
}
