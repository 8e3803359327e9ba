//! From a robot model to what the criteria need: the tool pose (FK) and the
//! points on the robot that RDM follows (S0 eq. 2.5), for every waypoint.
//!
//! The criteria themselves stay free of robot models; this is the one bridge,
//! used by the service and by benchmarks alike.

use nalgebra::{Isometry3, Point3};

use super::error::ScoreError;
use super::input::{Rows, validate_joint_rows};
use crate::robot::{Chain, Shape};

/// Which points on the links RDM follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PointSet {
    /// The origin of every link frame, base to tip (S0: "points on the
    /// robot's links").
    #[default]
    LinkOrigins,
    /// The link frame origins plus the extreme points of every collision
    /// shape ([`shape_extreme_points`]).
    CollisionVertices,
}

/// Extreme points of a collision primitive in its own frame, metres:
/// - box: its 8 corners `(±hx, ±hy, ±hz)`;
/// - sphere: centre `± r` along x, y, z (6);
/// - cylinder (along z, length `L`): `(±r, 0, ±L/2)` and `(0, ±r, ±L/2)` (8);
/// - capsule: the cylinder's 8 rim points plus the cap tips `(0, 0, ±(L/2 + r))` (10);
/// - mesh reference (never read): its frame origin (1).
///
/// The displacement `‖(R − I)·a + t‖` of a rigid motion is convex in `a`, so
/// over a box its maximum sits at a corner: RDM over corners is exact for
/// boxes; for round shapes these points under-estimate it by at most the
/// chord error.
///
/// ```
/// use kinplan_core::robot::Shape;
/// use kinplan_core::score::shape_extreme_points;
/// let cap = Shape::Capsule { radius: 0.1, length: 1.0 };
/// let pts = shape_extreme_points(&cap);
/// assert_eq!(pts.len(), 10);
/// assert!(pts.iter().any(|p| (p.z - 0.6).abs() < 1e-15));
/// ```
pub fn shape_extreme_points(shape: &Shape) -> Vec<Point3<f64>> {
    let rim = |r: f64, half: f64| {
        [-half, half]
            .into_iter()
            .flat_map(move |z| {
                [
                    Point3::new(r, 0.0, z),
                    Point3::new(-r, 0.0, z),
                    Point3::new(0.0, r, z),
                    Point3::new(0.0, -r, z),
                ]
            })
            .collect::<Vec<_>>()
    };
    match shape {
        Shape::Box { half_extents: h } => {
            let mut out = Vec::with_capacity(8);
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    for sz in [-1.0, 1.0] {
                        out.push(Point3::new(sx * h.x, sy * h.y, sz * h.z));
                    }
                }
            }
            out
        }
        Shape::Sphere { radius: r } => vec![
            Point3::new(*r, 0.0, 0.0),
            Point3::new(-r, 0.0, 0.0),
            Point3::new(0.0, *r, 0.0),
            Point3::new(0.0, -r, 0.0),
            Point3::new(0.0, 0.0, *r),
            Point3::new(0.0, 0.0, -r),
        ],
        Shape::Cylinder { radius, length } => rim(*radius, 0.5 * length),
        Shape::Capsule { radius, length } => {
            let half = 0.5 * length;
            let mut out = rim(*radius, half);
            out.push(Point3::new(0.0, 0.0, half + radius));
            out.push(Point3::new(0.0, 0.0, -(half + radius)));
            out
        }
        // a built-in robot's embedded mesh gives its vertices; a mesh file
        // the chain alone does not carry stands at its origin
        Shape::MeshReference { filename, scale } => crate::collision::builtin_mesh(filename).map_or_else(
            || vec![Point3::origin()],
            |m| {
                m.vertices
                    .iter()
                    .map(|p| Point3::from(p.coords.component_mul(scale)))
                    .collect()
            },
        ),
    }
}

/// The points RDM follows, each fixed in a link frame: `(link index in
/// [`Chain::links`], point in that link's frame)`, link origins first (one per
/// link, in chain order), then, with [`PointSet::CollisionVertices`], each
/// link's collision-shape extreme points placed by the shape's origin.
///
/// ```
/// let chain = kinplan_core::robot::builtin_chain("planar_2").unwrap();
/// use kinplan_core::score::{robot_link_points, PointSet};
/// assert_eq!(robot_link_points(&chain, PointSet::LinkOrigins).len(), 4);
/// // plus two capsules of 10 points each
/// assert_eq!(robot_link_points(&chain, PointSet::CollisionVertices).len(), 24);
/// ```
pub fn robot_link_points(chain: &Chain, set: PointSet) -> Vec<(usize, Point3<f64>)> {
    let mut out: Vec<(usize, Point3<f64>)> =
        (0..chain.links().len()).map(|i| (i, Point3::origin())).collect();
    if set == PointSet::CollisionVertices {
        for (i, link) in chain.collision().iter().enumerate().take(chain.links().len()) {
            for s in &link.shapes {
                out.extend(
                    shape_extreme_points(&s.shape)
                        .into_iter()
                        .map(|p| (i, s.origin * p)),
                );
            }
        }
    }
    out
}

/// Tool poses and robot points of a whole trajectory, base frame, metres.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainSamples {
    /// Tool (tip link) pose per waypoint.
    pub poses: Vec<Isometry3<f64>>,
    /// Robot points, row-major: `points_per_waypoint` per waypoint, the same
    /// points in the same order in every row. Empty without a point set.
    pub points: Vec<Point3<f64>>,
    /// Points per waypoint (0 without a point set).
    pub points_per_waypoint: usize,
}

impl ChainSamples {
    /// The robot points as rows for [`super::TrajectoryData::robot_points`];
    /// `None` without a point set.
    pub fn point_rows(&self) -> Option<Rows<'_, Point3<f64>>> {
        (self.points_per_waypoint > 0).then_some(Rows::Flat {
            values: &self.points,
            width: self.points_per_waypoint,
        })
    }
}

/// Forward kinematics of every waypoint of `joints`: the tool pose
/// ([`Chain::fk`]) and, with `set`, the robot points of
/// [`robot_link_points`] moved by the link frames ([`Chain::link_frames_into`]).
///
/// Validates the joints first (every row has `chain.dof()` finite values),
/// so errors name the joints, never the derived poses. One frame buffer is
/// reused across waypoints.
///
/// ```
/// use kinplan_core::score::{sample_chain, PointSet, Rows};
/// let chain = kinplan_core::robot::builtin_chain("planar_2").unwrap();
/// let q = [0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
/// let s = sample_chain(&chain, Rows::Flat { values: &q, width: 2 }, Some(PointSet::LinkOrigins)).unwrap();
/// assert!((s.poses[1].translation.vector.y - 1.0).abs() < 1e-12); // arm turned to +y
/// assert_eq!((s.points_per_waypoint, s.points.len()), (4, 8));
/// ```
pub fn sample_chain(
    chain: &Chain,
    joints: Rows<'_, f64>,
    set: Option<PointSet>,
) -> Result<ChainSamples, ScoreError> {
    validate_joint_rows(&joints, Some(chain.dof()))?;
    let n = joints.len();
    let local = set.map(|s| robot_link_points(chain, s)).unwrap_or_default();
    let mut poses = Vec::with_capacity(n);
    let mut points = Vec::with_capacity(n * local.len());
    let mut frames = Vec::with_capacity(chain.links().len());
    let mut mats = Vec::with_capacity(chain.links().len());
    // The tip link closes `links()`, so with link frames at hand its frame is
    // the tool pose and a second FK pass is not needed.
    let tip_is_last = chain.links().last().is_some_and(|l| l.name == chain.tip_link());
    for i in 0..n {
        let q = joints.row(i);
        if local.is_empty() {
            poses.push(chain.fk(q));
            continue;
        }
        chain.link_frames_into(q, &mut frames);
        match frames.last() {
            Some(tip) if tip_is_last => poses.push(*tip),
            _ => poses.push(chain.fk(q)),
        }
        // Rotation matrices once per link: 15 flops per point instead of a
        // quaternion rotation's ~30.
        mats.clear();
        mats.extend(
            frames
                .iter()
                .map(|f| (f.rotation.to_rotation_matrix(), f.translation.vector)),
        );
        points.extend(local.iter().map(|(link, p)| {
            let (r, t) = &mats[*link];
            Point3::from(r * p.coords + t)
        }));
    }
    Ok(ChainSamples {
        poses,
        points,
        points_per_waypoint: local.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::builtin_chain;
    use crate::score::ScoreField;

    #[test]
    fn box_corners_and_sphere_poles() {
        let b = Shape::Box {
            half_extents: nalgebra::Vector3::new(1.0, 2.0, 3.0),
        };
        let c = shape_extreme_points(&b);
        assert_eq!(c.len(), 8);
        assert!(
            c.iter()
                .all(|p| p.x.abs() == 1.0 && p.y.abs() == 2.0 && p.z.abs() == 3.0)
        );
        let s = shape_extreme_points(&Shape::Sphere { radius: 0.5 });
        assert!(s.iter().all(|p| (p.coords.norm() - 0.5).abs() < 1e-15));
    }

    #[test]
    fn planar_2_capsule_tip_is_the_farthest_point() {
        // link_2's capsule: origin 0.25 m along x, axis turned onto x, half
        // length 0.25 + radius 0.02: its far tip sits 1.02 m from joint 1.
        let chain = builtin_chain("planar_2").unwrap();
        let q = [0.0, 0.0];
        let s = sample_chain(
            &chain,
            Rows::Flat { values: &q, width: 2 },
            Some(PointSet::CollisionVertices),
        )
        .unwrap();
        let far = s.points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        assert!((far - 1.02).abs() < 1e-12, "{far}");
    }

    #[test]
    fn tool_pose_from_link_frames_equals_fk() {
        for name in crate::robot::BUILTIN_NAMES {
            let chain = builtin_chain(name).unwrap();
            let m = chain.dof();
            let q: Vec<f64> = (0..3 * m).map(|k| 0.1 + 0.37 * (k as f64).sin()).collect();
            let rows = Rows::Flat { values: &q, width: m };
            let plain = sample_chain(&chain, rows, None).unwrap();
            let with_points = sample_chain(&chain, rows, Some(PointSet::LinkOrigins)).unwrap();
            for (a, b) in plain.poses.iter().zip(&with_points.poses) {
                let d = (a.to_homogeneous() - b.to_homogeneous()).norm();
                assert!(d < 1e-12, "{name}: {d}");
            }
        }
    }

    #[test]
    fn bad_joints_are_named_before_fk() {
        let chain = builtin_chain("planar_2").unwrap();
        let q = vec![vec![0.0, 0.0], vec![0.0, f64::NAN]];
        assert!(matches!(
            sample_chain(&chain, Rows::Nested(&q), None),
            Err(ScoreError::NonFinite {
                field: ScoreField::Joints,
                index: 1,
                component: 1,
                ..
            })
        ));
        let q = vec![vec![0.0, 0.0], vec![0.0]];
        assert!(matches!(
            sample_chain(&chain, Rows::Nested(&q), None),
            Err(ScoreError::WrongJointCount { index: 1, .. })
        ));
    }
}
