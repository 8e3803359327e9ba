//! What a `Plan` call costs over loopback gRPC on the MotionBenchMaker Panda
//! problems, beside the server's own account of its work: starts
//! `<binary> serve`, then for every valid problem of every set sends the
//! RRT-Connect request a client would send (built-in `franka_panda_hand`,
//! fingers held at their 40 mm limit, the problem's boxes and cylinders,
//! padded motions, seed = problem number) and times it with a Rust client.
//!
//! Three request shapes per problem, each sent `--passes` times (median per
//! problem, then the median over the set's solved problems):
//! - *default*: the Plan defaults (shortcutting, timing, the final check);
//! - *no random shortcuts*: `shortcut_attempts = 0`, so the server's
//!   `rrt_connect` time is the search, its proof and the greedy vertex
//!   passes;
//! - *as URDF*: the default request with the same robot sent as URDF text
//!   instead of by name, the path a user's own robot takes; with the
//!   `--user-*` flags, another URDF of the same arm (joints named as the
//!   problems name them) with the collision mesh files it names and its SRDF,
//!   e.g. example-robot-data's Panda;
//! - *by model id*: that robot named by the model id the server returned for
//!   it (`DescribeRobot`), as the clients send a URDF robot after its first
//!   call.
//!
//! Before the problems, an idle round trip on the same connection for
//! reference: `ForwardKinematics` of the same built-in robot at its zero
//! state, [`FK_CALLS`] calls (the first 100 not counted), median printed.
//!
//! Per shape: the client's wall time; the server's `timings.total` (from the
//! call's arrival in the handler to its answer: validation, conversion, the
//! model and scene lookups and builds, the planner, timing) and of it
//! `timings.rrt_connect` (search, proof and shortcuts); and the service's
//! overhead, wall minus server total per problem (HTTP/2, protobuf, the
//! hand-over to the CPU pool and back, the client). A problem whose start or
//! goal the server refuses is not valid; a valid one counts as solved when
//! every call of every shape succeeded.
//!
//! ```text
//! tar xjf ../shared/bench/mbm/panda_problems.tar.bz2 -C target/mbm
//! cargo build --release -p kinplan-server -p kinplan-loadtest --example plan_latency
//! target/release/examples/plan_latency target/release/kinplan target/mbm/problems [--passes 5] [--set box]
//! ```

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use kinplan_core::collision::{Geometry, Obstacle, SceneLimits, parse_joint_request, parse_planning_scene};
use kinplan_core::robot::{builtin_srdf, builtin_urdf};
use kinplan_loadtest::pose_msg;
use kinplan_proto as pb;
use pb::planning_service_client::PlanningServiceClient;
use pb::robot_service_client::RobotServiceClient;
use tonic::transport::{Channel, Endpoint};

// the problem sets and the arm joints of a MoveIt state, as the in-process
// MotionBenchMaker runner reads them (its collision model is not used here)
#[path = "../../../examples/common/mbm_panda.rs"]
#[allow(dead_code)]
mod mbm_panda;
use mbm_panda::{SETS, arm};

const ROBOT: &str = "franka_panda_hand";
const FINGERS: [&str; 2] = ["panda_finger_joint1", "panda_finger_joint2"];
const FINGER_OPENING: f64 = 0.04;
/// Idle round trips timed for reference.
const FK_CALLS: usize = 2000;

struct KillOnDrop(std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free loopback port")
}

struct Args {
    binary: String,
    problems: PathBuf,
    passes: usize,
    set: Option<String>,
    /// The robot the "as URDF" column sends instead of the built-in's text.
    user: Option<UserRobot>,
}

/// A robot as a user sends it: URDF text, the collision mesh files it
/// names (`package://` URIs read under a root directory), its SRDF, and
/// the chain's end links.
struct UserRobot {
    urdf: String,
    srdf: String,
    meshes: Vec<pb::MeshFile>,
    base_link: String,
    tip_link: String,
}

impl UserRobot {
    fn read(urdf: &str, srdf: &str, root: &str, base_link: &str, tip_link: &str) -> Result<Self, String> {
        let text = std::fs::read_to_string(urdf).map_err(|e| format!("{urdf}: {e}"))?;
        let mut meshes: Vec<pb::MeshFile> = Vec::new();
        for part in text.split("<collision").skip(1) {
            let part = &part[..part.find("</collision>").unwrap_or(part.len())];
            if let Some(at) = part.find("filename=\"") {
                let uri = &part[at + 10..];
                let uri = &uri[..uri.find('"').ok_or("unterminated filename")?];
                if meshes.iter().all(|m| m.uri != uri) {
                    let path = format!("{root}/{}", uri.trim_start_matches("package://"));
                    let data = std::fs::read(&path).map_err(|e| format!("{path}: {e}"))?;
                    meshes.push(pb::MeshFile {
                        uri: uri.to_string(),
                        data,
                    });
                }
            }
        }
        Ok(UserRobot {
            urdf: text,
            srdf: std::fs::read_to_string(srdf).map_err(|e| format!("{srdf}: {e}"))?,
            meshes,
            base_link: base_link.into(),
            tip_link: tip_link.into(),
        })
    }
}

fn args() -> Result<Args, String> {
    let usage = "usage: plan_latency <kinplan binary> <problems dir> [--passes N] [--set NAME] \
                 [--user-urdf PATH --user-srdf PATH --package-root DIR --user-base LINK --user-tip LINK]";
    let mut it = std::env::args().skip(1);
    let binary = it.next().ok_or(usage)?;
    let problems = PathBuf::from(it.next().ok_or(usage)?);
    let (mut passes, mut set) = (5, None);
    let mut user: HashMap<String, String> = HashMap::new();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(usage)?;
        match flag.as_str() {
            "--passes" => passes = value.parse().map_err(|_| "--passes: a count")?,
            "--set" => set = Some(value),
            "--user-urdf" | "--user-srdf" | "--package-root" | "--user-base" | "--user-tip" => {
                user.insert(flag, value);
            }
            _ => return Err(usage.into()),
        }
    }
    let user = match user.len() {
        0 => None,
        5 => Some(UserRobot::read(
            &user["--user-urdf"],
            &user["--user-srdf"],
            &user["--package-root"],
            &user["--user-base"],
            &user["--user-tip"],
        )?),
        _ => return Err(usage.into()),
    };
    Ok(Args {
        binary,
        problems,
        passes: passes.max(1),
        set,
        user,
    })
}

/// A MotionBenchMaker obstacle as the client sends it (boxes, spheres,
/// cylinders: all these scenes hold).
fn object(o: &Obstacle) -> Result<pb::CollisionObject, String> {
    use pb::collision_object::Shape;
    let shape = match &o.geometry {
        Geometry::Box { half_extents: h } => Shape::Box(pb::Box {
            size: Some(pb::Vec3 {
                x: 2.0 * h.x,
                y: 2.0 * h.y,
                z: 2.0 * h.z,
            }),
        }),
        Geometry::Sphere { radius } => Shape::Sphere(pb::Sphere { radius: *radius }),
        Geometry::Cylinder { radius, length } => Shape::Cylinder(pb::Cylinder {
            radius: *radius,
            length: *length,
        }),
        other => return Err(format!("{}: unexpected shape {other:?}", o.name)),
    };
    Ok(pb::CollisionObject {
        id: o.name.clone(),
        pose: Some(pose_msg(&o.pose)),
        shape: Some(shape),
        unknown_as_obstacle: false,
    })
}

fn robot_ref(as_urdf: bool, user: Option<&UserRobot>) -> pb::RobotRef {
    if let (true, Some(u)) = (as_urdf, user) {
        return pb::RobotRef {
            source: Some(pb::robot_ref::Source::Urdf(u.urdf.clone())),
            base_link: u.base_link.clone(),
            tip_link: u.tip_link.clone(),
            held_joints: FINGERS
                .iter()
                .map(|f| (f.to_string(), FINGER_OPENING))
                .collect::<HashMap<_, _>>(),
            srdf: u.srdf.clone(),
            meshes: u.meshes.clone(),
            ..Default::default()
        };
    }
    let source = if as_urdf {
        pb::robot_ref::Source::Urdf(builtin_urdf(ROBOT).expect("built-in URDF").to_string())
    } else {
        pb::robot_ref::Source::Name(ROBOT.into())
    };
    pb::RobotRef {
        source: Some(source),
        base_link: if as_urdf {
            "base_link".into()
        } else {
            String::new()
        },
        tip_link: if as_urdf {
            "panda_hand_tcp".into()
        } else {
            String::new()
        },
        held_joints: FINGERS
            .iter()
            .map(|f| (f.to_string(), FINGER_OPENING))
            .collect::<HashMap<_, _>>(),
        // as a MoveIt user sends the robot: with its SRDF (designed contacts)
        srdf: if as_urdf {
            builtin_srdf(ROBOT).expect("built-in SRDF").to_string()
        } else {
            String::new()
        },
        ..Default::default()
    }
}

/// One problem as a Plan request; `shortcuts` overrides the default attempts.
fn request(
    robot: pb::RobotRef,
    scene: &pb::Scene,
    start: &[f64],
    goal: &[f64],
    seed: u64,
    shortcuts: Option<u32>,
) -> pb::PlanRequest {
    pb::PlanRequest {
        robot: Some(robot),
        start: start.to_vec(),
        goal: Some(pb::plan_request::Goal::GoalJoints(pb::JointState {
            positions: goal.to_vec(),
        })),
        scene: Some(scene.clone()),
        algorithm: pb::PlanAlgorithm::RrtConnect as i32,
        options: Some(pb::PlanOptions {
            padded_motion: true,
            rrt_connect: Some(pb::RrtConnectOptions {
                shortcut_attempts: shortcuts,
                ..Default::default()
            }),
            ..Default::default()
        }),
        seed,
    }
}

/// Per problem: median wall (µs), median server total (µs), median server
/// RRT-Connect time (µs); `None` when the plan did not succeed.
async fn time_request(
    client: &mut PlanningServiceClient<Channel>,
    req: &pb::PlanRequest,
    passes: usize,
) -> Result<Option<[f64; 3]>, tonic::Status> {
    let (mut wall, mut total, mut rrt) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..passes {
        let sent = req.clone();
        let started = Instant::now();
        let answer = client.plan(sent).await?.into_inner();
        wall.push(started.elapsed().as_secs_f64() * 1e6);
        if std::env::var_os("PLAN_LATENCY_DEBUG").is_some() {
            use pb::prost::Message;
            eprintln!(
                "wall {:.0} total {:.0} bytes {} points {}",
                wall.last().unwrap(),
                answer.timings.unwrap_or_default().total * 1e6,
                answer.encoded_len(),
                answer.trajectory.as_ref().map_or(0, |t| t.points.len())
            );
        }
        if answer.status != pb::PlanStatus::Succeeded as i32 {
            eprintln!("problem {}: {}", req.seed, answer.message);
            return Ok(None);
        }
        let t = answer.timings.unwrap_or_default();
        total.push(t.total * 1e6);
        rrt.push(t.rrt_connect * 1e6);
    }
    Ok(Some([median(&mut wall), median(&mut total), median(&mut rrt)]))
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

async fn connect(port: u16) -> Result<Channel, Box<dyn std::error::Error>> {
    let endpoint = Endpoint::from_shared(format!("http://127.0.0.1:{port}"))?.tcp_nodelay(true);
    for _ in 0..100 {
        if let Ok(c) = endpoint.connect().await {
            return Ok(c);
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    Err("the server did not start".into())
}

/// A set's problems: (number, scene, start, goal), valid or not.
type Problem = (u64, pb::Scene, Vec<f64>, Vec<f64>);

fn load_set(dir: &Path) -> Result<Vec<Problem>, Box<dyn std::error::Error>> {
    let mut out = Vec::new();
    for k in 1..=100u64 {
        let scene_path = dir.join(format!("scene{k:04}.yaml"));
        if !scene_path.exists() {
            continue;
        }
        let scene = parse_planning_scene(&std::fs::read_to_string(&scene_path)?, &SceneLimits::default())?;
        let joints = parse_joint_request(&std::fs::read_to_string(dir.join(format!("request{k:04}.yaml")))?)?;
        let objects = scene.obstacles().iter().map(object).collect::<Result<_, _>>()?;
        let (start, goal) = (arm(&joints.start, "start")?, arm(&joints.goal, "goal")?);
        out.push((k, pb::Scene { objects }, start, goal));
    }
    Ok(out)
}

#[tokio::main(flavor = "current_thread")]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = args()?;
    let port = free_port();
    let _server = KillOnDrop(
        std::process::Command::new(&a.binary)
            .args(["serve", "--listen", &format!("127.0.0.1:{port}")])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()?,
    );
    let channel = connect(port).await?;
    let mut robot = RobotServiceClient::new(channel.clone());
    let fk = pb::ForwardKinematicsRequest {
        robot: Some(robot_ref(false, None)),
        joint_positions: vec![0.0; 7],
        include_links: false,
    };
    let mut round_trips = Vec::with_capacity(FK_CALLS);
    for i in 0..FK_CALLS + 100 {
        let sent = fk.clone();
        let started = Instant::now();
        robot.forward_kinematics(sent).await?;
        if i >= 100 {
            round_trips.push(started.elapsed().as_secs_f64() * 1e6);
        }
    }
    println!(
        "idle round trip (ForwardKinematics, {FK_CALLS} calls, same connection): median {:.0} µs\n",
        median(&mut round_trips)
    );
    // the user's robot as the clients name it after the first call
    let described = robot
        .describe_robot(pb::DescribeRobotRequest {
            robot: Some(robot_ref(true, a.user.as_ref())),
            ..Default::default()
        })
        .await?
        .into_inner();
    let by_id = pb::RobotRef {
        source: Some(pb::robot_ref::Source::ModelId(described.model_id)),
        srdf: String::new(),
        meshes: Vec::new(),
        ..robot_ref(true, a.user.as_ref())
    };
    let mut client = PlanningServiceClient::new(channel);
    println!(
        "| set | solved / valid | default: wall | server total | of which RRT-Connect | overhead | no random shortcuts: wall | server RRT-Connect | overhead | as URDF: wall | URDF / name | by model id: wall | id / name |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let us = |v: f64| format!("{v:.0} µs");
    for set in SETS {
        if a.set.as_deref().is_some_and(|s| s != set) {
            continue;
        }
        let problems = load_set(&a.problems.join(format!("{set}_panda")))?;
        // default wall, total, RRT-Connect, overhead; no-random-shortcut wall,
        // RRT-Connect, overhead; as-URDF wall; by-model-id wall
        let mut cols: [Vec<f64>; 9] = Default::default();
        let (mut valid, mut solved) = (0, 0);
        for (k, scene, start, goal) in &problems {
            let by_name = request(robot_ref(false, None), scene, start, goal, *k, None);
            // Warm: the model and scene caches, as a client's second call finds them.
            let first = client.plan(by_name.clone()).await?.into_inner();
            let status = pb::PlanStatus::try_from(first.status).unwrap_or_default();
            if matches!(status, pb::PlanStatus::InvalidStart | pb::PlanStatus::InvalidGoal) {
                continue;
            }
            valid += 1;
            let search = request(robot_ref(false, None), scene, start, goal, *k, Some(0));
            let urdf = request(robot_ref(true, a.user.as_ref()), scene, start, goal, *k, None);
            let named = request(by_id.clone(), scene, start, goal, *k, None);
            client.plan(urdf.clone()).await?;
            let d = time_request(&mut client, &by_name, a.passes).await?;
            let s = time_request(&mut client, &search, a.passes).await?;
            let u = time_request(&mut client, &urdf, a.passes).await?;
            let i = time_request(&mut client, &named, a.passes).await?;
            if let (Some(d), Some(s), Some(u), Some(i)) = (d, s, u, i) {
                solved += 1;
                let row = [d[0], d[1], d[2], d[0] - d[1], s[0], s[2], s[0] - s[1], u[0], i[0]];
                for (col, v) in cols.iter_mut().zip(row) {
                    col.push(v);
                }
            }
        }
        let [dw, dt, dr, dover, sw, sr, sover, uw, iw] = cols.each_mut().map(|c| median(c));
        println!(
            "| {set} | {solved} / {valid} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2}× | {} | {:.2}× |",
            us(dw),
            us(dt),
            us(dr),
            us(dover),
            us(sw),
            us(sr),
            us(sover),
            us(uw),
            uw / dw,
            us(iw),
            iw / dw,
        );
    }
    Ok(())
}
