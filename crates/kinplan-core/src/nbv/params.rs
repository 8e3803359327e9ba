//! Parameters of a next-best-view request, with units, defaults and validation.

use std::time::Duration;

use nalgebra::{Isometry3, Point3};

use super::{GainMethod, NbvError, VisibilityParams};
use crate::ik::IkParams;

/// Utility weights of `f = w_d·D + w_r·R + w_i·Ig` (S0 §4.4). Default S0's
/// IG1_T025_R01: `w_i = 1, w_d = 0.25, w_r = 0.1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// Weight of the information gain Ig (≥ 0).
    pub w_i: f64,
    /// Weight of the distance term D (≥ 0).
    pub w_d: f64,
    /// Weight of the rotation term R (≥ 0).
    pub w_r: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Self {
            w_i: 1.0,
            w_d: 0.25,
            w_r: 0.1,
        }
    }
}

/// Options of [`next_best_view`](super::next_best_view) (docs/exploration.md).
#[derive(Debug, Clone, PartialEq)]
pub struct NbvParams {
    /// Box searched for frontier cells (m, map frame); `None` = the known bounds of
    /// the tree. Default None.
    pub region: Option<(Point3<f64>, Point3<f64>)>,
    /// A free cell is a frontier when at least this share of its 26 neighbours is
    /// unknown (in (0, 1]). Default 0.25.
    pub frontier_unknown_ratio: f64,
    /// At most this many frontier cells become candidates (evenly spaced in key order;
    /// count, 0 = no frontier candidates). Default 1000.
    pub max_frontier_candidates: usize,
    /// Radius of the potential field around a frontier cell (m, > 0). Default 0.5.
    pub field_radius: f64,
    /// Distance from the frontier cell back along −F to the camera (m, ≥ 0; raised to
    /// the camera's near range). Default 1.0.
    pub standoff: f64,
    /// Extra candidate camera poses from the caller (optical frame → map), e.g. a view
    /// sphere. Default none.
    pub extra_candidates: Vec<Isometry3<f64>>,
    /// ORF: robot base pose in the map (m). Default identity.
    pub robot_base: Isometry3<f64>,
    /// ORF: candidates farther than this from the base are dropped (m, > 0; `None` =
    /// estimated from the robot's forward kinematics). Default None.
    pub reach: Option<f64>,
    /// ORF also drops a candidate whose camera position lies in an occupied
    /// cell, in an unknown cell inside `region`, or below `region` (the
    /// camera cannot stand in an obstacle nor in unseen space of the cell;
    /// unseen space around the cell, above its floor, is allowed, since the
    /// planner checks the way there). Default false.
    pub free_viewpoint: bool,
    /// PTF: a candidate closer than this to a kept one (m, ≥ 0)… Default 0.2.
    pub position_threshold: f64,
    /// … and whose view direction differs by less than this (rad, ≥ 0) is dropped.
    /// Default 0.35 (20°).
    pub orientation_threshold: f64,
    /// IGF: candidates with Ig below this are dropped (≥ 0). Default 0.01.
    pub gain_threshold: f64,
    /// Gain method. Default intersection (S0).
    pub gain: GainMethod,
    /// The intersection gain counts only unknown cells inside `region`
    /// (space beyond it, e.g. behind the room's walls, never becomes known
    /// and would lure views forever). Ray gains ignore it. Default false.
    pub gain_in_region: bool,
    pub weights: Weights,
    /// Occlusion-aware visibility check of the best candidates after the first ranking
    /// (docs/exploration.md#visibility-check): each checked view's rays are cast through
    /// the tree, views predicted to reveal fewer than `min_new_cells` cells are dropped,
    /// and the survivors are ranked again with `Ig = reached / max reached` (candidates
    /// beyond the checked ones are not returned). `None` = off. Default None.
    pub visibility: Option<VisibilityParams>,
    /// Scale the weights by the unknown share u of the region: `w_i·(0.5 + u)`,
    /// `w_d·(1.5 − u)`, `w_r·(1.5 − u)` (S0 future work; our rule). Default false.
    pub adaptive_weights: bool,
    /// Check this many best candidates by IK (count; 0 = no IK). Default 10.
    pub ik_check: usize,
    /// Camera pose on the chain tip (camera optical frame in the tip frame). Default identity.
    pub camera_mount: Isometry3<f64>,
    /// IK options for the reachability check. Default: IkParams with 20 restarts and a
    /// 20 ms budget per candidate.
    pub ik: IkParams,
    /// Keep IK failures in the ranking with a failure count and `f − failure_penalty ·
    /// failures` instead of dropping them (S0 future work). Default false.
    pub count_failures: bool,
    /// Utility subtracted per recorded failure (≥ 0). Default 0.2.
    pub failure_penalty: f64,
    /// Failures recorded by earlier calls: `(position m, count)`, matched to a
    /// candidate within `position_threshold`. Default none.
    pub prior_failures: Vec<(Point3<f64>, u32)>,
    /// Ranked candidates returned (count ≥ 1). Default 10.
    pub max_results: usize,
    /// Wall-clock budget of the whole request (s), from its start; `None` = none.
    /// The request stops at this budget or at the caller's
    /// [`Deadline`](crate::Deadline), whichever comes first. Default None.
    pub time_budget: Option<Duration>,
    /// Seed of the IK restarts. Default 0.
    pub seed: u64,
}

impl Default for NbvParams {
    fn default() -> Self {
        let ik = IkParams {
            max_restarts: 20,
            time_budget: Some(Duration::from_millis(20)),
            ..IkParams::default()
        };
        Self {
            region: None,
            frontier_unknown_ratio: 0.25,
            max_frontier_candidates: 1000,
            field_radius: 0.5,
            standoff: 1.0,
            extra_candidates: Vec::new(),
            robot_base: Isometry3::identity(),
            reach: None,
            free_viewpoint: false,
            position_threshold: 0.2,
            orientation_threshold: 0.35,
            gain_threshold: 0.01,
            gain: GainMethod::Intersection,
            gain_in_region: false,
            weights: Weights::default(),
            visibility: None,
            adaptive_weights: false,
            ik_check: 10,
            camera_mount: Isometry3::identity(),
            ik,
            count_failures: false,
            failure_penalty: 0.2,
            prior_failures: Vec::new(),
            max_results: 10,
            time_budget: None,
            seed: 0,
        }
    }
}

impl NbvParams {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), NbvError> {
        let bad = |field, value: f64, reason| Err(NbvError::InvalidParam { field, value, reason });
        let nonneg = |field, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                bad(field, v, "must be finite and ≥ 0")
            }
        };
        if !(self.frontier_unknown_ratio > 0.0 && self.frontier_unknown_ratio <= 1.0) {
            return bad(
                "frontier_unknown_ratio",
                self.frontier_unknown_ratio,
                "must lie in (0, 1]",
            );
        }
        if !(self.field_radius.is_finite() && self.field_radius > 0.0) {
            return bad("field_radius", self.field_radius, "must be finite and > 0");
        }
        nonneg("standoff", self.standoff)?;
        nonneg("position_threshold", self.position_threshold)?;
        nonneg("orientation_threshold", self.orientation_threshold)?;
        nonneg("gain_threshold", self.gain_threshold)?;
        nonneg("failure_penalty", self.failure_penalty)?;
        nonneg("w_i", self.weights.w_i)?;
        nonneg("w_d", self.weights.w_d)?;
        nonneg("w_r", self.weights.w_r)?;
        if let Some(r) = self.reach
            && !(r.is_finite() && r > 0.0)
        {
            return bad("reach", r, "must be finite and > 0");
        }
        if let Some(f) = self.gain.fraction()
            && !(f > 0.0 && f <= 1.0)
        {
            return bad("gain.fraction", f, "must lie in (0, 1]");
        }
        if self.max_results == 0 {
            return bad("max_results", 0.0, "must be at least 1");
        }
        if let Some((a, b)) = &self.region
            && (a.iter().chain(b.iter()).any(|v| !v.is_finite()) || (0..3).any(|i| a[i] > b[i]))
        {
            return bad("region", 0.0, "must be finite with min ≤ max");
        }
        let poses_ok = self
            .extra_candidates
            .iter()
            .chain([&self.robot_base, &self.camera_mount])
            .all(|p| {
                p.translation
                    .vector
                    .iter()
                    .chain(p.rotation.coords.iter())
                    .all(|v| v.is_finite())
            });
        if !poses_ok {
            return Err(NbvError::NonFinite { field: "pose" });
        }
        if let Some(v) = &self.visibility {
            v.validate()?;
        }
        self.ik.validate()?;
        Ok(())
    }
}
