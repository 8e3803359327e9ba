//! The robot as collision bodies: every link's primitives (and meshes given
//! inline, as convex hulls or polytopes of few faces around them) in the link frame, plus bodies hanging off the
//! chain by fixed or locked joints (a gripper's fingers), each with a
//! bounding sphere for the broad phase. Posed by forward kinematics into a
//! stack array, so a query allocates nothing.

use std::sync::{Arc, OnceLock};

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::SharedShape;

use super::bound::enclosing;
use super::builtin_meshes::builtin_mesh;
use super::convert::{point_from_parry, pose_to_parry, vec_to_parry};
use super::face_axes::FaceAxes;
use super::fast::RobotFast;
use super::fixed_frame::{FixedFrame, column, turned};
use super::outer_polytope::{PLANES, outer_polytope};
use super::pair_table::{PairTable, TABLE_BUDGET};
use super::scene::{SceneLimits, validate_mesh_points};
use super::spheres::{LANE_SPHERES, SphereModel};
use super::sweep::SweepBound;
use super::trig::sin_cos;
use super::world::primitive_shape;
use super::{CollisionError, Geometry};
use crate::robot::{Chain, CollisionShape, JointKind, Shape};
use crate::{Deadline, Stop};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// Most collision bodies (links with geometry) a model may have: one bit
/// each in a `u64` of the padded check, whose top bit is its self pairs.
pub const MAX_BODIES: usize = 63;
const _: () = assert!(MAX_BODIES < 64);
/// Most links a chain may have to get a collision model.
pub const MAX_LINKS: usize = 96;
/// Most mesh vertices a model's shapes may take, summed over every
/// collision element that names a mesh (a mesh named twice counts twice):
/// each such element gets its own hull and fitted polytope, so this bounds
/// the build by the request's size and not by how often a URDF repeats a
/// reference.
pub const MAX_MESH_VERTICES: usize = 1_000_000;

/// Geometry attached rigidly to a chain link but not on the chain itself,
/// e.g. a finger held at a fixed opening.
#[derive(Debug, Clone, PartialEq)]
pub struct AttachedBody {
    /// Name reported in collisions (the URDF link name).
    pub name: String,
    /// The chain link it hangs from.
    pub parent_link: String,
    /// Pose of the body frame in the parent link frame.
    pub offset: Isometry3<f64>,
    pub shapes: Vec<CollisionShape>,
}

/// The vertices and triangles of a mesh file a URDF names, supplied by the
/// caller. A robot mesh is used as its convex hull, or as a polytope of
/// few faces around the hull when that has fewer corners ([`outer_polytope`]).
#[derive(Debug, Clone, PartialEq)]
pub struct InlineMesh {
    pub filename: String,
    pub vertices: Vec<Point3<f64>>,
    pub indices: Vec<u32>,
}

/// One shape of a body: shape frame in the body frame (parry's axis
/// convention folded in).
#[derive(Clone)]
pub(crate) struct BodyShape {
    pub offset: Isometry3<f64>,
    pub shape: SharedShape,
    /// The closed-form description in the body frame (spheres, capsules,
    /// boxes), or `None` when only parry decides.
    pub fast: RobotFast,
    /// A closed form holding the shape (body frame): `fast` itself when
    /// there is one, else a capsule or box around a mesh hull or a
    /// cylinder ([`super::bound`]). Bounds apart prove the shapes apart.
    pub bound: RobotFast,
    /// The separating-axis filter of a polytope shape, tried against scene
    /// leaves before the exact test ([`FaceAxes`]); `None` for other shapes.
    pub faces: Option<Arc<FaceAxes>>,
}

/// A rigid collision body.
#[derive(Clone)]
pub(crate) struct Body {
    pub name: String,
    /// Index in [`Chain::links`] of the link that carries it.
    pub link: usize,
    /// Body frame in that link's frame.
    pub offset: Isometry3<f64>,
    /// The nearest ancestor body in the kinematic tree.
    pub parent: Option<usize>,
    pub shapes: Vec<BodyShape>,
    /// Bounding sphere (body frame): centre and radius, metres.
    pub center: Vector3<f64>,
    pub radius: f64,
}

/// A robot's collision geometry (see the module doc). Immutable; share it
/// as `Arc<RobotModel>` with the chain.
#[derive(Clone)]
pub struct RobotModel {
    chain: Arc<Chain>,
    pub(crate) bodies: Vec<Body>,
    /// Body indices ordered by carrying link (stable).
    by_link: Vec<usize>,
    /// Each body's frame in the frame of the joint moving its link (the
    /// link's offset then the body's), composed once; `None` when it is the
    /// identity (the usual case: the body is the link's own geometry).
    in_joint: Vec<Option<FixedFrame>>,
    /// Each joint's fixed origin and motion, shaped for [`RobotModel::pose_bodies`].
    steps: Vec<JointStep>,
    /// The proved-free regions of the self pairs one or two joints move
    /// apart ([`PairTable`]), built on first use.
    pair_tables: OnceLock<Vec<PairTable>>,
    /// The sphere model of the batched checks, built on first use (`None`
    /// where it cannot be built).
    lane_spheres: OnceLock<Option<SphereModel>>,
}

/// One joint of the chain as forward kinematics applies it: `frame =
/// t · origin`, then the joint's motion. URDF origins are applied in the
/// shape they have ([`FixedFrame`]) and most revolute joints turn about
/// their frame's z axis; neither needs the general quaternion products.
#[derive(Debug, Clone, Copy)]
struct JointStep {
    origin: FixedFrame,
    axis: nalgebra::Unit<Vector3<f64>>,
    kind: JointKind,
    /// A revolute joint about `+z` of its frame.
    about_z: bool,
}

impl JointStep {
    fn of(joint: &crate::robot::Joint) -> Self {
        JointStep {
            origin: FixedFrame::of(&joint.origin),
            axis: joint.axis,
            kind: joint.kind,
            about_z: joint.kind != JointKind::Prismatic && joint.axis.into_inner() == Vector3::z(),
        }
    }
}

/// `r · Rz(v)` for a unit quaternion `r`: the product with
/// `(cos v/2, 0, 0, sin v/2)` written out.
#[inline]
fn turned_about_z(r: &UnitQuaternion<f64>, v: f64) -> UnitQuaternion<f64> {
    let (s, c) = sin_cos(0.5 * v);
    turned(r, 2, c, s)
}

impl std::fmt::Debug for RobotModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotModel")
            .field("robot", &self.chain.name())
            .field("bodies", &self.body_names().collect::<Vec<_>>())
            .finish()
    }
}

impl RobotModel {
    /// The collision model of `chain` alone (URDF primitives; a mesh file
    /// named by a link is an error, as its geometry is unknown).
    pub fn new(chain: Arc<Chain>) -> Result<Self, CollisionError> {
        Self::with_parts(chain, &[], &[])
    }

    /// The whole robot of the URDF `urdf` that `chain` was parsed from: the
    /// chain's bodies and every other link the chain carries
    /// ([`attached_bodies`](super::attached_bodies): a gripper beyond the tip,
    /// a pedestal above the base, other branches held at `locked` joint values
    /// or 0 clamped into their limits), with the geometry of mesh files from
    /// `meshes`.
    pub fn of_urdf(
        chain: Arc<Chain>,
        urdf: &str,
        locked: &[(&str, f64)],
        meshes: &[InlineMesh],
    ) -> Result<Self, CollisionError> {
        Self::of_urdf_until(chain, urdf, locked, meshes, Deadline::none())
    }

    /// [`Self::of_urdf`], stopping with [`CollisionError::Stopped`] once
    /// `deadline` says so (polled before every mesh element's shape).
    pub fn of_urdf_until(
        chain: Arc<Chain>,
        urdf: &str,
        locked: &[(&str, f64)],
        meshes: &[InlineMesh],
        deadline: Deadline<'_>,
    ) -> Result<Self, CollisionError> {
        let attached = super::attach::attached_bodies(urdf, &chain, locked)?;
        Self::with_parts_until(chain, &attached, meshes, deadline)
    }

    /// The collision model of `chain`, plus `attached` bodies and the
    /// geometry of mesh files named by links (`meshes`, matched by filename).
    pub fn with_parts(
        chain: Arc<Chain>,
        attached: &[AttachedBody],
        meshes: &[InlineMesh],
    ) -> Result<Self, CollisionError> {
        Self::with_parts_until(chain, attached, meshes, Deadline::none())
    }

    /// [`Self::with_parts`], stopping with [`CollisionError::Stopped`] once
    /// `deadline` says so (polled before every mesh element's shape).
    pub fn with_parts_until(
        chain: Arc<Chain>,
        attached: &[AttachedBody],
        meshes: &[InlineMesh],
        deadline: Deadline<'_>,
    ) -> Result<Self, CollisionError> {
        if chain.links().len() > MAX_LINKS {
            return Err(CollisionError::TooMany {
                field: "chain.links".into(),
                count: chain.links().len(),
                limit: MAX_LINKS,
            });
        }
        let named_vertices: usize = chain
            .collision()
            .iter()
            .flat_map(|lc| &lc.shapes)
            .chain(attached.iter().flat_map(|a| &a.shapes))
            .filter_map(|cs| match &cs.shape {
                Shape::MeshReference { filename, .. } => Some(filename),
                _ => None,
            })
            .map(|filename| named_mesh(meshes, filename).map_or(0, |m| m.vertices.len()))
            .fold(0usize, usize::saturating_add);
        if named_vertices > MAX_MESH_VERTICES {
            return Err(CollisionError::TooMany {
                field: "mesh vertices named by links[].collision (each naming element counts)".into(),
                count: named_vertices,
                limit: MAX_MESH_VERTICES,
            });
        }
        let mut bodies: Vec<Body> = Vec::new();
        // Body carried by each link, for attached bodies' parents.
        let mut last_body_at_link: Vec<Option<usize>> = vec![None; chain.links().len()];
        let mut last: Option<usize> = None;
        // A mesh's hull and fitted polytope are the costly part: built once
        // per file and scale however many elements name them, side by side;
        // then each body's shapes (placing a mesh's vertices for its bound),
        // side by side too. The first error in body order is the one
        // reported.
        let link_fields: Vec<String> = chain
            .collision()
            .iter()
            .map(|lc| format!("links[{}]", lc.link))
            .collect();
        let attached_fields: Vec<String> = (0..attached.len()).map(|k| format!("attached[{k}]")).collect();
        let elements = chain
            .collision()
            .iter()
            .map(|lc| &lc.shapes[..])
            .zip(&link_fields)
            .chain(attached.iter().map(|a| &a.shapes[..]).zip(&attached_fields));
        let hulls = mesh_hulls(elements, meshes, deadline);
        let link_shapes: Vec<_> = chain
            .collision()
            .par_iter()
            .zip(&link_fields)
            .map(|(lc, field)| body_shapes(&lc.shapes, &hulls, field))
            .collect();
        let attached_shapes: Vec<_> = attached
            .par_iter()
            .zip(&attached_fields)
            .map(|(a, field)| body_shapes(&a.shapes, &hulls, field))
            .collect();
        for ((li, lc), shapes) in chain.collision().iter().enumerate().zip(link_shapes) {
            let shapes = shapes?;
            if !shapes.is_empty() {
                bodies.push(make_body(
                    lc.link.clone(),
                    li,
                    Isometry3::identity(),
                    last,
                    shapes,
                ));
                last = Some(bodies.len() - 1);
            }
            last_body_at_link[li] = last;
        }
        for ((k, a), shapes) in attached.iter().enumerate().zip(attached_shapes) {
            let field = format!("attached[{k}]");
            let li = chain
                .links()
                .iter()
                .position(|l| l.name == a.parent_link)
                .ok_or_else(|| CollisionError::UnknownName {
                    field: format!("{field}.parent_link"),
                    name: a.parent_link.clone(),
                })?;
            if !a.offset.translation.vector.iter().all(|v| v.is_finite())
                || !a.offset.rotation.coords.iter().all(|v| v.is_finite())
            {
                return Err(CollisionError::NonFinite {
                    field: format!("{field}.offset"),
                });
            }
            let shapes = shapes?;
            if !shapes.is_empty() {
                bodies.push(make_body(
                    a.name.clone(),
                    li,
                    a.offset,
                    last_body_at_link[li],
                    shapes,
                ));
            }
        }
        if bodies.len() > MAX_BODIES {
            return Err(CollisionError::TooManyBodies {
                field: "links".into(),
                count: bodies.len(),
                limit: MAX_BODIES,
            });
        }
        let mut by_link: Vec<usize> = (0..bodies.len()).collect();
        by_link.sort_by_key(|&b| bodies[b].link);
        let in_joint = bodies
            .iter()
            .map(|b| {
                let t = chain.links()[b.link].offset * b.offset;
                Some(FixedFrame::of(&t)).filter(|f| !f.is_identity())
            })
            .collect();
        let steps = chain.joints().iter().map(JointStep::of).collect();
        Ok(RobotModel {
            chain,
            bodies,
            by_link,
            in_joint,
            steps,
            pair_tables: OnceLock::new(),
            lane_spheres: OnceLock::new(),
        })
    }

    /// The sphere model of the batched checks ([`LANE_SPHERES`]), built on
    /// the first call and then shared by every checker of the model; `None`
    /// where the model has none.
    pub(crate) fn lane_spheres(&self) -> Option<&SphereModel> {
        self.lane_spheres
            .get_or_init(|| SphereModel::build(self, &LANE_SPHERES).ok())
            .as_ref()
    }

    /// The [`PairTable`]s of every pair of bodies that qualifies (built on
    /// the first call, then shared by every checker of the model).
    pub(crate) fn pair_tables(&self) -> &[PairTable] {
        // with no deadline the build always finishes
        self.pair_tables_until(Deadline::none()).unwrap_or(&[])
    }

    /// [`Self::pair_tables`], stopping (and keeping nothing) once `deadline`
    /// says so; polled before every coarse cell.
    pub(crate) fn pair_tables_until(&self, deadline: Deadline<'_>) -> Result<&[PairTable], Stop> {
        if let Some(tables) = self.pair_tables.get() {
            return Ok(tables);
        }
        let built = self.build_pair_tables(deadline)?;
        Ok(self.pair_tables.get_or_init(|| built))
    }

    fn build_pair_tables(&self, deadline: Deadline<'_>) -> Result<Vec<PairTable>, Stop> {
        let Some(sweep) = SweepBound::new(self) else {
            return Ok(Vec::new());
        };
        let n = self.bodies.len();
        let mut budget = TABLE_BUDGET;
        let mut planned: Vec<_> = (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .filter_map(|(a, b)| PairTable::planned(self, &sweep, a, b, &mut budget))
            .collect();
        // every row of coarse cells of every table is proved on its own, so
        // side by side
        let rows: Vec<(usize, usize)> = (0..planned.len())
            .flat_map(|t| (0..PairTable::ROWS).map(move |row| (t, row)))
            .collect();
        let proved = rows
            .par_iter()
            .map(|&(t, row)| planned[t].proved_row(self, row, deadline))
            .collect::<Result<Vec<_>, Stop>>()?;
        for (&(t, _), blocks) in rows.iter().zip(proved) {
            blocks.into_iter().for_each(|block| planned[t].mark(block));
        }
        Ok(planned)
    }

    pub fn chain(&self) -> &Arc<Chain> {
        &self.chain
    }

    /// Number of collision bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Every body as (its name, the chain link carrying it, its shape count),
    /// in the model's order.
    pub fn bodies(&self) -> impl Iterator<Item = (&str, &str, usize)> {
        let links = self.chain.links();
        self.bodies
            .iter()
            .map(move |b| (b.name.as_str(), links[b.link].name.as_str(), b.shapes.len()))
    }

    /// Body names (link names), in body order.
    pub fn body_names(&self) -> impl Iterator<Item = &str> {
        self.bodies.iter().map(|b| b.name.as_str())
    }

    /// True when bodies `a` and `b` are parent and child in the kinematic
    /// tree (links without geometry skipped).
    pub fn adjacent(&self, a: usize, b: usize) -> bool {
        self.bodies[a].parent == Some(b) || self.bodies[b].parent == Some(a)
    }

    /// Poses (base frame) of every body at `q`, written into `out[..body_count()]`
    /// (`out` holds at least [`RobotModel::body_count`] entries).
    /// `q` must hold `dof()` values (missing ones read as 0).
    ///
    /// Link poses follow [`Chain::link_frames_into`]:
    /// `T_link = Π_{joints before it} (O_i · M_i(q_i)) · offset_link`; a body's
    /// pose is `T_link · offset_body`.
    pub(crate) fn body_poses(&self, q: &[f64], out: &mut [Isometry3<f64>]) {
        self.pose_bodies(q, out, None);
    }

    /// [`RobotModel::body_poses`], plus every joint's axis (a point on it
    /// and its unit direction, base frame) into `axes[..dof]`: the axis of
    /// joint `i` is `axis_i` in the frame `Π_{k<i} (O_k · M_k(q_k)) · O_i`.
    pub(crate) fn body_poses_and_axes(&self, q: &[f64], out: &mut [Isometry3<f64>], axes: &mut [JointAxis]) {
        self.pose_bodies(q, out, Some(axes));
    }

    fn pose_bodies(&self, q: &[f64], out: &mut [Isometry3<f64>], mut axes: Option<&mut [JointAxis]>) {
        let steps = &self.steps;
        let links = self.chain.links();
        let mut t = Isometry3::identity();
        let mut applied = 0;
        // `by_link` lists bodies by carrying link, so one pass down the
        // chain poses them all without storing every link frame.
        let mut next = 0;
        for (li, link) in links.iter().enumerate() {
            if next == self.by_link.len() && axes.is_none() {
                break;
            }
            if let Some(j) = link.after_joint {
                while applied <= j && applied < steps.len() {
                    let step = &steps[applied];
                    let frame = step.origin.after(&t);
                    if let Some(slot) = axes.as_deref_mut().and_then(|a| a.get_mut(applied)) {
                        *slot = JointAxis {
                            point: frame.translation.vector,
                            direction: if step.about_z {
                                column(&frame.rotation, 2)
                            } else {
                                frame.rotation * step.axis.into_inner()
                            },
                        };
                    }
                    let v = q.get(applied).copied().unwrap_or(0.0);
                    // frame · motion(v), without composing the motion's
                    // zero translation or identity rotation
                    t = match step.kind {
                        JointKind::Revolute | JointKind::Continuous if step.about_z => {
                            Isometry3::from_parts(frame.translation, turned_about_z(&frame.rotation, v))
                        }
                        JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(
                            frame.translation,
                            frame.rotation * UnitQuaternion::from_axis_angle(&step.axis, v),
                        ),
                        JointKind::Prismatic => Isometry3::from_parts(
                            Translation3::from(
                                frame.translation.vector + frame.rotation * (step.axis.into_inner() * v),
                            ),
                            frame.rotation,
                        ),
                    };
                    applied += 1;
                }
            }
            while next < self.by_link.len() && self.bodies[self.by_link[next]].link == li {
                let b = self.by_link[next];
                out[b] = match &self.in_joint[b] {
                    Some(offset) => offset.after(&t),
                    None => t,
                };
                next += 1;
            }
        }
    }
}

/// One step of forward kinematics as [`RobotModel::fk_program`] lists it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FkOp {
    /// `t ← t · origin · M(q_joint)`, `M` the joint's motion about or along
    /// the unit `axis` (joint frame).
    Joint {
        origin: Isometry3<f64>,
        axis: Vector3<f64>,
        kind: JointKind,
    },
    /// Body `body`'s pose is `t · offset` (the link's offset, then the
    /// body's).
    Body { body: usize, offset: Isometry3<f64> },
}

impl RobotModel {
    /// The forward kinematics of [`RobotModel::body_poses`] as a flat list
    /// of steps, in the order that pass applies them (joints down the chain,
    /// each body posed as soon as its link's joints are applied).
    pub(crate) fn fk_program(&self) -> Vec<FkOp> {
        let links = self.chain.links();
        let joints = self.chain.joints();
        let mut ops = Vec::new();
        let (mut applied, mut next) = (0, 0);
        for (li, link) in links.iter().enumerate() {
            if next == self.by_link.len() {
                break;
            }
            if let Some(j) = link.after_joint {
                while applied <= j && applied < joints.len() {
                    let joint = &joints[applied];
                    ops.push(FkOp::Joint {
                        origin: joint.origin,
                        axis: joint.axis.into_inner(),
                        kind: joint.kind,
                    });
                    applied += 1;
                }
            }
            while next < self.by_link.len() && self.bodies[self.by_link[next]].link == li {
                let b = self.by_link[next];
                let offset = links[li].offset * self.bodies[b].offset;
                ops.push(FkOp::Body { body: b, offset });
                next += 1;
            }
        }
        ops
    }
}

/// A joint's axis in the base frame: a point on it and its unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointAxis {
    pub point: Vector3<f64>,
    pub direction: Vector3<f64>,
}

impl Default for JointAxis {
    fn default() -> Self {
        JointAxis {
            point: Vector3::zeros(),
            direction: Vector3::z(),
        }
    }
}

fn make_body(
    name: String,
    link: usize,
    offset: Isometry3<f64>,
    parent: Option<usize>,
    shapes: Vec<BodyShape>,
) -> Body {
    // Bounding sphere: centred on the box around the shapes' spheres,
    // radius reaching the farthest of them.
    let spheres: Vec<(Vector3<f64>, f64)> = shapes
        .iter()
        .map(|s| {
            let bs = s.shape.compute_bounding_sphere(&pose_to_parry(&s.offset));
            (Vector3::new(bs.center.x, bs.center.y, bs.center.z), bs.radius)
        })
        .collect();
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for (c, r) in &spheres {
        lo = lo.inf(&(c - Vector3::repeat(*r)));
        hi = hi.sup(&(c + Vector3::repeat(*r)));
    }
    let center = 0.5 * (lo + hi);
    let radius = spheres
        .iter()
        .map(|(c, r)| (c - center).norm() + r)
        .fold(0.0, f64::max);
    Body {
        name,
        link,
        offset,
        parent,
        shapes,
        center,
        radius,
    }
}

/// The mesh a collision element names: the file sent with the request
/// under that name, else a built-in robot's embedded mesh.
fn named_mesh<'a>(meshes: &'a [InlineMesh], filename: &str) -> Option<&'a InlineMesh> {
    meshes
        .iter()
        .find(|m| m.filename == filename)
        .or_else(|| builtin_mesh(filename))
}

/// A mesh file at one scale (the bits of its three factors).
type MeshKey<'a> = (&'a str, [u64; 3]);

fn mesh_key<'a>(filename: &'a str, scale: &Vector3<f64>) -> MeshKey<'a> {
    (
        filename,
        [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()],
    )
}

/// The costly part of a mesh body, mesh frame, shared by every collision
/// element that names the same file at the same scale.
struct MeshHull {
    /// The mesh's vertices, scaled.
    points: Vec<parry3d_f64::math::Vector>,
    shape: MeshShape,
}

/// What collides for a mesh (each contains every vertex).
enum MeshShape {
    /// A polytope of few faces fitted around the hull ([`fewer_faced`]).
    Fitted(SharedShape),
    /// The hull itself, grown where parry's hull left vertices outside.
    Hull(SharedShape),
    /// Too many vertices to check against the hull: the closed-form bound
    /// of the element's vertices is the shape.
    Bound,
}

/// The [`MeshHull`] of every distinct mesh file and scale that `elements`
/// (the collision shapes of each body, with the body's field) name, built
/// side by side; a build that fails carries the error of the first element,
/// in body order, that names its mesh. Files neither sent nor built in are
/// left out (the element reports them).
fn mesh_hulls<'a>(
    elements: impl Iterator<Item = (&'a [CollisionShape], &'a String)>,
    meshes: &'a [InlineMesh],
    deadline: Deadline<'_>,
) -> HashMap<MeshKey<'a>, Result<MeshHull, CollisionError>> {
    let mut first: Vec<(MeshKey<'a>, &'a InlineMesh, String)> = Vec::new();
    let mut seen = HashSet::new();
    for (shapes, field) in elements {
        for (k, cs) in shapes.iter().enumerate() {
            if let Shape::MeshReference { filename, scale } = &cs.shape {
                let key = mesh_key(filename, scale);
                if let Some(mesh) = named_mesh(meshes, filename)
                    && seen.insert(key)
                {
                    first.push((key, mesh, format!("{field}.collision[{k}]")));
                }
            }
        }
    }
    first
        .par_iter()
        .map(|(key, mesh, field)| {
            let scale = Vector3::from(key.1.map(f64::from_bits));
            (*key, mesh_hull(mesh, &scale, field, deadline))
        })
        .collect()
}

/// A mesh's hull at `scale` and the shape that collides for it
/// ([`MeshShape`]); errors name `field`.
fn mesh_hull(
    mesh: &InlineMesh,
    scale: &Vector3<f64>,
    field: &str,
    deadline: Deadline<'_>,
) -> Result<MeshHull, CollisionError> {
    if let Some(stop) = deadline.stop() {
        return Err(CollisionError::Stopped {
            what: "building the robot's collision bodies (mesh hulls)".into(),
            stop,
        });
    }
    validate_mesh_points(&mesh.vertices, &mesh.indices, field, &SceneLimits::default())?;
    let points: Vec<_> = mesh
        .vertices
        .iter()
        .map(|p| vec_to_parry(&p.coords.component_mul(scale)))
        .collect();
    let hull = SharedShape::convex_hull(&points).ok_or_else(|| CollisionError::Degenerate {
        field: field.to_string(),
        reason: format!("mesh `{}` has no 3-D convex hull", mesh.filename),
    })?;
    // a polytope of few faces, itself checked to hold every point
    let shape = if let Some(polytope) = fewer_faced(&hull, &points) {
        MeshShape::Fitted(polytope)
    } else {
        match farthest_outside(&hull, &points) {
            Some(0.0) => MeshShape::Hull(hull),
            // parry's hull left points outside: grow it by the farthest
            Some(d) => MeshShape::Hull(
                SharedShape::round_convex_hull(&points, d * (1.0 + 1e-9) + 1e-12).expect("the hull exists"),
            ),
            None => MeshShape::Bound,
        }
    };
    Ok(MeshHull { points, shape })
}

/// parry shapes of URDF collision elements, meshes from `hulls`
/// ([`mesh_hulls`]); zero-size primitives (a URDF may declare them) are
/// skipped.
fn body_shapes(
    shapes: &[CollisionShape],
    hulls: &HashMap<MeshKey<'_>, Result<MeshHull, CollisionError>>,
    field: &str,
) -> Result<Vec<BodyShape>, CollisionError> {
    let mut out = Vec::with_capacity(shapes.len());
    for (k, cs) in shapes.iter().enumerate() {
        let field = format!("{field}.collision[{k}]");
        let geometry = match &cs.shape {
            Shape::Box { half_extents } => Geometry::Box {
                half_extents: *half_extents,
            },
            Shape::Sphere { radius } => Geometry::Sphere { radius: *radius },
            Shape::Cylinder { radius, length } => Geometry::Cylinder {
                radius: *radius,
                length: *length,
            },
            Shape::Capsule { radius, length } => Geometry::Capsule {
                radius: *radius,
                length: *length,
            },
            Shape::MeshReference { filename, scale } => {
                let mesh = match hulls.get(&mesh_key(filename, scale)) {
                    Some(built) => built.as_ref().map_err(Clone::clone)?,
                    None => {
                        return Err(CollisionError::MeshNotInline {
                            field: field.clone(),
                            filename: filename.clone(),
                        });
                    }
                };
                let placed = |p: &parry3d_f64::math::Vector| cs.origin * point_from_parry(*p);
                out.push(match &mesh.shape {
                    MeshShape::Fitted(polytope) => {
                        let corners = polytope.as_convex_polyhedron().expect("a polytope").points();
                        BodyShape {
                            offset: cs.origin,
                            shape: polytope.clone(),
                            fast: RobotFast::None,
                            bound: enclosing(&corners.iter().map(placed).collect::<Vec<_>>()),
                            faces: None,
                        }
                    }
                    MeshShape::Hull(hull) => BodyShape {
                        offset: cs.origin,
                        shape: hull.clone(),
                        fast: RobotFast::None,
                        bound: enclosing(&mesh.points.iter().map(placed).collect::<Vec<_>>()),
                        faces: None,
                    },
                    // too many points to check: the closed-form bound is the shape
                    MeshShape::Bound => {
                        bound_shape(enclosing(&mesh.points.iter().map(placed).collect::<Vec<_>>()))
                            .ok_or_else(|| CollisionError::Degenerate {
                                field: field.clone(),
                                reason: format!("mesh `{filename}` has no finite bound"),
                            })?
                    }
                });
                continue;
            }
        };
        let degenerate = match &geometry {
            Geometry::Box { half_extents } => half_extents.min() <= 0.0,
            Geometry::Sphere { radius } | Geometry::Capsule { radius, .. } => *radius <= 0.0,
            Geometry::Cylinder { radius, length } => *radius <= 0.0 || *length <= 0.0,
            _ => false,
        };
        if degenerate {
            continue;
        }
        let (shape, fix) = primitive_shape(&geometry).expect("primitive");
        let fast = match geometry {
            Geometry::Sphere { radius } => {
                let c = Point3::from(cs.origin.translation.vector);
                RobotFast::Swept {
                    a: c,
                    b: c,
                    r: radius,
                }
            }
            Geometry::Capsule { radius, length } => RobotFast::Swept {
                a: cs.origin * Point3::new(0.0, 0.0, -0.5 * length),
                b: cs.origin * Point3::new(0.0, 0.0, 0.5 * length),
                r: radius,
            },
            Geometry::Box { half_extents } => RobotFast::Box {
                offset: cs.origin,
                half: half_extents,
            },
            _ => RobotFast::None,
        };
        let bound = match geometry {
            // the capsule of the same axis and radius holds the cylinder
            Geometry::Cylinder { radius, length } => RobotFast::Swept {
                a: cs.origin * Point3::new(0.0, 0.0, -0.5 * length),
                b: cs.origin * Point3::new(0.0, 0.0, 0.5 * length),
                r: radius,
            },
            _ => fast,
        };
        out.push(BodyShape {
            offset: cs.origin * fix,
            shape,
            fast,
            bound,
            faces: None,
        });
    }
    for s in &mut out {
        s.faces = FaceAxes::of(&s.shape).map(Arc::new);
    }
    Ok(out)
}

/// Most point-against-face tests [`farthest_outside`] makes.
const MAX_HULL_CHECK: usize = 50_000_000;

/// How far the farthest of `points` lies outside `hull` (0 when all are
/// inside): parry's hull of a thin mesh can leave some of its points a
/// little outside. Each point is tested against the face planes, and one
/// found outside is projected onto the hull. `None` when that would take
/// more than [`MAX_HULL_CHECK`] tests, or the hull is not a polyhedron.
fn farthest_outside(hull: &SharedShape, points: &[parry3d_f64::math::Vector]) -> Option<f64> {
    let poly = hull.as_convex_polyhedron()?;
    let corners = poly.points();
    let planes: Vec<_> = poly
        .faces()
        .iter()
        .map(|f| {
            let on = corners[poly.vertices_adj_to_face()[f.first_vertex_or_edge as usize] as usize];
            (f.normal, f.normal.dot(on))
        })
        .collect();
    if points.len().saturating_mul(planes.len()) > MAX_HULL_CHECK {
        return None;
    }
    let mut farthest = 0.0f64;
    for p in points {
        if planes.iter().any(|(n, h)| n.dot(*p) > *h) {
            farthest = farthest.max(poly.distance_to_local_point(*p, true));
        }
    }
    Some(farthest)
}

/// The polytope of few faces around a mesh ([`outer_polytope`]), when the
/// mesh's hull (parry's, whose face normals are the candidate planes) has
/// more faces than such a polytope and more corners than it, and every
/// point of the mesh is checked inside the polytope; `None` otherwise.
/// Checked against the points, not the hull, it also stands where
/// parry's hull of a thin mesh leaves points outside.
fn fewer_faced(hull: &SharedShape, points: &[parry3d_f64::math::Vector]) -> Option<SharedShape> {
    let poly = hull.as_convex_polyhedron()?;
    if poly.faces().len() <= PLANES {
        return None;
    }
    let corners = poly.points();
    let around = poly.vertices_adj_to_face();
    let mut faces: Vec<(f64, Vector3<f64>)> = poly
        .faces()
        .iter()
        .map(|f| {
            let loop_ = &around[f.first_vertex_or_edge as usize..][..f.num_vertices_or_edges as usize];
            let at = |k: usize| point_from_parry(corners[loop_[k] as usize]);
            let twice_area: f64 = (1..loop_.len().saturating_sub(1))
                .map(|k| (at(k) - at(0)).cross(&(at(k + 1) - at(0))).norm())
                .sum();
            (twice_area, Vector3::new(f.normal.x, f.normal.y, f.normal.z))
        })
        .collect();
    faces.sort_by(|a, b| b.0.total_cmp(&a.0));
    let normals: Vec<Vector3<f64>> = faces.into_iter().map(|(_, n)| n).collect();
    let mesh: Vec<Point3<f64>> = points.iter().map(|p| point_from_parry(*p)).collect();
    let fitted = outer_polytope(&mesh, &normals)?;
    if fitted.len() >= corners.len() {
        return None;
    }
    let polytope =
        SharedShape::convex_hull(&fitted.iter().map(|p| vec_to_parry(&p.coords)).collect::<Vec<_>>())?;
    (farthest_outside(&polytope, points) == Some(0.0)).then_some(polytope)
}

/// A body shape that is its closed form `bound` (a capsule or a box, body
/// frame); `None` for no bound.
fn bound_shape(bound: RobotFast) -> Option<BodyShape> {
    let (offset, shape) = match bound {
        RobotFast::Swept { a, b, r } => {
            let (mid, axis) = (nalgebra::center(&a, &b), b - a);
            let turn = UnitQuaternion::rotation_between(&Vector3::y(), &axis).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(
                    &Vector3::x_axis(),
                    if axis.y < 0.0 { std::f64::consts::PI } else { 0.0 },
                )
            });
            (
                Isometry3::from_parts(Translation3::from(mid.coords), turn),
                SharedShape::capsule_y(0.5 * axis.norm(), r),
            )
        }
        RobotFast::Box { offset, half } => (offset, SharedShape::cuboid(half.x, half.y, half.z)),
        RobotFast::None => return None,
    };
    Some(BodyShape {
        offset,
        shape,
        fast: bound,
        bound,
        faces: None,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{RobotFast, bound_shape};
    use crate::collision::bound::tests::outside;
    use crate::collision::convert::{pose_to_parry, vec_to_parry};

    /// The shape that stands for a mesh too large to check is its bound:
    /// parry's shape holds a point exactly when the closed form does (away
    /// from the surface), for capsules along every direction and turned boxes.
    #[test]
    fn a_bound_standing_for_a_mesh_is_the_same_shape_in_parry() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let bounds = [
            RobotFast::Swept {
                a: Point3::new(0.1, -0.2, 0.3),
                b: Point3::new(-0.3, 0.25, 0.1),
                r: 0.07,
            },
            RobotFast::Swept {
                a: Point3::new(0.0, 0.2, 0.0),
                b: Point3::new(0.0, -0.2, 0.0),
                r: 0.05,
            },
            RobotFast::Swept {
                a: Point3::new(0.2, 0.1, 0.0),
                b: Point3::new(0.2, 0.1, 0.0),
                r: 0.05,
            },
            RobotFast::Box {
                offset: Isometry3::from_parts(
                    Translation3::new(0.1, 0.0, -0.2),
                    UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
                ),
                half: Vector3::new(0.2, 0.05, 0.1),
            },
        ];
        for bound in bounds {
            let shape = bound_shape(bound).unwrap();
            let pose = pose_to_parry(&shape.offset);
            for _ in 0..2000 {
                let p = Point3::new(
                    rng.random_range(-0.6..0.6),
                    rng.random_range(-0.6..0.6),
                    rng.random_range(-0.6..0.6),
                );
                let outside = outside(&bound, &p);
                if outside.abs() > 1e-9 {
                    let inside = shape.shape.contains_point(&pose, vec_to_parry(&p.coords));
                    assert_eq!(inside, outside < 0.0, "{bound:?} at {p:?}");
                }
            }
        }
        assert!(bound_shape(RobotFast::None).is_none());
    }
}
