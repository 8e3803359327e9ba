//! Closed-loop vector-distance navigation: [`navigate`] senses, steps the navigator and moves
//! the robot until it reaches the goal, gives up (no path), runs out of time, collides or is
//! stopped.

use serde::{Deserialize, Serialize};

use super::{Outcome, SimParams, SimRun, start_check, step_into};
use crate::Deadline;
use crate::mobile::chassis::Chassis;
use crate::mobile::error::MobileError;
use crate::mobile::field::MobileField;
use crate::mobile::pose::{Point2, Pose};
use crate::mobile::sensors::{RangeSensorParams, RangeSensors};
use crate::mobile::vector_distance::{VdfEvent, VdfParams, VdfState, vdf_step_mut};
use crate::mobile::world::World;

/// Settings of [`navigate`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NavigateParams {
    /// Step, radius, time limit.
    pub sim: SimParams,
    /// Sensor ring.
    pub sensors: RangeSensorParams,
    /// Navigator.
    pub vdf: VdfParams,
    /// Seed of the sensor noise.
    pub seed: u64,
}

/// Simulates the vector-distance navigator ([`vdf_step`](crate::mobile::vdf_step)) with the range
/// sensors of `params.sensors` (noise seeded by `params.seed`, so a run is deterministic)
/// from `start` to `goal` among `world`'s obstacles.
///
/// ```
/// use kinplan_core::Deadline;
/// use kinplan_core::mobile::{navigate, Chassis, NavigateParams, Obstacle, Outcome, Point2, Pose, World};
/// let world = World::new(vec![Obstacle::circle(2.0, 0.0, 0.5)]).unwrap();
/// let run = navigate(&Chassis::default(), Pose::new(0.0, 0.0, 0.0), Point2::new(4.0, 0.0), &world,
///                    &NavigateParams::default(), Deadline::none()).unwrap();
/// assert_eq!(run.outcome, Outcome::Reached);
/// ```
pub fn navigate(
    chassis: &Chassis,
    start: Pose,
    goal: Point2,
    world: &World,
    params: &NavigateParams,
    deadline: Deadline<'_>,
) -> Result<SimRun, MobileError> {
    chassis.validate()?;
    start.validate(MobileField::Start)?;
    goal.validate(MobileField::Goal)?;
    params.sim.validate()?;
    params.vdf.validate()?;
    let sim = &params.sim;
    let mut sensors = RangeSensors::new(params.sensors, params.seed)?;
    let mut run = SimRun::default();
    run.metrics.min_clearance = start_check(Some(world), start, sim.robot_radius)?;
    let steps = (sim.max_time / sim.dt).ceil() as usize;
    let mut readings = vec![0.0; params.sensors.count];
    let mut state = VdfState::default();
    let mut pose = start;
    run.states.push(pose);
    for k in 0..=steps {
        if deadline.expired() {
            run.outcome = Outcome::Cancelled;
            break;
        }
        if !sensors.sense_until(world, pose, sim.robot_radius, &mut readings, deadline) {
            run.outcome = Outcome::Cancelled;
            break;
        }
        let out = vdf_step_mut(&mut state, pose, goal, &readings, &params.vdf);
        match out.event {
            Some(VdfEvent::Reached) => {
                run.outcome = Outcome::Reached;
                break;
            }
            Some(VdfEvent::NoPath(reason)) => {
                run.outcome = Outcome::NoPath;
                run.no_path_reason = Some(reason);
                break;
            }
            Some(VdfEvent::Hit(h)) => run.hit_points.push(h),
            Some(VdfEvent::Leave(l)) => run.leave_points.push(l),
            None => {}
        }
        if k == steps {
            run.outcome = Outcome::Timeout;
            break;
        }
        run.modes.push(out.mode);
        if step_into(&mut run, Some(world), chassis, &mut pose, out.twist, sim) {
            break;
        }
    }
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::path_follow::PathFollowParams;
    use crate::mobile::simulate::follow_path;
    use crate::mobile::world::Obstacle;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    /// Random convex obstacles (circles and axis-aligned squares) between start and goal, kept
    /// 0.6 m apart from each other and 1 m away from start and goal.
    fn convex_world(seed: u64) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut obs: Vec<(Point2, f64, bool)> = Vec::new();
        let (s, g) = (Point2::new(0.0, 0.0), Point2::new(10.0, 0.0));
        for _ in 0..200 {
            if obs.len() >= 7 {
                break;
            }
            let c = Point2::new(rng.random_range(1.5..8.5), rng.random_range(-2.5..2.5));
            let r = rng.random_range(0.2..0.7);
            let square = rng.random_bool(0.4);
            if c.distance(s) < r + 1.0 || c.distance(g) < r + 1.0 {
                continue;
            }
            if obs.iter().any(|(o, ro, _)| o.distance(c) < r + ro + 0.9) {
                continue;
            }
            obs.push((c, r, square));
        }
        World::new(
            obs.into_iter()
                .map(|(c, r, sq)| {
                    if sq {
                        let h = r / 2f64.sqrt();
                        Obstacle::polygon(&[
                            (c.x - h, c.y - h),
                            (c.x + h, c.y - h),
                            (c.x + h, c.y + h),
                            (c.x - h, c.y + h),
                        ])
                    } else {
                        Obstacle::circle(c.x, c.y, r)
                    }
                })
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn navigator_reaches_the_goal_among_convex_obstacles() {
        let params = NavigateParams {
            sim: SimParams {
                robot_radius: 0.2,
                dt: 0.05,
                max_time: 120.0,
            },
            ..NavigateParams::default()
        };
        let mut failures = Vec::new();
        for seed in 0..20 {
            let w = convex_world(seed);
            let run = navigate(
                &Chassis::default(),
                Pose::new(0.0, 0.0, 0.0),
                Point2::new(10.0, 0.0),
                &w,
                &params,
                Deadline::none(),
            )
            .unwrap();
            if run.outcome != Outcome::Reached {
                failures.push((seed, run.outcome));
            }
            assert!(run.metrics.min_clearance.unwrap() >= 0.0 || run.outcome == Outcome::Collision);
        }
        assert!(failures.is_empty(), "{failures:?}");
    }

    #[test]
    fn walled_in_goal_is_no_path() {
        // Goal at (6, 0) inside a closed ring of 28 touching cylinders of radius 0.15 on a
        // circle of radius 1.3 around it.
        let mut obs = Vec::new();
        for i in 0..28 {
            let a = 2.0 * PI * i as f64 / 28.0;
            obs.push(Obstacle::circle(6.0 + 1.3 * a.cos(), 1.3 * a.sin(), 0.16));
        }
        let w = World::new(obs).unwrap();
        let p = NavigateParams {
            sim: SimParams {
                max_time: 300.0,
                ..SimParams::default()
            },
            ..NavigateParams::default()
        };
        let run = navigate(
            &Chassis::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(6.0, 0.0),
            &w,
            &p,
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(run.outcome, Outcome::NoPath, "{:?}", run.metrics);
        assert!(!run.hit_points.is_empty());
        // Going round the other way once does not change the verdict; it takes longer.
        let retry = NavigateParams {
            vdf: VdfParams {
                retry_other_side: true,
                ..VdfParams::default()
            },
            ..p
        };
        let again = navigate(
            &Chassis::default(),
            Pose::new(0.0, 0.0, 0.0),
            Point2::new(6.0, 0.0),
            &w,
            &retry,
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(again.outcome, Outcome::NoPath, "{:?}", again.metrics);
        assert!(again.metrics.steps > run.metrics.steps);
    }

    #[test]
    fn runs_are_deterministic_with_noise_and_cancellable() {
        let w = convex_world(3);
        let p = NavigateParams {
            sensors: RangeSensorParams {
                noise_sigma: 0.02,
                ..RangeSensorParams::default()
            },
            seed: 11,
            ..NavigateParams::default()
        };
        let a = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            Deadline::none(),
        )
        .unwrap();
        let b = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            Deadline::none(),
        )
        .unwrap();
        assert_eq!(a, b);
        let c = navigate(
            &Chassis::default(),
            Pose::default(),
            Point2::new(10.0, 0.0),
            &w,
            &p,
            Deadline::none().with_cancel(&|| true),
        )
        .unwrap();
        assert_eq!(c.outcome, Outcome::Cancelled);
        assert_eq!(c.states.len(), 1);
    }

    #[test]
    fn bad_inputs_are_rejected() {
        let w = World::new(vec![Obstacle::circle(0.0, 0.0, 0.5)]).unwrap();
        let p = NavigateParams::default();
        let c = Chassis::default();
        assert!(matches!(
            navigate(
                &c,
                Pose::default(),
                Point2::new(1.0, 0.0),
                &w,
                &p,
                Deadline::none()
            ),
            Err(MobileError::StartInCollision { obstacle: 0, .. })
        ));
        let bad_dt = NavigateParams {
            sim: SimParams {
                dt: -0.1,
                ..SimParams::default()
            },
            ..p
        };
        let too_long = SimParams {
            dt: 1e-6,
            max_time: 1e3,
            ..SimParams::default()
        };
        assert!(matches!(too_long.validate(), Err(MobileError::OutOfRange { .. })));
        assert!(
            navigate(
                &c,
                Pose::new(3.0, 0.0, 0.0),
                Point2::new(1.0, 0.0),
                &w,
                &bad_dt,
                Deadline::none()
            )
            .is_err()
        );
        assert!(
            navigate(
                &c,
                Pose::new(f64::NAN, 0.0, 0.0),
                Point2::new(1.0, 0.0),
                &w,
                &p,
                Deadline::none()
            )
            .is_err()
        );
        assert_eq!(
            follow_path(
                &c,
                Pose::default(),
                &[],
                None,
                &PathFollowParams::default(),
                &SimParams::default(),
                Deadline::none()
            ),
            Err(MobileError::EmptyPath)
        );
    }
}
