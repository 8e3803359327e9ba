//! Sensor model and input limits of the octree, with OctoMap's defaults.

use super::OctreeError;
use super::key::logodds;

/// OctoMap's occupancy sensor model (docs/octree.md#values-and-updates; OctoMap's `OcTree` defaults).
/// Probabilities are stored as f32 log-odds `ln(p/(1−p))`, exactly as OctoMap stores
/// them, so updates round the same way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorModel {
    /// P(occupied | hit) (probability in (0.5, 1)). Default 0.7.
    pub prob_hit: f64,
    /// P(occupied | ray passed) (probability in (0, 0.5)). Default 0.4.
    pub prob_miss: f64,
    /// Lower clamp of a node's probability (in (0, 1)). Default 0.1192.
    pub clamp_min: f64,
    /// Upper clamp of a node's probability (in (clamp_min, 1)). Default 0.971.
    pub clamp_max: f64,
    /// A node is occupied when its probability is strictly above this (in (0, 1)). Default 0.5.
    pub occupancy_threshold: f64,
}

impl Default for SensorModel {
    fn default() -> Self {
        // OctoMap's OcTree constructor values; 0.1192 / 0.971 are the clamps the issue
        // rounds to 0.12 / 0.97.
        Self {
            prob_hit: 0.7,
            prob_miss: 0.4,
            clamp_min: 0.1192,
            clamp_max: 0.971,
            occupancy_threshold: 0.5,
        }
    }
}

impl SensorModel {
    /// Checks every probability lies in its open interval.
    pub fn validate(&self) -> Result<(), OctreeError> {
        let check = |field, v: f64, lo: f64, hi: f64, reason| {
            if v.is_finite() && v > lo && v < hi {
                Ok(())
            } else {
                Err(OctreeError::InvalidParam {
                    field,
                    value: v,
                    reason,
                })
            }
        };
        check("prob_hit", self.prob_hit, 0.5, 1.0, "must lie in (0.5, 1)")?;
        check("prob_miss", self.prob_miss, 0.0, 0.5, "must lie in (0, 0.5)")?;
        check("clamp_min", self.clamp_min, 0.0, 1.0, "must lie in (0, 1)")?;
        check(
            "clamp_max",
            self.clamp_max,
            self.clamp_min,
            1.0,
            "must lie in (clamp_min, 1)",
        )?;
        check(
            "occupancy_threshold",
            self.occupancy_threshold,
            0.0,
            1.0,
            "must lie in (0, 1)",
        )
    }

    /// The model as f32 log-odds.
    pub fn log_odds(&self) -> LogOddsModel {
        LogOddsModel {
            hit: logodds(self.prob_hit),
            miss: logodds(self.prob_miss),
            clamp_min: logodds(self.clamp_min),
            clamp_max: logodds(self.clamp_max),
            threshold: logodds(self.occupancy_threshold),
        }
    }
}

/// [`SensorModel`] in f32 log-odds, the form the tree uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogOddsModel {
    pub hit: f32,
    pub miss: f32,
    pub clamp_min: f32,
    pub clamp_max: f32,
    pub threshold: f32,
}

/// Limits on what a parser accepts from an untrusted byte stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OctreeLimits {
    /// Most nodes (inner and leaves) a tree may hold (count ≥ 1). Every node costs
    /// 8 bytes plus 68 bytes per inner node, so the default is about 1.5 GB worst
    /// case. Default 20,000,000.
    pub max_nodes: usize,
}

impl Default for OctreeLimits {
    fn default() -> Self {
        Self {
            max_nodes: 20_000_000,
        }
    }
}

impl OctreeLimits {
    /// Checks `max_nodes ≥ 1`.
    pub fn validate(&self) -> Result<(), OctreeError> {
        if self.max_nodes == 0 {
            return Err(OctreeError::InvalidParam {
                field: "max_nodes",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_octomaps_f32_log_odds() {
        // bit patterns of OctoMap 1.10's getProbHitLog / getProbMissLog /
        // getClampingThresMinLog / getClampingThresMaxLog as f32
        let m = SensorModel::default().log_odds();
        assert_eq!(m.hit.to_bits(), 0x3f58e883);
        assert_eq!(m.miss.to_bits(), 0xbecf991f);
        assert_eq!(m.clamp_min.to_bits(), 0xc0000075);
        assert_eq!(m.clamp_max.to_bits(), 0x4060b4ba);
        assert_eq!(m.threshold, 0.0);
    }

    #[test]
    fn bad_models_are_refused() {
        let m = SensorModel {
            prob_hit: 0.4,
            ..Default::default()
        };
        assert!(matches!(
            m.validate(),
            Err(OctreeError::InvalidParam {
                field: "prob_hit",
                ..
            })
        ));
        let m = SensorModel {
            clamp_max: 0.1,
            ..Default::default()
        };
        assert!(m.validate().is_err());
        assert!(OctreeLimits { max_nodes: 0 }.validate().is_err());
    }
}
