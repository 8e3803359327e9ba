//! Collision models per robot chain: the bodies of its URDF `<collision>`
//! primitives — the whole robot: the chain and every link it carries (a
//! gripper beyond the tip, a pedestal above the base, off-chain joints at 0
//! clamped into their limits) — and the allowed-collision matrix sampled as MoveIt's setup
//! assistant does (10 000 states by default), built
//! once per parsed chain and kept in a small bounded cache beside the model
//! cache. Only an optimisation: a miss rebuilds, so every replica answers.

use std::sync::{Arc, Mutex, Weak};

use kinplan_core::collision::{
    AcmParams, AllowReason, AllowedCollisions, CollisionError, MeshFileLimits, RobotModel, read_mesh_file,
};
use kinplan_core::{Deadline, Stop};

use crate::runtime::models::{HeldJoints, ModelSource};
use kinplan_core::robot::Chain;

/// A chain's collision bodies and the body pairs never checked.
pub struct CollisionSetup {
    pub model: Arc<RobotModel>,
    pub acm: AllowedCollisions,
}

impl CollisionSetup {
    /// Builds the model — of the whole robot in `source` (the URDF `chain` was
    /// parsed from, with its mesh files), or of the chain alone without one —
    /// and samples the
    /// matrix: `acm_samples` states, fewer when the model has so many body
    /// pairs that the tests would exceed the domain's bound
    /// ([`AcmParams::samples_within`]).
    ///
    /// Stops with [`CollisionError::Stopped`] once `deadline` says so: it is
    /// polled before every mesh file is read, before every mesh element's
    /// hull, after the bodies are built, while the pair tables are built and
    /// during the sampling.
    pub fn build(
        chain: Arc<Chain>,
        model: Option<(&ModelSource, &[(String, f64)])>,
        acm_samples: usize,
        deadline: Deadline<'_>,
    ) -> Result<Self, CollisionError> {
        let stopped = |what: &str| {
            deadline.stop().map_or(Ok(()), |stop| {
                Err(CollisionError::Stopped {
                    what: what.into(),
                    stop,
                })
            })
        };
        let source = model.map(|(s, _)| s);
        let held: Vec<(&str, f64)> = model
            .map(|(_, h)| h.iter().map(|(n, v)| (n.as_str(), *v)).collect())
            .unwrap_or_default();
        let model = Arc::new(match source {
            Some(source) => {
                let limits = MeshFileLimits::default();
                let meshes = source
                    .meshes
                    .iter()
                    .map(|(uri, data)| {
                        stopped("reading the robot's mesh files")?;
                        read_mesh_file(uri, data, &limits)
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                RobotModel::of_urdf_until(chain, &source.urdf, &held, &meshes, deadline)?
            }
            None => RobotModel::new(chain)?,
        });
        stopped("building the robot's collision bodies")?;
        // MoveIt's disable_collisions pairs (by link name; pairs of links the
        // model does not hold are left out)
        let disabled: &[(String, String)] = match source.and_then(|s| s.srdf.as_deref()) {
            Some(srdf) => &srdf.parsed.disabled_collisions,
            None => &[],
        };
        let mut acm = AllowedCollisions::sampled_until(
            &model,
            &AcmParams {
                samples: AcmParams::samples_within(model.body_count(), acm_samples),
                ..AcmParams::default()
            },
            deadline,
        )?;
        acm.allow_named(
            &model,
            disabled.iter().map(|(a, b)| (a.as_str(), b.as_str())),
            AllowReason::User,
        );
        Ok(Self { model, acm })
    }
}

/// A cached setup: the chain it was built for (by identity), the held joint
/// values, the setup.
type CacheEntry = (Weak<Chain>, HeldJoints, Arc<CollisionSetup>);

/// Setups keyed by the identity of the chain they were built for. A setup
/// holds its chain (the robot model owns it), so the chain's address cannot
/// be reused by another chain while the entry lives; the capacity bounds the
/// cache (oldest entry out first).
pub struct CollisionModels {
    entries: Mutex<Vec<CacheEntry>>,
    capacity: usize,
    /// States sampled for each allowed-collision matrix.
    pub acm_samples: usize,
}

impl CollisionModels {
    pub fn new(capacity: usize, acm_samples: usize) -> Self {
        Self {
            entries: Mutex::new(Vec::new()),
            capacity: capacity.max(1),
            acm_samples,
        }
    }

    /// The setup built for this very chain with these held joint values, if cached.
    pub fn get(&self, chain: &Arc<Chain>, held: &[(String, f64)]) -> Option<Arc<CollisionSetup>> {
        let entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries
            .iter()
            .find(|(w, h, _)| **h == *held && w.upgrade().is_some_and(|c| Arc::ptr_eq(&c, chain)))
            .map(|(_, _, s)| s.clone())
    }

    /// Keeps `setup` for `chain` and `held`, dropping the oldest entries beyond the capacity.
    pub fn insert(&self, chain: &Arc<Chain>, held: &HeldJoints, setup: Arc<CollisionSetup>) {
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        if !entries
            .iter()
            .any(|(w, h, _)| h == held && w.upgrade().is_some_and(|c| Arc::ptr_eq(&c, chain)))
        {
            entries.push((Arc::downgrade(chain), held.clone(), setup));
        }
        while entries.len() > self.capacity {
            entries.remove(0);
        }
    }
}

/// The chain's collision setup: cached, or built on the CPU pool within the
/// call's deadline. A build the deadline stops is not cached, so its cost is
/// bounded by the call that asked for it; DEADLINE_EXCEEDED then says that
/// the first call for a robot must allow for the build.
pub async fn collision_setup(
    shared: &crate::runtime::Shared,
    robot: &crate::runtime::models::Resolved,
    budget: &crate::runtime::Budget,
) -> Result<Arc<CollisionSetup>, tonic::Status> {
    let cache = shared.collision.clone();
    if let Some(s) = cache.get(&robot.chain, &robot.held) {
        return Ok(s);
    }
    let chain = robot.chain.clone();
    let source = robot.source.clone();
    let held = robot.held.clone();
    shared
        .compute
        .run(budget, move |budget| {
            let setup = Arc::new(CollisionSetup::build(
                chain.clone(),
                Some((&source, &held[..])),
                cache.acm_samples,
                budget.deadline(),
            )?);
            cache.insert(&chain, &held, setup.clone());
            Ok(setup)
        })
        .await?
        .map_err(|e: CollisionError| match e {
            CollisionError::Stopped { what, stop } => stopped_status(&what, stop),
            e => crate::status::collision::collision_error("robot", e),
        })
}

/// DEADLINE_EXCEEDED (or CANCELLED) for a build stopped while `what`.
fn stopped_status(what: &str, stop: Stop) -> tonic::Status {
    match stop {
        Stop::Cancelled => tonic::Status::cancelled(format!("the call was cancelled while {what}")),
        Stop::Deadline => tonic::Status::deadline_exceeded(format!(
            "the deadline passed while {what}: the robot's collision model (mesh hulls and \
             allowed-collision matrix) is built on the first call for a robot and cached \
             afterwards; give that call a longer deadline"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinplan_core::robot::builtin_chain;

    #[test]
    fn a_setup_is_found_only_for_its_own_chain_and_held_values_and_the_capacity_holds() {
        let cache = CollisionModels::new(2, 50);
        let none: HeldJoints = Arc::from(Vec::new());
        let ur5 = builtin_chain("ur5").unwrap();
        let setup = Arc::new(CollisionSetup::build(ur5.clone(), None, 50, Deadline::none()).unwrap());
        cache.insert(&ur5, &none, setup.clone());
        assert!(Arc::ptr_eq(&cache.get(&ur5, &none).unwrap(), &setup));
        // other held values are another model
        let held: HeldJoints = Arc::from(vec![("j".to_string(), 0.5)]);
        assert!(cache.get(&ur5, &held).is_none());
        // An equal chain in another allocation is another model.
        let copy = Arc::new((*ur5).clone());
        assert!(cache.get(&copy, &none).is_none());
        cache.insert(
            &copy,
            &none,
            Arc::new(CollisionSetup::build(copy.clone(), None, 50, Deadline::none()).unwrap()),
        );
        drop(copy);
        // The dead entry is dropped on the next insert; capacity holds.
        let panda = builtin_chain("franka_panda").unwrap();
        cache.insert(
            &panda,
            &none,
            Arc::new(CollisionSetup::build(panda.clone(), None, 50, Deadline::none()).unwrap()),
        );
        assert_eq!(cache.entries.lock().unwrap().len(), 2);
    }
}
