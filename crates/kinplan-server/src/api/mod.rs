//! The gRPC handlers: one room per service of `proto/kinplan/v1`, each a
//! thin `mod.rs` (admit, convert, run on the CPU pool, reply) beside its
//! `convert.rs` (proto ↔ domain values). Uses `runtime` and `status`; the
//! transport puts the handlers behind a listener or calls them in process.

pub mod convert;
pub mod exploration;
pub mod fuzzing;
pub mod kinematics;
pub mod mobile;
pub mod planning;
pub mod robot;
pub mod scene;
pub mod scoring;

use crate::runtime::Shared;
use exploration::ExplorationApi;
use kinematics::KinematicsApi;
use mobile::MobileApi;
use planning::PlanningApi;
use robot::RobotApi;
use scoring::ScoringApi;

/// The six kinplan service adapters over one shared state, for callers that
/// invoke the handlers directly (the in-process backend's unary calls).
pub struct Apis {
    pub robot: RobotApi,
    pub scoring: ScoringApi,
    pub mobile: MobileApi,
    pub kinematics: KinematicsApi,
    pub planning: PlanningApi,
    pub exploration: ExplorationApi,
}

impl Apis {
    pub fn new(shared: &Shared) -> Apis {
        Apis {
            robot: RobotApi::new(shared.clone()),
            scoring: ScoringApi::new(shared.clone()),
            mobile: MobileApi::new(shared.clone()),
            kinematics: KinematicsApi::new(shared.clone()),
            planning: PlanningApi::new(shared.clone()),
            exploration: ExplorationApi::new(shared.clone()),
        }
    }
}
