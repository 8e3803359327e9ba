//! Options of the analytic solvers, with units, defaults and validation.

use super::super::{IkError, IkParam};

/// Which whole-turn variants of a wide-range joint's angle are returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Turns {
    /// Every `q + 2πk` inside the limits (at most [`MAX_TURNS`](super::MAX_TURNS)
    /// per joint, nearest zero first); a continuous joint gives its value in (−π, π].
    #[default]
    All,
    /// Only the variant nearest the seed (or zero without a seed).
    NearestSeed,
}

/// Options of [`AnalyticArm`](super::AnalyticArm) analysis and solving.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalyticParams {
    /// Two axes are parallel when `‖hᵢ × hⱼ‖ ≤` this (rad), and lines meet when
    /// their distance is `≤` this (m, scaled by 1 m). Default 1e-9.
    pub geometry_tolerance: f64,
    /// A subproblem answer is exact when its residual is `≤` this (m for
    /// positions, dimensionless for unit directions). Default 1e-9.
    pub solve_tolerance: f64,
    /// Whole-turn variants returned. Default all.
    pub turns: Turns,
    /// Rank solutions with the seed's configuration flags first (then by distance
    /// to the seed), so a stream keeps one configuration. Default false: by
    /// distance only.
    pub hold_configuration: bool,
    /// 7-joint chains: the joint (0-based chain index) held at the seed's value
    /// so that the other six are solved in closed form; `None` = the first of
    /// joints 3, 4, 5, 7, 1, 2, 6 that leaves a covered arm. Default none.
    pub redundant_joint: Option<usize>,
    /// 7-joint chains: false = the held joint takes the seed's value; true =
    /// its value is searched for the solution nearest the seed (see
    /// `search_held`: samples across its limits, then Brent's minimiser), and
    /// every solution at the value found is returned. Default false.
    pub search_redundant: bool,
    /// Evenly spaced held values (count, ≥ 2) the search starts from; the
    /// search can miss a nearer solution only in a gap between two samples.
    /// Default 24.
    pub redundant_samples: usize,
    /// 6-joint arms of the searched family (`searched_6r`): evenly spaced
    /// values (count, ≥ 8) of the searched joint over its circle at which
    /// the residual is sampled; a solution is missed only where two of one
    /// branch lie within `2π/search_samples` rad of each other in that joint
    /// (or at a tangent zero). Default 128.
    pub search_samples: usize,
}

impl Default for AnalyticParams {
    fn default() -> Self {
        Self {
            geometry_tolerance: 1e-9,
            solve_tolerance: 1e-9,
            turns: Turns::All,
            hold_configuration: false,
            redundant_joint: None,
            search_redundant: false,
            redundant_samples: 24,
            search_samples: 128,
        }
    }
}

impl AnalyticParams {
    /// Rejects non-finite or non-positive tolerances, naming the field.
    pub fn validate(&self) -> Result<(), IkError> {
        for (field, value) in [
            (IkParam::GeometryTolerance, self.geometry_tolerance),
            (IkParam::SolveTolerance, self.solve_tolerance),
        ] {
            if !(value.is_finite() && value > 0.0 && value < 1.0) {
                return Err(IkError::InvalidParam {
                    field,
                    value,
                    reason: "must be finite, > 0 and < 1",
                });
            }
        }
        if !(2..=MAX_SAMPLES).contains(&self.redundant_samples) {
            return Err(IkError::InvalidParam {
                field: IkParam::RedundantSamples,
                value: self.redundant_samples as f64,
                reason: "must be at least 2 and at most 4096",
            });
        }
        if !(8..=MAX_SAMPLES).contains(&self.search_samples) {
            return Err(IkError::InvalidParam {
                field: IkParam::SearchSamples,
                value: self.search_samples as f64,
                reason: "must be at least 8 and at most 4096",
            });
        }
        Ok(())
    }
}

/// Most held values [`AnalyticParams::redundant_samples`] may ask for.
pub const MAX_SAMPLES: usize = 4096;
