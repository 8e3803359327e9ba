//! The requests a load test sends: a fixed, seeded pool per RPC, built before
//! the clock starts so request generation costs nothing during the run.

use kinplan_core::robot::{Chain, builtin_chain};
use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use kinplan_proto::{self as pb, robot_ref::Source};

/// The RPC a load test calls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Rpc {
    /// RobotService.ForwardKinematics of a random state.
    Fk,
    /// RobotService.Jacobian of a random state.
    Jacobian,
    /// KinematicsService.SolveIk of a reachable pose (FK of a random state),
    /// seeded 0.1 rad from the answer on every joint (a warm, tracking-like solve).
    Ik,
    /// KinematicsService.SolveIk of a reachable pose from the middle of the limits
    /// (cold: restarts as needed).
    IkCold,
    /// ScoringService.ScoreTrajectory of a 100-waypoint random trajectory.
    Score,
}

/// One prepared request of any workload.
#[derive(Debug, Clone)]
pub enum Workload {
    Fk(pb::ForwardKinematicsRequest),
    Jacobian(pb::JacobianRequest),
    Ik(pb::SolveIkRequest),
    Score(pb::ScoreTrajectoryRequest),
}

/// `count` requests of `rpc` on the built-in `robot`, from RNG `seed`.
pub fn build_pool(rpc: Rpc, robot: &str, count: usize, seed: u64) -> Result<Vec<Workload>, String> {
    let chain = builtin_chain(robot).map_err(|e| format!("--robot: {e}"))?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let robot_ref = || pb::RobotRef {
        source: Some(Source::Name(robot.to_owned())),
        ..Default::default()
    };
    let pool = (0..count.max(1))
        .map(|_| {
            let q = random_state(&chain, &mut rng);
            match rpc {
                Rpc::Fk => Workload::Fk(pb::ForwardKinematicsRequest {
                    robot: Some(robot_ref()),
                    joint_positions: q,
                    include_links: false,
                }),
                Rpc::Jacobian => Workload::Jacobian(pb::JacobianRequest {
                    robot: Some(robot_ref()),
                    joint_positions: q,
                }),
                Rpc::Ik | Rpc::IkCold => {
                    let target = pose_msg(&chain.fk(&q));
                    let seed = if rpc == Rpc::Ik {
                        q.iter()
                            .zip(chain.limits())
                            .map(|(v, (lo, hi))| (v + 0.1).clamp(lo, hi))
                            .collect()
                    } else {
                        Vec::new()
                    };
                    Workload::Ik(pb::SolveIkRequest {
                        robot: Some(robot_ref()),
                        target: Some(target),
                        seed,
                        options: None,
                    })
                }
                Rpc::Score => {
                    let end = random_state(&chain, &mut rng);
                    let points = (0..100)
                        .map(|i| {
                            let t = i as f64 / 99.0;
                            pb::JointPoint {
                                positions: q.iter().zip(&end).map(|(a, b)| a + t * (b - a)).collect(),
                                time_from_start: 0.0,
                                ..Default::default()
                            }
                        })
                        .collect();
                    Workload::Score(pb::ScoreTrajectoryRequest {
                        robot: Some(robot_ref()),
                        trajectory: Some(pb::JointTrajectory {
                            joint_names: Vec::new(),
                            points,
                        }),
                        options: None,
                    })
                }
            }
        })
        .collect();
    Ok(pool)
}

/// A uniform state inside the limits (±π for unlimited revolute joints).
fn random_state(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .limits()
        .map(|(lo, hi)| {
            let (lo, hi) = if lo.is_finite() && hi.is_finite() {
                (lo, hi)
            } else {
                (-std::f64::consts::PI, std::f64::consts::PI)
            };
            if hi > lo { rng.random_range(lo..hi) } else { lo }
        })
        .collect()
}

/// A pose as the contract sends it (position in metres, unit quaternion).
pub fn pose_msg(t: &Isometry3<f64>) -> pb::Pose {
    let p = t.translation.vector;
    let q = t.rotation.quaternion();
    pb::Pose {
        position: Some(pb::Vec3 {
            x: p.x,
            y: p.y,
            z: p.z,
        }),
        orientation: Some(pb::Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ik_targets_are_the_fk_of_a_state_within_limits_and_seeds_stay_inside() {
        let chain = builtin_chain("ur5").unwrap();
        let pool = build_pool(Rpc::Ik, "ur5", 20, 7).unwrap();
        for w in pool {
            let Workload::Ik(req) = w else {
                panic!("not an IK request")
            };
            assert_eq!(req.seed.len(), chain.dof());
            for (v, (lo, hi)) in req.seed.iter().zip(chain.limits()) {
                assert!((lo..=hi).contains(v));
            }
            let q = req.target.unwrap().orientation.unwrap();
            let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
            assert!((norm - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn pools_are_reproducible_and_unknown_robots_are_refused() {
        let a = build_pool(Rpc::Fk, "franka_panda", 5, 3).unwrap();
        let b = build_pool(Rpc::Fk, "franka_panda", 5, 3).unwrap();
        let first = |p: &[Workload]| match &p[0] {
            Workload::Fk(r) => r.joint_positions.clone(),
            _ => unreachable!(),
        };
        assert_eq!(first(&a), first(&b));
        assert!(
            build_pool(Rpc::Fk, "no_such_robot", 5, 3)
                .unwrap_err()
                .starts_with("--robot")
        );
    }
}
