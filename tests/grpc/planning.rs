//! PlanningService end to end: plans around obstacles re-checked by the
//! server's CheckState at a finer resolution, limits and timing checked
//! against DescribeRobot, pose goals against forward kinematics, witness
//! points against the sphere they lie on, and bad input named by field.

use std::time::{Duration, Instant};

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, collision_object::Shape, plan_request::Goal, planning_service_client::PlanningServiceClient,
    robot_service_client::RobotServiceClient,
};
use tonic::Code;

use crate::{named, start};

const ROBOT: &str = "ur5";
const START: [f64; 6] = [-1.2, -1.3, 1.4, -1.6, -1.57, 0.0];
const GOAL: [f64; 6] = [1.2, -1.3, 1.4, -1.6, -1.57, 0.0];

fn config() -> ServerConfig {
    ServerConfig {
        acm_samples: 300,
        ..ServerConfig::default()
    }
}

fn sphere(id: &str, centre: [f64; 3], radius: f64) -> pb::CollisionObject {
    pb::CollisionObject {
        id: id.into(),
        pose: Some(pb::Pose {
            position: Some(pb::Vec3 {
                x: centre[0],
                y: centre[1],
                z: centre[2],
            }),
            orientation: None,
        }),
        shape: Some(Shape::Sphere(pb::Sphere { radius })),
        unknown_as_obstacle: false,
    }
}

fn request(algorithm: pb::PlanAlgorithm, scene: Vec<pb::CollisionObject>) -> pb::PlanRequest {
    pb::PlanRequest {
        robot: named(ROBOT),
        start: START.to_vec(),
        goal: Some(Goal::GoalJoints(pb::JointState {
            positions: GOAL.to_vec(),
        })),
        scene: Some(pb::Scene { objects: scene }),
        algorithm: algorithm as i32,
        options: None,
        seed: 7,
    }
}

async fn tool_position(robots: &mut RobotServiceClient<tonic::transport::Channel>, q: &[f64]) -> [f64; 3] {
    let p = robots
        .forward_kinematics(pb::ForwardKinematicsRequest {
            robot: named(ROBOT),
            joint_positions: q.to_vec(),
            include_links: false,
        })
        .await
        .unwrap()
        .into_inner()
        .tool_pose
        .unwrap()
        .position
        .unwrap();
    [p.x, p.y, p.z]
}

/// A sphere where the tool passes at the middle of the straight joint-space
/// line, so the line is blocked and the planner must go around it.
async fn blocking_sphere(robots: &mut RobotServiceClient<tonic::transport::Channel>) -> pb::CollisionObject {
    let mid: Vec<f64> = START.iter().zip(GOAL).map(|(a, b)| (a + b) / 2.0).collect();
    sphere("ball", tool_position(robots, &mid).await, 0.12)
}

/// States along every segment, at most `step` rad apart, all valid per CheckState.
async fn assert_path_valid(
    planning: &mut PlanningServiceClient<tonic::transport::Channel>,
    scene: &[pb::CollisionObject],
    traj: &pb::JointTrajectory,
    step: f64,
) {
    let mut states = Vec::new();
    for w in traj.points.windows(2) {
        let (a, b) = (&w[0].positions, &w[1].positions);
        let span = a.iter().zip(b).map(|(x, y)| (y - x).abs()).fold(0.0, f64::max);
        let n = (span / step).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            states.push(pb::JointState {
                positions: a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect(),
            });
        }
    }
    let count = states.len();
    let checks = planning
        .check_state(pb::CheckStateRequest {
            robot: named(ROBOT),
            states,
            scene: Some(pb::Scene {
                objects: scene.to_vec(),
            }),
            max_distance: None,
        })
        .await
        .unwrap()
        .into_inner()
        .states;
    assert_eq!(checks.len(), count);
    if let Some(bad) = checks.iter().position(|c| !c.valid) {
        panic!(
            "state {bad} of {count} on the path is invalid: {:?}",
            checks[bad].colliding
        );
    }
}

#[tokio::test]
async fn every_planner_goes_around_a_blocking_sphere_within_the_speed_limits() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let ball = blocking_sphere(&mut robots).await;
    // The straight line is blocked, the ends are free.
    let mid: Vec<f64> = START.iter().zip(GOAL).map(|(a, b)| (a + b) / 2.0).collect();
    let ends = planning
        .check_state(pb::CheckStateRequest {
            robot: named(ROBOT),
            states: [START.to_vec(), mid, GOAL.to_vec()]
                .into_iter()
                .map(|positions| pb::JointState { positions })
                .collect(),
            scene: Some(pb::Scene {
                objects: vec![ball.clone()],
            }),
            max_distance: None,
        })
        .await
        .unwrap()
        .into_inner()
        .states;
    assert!(ends[0].valid && ends[2].valid && !ends[1].valid, "{ends:?}");
    assert!(
        ends[1].colliding.iter().any(|c| c.ends_with(":ball")),
        "{:?}",
        ends[1].colliding
    );

    let limits: Vec<f64> = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: named(ROBOT),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner()
        .joints
        .iter()
        .map(|j| j.max_velocity)
        .collect();
    for algorithm in [
        pb::PlanAlgorithm::RrtConnect,
        pb::PlanAlgorithm::Stomp,
        pb::PlanAlgorithm::Ccstomp,
    ] {
        let reply = planning
            .plan(request(algorithm, vec![ball.clone()]))
            .await
            .unwrap()
            .into_inner();
        assert_eq!(
            reply.status,
            pb::PlanStatus::Succeeded as i32,
            "{algorithm:?}: {}",
            reply.message
        );
        assert!(reply.valid);
        let traj = reply.trajectory.unwrap();
        let (first, last) = (&traj.points[0], traj.points.last().unwrap());
        assert_eq!(
            first.positions,
            START.to_vec(),
            "{algorithm:?}: start kept exactly"
        );
        assert_eq!(last.positions, GOAL.to_vec(), "{algorithm:?}: goal kept exactly");
        assert_eq!(first.time_from_start, 0.0);
        for w in traj.points.windows(2) {
            let dt = w[1].time_from_start - w[0].time_from_start;
            assert!(dt > 0.0, "{algorithm:?}: times increase");
            for (j, v) in limits.iter().enumerate() {
                let speed = (w[1].positions[j] - w[0].positions[j]).abs() / dt;
                assert!(
                    speed <= v * (1.0 + 1e-9),
                    "{algorithm:?}: joint {j} at {speed} rad/s > {v}"
                );
            }
        }
        assert!((reply.duration - last.time_from_start).abs() < 1e-12);
        assert_path_valid(&mut planning, std::slice::from_ref(&ball), &traj, 0.01).await;
        // JD of the reply against the trajectory it carries.
        let jd: f64 = traj
            .points
            .windows(2)
            .map(|w| {
                w[0].positions
                    .iter()
                    .zip(&w[1].positions)
                    .map(|(a, b)| (b - a).abs())
                    .sum::<f64>()
            })
            .sum();
        assert!(
            (reply.criteria["JD"] - jd).abs() < 1e-9 * jd.max(1.0),
            "{algorithm:?}"
        );
        if algorithm == pb::PlanAlgorithm::Ccstomp {
            let dev = reply.deviation.unwrap();
            assert!(!dev.violates_tolerance);
            assert!(dev.translation.iter().all(|&t| t <= 1.0) && dev.rotation.iter().all(|&r| r <= 0.2));
        }
    }
}

#[tokio::test]
async fn the_same_seed_gives_the_same_trajectory_and_another_seed_may_not() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let ball = blocking_sphere(&mut robots).await;
    for algorithm in [pb::PlanAlgorithm::RrtConnect, pb::PlanAlgorithm::Stomp] {
        let a = planning
            .plan(request(algorithm, vec![ball.clone()]))
            .await
            .unwrap()
            .into_inner();
        let b = planning
            .plan(request(algorithm, vec![ball.clone()]))
            .await
            .unwrap()
            .into_inner();
        assert_eq!(a.trajectory, b.trajectory, "{algorithm:?}");
    }
}

#[tokio::test]
async fn a_pose_goal_ends_at_that_pose() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let target = robots
        .forward_kinematics(pb::ForwardKinematicsRequest {
            robot: named(ROBOT),
            joint_positions: GOAL.to_vec(),
            include_links: false,
        })
        .await
        .unwrap()
        .into_inner()
        .tool_pose
        .unwrap();
    let mut req = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
    req.goal = Some(Goal::GoalPose(target));
    let reply = planning.plan(req).await.unwrap().into_inner();
    assert_eq!(
        reply.status,
        pb::PlanStatus::Succeeded as i32,
        "{}",
        reply.message
    );
    let end = reply.trajectory.unwrap().points.last().unwrap().positions.clone();
    assert_eq!(end, reply.goal);
    let reached = tool_position(&mut robots, &end).await;
    let p = target.position.unwrap();
    let err = ((reached[0] - p.x).powi(2) + (reached[1] - p.y).powi(2) + (reached[2] - p.z).powi(2)).sqrt();
    assert!(err < 1e-4, "tool {err} m from the goal pose");
}

#[tokio::test]
async fn a_start_inside_an_obstacle_is_reported_with_the_colliding_pair() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let at_tool = tool_position(&mut robots, &START).await;
    let reply = planning
        .plan(request(
            pb::PlanAlgorithm::RrtConnect,
            vec![sphere("crate", at_tool, 0.05)],
        ))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.status, pb::PlanStatus::InvalidStart as i32);
    assert!(
        reply.colliding.iter().any(|c| c.ends_with(":crate")),
        "{:?}",
        reply.colliding
    );
    assert!(reply.message.contains("crate"), "{}", reply.message);
    // Out of limits is invalid too.
    let mut req = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
    req.start[1] = 10.0;
    let reply = planning.plan(req).await.unwrap().into_inner();
    assert_eq!(reply.status, pb::PlanStatus::InvalidStart as i32);
    assert!(
        reply.colliding.contains(&"joint 1".to_string()),
        "{:?}",
        reply.colliding
    );
}

#[tokio::test]
async fn a_short_budget_ends_in_time_with_timeout() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let ball = blocking_sphere(&mut robots).await;
    let mut req = request(pb::PlanAlgorithm::Stomp, vec![ball]);
    req.options = Some(pb::PlanOptions {
        stomp: Some(pb::StompOptions {
            max_iterations: Some(1_000_000),
            iterations_after_valid: Some(1_000_000),
            straight_line_start: true,
            // noise too small to leave the ball: no valid trajectory, ever
            noise_stddev: vec![1e-4],
            ..Default::default()
        }),
        time_budget: Some(0.05),
        ..Default::default()
    });
    // Warm the collision setup first: its one-off sampling is not the budget's.
    planning
        .plan(request(pb::PlanAlgorithm::RrtConnect, Vec::new()))
        .await
        .unwrap();
    let started = Instant::now();
    let reply = planning.plan(req).await.unwrap().into_inner();
    let took = started.elapsed();
    assert_eq!(reply.status, pb::PlanStatus::Timeout as i32, "{}", reply.message);
    assert!(took < Duration::from_millis(500), "answered after {took:?}");
}

#[tokio::test]
async fn plan_stream_sends_iterations_then_the_result() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let ball = blocking_sphere(&mut robots).await;
    let mut stream = planning
        .plan_stream(request(pb::PlanAlgorithm::Stomp, vec![ball]))
        .await
        .unwrap()
        .into_inner();
    let mut messages = Vec::new();
    while let Some(m) = stream.message().await.unwrap() {
        messages.push(m);
    }
    let (last, iterations) = messages.split_last().unwrap();
    let result = last.result.as_ref().expect("the last message carries the result");
    assert_eq!(result.status, pb::PlanStatus::Succeeded as i32);
    assert!(!iterations.is_empty());
    for (k, m) in iterations.iter().enumerate() {
        assert!(m.result.is_none());
        assert_eq!(m.trajectory.as_ref().unwrap().points.len(), 40, "message {k}");
    }
}

#[tokio::test]
async fn witness_points_lie_on_the_sphere_at_the_reported_clearance() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    // A ball 0.25 m above the tool: nearer than any other robot part.
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let tool = tool_position(&mut robots, &START).await;
    let centre = [tool[0], tool[1], tool[2] + 0.25];
    let r = 0.1;
    let check = planning
        .check_state(pb::CheckStateRequest {
            robot: named(ROBOT),
            states: vec![pb::JointState {
                positions: START.to_vec(),
            }],
            scene: Some(pb::Scene {
                objects: vec![sphere("s", centre, r)],
            }),
            max_distance: Some(5.0),
        })
        .await
        .unwrap()
        .into_inner()
        .states
        .remove(0);
    assert!(check.valid && check.within_limits);
    assert!(check.closest_pair.ends_with(":s"), "{}", check.closest_pair);
    let (a, b) = (check.robot_point.unwrap(), check.obstacle_point.unwrap());
    let on_sphere =
        ((b.x - centre[0]).powi(2) + (b.y - centre[1]).powi(2) + (b.z - centre[2]).powi(2)).sqrt();
    assert!(
        (on_sphere - r).abs() < 1e-6,
        "obstacle witness {on_sphere} m from the centre"
    );
    let gap = ((a.x - b.x).powi(2) + (a.y - b.y).powi(2) + (a.z - b.z).powi(2)).sqrt();
    assert!(
        (gap - check.clearance).abs() < 1e-6,
        "{gap} vs {}",
        check.clearance
    );
    assert!(check.clearance > 0.0);
}

#[tokio::test]
async fn bad_input_is_named_by_field() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let cases: Vec<(pb::PlanRequest, &str)> = vec![
        (
            {
                let mut r = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
                r.start[2] = f64::NAN;
                r
            },
            "start[2]",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
                r.start.pop();
                r
            },
            "start",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
                r.goal = None;
                r
            },
            "goal",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
                r.goal = Some(Goal::GoalPose(pb::Pose {
                    position: Some(pb::Vec3 {
                        x: f64::INFINITY,
                        y: 0.0,
                        z: 0.0,
                    }),
                    orientation: None,
                }));
                r
            },
            "goal_pose.position.x",
        ),
        (
            request(
                pb::PlanAlgorithm::RrtConnect,
                vec![pb::CollisionObject {
                    id: "m".into(),
                    pose: None,
                    shape: Some(Shape::Mesh(pb::TriangleMesh {
                        vertices: vec![
                            pb::Vec3 {
                                x: 0.0,
                                y: 0.0,
                                z: 0.0
                            };
                            3
                        ],
                        indices: vec![0, 1, 7],
                    })),
                    unknown_as_obstacle: false,
                }],
            ),
            "scene.objects[0].mesh.indices[2]",
        ),
        (
            request(
                pb::PlanAlgorithm::RrtConnect,
                vec![sphere("s", [0.0, 0.0, 0.0], -1.0)],
            ),
            "scene.objects[0].sphere.radius",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::Stomp, Vec::new());
                r.options = Some(pb::PlanOptions {
                    stomp: Some(pb::StompOptions {
                        cost_sensitivity: Some(-1.0),
                        ..Default::default()
                    }),
                    ..Default::default()
                });
                r
            },
            "options.stomp.cost_sensitivity",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::Ccstomp, Vec::new());
                r.options = Some(pb::PlanOptions {
                    cartesian: Some(pb::CartesianOptions {
                        violation_penalty: Some(-1.0),
                        ..Default::default()
                    }),
                    ..Default::default()
                });
                r
            },
            "options.cartesian.violation_penalty",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::Ccstomp, Vec::new());
                r.options = Some(pb::PlanOptions {
                    cartesian: Some(pb::CartesianOptions {
                        rotation_stddev: Some(0.0),
                        ..Default::default()
                    }),
                    ..Default::default()
                });
                r
            },
            "options.cartesian.rotation_stddev",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::Stomp, Vec::new());
                r.options = Some(pb::PlanOptions {
                    stomp: Some(pb::StompOptions {
                        timesteps: Some(10_000),
                        max_rollouts: Some(10_000),
                        ..Default::default()
                    }),
                    ..Default::default()
                });
                r
            },
            "options.stomp",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::RrtConnect, Vec::new());
                r.options = Some(pb::PlanOptions {
                    motion_resolution: Some(0.5),
                    ..Default::default()
                });
                r
            },
            "options.motion_resolution",
        ),
        (
            {
                let mut r = request(pb::PlanAlgorithm::Ccstomp, Vec::new());
                r.options = Some(pb::PlanOptions {
                    stomp: Some(pb::StompOptions {
                        initial_trajectory: 9,
                        ..Default::default()
                    }),
                    ..Default::default()
                });
                r
            },
            "options.stomp.initial_trajectory",
        ),
    ];
    for (req, field) in cases {
        let err = planning.plan(req).await.unwrap_err();
        assert_eq!(err.code(), Code::InvalidArgument, "{field}: {}", err.message());
        assert!(
            err.message().starts_with(&format!("{field}:")),
            "{field}: {}",
            err.message()
        );
    }
}

#[tokio::test]
async fn padded_motions_plan_around_the_sphere_and_an_unbounded_robot_is_refused() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let ball = blocking_sphere(&mut robots).await;
    let mut req = request(pb::PlanAlgorithm::RrtConnect, vec![ball.clone()]);
    req.options = Some(pb::PlanOptions {
        padded_motion: true,
        ..Default::default()
    });
    let r = planning.plan(req).await.unwrap().into_inner();
    assert_eq!(r.status, pb::PlanStatus::Succeeded as i32, "{}", r.message);
    assert_path_valid(&mut planning, &[ball], r.trajectory.as_ref().unwrap(), 0.002).await;

    // a telescope on a turntable: its links can move arbitrarily far
    let telescope = r#"<robot name="t"><link name="base"/><link name="turn"/>
      <link name="tip"><collision><geometry><sphere radius="0.02"/></geometry></collision></link>
      <joint name="r" type="revolute"><parent link="base"/><child link="turn"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="0" velocity="1"/></joint>
      <joint name="p" type="prismatic"><parent link="turn"/><child link="tip"/><axis xyz="1 0 0"/>
        <limit lower="-inf" upper="inf" effort="0" velocity="1"/></joint></robot>"#;
    let req = pb::PlanRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(telescope.into())),
            ..Default::default()
        }),
        start: vec![0.0, 0.5],
        goal: Some(Goal::GoalJoints(pb::JointState {
            positions: vec![1.0, 0.5],
        })),
        scene: None,
        algorithm: pb::PlanAlgorithm::RrtConnect as i32,
        options: Some(pb::PlanOptions {
            padded_motion: true,
            ..Default::default()
        }),
        seed: 1,
    };
    let status = planning.plan(req).await.unwrap_err();
    assert_eq!(status.code(), Code::InvalidArgument, "{status:?}");
    assert!(
        status.message().starts_with("options.padded_motion"),
        "{status:?}"
    );
}

/// Regression: links off the chain — a gripper fixed beyond the tip, a
/// pedestal above the base, a built-in hand's fingers — were not part of the
/// collision model, so CheckState called states free whose gripper met an
/// obstacle. A one-joint arm `base → arm` (tip `arm`, a 0.05 × 0.05 × 0.5 m
/// box up z), a 0.1 m gripper cube centred 0.55 m up, a 0.4 m pedestal cube
/// centred 0.3 m below the base: balls placed by hand on each.
#[tokio::test]
async fn the_whole_robot_collides_in_check_state() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let urdf = r#"<robot name="whole">
      <link name="world"/>
      <link name="pedestal"><collision><origin xyz="0 0 0.2"/><geometry><box size="0.4 0.4 0.4"/></geometry></collision></link>
      <link name="base"/>
      <link name="arm"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision></link>
      <link name="gripper"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
      <joint name="w" type="fixed"><parent link="world"/><child link="pedestal"/></joint>
      <joint name="p" type="fixed"><parent link="pedestal"/><child link="base"/><origin xyz="0 0 0.5"/></joint>
      <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="flange" type="fixed"><parent link="arm"/><child link="gripper"/><origin xyz="0 0 0.5"/></joint>
    </robot>"#;
    let robot = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(urdf.into())),
        base_link: "base".into(),
        tip_link: "arm".into(),
        ..Default::default()
    });
    let check = |ball: pb::CollisionObject| pb::CheckStateRequest {
        robot: robot.clone(),
        states: vec![pb::JointState { positions: vec![0.0] }],
        scene: Some(pb::Scene { objects: vec![ball] }),
        max_distance: None,
    };
    for (what, centre) in [("gripper", [0.07, 0.0, 0.55]), ("pedestal", [0.23, 0.0, -0.3])] {
        let reply = planning
            .check_state(check(sphere("ball", centre, 0.03)))
            .await
            .unwrap()
            .into_inner();
        let state = &reply.states[0];
        assert!(!state.valid, "{what}: {state:?}");
        assert_eq!(state.colliding, [format!("{what}:ball")], "{what}");
    }
    // DescribeRobot lists every body and what carries it
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let described = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: robot.clone(),
            include_collision_bodies: true,
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    let mut bodies: Vec<(String, String)> = described
        .collision_bodies
        .iter()
        .map(|b| (b.name.clone(), b.carried_by.clone()))
        .collect();
    bodies.sort();
    let pair = |a: &str, b: &str| (a.to_string(), b.to_string());
    assert_eq!(
        bodies,
        [
            pair("arm", "arm"),
            pair("gripper", "arm"),
            pair("pedestal", "base")
        ]
    );
    // clear of everything: 0.1 m beside the gripper
    let reply = planning
        .check_state(check(sphere("ball", [0.2, 0.0, 0.55], 0.03)))
        .await
        .unwrap()
        .into_inner();
    assert!(reply.states[0].valid);

    // the built-in Panda with its hand: the fingers (closed, off the chain) collide
    let q = [0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.785];
    let fk = robots
        .forward_kinematics(pb::ForwardKinematicsRequest {
            robot: named("franka_panda_hand"),
            joint_positions: q.to_vec(),
            include_links: true,
        })
        .await
        .unwrap()
        .into_inner();
    let tool = fk.tool_pose.unwrap().position.unwrap();
    let reply = planning
        .check_state(pb::CheckStateRequest {
            robot: named("franka_panda_hand"),
            states: vec![pb::JointState {
                positions: q.to_vec(),
            }],
            scene: Some(pb::Scene {
                objects: vec![sphere("ball", [tool.x, tool.y, tool.z], 0.005)],
            }),
            max_distance: None,
        })
        .await
        .unwrap()
        .into_inner();
    let hit: Vec<&str> = reply.states[0]
        .colliding
        .iter()
        .map(|c| c.split(':').next().unwrap())
        .collect();
    assert!(
        hit.iter().any(|l| l.contains("finger")),
        "a ball between the closed fingertips touches a finger: {:?}",
        reply.states[0].colliding
    );
    // held open at their 40 mm limit, the fingers clear the 5 mm ball
    let open = |value: f64| {
        let mut robot = named("franka_panda_hand").unwrap();
        robot.held_joints = [("panda_finger_joint1", value), ("panda_finger_joint2", value)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        pb::CheckStateRequest {
            robot: Some(robot),
            states: vec![pb::JointState {
                positions: q.to_vec(),
            }],
            scene: Some(pb::Scene {
                objects: vec![sphere("ball", [tool.x, tool.y, tool.z], 0.005)],
            }),
            max_distance: None,
        }
    };
    let opened = planning.check_state(open(0.04)).await.unwrap().into_inner();
    assert!(opened.states[0].valid, "{:?}", opened.states[0]);
    let closed = planning.check_state(open(0.0)).await.unwrap().into_inner();
    assert!(!closed.states[0].valid);
}

/// A robot's own mesh files travel with its URDF: a one-joint arm whose link
/// is a cube mesh (an OBJ of the unit cube centred on the origin, scaled by
/// the URDF to 0.1 m and placed 0.25 m up the link) collides where the cube
/// is, by the model id afterwards too; a missing or broken file is an error
/// naming its URI.
#[tokio::test]
async fn mesh_files_travel_with_the_model() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let uri = "package://arm/meshes/link.obj";
    let urdf = format!(
        r#"<robot name="meshy"><link name="base"/>
          <link name="arm"><collision><origin xyz="0 0 0.25"/><geometry><mesh filename="{uri}" scale="0.1 0.1 0.1"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
            <limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>"#
    );
    let mut cube = String::new();
    for i in 0..8 {
        let c = |bit: usize| if i & bit == 0 { -0.5 } else { 0.5 };
        cube += &format!("v {} {} {}\n", c(1), c(2), c(4));
    }
    for f in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        cube += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    let with = |data: &[u8]| {
        Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(urdf.clone())),
            meshes: vec![pb::MeshFile {
                uri: uri.into(),
                data: data.to_vec(),
            }],
            ..Default::default()
        })
    };
    let check = |robot, x: f64| pb::CheckStateRequest {
        robot,
        states: vec![pb::JointState { positions: vec![0.0] }],
        scene: Some(pb::Scene {
            objects: vec![sphere("ball", [x, 0.0, 0.25], 0.02)],
        }),
        max_distance: Some(1.0),
    };
    // the cube's face at x = 0.05: a ball at 0.06 touches it, one at 0.08 is 10 mm clear
    let touching = planning
        .check_state(check(with(cube.as_bytes()), 0.06))
        .await
        .unwrap()
        .into_inner();
    assert!(!touching.states[0].valid, "{:?}", touching.states[0]);
    let clear = planning
        .check_state(check(with(cube.as_bytes()), 0.08))
        .await
        .unwrap()
        .into_inner();
    assert!(clear.states[0].valid);
    assert!(
        (clear.states[0].clearance - 0.01).abs() < 1e-6,
        "{}",
        clear.states[0].clearance
    );
    // the model id names the URDF and its meshes
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let id = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: with(cube.as_bytes()),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner()
        .model_id;
    assert_eq!(id.len(), 32);
    let by_id = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::ModelId(id)),
        ..Default::default()
    });
    let again = planning
        .check_state(check(by_id, 0.06))
        .await
        .unwrap()
        .into_inner();
    assert!(!again.states[0].valid);
    // missing and broken files name the URI
    let missing = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(urdf.clone())),
        ..Default::default()
    });
    let err = planning.check_state(check(missing, 0.06)).await.unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(
        err.message().contains(uri) && err.message().contains("RobotRef.meshes"),
        "{}",
        err.message()
    );
    let err = planning
        .check_state(check(with(b"v 0 0 nan\nf 1 1 1\n"), 0.06))
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(err.message().contains(uri), "{}", err.message());
}

/// MoveIt's SRDF comes with the URDF: its disable_collisions pairs are never
/// checked, its group names the chain and its group states come back from
/// DescribeRobot. A two-joint arm whose second link (0.6 m) reaches the base
/// box when folded back (q2 = 3 rad: its end 0.1 + 0.5 − 0.6·cos(0.14) ≈ 0.0 m
/// high, below the base's top at 0.1 m).
#[tokio::test]
async fn an_srdf_disables_pairs_names_the_chain_and_the_states() {
    let server = start(config()).await;
    let mut planning = PlanningServiceClient::new(server.channel.clone());
    let mut robots = RobotServiceClient::new(server.channel.clone());
    let urdf = r#"<robot name="folding">
      <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
      <link name="l1"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision></link>
      <link name="l2"><collision><origin xyz="0 0 0.3"/><geometry><box size="0.05 0.05 0.6"/></geometry></collision></link>
      <link name="tool"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="t" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0 0 0.6"/></joint>
    </robot>"#;
    let srdf = r#"<robot name="folding">
      <group name="arm"><chain base_link="base" tip_link="tool"/></group>
      <group name="upper"><chain base_link="base" tip_link="l1"/></group>
      <group_state name="folded" group="arm"><joint name="j1" value="0"/><joint name="j2" value="3"/></group_state>
      <disable_collisions link1="base" link2="l2" reason="Never"/>
    </robot>"#;
    let reference = |srdf: &str, group: &str| {
        Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(urdf.into())),
            srdf: srdf.into(),
            group: group.into(),
            ..Default::default()
        })
    };
    let folded = |robot| pb::CheckStateRequest {
        robot,
        states: vec![pb::JointState {
            positions: vec![0.0, 3.0],
        }],
        scene: None,
        max_distance: None,
    };
    let without = planning
        .check_state(folded(reference("", "")))
        .await
        .unwrap()
        .into_inner();
    assert!(!without.states[0].valid, "{:?}", without.states[0]);
    assert!(
        without.states[0]
            .colliding
            .iter()
            .any(|c| c.contains("base") && c.contains("l2"))
    );
    let with = planning
        .check_state(folded(reference(srdf, "")))
        .await
        .unwrap()
        .into_inner();
    assert!(with.states[0].valid, "{:?}", with.states[0]);
    // the group names the chain; the states come back as written
    let described = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: reference(srdf, "upper"),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(
        (described.base_link.as_str(), described.tip_link.as_str()),
        ("base", "l1")
    );
    assert_eq!(described.named_states.len(), 1);
    let state = &described.named_states[0];
    assert_eq!((state.name.as_str(), state.group.as_str()), ("folded", "arm"));
    assert_eq!(state.joint_names, ["j1", "j2"]);
    assert_eq!(state.positions, [0.0, 3.0]);
    // the SRDF is part of the model: another id than the URDF's alone
    let plain = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: reference("", ""),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    assert_ne!(plain.model_id, described.model_id);
    // bad input is named
    let err = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: reference(srdf, "nope"),
            ..Default::default()
        })
        .await
        .unwrap_err();
    assert!(err.message().starts_with("robot.group"), "{}", err.message());
    let err = robots
        .describe_robot(pb::DescribeRobotRequest {
            robot: reference("<robot><group_state", ""),
            ..Default::default()
        })
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument, "{err:?}");
}
