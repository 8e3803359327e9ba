//! The typed client against a real server (started in-process on a free
//! loopback port): results checked against hand-derived kinematics, finite
//! differences and round trips; errors checked for their gRPC codes and the
//! field they name.

use std::time::Duration;

use kinplan_client::{
    Algorithm, Client, Code, Goal, IkMethod, IkOptions, Obstacle, PlanSettings, PlanStatus, Shape,
};
use kinplan_server::{ServerConfig, serve};
use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

const KR210: &str = "kuka_kr210_r2700_extra";

/// A planar two-link arm: shoulder at height 0.5 about z, upper arm 0.4 m,
/// the tool at the elbow's frame (so FK is hand-computable).
const TWO_LINK_URDF: &str = r#"<robot name="two_link">
  <link name="base"/><link name="upper"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
</robot>"#;

struct Server {
    address: String,
    _stop: tokio::sync::oneshot::Sender<()>,
}

async fn server() -> Server {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let config = ServerConfig {
        acm_samples: 300,
        ..ServerConfig::default()
    };
    tokio::spawn(async move {
        serve(config, listener, async {
            let _ = stopped.await;
        })
        .await
        .unwrap();
    });
    Server { address, _stop: stop }
}

fn distance(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let dr = a.rotation.angle_to(&b.rotation);
    (dp, dr)
}

#[tokio::test]
async fn fk_of_an_inline_urdf_matches_the_hand_computation() {
    let s = server().await;
    let client = Client::connect(&s.address).await.unwrap();
    let robot = client.robot_from_urdf(TWO_LINK_URDF);
    let (a, b) = (0.3_f64, 0.9_f64);
    let pose = robot.fk(&[a, b]).await.unwrap();
    // the tool frame sits at the elbow: 0.4 m along the upper arm, turned by a + b
    let expected = Isometry3::from_parts(
        Translation3::new(0.4 * a.cos(), 0.4 * a.sin(), 0.5),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a + b),
    );
    let (dp, dr) = distance(&pose, &expected);
    assert!(dp < 1e-12 && dr < 1e-9, "{pose} vs {expected}");
    // the hash came back and is used from now on
    assert!(robot.model_id().is_some());
    let info = robot.describe().await.unwrap();
    assert_eq!(info.joint_names, ["shoulder", "elbow"]);
    assert_eq!(info.upper, DVector::from_vec(vec![3.0, 3.0]));
}

#[tokio::test]
async fn a_replica_without_the_model_gets_the_urdf_again() {
    let (a, b) = (server().await, server().await);
    let robot_a = Client::connect(&a.address)
        .await
        .unwrap()
        .robot_from_urdf(TWO_LINK_URDF);
    robot_a.fk(&[0.0, 0.0]).await.unwrap();
    let id = robot_a.model_id().expect("the server returned a hash");

    // replica b has never seen the model: a call naming the hash alone fails there ...
    let client_b = Client::connect(&b.address).await.unwrap();
    let mut raw = kinplan_client::pb::robot_service_client::RobotServiceClient::new(client_b.channel());
    let by_hash = raw
        .forward_kinematics(kinplan_client::pb::ForwardKinematicsRequest {
            robot: Some(kinplan_client::pb::RobotRef {
                source: Some(kinplan_client::pb::robot_ref::Source::ModelId(id.clone())),
                ..Default::default()
            }),
            joint_positions: vec![0.0, 0.0],
            include_links: false,
        })
        .await
        .unwrap_err();
    assert_eq!(by_hash.code(), Code::NotFound);
    // ... but the robot, moved to b with its cached hash, resends the URDF and succeeds
    let robot_b = robot_a.on(&client_b);
    let pose = robot_b.fk(&[0.0, 0.0]).await.unwrap();
    assert!((pose.translation.vector - Vector3::new(0.4, 0.0, 0.5)).norm() < 1e-12);
    assert_eq!(robot_b.model_id(), Some(id), "same text, same content hash");
}

#[tokio::test]
async fn ik_round_trips_through_fk_and_the_batch_agrees() {
    let s = server().await;
    let robot = Client::connect(&s.address).await.unwrap().robot(KR210);
    let states = [
        [0.2, -1.6, 1.7, 0.3, 0.8, -0.2],
        [-0.7, -1.1, 1.2, -0.4, 0.5, 1.0],
        [1.1, -1.9, 2.0, 0.9, -0.6, 0.3],
    ];
    let batch = robot
        .fk_batch(&states.map(|q| DVector::from_row_slice(&q)))
        .await
        .unwrap();
    for (q, from_batch) in states.iter().zip(&batch) {
        let target = robot.fk(q).await.unwrap();
        let (dp, dr) = distance(&target, from_batch);
        assert!(dp < 1e-12 && dr < 1e-9);
        let answer = robot.ik(&target, &[], &IkOptions::default()).await.unwrap();
        assert!(answer.success, "{answer:?}");
        let reached = robot.fk(answer.joints.as_slice()).await.unwrap();
        let (dp, dr) = distance(&reached, &target);
        assert!(dp <= 1e-5 && dr <= 1e-5, "FK(IK(x)) is {dp} m, {dr} rad from x");
    }
}

#[tokio::test]
async fn the_jacobian_matches_finite_differences_of_fk() {
    let s = server().await;
    let robot = Client::connect(&s.address).await.unwrap().robot(KR210);
    let q = [0.3, -1.4, 1.5, 0.2, 0.7, -0.5];
    let (jacobian, pose) = robot.jacobian(&q).await.unwrap();
    assert_eq!(pose, robot.fk(&q).await.unwrap());
    assert_eq!(jacobian.shape(), (6, 6));
    let h = 1e-6;
    for i in 0..6 {
        let (mut plus, mut minus) = (q, q);
        plus[i] += h;
        minus[i] -= h;
        let (p, m) = (robot.fk(&plus).await.unwrap(), robot.fk(&minus).await.unwrap());
        let linear = (p.translation.vector - m.translation.vector) / (2.0 * h);
        // angular velocity: the rotation vector of R(q+h) R(q-h)^T over 2h
        let angular = (p.rotation * m.rotation.inverse()).scaled_axis() / (2.0 * h);
        for r in 0..3 {
            assert!((jacobian[(r, i)] - linear[r]).abs() < 1e-6, "J[{r},{i}]");
            assert!(
                (jacobian[(r + 3, i)] - angular[r]).abs() < 1e-6,
                "J[{},{i}]",
                r + 3
            );
        }
    }
}

#[tokio::test]
async fn a_stream_session_follows_a_circle() {
    let s = server().await;
    let robot = Client::connect(&s.address).await.unwrap().robot(KR210);
    let q0 = [0.2, -1.6, 1.7, 0.3, 0.8, -0.2];
    let start = robot.fk(&q0).await.unwrap();
    let centre = start.translation.vector - Vector3::new(0.01, 0.0, 0.0);
    let mut session = robot.ik_stream(&q0, &IkOptions::default()).await.unwrap();
    let mut previous = DVector::from_row_slice(&q0);
    for k in 0..50 {
        let angle = std::f64::consts::TAU * f64::from(k) / 50.0;
        let mut target = start;
        target.translation.vector = centre + Vector3::new(angle.cos(), angle.sin(), 0.0) * 0.01;
        let answer = session.solve(&target).await.unwrap();
        assert!(answer.success, "target {k}: {answer:?}");
        let (dp, dr) = distance(&robot.fk(answer.joints.as_slice()).await.unwrap(), &target);
        assert!(dp <= 1e-5 && dr <= 1e-5, "target {k}");
        // warm-started on the same branch: 1.3 mm steps need small joint steps
        assert!(
            (&answer.joints - &previous).amax() < 0.05,
            "target {k} jumped branches"
        );
        previous = answer.joints;
    }
    // pipelined: three targets out, three answers back in order
    let sequences: Vec<u64> = {
        let mut v = Vec::new();
        for _ in 0..3 {
            v.push(session.send(&start, &[]).await.unwrap());
        }
        v
    };
    for expected in sequences {
        let (sequence, answer) = session.recv().await.unwrap();
        assert_eq!(sequence, expected);
        assert!(answer.success);
    }
}

#[tokio::test]
async fn a_plan_goes_around_a_sphere_on_the_straight_line() {
    const START: [f64; 6] = [-1.2, -1.3, 1.4, -1.6, -1.57, 0.0];
    const GOAL: [f64; 6] = [1.2, -1.3, 1.4, -1.6, -1.57, 0.0];
    let s = server().await;
    let robot = Client::connect(&s.address).await.unwrap().robot("ur5");
    let mid: Vec<f64> = START.iter().zip(GOAL).map(|(a, b)| (a + b) / 2.0).collect();
    let centre = robot.fk(&mid).await.unwrap().translation.vector;
    let radius = 0.12;
    let scene = [Obstacle::new(
        "ball",
        Isometry3::translation(centre.x, centre.y, centre.z),
        Shape::Sphere { radius },
    )];
    let straight_mid = robot
        .check_states(&[DVector::from_vec(mid)], &scene)
        .await
        .unwrap();
    assert!(!straight_mid[0].valid, "the sphere blocks the straight line");

    let goal = Goal::Joints(DVector::from_row_slice(&GOAL));
    let plan = robot
        .plan(&START, &goal, &scene, &PlanSettings::default())
        .await
        .unwrap();
    assert_eq!(plan.status, PlanStatus::Succeeded, "{}", plan.message);
    assert!(plan.valid);
    let n = plan.positions.nrows();
    assert!(n >= 2);
    assert_eq!(plan.positions.row(0).iter().copied().collect::<Vec<_>>(), START);
    assert_eq!(
        plan.positions.row(n - 1).iter().copied().collect::<Vec<_>>(),
        GOAL
    );
    assert!(
        plan.times.windows(2).all(|w| w[1] > w[0]),
        "timed: {:?}",
        plan.times
    );
    // an independent look: the tool point never enters the sphere, at 20
    // states per segment
    let mut states = Vec::new();
    for w in 0..n - 1 {
        for k in 0..20 {
            let s = f64::from(k) / 20.0;
            states.push(
                plan.positions.row(w).transpose() * (1.0 - s) + plan.positions.row(w + 1).transpose() * s,
            );
        }
    }
    for pose in robot.fk_batch(&states).await.unwrap() {
        assert!((pose.translation.vector - centre).norm() > radius);
    }
    assert!(
        robot
            .check_states(&states, &scene)
            .await
            .unwrap()
            .iter()
            .all(|c| c.valid)
    );

    // the same request gives the same plan
    let again = robot
        .plan(&START, &goal, &scene, &PlanSettings::default())
        .await
        .unwrap();
    assert_eq!(again.positions, plan.positions);
    let stomp = PlanSettings {
        algorithm: Algorithm::Stomp,
        seed: 3,
        ..PlanSettings::default()
    };
    let stomp_plan = robot.plan(&START, &goal, &scene, &stomp).await.unwrap();
    assert_eq!(stomp_plan.status, PlanStatus::Succeeded, "{}", stomp_plan.message);
}

#[tokio::test]
async fn bad_input_and_missed_deadlines_are_typed_errors() {
    let s = server().await;
    let client = Client::connect(&s.address).await.unwrap();
    let robot = client.robot(KR210);

    let nan_target = Isometry3::translation(f64::NAN, 0.0, 1.0);
    let e = robot
        .ik(&nan_target, &[], &IkOptions::default())
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("target.position"), "{e}");

    let e = robot.fk(&[0.0; 5]).await.unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("joint_positions"), "{e}");

    let e = client.robot("no_such_robot").fk(&[0.0; 6]).await.unwrap_err();
    assert_eq!(e.code(), Code::NotFound);

    let fabrik = IkOptions {
        method: IkMethod::Fabrik,
        ..IkOptions::default()
    };
    let e = robot
        .ik(&Isometry3::translation(1.5, 0.2, 1.2), &[], &fabrik)
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument, "FABRIK needs position_only: {e}");

    // IK fits its time budget inside the deadline: an unreachable pose under a
    // 1 s deadline answers the best attempt, flagged, before the deadline (a
    // shorter one left too little reply margin for a debug build on a loaded
    // machine)
    let short = client.with_timeout(Duration::from_millis(1000)).robot(KR210);
    let endless = IkOptions {
        max_restarts: Some(1_000_000),
        ..IkOptions::default()
    };
    let answer = short
        .ik(&Isometry3::translation(9.0, 0.0, 1.0), &[], &endless)
        .await
        .unwrap();
    assert!(!answer.success);
    assert_eq!(answer.status, kinplan_client::IkStatus::TimeBudget);

    // work that cannot fit: FK of 200,000 states in 1 ms is DEADLINE_EXCEEDED
    let states: Vec<DVector<f64>> = (0..200_000)
        .map(|i| DVector::from_element(6, 1e-6 * f64::from(i)))
        .collect();
    let e = client
        .with_timeout(Duration::from_millis(1))
        .robot("ur5")
        .fk_batch(&states)
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::DeadlineExceeded, "{e}");
}

#[tokio::test]
async fn unavailable_replicas_are_retried_and_unreachable_servers_say_so() {
    let s = server().await;
    // a port nobody listens on
    let dead = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().to_string()
    };
    let e = Client::connect(&dead).await.unwrap_err();
    assert_eq!(e.code(), Code::Unavailable);
    assert!(e.to_string().contains("kinplan serve"), "{e}");

    let balanced = Client::connect_balanced([dead.as_str(), s.address.as_str()]).unwrap();
    let robot = balanced.robot(KR210);
    for _ in 0..20 {
        robot.fk(&[0.0; 6]).await.unwrap();
    }
    assert!(balanced.list_robots().await.unwrap().iter().any(|n| n == KR210));
}

/// A robot's mesh files travel with its URDF: the two-link arm with a 0.1 m
/// cube mesh (an OBJ, given by the URI the URDF writes) on its upper arm
/// collides with a ball on the cube and not with one 10 mm off it.
#[tokio::test]
async fn a_urdf_with_its_mesh_files_collides_as_its_meshes() {
    let s = server().await;
    let client = Client::connect(&s.address).await.unwrap();
    let uri = "package://two_link/meshes/upper.obj";
    let urdf = TWO_LINK_URDF.replace(
        r#"<link name="upper"/>"#,
        &format!(
            r#"<link name="upper"><collision><origin xyz="0.2 0 0"/><geometry><mesh filename="{uri}"/></geometry></collision></link>"#
        ),
    );
    let mut cube = String::new();
    for i in 0..8 {
        let c = |bit: usize| if i & bit == 0 { -0.05 } else { 0.05 };
        cube += &format!("v {} {} {}\n", c(1), c(2), c(4));
    }
    cube += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    let robot = client.robot_from_urdf_with_meshes(urdf, [(uri.to_string(), cube.into_bytes())]);
    // the cube spans y ±0.05 around (0.2, 0, 0.5) at q = 0
    let ball = |y: f64| {
        vec![Obstacle::new(
            "ball",
            Isometry3::translation(0.2, y, 0.5),
            Shape::Sphere { radius: 0.02 },
        )]
    };
    let q = [DVector::from_vec(vec![0.0, 0.0])];
    let touching = robot.check_states(&q, &ball(0.06)).await.unwrap();
    assert!(!touching[0].valid, "{:?}", touching[0].colliding);
    let clear = robot.check_states(&q, &ball(0.08)).await.unwrap();
    assert!(
        clear[0].valid && (clear[0].clearance - 0.01).abs() < 1e-6,
        "{}",
        clear[0].clearance
    );
    // once a reply carried the model id, it names the URDF and its meshes
    robot.fk(&[0.0, 0.0]).await.unwrap();
    assert!(robot.model_id().is_some());
    let by_id = robot.check_states(&q, &ball(0.06)).await.unwrap();
    assert!(!by_id[0].valid);
}
