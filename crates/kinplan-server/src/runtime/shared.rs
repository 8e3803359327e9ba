//! The state every service handler shares: the model cache, the CPU pool and
//! the collision models, and the first steps of every call about a robot.

use std::sync::Arc;

use tokio::sync::OwnedSemaphorePermit;

use super::collision_models::CollisionModels;
use super::models::Resolved;
use super::{Budget, Compute, ModelStore};
use crate::pb;

/// What every service handler shares: the model cache, the CPU pool and the
/// collision models.
#[derive(Clone)]
pub struct Shared {
    pub models: Arc<ModelStore>,
    pub compute: Arc<Compute>,
    pub collision: Arc<CollisionModels>,
}

impl Shared {
    /// The first steps of every call about a robot: admission (or shedding with
    /// RESOURCE_EXHAUSTED), the request's budget, and the robot it names, from the
    /// cache or parsed on the CPU pool. Hold the permit until the reply.
    pub async fn admit_robot<T: prost::Message>(
        &self,
        request: &tonic::Request<T>,
        robot: Option<&pb::RobotRef>,
    ) -> Result<(OwnedSemaphorePermit, Budget, Resolved), tonic::Status> {
        let (permit, budget) = self.compute.admit(request)?;
        let robot = self.models.resolve(robot, &self.compute, &budget).await?;
        Ok((permit, budget, robot))
    }
}
