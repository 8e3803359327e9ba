//! MoveIt's Semantic Robot Description Format: the planning groups (chains
//! and link sets), named joint states, end effectors and the link pairs that
//! never need a collision check, as a MoveIt configuration gives them. Read
//! from text only, after the same structural bounds as a URDF.

use serde::Deserialize;

use super::RobotError;
use super::urdf::{UrdfLimits, prescan};

/// What kinplan uses of an SRDF.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Srdf {
    pub groups: Vec<Group>,
    pub group_states: Vec<GroupState>,
    pub end_effectors: Vec<EndEffector>,
    /// `<disable_collisions link1 link2>`: pairs never checked.
    pub disabled_collisions: Vec<(String, String)>,
}

/// A planning group: chains (base, tip), links and joints named directly.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Group {
    pub name: String,
    pub chains: Vec<(String, String)>,
    pub links: Vec<String>,
    pub joints: Vec<String>,
}

/// A named state of a group: joint name → value (rad or m).
#[derive(Debug, Clone, PartialEq)]
pub struct GroupState {
    pub name: String,
    pub group: String,
    pub joints: Vec<(String, f64)>,
}

/// An end effector: its group and the link it hangs from.
#[derive(Debug, Clone, PartialEq)]
pub struct EndEffector {
    pub name: String,
    pub parent_link: String,
    pub group: String,
}

impl Srdf {
    /// The group called `name`.
    pub fn group(&self, name: &str) -> Option<&Group> {
        self.groups.iter().find(|g| g.name == name)
    }
}

#[derive(Deserialize)]
struct Doc {
    #[serde(rename = "group", default)]
    groups: Vec<GroupXml>,
    #[serde(rename = "group_state", default)]
    group_states: Vec<StateXml>,
    #[serde(rename = "end_effector", default)]
    end_effectors: Vec<EndEffectorXml>,
    #[serde(rename = "disable_collisions", default)]
    disabled: Vec<DisableXml>,
}

#[derive(Deserialize)]
struct Named {
    #[serde(rename = "@name")]
    name: String,
}

#[derive(Deserialize)]
struct GroupXml {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "chain", default)]
    chains: Vec<ChainXml>,
    #[serde(rename = "link", default)]
    links: Vec<Named>,
    #[serde(rename = "joint", default)]
    joints: Vec<Named>,
}

#[derive(Deserialize)]
struct ChainXml {
    #[serde(rename = "@base_link")]
    base_link: String,
    #[serde(rename = "@tip_link")]
    tip_link: String,
}

#[derive(Deserialize)]
struct StateXml {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@group")]
    group: String,
    #[serde(rename = "joint", default)]
    joints: Vec<JointValueXml>,
}

#[derive(Deserialize)]
struct JointValueXml {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@value")]
    value: String,
}

#[derive(Deserialize)]
struct EndEffectorXml {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@parent_link")]
    parent_link: String,
    #[serde(rename = "@group")]
    group: String,
}

#[derive(Deserialize)]
struct DisableXml {
    #[serde(rename = "@link1")]
    link1: String,
    #[serde(rename = "@link2")]
    link2: String,
}

/// Parses SRDF text, within the URDF's structural limits (size, element
/// count, nesting depth; no document type declarations). A joint value must
/// be a finite number (a multi-DOF joint's several values are refused).
///
/// ```
/// let s = kinplan_core::robot::parse_srdf(r#"<robot name="arm">
///   <group name="arm"><chain base_link="base" tip_link="tool"/></group>
///   <group_state name="ready" group="arm"><joint name="j1" value="0.5"/></group_state>
///   <disable_collisions link1="base" link2="upper" reason="Adjacent"/>
/// </robot>"#, &Default::default()).unwrap();
/// assert_eq!(s.group("arm").unwrap().chains, [("base".to_string(), "tool".to_string())]);
/// assert_eq!(s.group_states[0].joints, [("j1".to_string(), 0.5)]);
/// assert_eq!(s.disabled_collisions, [("base".to_string(), "upper".to_string())]);
/// ```
pub fn parse_srdf(text: &str, limits: &UrdfLimits) -> Result<Srdf, RobotError> {
    let bad = |reason: String| RobotError::MalformedSrdf(reason);
    if text.len() > limits.max_bytes {
        return Err(bad(format!(
            "{} bytes exceed the limit of {}",
            text.len(),
            limits.max_bytes
        )));
    }
    prescan(text, limits).map_err(|e| bad(e.to_string()))?;
    let doc: Doc = quick_xml::de::from_str(text).map_err(|e| bad(e.to_string()))?;
    let mut group_states = Vec::with_capacity(doc.group_states.len());
    for s in doc.group_states {
        let mut joints = Vec::with_capacity(s.joints.len());
        for j in s.joints {
            let value: f64 = j
                .value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| {
                    bad(format!(
                        "group_state `{}`: joint `{}` has value `{}`, not one finite number",
                        s.name, j.name, j.value
                    ))
                })?;
            joints.push((j.name, value));
        }
        group_states.push(GroupState {
            name: s.name,
            group: s.group,
            joints,
        });
    }
    Ok(Srdf {
        groups: doc
            .groups
            .into_iter()
            .map(|g| Group {
                name: g.name,
                chains: g.chains.into_iter().map(|c| (c.base_link, c.tip_link)).collect(),
                links: g.links.into_iter().map(|l| l.name).collect(),
                joints: g.joints.into_iter().map(|j| j.name).collect(),
            })
            .collect(),
        group_states,
        end_effectors: doc
            .end_effectors
            .into_iter()
            .map(|e| EndEffector {
                name: e.name,
                parent_link: e.parent_link,
                group: e.group,
            })
            .collect(),
        disabled_collisions: doc.disabled.into_iter().map(|d| (d.link1, d.link2)).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shape of a MoveIt setup assistant's output (the Panda's, abridged),
    /// its elements interleaved as the assistant writes them.
    const PANDA: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<!--This does not replace URDF, and is not an extension of URDF.-->
<robot name="panda">
    <group name="panda_arm">
        <chain base_link="panda_link0" tip_link="panda_link8"/>
    </group>
    <group name="hand">
        <link name="panda_hand"/>
        <link name="panda_leftfinger"/>
        <link name="panda_rightfinger"/>
        <joint name="panda_finger_joint1"/>
    </group>
    <group_state name="ready" group="panda_arm">
        <joint name="panda_joint1" value="0"/>
        <joint name="panda_joint2" value="-0.785"/>
        <joint name="panda_joint4" value="-2.356"/>
    </group_state>
    <end_effector name="hand" parent_link="panda_link8" group="hand" parent_group="panda_arm"/>
    <virtual_joint name="virtual_joint" type="floating" parent_frame="world" child_link="panda_link0"/>
    <disable_collisions link1="panda_hand" link2="panda_leftfinger" reason="Adjacent"/>
    <group_state name="open" group="hand">
        <joint name="panda_finger_joint1" value="0.035"/>
    </group_state>
    <disable_collisions link1="panda_link0" link2="panda_link1" reason="Adjacent"/>
</robot>"#;

    #[test]
    fn a_setup_assistant_srdf_reads_with_its_elements_interleaved() {
        let s = parse_srdf(PANDA, &UrdfLimits::default()).unwrap();
        assert_eq!(s.groups.len(), 2);
        let arm = s.group("panda_arm").unwrap();
        assert_eq!(arm.chains, [("panda_link0".into(), "panda_link8".into())]);
        assert_eq!(s.group("hand").unwrap().links.len(), 3);
        let names: Vec<&str> = s.group_states.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["ready", "open"]);
        assert_eq!(s.group_states[0].joints[1], ("panda_joint2".into(), -0.785));
        assert_eq!(s.end_effectors[0].parent_link, "panda_link8");
        assert_eq!(s.disabled_collisions.len(), 2);
        assert_eq!(
            s.disabled_collisions[1],
            ("panda_link0".into(), "panda_link1".into())
        );
    }

    #[test]
    fn bad_srdfs_are_errors_not_panics() {
        let lim = UrdfLimits::default();
        for bad in [
            "<robot>",
            "not xml at all",
            r#"<robot><group_state name="s" group="g"><joint name="j" value="nan"/></group_state></robot>"#,
            r#"<robot><group_state name="s" group="g"><joint name="j" value="0 1 2"/></group_state></robot>"#,
            r#"<!DOCTYPE r [<!ENTITY a "aaaa">]><robot/>"#,
        ] {
            assert!(parse_srdf(bad, &lim).is_err(), "{bad}");
        }
        let deep = format!(
            "<robot>{}{}</robot>",
            "<group>".repeat(100),
            "</group>".repeat(100)
        );
        assert!(matches!(
            parse_srdf(&deep, &lim),
            Err(RobotError::MalformedSrdf(_))
        ));
        // an empty description is a valid one
        assert_eq!(parse_srdf("<robot name=\"r\"/>", &lim).unwrap(), Srdf::default());
    }
}
