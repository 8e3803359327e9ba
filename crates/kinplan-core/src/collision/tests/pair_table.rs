//! The pair tables against the exact geometry: a pair a table proves apart,
//! at a state or over a piece, is apart by parry's test at that state and at
//! every state sampled in the piece.

use std::sync::Arc;

use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::convert::pose_to_parry;
use super::super::model::MAX_BODIES;
use super::super::*;

fn panda_hand() -> Arc<RobotModel> {
    Arc::new(super::panda_hand_open())
}

fn random_state(model: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<f64> {
    super::lanes::random_state(model.chain(), rng)
}

/// Distance of bodies `a` and `b` at `q` (0 when they touch), by parry's
/// own query on every pair of their shapes, without the checker's bounds.
fn gap(model: &RobotModel, q: &[f64], a: usize, b: usize) -> f64 {
    let mut poses = [Isometry3::identity(); MAX_BODIES];
    model.body_poses(q, &mut poses);
    let bodies = &model.bodies;
    let mut nearest = f64::INFINITY;
    for sa in &bodies[a].shapes {
        for sb in &bodies[b].shapes {
            let (pa, pb) = (
                pose_to_parry(&(poses[a] * sa.offset)),
                pose_to_parry(&(poses[b] * sb.offset)),
            );
            nearest = nearest.min(
                parry3d_f64::query::distance(&pa, &*sa.shape, &pb, &*sb.shape)
                    .unwrap()
                    .distance,
            );
        }
    }
    nearest
}

fn name(model: &RobotModel, b: usize) -> &str {
    model.body_names().nth(b).unwrap()
}

#[test]
fn the_panda_wrist_pairs_have_tables_that_prove_most_states() {
    let model = panda_hand();
    let t0 = std::time::Instant::now();
    let tables = model.pair_tables();
    eprintln!("{} tables in {:?}", tables.len(), t0.elapsed());
    let names: Vec<(&str, &str)> = tables
        .iter()
        .map(|t| (name(&model, t.a), name(&model, t.b)))
        .collect();
    for pair in [("link_5", "link_7"), ("link_5", "panda_hand")] {
        assert!(names.contains(&pair), "{pair:?} not in {names:?}");
    }
    // not vacuous: most random states are proved for the wrist pairs
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for t in tables.iter().filter(|t| name(&model, t.a) == "link_5") {
        let proved = (0..2000)
            .filter(|_| t.proves_apart(&random_state(&model, &mut rng), &[]))
            .count();
        assert!(
            proved > 1400,
            "{} {}: {proved} of 2000",
            name(&model, t.a),
            name(&model, t.b)
        );
    }
}

#[test]
fn a_pair_proved_apart_is_apart_in_the_exact_geometry() {
    let model = panda_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let (mut proved, mut nearest) = (0, f64::INFINITY);
    for _ in 0..20_000 {
        let q = random_state(&model, &mut rng);
        for t in model.pair_tables() {
            if t.proves_apart(&q, &[]) {
                let d = gap(&model, &q, t.a, t.b);
                assert!(
                    d > 0.0,
                    "{q:?}: {} {} proved apart at {d} m",
                    name(&model, t.a),
                    name(&model, t.b)
                );
                proved += 1;
                nearest = nearest.min(d);
            }
        }
    }
    assert!(proved > 20_000, "{proved}");
    // the proofs reach close to the bodies, as the cells allow
    assert!(nearest < 0.01, "{nearest}");
}

#[test]
fn a_pair_proved_apart_over_a_piece_is_apart_at_every_state_in_it() {
    let model = panda_hand();
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let mut proved = 0;
    for _ in 0..3000 {
        let q = random_state(&model, &mut rng);
        let half: Vec<f64> = q.iter().map(|_| rng.random_range(-0.06..0.06)).collect();
        for t in model.pair_tables() {
            if !t.proves_apart(&q, &half) {
                continue;
            }
            proved += 1;
            for _ in 0..20 {
                let s: f64 = rng.random_range(-1.0..=1.0);
                let x: Vec<f64> = q.iter().zip(&half).map(|(v, h)| v + s * h).collect();
                let d = gap(&model, &x, t.a, t.b);
                assert!(
                    d > 0.0,
                    "{x:?}: {} {} proved apart at {d} m",
                    name(&model, t.a),
                    name(&model, t.b)
                );
            }
        }
    }
    assert!(proved > 3000, "{proved}");
}

#[test]
fn a_pair_allowed_as_proved_is_apart_in_the_exact_geometry_everywhere() {
    let model = panda_hand();
    let acm = AllowedCollisions::sampled(
        &model,
        &AcmParams {
            samples: 500,
            ..AcmParams::default()
        },
    )
    .unwrap();
    let n = model.body_count();
    let proved: Vec<(usize, usize)> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .filter(|&(a, b)| acm.reason(a, b) == Some(AllowReason::Proved))
        .collect();
    // link_1–link_3 and the other pairs two joints apart along the arm, and
    // the two fingers held open, which no joint moves relative to each other
    assert!(proved.len() >= 3, "{proved:?}");
    let index = |n: &str| model.body_names().position(|b| b == n).unwrap();
    let fingers = (index("panda_leftfinger"), index("panda_rightfinger"));
    assert!(proved.contains(&fingers), "{proved:?}");
    let mut rng = ChaCha8Rng::seed_from_u64(44);
    let mut nearest = f64::INFINITY;
    for _ in 0..5000 {
        let q = random_state(&model, &mut rng);
        for &(a, b) in &proved {
            let d = gap(&model, &q, a, b);
            assert!(d > 0.0, "{q:?}: {} {} at {d} m", name(&model, a), name(&model, b));
            nearest = nearest.min(d);
        }
    }
    eprintln!("{proved:?}: nearest {nearest} m");
}

#[test]
fn states_outside_a_table_or_not_finite_are_not_proved() {
    let model = panda_hand();
    let t = &model.pair_tables()[0];
    let mut q = vec![0.5; model.chain().dof()];
    for bad in [f64::NAN, f64::INFINITY, -10.0, 10.0] {
        q.iter_mut().for_each(|v| *v = bad);
        assert!(!t.proves_apart(&q, &[]), "{bad}");
    }
    assert!(!t.proves_apart(&[], &[]));
}
