//! MobileService over gRPC: wheel kinematics derived by hand for every chassis, forward ∘
//! inverse round trips, the Lyapunov run of S1 (S = (−1, 1, 3π/4) → G = (0, 0, 0)), the
//! stateless ControlStep token, navigation around convex obstacles, NO_PATH when walled in,
//! a collision, and every class of bad input.

use std::f64::consts::{FRAC_PI_4, PI};

use kinplan_server::ServerConfig;
use kinplan_server::pb::{self, mobile_service_client::MobileServiceClient};
use tonic::Code;
use tonic::transport::Channel;
use tonic_types::StatusExt;

use crate::start;

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!((got - want).abs() <= tol, "{what}: got {got}, want {want}");
}

fn omni() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Omni(Default::default())),
    })
}

fn car() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Car(Default::default())),
    })
}

fn tricycle() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Tricycle(Default::default())),
    })
}

fn differential() -> Option<pb::Chassis> {
    Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Differential(Default::default())),
    })
}

fn twist(vx: f64, vy: f64, omega: f64) -> pb::Twist2D {
    pb::Twist2D { vx, vy, omega }
}

fn pose(x: f64, y: f64, theta: f64) -> Option<pb::Pose2D> {
    Some(pb::Pose2D { x, y, theta })
}

fn point(x: f64, y: f64) -> Option<pb::Point2D> {
    Some(pb::Point2D { x, y })
}

fn node(x: f64, y: f64, heading: Option<f64>) -> pb::PathNode {
    pb::PathNode { x, y, heading }
}

fn circle(x: f64, y: f64, radius: f64) -> pb::Obstacle {
    pb::Obstacle {
        shape: Some(pb::obstacle::Shape::Circle(pb::Circle {
            center: point(x, y),
            radius,
        })),
    }
}

fn square(cx: f64, cy: f64, half: f64) -> pb::Obstacle {
    let v = |x: f64, y: f64| pb::Point2D { x, y };
    pb::Obstacle {
        shape: Some(pb::obstacle::Shape::Polygon(pb::Polygon {
            vertices: vec![
                v(cx - half, cy - half),
                v(cx + half, cy - half),
                v(cx + half, cy + half),
                v(cx - half, cy + half),
            ],
        })),
    }
}

fn inverse(chassis: Option<pb::Chassis>, t: pb::Twist2D) -> pb::WheelKinematicsRequest {
    pb::WheelKinematicsRequest {
        chassis,
        input: Some(pb::wheel_kinematics_request::Input::Twist(t)),
    }
}

fn forward(chassis: Option<pb::Chassis>, w: pb::WheelState) -> pb::WheelKinematicsRequest {
    pb::WheelKinematicsRequest {
        chassis,
        input: Some(pb::wheel_kinematics_request::Input::Wheels(w)),
    }
}

async fn wheels_of(
    client: &mut MobileServiceClient<Channel>,
    req: pb::WheelKinematicsRequest,
) -> pb::WheelKinematicsResponse {
    client.wheel_kinematics(req).await.unwrap().into_inner()
}

/// OMR-III (r = 0.1 m, R = 0.3 m, φ_0 = 90°, rim ≤ 0.5 m/s), MOBIL-II (L = 0.6 m,
/// t = 0.62 m, r = 0.1 m), tricycle (L = 0.6 m, r = 0.1 m), Jackal-like differential
/// (r = 0.098 m, b = 0.37559 m), each derived from the formulas in src/mobile/README.md.
#[tokio::test]
async fn wheel_kinematics_by_hand_and_round_trips() {
    let server = start(ServerConfig::default()).await;
    let mut client = MobileServiceClient::new(server.channel.clone());
    use pb::wheel_state::Kind;

    // Omni, pure rotation ω = 1 rad/s: every wheel u_i = Rω / r = 0.3 / 0.1 = 3 rad/s.
    let r = wheels_of(&mut client, inverse(omni(), twist(0.0, 0.0, 1.0))).await;
    let Some(Kind::Omni(w)) = r.wheels.unwrap().kind else {
        panic!("omni wheels")
    };
    for (i, u) in w.speeds.iter().enumerate() {
        close(*u, 3.0, 1e-12, &format!("omni wheel {i}"));
    }
    let sat = r.saturation.unwrap();
    assert_eq!(sat.speed_scale, 1.0);
    assert!(!sat.lateral_dropped && !sat.steering_clamped);

    // Omni, forward 0.2 m/s: u_i = −sin φ_i · v_x / r with φ = 90°, 210°, 330° → −2, 1, 1.
    let r = wheels_of(&mut client, inverse(omni(), twist(0.2, 0.0, 0.0))).await;
    let Some(Kind::Omni(w)) = r.wheels.unwrap().kind else {
        panic!("omni wheels")
    };
    for (u, want) in w.speeds.iter().zip([-2.0, 1.0, 1.0]) {
        close(*u, want, 1e-12, "omni forward");
    }

    // Omni, ω = 2 rad/s needs a 0.6 m/s rim: scaled by 0.5/0.6 to 5 rad/s per wheel.
    let r = wheels_of(&mut client, inverse(omni(), twist(0.0, 0.0, 2.0))).await;
    close(r.saturation.unwrap().speed_scale, 0.5 / 0.6, 1e-12, "omni scale");
    close(r.twist.unwrap().omega, 2.0 * 0.5 / 0.6, 1e-12, "omni applied ω");
    let Some(Kind::Omni(w)) = r.wheels.unwrap().kind else {
        panic!("omni wheels")
    };
    close(w.speeds[0], 5.0, 1e-12, "omni saturated wheel");

    // MOBIL-II, v = 0.5 m/s on a 1 m radius (ω = 0.5 rad/s):
    // u_{l,r} = (v ∓ ωt/2)/r = 3.45, 6.55 rad/s; δ_{l,r} = atan(ωL / (v ∓ ωt/2)).
    let r = wheels_of(&mut client, inverse(car(), twist(0.5, 0.0, 0.5))).await;
    let Some(Kind::Car(w)) = r.wheels.clone().unwrap().kind else {
        panic!("car wheels")
    };
    close(w.rear_left, 3.45, 1e-12, "car rear left");
    close(w.rear_right, 6.55, 1e-12, "car rear right");
    close(w.steer_left, (0.3f64 / 0.345).atan(), 1e-12, "car steer left");
    close(w.steer_right, (0.3f64 / 0.655).atan(), 1e-12, "car steer right");
    assert!(w.steer_left > w.steer_right, "the inner (left) wheel steers more");
    // A lateral speed is dropped on the car.
    let r2 = wheels_of(&mut client, inverse(car(), twist(0.5, 0.3, 0.5))).await;
    assert!(r2.saturation.unwrap().lateral_dropped);
    assert_eq!(r2.twist.unwrap().vy, 0.0);

    // Tricycle, v = 0.3, ω = 0.5: δ = atan(0.5·0.6/0.3) = π/4, u = √(0.09 + 0.09)/0.1.
    let r = wheels_of(&mut client, inverse(tricycle(), twist(0.3, 0.0, 0.5))).await;
    let Some(Kind::Tricycle(w)) = r.wheels.unwrap().kind else {
        panic!("tricycle wheel")
    };
    close(w.steer, FRAC_PI_4, 1e-12, "tricycle steer");
    close(w.speed, 0.18f64.sqrt() / 0.1, 1e-12, "tricycle speed");
    // The steering limit (70°) clamps a tight turn: ω ≤ v tan 70° / L.
    let r = wheels_of(&mut client, inverse(tricycle(), twist(0.1, 0.0, 2.0))).await;
    assert!(r.saturation.unwrap().steering_clamped);
    let Some(Kind::Tricycle(w)) = r.wheels.unwrap().kind else {
        panic!("tricycle wheel")
    };
    close(w.steer, 70f64.to_radians(), 1e-9, "tricycle steer at the limit");

    // Differential, turning on the spot at 1 rad/s: u_{l,r} = ∓(b/2)/r.
    let r = wheels_of(&mut client, inverse(differential(), twist(0.0, 0.0, 1.0))).await;
    let Some(Kind::Differential(w)) = r.wheels.unwrap().kind else {
        panic!("diff wheels")
    };
    close(w.left, -0.37559 / 2.0 / 0.098, 1e-12, "diff left");
    close(w.right, 0.37559 / 2.0 / 0.098, 1e-12, "diff right");

    // Forward by hand: omni wheels (3, 3, 3) → pure rotation ω = r·Σu / (3R) = 1 rad/s.
    let f = wheels_of(
        &mut client,
        forward(
            omni(),
            pb::WheelState {
                kind: Some(Kind::Omni(pb::OmniWheels {
                    speeds: vec![3.0, 3.0, 3.0],
                })),
            },
        ),
    )
    .await;
    let t = f.twist.unwrap();
    close(t.vx, 0.0, 1e-12, "omni fk vx");
    close(t.vy, 0.0, 1e-12, "omni fk vy");
    close(t.omega, 1.0, 1e-12, "omni fk ω");

    // forward ∘ inverse = the applied (saturated) twist, for every chassis.
    for (name, chassis, t) in [
        ("omni", omni(), twist(0.2, -0.1, 0.4)),
        ("car", car(), twist(0.4, 0.0, -0.3)),
        ("tricycle", tricycle(), twist(-0.2, 0.0, 0.25)),
        ("differential", differential(), twist(0.7, 0.0, 1.3)),
        ("omni saturated", omni(), twist(1.0, 1.0, 3.0)),
    ] {
        let inv = wheels_of(&mut client, inverse(chassis, t)).await;
        let applied = inv.twist.unwrap();
        let fwd = wheels_of(&mut client, forward(chassis, inv.wheels.unwrap())).await;
        let back = fwd.twist.unwrap();
        close(back.vx, applied.vx, 1e-9, &format!("{name} vx"));
        close(back.vy, applied.vy, 1e-9, &format!("{name} vy"));
        close(back.omega, applied.omega, 1e-9, &format!("{name} ω"));
    }
}

fn lyapunov_value(p: &pb::Pose2D) -> f64 {
    let (lambda, h) = (0.55, 0.5);
    let e = p.x.hypot(p.y);
    let theta = (-p.y).atan2(-p.x);
    let alpha = wrap(theta - p.theta);
    0.5 * (lambda * e * e + alpha * alpha + h * theta * theta)
}

fn wrap(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w == -PI { PI } else { w }
}

/// S1 §4.2.3: from S = (−1, 1, 3π/4) to G = (0, 0, 0) with γ = 0.5, k = 0.3, h = 0.5,
/// λ = 0.55 the Lyapunov function never increases and the end error is < 1 cm and < 1°.
#[tokio::test]
async fn lyapunov_follow_path_converges() {
    let server = start(ServerConfig::default()).await;
    let mut client = MobileServiceClient::new(server.channel.clone());
    let req = pb::FollowPathRequest {
        chassis: differential(),
        start: pose(-1.0, 1.0, 3.0 * PI / 4.0),
        path: vec![node(0.0, 0.0, Some(0.0))],
        controller: pb::Controller::Lyapunov as i32,
        follow: Some(pb::FollowOptions {
            goal_tolerance: Some(0.005),
            heading_tolerance: Some(0.5f64.to_radians()),
            lyapunov: Some(pb::LyapunovGains {
                gamma: Some(0.5),
                k: Some(0.3),
                h: Some(0.5),
                lambda: Some(0.55),
                ..Default::default()
            }),
            ..Default::default()
        }),
        world: vec![],
        sim: Some(pb::SimOptions {
            dt: Some(0.01),
            max_time: Some(200.0),
            ..Default::default()
        }),
    };
    let run = client.follow_path(req).await.unwrap().into_inner();
    assert_eq!(run.outcome, pb::Outcome::Reached as i32, "{:?}", run.metrics);
    let last = run.states.last().unwrap();
    assert!(last.x.hypot(last.y) < 0.01, "{last:?}");
    assert!(wrap(last.theta).abs() < 1f64.to_radians(), "{last:?}");
    let v: Vec<f64> = run.states.iter().map(lyapunov_value).collect();
    for (k, w) in v.windows(2).enumerate() {
        assert!(w[1] <= w[0] + 1e-9, "V rose at step {k}: {} -> {}", w[0], w[1]);
    }
    let m = run.metrics.unwrap();
    assert_eq!(run.states.len(), m.steps as usize + 1);
    assert_eq!(run.commands.len(), m.steps as usize);
    close(m.time, m.steps as f64 * 0.01, 1e-9, "time = steps · dt");
    assert!(m.path_length > 2f64.sqrt(), "longer than the straight line");
    assert!(m.min_clearance.is_none(), "no obstacles, no clearance");
    assert!(run.modes.is_empty());
}

/// The server keeps no controller state: the token carries it. Vector distance with given
/// readings: a free ring and the goal straight ahead → (0.5 m/s, 0) in R mode; the front
/// blocked → the navigator locks. A step with the token continues the episode; the same step
/// without a token starts over and answers exactly as the first step did.
#[tokio::test]
async fn control_step_token_round_trip() {
    let server = start(ServerConfig::default()).await;
    let mut client = MobileServiceClient::new(server.channel.clone());
    let step = |readings: Vec<f64>, token: Vec<u8>| pb::ControlStepRequest {
        chassis: differential(),
        state: pose(0.0, 0.0, 0.0),
        controller: pb::Controller::VectorDistance as i32,
        goal: point(5.0, 0.0),
        readings,
        state_token: token,
        ..Default::default()
    };
    let free = client
        .control_step(step(vec![2.0; 8], vec![]))
        .await
        .unwrap()
        .into_inner();
    let c = free.command.unwrap();
    close(c.vx, 0.5, 1e-12, "free vx");
    close(c.omega, 0.0, 1e-12, "free ω");
    assert_eq!(free.mode, pb::NavMode::Rotate as i32);
    assert!(!free.state_token.is_empty());

    let mut blocked = vec![2.0; 8];
    blocked[0] = 0.1;
    let first = client
        .control_step(step(blocked.clone(), vec![]))
        .await
        .unwrap()
        .into_inner();
    let second = client
        .control_step(step(blocked.clone(), first.state_token.clone()))
        .await
        .unwrap()
        .into_inner();
    let fresh = client
        .control_step(step(blocked.clone(), vec![]))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(fresh, first, "an empty token is a fresh controller");
    assert_eq!(second.mode, pb::NavMode::Lock as i32, "the token carries L mode");
    assert_ne!(second.state_token, first.state_token, "the episode advanced");
    // The given readings come back as used.
    assert_eq!(first.readings, blocked);

    // Path following: node 0 at (0.1, 0) lies inside the 0.3 m switching distance of the
    // origin, so the first step moves on to node 1; with that token a robot back at (−1, 0)
    // keeps node 1, a fresh one aims at node 0 again.
    let follow = |x: f64, token: Vec<u8>| pb::ControlStepRequest {
        chassis: differential(),
        state: pose(x, 0.0, 0.0),
        controller: pb::Controller::PurePursuit as i32,
        path: vec![node(0.1, 0.0, None), node(2.0, 0.0, None)],
        state_token: token,
        ..Default::default()
    };
    let a = client
        .control_step(follow(0.0, vec![]))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(a.target_node, 1);
    let b = client
        .control_step(follow(-1.0, a.state_token.clone()))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(b.target_node, 1);
    let c = client
        .control_step(follow(-1.0, vec![]))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(c.target_node, 0);
    // A vector-distance token is not a path-following token.
    let err = client
        .control_step(follow(0.0, free.state_token.clone()))
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(err.message().starts_with("state_token"), "{}", err.message());

    // Sensing a world instead of given readings: a wall 0.5 m ahead of a 0.22 m robot gives
    // sensor 0 a gap of 0.5 − 0.22 = 0.28 m (a 0.5 × 4 m box from x = 0.5).
    let wall = pb::Obstacle {
        shape: Some(pb::obstacle::Shape::Polygon(pb::Polygon {
            vertices: vec![
                pb::Point2D { x: 0.5, y: -2.0 },
                pb::Point2D { x: 1.0, y: -2.0 },
                pb::Point2D { x: 1.0, y: 2.0 },
                pb::Point2D { x: 0.5, y: 2.0 },
            ],
        })),
    };
    let sensed = client
        .control_step(pb::ControlStepRequest {
            world: vec![wall],
            robot_radius: Some(0.22),
            sensors: Some(pb::RangeSensorParams {
                rays_per_beam: Some(1),
                ..Default::default()
            }),
            ..step(vec![], vec![])
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(sensed.readings.len(), 8);
    close(sensed.readings[0], 0.28, 1e-9, "gap ahead");
    close(sensed.readings[4], 2.0, 1e-12, "free behind (max range)");
}

fn navigate(world: Vec<pb::Obstacle>, goal: (f64, f64), max_time: f64) -> pb::NavigateRequest {
    pb::NavigateRequest {
        chassis: differential(),
        start: pose(0.0, 0.0, 0.0),
        goal: point(goal.0, goal.1),
        world,
        sim: Some(pb::SimOptions {
            robot_radius: Some(0.22),
            dt: Some(0.05),
            max_time: Some(max_time),
        }),
        ..Default::default()
    }
}

#[tokio::test]
async fn navigate_reaches_walled_in_is_no_path_and_collisions_are_reported() {
    let server = start(ServerConfig::default()).await;
    let mut client = MobileServiceClient::new(server.channel.clone());

    // A disc on the straight line and a square beside it: reached, never touching them.
    let req = navigate(
        vec![circle(2.0, 0.0, 0.5), square(3.0, -1.2, 0.3)],
        (4.0, 0.0),
        100.0,
    );
    let run = client.navigate(req).await.unwrap().into_inner();
    assert_eq!(run.outcome, pb::Outcome::Reached as i32);
    let last = run.states.last().unwrap();
    assert!((last.x - 4.0).hypot(last.y) <= 0.1, "{last:?}");
    let m = run.metrics.unwrap();
    assert!(m.min_clearance.unwrap() >= 0.0);
    assert!(
        m.path_length > 4.0,
        "a detour is longer than 4 m: {}",
        m.path_length
    );
    assert_eq!(run.modes.len(), m.steps as usize);
    assert!(
        run.modes.iter().any(|&k| k != pb::NavMode::Rotate as i32),
        "the obstacle made the navigator leave R mode"
    );

    // The same world with the global planner: grid A* + pure pursuit.
    let mut req = navigate(
        vec![circle(2.0, 0.0, 0.5), square(3.0, -1.2, 0.3)],
        (4.0, 0.0),
        100.0,
    );
    req.navigator = pb::Navigator::GridAstar as i32;
    let run = client.navigate(req.clone()).await.unwrap().into_inner();
    assert_eq!(run.outcome, pb::Outcome::Reached as i32);
    assert!(run.metrics.unwrap().min_clearance.unwrap() >= 0.0);
    // An unset controller follows the grid path with pure pursuit: the very same run.
    req.controller = pb::Controller::PurePursuit as i32;
    let pure_pursuit = client.navigate(req.clone()).await.unwrap().into_inner();
    assert_eq!(run, pure_pursuit);
    req.controller = pb::Controller::Lyapunov as i32;
    let lyapunov = client.navigate(req).await.unwrap().into_inner();
    assert_ne!(run.states, lyapunov.states);

    // The goal (6, 0) inside a closed ring of 28 touching discs: NO_PATH, with a hit point.
    let ring: Vec<pb::Obstacle> = (0..28)
        .map(|i| {
            let a = 2.0 * PI * i as f64 / 28.0;
            circle(6.0 + 1.3 * a.cos(), 1.3 * a.sin(), 0.16)
        })
        .collect();
    let run = client
        .navigate(navigate(ring.clone(), (6.0, 0.0), 300.0))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(run.outcome, pb::Outcome::NoPath as i32, "{:?}", run.metrics);
    assert!(!run.hit_points.is_empty());
    assert_ne!(run.no_path_reason, pb::NoPathReason::Unspecified as i32);
    assert!(run.metrics.unwrap().min_clearance.unwrap() >= 0.0);
    // Going round the other way once first (vdf.retry_other_side): still NO_PATH, later.
    let steps = run.metrics.unwrap().steps;
    let mut req = navigate(ring.clone(), (6.0, 0.0), 300.0);
    req.vdf = Some(pb::VectorDistanceParams {
        retry_other_side: Some(true),
        ..Default::default()
    });
    let again = client.navigate(req).await.unwrap().into_inner();
    assert_eq!(again.outcome, pb::Outcome::NoPath as i32);
    assert!(again.metrics.unwrap().steps > steps);
    let mut req = navigate(ring, (6.0, 0.0), 300.0);
    req.navigator = pb::Navigator::GridAstar as i32;
    let run = client.navigate(req).await.unwrap().into_inner();
    assert_eq!(run.outcome, pb::Outcome::NoPath as i32);
    assert_eq!(run.no_path_reason, pb::NoPathReason::NoGridPath as i32);

    // Following a straight path through a disc: COLLISION with obstacle 0, the last state the
    // first one whose disc overlaps it.
    let req = pb::FollowPathRequest {
        chassis: differential(),
        start: pose(0.0, 0.0, 0.0),
        path: vec![node(4.0, 0.0, None)],
        controller: pb::Controller::PurePursuit as i32,
        world: vec![circle(5.0, 5.0, 0.3), circle(2.0, 0.0, 0.5)],
        ..Default::default()
    };
    let run = client.follow_path(req).await.unwrap().into_inner();
    assert_eq!(run.outcome, pb::Outcome::Collision as i32);
    assert_eq!(run.collided_with, Some(1));
    let last = run.states.last().unwrap();
    assert!((last.x - 2.0).hypot(last.y) < 0.5 + 0.22, "{last:?}");
    let before = &run.states[run.states.len() - 2];
    assert!((before.x - 2.0).hypot(before.y) >= 0.5 + 0.22, "{before:?}");
    assert!(run.metrics.unwrap().min_clearance.unwrap() < 0.0);
}

#[tokio::test]
async fn bad_inputs_name_their_field_and_the_server_keeps_serving() {
    let server = start(ServerConfig::default()).await;
    let mut client = MobileServiceClient::new(server.channel.clone());
    fn check(what: &str, status: tonic::Status, field: &str) {
        assert_eq!(status.code(), Code::InvalidArgument, "{what}: {status:?}");
        assert!(
            status.message().starts_with(field),
            "{what}: {}",
            status.message()
        );
        let details = status.get_details_bad_request().expect("BadRequest details");
        assert_eq!(details.field_violations[0].field, field, "{what}");
    }

    let omni_zero_r = Some(pb::Chassis {
        kind: Some(pb::chassis::Kind::Omni(pb::OmniChassis {
            wheel_radius: Some(0.0),
            ..Default::default()
        })),
    });
    let wheel_cases: Vec<(&str, pb::WheelKinematicsRequest, &str)> = vec![
        (
            "zero wheel radius",
            inverse(omni_zero_r, twist(0.1, 0.0, 0.0)),
            "chassis.omni.wheel_radius",
        ),
        (
            "NaN twist",
            inverse(omni(), twist(f64::NAN, 0.0, 0.0)),
            "twist.vx",
        ),
        (
            "no input",
            pb::WheelKinematicsRequest {
                chassis: omni(),
                input: None,
            },
            "input",
        ),
        (
            "two omni speeds",
            forward(
                omni(),
                pb::WheelState {
                    kind: Some(pb::wheel_state::Kind::Omni(pb::OmniWheels {
                        speeds: vec![1.0, 2.0],
                    })),
                },
            ),
            "wheels.omni.speeds",
        ),
        (
            "wheels of another chassis",
            forward(
                car(),
                pb::WheelState {
                    kind: Some(pb::wheel_state::Kind::Differential(pb::DifferentialWheels {
                        left: 1.0,
                        right: 1.0,
                    })),
                },
            ),
            "wheels",
        ),
    ];
    for (what, req, field) in wheel_cases {
        check(what, client.wheel_kinematics(req).await.unwrap_err(), field);
        client
            .wheel_kinematics(inverse(omni(), twist(0.1, 0.0, 0.0)))
            .await
            .unwrap_or_else(|e| panic!("after {what}: {e:?}"));
    }

    let vd = |state: Option<pb::Pose2D>| pb::ControlStepRequest {
        state,
        controller: pb::Controller::VectorDistance as i32,
        goal: point(5.0, 0.0),
        readings: vec![2.0; 8],
        ..Default::default()
    };
    let step_cases: Vec<(&str, pb::ControlStepRequest, &str)> = vec![
        ("NaN state", vd(pose(f64::NAN, 0.0, 0.0)), "state.x"),
        (
            "bad token",
            pb::ControlStepRequest {
                state_token: b"not a token".to_vec(),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "state_token",
        ),
        (
            "wrong reading count",
            pb::ControlStepRequest {
                readings: vec![2.0; 5],
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "readings",
        ),
        (
            "NaN safe distance",
            pb::ControlStepRequest {
                vdf: Some(pb::VectorDistanceParams {
                    safe_distance: Some(f64::NAN),
                    ..Default::default()
                }),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "vdf.safe_distance",
        ),
        (
            "negative dt",
            pb::ControlStepRequest {
                controller: pb::Controller::Lyapunov as i32,
                path: vec![node(1.0, 0.0, None)],
                dt: Some(-0.1),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "dt",
        ),
        (
            "empty path",
            pb::ControlStepRequest {
                controller: pb::Controller::Lyapunov as i32,
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "path",
        ),
        (
            "NaN reading",
            pb::ControlStepRequest {
                readings: vec![2.0, 2.0, 2.0, f64::NAN, 2.0, 2.0, 2.0, 2.0],
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "readings[3]",
        ),
        (
            "negative sensing radius",
            pb::ControlStepRequest {
                readings: vec![],
                world: vec![circle(3.0, 0.0, 0.5)],
                robot_radius: Some(-0.2),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "robot_radius",
        ),
        (
            "zero tricycle wheelbase",
            pb::ControlStepRequest {
                chassis: Some(pb::Chassis {
                    kind: Some(pb::chassis::Kind::Tricycle(pb::TricycleChassis {
                        wheelbase: Some(0.0),
                        ..Default::default()
                    })),
                }),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "chassis.tricycle.wheelbase",
        ),
        (
            "forged path-follow token",
            pb::ControlStepRequest {
                controller: pb::Controller::PurePursuit as i32,
                path: vec![node(1.0, 0.0, None), node(2.0, 0.0, None)],
                state_token: br#"{"target":5,"segment":0}"#.to_vec(),
                ..vd(pose(0.0, 0.0, 0.0))
            },
            "state_token",
        ),
    ];
    for (what, req, field) in step_cases {
        check(what, client.control_step(req).await.unwrap_err(), field);
    }

    let follow = |path: Vec<pb::PathNode>, sim: Option<pb::SimOptions>| pb::FollowPathRequest {
        chassis: omni(),
        start: pose(0.0, 0.0, 0.0),
        path,
        sim,
        ..Default::default()
    };
    let ok_path = vec![node(1.0, 0.0, None)];
    let sim = |dt: f64, max_time: f64| {
        Some(pb::SimOptions {
            dt: Some(dt),
            max_time: Some(max_time),
            ..Default::default()
        })
    };
    let follow_cases: Vec<(&str, pb::FollowPathRequest, &str)> = vec![
        ("empty path", follow(vec![], None), "path"),
        ("negative dt", follow(ok_path.clone(), sim(-0.05, 10.0)), "sim.dt"),
        (
            "too many steps",
            follow(ok_path.clone(), sim(0.001, 1000.0)),
            "sim.max_time",
        ),
        (
            "NaN heading",
            follow(vec![node(1.0, 0.0, Some(f64::NAN))], None),
            "path[0].heading",
        ),
        (
            "too many nodes",
            follow(vec![node(1.0, 0.0, None); 10_001], None),
            "path",
        ),
        (
            "negative gain",
            pb::FollowPathRequest {
                follow: Some(pb::FollowOptions {
                    lyapunov: Some(pb::LyapunovGains {
                        gamma: Some(-0.5),
                        ..Default::default()
                    }),
                    ..Default::default()
                }),
                ..follow(ok_path.clone(), None)
            },
            "follow.lyapunov.gamma",
        ),
        (
            "vector distance is no path follower",
            pb::FollowPathRequest {
                controller: pb::Controller::VectorDistance as i32,
                ..follow(ok_path.clone(), None)
            },
            "controller",
        ),
        (
            "start inside an obstacle",
            pb::FollowPathRequest {
                world: vec![circle(0.1, 0.0, 0.3)],
                ..follow(ok_path.clone(), None)
            },
            "start",
        ),
        (
            "NaN node y",
            follow(vec![node(1.0, 0.0, None), node(2.0, f64::NAN, None)], None),
            "path[1].y",
        ),
        (
            "car steering beyond 90 degrees",
            pb::FollowPathRequest {
                chassis: Some(pb::Chassis {
                    kind: Some(pb::chassis::Kind::Car(pb::CarChassis {
                        max_steer: Some(2.0),
                        ..Default::default()
                    })),
                }),
                ..follow(ok_path.clone(), None)
            },
            "chassis.car.max_steer",
        ),
        (
            "negative lookahead",
            pb::FollowPathRequest {
                controller: pb::Controller::PurePursuit as i32,
                follow: Some(pb::FollowOptions {
                    pure_pursuit: Some(pb::PurePursuitGains {
                        lookahead: Some(-1.0),
                        ..Default::default()
                    }),
                    ..Default::default()
                }),
                ..follow(ok_path.clone(), None)
            },
            "follow.pure_pursuit.lookahead",
        ),
        (
            "zero heading tolerance",
            pb::FollowPathRequest {
                follow: Some(pb::FollowOptions {
                    heading_tolerance: Some(0.0),
                    ..Default::default()
                }),
                ..follow(ok_path.clone(), None)
            },
            "follow.heading_tolerance",
        ),
        (
            "negative robot radius",
            follow(
                ok_path.clone(),
                Some(pb::SimOptions {
                    robot_radius: Some(-0.1),
                    ..Default::default()
                }),
            ),
            "sim.robot_radius",
        ),
    ];
    for (what, req, field) in follow_cases {
        check(what, client.follow_path(req).await.unwrap_err(), field);
    }

    let nav_cases: Vec<(&str, pb::NavigateRequest, &str)> = vec![
        (
            "zero-radius circle",
            navigate(
                vec![circle(5.0, 5.0, 0.3), circle(2.0, 0.0, 0.0)],
                (4.0, 0.0),
                10.0,
            ),
            "world[1].circle.radius",
        ),
        (
            "polygon of two vertices",
            navigate(
                vec![pb::Obstacle {
                    shape: Some(pb::obstacle::Shape::Polygon(pb::Polygon {
                        vertices: vec![pb::Point2D { x: 1.0, y: 1.0 }, pb::Point2D { x: 2.0, y: 1.0 }],
                    })),
                }],
                (4.0, 0.0),
                10.0,
            ),
            "world[0].polygon.vertices",
        ),
        (
            "obstacle without a shape",
            navigate(vec![pb::Obstacle { shape: None }], (4.0, 0.0), 10.0),
            "world[0]",
        ),
        (
            "too many obstacles",
            navigate(vec![circle(50.0, 50.0, 0.1); 10_001], (4.0, 0.0), 10.0),
            "world",
        ),
        ("NaN goal", navigate(vec![], (f64::NAN, 0.0), 10.0), "goal.x"),
        (
            "too many sensors",
            pb::NavigateRequest {
                sensors: Some(pb::RangeSensorParams {
                    count: Some(1000),
                    ..Default::default()
                }),
                ..navigate(vec![], (4.0, 0.0), 10.0)
            },
            "sensors.count",
        ),
        (
            "NaN circle centre",
            navigate(vec![circle(f64::NAN, 0.0, 0.3)], (4.0, 0.0), 10.0),
            "world[0].circle.center.x",
        ),
        (
            "NaN polygon vertex",
            navigate(
                vec![
                    circle(9.0, 9.0, 0.3),
                    pb::Obstacle {
                        shape: Some(pb::obstacle::Shape::Polygon(pb::Polygon {
                            vertices: vec![
                                pb::Point2D { x: 1.0, y: 1.0 },
                                pb::Point2D { x: 2.0, y: f64::NAN },
                                pb::Point2D { x: 2.0, y: 2.0 },
                            ],
                        })),
                    },
                ],
                (4.0, 0.0),
                10.0,
            ),
            "world[1].polygon.vertices[1].y",
        ),
        (
            "far start heading",
            pb::NavigateRequest {
                start: pose(0.0, 0.0, 1e300),
                ..navigate(vec![], (4.0, 0.0), 10.0)
            },
            "start.theta",
        ),
        (
            "weight decay above one",
            pb::NavigateRequest {
                vdf: Some(pb::VectorDistanceParams {
                    weight_decay: Some(1.5),
                    ..Default::default()
                }),
                ..navigate(vec![], (4.0, 0.0), 10.0)
            },
            "vdf.weight_decay",
        ),
        (
            "negative beam width",
            pb::NavigateRequest {
                sensors: Some(pb::RangeSensorParams {
                    beam_width: Some(-1.0),
                    ..Default::default()
                }),
                ..navigate(vec![], (4.0, 0.0), 10.0)
            },
            "sensors.beam_width",
        ),
        (
            "zero grid resolution",
            pb::NavigateRequest {
                navigator: pb::Navigator::GridAstar as i32,
                astar: Some(pb::GridAstarOptions {
                    resolution: Some(0.0),
                    ..Default::default()
                }),
                ..navigate(vec![circle(2.0, 0.0, 0.5)], (4.0, 0.0), 10.0)
            },
            "astar.resolution",
        ),
    ];
    for (what, req, field) in nav_cases {
        check(what, client.navigate(req).await.unwrap_err(), field);
    }
    let run = client
        .navigate(navigate(vec![], (1.0, 0.0), 10.0))
        .await
        .expect("still serving")
        .into_inner();
    assert_eq!(run.outcome, pb::Outcome::Reached as i32);
}
