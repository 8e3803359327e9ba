//! One step of a stateless controller (docs/mobile.md): the controller's memory comes in
//! and goes out as an opaque token ([`decode_token`] / [`encode_token`]), so a server can
//! answer each step without keeping anything between calls. The vector-distance navigator
//! senses the world itself when it is given no readings.

use super::chassis::{Chassis, Saturation};
use super::error::{MobileError, check_positive};
use super::field::MobileField;
use super::path_follow::{PathFollowParams, PathFollowState, PathNode, path_follow_step, validate_path};
use super::pose::{Point2, Pose, Twist};
use super::sensors::{RangeSensorParams, RangeSensors};
use super::simulate::SimParams;
use super::token::{decode_token, encode_token};
use super::vector_distance::{NavMode, VdfEvent, VdfParams, VdfState, vdf_step};
use super::world::World;
use crate::Deadline;

/// Settings of one step that have defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOptions {
    /// Control period, s (default: the simulation's, 0.05).
    pub dt: f64,
    /// Robot disc radius for sensing a world, m (default: the simulation's, 0.22).
    pub robot_radius: f64,
    /// Seed of the sensor noise (default 0).
    pub seed: u64,
}

impl Default for StepOptions {
    fn default() -> Self {
        let sim = SimParams::default();
        Self {
            dt: sim.dt,
            robot_radius: sim.robot_radius,
            seed: 0,
        }
    }
}

/// The controller of one step and its inputs.
#[derive(Clone, Copy, Debug)]
pub enum StepController<'a> {
    /// The vector-distance navigator towards `goal`.
    VectorDistance {
        /// The goal.
        goal: Point2,
        /// The sensor ring.
        sensors: RangeSensorParams,
        /// Navigator parameters.
        vdf: VdfParams,
        /// Gaps, one per sensor; empty with a `world`: sensed in it.
        readings: &'a [f64],
        /// Obstacles to sense when no readings are given.
        world: Option<&'a World>,
    },
    /// A path-following controller along `path`.
    FollowPath {
        /// Nodal points.
        path: &'a [PathNode],
        /// Follower parameters (the controller among them).
        follow: PathFollowParams,
    },
}

/// What a step reports beyond the command.
#[derive(Clone, Debug, PartialEq)]
pub enum StepReport {
    /// Vector distance.
    VectorDistance {
        /// Mode used for this step.
        mode: NavMode,
        /// The readings used (given or sensed), m.
        readings: Vec<f64>,
        /// The vector sum F, world frame.
        force: Point2,
        /// Reached, hit, leave or no path.
        event: Option<VdfEvent>,
    },
    /// Path following.
    FollowPath {
        /// Index of the active node after this step.
        target_node: usize,
    },
}

/// The result of one step.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlStep {
    /// The controller's command, body frame.
    pub command: Twist,
    /// The command after the chassis limits ([`Chassis::saturate`]).
    pub applied: Twist,
    /// How the command was limited.
    pub saturation: Saturation,
    /// The goal (or last node, with its heading if given) is reached.
    pub reached: bool,
    /// The controller's memory for the next step.
    pub token: Vec<u8>,
    /// Controller-specific report.
    pub report: StepReport,
}

/// One step of `controller` for a robot at `pose` on `chassis`, continuing from `token`
/// (empty: a fresh controller). Vector distance: the readings given, or, when none are given
/// and a world is, the readings of a ring of `sensors` around a disc of
/// `options.robot_radius` sensed in it (noise seeded by `options.seed`), then
/// [`vdf_step`]. Path following: [`path_follow_step`] with period `options.dt`, the token's
/// node indices checked against the path, parameters adapted to the chassis
/// ([`PathFollowParams::for_chassis`]). The command is saturated by the chassis.
/// `Ok(None)` when `deadline` stopped the sensing.
pub fn control_step(
    chassis: &Chassis,
    pose: Pose,
    token: &[u8],
    controller: &StepController,
    options: &StepOptions,
    deadline: Deadline<'_>,
) -> Result<Option<ControlStep>, MobileError> {
    chassis.validate()?;
    let (command, reached, token, report) = match *controller {
        StepController::VectorDistance {
            goal,
            sensors,
            vdf,
            readings,
            world,
        } => {
            let memory: VdfState = decode_token(token, &())?;
            let readings = match world {
                Some(world) if readings.is_empty() => {
                    match sense(world, pose, &sensors, options, deadline)? {
                        Some(sensed) => sensed,
                        None => return Ok(None),
                    }
                }
                _ => readings.to_vec(),
            };
            let (next, out) = vdf_step(&memory, pose, goal, &readings, &sensors, &vdf)?;
            let report = StepReport::VectorDistance {
                mode: out.mode,
                readings,
                force: out.force,
                event: out.event,
            };
            let reached = out.event == Some(VdfEvent::Reached);
            (out.twist, reached, encode_token(&next, &())?, report)
        }
        StepController::FollowPath { path, follow } => {
            validate_path(path)?;
            let progress: PathFollowState = decode_token(token, &path.len())?;
            let s = path_follow_step(pose, path, progress, options.dt, &follow.for_chassis(chassis))?;
            let report = StepReport::FollowPath {
                target_node: s.next.target,
            };
            (s.twist, s.reached, encode_token(&s.next, &path.len())?, report)
        }
    };
    let (applied, saturation) = chassis.saturate(command);
    Ok(Some(ControlStep {
        command,
        applied,
        saturation,
        reached,
        token,
        report,
    }))
}

/// The ring's readings at `pose` in `world`; `None` when stopped.
fn sense(
    world: &World,
    pose: Pose,
    sensors: &RangeSensorParams,
    options: &StepOptions,
    deadline: Deadline<'_>,
) -> Result<Option<Vec<f64>>, MobileError> {
    check_positive(MobileField::RobotRadius, options.robot_radius)?;
    pose.validate(MobileField::State)?;
    let mut ring = RangeSensors::new(*sensors, options.seed)?;
    let mut out = vec![0.0; sensors.count];
    Ok(ring
        .sense_until(world, pose, options.robot_radius, &mut out, deadline)
        .then_some(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::world::Obstacle;

    fn vd<'a>(readings: &'a [f64], world: Option<&'a World>) -> StepController<'a> {
        StepController::VectorDistance {
            goal: Point2::new(5.0, 0.0),
            sensors: RangeSensorParams {
                rays_per_beam: 1,
                ..RangeSensorParams::default()
            },
            vdf: VdfParams::default(),
            readings,
            world,
        }
    }

    /// Without readings the ring senses the world: a wall from x = 0.5 and a 0.22 m robot
    /// leave sensor 0 a gap of 0.5 − 0.22 = 0.28 m, and nothing within the 2 m range behind.
    /// With readings given, the world is not sensed.
    #[test]
    fn no_readings_means_sensing_the_world() {
        let wall = World::new(vec![Obstacle::polygon(&[
            (0.5, -2.0),
            (1.0, -2.0),
            (1.0, 2.0),
            (0.5, 2.0),
        ])])
        .unwrap();
        let chassis = Chassis::default();
        let opts = StepOptions::default();
        let step = control_step(
            &chassis,
            Pose::default(),
            b"",
            &vd(&[], Some(&wall)),
            &opts,
            Deadline::none(),
        )
        .unwrap()
        .unwrap();
        let StepReport::VectorDistance { readings, .. } = &step.report else {
            panic!("{:?}", step.report)
        };
        assert!((readings[0] - 0.28).abs() < 1e-9, "{readings:?}");
        assert_eq!(readings[4], 2.0);
        let given = [2.0; 8];
        let step = control_step(
            &chassis,
            Pose::default(),
            b"",
            &vd(&given, Some(&wall)),
            &opts,
            Deadline::none(),
        )
        .unwrap()
        .unwrap();
        assert!(matches!(&step.report, StepReport::VectorDistance { readings, .. } if readings == &given));
        // Stopped while sensing: no step.
        assert_eq!(
            control_step(
                &chassis,
                Pose::default(),
                b"",
                &vd(&[], Some(&wall)),
                &opts,
                Deadline::none().with_cancel(&|| true)
            )
            .unwrap(),
            None
        );
        let bad_radius = StepOptions {
            robot_radius: -1.0,
            ..opts
        };
        assert!(matches!(
            control_step(
                &chassis,
                Pose::default(),
                b"",
                &vd(&[], Some(&wall)),
                &bad_radius,
                Deadline::none()
            ),
            Err(MobileError::NotPositive {
                field: MobileField::RobotRadius,
                ..
            })
        ));
    }

    /// The path-follow token carries the active node; one pointing past the path, or a token
    /// of the other controller, is refused as a bad token.
    #[test]
    fn path_follow_tokens_continue_and_forged_ones_are_refused() {
        let path = [PathNode::at(0.1, 0.0), PathNode::at(2.0, 0.0)];
        let follow = StepController::FollowPath {
            path: &path,
            follow: PathFollowParams::default(),
        };
        let chassis = Chassis::default();
        let opts = StepOptions::default();
        let first = control_step(&chassis, Pose::default(), b"", &follow, &opts, Deadline::none())
            .unwrap()
            .unwrap();
        // Node 0 lies inside the 0.3 m switching distance.
        assert_eq!(first.report, StepReport::FollowPath { target_node: 1 });
        let back = Pose::new(-1.0, 0.0, 0.0);
        let kept = control_step(&chassis, back, &first.token, &follow, &opts, Deadline::none())
            .unwrap()
            .unwrap();
        assert_eq!(kept.report, StepReport::FollowPath { target_node: 1 });
        for forged in [
            &br#"{"target":2,"segment":0}"#[..],
            br#"{"target":0,"segment":9}"#,
        ] {
            assert!(matches!(
                control_step(&chassis, back, forged, &follow, &opts, Deadline::none()),
                Err(MobileError::BadToken { .. })
            ));
        }
        let vd_token = VdfState::default().to_token().unwrap();
        assert!(matches!(
            control_step(&chassis, back, &vd_token, &follow, &opts, Deadline::none()),
            Err(MobileError::BadToken { .. })
        ));
        // A negative period is the step's own field.
        let bad_dt = StepOptions { dt: -0.1, ..opts };
        assert!(matches!(
            control_step(&chassis, back, b"", &follow, &bad_dt, Deadline::none()),
            Err(MobileError::NotPositive {
                field: MobileField::Dt,
                ..
            })
        ));
    }

    /// Every step's token decodes again, even from the largest counters a token may carry
    /// (they saturate instead of leaving the token's bounds).
    #[test]
    fn tokens_from_saturated_counters_stay_valid() {
        let s = VdfState {
            steps_in_mode: crate::mobile::MAX_TOKEN_STEPS,
            steps_since_progress: crate::mobile::MAX_TOKEN_STEPS,
            hit_point: Some(Point2::new(-3.0, 0.0)),
            hit_distance: 8.0,
            best_distance: Some(5.0),
            ..VdfState::default()
        };
        let mut blocked = [2.0; 8];
        blocked[0] = 0.1;
        let step = control_step(
            &Chassis::default(),
            Pose::default(),
            &s.to_token().unwrap(),
            &vd(&blocked, None),
            &StepOptions::default(),
            Deadline::none(),
        )
        .unwrap()
        .unwrap();
        let next = VdfState::from_token(&step.token).unwrap();
        assert!(next.steps_since_progress <= crate::mobile::MAX_TOKEN_STEPS);
    }
}
