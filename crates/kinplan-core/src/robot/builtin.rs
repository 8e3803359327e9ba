//! The built-in robots, embedded as URDF text and parsed once on first use.
//! `builtin/generate.py` writes the URDFs from the published data.

use std::sync::{Arc, OnceLock};

use super::{Chain, ChainSpec, RobotError, Srdf, UrdfLimits, parse_chain, parse_srdf};

macro_rules! builtins {
    ($($name:literal),* $(,)?) => {
        /// Names of the built-in robots.
        pub const BUILTIN_NAMES: &[&str] = &[$($name),*];
        const BUILTIN_URDFS: &[&str] = &[$(include_str!(concat!("builtin/", $name, ".urdf"))),*];
    };
}

/// The six industrial arms among the built-ins (the planar chains left out): the
/// one list that tests, benchmarks and examples iterate over.
pub const ARM_NAMES: [&str; 6] = [
    "kuka_kr210_r2700_extra",
    "kuka_kr120_r2500_pro",
    "abb_irb4600_60_205",
    "ur5",
    "franka_panda",
    "kuka_lbr_iiwa14_r820",
];

builtins!(
    "kuka_kr210_r2700_extra",
    "kuka_kr120_r2500_pro",
    "abb_irb4600_60_205",
    "ur5",
    "franka_panda",
    "franka_panda_hand",
    "kuka_lbr_iiwa14_r820",
    "planar_2",
    "planar_3",
    "planar_4",
    "planar_5",
    "planar_6",
    "planar_7",
    "planar_8",
    "planar_9",
    "planar_10",
);

/// Tip links of built-in robots whose URDF tree has several leaves (a
/// gripper's fingers); the others end in their single leaf.
const BUILTIN_TIPS: &[(&str, &str)] = &[("franka_panda_hand", "panda_hand_tcp")];

/// The URDF text of a built-in robot.
pub fn builtin_urdf(name: &str) -> Result<&'static str, RobotError> {
    BUILTIN_NAMES
        .iter()
        .position(|n| *n == name)
        .map(|i| BUILTIN_URDFS[i])
        .ok_or_else(|| RobotError::UnknownRobot {
            name: super::urdf::clip(name),
            known: BUILTIN_NAMES.join(", "),
        })
}

/// The MoveIt SRDF of a built-in robot, when it has designed contacts: pairs
/// of links in contact at the default pose of the real robot, which the
/// collision checks allow (`collision::AllowedCollisions::allow_named`). The
/// Panda's come from MoveIt's Panda configuration (`panda_moveit_config`:
/// finger against finger); `generate.py` writes them.
pub fn builtin_srdf(name: &str) -> Option<&'static str> {
    match name {
        "franka_panda" => Some(include_str!("builtin/franka_panda.srdf")),
        "franka_panda_hand" => Some(include_str!("builtin/franka_panda_hand.srdf")),
        _ => None,
    }
}

/// [`builtin_srdf`] as read, parsed once.
pub fn builtin_srdf_parsed(name: &str) -> Option<&'static Srdf> {
    static PARSED: OnceLock<Vec<(&'static str, Srdf)>> = OnceLock::new();
    let parsed = PARSED.get_or_init(|| {
        BUILTIN_NAMES
            .iter()
            .filter_map(|n| {
                let text = builtin_srdf(n)?;
                Some((
                    *n,
                    parse_srdf(text, &UrdfLimits::default()).expect("the built-in SRDFs parse"),
                ))
            })
            .collect()
    });
    parsed.iter().find(|(n, _)| *n == name).map(|(_, s)| s)
}

/// The default chain (base_link → tool tip) of a built-in robot, parsed once.
pub fn builtin_chain(name: &str) -> Result<Arc<Chain>, RobotError> {
    static CHAINS: OnceLock<Vec<OnceLock<Arc<Chain>>>> = OnceLock::new();
    let index = BUILTIN_NAMES
        .iter()
        .position(|n| *n == name)
        .ok_or_else(|| RobotError::UnknownRobot {
            name: super::urdf::clip(name),
            known: BUILTIN_NAMES.join(", "),
        })?;
    let cells = CHAINS.get_or_init(|| BUILTIN_NAMES.iter().map(|_| OnceLock::new()).collect());
    let chain = cells[index].get_or_init(|| {
        let spec = ChainSpec {
            base_link: None,
            tip_link: BUILTIN_TIPS
                .iter()
                .find(|(n, _)| *n == BUILTIN_NAMES[index])
                .map(|(_, tip)| tip.to_string()),
        };
        let chain = parse_chain(BUILTIN_URDFS[index], &spec, UrdfLimits::default())
            .expect("built-in URDFs are valid (checked by tests)");
        Arc::new(chain)
    });
    Ok(chain.clone())
}
