//! Parameters of the planners, with units, cited defaults and validation.

use super::error::{PlanError, PlanField, require};

/// Where STOMP starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InitialTrajectory {
    /// The algorithm's own start: [`Self::CartesianLine`] for CCSTOMP (its
    /// cost is measured against that line; on S0 §3.3 it succeeds far more
    /// often than the RRT-Connect start, `benches/RESULTS.md`),
    /// [`Self::RrtConnectIfBlocked`] for STOMP.
    #[default]
    ForAlgorithm,
    /// The straight joint-space line from start to goal (MoveIt's STOMP).
    StraightLine,
    /// The straight line when it is valid, otherwise an RRT-Connect path
    /// (shortcut, resampled to the timesteps); the line again if RRT-Connect
    /// finds nothing within its sample budget.
    RrtConnectIfBlocked,
    /// The tool's straight Cartesian line (lerp/slerp between the end poses)
    /// solved by IK waypoint after waypoint, warm-started, when that succeeds
    /// without a branch jump (> 0.5 rad) and is valid. For CCSTOMP, when it is
    /// blocked: a Cartesian detour inside the tolerance tube at the slerped
    /// orientation (smooth detours, then a ladder graph), else RRT-Connect's
    /// path projected into the tube (docs/planning.md#ccstomps-start-inside-the-tube).
    /// For STOMP, when blocked: as `RrtConnectIfBlocked`. Suits CCSTOMP, whose
    /// cost is measured against that line.
    CartesianLine,
}

impl InitialTrajectory {
    /// The start `algorithm` uses ([`Self::ForAlgorithm`] resolved).
    pub fn for_algorithm(self, algorithm: super::Algorithm) -> InitialTrajectory {
        match (self, algorithm) {
            (InitialTrajectory::ForAlgorithm, super::Algorithm::Ccstomp) => InitialTrajectory::CartesianLine,
            (InitialTrajectory::ForAlgorithm, _) => InitialTrajectory::RrtConnectIfBlocked,
            (chosen, _) => chosen,
        }
    }
}

/// Options of STOMP (docs/planning.md#stomp). Defaults follow MoveIt 2's STOMP
/// plugin (40 timesteps, 15 rollouts, 25 kept at most, sensitivity 0.5,
/// control-cost weight 0.1, 50 iterations).
#[derive(Debug, Clone, PartialEq)]
pub struct StompParams {
    /// Waypoints N of the trajectory, start and goal included (≥ 3). Default 40.
    pub timesteps: usize,
    /// New noisy rollouts K per iteration (≥ 1). Default 15.
    pub rollouts: usize,
    /// Rollouts per iteration including the best earlier ones reused
    /// (≥ `rollouts`). Default 25.
    pub max_rollouts: usize,
    /// Iteration cap (≥ 1). Default 50.
    pub max_iterations: usize,
    /// Iterations run after the first valid trajectory (≥ 0). Default 5.
    pub iterations_after_valid: usize,
    /// Joint-space noise σ_d per joint (rad or m, > 0); one value applies to
    /// every joint. Default `[0.2]`.
    pub noise_stddev: Vec<f64>,
    /// Cost sensitivity h of `exp(−h·(S − min S)/(max S − min S))` (> 0). Default 0.5.
    pub cost_sensitivity: f64,
    /// Weight of the control (acceleration) cost ½·θᵀRθ (≥ 0). Default 0.1.
    pub control_cost_weight: f64,
    /// Cost of a waypoint whose state or adjacent motion collides (≥ 0). Default 1.
    pub collision_penalty: f64,
    /// Half-width (waypoints) of the Epanechnikov window the collision
    /// penalty is smoothed over. Default 2.
    pub kernel_half_width: usize,
    /// d_max of the distance cost `(d_max − d)/d_max` (m, > 0). Default 0.1.
    pub clearance_distance: f64,
    /// Weight of the distance cost (≥ 0; 0 skips the clearance queries). Default 1.
    pub clearance_weight: f64,
    /// Cost per rad (or m) beyond a joint limit (≥ 0). Default 10.
    pub joint_limit_weight: f64,
    /// How the first trajectory is made. Default [`InitialTrajectory::ForAlgorithm`].
    pub initial: InitialTrajectory,
}

impl Default for StompParams {
    fn default() -> Self {
        Self {
            timesteps: 40,
            rollouts: 15,
            max_rollouts: 25,
            max_iterations: 50,
            iterations_after_valid: 5,
            noise_stddev: vec![0.2],
            cost_sensitivity: 0.5,
            control_cost_weight: 0.1,
            collision_penalty: 1.0,
            kernel_half_width: 2,
            clearance_distance: 0.1,
            clearance_weight: 1.0,
            joint_limit_weight: 10.0,
            initial: InitialTrajectory::default(),
        }
    }
}

impl StompParams {
    /// Checks every range; `dof` sizes the noise vector (1 or `dof` values).
    pub fn validate(&self, dof: usize) -> Result<(), PlanError> {
        use PlanField as F;
        let n = self.timesteps;
        require(
            (3..=10_000).contains(&n),
            F::Timesteps,
            n as f64,
            "must be in 3..=10000",
        )?;
        require(
            (1..=10_000).contains(&self.rollouts),
            F::Rollouts,
            self.rollouts as f64,
            "must be in 1..=10000",
        )?;
        require(
            self.max_rollouts >= self.rollouts && self.max_rollouts <= 10_000,
            F::MaxRollouts,
            self.max_rollouts as f64,
            "must be >= rollouts and <= 10000",
        )?;
        require(self.max_iterations >= 1, F::MaxIterations, 0.0, "must be >= 1")?;
        require(
            self.noise_stddev.len() == 1 || self.noise_stddev.len() == dof,
            F::NoiseStddev,
            self.noise_stddev.len() as f64,
            "needs 1 or dof values",
        )?;
        for &s in &self.noise_stddev {
            require(
                s.is_finite() && s > 0.0,
                F::NoiseStddev,
                s,
                "must be finite and > 0",
            )?;
        }
        let h = self.cost_sensitivity;
        require(
            h.is_finite() && h > 0.0,
            F::CostSensitivity,
            h,
            "must be finite and > 0",
        )?;
        for (field, v) in [
            (F::ControlCostWeight, self.control_cost_weight),
            (F::CollisionPenalty, self.collision_penalty),
            (F::ClearanceWeight, self.clearance_weight),
            (F::JointLimitWeight, self.joint_limit_weight),
        ] {
            require(v.is_finite() && v >= 0.0, field, v, "must be finite and >= 0")?;
        }
        let d = self.clearance_distance;
        require(
            d.is_finite() && d > 0.0,
            F::ClearanceDistance,
            d,
            "must be finite and > 0",
        )?;
        require(
            self.kernel_half_width <= n,
            F::KernelHalfWidth,
            self.kernel_half_width as f64,
            "must be <= timesteps",
        )
    }

    /// σ of joint `j`.
    pub(crate) fn stddev(&self, j: usize) -> f64 {
        if self.noise_stddev.len() == 1 {
            self.noise_stddev[0]
        } else {
            self.noise_stddev[j]
        }
    }
}

/// Options of the two CCSTOMP extensions (docs/planning.md#ccstomp, S0 §3.1–3.2).
/// Defaults are S0 §3.3's experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CartesianParams {
    /// Tolerance t_t on the tool's distance from the straight line (m, > 0). Default 1.
    pub translation_tolerance: f64,
    /// Tolerance t_r on the tool's rotation from the slerped orientation (rad, > 0). Default 0.2.
    pub rotation_tolerance: f64,
    /// Weight w_t (≥ 0). Default 1.
    pub translation_weight: f64,
    /// Weight w_r (≥ 0). Default 1.
    pub rotation_weight: f64,
    /// σ of r1, r2, r3 — translation noise along the tool axes (m, > 0). Default 0.5.
    pub translation_stddev: f64,
    /// σ of r4, r5, r6 — rotation noise about the tool axes (rad, > 0). Default 0.1.
    pub rotation_stddev: f64,
    /// Levenberg–Marquardt iterations of the warm-started IK per sample (≥ 1). Default 30.
    pub ik_iterations: usize,
    /// Extra cost per waypoint beyond a tolerance (≥ 0), so violating
    /// rollouts rank below compliant ones. Default 10.
    pub violation_penalty: f64,
}

impl Default for CartesianParams {
    fn default() -> Self {
        Self {
            translation_tolerance: 1.0,
            rotation_tolerance: 0.2,
            translation_weight: 1.0,
            rotation_weight: 1.0,
            translation_stddev: 0.5,
            rotation_stddev: 0.1,
            ik_iterations: 30,
            violation_penalty: 10.0,
        }
    }
}

impl CartesianParams {
    /// Checks every range.
    pub fn validate(&self) -> Result<(), PlanError> {
        use PlanField as F;
        for (field, v) in [
            (F::TranslationTolerance, self.translation_tolerance),
            (F::RotationTolerance, self.rotation_tolerance),
            (F::TranslationStddev, self.translation_stddev),
            (F::RotationStddev, self.rotation_stddev),
        ] {
            require(v.is_finite() && v > 0.0, field, v, "must be finite and > 0")?;
        }
        for (field, v) in [
            (F::TranslationWeight, self.translation_weight),
            (F::RotationWeight, self.rotation_weight),
            (F::ViolationPenalty, self.violation_penalty),
        ] {
            require(v.is_finite() && v >= 0.0, field, v, "must be finite and >= 0")?;
        }
        require(
            (1..=10_000).contains(&self.ik_iterations),
            F::IkIterations,
            self.ik_iterations as f64,
            "must be in 1..=10000",
        )
    }
}

/// Options of RRT-Connect and its shortcutting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrtParams {
    /// Longest extension step, Euclidean in joint space (rad or m, > 0). Default 1.0.
    pub range: f64,
    /// Random samples before giving up (≥ 1). Default 100 000.
    pub max_samples: usize,
    /// Random shortcut attempts after the greedy vertex pass (≥ 0). Default
    /// 100. Each draws a stretch of at most a third of the path's length and
    /// replaces it by the chord between its ends when that is valid; an
    /// attempt whose chord would shorten the path by at most 0.01 rad (or m)
    /// costs no check (docs/planning.md#rrt-connect).
    pub shortcut_attempts: usize,
    /// Resolution (rad or m, in (0, 1]) at which shortcutting checks the
    /// motions it tries, when finer than the checker's; `None` (default):
    /// the checker's. Shortcuts pull the path against obstacles, so a finer
    /// check here removes most grazing contacts a later, finer re-check would
    /// find, without slowing the search.
    pub shortcut_resolution: Option<f64>,
}

impl Default for RrtParams {
    fn default() -> Self {
        Self {
            range: 1.0,
            max_samples: 100_000,
            shortcut_attempts: 100,
            shortcut_resolution: None,
        }
    }
}

impl RrtParams {
    /// Checks every range.
    pub fn validate(&self) -> Result<(), PlanError> {
        require(
            self.range.is_finite() && self.range > 0.0,
            PlanField::RrtRange,
            self.range,
            "must be finite and > 0",
        )?;
        require(
            self.max_samples >= 1,
            PlanField::RrtMaxSamples,
            0.0,
            "must be >= 1",
        )?;
        require(
            self.shortcut_attempts <= 1_000_000,
            PlanField::ShortcutAttempts,
            self.shortcut_attempts as f64,
            "must be <= 1e6",
        )?;
        match self.shortcut_resolution {
            Some(r) => require(
                r.is_finite() && r > 0.0 && r <= 1.0,
                PlanField::ShortcutResolution,
                r,
                "must be in (0, 1]",
            ),
            None => Ok(()),
        }
    }
}
