//! A robot on a server: which model (built-in name or inline URDF), which
//! chain, and the content hash an inline URDF is referred to by after the
//! first call. Forward kinematics and Jacobians live here; IK in `ik.rs`,
//! planning in `plan.rs`.

use std::future::Future;
use std::sync::{Arc, Mutex};

use nalgebra::{DMatrix, DVector, Isometry3};
use tonic::transport::Channel;

use crate::client::Client;
use crate::convert::{matrix_from_proto, pose_from_proto, states_to_proto};
use crate::error::{Error, Result};
use crate::pb::{self, robot_ref::Source, robot_service_client::RobotServiceClient};

/// Which model and chain a [`Robot`] names.
#[derive(Clone, Debug)]
pub(crate) struct RobotSpec {
    source: ModelSource,
    base_link: String,
    tip_link: String,
}

#[derive(Clone, Debug)]
enum ModelSource {
    Builtin(String),
    /// URDF text and the mesh files it names, (URI as written, bytes).
    Urdf(Arc<str>, Arc<[(String, Vec<u8>)]>),
}

impl RobotSpec {
    pub(crate) fn builtin(name: &str) -> RobotSpec {
        RobotSpec {
            source: ModelSource::Builtin(name.to_owned()),
            base_link: String::new(),
            tip_link: String::new(),
        }
    }

    pub(crate) fn urdf(text: String, meshes: Vec<(String, Vec<u8>)>) -> RobotSpec {
        RobotSpec {
            source: ModelSource::Urdf(text.into(), meshes.into()),
            base_link: String::new(),
            tip_link: String::new(),
        }
    }
}

/// A robot model on a server, with the calls about it.
///
/// An inline URDF is sent with the first call only; the server answers with
/// its content hash (`model_id`), which later calls send instead. A replica
/// that does not hold that model answers `NOT_FOUND`, and the call is then
/// repeated once with the URDF text — so a robot keeps working across
/// replicas and restarts. Clones share the cached hash.
#[derive(Clone, Debug)]
pub struct Robot {
    client: Client,
    spec: RobotSpec,
    model_id: Arc<Mutex<Vec<u8>>>,
}

/// Joint names, limits and speeds of a robot's chain, as the server sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotInfo {
    pub name: String,
    pub base_link: String,
    pub tip_link: String,
    pub joint_names: Vec<String>,
    /// Lower and upper joint limits, rad (m for prismatic joints); infinite when unlimited.
    pub lower: DVector<f64>,
    pub upper: DVector<f64>,
    /// Joint speed limits, rad/s (m/s); 0 when the model gives none.
    pub max_velocity: DVector<f64>,
}

impl RobotInfo {
    /// Moving joints of the chain.
    pub fn dof(&self) -> usize {
        self.joint_names.len()
    }
}

impl Robot {
    pub(crate) fn new(client: Client, spec: RobotSpec) -> Robot {
        Robot {
            client,
            spec,
            model_id: Arc::new(Mutex::new(Vec::new())),
        }
    }

    /// The same model with the chain from `base_link` to `tip_link` (empty: the
    /// tree's root / its single end link).
    pub fn with_chain(&self, base_link: &str, tip_link: &str) -> Robot {
        let mut spec = self.spec.clone();
        spec.base_link = base_link.to_owned();
        spec.tip_link = tip_link.to_owned();
        Robot::new(self.client.clone(), spec)
    }

    /// The same robot over another connection (another replica, another
    /// deadline: see [`Client::with_timeout`]); the cached model hash is kept.
    pub fn on(&self, client: &Client) -> Robot {
        Robot {
            client: client.clone(),
            ..self.clone()
        }
    }

    /// The client this robot calls through.
    pub fn client(&self) -> &Client {
        &self.client
    }

    /// The content hash of an inline URDF once a server has returned it.
    pub fn model_id(&self) -> Option<Vec<u8>> {
        let id = self.cached_id();
        (!id.is_empty()).then_some(id)
    }

    fn cached_id(&self) -> Vec<u8> {
        self.model_id.lock().map(|id| id.clone()).unwrap_or_default()
    }

    pub(crate) fn remember(&self, id: &[u8]) {
        if matches!(self.spec.source, ModelSource::Urdf(..))
            && !id.is_empty()
            && let Ok(mut cached) = self.model_id.lock()
        {
            *cached = id.to_vec();
        }
    }

    pub(crate) fn forget(&self) {
        if let Ok(mut cached) = self.model_id.lock() {
            cached.clear();
        }
    }

    /// The reference to send: the name, the cached hash, or the URDF text.
    pub(crate) fn reference(&self, inline: bool) -> pb::RobotRef {
        let (source, meshes) = match &self.spec.source {
            ModelSource::Builtin(name) => (Source::Name(name.clone()), Vec::new()),
            ModelSource::Urdf(text, files) => {
                let id = self.cached_id();
                if inline || id.is_empty() {
                    let meshes = files
                        .iter()
                        .map(|(uri, data)| pb::MeshFile {
                            uri: uri.clone(),
                            data: data.clone(),
                        })
                        .collect();
                    (Source::Urdf(text.to_string()), meshes)
                } else {
                    (Source::ModelId(id), Vec::new())
                }
            }
        };
        pb::RobotRef {
            source: Some(source),
            base_link: self.spec.base_link.clone(),
            tip_link: self.spec.tip_link.clone(),
            meshes,
            ..Default::default()
        }
    }

    /// True when `reference(false)` would name a cached hash.
    pub(crate) fn sends_model_id(&self) -> bool {
        matches!(self.spec.source, ModelSource::Urdf(..)) && !self.cached_id().is_empty()
    }

    /// A unary call about this robot, with the model-hash rule: `build` makes
    /// the request from a reference, `model_id` reads the hash from the answer.
    pub(crate) async fn call<Req, Resp, F, Fut>(
        &self,
        build: impl Fn(pb::RobotRef) -> Req,
        call: F,
        model_id: impl Fn(&Resp) -> &[u8],
    ) -> Result<Resp>
    where
        Req: Clone,
        F: Fn(Channel, tonic::Request<Req>) -> Fut,
        Fut: Future<Output = std::result::Result<tonic::Response<Resp>, tonic::Status>>,
    {
        let used_id = self.sends_model_id();
        let reply = match self.client.unary(build(self.reference(false)), &call).await {
            Err(e) if used_id && e.code() == tonic::Code::NotFound => {
                self.forget();
                self.client.unary(build(self.reference(true)), &call).await?
            }
            other => other?,
        };
        self.remember(model_id(&reply));
        Ok(reply)
    }

    /// The chain's joints and limits.
    pub async fn describe(&self) -> Result<RobotInfo> {
        let r = self
            .call(
                |robot| pb::DescribeRobotRequest {
                    robot: Some(robot),
                    ..Default::default()
                },
                |ch, req| async move { RobotServiceClient::new(ch).describe_robot(req).await },
                |r| &r.model_id,
            )
            .await?;
        let column =
            |f: fn(&pb::JointInfo) -> f64| DVector::from_iterator(r.joints.len(), r.joints.iter().map(f));
        Ok(RobotInfo {
            lower: column(|j| j.lower),
            upper: column(|j| j.upper),
            max_velocity: column(|j| j.max_velocity),
            joint_names: r.joints.iter().map(|j| j.name.clone()).collect(),
            name: r.name,
            base_link: r.base_link,
            tip_link: r.tip_link,
        })
    }

    /// Tool (tip link) pose in the base frame at joint positions `q`
    /// (rad, m for prismatic joints; chain order).
    pub async fn fk(&self, q: &[f64]) -> Result<Isometry3<f64>> {
        let r = self
            .call(
                |robot| pb::ForwardKinematicsRequest {
                    robot: Some(robot),
                    joint_positions: q.to_vec(),
                    include_links: false,
                },
                |ch, req| async move { RobotServiceClient::new(ch).forward_kinematics(req).await },
                |r| &r.model_id,
            )
            .await?;
        pose_from_proto(r.tool_pose.as_ref(), "tool_pose")
    }

    /// The 6 × n geometric Jacobian at `q` (rows: linear velocity of the tool
    /// origin, then angular velocity; base frame) and the tool pose there.
    pub async fn jacobian(&self, q: &[f64]) -> Result<(DMatrix<f64>, Isometry3<f64>)> {
        let r = self
            .call(
                |robot| pb::JacobianRequest {
                    robot: Some(robot),
                    joint_positions: q.to_vec(),
                },
                |ch, req| async move { RobotServiceClient::new(ch).jacobian(req).await },
                |r| &r.model_id,
            )
            .await?;
        Ok((
            matrix_from_proto(r.jacobian.as_ref(), "jacobian")?,
            pose_from_proto(r.tool_pose.as_ref(), "tool_pose")?,
        ))
    }

    /// Tool poses of many joint states in one call (one state per entry).
    pub async fn fk_batch(&self, states: &[DVector<f64>]) -> Result<Vec<Isometry3<f64>>> {
        let request = states_to_proto(states);
        let r = self
            .call(
                |robot| pb::ForwardKinematicsBatchRequest {
                    robot: Some(robot),
                    joint_positions: Some(request.clone()),
                    include_jacobians: false,
                },
                |ch, req| async move { RobotServiceClient::new(ch).forward_kinematics_batch(req).await },
                |r| &r.model_id,
            )
            .await?;
        let poses = matrix_from_proto(r.tool_poses.as_ref(), "tool_poses")?;
        if poses.nrows() != states.len() || poses.ncols() != 7 {
            return Err(Error::Reply("tool_poses"));
        }
        poses
            .row_iter()
            .map(|row| {
                let pose = pb::Pose {
                    position: Some(pb::Vec3 {
                        x: row[0],
                        y: row[1],
                        z: row[2],
                    }),
                    orientation: Some(pb::Quaternion {
                        x: row[3],
                        y: row[4],
                        z: row[5],
                        w: row[6],
                    }),
                };
                pose_from_proto(Some(&pose), "tool_poses")
            })
            .collect()
    }
}
