//! A bounded property test: hostile but well-formed requests — NaN,
//! ±inf, 1e308, 5e-324, huge counts, empty and oversized fields, forged
//! tokens — at every RPC of one real in-process server. For each: no panic
//! (the server keeps answering), no INTERNAL (so no non-finite number reached
//! an OK reply: the reply check turns those into INTERNAL), no UNKNOWN, and an
//! answer within the deadline. CI fixes the seed (PROPTEST_RNG_SEED).

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, exploration_service_client::ExplorationServiceClient,
    kinematics_service_client::KinematicsServiceClient, mobile_service_client::MobileServiceClient,
    planning_service_client::PlanningServiceClient, robot_service_client::RobotServiceClient,
    scoring_service_client::ScoringServiceClient,
};
use proptest::prelude::*;
use tonic::Code;
use tonic::transport::Channel;

use crate::{TestServer, named, start};

/// The server's default deadline in this test; answers must come within it
/// (plus scheduling slack on a loaded machine).
const DEADLINE: Duration = Duration::from_millis(500);

struct Shared {
    runtime: tokio::runtime::Runtime,
    server: TestServer,
}

fn shared() -> &'static Shared {
    static SHARED: OnceLock<Shared> = OnceLock::new();
    SHARED.get_or_init(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .unwrap();
        let server = runtime.block_on(start(ServerConfig {
            request_timeout: Some(DEADLINE),
            cpu_threads: 2,
            ..ServerConfig::default()
        }));
        Shared { runtime, server }
    })
}

fn channel() -> Channel {
    shared().server.channel.clone()
}

fn hostile_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(1e308),
        Just(-1e308),
        Just(5e-324),
        Just(1e-300),
        Just(0.0),
        Just(-0.0),
        Just(1e6),
        -10.0..10.0f64,
    ]
}

fn hostile_u32() -> impl Strategy<Value = u32> {
    prop_oneof![Just(0u32), Just(1), Just(u32::MAX), Just(1_000_000_000), 0..64u32]
}

fn vec3(v: [f64; 3]) -> Option<pb::Vec3> {
    Some(pb::Vec3 {
        x: v[0],
        y: v[1],
        z: v[2],
    })
}

fn pose(v: [f64; 7]) -> Option<pb::Pose> {
    Some(pb::Pose {
        position: vec3([v[0], v[1], v[2]]),
        orientation: Some(pb::Quaternion {
            w: v[3],
            x: v[4],
            y: v[5],
            z: v[6],
        }),
    })
}

fn differential() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Differential(Default::default())),
    })
}

/// Checks one answer: any code but INTERNAL / UNKNOWN / CANCELLED, in time.
fn judge<T>(what: &str, started: Instant, answer: Result<T, tonic::Status>) -> Result<(), TestCaseError> {
    let took = started.elapsed();
    prop_assert!(
        took < DEADLINE + Duration::from_millis(1500),
        "{what}: answered after {took:?}"
    );
    if let Err(status) = answer {
        prop_assert!(
            !matches!(status.code(), Code::Internal | Code::Unknown | Code::Cancelled),
            "{what}: {:?} {}",
            status.code(),
            status.message()
        );
    }
    Ok(())
}

#[derive(Debug, Clone)]
struct Values {
    f: Vec<f64>,
    n: Vec<u32>,
    token: Vec<u8>,
    robot: usize,
}

fn values() -> impl Strategy<Value = Values> {
    (
        proptest::collection::vec(hostile_f64(), 24),
        proptest::collection::vec(hostile_u32(), 8),
        prop_oneof![
            Just(Vec::new()),
            Just(br#"{"mode":"Track","steps_in_mode":18446744073709551615}"#.to_vec()),
            Just(b"{not json".to_vec()),
            Just(br#"{"target":18446744073709551615,"segment":0}"#.to_vec()),
            proptest::collection::vec(any::<u8>(), 0..64),
        ],
        0usize..4,
    )
        .prop_map(|(f, n, token, robot)| Values { f, n, token, robot })
}

const ROBOTS: [&str; 4] = ["ur5", "planar_2", "kuka_kr210_r2700_extra", "no_such_robot"];

async fn every_rpc(v: Values) -> Result<(), TestCaseError> {
    let f = &v.f;
    let robot = named(ROBOTS[v.robot]);
    let joints: Vec<f64> = f[..(v.n[0] as usize % 8)].to_vec();
    let mut robots = RobotServiceClient::new(channel());
    let mut ik = KinematicsServiceClient::new(channel());
    let mut scoring = ScoringServiceClient::new(channel());
    let mut mobile = MobileServiceClient::new(channel());

    let t = Instant::now();
    judge(
        "ListRobots",
        t,
        robots.list_robots(pb::ListRobotsRequest {}).await,
    )?;
    let t = Instant::now();
    let urdf = format!(
        r#"<robot name="h"><link name="a"/><link name="b"/><joint name="j" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="{} {} 0"/><axis xyz="{} {} {}"/><limit lower="{}" upper="{}" effort="1" velocity="{}"/></joint></robot>"#,
        f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]
    );
    let inline = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(urdf)),
        ..Default::default()
    });
    judge(
        "DescribeRobot",
        t,
        robots
            .describe_robot(pb::DescribeRobotRequest {
                robot: inline.clone(),
                ..Default::default()
            })
            .await,
    )?;
    for r in [robot.clone(), inline.clone()] {
        let t = Instant::now();
        let fk = pb::ForwardKinematicsRequest {
            robot: r.clone(),
            joint_positions: joints.clone(),
            include_links: v.n[1].is_multiple_of(2),
        };
        judge("ForwardKinematics", t, robots.forward_kinematics(fk).await)?;
        let t = Instant::now();
        let jac = pb::JacobianRequest {
            robot: r.clone(),
            joint_positions: joints.clone(),
        };
        judge("Jacobian", t, robots.jacobian(jac).await)?;
    }

    let options = Some(pb::IkOptions {
        method: (v.n[2] % 8) as i32,
        linear_solver: (v.n[3] % 5) as i32,
        position_tolerance: Some(f[8]),
        max_iterations: v.n[4] % 10_000,
        damping: Some(f[9]),
        max_step: Some(f[10]),
        max_restarts: Some(v.n[5]),
        num_solutions: v.n[6] % 4,
        time_budget: Some(f[11].abs().min(0.05)),
        rlxa_max_iterations: Some(v.n[7]),
        position_only: v.n[1].is_multiple_of(3),
        ..Default::default()
    });
    let target = pose([f[12], f[13], f[14], f[15], f[16], f[17], f[18]]);
    let t = Instant::now();
    let solve = pb::SolveIkRequest {
        robot: robot.clone(),
        target,
        seed: joints.clone(),
        options,
    };
    judge("SolveIk", t, ik.solve_ik(solve).await)?;
    let t = Instant::now();
    let batch = pb::SolveIkBatchRequest {
        seeds: None,
        robot: robot.clone(),
        targets: vec![target.unwrap_or_default(); (v.n[0] % 5) as usize],
        seed: joints.clone(),
        options,
    };
    judge("SolveIkBatch", t, ik.solve_ik_batch(batch).await)?;
    let t = Instant::now();
    let track = pb::TrackPathRequest {
        robot: robot.clone(),
        line: Some(pb::LinePath {
            start: None,
            end: target,
            steps: v.n[4],
        }),
        options,
        ..Default::default()
    };
    judge("TrackPath", t, ik.track_path(track).await)?;
    let t = Instant::now();
    let (tx, rx) = tokio::sync::mpsc::channel(4);
    let _ = tx
        .send(pb::StreamIkRequest {
            sequence: v.n[0] as u64,
            robot: robot.clone(),
            options,
            target,
            seed: joints.clone(),
        })
        .await;
    let _ = tx
        .send(pb::StreamIkRequest {
            sequence: u64::MAX,
            target: pose([f[19], f[20], f[21], 1.0, 0.0, 0.0, 0.0]),
            ..Default::default()
        })
        .await;
    drop(tx);
    match ik
        .stream_ik(tokio_stream::wrappers::ReceiverStream::new(rx))
        .await
    {
        Ok(answers) => {
            let mut answers = answers.into_inner();
            loop {
                match answers.message().await {
                    Ok(Some(_)) => continue,
                    Ok(None) => break,
                    Err(e) => {
                        judge::<()>("StreamIk", t, Err(e))?;
                        break;
                    }
                }
            }
        }
        Err(e) => judge::<()>("StreamIk", t, Err(e))?,
    }
    let t = Instant::now();
    let (rows, cols) = (v.n[1] % 4 + 1, v.n[2] % 4 + 1);
    let linear = pb::SolveLinearSystemRequest {
        a: Some(pb::Matrix {
            rows,
            cols,
            data: f.iter().cycle().take((rows * cols) as usize).copied().collect(),
        }),
        b: f[3..3 + rows as usize].to_vec(),
        method: (v.n[3] % 4) as i32,
        max_iterations: v.n[5],
        tolerance: Some(f[22]),
        record_history: v.n[6].is_multiple_of(2),
        ..Default::default()
    };
    judge("SolveLinearSystem", t, ik.solve_linear_system(linear).await)?;

    let points = |n: usize| -> Vec<pb::JointPoint> {
        (0..n)
            .map(|k| pb::JointPoint {
                positions: joints.iter().map(|q| q + 0.01 * k as f64).collect(),
                time_from_start: f[23] * k as f64,
                ..Default::default()
            })
            .collect()
    };
    let trajectory = pb::JointTrajectory {
        points: points((v.n[4] % 40) as usize),
        ..Default::default()
    };
    let score_options = Some(pb::ScoreOptions {
        max_velocity: f[..(v.n[6] % 7) as usize].to_vec(),
        joint_weights: f[7..7 + (v.n[7] % 7) as usize].to_vec(),
        robot_points: (v.n[0] % 4) as i32,
        ..Default::default()
    });
    let t = Instant::now();
    let score = pb::ScoreTrajectoryRequest {
        robot: robot.clone(),
        trajectory: Some(trajectory.clone()),
        options: score_options.clone(),
    };
    judge("ScoreTrajectory", t, scoring.score_trajectory(score).await)?;
    let t = Instant::now();
    let compare = pb::CompareTrajectoriesRequest {
        robot: robot.clone(),
        sets: vec![pb::TrajectorySet {
            label: "a".into(),
            trajectories: vec![trajectory.clone(); (v.n[1] % 3) as usize],
        }],
        options: score_options,
    };
    judge(
        "CompareTrajectories",
        t,
        scoring.compare_trajectories(compare).await,
    )?;

    let twist = pb::Twist2D {
        vx: f[0],
        vy: f[1],
        omega: f[2],
    };
    let t = Instant::now();
    let wheels = pb::WheelKinematicsRequest {
        chassis: differential(),
        input: Some(pb::wheel_kinematics_request::Input::Twist(twist)),
    };
    judge("WheelKinematics", t, mobile.wheel_kinematics(wheels).await)?;
    let state = Some(pb::Pose2D {
        x: f[3],
        y: f[4],
        theta: f[5],
    });
    let world = vec![pb::Obstacle {
        shape: Some(pb::obstacle::Shape::Circle(pb::Circle {
            center: Some(pb::Point2D { x: f[6], y: f[7] }),
            radius: f[8],
        })),
    }];
    let path = vec![
        pb::PathNode {
            x: f[9],
            y: f[10],
            heading: None,
        },
        pb::PathNode {
            x: f[11],
            y: f[12],
            heading: Some(f[13]),
        },
    ];
    let goal = Some(pb::Point2D { x: f[14], y: f[15] });
    for controller in 0..4 {
        let t = Instant::now();
        let step = pb::ControlStepRequest {
            chassis: differential(),
            state,
            controller,
            path: path.clone(),
            goal,
            readings: f[..(v.n[2] % 10) as usize].to_vec(),
            world: if v.n[3].is_multiple_of(2) {
                world.clone()
            } else {
                Vec::new()
            },
            dt: Some(f[16]),
            state_token: v.token.clone(),
            ..Default::default()
        };
        judge("ControlStep", t, mobile.control_step(step).await)?;
    }
    let sim = Some(pb::SimOptions {
        robot_radius: Some(f[17]),
        dt: Some(f[18].abs().max(0.01)),
        max_time: Some(f[19].abs().min(5.0)),
    });
    let t = Instant::now();
    let follow = pb::FollowPathRequest {
        chassis: differential(),
        start: state,
        path: path.clone(),
        world: world.clone(),
        sim,
        ..Default::default()
    };
    judge("FollowPath", t, mobile.follow_path(follow).await)?;
    for navigator in 0..3 {
        let t = Instant::now();
        let nav = pb::NavigateRequest {
            chassis: differential(),
            start: state,
            goal,
            world: world.clone(),
            sim,
            navigator,
            ..Default::default()
        };
        judge("Navigate", t, mobile.navigate(nav).await)?;
    }
    Ok(())
}

/// A value no physical field accepts: not finite, beyond ±1e6 or subnormal.
fn absurd(v: f64) -> bool {
    !v.is_finite() || v.abs() > 1e6 || (v != 0.0 && v.abs() < f64::MIN_POSITIVE)
}

/// [`judge`], and the answer must be an error when the request held an absurd
/// value in a physical field.
fn judge_refused<T>(
    what: &str,
    started: Instant,
    must_refuse: bool,
    answer: Result<T, tonic::Status>,
) -> Result<(), TestCaseError> {
    let refused = answer.is_err();
    judge(what, started, answer)?;
    prop_assert!(!must_refuse || refused, "{what}: OK for an absurd value");
    Ok(())
}

/// Values for the planning and exploration requests: every field valid but one,
/// `slot`, which takes the hostile value `f[slot]` (with `slot ≥ 24` every field
/// is valid, so the valid paths run too).
struct OneHostile<'a> {
    f: &'a [f64],
    slot: usize,
}

impl OneHostile<'_> {
    /// Field `i`'s value: hostile when `i` is the chosen slot, else `valid`.
    fn at(&self, i: usize, valid: f64) -> f64 {
        if i == self.slot { self.f[i] } else { valid }
    }

    /// Whether field `i` is the hostile one and its value is absurd.
    fn absurd_at(&self, i: usize) -> bool {
        i == self.slot && absurd(self.f[i])
    }

    fn any_absurd(&self, fields: std::ops::Range<usize>) -> bool {
        fields.into_iter().any(|i| self.absurd_at(i))
    }
}

/// A scene (slots 0–9): a box with a hostile pose or size, and the tetrahedron and
/// sphere that a UR5 at `[0, −1.5, 1.5, 0, 0, 0]` penetrates, in either order.
fn scene(h: &OneHostile<'_>, swap: bool) -> pb::Scene {
    let at = [-0.4223, -0.1914, 0.4184, 1.0, 0.0, 0.0, 0.0];
    let object = |shape| pb::CollisionObject {
        id: "o".into(),
        pose: pose(at),
        shape: Some(shape),
        unknown_as_obstacle: false,
    };
    let tetra = pb::collision_object::Shape::Mesh(pb::TriangleMesh {
        vertices: [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]
            .iter()
            .map(|p| vec3(*p).unwrap())
            .collect(),
        indices: vec![0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3],
    });
    let sphere = pb::collision_object::Shape::Sphere(pb::Sphere { radius: 0.05 });
    let valid = [1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.1];
    let v: Vec<f64> = (0..10).map(|i| h.at(i, valid[i])).collect();
    let hostile_box = pb::CollisionObject {
        id: "box".into(),
        pose: pose([v[0], v[1], v[2], v[3], v[4], v[5], v[6]]),
        shape: Some(pb::collision_object::Shape::Box(pb::Box {
            size: vec3([v[7], v[8], v[9]]),
        })),
        unknown_as_obstacle: false,
    };
    let mut objects = vec![object(tetra), object(sphere), hostile_box];
    if swap {
        objects.swap(0, 1);
    }
    pb::Scene { objects }
}

async fn planning_and_exploration(v: Values) -> Result<(), TestCaseError> {
    let h = OneHostile {
        f: &v.f,
        slot: (v.n[7] % 32) as usize,
    };
    let swap = v.n[0].is_multiple_of(2);
    let ur5 = [0.0, -1.5, 1.5, 0.0, 0.0, 0.0];
    let free = [1.0, -1.2, 1.0, 0.0, 0.0, 0.0];
    let mut planning = PlanningServiceClient::new(channel());
    let mut exploration = ExplorationServiceClient::new(channel());
    // a bad orientation of the box (slots 3–6, w x y z) is absurd, or of no
    // unit norm unless all zero (an unset quaternion is the identity)
    let orientation: Vec<f64> = (3..7).map(|i| h.at(i, if i == 3 { 1.0 } else { 0.0 })).collect();
    let norm = orientation.iter().map(|c| c * c).sum::<f64>().sqrt();
    let unset = orientation.iter().all(|c| *c == 0.0);
    let unit = (norm - 1.0).abs() <= 1e-6; // false for a NaN norm
    let bad_scene = h.any_absurd(0..10)
        || ((3..7).contains(&h.slot) && !unset && !unit)
        || ((7..10).contains(&h.slot) && h.f[h.slot] <= 0.0);

    // CheckState: the penetrating pair in either order, one hostile value
    let t = Instant::now();
    let state: Vec<f64> = (0..6).map(|i| h.at(10 + i, ur5[i])).collect();
    let check = pb::CheckStateRequest {
        robot: named("ur5"),
        states: vec![
            pb::JointState {
                positions: ur5.to_vec(),
            },
            pb::JointState { positions: state },
        ],
        scene: Some(scene(&h, swap)),
        max_distance: Some(h.at(16, 0.5)),
    };
    let bad = bad_scene || h.any_absurd(10..17) || (h.slot == 16 && h.f[16] <= 0.0);
    judge_refused("CheckState", t, bad, planning.check_state(check).await)?;

    // Plan and PlanStream: every algorithm, one hostile start, goal or option
    let options = pb::PlanOptions {
        stomp: Some(pb::StompOptions {
            timesteps: Some(v.n[2] % 12_000),
            rollouts: Some(v.n[3] % 40),
            max_iterations: Some(v.n[4] % 50),
            cost_sensitivity: Some(h.at(17, 10.0)),
            ..Default::default()
        }),
        rrt_connect: Some(pb::RrtConnectOptions {
            range: Some(h.at(18, 0.3)),
            max_samples: Some(v.n[6] % 5_000),
            shortcut_attempts: Some(v.n[5] % 100),
        }),
        motion_resolution: Some(h.at(19, 0.05)),
        time_budget: Some(h.at(20, 0.05)),
        padded_motion: v.n[1].is_multiple_of(3),
        ..Default::default()
    };
    let goal = if v.n[2].is_multiple_of(2) {
        pb::plan_request::Goal::GoalJoints(pb::JointState {
            positions: (0..6)
                .map(|i| if i == 0 { h.at(21, free[0]) } else { free[i] })
                .collect(),
        })
    } else {
        let q = [h.at(22, 0.0), 1.0, 0.0, 0.0];
        pb::plan_request::Goal::GoalPose(pose([0.4, 0.1, h.at(23, 0.4), q[0], q[1], q[2], q[3]]).unwrap())
    };
    let plan = pb::PlanRequest {
        robot: named("ur5"),
        start: free.iter().map(|q| -q).collect(),
        goal: Some(goal),
        scene: Some(pb::Scene {
            objects: scene(&h, swap).objects[2..].to_vec(),
        }),
        algorithm: (v.n[4] % 4) as i32,
        options: Some(options),
        seed: v.n[5] as u64,
    };
    let bad = h.any_absurd(0..10) || h.any_absurd(17..24);
    let t = Instant::now();
    judge_refused("Plan", t, bad, planning.plan(plan.clone()).await)?;
    let t = Instant::now();
    let answer = match planning.plan_stream(plan).await {
        Ok(frames) => drain(frames.into_inner()).await,
        Err(e) => Err(e),
    };
    judge_refused("PlanStream", t, bad, answer)?;

    // the octree RPCs: one hostile resolution, point, pose, box or camera value
    let octree = Some(pb::Octree {
        id: if v.n[6].is_multiple_of(5) {
            "ColorOcTree"
        } else {
            "OcTree"
        }
        .into(),
        resolution: h.at(0, 0.1),
        binary: true,
        data: if v.n[0].is_multiple_of(3) {
            Vec::new()
        } else {
            vec![0x66, 0x66]
        },
    });
    let bad_tree = h.absurd_at(0);
    let bbox = Some(pb::BoundingBox {
        min: vec3([h.at(1, -1.0), h.at(2, -1.0), h.at(3, -1.0)]),
        max: vec3([h.at(4, 1.0), h.at(5, 1.0), h.at(6, 1.0)]),
    });
    let t = Instant::now();
    let info = pb::OctreeInfoRequest {
        octree: octree.clone(),
        r#box: if v.n[1].is_multiple_of(2) { bbox } else { None },
    };
    let bad = bad_tree || (v.n[1].is_multiple_of(2) && h.any_absurd(1..7));
    judge_refused("OctreeInfo", t, bad, exploration.octree_info(info).await)?;
    let t = Instant::now();
    let scan = pb::InsertScanRequest {
        octree: if v.n[2].is_multiple_of(2) {
            octree.clone()
        } else {
            None
        },
        resolution: h.at(7, 0.1),
        sensor_pose: pose([h.at(8, 0.0), h.at(9, 0.0), h.at(10, 0.0), 1.0, 0.0, 0.0, 0.0]),
        scan: Some(pb::insert_scan_request::Scan::Points(pb::PointCloud {
            xyz: (11..17).map(|i| h.at(i, 1.0 + i as f64 / 10.0) as f32).collect(),
        })),
        max_range: Some(h.at(17, -1.0)),
        discretize: v.n[4].is_multiple_of(2),
        full: false,
        near_ray_spacing: 0.0,
    };
    let bad = h.any_absurd(8..11) || h.absurd_at(17) || (v.n[2].is_multiple_of(2) && bad_tree);
    judge_refused("InsertScan", t, bad, exploration.insert_scan(scan).await)?;
    let t = Instant::now();
    let nbv = pb::NextBestViewRequest {
        octree: octree.clone(),
        camera: Some(pb::CameraModel {
            horizontal_fov: Some(h.at(18, 1.2)),
            width: Some(v.n[5] % 100),
            height: Some(v.n[6] % 100),
            ..Default::default()
        }),
        camera_pose: pose([h.at(19, 0.0), h.at(20, 0.0), h.at(21, 1.0), 1.0, 0.0, 0.0, 0.0]),
        robot: if v.n[3].is_multiple_of(2) {
            named("ur5")
        } else {
            None
        },
        options: Some(pb::NbvOptions {
            region: bbox,
            ..Default::default()
        }),
        ..Default::default()
    };
    let bad = bad_tree || h.any_absurd(1..7) || h.any_absurd(18..22);
    judge_refused("NextBestView", t, bad, exploration.next_best_view(nbv).await)?;
    let t = Instant::now();
    let explore = pb::ExploreRequest {
        robot: named("ur5"),
        start: free.to_vec(),
        scene: Some(pb::Scene {
            objects: scene(&h, swap).objects[2..].to_vec(),
        }),
        region: bbox,
        resolution: Some(h.at(22, 0.1)),
        stop: Some(pb::ExploreStopRule {
            max_iterations: Some(v.n[0] % 3),
            ..Default::default()
        }),
        plan_time_budget: Some(h.at(23, 0.05)),
        ..Default::default()
    };
    let bad = h.any_absurd(0..7) || h.any_absurd(22..24);
    let answer = match exploration.explore(explore).await {
        Ok(steps) => drain(steps.into_inner()).await,
        Err(e) => Err(e),
    };
    judge_refused("Explore", t, bad, answer)
}

/// Reads a reply stream to its end: the first error, or OK.
async fn drain<T>(mut stream: tonic::Streaming<T>) -> Result<(), tonic::Status> {
    while stream.message().await?.is_some() {}
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// The planning and exploration RPCs answer hostile values with a
    /// considered status, in time, and never OK for an absurd physical value.
    #[test]
    fn hostile_values_at_every_planning_and_exploration_rpc(v in values()) {
        shared().runtime.block_on(planning_and_exploration(v))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Every RPC answers hostile values with a considered status, in time.
    #[test]
    fn hostile_values_at_every_rpc(v in values()) {
        shared().runtime.block_on(every_rpc(v))?;
    }
}
