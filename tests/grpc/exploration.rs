//! ExplorationService end to end: a hand-placed wall scanned into an empty
//! tree (cells counted by hand), the tree's round trip through OctreeInfo,
//! next-best views checked against the utility formula, and bad input.

use kinplan_server::ServerConfig;
use kinplan_server::pb::{
    self, exploration_service_client::ExplorationServiceClient, insert_scan_request::Scan,
};
use tonic::Code;

use crate::start;

const RES: f64 = 0.1;

/// A 6 × 6 wall of points at the centres of the cells x ∈ [2.0, 2.1),
/// y, z ∈ [−0.3, 0.3): 36 distinct end-point cells.
fn wall() -> Vec<f32> {
    let mut xyz = Vec::new();
    for iy in -3..3 {
        for iz in -3..3 {
            xyz.extend([2.05f32, (iy as f32 + 0.5) * 0.1, (iz as f32 + 0.5) * 0.1]);
        }
    }
    xyz
}

fn scan_request(octree: Option<pb::Octree>, xyz: Vec<f32>) -> pb::InsertScanRequest {
    pb::InsertScanRequest {
        octree,
        resolution: RES,
        sensor_pose: Some(pb::Pose::default()),
        scan: Some(Scan::Points(pb::PointCloud { xyz })),
        max_range: None,
        discretize: false,
        full: false,
        near_ray_spacing: 0.0,
    }
}

#[tokio::test]
async fn a_scanned_wall_has_the_hand_counted_cells_and_round_trips() {
    let server = start(ServerConfig::default()).await;
    let mut exploration = ExplorationServiceClient::new(server.channel.clone());
    let reply = exploration
        .insert_scan(scan_request(None, wall()))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.occupied_cells, 36);
    assert_eq!(reply.skipped_points, 0);
    // Every beam crosses the cells from the origin's cell to x = 2.0: at least 20 free cells each.
    assert!(reply.free_cells >= 20, "{}", reply.free_cells);
    let stats = reply.stats.unwrap();
    assert_eq!(
        stats.occupied_leaves, 36,
        "a one-cell-thick wall cannot be pruned"
    );
    let tree = reply.octree.unwrap();
    assert!(tree.binary && tree.id == "OcTree");

    let info = exploration
        .octree_info(pb::OctreeInfoRequest {
            octree: Some(tree.clone()),
            r#box: None,
        })
        .await
        .unwrap()
        .into_inner();
    let again = info.stats.unwrap();
    assert_eq!(
        (again.occupied_leaves, again.free_leaves),
        (stats.occupied_leaves, stats.free_leaves)
    );
    assert!(
        (info.occupied_volume - 36.0 * RES.powi(3)).abs() < 1e-9,
        "{}",
        info.occupied_volume
    );

    // A second scan of the same wall adds no cell.
    let twice = exploration
        .insert_scan(scan_request(Some(tree), wall()))
        .await
        .unwrap()
        .into_inner();
    assert_eq!(twice.stats.unwrap().occupied_leaves, 36);
}

#[tokio::test]
async fn next_best_views_are_ranked_by_the_utility_formula() {
    let server = start(ServerConfig::default()).await;
    let mut exploration = ExplorationServiceClient::new(server.channel.clone());
    let tree = exploration
        .insert_scan(scan_request(None, wall()))
        .await
        .unwrap()
        .into_inner()
        .octree;
    let reply = exploration
        .next_best_view(pb::NextBestViewRequest {
            octree: tree,
            camera: None,
            camera_pose: Some(pb::Pose::default()),
            robot: None,
            robot_base: None,
            camera_mount: None,
            candidate_poses: Vec::new(),
            options: Some(pb::NbvOptions {
                weights: Some(pb::UtilityWeights {
                    information_gain: Some(1.0),
                    distance: Some(0.5),
                    rotation: Some(0.25),
                }),
                max_results: Some(5),
                ..Default::default()
            }),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(reply.status, pb::NbvStatus::Complete as i32);
    let s = reply.stages.unwrap();
    assert!(s.frontier_cells > 0 && s.after_ptf <= s.after_orf && s.after_igf <= s.after_ptf);
    assert!(!reply.candidates.is_empty() && reply.candidates.len() <= 5);
    for c in &reply.candidates {
        let f = 0.5 * c.distance_score + 0.25 * c.rotation_score + c.information_gain;
        assert!((c.utility - f).abs() < 1e-9, "{} vs {f}", c.utility);
        // Intersection counts cell centres inside the frustum against its
        // volume in cells: at most a fraction of a percent over 1.
        assert!(
            (0.0..=1.01).contains(&c.information_gain),
            "Ig {} from {} cells",
            c.information_gain,
            c.unknown_cells
        );
        assert_eq!(c.reachability, pb::Reachability::Unchecked as i32);
    }
    assert!(reply.candidates.windows(2).all(|w| w[0].utility >= w[1].utility));
}

#[tokio::test]
async fn bad_exploration_input_is_named_by_field() {
    let server = start(ServerConfig::default()).await;
    let mut exploration = ExplorationServiceClient::new(server.channel.clone());
    let good = exploration
        .insert_scan(scan_request(None, wall()))
        .await
        .unwrap()
        .into_inner()
        .octree
        .unwrap();
    let mut truncated = good.clone();
    truncated.data.truncate(truncated.data.len() - 1);
    let err = exploration
        .octree_info(pb::OctreeInfoRequest {
            octree: Some(truncated),
            r#box: None,
        })
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(err.message().starts_with("octree:"), "{}", err.message());

    let err = exploration
        .insert_scan(scan_request(None, vec![1.0; 4]))
        .await
        .unwrap_err();
    assert!(err.message().starts_with("points.xyz:"), "{}", err.message());

    let mut nan_pose = scan_request(None, wall());
    nan_pose.sensor_pose = Some(pb::Pose {
        position: Some(pb::Vec3 {
            x: f64::NAN,
            y: 0.0,
            z: 0.0,
        }),
        orientation: None,
    });
    let err = exploration.insert_scan(nan_pose).await.unwrap_err();
    assert!(
        err.message().starts_with("sensor_pose.position.x:"),
        "{}",
        err.message()
    );

    let err = exploration
        .next_best_view(pb::NextBestViewRequest {
            octree: Some(good),
            camera: Some(pb::CameraModel {
                horizontal_fov: Some(0.0),
                ..Default::default()
            }),
            camera_pose: Some(pb::Pose::default()),
            ..Default::default()
        })
        .await
        .unwrap_err();
    assert_eq!(err.code(), Code::InvalidArgument);
    assert!(err.message().starts_with("camera:"), "{}", err.message());
}

/// A 4 × 3 depth image of a plane 2 m ahead (fx = fy = 2 px, cx = 1.5,
/// cy = 1): pixel (u, v) is the point (u − 1.5, v − 1, 2) in the optical
/// frame, here the world frame (identity sensor pose).
fn plane_image() -> pb::DepthImage {
    pb::DepthImage {
        width: 4,
        height: 3,
        depth: vec![2.0; 12],
        fx: 2.0,
        fy: 2.0,
        cx: 1.5,
        cy: 1.0,
        ..Default::default()
    }
}

#[tokio::test]
async fn depth_images_in_metres_millimetres_or_with_a_camera_model_insert_like_their_points() {
    let server = start(ServerConfig::default()).await;
    let mut exploration = ExplorationServiceClient::new(server.channel.clone());
    let with = |scan| pb::InsertScanRequest {
        scan: Some(scan),
        ..scan_request(None, Vec::new())
    };
    let mut xyz = Vec::new();
    for v in 0..3 {
        for u in 0..4 {
            xyz.extend([u as f32 - 1.5, v as f32 - 1.0, 2.0]);
        }
    }
    let by_points = exploration
        .insert_scan(with(Scan::Points(pb::PointCloud { xyz })))
        .await
        .unwrap()
        .into_inner();
    let mm = pb::DepthImage {
        depth: Vec::new(),
        depth_mm: [2000u16.to_le_bytes(); 12].concat(),
        ..plane_image()
    };
    // the camera model with the same intrinsics: tan(hfov/2) = 1.5/2, tan(vfov/2) = 1/2
    let camera = pb::DepthImage {
        fx: 0.0,
        fy: 0.0,
        cx: 0.0,
        cy: 0.0,
        camera: Some(pb::CameraModel {
            horizontal_fov: Some(2.0 * 0.75f64.atan()),
            vertical_fov: Some(2.0 * 0.5f64.atan()),
            width: Some(4),
            height: Some(3),
            ..Default::default()
        }),
        ..plane_image()
    };
    for image in [plane_image(), mm, camera] {
        let reply = exploration
            .insert_scan(with(Scan::DepthImage(image)))
            .await
            .unwrap()
            .into_inner();
        assert_eq!(reply.occupied_cells, by_points.occupied_cells);
        assert_eq!(reply.free_cells, by_points.free_cells);
        assert_eq!(reply.octree.unwrap().data, by_points.octree.clone().unwrap().data);
    }

    // bad images name their field
    let cases: Vec<(pb::DepthImage, &str)> = vec![
        (
            pb::DepthImage {
                depth_mm: vec![0; 24],
                ..plane_image()
            },
            "depth_image.depth_mm:",
        ),
        (
            pb::DepthImage {
                depth: Vec::new(),
                depth_mm: vec![0; 23],
                ..plane_image()
            },
            "depth_image.depth_mm:",
        ),
        (
            pb::DepthImage {
                width: 1 << 13,
                height: 1 << 12,
                ..plane_image()
            },
            "depth_image.width:",
        ),
        (
            pb::DepthImage {
                fx: 0.0,
                fy: 0.0,
                cx: 0.0,
                cy: 0.0,
                camera: Some(pb::CameraModel::default()),
                ..plane_image()
            },
            "depth_image.camera.width:",
        ),
        (
            pb::DepthImage {
                camera: Some(pb::CameraModel::default()),
                ..plane_image()
            },
            "depth_image.camera:",
        ),
        (
            pb::DepthImage {
                depth: Vec::new(),
                ..plane_image()
            },
            "depth_image.depth:",
        ),
    ];
    for (image, field) in cases {
        let err = exploration
            .insert_scan(with(Scan::DepthImage(image)))
            .await
            .unwrap_err();
        assert_eq!(err.code(), Code::InvalidArgument, "{}", err.message());
        assert!(err.message().starts_with(field), "{field}: {}", err.message());
    }
}

#[tokio::test]
async fn a_shared_near_field_keeps_every_end_point_and_refuses_bad_spacings_by_name() {
    let server = start(ServerConfig::default()).await;
    let mut exploration = ExplorationServiceClient::new(server.channel.clone());
    // 64 × 48 pixels, f = 40 px, of a plane tilted away from the camera (2–4.5 m)
    let (w, h) = (64u32, 48u32);
    let depth: Vec<f32> = (0..w * h)
        .map(|i| 2.0 + 2.5 * (i % w) as f32 / w as f32)
        .collect();
    let image = pb::DepthImage {
        width: w,
        height: h,
        depth,
        fx: 40.0,
        fy: 40.0,
        cx: 31.5,
        cy: 23.5,
        ..Default::default()
    };
    let with = |spacing: f64, discretize: bool| pb::InsertScanRequest {
        scan: Some(Scan::DepthImage(image.clone())),
        near_ray_spacing: spacing,
        discretize,
        ..scan_request(None, Vec::new())
    };
    let exact = exploration
        .insert_scan(with(0.0, false))
        .await
        .unwrap()
        .into_inner();
    let fast = exploration
        .insert_scan(with(0.7, false))
        .await
        .unwrap()
        .into_inner();
    // every end point is still occupied; the free cells are those of the exact beams
    // after each beam's start, so at most as many, and all but a few of them
    assert_eq!(fast.occupied_cells, exact.occupied_cells);
    assert!(fast.free_cells <= exact.free_cells);
    assert!(
        fast.free_cells * 100 >= exact.free_cells * 99,
        "{} of {} free cells",
        fast.free_cells,
        exact.free_cells
    );
    for (spacing, discretize) in [(1.5, false), (-0.1, false), (f64::NAN, false), (0.5, true)] {
        let err = exploration
            .insert_scan(with(spacing, discretize))
            .await
            .unwrap_err();
        assert_eq!(err.code(), Code::InvalidArgument, "{}", err.message());
        assert!(err.message().starts_with("near_ray_spacing"), "{}", err.message());
    }
}
