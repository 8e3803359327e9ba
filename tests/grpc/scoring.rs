//! ScoringService over gRPC: criteria checked against hand derivations on
//! planar_2 (two 0.5 m links turning about z, speed limits π rad/s), the
//! reversal invariances on the KR 210, short trajectories, a 10,000-waypoint
//! request, and every bad input.

use std::f64::consts::PI;

use kinplan_server::ServerConfig;
use kinplan_server::pb::{self, scoring_service_client::ScoringServiceClient};
use tonic::Code;
use tonic_health::pb::{
    HealthCheckRequest, health_check_response::ServingStatus, health_client::HealthClient,
};
use tonic_types::StatusExt;

use crate::{named, start};

fn trajectory(rows: &[Vec<f64>]) -> pb::JointTrajectory {
    pb::JointTrajectory {
        joint_names: Vec::new(),
        points: rows
            .iter()
            .map(|q| pb::JointPoint {
                positions: q.clone(),
                time_from_start: 0.0,
                ..Default::default()
            })
            .collect(),
    }
}

fn timed(rows: &[Vec<f64>], times: &[f64]) -> pb::JointTrajectory {
    let mut t = trajectory(rows);
    for (p, &s) in t.points.iter_mut().zip(times) {
        p.time_from_start = s;
    }
    t
}

fn request(robot: &str, t: pb::JointTrajectory, options: pb::ScoreOptions) -> pb::ScoreTrajectoryRequest {
    pb::ScoreTrajectoryRequest {
        robot: named(robot),
        trajectory: Some(t),
        options: Some(options),
    }
}

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!((got - want).abs() <= tol, "{what}: got {got}, want {want}");
}

/// planar_2, joint 1 stepping 0.1 rad four times: the tool (1 m out) moves
/// on a unit circle.
fn arc() -> Vec<Vec<f64>> {
    (0..5).map(|i| vec![0.1 * i as f64, 0.0]).collect()
}

#[tokio::test]
async fn straight_joint_move_by_hand() {
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let reply = scoring
        .score_trajectory(request(
            "planar_2",
            trajectory(&arc()),
            pb::ScoreOptions {
                joint_weights: vec![2.0, 3.0],
                series: true,
                ..Default::default()
            },
        ))
        .await
        .unwrap()
        .into_inner();
    let c = &reply.criteria;
    let chord = 2.0 * (0.05f64).sin(); // |p_i − p_{i−1}| on the unit circle
    close(c["JD"], 0.4, 1e-12, "JD = 4 × 0.1");
    close(c["CPC"], 0.8, 1e-12, "CPC = 2 × JD (weight 2 on joint 1)");
    close(c["CD"], 4.0 * chord, 1e-12, "CD = 4 chords");
    close(c["OC"], 0.2, 1e-12, "OC = 4 half angles of 0.1 rad");
    close(c["OC_geodesic"], 0.4, 1e-12, "OC_geodesic");
    // Link origins: the tool frame is the point farthest from joint 1.
    close(c["RDM"], 4.0 * chord, 1e-12, "RDM over link origins");
    // Δ³ of a uniform circular motion: |e^{ih} − 1|³ = chord³, at i = 3 and 4.
    close(c["CJ"], 2.0 * chord.powi(3), 1e-12, "CJ");
    close(c["CMJ"], chord.powi(3), 1e-12, "CMJ");
    close(c["JJ"], 0.0, 1e-12, "JJ of a linear joint ramp");
    close(c["cycle_time"], 0.4 / PI, 1e-12, "cycle time = 4 × 0.1 / π");
    assert_eq!(reply.waypoints, 5);
    assert_eq!(reply.robot_points, 4);
    assert!(reply.cycle_time_unavailable.is_empty());
    let ct = reply.cycle_time.as_ref().unwrap();
    assert_eq!(ct.segments.len(), 4);
    assert!(ct.segments.iter().all(|s| s.limiting_joint == 0));
    assert_eq!(ct.potentials.len(), 3);
    assert!(
        ct.potentials.iter().all(|p| !p.has_potential),
        "{:?}",
        ct.potentials
    );
    let s = reply.series.as_ref().unwrap();
    assert_eq!(s.cd.len(), 5);
    close(s.cd[0], 0.0, 0.0, "series starts at 0");
    close(s.cd[3], chord, 1e-12, "cd[3]");
    close(s.cartesian_jerk[4], chord.powi(3), 1e-12, "cartesian_jerk[4]");
    assert!(s.joint_jerk_rate.is_empty(), "untimed: no jerk rate");
    assert!(reply.time_scaled.is_none());

    // Collision vertices: the tip of link 2's capsule lies 1.02 m out.
    let reply = scoring
        .score_trajectory(request(
            "planar_2",
            trajectory(&arc()),
            pb::ScoreOptions {
                robot_points: pb::RobotPoints::CollisionVertices as i32,
                ..Default::default()
            },
        ))
        .await
        .unwrap()
        .into_inner();
    close(
        reply.criteria["RDM"],
        4.0 * 1.02 * chord,
        1e-12,
        "RDM over capsule tips",
    );
    assert_eq!(reply.robot_points, 24);
    close(reply.criteria["CPC"], 0.4, 1e-12, "CPC with unit weights = JD");
    let reply = scoring
        .score_trajectory(request(
            "planar_2",
            trajectory(&arc()),
            pb::ScoreOptions {
                robot_points: pb::RobotPoints::None as i32,
                ..Default::default()
            },
        ))
        .await
        .unwrap()
        .into_inner();
    assert!(!reply.criteria.contains_key("RDM"));
}

#[tokio::test]
async fn jerk_spike_peaks_and_time_potential_by_hand() {
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    // Joint 2 jumps out by d at waypoint 3 and back: Σ|Δ³q| = 0,0,0,d,3d,3d,d.
    let d = 0.5;
    let rows: Vec<Vec<f64>> = (0..7).map(|i| vec![0.0, if i == 3 { d } else { 0.0 }]).collect();
    let h = 0.5; // seconds between waypoints
    let times: Vec<f64> = (0..7).map(|i| h * i as f64).collect();
    let reply = scoring
        .score_trajectory(request(
            "planar_2",
            timed(&rows, &times),
            pb::ScoreOptions {
                series: true,
                ..Default::default()
            },
        ))
        .await
        .unwrap()
        .into_inner();
    let c = &reply.criteria;
    close(c["JD"], 2.0 * d, 1e-12, "JD");
    close(c["JJ"], 8.0 * d, 1e-12, "JJ = d + 3d + 3d + d");
    close(c["JMJ"], 3.0 * d, 1e-12, "JMJ");
    // One plateau peak 3d at waypoints 4-5, reported at 4: 3·log10(1.5) + 4.
    close(c["JJP"], 3.0 * (3.0 * d).log10() + 4.0, 1e-12, "JJP");
    assert_eq!(reply.joint_peak_count, 1);
    let s = reply.series.as_ref().unwrap();
    assert_eq!(s.joint_peaks.len(), 1);
    assert_eq!(s.joint_peaks[0].index, 4);
    close(s.joint_peaks[0].slowdown, c["JJP"], 1e-12, "peak slowdown");
    let joint_jerk: Vec<f64> = s.joint_jerk.clone();
    for (got, want) in joint_jerk.iter().zip([0.0, 0.0, 0.0, d, 3.0 * d, 3.0 * d, d]) {
        close(*got, want, 1e-12, "joint_jerk series");
    }
    // Uniform step h: the time-scaled jerk is Δ³/h³.
    let ts = reply.time_scaled.as_ref().unwrap();
    close(ts.jj, 8.0 * d / h.powi(3), 1e-9, "time-scaled JJ");
    close(
        s.joint_jerk_rate[4],
        3.0 * d / h.powi(3),
        1e-9,
        "jerk rate series",
    );
    // The spike costs 2·d/π s; leaving out waypoint 3 saves all of it.
    let ct = reply.cycle_time.as_ref().unwrap();
    close(ct.total, 2.0 * d / PI, 1e-12, "cycle time");
    let p3 = ct.potentials.iter().find(|p| p.index == 3).unwrap();
    assert!(p3.has_potential);
    close(p3.gain, 2.0 * d / PI, 1e-12, "gain at waypoint 3");
    assert_eq!(ct.potentials.iter().filter(|p| p.has_potential).count(), 1);
    assert_eq!(ct.segments[2].limiting_joint, 1);
    assert_eq!(ct.segments[0].limiting_joint, -1);

    // Regression coefficients and acceleration ramps from the request.
    let reply = scoring
        .score_trajectory(request(
            "planar_2",
            trajectory(&rows),
            pb::ScoreOptions {
                jerk_peaks: Some(pb::JerkPeakOptions {
                    joint_log_gain: Some(1.0),
                    joint_offset: Some(0.0),
                    ..Default::default()
                }),
                max_acceleration: vec![1.0, 1.0],
                ..Default::default()
            },
        ))
        .await
        .unwrap()
        .into_inner();
    close(
        reply.criteria["JJP"],
        (3.0 * d).log10(),
        1e-12,
        "JJP with a = 1, b = 0",
    );
    // d = 0.5 < v²/a = π²: triangular profile 2·√(d/a) per segment, twice.
    close(
        reply.criteria["cycle_time"],
        4.0 * (d).sqrt(),
        1e-12,
        "cycle time with ramps",
    );
}

#[tokio::test]
async fn reversal_keeps_the_path_criteria_and_short_trajectories_are_zero() {
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let rows: Vec<Vec<f64>> = (0..40)
        .map(|i| {
            let s = i as f64 / 39.0;
            vec![
                0.8 * s,
                -1.2 + 0.5 * (3.0 * s).sin(),
                1.0 - 0.4 * s * s,
                0.3 * (5.0 * s).cos(),
                0.6 * s,
                -0.9 * s + 0.2 * (7.0 * s).sin(),
            ]
        })
        .collect();
    let reversed: Vec<Vec<f64>> = rows.iter().rev().cloned().collect();
    let options = pb::ScoreOptions {
        joint_weights: vec![1.0, 2.0, 0.5, 0.3, 0.2, 0.1],
        robot_points: pb::RobotPoints::CollisionVertices as i32,
        ..Default::default()
    };
    let mut scores = Vec::new();
    for t in [&rows, &reversed] {
        scores.push(
            scoring
                .score_trajectory(request("kuka_kr210_r2700_extra", trajectory(t), options.clone()))
                .await
                .unwrap()
                .into_inner()
                .criteria,
        );
    }
    for key in ["CD", "JD", "OC", "OC_geodesic", "CPC", "RDM", "cycle_time"] {
        let (a, b) = (scores[0][key], scores[1][key]);
        assert!(a > 0.0, "{key} = {a}");
        close(b, a, 1e-9 * a, key);
    }

    for (n, distance_zero) in [(0, true), (1, true), (3, false)] {
        let reply = scoring
            .score_trajectory(request("planar_2", trajectory(&arc()[..n]), Default::default()))
            .await
            .unwrap()
            .into_inner();
        let c = &reply.criteria;
        assert_eq!(reply.waypoints, n as u32);
        for key in ["JJ", "CJ", "JMJ", "CMJ", "JJP", "CJP"] {
            assert_eq!(c[key], 0.0, "{key} for n = {n}");
        }
        if distance_zero {
            for key in ["CD", "JD", "OC", "CPC", "RDM", "cycle_time"] {
                assert_eq!(c[key], 0.0, "{key} for n = {n}");
            }
        } else {
            close(c["JD"], 0.2, 1e-12, "JD of 3 points");
        }
    }
}

#[tokio::test]
async fn comparison_statistics_by_hand_and_a_large_trajectory() {
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let ramp = |steps: usize, step: f64| -> pb::JointTrajectory {
        trajectory(
            &(0..=steps)
                .map(|i| vec![step * i as f64, 0.0])
                .collect::<Vec<_>>(),
        )
    };
    let reply = scoring
        .compare_trajectories(pb::CompareTrajectoriesRequest {
            robot: named("planar_2"),
            sets: vec![
                pb::TrajectorySet {
                    label: "rrt".into(),
                    trajectories: vec![ramp(4, 0.1), ramp(2, 0.1)],
                },
                pb::TrajectorySet {
                    label: "ccstomp".into(),
                    trajectories: vec![ramp(3, 0.1)],
                },
            ],
            options: None,
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.sets.len(), 2);
    assert_eq!(reply.criteria[..3], ["CD", "JD", "OC"]);
    let rrt = &reply.sets[0];
    assert_eq!((rrt.label.as_str(), rrt.trajectories), ("rrt", 2));
    let jd = &rrt.criteria["JD"];
    // JD 0.4 and 0.2: mean 0.3, sample variance 0.02, population 0.01, sum 0.6.
    close(jd.mean, 0.3, 1e-12, "mean");
    close(jd.variance.unwrap(), 0.02, 1e-12, "sample variance");
    close(jd.population_variance, 0.01, 1e-12, "population variance");
    close(jd.sum, 0.6, 1e-12, "sum");
    close(jd.min, 0.2, 1e-12, "min");
    close(jd.max, 0.4, 1e-12, "max");
    assert_eq!(jd.count, 2);
    close(rrt.scores[1].criteria["JD"], 0.2, 1e-12, "per-trajectory JD");
    let cc = &reply.sets[1].criteria["JD"];
    assert_eq!(cc.variance, None, "one trajectory: no sample variance");
    close(cc.sum, 0.3, 1e-12, "ccstomp sum");

    // 10,000 waypoints (scored on the CPU pool): JD of a ramp by hand.
    let n = 10_000;
    let step = 1e-4;
    let big = (0..n)
        .map(|i| vec![step * i as f64, 0.5, 0.0, 0.0, 0.0, 0.0])
        .collect::<Vec<_>>();
    let reply = scoring
        .score_trajectory(request(
            "kuka_kr210_r2700_extra",
            trajectory(&big),
            Default::default(),
        ))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.waypoints, n as u32);
    close(
        reply.criteria["JD"],
        step * (n - 1) as f64,
        1e-9,
        "JD of the ramp",
    );
    close(
        reply.criteria["OC_geodesic"],
        step * (n - 1) as f64,
        1e-9,
        "tool turns with A1",
    );
}

#[tokio::test]
async fn bad_inputs_name_their_field_and_the_server_keeps_serving() {
    let server = start(ServerConfig::default()).await;
    let mut health = HealthClient::new(server.channel.clone());
    let status = health
        .check(HealthCheckRequest {
            service: "kinplan.v1.ScoringService".into(),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(status.status(), ServingStatus::Serving);
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let ok = arc();
    let mut ragged = arc();
    ragged[2].push(0.0);
    let mut nan = arc();
    nan[1][0] = f64::NAN;
    let three: Vec<Vec<f64>> = arc()
        .into_iter()
        .map(|mut q| {
            q.push(0.0);
            q
        })
        .collect();
    let opts = |o: pb::ScoreOptions| request("planar_2", trajectory(&ok), o);
    let mut names = trajectory(&ok);
    names.joint_names = vec!["joint_2".into(), "joint_1".into()];
    let cases: Vec<(&str, pb::ScoreTrajectoryRequest, &str)> = vec![
        (
            "ragged rows",
            request("planar_2", trajectory(&ragged), Default::default()),
            "trajectory.points[2].positions",
        ),
        (
            "NaN",
            request("planar_2", trajectory(&nan), Default::default()),
            "trajectory.points[1].positions[0]",
        ),
        (
            "wrong joint count",
            request("planar_2", trajectory(&three), Default::default()),
            "trajectory.points[0].positions",
        ),
        (
            "non-increasing timestamps",
            request(
                "planar_2",
                timed(&ok, &[0.0, 0.1, 0.2, 0.2, 0.3]),
                Default::default(),
            ),
            "trajectory.points[3].time_from_start",
        ),
        (
            "infinite timestamp",
            request(
                "planar_2",
                timed(&ok, &[0.0, 0.1, f64::INFINITY, 0.3, 0.4]),
                Default::default(),
            ),
            "trajectory.points[2].time_from_start",
        ),
        (
            "missing trajectory",
            pb::ScoreTrajectoryRequest {
                robot: named("planar_2"),
                trajectory: None,
                options: None,
            },
            "trajectory",
        ),
        (
            "joint names",
            request("planar_2", names, Default::default()),
            "trajectory.joint_names",
        ),
        (
            "negative weight",
            opts(pb::ScoreOptions {
                joint_weights: vec![-1.0, 1.0],
                ..Default::default()
            }),
            "options.joint_weights[0]",
        ),
        (
            "weight count",
            opts(pb::ScoreOptions {
                joint_weights: vec![1.0],
                ..Default::default()
            }),
            "options.joint_weights",
        ),
        (
            "zero speed",
            opts(pb::ScoreOptions {
                max_velocity: vec![1.0, 0.0],
                ..Default::default()
            }),
            "options.max_velocity[1]",
        ),
        (
            "acceleration count",
            opts(pb::ScoreOptions {
                max_acceleration: vec![1.0, 1.0, 1.0],
                ..Default::default()
            }),
            "options.max_acceleration",
        ),
        (
            "NaN gain",
            opts(pb::ScoreOptions {
                jerk_peaks: Some(pb::JerkPeakOptions {
                    joint_log_gain: Some(f64::NAN),
                    ..Default::default()
                }),
                ..Default::default()
            }),
            "options.jerk_peaks.joint_log_gain",
        ),
        (
            "negative tolerance",
            opts(pb::ScoreOptions {
                potential_tolerance: Some(-1.0),
                ..Default::default()
            }),
            "options.potential_tolerance",
        ),
        (
            "unknown point set",
            opts(pb::ScoreOptions {
                robot_points: 9,
                ..Default::default()
            }),
            "options.robot_points",
        ),
        (
            "missing robot",
            pb::ScoreTrajectoryRequest {
                robot: None,
                trajectory: Some(trajectory(&ok)),
                options: None,
            },
            "robot",
        ),
    ];
    let still_serving = request("planar_2", trajectory(&ok), Default::default());
    for (what, req, field) in cases {
        let status = scoring.score_trajectory(req).await.unwrap_err();
        assert_eq!(status.code(), Code::InvalidArgument, "{what}: {status:?}");
        assert!(
            status.message().starts_with(field),
            "{what}: {}",
            status.message()
        );
        let details = status.get_details_bad_request().expect("BadRequest details");
        assert_eq!(details.field_violations[0].field, field, "{what}");
        scoring
            .score_trajectory(still_serving.clone())
            .await
            .unwrap_or_else(|e| panic!("after {what}: {e:?}"));
    }

    let set = |label: &str, t: Vec<pb::JointTrajectory>| pb::TrajectorySet {
        label: label.into(),
        trajectories: t,
    };
    let compare = |sets: Vec<pb::TrajectorySet>| pb::CompareTrajectoriesRequest {
        robot: named("planar_2"),
        sets,
        options: None,
    };
    let cases: Vec<(&str, pb::CompareTrajectoriesRequest, &str)> = vec![
        ("no sets", compare(vec![]), "sets"),
        (
            "empty set",
            compare(vec![set("a", vec![trajectory(&ok)]), set("b", vec![])]),
            "sets[1].trajectories",
        ),
        (
            "duplicate label",
            compare(vec![
                set("a", vec![trajectory(&ok)]),
                set("a", vec![trajectory(&ok)]),
            ]),
            "sets[1].label",
        ),
        (
            "empty label",
            compare(vec![set("", vec![trajectory(&ok)])]),
            "sets[0].label",
        ),
        (
            "NaN in a set",
            compare(vec![
                set("a", vec![trajectory(&ok)]),
                set("b", vec![trajectory(&ok), trajectory(&nan)]),
            ]),
            "sets[1].trajectories[1].points[1].positions[0]",
        ),
    ];
    for (what, req, field) in cases {
        let status = scoring.compare_trajectories(req).await.unwrap_err();
        assert_eq!(status.code(), Code::InvalidArgument, "{what}: {status:?}");
        assert!(
            status.message().starts_with(field),
            "{what}: {}",
            status.message()
        );
        let details = status.get_details_bad_request().expect("BadRequest details");
        assert_eq!(details.field_violations[0].field, field, "{what}");
    }
    scoring
        .compare_trajectories(compare(vec![set("a", vec![trajectory(&ok)])]))
        .await
        .expect("still serving");
}

/// A URDF without speed limits: no cycle time, a reason naming the joint; the
/// limits can come with the request instead. Inline models get a model id.
#[tokio::test]
async fn cycle_time_needs_speed_limits() {
    const NO_SPEED: &str = r#"<robot name="slider">
      <link name="base"/><link name="carriage"/><link name="tool"/>
      <joint name="rail" type="prismatic"><parent link="base"/><child link="carriage"/>
        <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
        <limit lower="-1" upper="1" effort="1" velocity="0"/></joint>
      <joint name="wrist" type="revolute"><parent link="carriage"/><child link="tool"/>
        <origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="1" velocity="2"/></joint>
    </robot>"#;
    let server = start(ServerConfig::default()).await;
    let mut scoring = ScoringServiceClient::new(server.channel.clone());
    let robot = Some(pb::RobotRef {
        source: Some(pb::robot_ref::Source::Urdf(NO_SPEED.into())),
        ..Default::default()
    });
    // The carriage slides 0.3 m in three steps while the wrist turns 0.6 rad.
    let rows: Vec<Vec<f64>> = (0..4).map(|i| vec![0.1 * i as f64, 0.2 * i as f64]).collect();
    let reply = scoring
        .score_trajectory(pb::ScoreTrajectoryRequest {
            robot: robot.clone(),
            trajectory: Some(trajectory(&rows)),
            options: None,
        })
        .await
        .unwrap()
        .into_inner();
    assert!(!reply.criteria.contains_key("cycle_time"));
    assert!(reply.cycle_time.is_none());
    assert!(
        reply.cycle_time_unavailable.contains("\"rail\""),
        "{}",
        reply.cycle_time_unavailable
    );
    assert_eq!(reply.model_id.len(), 32);
    // Prismatic joint: JD mixes metres and radians, CD is the slide, OC the turn.
    close(reply.criteria["JD"], 0.3 + 0.6, 1e-12, "JD");
    close(reply.criteria["CD"], 0.3, 1e-12, "CD");
    close(reply.criteria["OC_geodesic"], 0.6, 1e-12, "OC_geodesic");
    let reply = scoring
        .score_trajectory(pb::ScoreTrajectoryRequest {
            robot: Some(pb::RobotRef {
                source: Some(pb::robot_ref::Source::ModelId(reply.model_id)),
                ..Default::default()
            }),
            trajectory: Some(trajectory(&rows)),
            options: Some(pb::ScoreOptions {
                max_velocity: vec![0.5, 2.0],
                ..Default::default()
            }),
        })
        .await
        .unwrap()
        .into_inner();
    // Per step: rail 0.1 m / 0.5 m/s = 0.2 s, wrist 0.2 rad / 2 rad/s = 0.1 s.
    close(reply.criteria["cycle_time"], 0.6, 1e-12, "cycle time");
    assert!(reply.cycle_time_unavailable.is_empty());
    assert!(
        reply
            .cycle_time
            .unwrap()
            .segments
            .iter()
            .all(|s| s.limiting_joint == 0)
    );
}
