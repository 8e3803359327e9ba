//! Parameters of an exploration run, with units, defaults and validation.

use std::time::Duration;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use super::{ExploreError, ExploreField, SensorParams};
use crate::nbv::{CameraModel, NbvParams, VisibilityParams};
use crate::plan::{Algorithm, PlanRequest};

/// Most cells a region may hold (each iteration looks every one up).
pub const MAX_REGION_CELLS: usize = 1 << 20;
/// Most rays one rendered image may cast (`⌈width/stride⌉·⌈height/stride⌉`):
/// the image, its points and their beams grow with it.
pub const MAX_RAYS_PER_IMAGE: usize = 1 << 20;

/// When the loop stops (whichever comes first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopRule {
    /// Share of the region's observable cells known (free or occupied) at
    /// which the exploration is complete (in (0, 1]). Default 0.95.
    pub known_ratio: f64,
    /// Iterations at most (count ≥ 1). Default 40.
    pub max_iterations: usize,
    /// Iterations in a row without a successful motion at most (count ≥ 1).
    /// Default 4.
    pub max_consecutive_failures: usize,
}

impl Default for StopRule {
    fn default() -> Self {
        StopRule {
            known_ratio: 0.95,
            max_iterations: 40,
            max_consecutive_failures: 4,
        }
    }
}

/// Options of [`explore`](super::explore) (docs/exploration.md#the-exploration-loop, S0 §4–5). The
/// world frame is the robot's base frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ExploreParams {
    /// The box explored (m): NBV searches it for frontiers, the known ratio
    /// counts its cells, and the planner avoids the occupied cells inside it.
    pub region: (Point3<f64>, Point3<f64>),
    /// Octree resolution (m, in [0.01, 1]). Default 0.1.
    pub resolution: f64,
    pub camera: CameraModel,
    /// Camera optical frame in the chain's tip frame. Default: 5 cm along
    /// the tip's z axis, turned −90° about it, so a tip whose x axis points
    /// down (ROS-Industrial's tool0 on a level arm) gives an upright image.
    pub camera_mount: Isometry3<f64>,
    pub sensor: SensorParams,
    /// Next-best-view options. The loop sets `region`, `robot_base`,
    /// `camera_mount`, `count_failures`, `prior_failures`, `max_results`,
    /// `visibility` (from [`ExploreParams::visibility`]) and `seed` itself; the rest (weights, filters, gain method, IK) is
    /// taken from here.
    pub nbv: NbvParams,
    /// Planner and its options. The loop sets `start`, `goal` and `seed`.
    /// Default CCSTOMP with the defaults of [`PlanRequest`].
    pub plan: PlanRequest,
    /// Wall-clock budget of one planning call (m, > 0). Default 2 s.
    pub plan_time_budget: Duration,
    /// Ranked views tried per iteration, best first, until one is reached
    /// (count ≥ 1); each that fails IK or planning is recorded as a failure
    /// at its position and lowers its utility in later iterations (S0's
    /// future work). Default 5.
    pub candidates_per_iteration: usize,
    /// Camera poses (optical frame, world) offered to NBV beside the
    /// frontier candidates in every iteration; they pass the same filters
    /// and gain. Frontier views sit a stand-off from the frontier, often
    /// inside clutter a large arm cannot enter; these stand in the free
    /// band between the robot and the region. Default
    /// [`ExploreParams::approach_views`] of the region.
    pub extra_views: Vec<Isometry3<f64>>,
    /// Joint offsets (rad, one vector of `dof` values each) visited from the
    /// start before the first iteration, scanning at each (S0 §4: an
    /// initial motion of the last joints only). Offsets that would put the
    /// robot in collision or outside its limits are skipped. Default:
    /// [`ExploreParams::wrist_sweep`] for a 6-joint arm.
    pub initial_offsets: Vec<Vec<f64>>,
    pub stop: StopRule,
    /// The visibility check NBV runs on its best views before any is tried
    /// (docs/exploration.md#visibility-check): a view whose rays, cast
    /// through the octree, reach fewer than `min_new_cells` unknown region
    /// cells first is never executed, and the loop stops as
    /// `ObservableExhausted` once every candidate is predicted below it.
    /// `None`: S0's occlusion-blind choice (a view is judged only after the
    /// arm went there). Default: [`VisibilityParams::default`] (its pixel
    /// stride 8 is twice the sensor's default 4, so every predicted ray is
    /// one the sensor casts).
    pub visibility: Option<VisibilityParams>,
    /// Seeds the NBV IK restarts, the planner and the sensor noise.
    pub seed: u64,
}

impl ExploreParams {
    /// Offsets of the last three joints of a 6-joint arm: ±0.5 rad on joint
    /// 5 (pitch) and ±0.6 rad on joint 4 (roll), then back to the start.
    pub fn wrist_sweep(dof: usize) -> Vec<Vec<f64>> {
        if dof < 3 {
            return Vec::new();
        }
        let offset = |j: usize, v: f64| {
            let mut o = vec![0.0; dof];
            o[j] = v;
            o
        };
        vec![
            offset(dof - 2, 0.5),
            offset(dof - 2, -0.5),
            offset(dof - 3, 0.6),
            offset(dof - 3, -0.6),
        ]
    }

    /// Views from before and above the region's near (−x) face: camera
    /// positions 0.8 m and 0.4 m before it and a quarter of the way into it,
    /// at five evenly spaced y across the region and at three heights (the
    /// region's middle, 0.3 m and 0.7 m above its top), each aimed at six
    /// points: y at ¼, ½, ¾ of the region on its mid-height line and on a
    /// line 15 % above its floor (through the middle of its x range) — 270
    /// poses. Views from above let the camera look over a wall into the cell.
    pub fn approach_views(region: &(Point3<f64>, Point3<f64>)) -> Vec<Isometry3<f64>> {
        let (a, b) = region;
        let mid_z = 0.5 * (a.z + b.z);
        let low_z = a.z + 0.15 * (b.z - a.z);
        let mid_x = 0.5 * (a.x + b.x);
        let mut out = Vec::with_capacity(270);
        for x in [a.x - 0.8, a.x - 0.4, a.x + 0.25 * (b.x - a.x)] {
            for k in 0..5 {
                let y = a.y + (b.y - a.y) * (k as f64 + 0.5) / 5.0;
                for z in [mid_z, b.z + 0.3, b.z + 0.7] {
                    let p = Point3::new(x, y, z);
                    for aim_z in [mid_z, low_z] {
                        for t in [0.25, 0.5, 0.75] {
                            let aim = Point3::new(mid_x, a.y + (b.y - a.y) * t, aim_z);
                            out.extend(crate::nbv::look_along(&p, &(aim - p)));
                        }
                    }
                }
            }
        }
        out
    }

    /// Defaults for a region and a robot with `dof` joints.
    pub fn new(region: (Point3<f64>, Point3<f64>), dof: usize) -> Self {
        ExploreParams {
            region,
            resolution: 0.1,
            camera: CameraModel::default(),
            camera_mount: Isometry3::from_parts(
                Translation3::new(0.0, 0.0, 0.05),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -std::f64::consts::FRAC_PI_2),
            ),
            sensor: SensorParams::default(),
            nbv: NbvParams::default(),
            plan: PlanRequest {
                algorithm: Algorithm::Ccstomp,
                ..PlanRequest::default()
            },
            plan_time_budget: Duration::from_secs(2),
            candidates_per_iteration: 5,
            extra_views: Self::approach_views(&region),
            initial_offsets: Self::wrist_sweep(dof),
            stop: StopRule::default(),
            visibility: Some(VisibilityParams::default()),
            seed: 0,
        }
    }

    /// Checks the ranges given in the field docs (the NBV and planner
    /// options are checked by their own rooms).
    pub fn validate(&self, dof: usize) -> Result<(), ExploreError> {
        use ExploreField as F;
        let bad = |f, r: &str| Err(ExploreError::invalid(f, r));
        let (a, b) = &self.region;
        if a.iter()
            .chain(b.iter())
            .any(|v| !v.is_finite() || v.abs() > 1.0e3)
        {
            return bad(F::Region, "corners must be finite and within ±1000 m");
        }
        if (0..3).any(|i| a[i] >= b[i]) {
            return bad(F::Region, "min must be below max on every axis");
        }
        if !(self.resolution >= 0.01 && self.resolution <= 1.0) {
            return bad(F::Resolution, "must lie in [0.01, 1] m");
        }
        let cells = (0..3)
            .map(|i| ((b[i] - a[i]) / self.resolution).ceil())
            .product::<f64>();
        // every iteration looks each region cell up (known ratio)
        if cells > MAX_REGION_CELLS as f64 {
            return bad(F::Region, "holds more than 1 million cells at this resolution");
        }
        let m = &self.camera_mount;
        if m.translation
            .vector
            .iter()
            .chain(m.rotation.coords.iter())
            .any(|v| !v.is_finite())
        {
            return bad(F::CameraMount, "must be finite");
        }
        if self.sensor.pixel_stride == 0 || self.sensor.pixel_stride > 64 {
            return bad(F::PixelStride, "must lie in [1, 64]");
        }
        let stride = self.sensor.pixel_stride.max(1);
        let rays = self.camera.width.div_ceil(stride) * self.camera.height.div_ceil(stride);
        if rays > MAX_RAYS_PER_IMAGE {
            return bad(
                F::PixelStride,
                "more than 2^20 rays per image: raise the stride or lower the image size",
            );
        }
        if !(self.sensor.noise_stddev.is_finite() && self.sensor.noise_stddev >= 0.0) {
            return bad(F::NoiseStddev, "must be finite and ≥ 0");
        }
        if !(0.0..=1.0).contains(&self.sensor.near_ray_spacing) {
            return bad(F::NearRaySpacing, "must lie in [0, 1] cells");
        }
        if !(self.stop.known_ratio > 0.0 && self.stop.known_ratio <= 1.0) {
            return bad(F::KnownRatio, "must lie in (0, 1]");
        }
        if self.stop.max_iterations == 0 || self.stop.max_iterations > 10_000 {
            return bad(F::MaxIterations, "must lie in [1, 10000]");
        }
        if self.stop.max_consecutive_failures == 0 {
            return bad(F::ConsecutiveFailures, "must be ≥ 1");
        }
        if self.candidates_per_iteration == 0 || self.candidates_per_iteration > 100 {
            return bad(F::CandidatesPerIteration, "must lie in [1, 100]");
        }
        if self.plan_time_budget.is_zero() {
            return bad(F::PlanTimeBudget, "must be > 0");
        }
        if self.extra_views.len() > 10_000 {
            return bad(F::ExtraViews, "at most 10000 views");
        }
        if self.initial_offsets.len() > 64 {
            return bad(F::InitialOffsets, "at most 64 offsets");
        }
        if self
            .initial_offsets
            .iter()
            .any(|o| o.len() != dof || o.iter().any(|v| !v.is_finite()))
        {
            return bad(F::InitialOffsets, "each offset needs one finite value per joint");
        }
        self.camera.validate()?;
        self.nbv.validate()?;
        if let Some(v) = &self.visibility {
            v.validate()?;
        }
        Ok(())
    }
}
