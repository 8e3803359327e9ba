//! Built-in models checked against kinematics written independently from the
//! published tables: Denavit–Hartenberg products and hand-derived poses.

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Isometry3, Matrix4, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;

/// Standard DH link transform Rz(θ) Tz(d) Tx(a) Rx(α) as a 4×4 matrix.
fn dh(theta: f64, d: f64, a: f64, alpha: f64) -> Matrix4<f64> {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    Matrix4::new(
        ct,
        -st * ca,
        st * sa,
        a * ct, //
        st,
        ct * ca,
        -ct * sa,
        a * st, //
        0.0,
        sa,
        ca,
        d, //
        0.0,
        0.0,
        0.0,
        1.0,
    )
}

/// Modified (Craig) DH link transform Rx(α) Tx(a) Rz(θ) Tz(d).
fn craig(alpha: f64, a: f64, theta: f64, d: f64) -> Matrix4<f64> {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    Matrix4::new(
        ct,
        -st,
        0.0,
        a, //
        st * ca,
        ct * ca,
        -sa,
        -sa * d, //
        st * sa,
        ct * sa,
        ca,
        ca * d, //
        0.0,
        0.0,
        0.0,
        1.0,
    )
}

fn rot_z(angle: f64) -> Matrix4<f64> {
    dh(angle, 0.0, 0.0, 0.0)
}

/// Tool pose from a DH table: rows (θ offset, θ sign, d, a, α), then `tool`.
fn dh_chain(rows: &[(f64, f64, f64, f64, f64)], q: &[f64], tool: Matrix4<f64>) -> Matrix4<f64> {
    rows.iter().zip(q).fold(
        Matrix4::<f64>::identity(),
        |t, (&(off, sign, d, a, alpha), &qi)| t * dh(off + sign * qi, d, a, alpha),
    ) * tool
}

/// KUKA KR 210 / KR 120: standard DH derived by hand from the table, with the
/// controller's signs (A1 about −z, A4 and A6 about −x) as θ = −q.
fn kuka_dh(d4: f64, q: &[f64]) -> Matrix4<f64> {
    let rows = [
        (0.0, -1.0, 0.675, 0.35, -FRAC_PI_2),
        (0.0, 1.0, 0.0, 1.15, 0.0),
        (FRAC_PI_2, 1.0, 0.0, 0.041, FRAC_PI_2),
        (0.0, -1.0, d4, 0.0, -FRAC_PI_2),
        (0.0, 1.0, 0.0, 0.0, FRAC_PI_2),
        (0.0, -1.0, 0.215, 0.0, 0.0),
    ];
    dh_chain(&rows, q, Matrix4::identity())
}

/// ABB IRB 4600-60/2.05: standard DH derived by hand (θ2 offset −90°); the
/// ROS-Industrial tool0 has x opposite to DH x6, hence Rz(π).
fn abb_dh(q: &[f64]) -> Matrix4<f64> {
    let rows = [
        (0.0, 1.0, 0.495, 0.175, -FRAC_PI_2),
        (-FRAC_PI_2, 1.0, 0.0, 0.9, 0.0),
        (0.0, 1.0, 0.0, 0.175, -FRAC_PI_2),
        (0.0, 1.0, 0.96, 0.0, FRAC_PI_2),
        (0.0, 1.0, 0.0, 0.0, -FRAC_PI_2),
        (0.0, 1.0, 0.135, 0.0, 0.0),
    ];
    dh_chain(&rows, q, rot_z(PI))
}

fn ur5_dh(q: &[f64]) -> Matrix4<f64> {
    let d = [0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823];
    let a = [0.0, -0.425, -0.39225, 0.0, 0.0, 0.0];
    let alpha = [FRAC_PI_2, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2, 0.0];
    let rows: Vec<_> = (0..6).map(|i| (0.0, 1.0, d[i], a[i], alpha[i])).collect();
    dh_chain(&rows, q, Matrix4::identity())
}

fn iiwa_dh(q: &[f64]) -> Matrix4<f64> {
    let d = [0.36, 0.0, 0.42, 0.0, 0.4, 0.0, 0.081];
    let alpha = [
        -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2, -FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2, 0.0,
    ];
    let rows: Vec<_> = (0..7).map(|i| (0.0, 1.0, d[i], 0.0, alpha[i])).collect();
    dh_chain(&rows, q, Matrix4::identity())
}

fn panda_craig(q: &[f64]) -> Matrix4<f64> {
    let a = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088];
    let d = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0];
    let alpha = [
        0.0, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2,
    ];
    (0..7).fold(Matrix4::<f64>::identity(), |t, i| {
        t * craig(alpha[i], a[i], q[i], d[i])
    }) * craig(0.0, 0.0, 0.0, 0.107)
}

fn planar(n: usize, q: &[f64]) -> Matrix4<f64> {
    let rows: Vec<_> = (0..n).map(|_| (0.0, 1.0, 0.0, 1.0 / n as f64, 0.0)).collect();
    dh_chain(&rows, q, Matrix4::identity())
}

fn reference(name: &str, q: &[f64]) -> Matrix4<f64> {
    match name {
        "kuka_kr210_r2700_extra" => kuka_dh(1.2, q),
        "kuka_kr120_r2500_pro" => kuka_dh(1.0, q),
        "abb_irb4600_60_205" => abb_dh(q),
        "ur5" => ur5_dh(q),
        "franka_panda" => panda_craig(q),
        // The Franka Hand turns −45° about the flange z; its TCP is 103.4 mm out.
        "franka_panda_hand" => {
            let hand = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -PI / 4.0).to_homogeneous();
            panda_craig(q) * hand * Matrix4::new_translation(&Vector3::new(0.0, 0.0, 0.1034))
        }
        "kuka_lbr_iiwa14_r820" => iiwa_dh(q),
        planar_n => planar(planar_n["planar_".len()..].parse().unwrap(), q),
    }
}

fn random_q(chain: &Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .limits()
        .map(|(lo, hi)| rng.random_range(lo.max(-PI)..=hi.min(PI)))
        .collect()
}

#[test]
fn every_builtin_matches_its_published_kinematics() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for name in BUILTIN_NAMES {
        let chain = builtin_chain(name).unwrap();
        for _ in 0..200 {
            let q = random_q(&chain, &mut rng);
            let ours = chain.fk(&q).to_homogeneous();
            let theirs = reference(name, &q);
            let dp = (ours.fixed_view::<3, 1>(0, 3) - theirs.fixed_view::<3, 1>(0, 3)).norm();
            let dr = (ours.fixed_view::<3, 3>(0, 0) - theirs.fixed_view::<3, 3>(0, 0)).norm();
            assert!(dp < 1e-9, "{name}: position differs by {dp} m at {q:?}");
            assert!(dr < 1e-9, "{name}: orientation differs by {dr} at {q:?}");
        }
    }
}

#[test]
fn zero_poses_match_hand_derived_positions() {
    let cases: [(&str, Vector3<f64>); 6] = [
        // Arm stretched forward: 350 + 1150 + 1200 + 215 mm, height 675 − 41 mm.
        ("kuka_kr210_r2700_extra", Vector3::new(2.915, 0.0, 0.634)),
        ("kuka_kr120_r2500_pro", Vector3::new(2.715, 0.0, 0.634)),
        // Arm 2 vertical: x = 175 + 960 + 135, z = 495 + 900 + 175 mm.
        ("abb_irb4600_60_205", Vector3::new(1.27, 0.0, 1.57)),
        // UR5 zero, DH base frame: x = a2 + a3, y = −(d4 + d6), z = d1 − d5.
        ("ur5", Vector3::new(-0.81725, -0.19145, -0.005491)),
        ("kuka_lbr_iiwa14_r820", Vector3::new(0.0, 0.0, 1.261)),
        ("planar_4", Vector3::new(1.0, 0.0, 0.0)),
    ];
    for (name, expected) in cases {
        let chain = builtin_chain(name).unwrap();
        let p = chain.fk(&vec![0.0; chain.dof()]).translation.vector;
        assert!((p - expected).norm() < 1e-9, "{name}: {p:?} vs {expected:?}");
    }
}

#[test]
fn jacobian_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let h = 1e-6;
    for name in BUILTIN_NAMES {
        let chain = builtin_chain(name).unwrap();
        for _ in 0..20 {
            let q = random_q(&chain, &mut rng);
            let jac = chain.jacobian(&q);
            for i in 0..chain.dof() {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += h;
                qm[i] -= h;
                let (tp, tm) = (chain.fk(&qp), chain.fk(&qm));
                let v = (tp.translation.vector - tm.translation.vector) / (2.0 * h);
                // Angular velocity from the rotation difference R(q+h) R(q−h)ᵀ.
                let w = (tp.rotation * tm.rotation.inverse()).scaled_axis() / (2.0 * h);
                let col = jac.column(i);
                let err_v = (col.fixed_rows::<3>(0) - v).norm();
                let err_w = (col.fixed_rows::<3>(3) - w).norm();
                assert!(err_v < 1e-6 && err_w < 1e-6, "{name} joint {i}: {err_v} {err_w}");
            }
        }
    }
}

#[test]
fn link_frames_end_at_the_tip() {
    let chain = builtin_chain("franka_panda").unwrap();
    let q = [0.1, -0.4, 0.3, -2.0, 0.2, 1.5, 0.7];
    let mut frames = Vec::new();
    chain.link_frames_into(&q, &mut frames);
    assert_eq!(frames.len(), chain.links().len());
    let tip: Isometry3<f64> = *frames.last().unwrap();
    assert!((tip.to_homogeneous() - chain.fk(&q).to_homogeneous()).norm() < 1e-12);
    assert_eq!(chain.links()[0].name, "base_link");
}

#[test]
fn prismatic_and_fixed_joints_compose() {
    let urdf = r#"<robot name="slide">
      <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
      <joint name="j1" type="prismatic"><parent link="a"/><child link="b"/>
        <origin xyz="0 0 1" rpy="0 0 0"/><axis xyz="1 0 0"/>
        <limit lower="0" upper="2" effort="1" velocity="0.5"/></joint>
      <joint name="f" type="fixed"><parent link="b"/><child link="c"/>
        <origin xyz="0 1 0" rpy="0 0 1.5707963267948966"/></joint>
      <joint name="j2" type="continuous"><parent link="c"/><child link="d"/>
        <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
    </robot>"#;
    let chain = parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    assert_eq!(chain.dof(), 2);
    assert_eq!(chain.joints()[0].max_velocity, Some(0.5));
    assert!(chain.joints()[1].upper.is_infinite());
    // Slide 0.7 along x, then (0,1,0), then the yawed frame puts (0.5,0,0) along +y.
    let p = chain.fk(&[0.7, 0.3]).translation.vector;
    assert!((p - Vector3::new(0.7, 1.5, 1.0)).norm() < 1e-12, "{p:?}");
    let jac = chain.jacobian(&[0.7, 0.3]);
    assert!((jac.column(0) - nalgebra::Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0)).norm() < 1e-12);
}

#[test]
fn bad_urdfs_are_rejected_with_reasons() {
    let spec = ChainSpec::default();
    let limits = UrdfLimits::default();
    let err = |text: &str| parse_chain(text, &spec, limits).unwrap_err();
    assert!(matches!(err(""), RobotError::MalformedUrdf(_)));
    assert!(matches!(err("<robot"), RobotError::MalformedUrdf(_)));
    assert!(matches!(err("not xml at all"), RobotError::MalformedUrdf(_)));
    let two_tips = r#"<robot name="y"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="fixed"><parent link="a"/><child link="c"/></joint></robot>"#;
    assert!(matches!(err(two_tips), RobotError::AmbiguousTip { .. }));
    let spec_bc = ChainSpec {
        base_link: Some("b".into()),
        tip_link: Some("c".into()),
    };
    assert!(matches!(
        parse_chain(two_tips, &spec_bc, limits).unwrap_err(),
        RobotError::NotSerialChain { .. }
    ));
    let spec_x = ChainSpec {
        base_link: None,
        tip_link: Some("x".into()),
    };
    assert!(matches!(
        parse_chain(two_tips, &spec_x, limits).unwrap_err(),
        RobotError::UnknownLink { .. }
    ));
    let nan = r#"<robot name="n"><link name="a"/><link name="b"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <origin xyz="0 NaN 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
    assert!(matches!(err(nan), RobotError::NonFiniteValue { .. }));
    let floating = r#"<robot name="f"><link name="a"/><link name="b"/>
      <joint name="j" type="floating"><parent link="a"/><child link="b"/></joint></robot>"#;
    assert!(matches!(err(floating), RobotError::UnsupportedJoint { .. }));
    let small = UrdfLimits {
        max_bytes: 10,
        max_elements: 5,
        ..UrdfLimits::default()
    };
    assert!(matches!(
        parse_chain(nan, &spec, small).unwrap_err(),
        RobotError::UrdfTooLarge { .. }
    ));
}

#[test]
fn mesh_files_are_reported_not_read() {
    let urdf = r#"<robot name="m"><link name="a"><collision><geometry>
      <mesh filename="/etc/passwd"/></geometry></collision></link></robot>"#;
    let chain = parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    assert_eq!(chain.dof(), 0);
    assert_eq!(
        chain.collision()[0].shapes[0].shape,
        Shape::MeshReference {
            filename: "/etc/passwd".into(),
            scale: nalgebra::Vector3::new(1.0, 1.0, 1.0),
        }
    );
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, ..Default::default() })]

    /// Mangled URDFs (text cut, spliced or replaced by XML-significant or non-finite
    /// text) are answered with an error or a chain, never a panic, and a chain they
    /// yield evaluates without panicking.
    #[test]
    fn mangled_urdfs_never_panic(
        robot in 0usize..BUILTIN_NAMES.len(),
        cut in 0usize..20_000,
        len in 0usize..64,
        insert in proptest::sample::select(vec!["", "<", ">", "\"", "nan", "inf", "-1e309", "<joint", "</robot>", "&amp;", "\u{0}"]),
    ) {
        let text = builtin_urdf(BUILTIN_NAMES[robot]).unwrap();
        let start = text.char_indices().map(|(i, _)| i).find(|&i| i >= cut.min(text.len())).unwrap_or(text.len());
        let end = text.char_indices().map(|(i, _)| i).find(|&i| i >= start + len).unwrap_or(text.len());
        let mangled = format!("{}{insert}{}", &text[..start], &text[end..]);
        if let Ok(chain) = parse_chain(&mangled, &ChainSpec::default(), UrdfLimits::default()) {
            let q = vec![0.0; chain.dof()];
            let _ = chain.fk(&q);
            let _ = chain.jacobian(&q);
        }
    }
}

#[test]
fn every_arm_name_is_a_built_in_with_six_or_seven_joints() {
    for name in ARM_NAMES {
        let dof = builtin_chain(name).unwrap().dof();
        assert!(dof == 6 || dof == 7, "{name}: {dof} joints");
    }
}

fn two_links(joint_body: &str) -> String {
    format!(
        r#"<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{joint_body}</joint></robot>"#
    )
}

/// Regression: 3,500 nested elements overflowed a pool thread's stack in the
/// recursive XML parser and aborted the server.
#[test]
fn deeply_nested_urdf_is_rejected_before_parsing() {
    let text = format!(
        r#"<robot name="r"><link name="a"/>{}{}</robot>"#,
        "<x>".repeat(3500),
        "</x>".repeat(3500)
    );
    let err = parse_chain(&text, &ChainSpec::default(), UrdfLimits::default()).unwrap_err();
    assert!(err.to_string().contains("nested more than 64 deep"), "{err}");
    // 64 levels are fine for the scan (the parser then decides).
    let ok = format!(
        r#"<robot name="r"><link name="a"/>{}{}</robot>"#,
        "<x>".repeat(62),
        "</x>".repeat(62)
    );
    parse_chain(&ok, &ChainSpec::default(), UrdfLimits::default()).unwrap();
}

/// Regression: 840 KB of unclosed `<x>` cost the parser 30–42 s of CPU. The
/// bound below is a regression guard two orders of magnitude under that, not a
/// performance claim (the pre-scan rejects it in well under a millisecond in a
/// release build).
#[test]
fn unclosed_elements_at_the_size_limit_fail_fast() {
    let text = format!(r#"<robot name="r"><link name="a"/>{}"#, "<x>".repeat(280_000));
    let started = std::time::Instant::now();
    assert!(parse_chain(&text, &ChainSpec::default(), UrdfLimits::default()).is_err());
    assert!(
        started.elapsed() < std::time::Duration::from_millis(500),
        "{:?}",
        started.elapsed()
    );
    // Many siblings, quoted `>` and comments are scanned, not mistaken for depth.
    let siblings = format!(
        r#"<robot name="r"><!-- <a><b> --><link name="a"><collision name="v>x"><geometry><box size="1 1 1"/></geometry></collision></link>{}</robot>"#,
        "<material name=\"m\"/>".repeat(15_000)
    );
    let started = std::time::Instant::now();
    parse_chain(&siblings, &ChainSpec::default(), UrdfLimits::default()).unwrap();
    eprintln!("15,000 siblings: {:?}", started.elapsed());
    let too_many = format!(r#"<robot name="r">{}</robot>"#, "<x/>".repeat(25_000));
    assert!(matches!(
        parse_chain(&too_many, &ChainSpec::default(), UrdfLimits::default()).unwrap_err(),
        RobotError::TooManyElements {
            what: "XML elements",
            ..
        }
    ));
    let doctype = r#"<!DOCTYPE r [<!ENTITY a "aaaa">]><robot name="r"><link name="a"/></robot>"#;
    assert!(parse_chain(doctype, &ChainSpec::default(), UrdfLimits::default()).is_err());
}

/// Regression: an axis of (1e308, 1e308, 0) overflowed normalisation, origins of
/// 1e308 gave non-finite FK, and velocity limits of −5 or NaN were accepted.
#[test]
fn extreme_urdf_values_are_rejected_or_normalised() {
    let spec = ChainSpec::default();
    let limits = UrdfLimits::default();
    let lim = r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#;
    let huge_axis = two_links(&format!(r#"<axis xyz="1e308 1e308 0"/>{lim}"#));
    let chain = parse_chain(&huge_axis, &spec, limits).unwrap();
    let axis = chain.joints()[0].axis;
    assert!(
        (axis.x - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12,
        "{axis:?}"
    );
    let zero_axis = two_links(&format!(r#"<axis xyz="0 0 1e-300"/>{lim}"#));
    assert!(matches!(
        parse_chain(&zero_axis, &spec, limits).unwrap_err(),
        RobotError::ZeroAxis { .. }
    ));
    let far = two_links(&format!(r#"<origin xyz="1e308 0 0"/>{lim}"#));
    assert!(matches!(
        parse_chain(&far, &spec, limits).unwrap_err(),
        RobotError::ValueOutOfRange { .. }
    ));
    for velocity in ["-5", "NaN", "5e-324"] {
        let v = two_links(&format!(
            r#"<limit lower="-1" upper="1" effort="1" velocity="{velocity}"/>"#
        ));
        assert!(
            matches!(
                parse_chain(&v, &spec, limits).unwrap_err(),
                RobotError::ValueOutOfRange { .. }
            ),
            "velocity {velocity}"
        );
    }
    let effort = two_links(r#"<limit lower="-1" upper="1" effort="-1" velocity="1"/>"#);
    assert!(parse_chain(&effort, &spec, limits).is_err());
    // Joint values are bounded too, so FK stays finite.
    let slide = r#"<robot name="s"><link name="a"/><link name="b"/>
      <joint name="j" type="prismatic"><parent link="a"/><child link="b"/>
      <limit lower="-1e300" upper="1e300" effort="1" velocity="1"/></joint></robot>"#;
    let chain = parse_chain(slide, &spec, limits).unwrap();
    assert!(matches!(
        chain.check_joints(&[1e308]).unwrap_err(),
        RobotError::JointOutOfRange { .. }
    ));
    chain.check_joints(&[1e6]).unwrap();
    assert!(chain.fk(&[1e6]).translation.vector.iter().all(|v| v.is_finite()));
}

/// Regression: duplicate joint names and a cycle detached from the root were accepted.
#[test]
fn duplicate_joints_and_detached_cycles_are_rejected() {
    let spec = ChainSpec::default();
    let limits = UrdfLimits::default();
    let dup = r#"<robot name="d"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="j" type="fixed"><parent link="b"/><child link="c"/></joint></robot>"#;
    let err = parse_chain(dup, &spec, limits).unwrap_err();
    assert!(err.to_string().contains("two joints share the name `j`"), "{err}");
    let cycle = r#"<robot name="c"><link name="a"/><link name="b"/><link name="x"/><link name="y"/>
      <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="fixed"><parent link="x"/><child link="y"/></joint>
      <joint name="j3" type="fixed"><parent link="y"/><child link="x"/></joint></robot>"#;
    let err = parse_chain(cycle, &spec, limits).unwrap_err();
    assert!(
        err.to_string().contains("cycle of joints detached from the root"),
        "{err}"
    );
}

/// Regression: 25,000 collision boxes in a 1.7 MB URDF were accepted, and scoring
/// with collision-vertex points then used gigabytes.
#[test]
fn collision_shapes_per_model_are_limited() {
    let boxes = r#"<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>"#.repeat(1001);
    let text = format!(r#"<robot name="b"><link name="a">{boxes}</link></robot>"#);
    assert!(matches!(
        parse_chain(&text, &ChainSpec::default(), UrdfLimits::default()).unwrap_err(),
        RobotError::TooManyElements {
            what: "collision shapes",
            ..
        }
    ));
}

/// Names echoed in errors are clipped, so a 3,000-character name cannot blow up
/// a reply's metadata.
#[test]
fn echoed_names_are_clipped() {
    let long = "n".repeat(3000);
    let err = builtin_chain(&long).unwrap_err().to_string();
    assert!(err.len() < 400 && err.contains('…'), "{}", err.len());
}

/// Signed distance (m) from `p` (in the shape's frame) to a URDF primitive:
/// capsules and cylinders along z, centred.
fn urdf_shape_distance(shape: &urdf_rs::Geometry, p: &Vector3<f64>) -> f64 {
    match shape {
        urdf_rs::Geometry::Sphere { radius } => p.norm() - radius,
        urdf_rs::Geometry::Capsule { radius, length } => {
            let z = p.z.clamp(-length / 2.0, length / 2.0);
            (p - Vector3::new(0.0, 0.0, z)).norm() - radius
        }
        urdf_rs::Geometry::Box { size } => {
            let q = p.abs() - Vector3::new(size[0], size[1], size[2]) / 2.0;
            q.map(|v| v.max(0.0)).norm() + q.max().min(0.0)
        }
        other => panic!("unexpected shape {other:?}"),
    }
}

/// The convex polytope an embedded mesh file (`kinplan://builtin/…`, an
/// OBJ) describes, as its outward faces `(normal, point)`, after checking
/// that the faces close up (every edge in exactly two faces, once each way)
/// and that no vertex lies in front of any face (by more than 1 µm), so
/// the faces bound the
/// convex hull of the vertices, which the collision model uses. Read from
/// the file with its own parser, not the library's.
fn builtin_hull_faces(filename: &str) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let path = filename
        .strip_prefix("kinplan://builtin/")
        .expect("an embedded mesh");
    let file = format!("{}/src/robot/builtin/meshes/{path}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(file).unwrap();
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let x: Vec<f64> = it.map(|t| t.parse().unwrap()).collect();
                v.push(Vector3::new(x[0], x[1], x[2]));
            }
            Some("f") => f.push(it.map(|t| t.parse::<usize>().unwrap() - 1).collect::<Vec<_>>()),
            _ => {}
        }
    }
    let mut edges = std::collections::HashMap::new();
    let faces: Vec<_> = f
        .iter()
        .map(|t| {
            assert_eq!(t.len(), 3, "{filename}: triangles");
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
            let n = (v[t[1]] - v[t[0]]).cross(&(v[t[2]] - v[t[0]])).normalize();
            for p in &v {
                let ahead = n.dot(&(p - v[t[0]]));
                assert!(ahead <= 1e-6, "{filename}: not convex or not outward ({ahead} m)");
            }
            (n, v[t[0]])
        })
        .collect();
    for (&(a, b), &count) in &edges {
        assert!(
            count == 1 && edges.get(&(b, a)) == Some(&1),
            "{filename}: edge {a}-{b} not closed"
        );
    }
    faces
}

/// The built-in Panda's and UR5's collision shapes hold the real arms: every
/// vertex of the collision meshes MoveIt plans with (example-robot-data,
/// placed in the built-in link frames by `fit_covers.py`, which checks the
/// kinematics against pinocchio's) lies inside the one convex shape of its
/// link (a primitive, or the grown hull of the mesh the library embeds), so
/// the shape holds the mesh, and a state the built-in model finds free is
/// free for the real arm. Read straight from the URDF text and the mesh
/// files, not through our parsers.
#[test]
fn builtin_shapes_hold_the_real_meshes() {
    let panda = include_str!("builtin/panda_mesh_points.txt");
    let ur5 = include_str!("builtin/ur5_mesh_points.txt");
    for (name, points) in [
        ("franka_panda", panda),
        ("franka_panda_hand", panda),
        ("ur5", ur5),
    ] {
        let robot = urdf_rs::read_from_string(builtin_urdf(name).unwrap()).unwrap();
        let mut checked = 0;
        for line in points.lines().filter(|l| !l.starts_with('#')) {
            let mut it = line.split_whitespace();
            let link_name = it.next().unwrap();
            let v: Vec<f64> = it.map(|x| x.parse().unwrap()).collect();
            let Some(link) = robot.links.iter().find(|l| l.name == link_name) else {
                assert!(name == "franka_panda", "{name} has no link {link_name}");
                continue;
            };
            assert_eq!(link.collision.len(), 1, "{name} {link_name}: one convex shape");
            let c = &link.collision[0];
            let (xyz, rpy) = (c.origin.xyz, c.origin.rpy);
            let pose = Isometry3::new(Vector3::new(xyz[0], xyz[1], xyz[2]), Vector3::zeros())
                * nalgebra::UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
            let local = pose.inverse_transform_point(&nalgebra::Point3::new(v[0], v[1], v[2]));
            let d = match &c.geometry {
                urdf_rs::Geometry::Mesh { filename, .. } => builtin_hull_faces(filename)
                    .iter()
                    .map(|(n, p)| n.dot(&(local.coords - p)))
                    .fold(f64::NEG_INFINITY, f64::max),
                primitive => urdf_shape_distance(primitive, &local.coords),
            };
            assert!(
                d <= -1e-4,
                "{name} {link_name}: mesh vertex {v:?} at {d} m from its shape (must be 0.1 mm inside)"
            );
            checked += 1;
        }
        assert!(checked >= 500, "{name}: {checked} vertices checked");
    }
}
