//! Path tracking: circles and lines sampled by the path builders, and their bad input.

use super::*;

/// Planar chain tracing a circle (S2 Tab. 5 setting): every step converges, joints move
/// continuously.
#[test]
fn track_circle_on_planar_chain() {
    for n in [2, 5, 10] {
        let chain = builtin_chain(&format!("planar_{n}")).unwrap();
        let q0: Vec<f64> = (0..n).map(|i| if i == 0 { 0.2 } else { 0.3 }).collect();
        let start = chain.fk(&q0);
        let centre = Point3::from(start.translation.vector * 0.8);
        let path = circle_path(&start, &centre, &Vector3::z(), std::f64::consts::PI / 50.0, 100).unwrap();
        let targets: Vec<IkTarget> = path
            .iter()
            .map(|t| IkTarget::Position(Point3::from(t.translation.vector)))
            .collect();
        for solver in [
            LinearSolverKind::SvdPseudoinverse,
            LinearSolverKind::AngleRelaxation,
        ] {
            let tp = TrackParams {
                ik: IkParams {
                    linear_solver: solver,
                    position_tolerance: 6e-5,
                    ..TrackParams::default().ik
                },
                ..TrackParams::default()
            };
            let r = track_path(&chain, &targets, &q0, &tp, 1, Deadline::none()).unwrap();
            assert!(r.all_converged, "planar_{n} {solver:?}");
            assert_eq!(r.steps.len(), 101);
            assert!(
                r.max_joint_step < 0.6,
                "planar_{n} {solver:?}: jump {}",
                r.max_joint_step
            );
            for (s, t) in r.steps.iter().zip(&targets) {
                assert!((chain.fk(&s.joints).translation.vector - t.position()).norm() <= 6e-5);
            }
        }
    }
}

/// KR 210 tracing a 10 mm circle with fixed orientation (S2 Tab. 6 setting) and a line.
#[test]
fn track_kr210_circle_and_line() {
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let q0 = [0.1, -1.2, 1.0, 0.2, 0.8, 0.1];
    let start = chain.fk(&q0);
    let centre = Point3::from(start.translation.vector - Vector3::new(0.01, 0.0, 0.0));
    let circle = circle_path(&start, &centre, &Vector3::z(), std::f64::consts::PI / 100.0, 200).unwrap();
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.0, 0.2, -0.1)),
        start.rotation * UnitQuaternion::from_euler_angles(0.0, 0.2, 0.0),
    );
    let line = line_path(&start, &end, 50).unwrap();
    assert!((line[50].translation.vector - end.translation.vector).norm() < 1e-12);
    for path in [circle, line] {
        let targets: Vec<IkTarget> = path.iter().map(|t| IkTarget::Pose(*t)).collect();
        let r = track_path(
            &chain,
            &targets,
            &q0,
            &TrackParams::default(),
            1,
            Deadline::none(),
        )
        .unwrap();
        assert!(r.all_converged);
        assert!(r.max_joint_step < 0.1, "jump {}", r.max_joint_step);
    }
}

#[test]
fn bad_paths_are_errors() {
    let chain = builtin_chain("planar_3").unwrap();
    assert!(matches!(
        track_path(
            &chain,
            &[],
            &[0.0; 3],
            &TrackParams::default(),
            0,
            Deadline::none()
        ),
        Err(IkError::EmptyPath)
    ));
    let s = Isometry3::identity();
    let path_field = |r: Result<Vec<Isometry3<f64>>, IkError>| match r {
        Err(IkError::InvalidPath { field, .. }) => field,
        other => panic!("expected InvalidPath, got {other:?}"),
    };
    assert_eq!(path_field(line_path(&s, &s, 0)), PathParam::Steps);
    let o = Point3::origin();
    assert_eq!(
        path_field(circle_path(&s, &o, &Vector3::zeros(), 0.1, 10)),
        PathParam::Normal
    );
    assert_eq!(
        path_field(circle_path(&s, &o, &Vector3::z(), f64::NAN, 10)),
        PathParam::AngleStep
    );
    let far = Point3::new(0.0, f64::INFINITY, 0.0);
    assert_eq!(
        path_field(circle_path(&s, &far, &Vector3::z(), 0.1, 10)),
        PathParam::Centre
    );
    let nan_axis = Vector3::new(0.0, 0.0, f64::NAN);
    assert_eq!(
        path_field(circle_path(&s, &o, &nan_axis, 0.1, 10)),
        PathParam::Normal
    );
}
