//! What the MotionBenchMaker examples share: the seven problem sets and the
//! Panda-with-hand collision model (fingers at the request's opening) with its
//! allowed-collision matrix, built once per opening.

use std::collections::BTreeMap;
use std::sync::Arc;

use kinplan_core::collision::{AcmParams, AllowedCollisions, RobotModel, attached_bodies};
use kinplan_core::robot::{Chain, builtin_urdf};

/// The problem sets of `../shared/bench/mbm/` in MotionBenchMaker's order.
pub use kinplan_core::mbm_data::SETS;

/// A collision model and its allowed-collision matrix.
pub type Model = (Arc<RobotModel>, AllowedCollisions);

/// The Panda with its hand, fingers opened to `opening` (m), from `cache`.
pub fn model(chain: &Arc<Chain>, opening: f64, cache: &mut BTreeMap<u64, Model>) -> Model {
    cache
        .entry(opening.to_bits())
        .or_insert_with(|| {
            let urdf = builtin_urdf("franka_panda_hand").unwrap();
            let fingers = [("panda_finger_joint1", opening), ("panda_finger_joint2", opening)];
            let attached = attached_bodies(urdf, chain, &fingers).unwrap();
            let model = Arc::new(RobotModel::with_parts(chain.clone(), &attached, &[]).unwrap());
            let acm = AllowedCollisions::builtin(&model, "franka_panda_hand", &AcmParams::default()).unwrap();
            (model, acm)
        })
        .clone()
}

/// The seven arm joints of a MoveIt joint state (names `panda_joint1..7`);
/// `field` names the state in the error.
pub fn arm(joints: &[(String, f64)], field: &str) -> Result<Vec<f64>, String> {
    let mut q = vec![f64::NAN; 7];
    for (name, v) in joints {
        if let Some(i) = name
            .strip_prefix("panda_joint")
            .and_then(|s| s.parse::<usize>().ok())
            && (1..=7).contains(&i)
        {
            q[i - 1] = *v;
        }
    }
    if q.iter().any(|v| v.is_nan()) {
        return Err(format!("{field}: missing panda_joint1..7"));
    }
    Ok(q)
}
