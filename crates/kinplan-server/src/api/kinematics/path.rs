//! TrackPath's poses: explicit poses, or a line or circle sampled into steps.

use super::*;

/// The poses of a `TrackPath` and the field they came from.
pub(super) fn path_in(
    poses: &[pb::Pose],
    line: Option<&pb::LinePath>,
    circle: Option<&pb::CirclePath>,
    chain: &Chain,
    seed: &[f64],
) -> Result<(Vec<Isometry3<f64>>, PathAt), Status> {
    let given = usize::from(!poses.is_empty()) + usize::from(line.is_some()) + usize::from(circle.is_some());
    if given != 1 {
        return Err(invalid(
            "poses",
            format!("exactly one of poses, line and circle is required, got {given}"),
        ));
    }
    let steps = |field: &str, steps: u32| {
        if steps == 0 || steps as usize >= MAX_PATH_POSES {
            Err(invalid(
                field,
                format!("must be between 1 and {}, got {steps}", MAX_PATH_POSES - 1),
            ))
        } else {
            Ok(steps as usize)
        }
    };
    let start = |field: &str, p: Option<&pb::Pose>| match p {
        Some(p) => pose_in(field, Some(p)),
        None => Ok(chain.fk(seed)),
    };
    if let Some(line) = line {
        let s = start("line.start", line.start.as_ref())?;
        let e = pose_in("line.end", line.end.as_ref())?;
        let n = steps("line.steps", line.steps)?;
        let path = line_path(&s, &e, n).map_err(|e| ik_error(e, IkAt::Path(PathAt::Line)))?;
        return Ok((path, PathAt::Line));
    }
    if let Some(c) = circle {
        let s = start("circle.start", c.start.as_ref())?;
        if c.centre.is_none() {
            return Err(invalid("circle.centre", "is required"));
        }
        let centre = Point3::from(vec3_in("circle.centre", c.centre.as_ref())?);
        let normal = vec3_in("circle.normal", c.normal.as_ref())?;
        let n = steps("circle.steps", c.steps)?;
        let path = circle_path(&s, &centre, &normal, c.angle_step, n)
            .map_err(|e| ik_error(e, IkAt::Path(PathAt::Circle)))?;
        return Ok((path, PathAt::Circle));
    }
    if poses.len() > MAX_PATH_POSES {
        return Err(invalid(
            "poses",
            format!("{} poses exceed the limit of {MAX_PATH_POSES}", poses.len()),
        ));
    }
    let path = poses
        .iter()
        .enumerate()
        .map(|(i, p)| pose_in(&format!("poses[{i}]"), Some(p)))
        .collect::<Result<_, _>>()?;
    Ok((path, PathAt::Poses))
}
