//! Properties on random trajectories: reversal and quaternion-sign invariance,
//! OC bounds, no panic on any input, the single pass against the printed S0
//! formulas, PTP time subadditivity.

use super::*;

/// Joints, poses, robot points, CPC weights.
type Trajectory = (
    Vec<Vec<f64>>,
    Vec<Isometry3<f64>>,
    Vec<Vec<Point3<f64>>>,
    Vec<f64>,
);

fn arb_trajectory() -> impl Strategy<Value = Trajectory> {
    (2usize..25, 1usize..7, 0usize..5).prop_flat_map(|(n, m, k)| {
        (
            prop::collection::vec(prop::collection::vec(-3.0..3.0f64, m), n),
            prop::collection::vec(
                (
                    prop::array::uniform3(-2.0..2.0f64),
                    prop::array::uniform3(-3.0..3.0f64),
                ),
                n,
            ),
            prop::collection::vec(prop::collection::vec(prop::array::uniform3(-1.0..1.0f64), k), n),
            prop::collection::vec(0.0..5.0f64, m),
        )
            .prop_map(|(q, poses, pts, w)| {
                let poses = poses
                    .into_iter()
                    .map(|(t, r)| Isometry3::new(Vector3::from(t), Vector3::from(r)))
                    .collect();
                let pts = pts
                    .into_iter()
                    .map(|row| row.into_iter().map(Point3::from).collect())
                    .collect();
                (q, poses, pts, w)
            })
    })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #[test]
    fn reversing_a_path_keeps_the_criteria((q, poses, pts, w) in arb_trajectory()) {
        let fwd = TrajectoryData { robot_points: Some(Rows::Nested(&pts)), ..TrajectoryData::new(Rows::Nested(&q), &poses) };
        let (mut rq, mut rp, mut rpts) = (q.clone(), poses.clone(), pts.clone());
        rq.reverse();
        rp.reverse();
        rpts.reverse();
        let bwd = TrajectoryData { robot_points: Some(Rows::Nested(&rpts)), ..TrajectoryData::new(Rows::Nested(&rq), &rp) };
        let a = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(fwd) }, &ScoreParams::default()).unwrap().scores;
        let b = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(bwd) }, &ScoreParams::default()).unwrap().scores;
        for c in [Criterion::Cd, Criterion::Jd, Criterion::Oc, Criterion::OcGeodesic, Criterion::Cpc, Criterion::Rdm,
                  Criterion::Jj, Criterion::Cj, Criterion::Jmj, Criterion::Cmj] {
            let (x, y) = (a.get(c).unwrap(), b.get(c).unwrap());
            prop_assert!(close(x, y), "{c}: {x} vs {y}");
        }
    }

    #[test]
    fn quaternion_signs_do_not_matter((q, poses, _pts, _w) in arb_trajectory(), flips in prop::collection::vec(any::<bool>(), 25)) {
        let flipped: Vec<_> = poses.iter().zip(&flips).map(|(p, &f)| {
            let mut p = *p;
            if f { p.rotation = UnitQuaternion::new_unchecked(-p.rotation.into_inner()); }
            p
        }).collect();
        let a = scores_of(&q, &poses);
        let b = scores_of(&q, &flipped);
        prop_assert!(close(a.oc, b.oc));
    }

    #[test]
    fn oc_is_a_half_of_the_geodesic_and_at_most_the_sum_of_pi_halves((q, poses, _pts, _w) in arb_trajectory()) {
        let s = scores_of(&q, &poses);
        prop_assert!(close(s.oc_geodesic, 2.0 * s.oc));
        prop_assert!(s.oc <= (poses.len() - 1) as f64 * std::f64::consts::FRAC_PI_2 + 1e-12);
    }

    #[test]
    fn any_input_is_answered_without_panic(
        rows in prop::collection::vec(prop::collection::vec(prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -1e300..1e300f64], 0..4), 0..8),
        npose in 0usize..8,
        ts in prop::option::of(prop::collection::vec(-1.0..1.0f64, 0..8)),
        dof in prop::option::of(0usize..4),
        w in prop::option::of(prop::collection::vec(-1.0..2.0f64, 0..4)),
        v in prop::collection::vec(-1.0..2.0f64, 0..4),
    ) {
        let poses = still_poses(npose);
        let t = TrajectoryData { timestamps: ts.as_deref(), ..TrajectoryData::new(Rows::Nested(&rows), &poses) };
        let input = ScoreInput { dof, joint_weights: w.as_deref(), limits: Some(JointLimits { v_max: &v, a_max: None }), ..ScoreInput::new(t) };
        let _ = score(&input, &ScoreParams { series: true, ..Default::default() });
    }
}

/// The S0 formulas written out literally (acos of the printed dot product,
/// nested sums over index ranges), to check the single pass against.
#[allow(clippy::needless_range_loop)] // indices on purpose: it mirrors the formulas
fn reference(q: &[Vec<f64>], poses: &[Isometry3<f64>], pts: &[Vec<Point3<f64>>], w: &[f64]) -> [f64; 10] {
    let n = q.len();
    let m = q[0].len();
    let p = |i: usize| poses[i].translation.vector;
    let (mut cd, mut jd, mut oc, mut cpc, mut rdm) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 1..n {
        cd += (p(i) - p(i - 1)).norm();
        for j in 0..m {
            jd += (q[i][j] - q[i - 1][j]).abs();
            cpc += w[j] * (q[i][j] - q[i - 1][j]).abs();
        }
        let (a, b) = (poses[i].rotation.coords, poses[i - 1].rotation.coords);
        let dot = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
        oc += dot.abs().clamp(-1.0, 1.0).acos();
        let mut mx: f64 = 0.0;
        for k in 0..pts[i].len() {
            mx = mx.max((pts[i][k] - pts[i - 1][k]).norm());
        }
        rdm += mx;
    }
    let (mut jj, mut cj, mut jmj, mut cmj) = (0.0, 0.0, 0.0f64, 0.0f64);
    for i in 3..n {
        let mut s = 0.0;
        for j in 0..m {
            s += (q[i][j] - 3.0 * q[i - 1][j] + 3.0 * q[i - 2][j] - q[i - 3][j]).abs();
        }
        let c = (p(i) - 3.0 * p(i - 1) + 3.0 * p(i - 2) - p(i - 3)).norm();
        jj += s;
        cj += c;
        jmj = jmj.max(s);
        cmj = cmj.max(c);
    }
    [cd, jd, oc, 2.0 * oc, cpc, rdm, jj, cj, jmj, cmj]
}

proptest! {
    #[test]
    fn single_pass_matches_the_printed_formulas((q, poses, pts, w) in arb_trajectory()) {
        let t = TrajectoryData { robot_points: Some(Rows::Nested(&pts)), ..TrajectoryData::new(Rows::Nested(&q), &poses) };
        let s = score(&ScoreInput { joint_weights: Some(&w), ..ScoreInput::new(t) }, &ScoreParams::default()).unwrap().scores;
        let want = reference(&q, &poses, &pts, &w);
        let got = [s.cd, s.jd, s.oc, s.oc_geodesic, s.cpc, s.rdm.unwrap(), s.jj, s.cj, s.jmj, s.cmj];
        for (k, (g, r)) in got.iter().zip(want).enumerate() {
            // acos near 1 loses digits: the OC terms get a looser bound
            let tol = if k == 2 || k == 3 { 1e-6 } else { 1e-9 };
            prop_assert!((g - r).abs() <= tol * (1.0 + r.abs()), "criterion {k}: {g} vs {r}");
        }
    }

    #[test]
    fn ptp_time_is_subadditive(
        a in prop::collection::vec(-3.0..3.0f64, 3),
        b in prop::collection::vec(-3.0..3.0f64, 3),
        c in prop::collection::vec(-3.0..3.0f64, 3),
        v in prop::collection::vec(0.1..3.0f64, 3),
        acc in prop::option::of(prop::collection::vec(0.1..10.0f64, 3)),
    ) {
        let lim = JointLimits { v_max: &v, a_max: acc.as_deref() };
        let q: Vec<f64> = [a, b, c].concat();
        let ct = crate::score::cycle_time(Rows::Flat { values: &q, width: 3 }, &lim, &Default::default()).unwrap();
        let tp = ct.potentials[0];
        prop_assert!(tp.gain >= -1e-12, "{tp:?}");
        prop_assert!((ct.total - tp.via).abs() < 1e-12);
    }
}
