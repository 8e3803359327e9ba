//! Planning: obstacles, goals, the `Plan` and `CheckState` calls.

use std::collections::HashMap;
use std::time::Duration;

use nalgebra::{DMatrix, DVector, Isometry3, Point3, Vector3};

use crate::convert::{pose_to_proto, vec3_to_proto};
use crate::error::Result;
use crate::pb::{self, planning_service_client::PlanningServiceClient};
use crate::robot::Robot;

/// An obstacle's geometry, in its own frame (metres).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Full edge lengths along x, y, z.
    Box {
        size: Vector3<f64>,
    },
    Sphere {
        radius: f64,
    },
    /// Along z, centred.
    Cylinder {
        radius: f64,
        length: f64,
    },
    /// Along z, `length` between the cap centres, centred.
    Capsule {
        radius: f64,
        length: f64,
    },
    /// Vertices and triangles (three vertex indices each).
    Mesh {
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
    },
}

/// An obstacle placed in the robot's base frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    pub id: String,
    pub pose: Isometry3<f64>,
    pub shape: Shape,
}

impl Obstacle {
    pub fn new(id: &str, pose: Isometry3<f64>, shape: Shape) -> Obstacle {
        Obstacle {
            id: id.to_owned(),
            pose,
            shape,
        }
    }

    fn to_proto(&self) -> pb::CollisionObject {
        use pb::collision_object::Shape as S;
        let shape = match &self.shape {
            Shape::Box { size } => S::Box(pb::Box {
                size: Some(vec3_to_proto(size)),
            }),
            Shape::Sphere { radius } => S::Sphere(pb::Sphere { radius: *radius }),
            Shape::Cylinder { radius, length } => S::Cylinder(pb::Cylinder {
                radius: *radius,
                length: *length,
            }),
            Shape::Capsule { radius, length } => S::Capsule(pb::Capsule {
                radius: *radius,
                length: *length,
            }),
            Shape::Mesh { vertices, triangles } => S::Mesh(pb::TriangleMesh {
                vertices: vertices.iter().map(|v| vec3_to_proto(&v.coords)).collect(),
                indices: triangles.iter().flatten().copied().collect(),
            }),
        };
        pb::CollisionObject {
            id: self.id.clone(),
            pose: Some(pose_to_proto(&self.pose)),
            shape: Some(shape),
            unknown_as_obstacle: false,
        }
    }
}

fn scene_to_proto(scene: &[Obstacle]) -> pb::Scene {
    pb::Scene {
        objects: scene.iter().map(Obstacle::to_proto).collect(),
    }
}

/// Where a plan ends.
#[derive(Clone, Debug, PartialEq)]
pub enum Goal {
    /// Joint positions, chain order.
    Joints(DVector<f64>),
    /// A tool pose in the base frame: the server picks the valid IK solution
    /// nearest the start.
    Pose(Isometry3<f64>),
}

/// Planner (docs/planning.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Algorithm {
    #[default]
    RrtConnect,
    Stomp,
    /// STOMP with S0's Cartesian noise and Cartesian distance cost.
    Ccstomp,
}

/// What to plan with. `options` carries every tunable the contract has
/// (STOMP, CCSTOMP, RRT-Connect, timing); its unset fields take the server's defaults.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlanSettings {
    pub algorithm: Algorithm,
    /// Seed of every random choice: the same request gives the same plan.
    pub seed: u64,
    /// Planning budget; unset: the call's deadline less a reply margin.
    pub time_budget: Option<Duration>,
    pub options: pb::PlanOptions,
}

/// How a plan ended.
pub use pb::PlanStatus;

/// A planned, timed trajectory and how it ended.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    pub status: PlanStatus,
    pub message: String,
    /// Collision-free (and within the Cartesian tolerances for CCSTOMP).
    pub valid: bool,
    /// Waypoints × joints (rad, m for prismatic joints); 0 rows when nothing was found.
    pub positions: DMatrix<f64>,
    /// Time of each waypoint from the start, seconds.
    pub times: Vec<f64>,
    /// "link:object" / "link:link" pairs for an invalid start or goal.
    pub colliding: Vec<String>,
    /// S0 criteria of the trajectory ("CD" m, "JD" rad, "OC" rad, …, "cycle_time" s).
    pub criteria: HashMap<String, f64>,
    /// The goal joints used (the chosen IK solution for a pose goal).
    pub goal: DVector<f64>,
}

/// Validity and clearance of one joint state.
#[derive(Clone, Debug, PartialEq)]
pub struct StateCheck {
    pub valid: bool,
    pub within_limits: bool,
    /// Smallest signed distance to an obstacle or a non-adjacent link, metres
    /// (negative: penetration), capped at the request's maximum (1 m).
    pub clearance: f64,
    pub colliding: Vec<String>,
}

impl Robot {
    /// A collision-free timed trajectory from `start` to `goal` among `scene`.
    /// Planning failures are statuses of the answer; only malformed input is an error.
    pub async fn plan(
        &self,
        start: &[f64],
        goal: &Goal,
        scene: &[Obstacle],
        settings: &PlanSettings,
    ) -> Result<Plan> {
        use pb::plan_request::Goal as G;
        let goal = match goal {
            Goal::Joints(q) => G::GoalJoints(pb::JointState {
                positions: q.iter().copied().collect(),
            }),
            Goal::Pose(pose) => G::GoalPose(pose_to_proto(pose)),
        };
        let algorithm = match settings.algorithm {
            Algorithm::RrtConnect => pb::PlanAlgorithm::RrtConnect,
            Algorithm::Stomp => pb::PlanAlgorithm::Stomp,
            Algorithm::Ccstomp => pb::PlanAlgorithm::Ccstomp,
        };
        let mut options = settings.options.clone();
        if let Some(budget) = settings.time_budget {
            options.time_budget = Some(budget.as_secs_f64());
        }
        let scene = scene_to_proto(scene);
        let r = self
            .call(
                |robot| pb::PlanRequest {
                    robot: Some(robot),
                    start: start.to_vec(),
                    goal: Some(goal.clone()),
                    scene: Some(scene.clone()),
                    algorithm: algorithm as i32,
                    options: Some(options.clone()),
                    seed: settings.seed,
                },
                |ch, req| async move { PlanningServiceClient::new(ch).plan(req).await },
                |_| &[],
            )
            .await?;
        let status = r.status();
        let points = r.trajectory.map(|t| t.points).unwrap_or_default();
        let dof = points.first().map_or(0, |p| p.positions.len());
        Ok(Plan {
            status,
            valid: r.valid,
            positions: DMatrix::from_row_iterator(
                points.len(),
                dof,
                points.iter().flat_map(|p| p.positions.iter().copied()),
            ),
            times: points.iter().map(|p| p.time_from_start).collect(),
            message: r.message,
            colliding: r.colliding,
            criteria: r.criteria,
            goal: DVector::from_vec(r.goal),
        })
    }

    /// Validity and clearance of each state among `scene`.
    pub async fn check_states(&self, states: &[DVector<f64>], scene: &[Obstacle]) -> Result<Vec<StateCheck>> {
        let scene = scene_to_proto(scene);
        let states: Vec<pb::JointState> = states
            .iter()
            .map(|q| pb::JointState {
                positions: q.iter().copied().collect(),
            })
            .collect();
        let r = self
            .call(
                |robot| pb::CheckStateRequest {
                    robot: Some(robot),
                    states: states.clone(),
                    scene: Some(scene.clone()),
                    max_distance: None,
                },
                |ch, req| async move { PlanningServiceClient::new(ch).check_state(req).await },
                |_| &[],
            )
            .await?;
        Ok(r.states
            .into_iter()
            .map(|s| StateCheck {
                valid: s.valid,
                within_limits: s.within_limits,
                clearance: s.clearance,
                colliding: s.colliding,
            })
            .collect())
    }
}
