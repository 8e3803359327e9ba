//! Readers for MoveIt's YAML messages, as MotionBenchMaker and MoveIt's
//! `.scene`-to-YAML tools write them: a `PlanningScene`'s world collision
//! objects become a [`Scene`], and a `MotionPlanRequest`'s start state and
//! joint goal become named joint values.
//!
//! YAML is read with **yaml-rust2** (pure Rust, maintained, YAML 1.2; with
//! default features off it pulls only `arraydeque` and `hashlink`), so the
//! loader needs no cargo feature. `serde_yaml` is archived and was not
//! considered.
//!
//! Conventions (MoveIt `shape_msgs/SolidPrimitive`): box dimensions are full
//! edge lengths `[x, y, z]`; cylinder `[height, radius]` along z; sphere
//! `[radius]`; cone is not supported. Orientations are `[x, y, z, w]` lists
//! or `{x, y, z, w}` maps and are normalised (a zero quaternion is an
//! error). A primitive's pose is `object.pose · primitive_pose` (the object
//! pose is absent in older messages: identity). Frames are taken as the
//! robot's base frame; `header.frame_id` is not interpreted.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use yaml_rust2::{Yaml, YamlLoader};

use super::{CollisionError, Geometry, Obstacle, Scene, SceneLimits};

/// Largest YAML document read (bytes).
pub const MAX_YAML_BYTES: usize = 16 << 20;

/// A joint-space planning request: start and goal joint values by name.
#[derive(Debug, Clone, PartialEq)]
pub struct JointRequest {
    pub group: String,
    /// `start_state.joint_state` names and positions (rad or m).
    pub start: Vec<(String, f64)>,
    /// `goal_constraints[0].joint_constraints` names and positions.
    pub goal: Vec<(String, f64)>,
}

fn load(text: &str) -> Result<Yaml, CollisionError> {
    if text.len() > MAX_YAML_BYTES {
        return Err(CollisionError::TooLarge {
            field: "yaml".into(),
            value: text.len() as f64,
            limit: MAX_YAML_BYTES as f64,
        });
    }
    let mut docs = YamlLoader::load_from_str(text).map_err(|e| CollisionError::Parse {
        field: "yaml".into(),
        reason: e.to_string(),
    })?;
    if docs.is_empty() {
        return Err(CollisionError::Empty { field: "yaml".into() });
    }
    Ok(docs.swap_remove(0))
}

fn number(y: &Yaml, field: &str) -> Result<f64, CollisionError> {
    let v = match y {
        Yaml::Real(_) => y.as_f64(),
        Yaml::Integer(i) => Some(*i as f64),
        _ => None,
    };
    let v = v.ok_or_else(|| CollisionError::Parse {
        field: field.into(),
        reason: "expected a number".into(),
    })?;
    if !v.is_finite() {
        return Err(CollisionError::NonFinite { field: field.into() });
    }
    Ok(v)
}

/// `[a, b, c…]` or `{keys[0]: a, …}`.
fn numbers(y: &Yaml, keys: &[&str], field: &str) -> Result<Vec<f64>, CollisionError> {
    match y {
        Yaml::Array(items) => items
            .iter()
            .enumerate()
            .map(|(k, v)| number(v, &format!("{field}[{k}]")))
            .collect(),
        Yaml::Hash(_) => keys
            .iter()
            .map(|k| number(&y[*k], &format!("{field}.{k}")))
            .collect(),
        _ => Err(CollisionError::Parse {
            field: field.into(),
            reason: "expected a list or a map of numbers".into(),
        }),
    }
}

fn fixed<const N: usize>(y: &Yaml, keys: &[&str; N], field: &str) -> Result<[f64; N], CollisionError> {
    let v = numbers(y, keys, field)?;
    v.as_slice().try_into().map_err(|_| CollisionError::Parse {
        field: field.into(),
        reason: format!("expected {N} numbers, got {}", v.len()),
    })
}

/// A `geometry_msgs/Pose` (`position`, `orientation`); absent → identity.
fn pose(y: &Yaml, field: &str) -> Result<Isometry3<f64>, CollisionError> {
    if y.is_badvalue() || matches!(y, Yaml::Null) {
        return Ok(Isometry3::identity());
    }
    let p = fixed(&y["position"], &["x", "y", "z"], &format!("{field}.position"))?;
    let o = &y["orientation"];
    let rotation = if o.is_badvalue() {
        UnitQuaternion::identity()
    } else {
        let [x, yy, z, w] = fixed(o, &["x", "y", "z", "w"], &format!("{field}.orientation"))?;
        let q = Quaternion::new(w, x, yy, z);
        if q.norm() < 1e-9 {
            return Err(CollisionError::Degenerate {
                field: format!("{field}.orientation"),
                reason: "zero quaternion".into(),
            });
        }
        UnitQuaternion::from_quaternion(q)
    };
    Ok(Isometry3::from_parts(
        Translation3::new(p[0], p[1], p[2]),
        rotation,
    ))
}

fn list<'a>(y: &'a Yaml, field: &str) -> Result<&'a [Yaml], CollisionError> {
    match y {
        Yaml::Array(a) => Ok(a),
        Yaml::BadValue | Yaml::Null => Ok(&[]),
        _ => Err(CollisionError::Parse {
            field: field.into(),
            reason: "expected a list".into(),
        }),
    }
}

fn primitive(y: &Yaml, field: &str) -> Result<Geometry, CollisionError> {
    let kind = &y["type"];
    let dims = numbers(&y["dimensions"], &[], &format!("{field}.dimensions"))?;
    let need = |n: usize| {
        if dims.len() < n {
            Err(CollisionError::Parse {
                field: format!("{field}.dimensions"),
                reason: format!("expected {n} numbers, got {}", dims.len()),
            })
        } else {
            Ok(())
        }
    };
    // MoveIt writes the type as a name or as the message's enum value.
    let name = match kind {
        Yaml::String(s) => s.to_lowercase(),
        Yaml::Integer(1) => "box".into(),
        Yaml::Integer(2) => "sphere".into(),
        Yaml::Integer(3) => "cylinder".into(),
        Yaml::Integer(4) => "cone".into(),
        _ => String::new(),
    };
    match name.as_str() {
        "box" => {
            need(3)?;
            Ok(Geometry::Box {
                half_extents: Vector3::new(dims[0], dims[1], dims[2]) * 0.5,
            })
        }
        "sphere" => {
            need(1)?;
            Ok(Geometry::Sphere { radius: dims[0] })
        }
        "cylinder" => {
            need(2)?;
            Ok(Geometry::Cylinder {
                length: dims[0],
                radius: dims[1],
            })
        }
        _ => Err(CollisionError::Parse {
            field: format!("{field}.type"),
            reason: format!("unsupported primitive type {kind:?} (box, sphere, cylinder)"),
        }),
    }
}

fn mesh(y: &Yaml, field: &str) -> Result<Geometry, CollisionError> {
    let vertices = list(&y["vertices"], &format!("{field}.vertices"))?
        .iter()
        .enumerate()
        .map(|(k, v)| {
            fixed(v, &["x", "y", "z"], &format!("{field}.vertices[{k}]"))
                .map(|p| Point3::new(p[0], p[1], p[2]))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut indices = Vec::new();
    for (k, t) in list(&y["triangles"], &format!("{field}.triangles"))?
        .iter()
        .enumerate()
    {
        let f = format!("{field}.triangles[{k}].vertex_indices");
        for (c, v) in fixed(&t["vertex_indices"], &["0", "1", "2"], &f)?
            .iter()
            .enumerate()
        {
            if *v < 0.0 || *v > u32::MAX as f64 || v.fract() != 0.0 {
                return Err(CollisionError::Parse {
                    field: format!("{f}[{c}]"),
                    reason: format!("{v} is not a vertex index"),
                });
            }
            indices.push(*v as u32);
        }
    }
    Ok(Geometry::Mesh { vertices, indices })
}

/// The world collision objects of a MoveIt `PlanningScene` YAML document,
/// validated against `limits`. Obstacles are named by object `id`, with
/// `#k` appended for the k-th shape of an object that has several.
pub fn parse_planning_scene(text: &str, limits: &SceneLimits) -> Result<Scene, CollisionError> {
    let doc = load(text)?;
    let mut obstacles = Vec::new();
    for (i, o) in list(&doc["world"]["collision_objects"], "world.collision_objects")?
        .iter()
        .enumerate()
    {
        let field = format!("world.collision_objects[{i}]");
        let id = o["id"].as_str().unwrap_or("").to_string();
        let object = pose(&o["pose"], &format!("{field}.pose"))?;
        let mut shapes = Vec::new();
        let prims = list(&o["primitives"], &format!("{field}.primitives"))?;
        let prim_poses = list(&o["primitive_poses"], &format!("{field}.primitive_poses"))?;
        for (k, p) in prims.iter().enumerate() {
            let f = format!("{field}.primitives[{k}]");
            let pp = prim_poses.get(k).ok_or_else(|| CollisionError::Parse {
                field: format!("{field}.primitive_poses"),
                reason: format!("{} poses for {} primitives", prim_poses.len(), prims.len()),
            })?;
            shapes.push((
                primitive(p, &f)?,
                pose(pp, &format!("{field}.primitive_poses[{k}]"))?,
            ));
        }
        let meshes = list(&o["meshes"], &format!("{field}.meshes"))?;
        let mesh_poses = list(&o["mesh_poses"], &format!("{field}.mesh_poses"))?;
        for (k, m) in meshes.iter().enumerate() {
            let f = format!("{field}.meshes[{k}]");
            let mp = mesh_poses.get(k).ok_or_else(|| CollisionError::Parse {
                field: format!("{field}.mesh_poses"),
                reason: format!("{} poses for {} meshes", mesh_poses.len(), meshes.len()),
            })?;
            shapes.push((mesh(m, &f)?, pose(mp, &format!("{field}.mesh_poses[{k}]"))?));
        }
        let several = shapes.len() > 1;
        for (k, (geometry, p)) in shapes.into_iter().enumerate() {
            let name = if several { format!("{id}#{k}") } else { id.clone() };
            obstacles.push(Obstacle::new(name, object * p, geometry));
        }
    }
    Scene::new(obstacles, limits)
}

/// Start state and joint goal of a MoveIt `MotionPlanRequest` YAML document.
pub fn parse_joint_request(text: &str) -> Result<JointRequest, CollisionError> {
    let doc = load(text)?;
    let js = &doc["start_state"]["joint_state"];
    let names = list(&js["name"], "start_state.joint_state.name")?;
    let positions = numbers(&js["position"], &[], "start_state.joint_state.position")?;
    if names.len() != positions.len() {
        return Err(CollisionError::Parse {
            field: "start_state.joint_state".into(),
            reason: format!("{} names for {} positions", names.len(), positions.len()),
        });
    }
    let start = names
        .iter()
        .zip(positions)
        .enumerate()
        .map(|(k, (n, v))| {
            n.as_str()
                .map(|s| (s.to_string(), v))
                .ok_or_else(|| CollisionError::Parse {
                    field: format!("start_state.joint_state.name[{k}]"),
                    reason: "expected a string".into(),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let goal = list(
        &doc["goal_constraints"][0]["joint_constraints"],
        "goal_constraints[0].joint_constraints",
    )?
    .iter()
    .enumerate()
    .map(|(k, c)| {
        let f = format!("goal_constraints[0].joint_constraints[{k}]");
        let name = c["joint_name"].as_str().ok_or_else(|| CollisionError::Parse {
            field: format!("{f}.joint_name"),
            reason: "expected a string".into(),
        })?;
        Ok((
            name.to_string(),
            number(&c["position"], &format!("{f}.position"))?,
        ))
    })
    .collect::<Result<Vec<_>, CollisionError>>()?;
    Ok(JointRequest {
        group: doc["group_name"].as_str().unwrap_or("").to_string(),
        start,
        goal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
name: ""
world:
  collision_objects:
    - id: table
      primitive_poses:
        - position: [0.5, 0, -0.02]
          orientation: [0, 0, 0.7071067811865476, 0.7071067811865476]
      primitives:
        - type: box
          dimensions: [1.0, 0.6, 0.04]
    - id: can
      pose: {position: {x: 0.1, y: 0, z: 0}, orientation: {x: 0, y: 0, z: 0, w: 1}}
      primitives:
        - {type: cylinder, dimensions: [0.14, 0.03]}
        - {type: sphere, dimensions: [0.05]}
      primitive_poses:
        - {position: [0.4, 0.2, 0.07], orientation: [0, 0, 0, 1]}
        - {position: [0, 0, 1], orientation: [0, 0, 0, 2]}
"#;

    #[test]
    fn a_planning_scene_becomes_obstacles_with_composed_poses() {
        let scene = parse_planning_scene(SCENE, &SceneLimits::default()).unwrap();
        let o = scene.obstacles();
        assert_eq!(o.len(), 3);
        assert_eq!(o[0].name, "table");
        assert_eq!(
            o[0].geometry,
            Geometry::Box {
                half_extents: Vector3::new(0.5, 0.3, 0.02)
            }
        );
        // Rotated 90° about z: the box's x axis points along y.
        let x_axis = o[0].pose.rotation * Vector3::x();
        assert!((x_axis - Vector3::y()).norm() < 1e-12);
        assert_eq!(o[1].name, "can#0");
        assert_eq!(
            o[1].geometry,
            Geometry::Cylinder {
                radius: 0.03,
                length: 0.14
            }
        );
        assert!((o[1].pose.translation.vector - Vector3::new(0.5, 0.2, 0.07)).norm() < 1e-12);
        // A non-unit quaternion is normalised.
        assert!((o[2].pose.rotation.angle()).abs() < 1e-12);
    }

    #[test]
    fn bad_scenes_name_the_field() {
        let e =
            parse_planning_scene(&SCENE.replace("[0.05]", "[.nan]"), &SceneLimits::default()).unwrap_err();
        assert_eq!(
            e,
            CollisionError::NonFinite {
                field: "world.collision_objects[1].primitives[1].dimensions[0]".into()
            }
        );
        let e = parse_planning_scene(&SCENE.replace("type: box", "type: cone"), &SceneLimits::default())
            .unwrap_err();
        assert!(
            matches!(&e, CollisionError::Parse { field, .. } if field == "world.collision_objects[0].primitives[0].type")
        );
        let e = parse_planning_scene(
            &SCENE.replace("[0, 0, 0, 2]", "[0, 0, 0, 0]"),
            &SceneLimits::default(),
        )
        .unwrap_err();
        assert!(matches!(e, CollisionError::Degenerate { .. }));
        let e = parse_planning_scene(
            &SCENE.replace("[1.0, 0.6, 0.04]", "[1.0, -0.6, 0.04]"),
            &SceneLimits::default(),
        )
        .unwrap_err();
        assert!(matches!(e, CollisionError::NotPositive { .. }));
        assert!(parse_planning_scene("world: [", &SceneLimits::default()).is_err());
    }

    #[test]
    fn a_request_gives_start_and_goal_joints() {
        let text = r#"
group_name: panda_arm
goal_constraints:
  - joint_constraints:
      - joint_name: j1
        position: 0.5
      - position: -1
        joint_name: j2
start_state:
  joint_state:
    position: [0, -0.785, 0.065]
    name: [j1, j2, finger]
"#;
        let r = parse_joint_request(text).unwrap();
        assert_eq!(r.group, "panda_arm");
        assert_eq!(
            r.start,
            vec![
                ("j1".into(), 0.0),
                ("j2".into(), -0.785),
                ("finger".into(), 0.065)
            ]
        );
        assert_eq!(r.goal, vec![("j1".into(), 0.5), ("j2".into(), -1.0)]);
        assert!(parse_joint_request(&text.replace("name: [j1, j2, finger]", "name: [j1, j2]")).is_err());
    }
}
