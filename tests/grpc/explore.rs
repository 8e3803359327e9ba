//! ExplorationService.Explore end to end: the IRB 4600 explores a small
//! walled-in box; the stream's iterations and summary are checked against
//! independent facts (known ratio never falls, each trajectory starts where
//! the previous ended, the final tree parses and holds the scanned wall),
//! and bad input is named by field.

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, collision_object::Shape, exploration_service_client::ExplorationServiceClient,
    explore_response::Event,
};
use tonic::Code;
use tonic_types::StatusExt;

use crate::start;

fn vec3(x: f64, y: f64, z: f64) -> pb::Vec3 {
    pb::Vec3 { x, y, z }
}

fn cuboid(id: &str, c: [f64; 3], size: [f64; 3]) -> pb::CollisionObject {
    pb::CollisionObject {
        id: id.into(),
        pose: Some(pb::Pose {
            position: Some(vec3(c[0], c[1], c[2])),
            orientation: Some(pb::Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            }),
        }),
        shape: Some(Shape::Box(pb::Box {
            size: Some(vec3(size[0], size[1], size[2])),
        })),
        unknown_as_obstacle: false,
    }
}

/// Floor below the plinth, a back wall at x = 3.5, a crate and a shelf
/// that hides what is behind it.
fn scene() -> pb::Scene {
    pb::Scene {
        objects: vec![
            cuboid("floor", [1.0, 0.0, -0.4], [8.0, 8.0, 0.1]),
            cuboid("back wall", [3.6, 0.0, 1.0], [0.2, 8.0, 2.8]),
            cuboid("crate", [2.3, 0.3, -0.05], [0.5, 0.5, 0.6]),
            cuboid("shelf", [2.0, -0.6, 0.2], [0.3, 0.8, 1.1]),
        ],
    }
}

const START: [f64; 6] = [0.0, -0.2, 0.3, 0.0, 0.75, 0.0];

fn request() -> pb::ExploreRequest {
    pb::ExploreRequest {
        robot: Some(pb::RobotRef {
            source: Some(pb::robot_ref::Source::Name("abb_irb4600_60_205".into())),
            ..Default::default()
        }),
        start: START.to_vec(),
        scene: Some(scene()),
        region: Some(pb::BoundingBox {
            min: Some(vec3(1.4, -1.2, -0.29)),
            max: Some(vec3(3.2, 1.2, 1.0)),
        }),
        resolution: Some(0.2),
        pixel_stride: Some(8),
        stop: Some(pb::ExploreStopRule {
            known_ratio: Some(1.0),
            max_iterations: Some(3),
            max_consecutive_failures: None,
        }),
        seed: 5,
        ..Default::default()
    }
}

#[tokio::test]
async fn an_exploration_streams_iterations_then_a_summary_with_the_tree() {
    let server = start(ServerConfig::default()).await;
    let mut client = ExplorationServiceClient::new(server.channel.clone());
    let mut stream = client.explore(request()).await.unwrap().into_inner();
    let mut iterations = Vec::new();
    let mut summary = None;
    while let Some(msg) = stream.message().await.unwrap() {
        match msg.event.unwrap() {
            Event::Iteration(it) => {
                assert!(summary.is_none(), "an iteration after the summary");
                iterations.push(it);
            }
            Event::Summary(s) => summary = Some(s),
        }
    }
    let s = summary.expect("a summary closes the stream");
    assert_eq!(s.iterations as usize, iterations.len());
    assert!(
        s.iterations >= 1 && s.iterations <= 3,
        "status {} known {} of {}",
        s.status,
        s.initial_known_ratio,
        s.observable_cells
    );
    assert!(s.observable_cells > 0);
    let mut last = s.initial_known_ratio;
    let mut q = START.to_vec();
    let mut cd = 0.0;
    for (k, it) in iterations.iter().enumerate() {
        assert_eq!(it.iteration as usize, k + 1);
        assert!(it.known_ratio >= last);
        last = it.known_ratio;
        if let Some(t) = &it.trajectory
            && !t.points.is_empty()
        {
            let first = &t.points[0].positions;
            for (a, b) in first.iter().zip(&q) {
                assert!((a - b).abs() < 1e-9, "trajectory {k} starts elsewhere");
            }
            q = t.points.last().unwrap().positions.clone();
            assert!(
                t.points
                    .windows(2)
                    .all(|w| w[1].time_from_start > w[0].time_from_start)
            );
            cd += it.criteria["CD"];
        }
        assert_eq!(it.joints, q);
    }
    assert_eq!(s.known_ratio, last);
    assert_eq!(s.final_joints, q);
    assert!((s.totals.as_ref().unwrap().cd - cd).abs() < 1e-9);
    // the final tree parses, at the requested resolution, with free and occupied leaves
    let info = client
        .octree_info(pb::OctreeInfoRequest {
            octree: s.octree.clone(),
            ..Default::default()
        })
        .await
        .unwrap()
        .into_inner();
    let stats = info.stats.unwrap();
    assert!(stats.occupied_leaves > 0 && stats.free_leaves > 0);
    assert!((stats.resolution - 0.2).abs() < 1e-12);
}

#[tokio::test]
async fn an_exploration_with_the_shared_near_field_knows_what_the_exact_inserts_know() {
    let server = start(ServerConfig::default()).await;
    let mut client = ExplorationServiceClient::new(server.channel.clone());
    let mut summaries = Vec::new();
    for spacing in [None, Some(0.7)] {
        let mut r = request();
        r.near_ray_spacing = spacing;
        r.stop.as_mut().unwrap().max_iterations = Some(1);
        let mut stream = client.explore(r).await.unwrap().into_inner();
        let mut summary = None;
        while let Some(msg) = stream.message().await.unwrap() {
            if let Event::Summary(s) = msg.event.unwrap() {
                summary = Some(s);
            }
        }
        summaries.push(summary.expect("a summary closes the stream"));
    }
    // the initial sweep's scans: the same cells known to within a few per thousand
    let (exact, shared) = (&summaries[0], &summaries[1]);
    assert_eq!(exact.observable_cells, shared.observable_cells);
    assert!(exact.initial_known_ratio > 0.0);
    assert!(
        (exact.initial_known_ratio - shared.initial_known_ratio).abs() <= 0.005,
        "{} {}",
        exact.initial_known_ratio,
        shared.initial_known_ratio
    );
}

#[tokio::test]
async fn bad_exploration_requests_are_named_by_field() {
    let server = start(ServerConfig::default()).await;
    let mut client = ExplorationServiceClient::new(server.channel.clone());
    let cases: Vec<(&str, pb::ExploreRequest)> = vec![
        ("camera", {
            let mut r = request();
            r.camera = Some(pb::CameraModel {
                horizontal_fov: Some(0.0),
                ..Default::default()
            });
            r
        }),
        ("scene", {
            let mut r = request();
            r.scene = Some(pb::Scene::default());
            r
        }),
        ("start", {
            let mut r = request();
            r.start = vec![0.0; 5];
            r
        }),
        ("region", {
            let mut r = request();
            r.region = None;
            r
        }),
        ("resolution", {
            let mut r = request();
            r.resolution = Some(f64::NAN);
            r
        }),
        ("stop.known_ratio", {
            let mut r = request();
            r.stop.as_mut().unwrap().known_ratio = Some(1.5);
            r
        }),
        ("camera_link", {
            let mut r = request();
            r.camera_link = "no_such_link".into();
            r
        }),
        ("camera_link", {
            let mut r = request();
            r.camera_link = "link_3".into();
            r
        }),
        ("nbv.weights.distance", {
            let mut r = request();
            r.nbv = Some(pb::NbvOptions {
                weights: Some(pb::UtilityWeights {
                    distance: Some(f64::INFINITY),
                    ..Default::default()
                }),
                ..Default::default()
            });
            r
        }),
        ("nbv.visibility", {
            let mut r = request();
            r.nbv = Some(pb::NbvOptions {
                visibility: Some(pb::VisibilityCheck::default()),
                ..Default::default()
            });
            r
        }),
    ];
    for (field, req) in cases {
        let Err(err) = client.explore(req).await else {
            panic!("{field}: accepted");
        };
        assert_eq!(err.code(), Code::InvalidArgument, "{field}: {}", err.message());
        assert!(err.message().contains(field), "{field}: {}", err.message());
    }
    // Parameters the explore room names (ExploreField) are reported by their
    // request field, exactly.
    let mut stride = request();
    stride.pixel_stride = Some(0);
    let mut noise = request();
    noise.noise_stddev = Some(-1.0);
    let mut near = request();
    near.near_ray_spacing = Some(1.5);
    for (field, req) in [
        ("pixel_stride", stride),
        ("noise_stddev", noise),
        ("near_ray_spacing", near),
    ] {
        let Err(err) = client.explore(req).await else {
            panic!("{field}: accepted");
        };
        assert_eq!(err.code(), Code::InvalidArgument, "{field}: {}", err.message());
        let details = err.get_details_bad_request().expect("BadRequest details");
        assert_eq!(details.field_violations[0].field, field);
    }
    // a start in collision with the scene is refused before the loop runs
    let mut r = request();
    r.scene
        .as_mut()
        .unwrap()
        .objects
        .push(cuboid("on the arm", [1.0, 0.0, 1.6], [0.6, 0.6, 0.6]));
    let mut stream = client.explore(r).await.unwrap().into_inner();
    let Err(err) = stream.message().await else {
        panic!("a start in collision was accepted");
    };
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(err.message().contains("start"), "{}", err.message());
}

#[tokio::test]
async fn the_time_budget_ends_a_long_exploration_with_a_timeout_summary() {
    let server = start(ServerConfig::default()).await;
    let mut client = ExplorationServiceClient::new(server.channel.clone());
    let mut req = request();
    req.resolution = Some(0.1);
    req.pixel_stride = Some(2);
    req.stop = Some(pb::ExploreStopRule {
        known_ratio: Some(1.0),
        max_iterations: Some(10_000),
        max_consecutive_failures: Some(10_000),
    });
    // well under the time the loop needs before it runs out of views here
    req.time_budget = Some(0.08);
    let t0 = std::time::Instant::now();
    let mut stream = client.explore(req).await.unwrap().into_inner();
    let mut summary = None;
    while let Some(msg) = stream.message().await.unwrap() {
        if let Some(Event::Summary(s)) = msg.event {
            summary = Some(s);
        }
    }
    let s = summary.expect("a summary");
    assert_eq!(s.status, pb::ExploreStatus::Timeout as i32);
    // one stage past the budget at most: a plan is cut by the same deadline
    assert!(
        t0.elapsed() < std::time::Duration::from_secs(4),
        "{:?}",
        t0.elapsed()
    );
}
