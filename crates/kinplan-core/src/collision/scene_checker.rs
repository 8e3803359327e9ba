//! [`SceneChecker`]: the [`StateChecker`] of one robot model in one scene.
//!
//! A state is valid when every joint is within its limits and no body
//! overlaps an obstacle or a body it is not allowed to touch (touching
//! counts as overlap). Per query: forward kinematics into stack arrays;
//! for each body, the scene BVH is queried with the box around the body's
//! bounding sphere, leaves are culled by sphere–box distance, and parry's
//! exact test runs on the survivors; then the checked self pairs, culled by
//! sphere–sphere distance. Bodies fixed to the base are tested against the
//! scene once, when the checker is built, and moving bodies whose reach
//! meets no obstacle not at all (`scene_bodies`). Nothing is allocated, so
//! checkers are shared freely between rayon threads.

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Vector3};

use super::acm::AllowedCollisions;
use super::bvh::Aabb;
use super::lanes8::{Flags, Lanes8, MAX_BODIES8, MAX_DOF8, WIDTH};
use super::model::{JointAxis, MAX_BODIES, MAX_LINKS, RobotModel};
use super::narrow::{
    Witness, body_body_contact, body_body_intersect, body_body_within, body_leaf_contact,
    body_leaf_intersect, body_leaf_within, shapes_intersect_leaf, sphere_center,
};
use super::sweep::SweepBound;
use super::world::SceneGeometry;
use super::{CollisionError, MotionCheck, PadVerdict, StateChecker};
use crate::robot::JointKind;

/// Joints of the chains whose padded checks keep their axes in a small buffer.
const SMALL_CHAIN: usize = 16;
/// Bodies of the models whose state checks keep poses, centres and pads in
/// buffers of this size instead of [`MAX_BODIES`]: an arm with a gripper
/// has about a dozen, and every check would otherwise fill four arrays of 63.
const SMALL_MODEL: usize = 16;

/// Options of a [`SceneChecker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckerParams {
    /// Largest joint step (rad or m) between states checked along a motion
    /// (default and largest allowed: [`Self::MAX_MOTION_RESOLUTION`]).
    pub motion_resolution: f64,
    /// Prove each motion free piece by piece, every body padded by how far it
    /// can move within the piece ([`MotionCheck::Padded`], conservative);
    /// `false` checks interpolated states as they are
    /// ([`MotionCheck::Interpolated`]).
    pub padded_motion: bool,
    /// Check the states of a motion eight at a time through the sphere model
    /// in `f32` vector lanes, the states it leaves unsure exactly, only for
    /// the bodies and pairs the spheres did not clear
    /// ([`StateChecker::states_valid`]; the same verdicts), and offer the
    /// pieces of a padded motion to the spheres eight at a time
    /// ([`StateChecker::padded_free_batch`]; sound, but a piece the spheres
    /// prove may be one the one-piece check would have halved). Models and
    /// scenes beyond the lanes' limits are checked exactly whatever this
    /// says. Default `true`.
    pub batched: bool,
}

impl Default for CheckerParams {
    fn default() -> Self {
        CheckerParams {
            motion_resolution: Self::MAX_MOTION_RESOLUTION,
            padded_motion: false,
            batched: true,
        }
    }
}

impl CheckerParams {
    /// The coarsest allowed motion resolution, 0.05 rad (or m).
    pub const MAX_MOTION_RESOLUTION: f64 = 0.05;

    pub fn validate(&self) -> Result<(), CollisionError> {
        let r = self.motion_resolution;
        let upper = Self::MAX_MOTION_RESOLUTION;
        if !(r.is_finite() && r > 0.0 && r <= upper) {
            return Err(CollisionError::OutOfRange {
                field: "motion_resolution".into(),
                value: r,
                lower: 0.0,
                upper,
            });
        }
        Ok(())
    }
}

/// What a robot part touched: another body of the robot or an obstacle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Part {
    /// A robot body, by link name.
    Link(String),
    /// An obstacle, by index in the scene and name.
    Obstacle { index: usize, name: String },
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Part::Link(name) => write!(f, "link `{name}`"),
            Part::Obstacle { name, .. } => write!(f, "obstacle `{name}`"),
        }
    }
}

/// The nearest (or deepest) pair between the robot and the rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Proximity {
    /// Signed distance (m), negative by the penetration depth.
    pub distance: f64,
    /// The robot link.
    pub link: String,
    /// What it is nearest to.
    pub other: Part,
    /// Witness point on the link (base frame, m).
    pub point_on_link: Point3<f64>,
    /// Witness point on the other part (base frame, m).
    pub point_on_other: Point3<f64>,
}

/// Everything wrong with one state, for INVALID_START / INVALID_GOAL messages.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StateReport {
    /// Joints outside their limits: (index, value, lower, upper).
    pub out_of_limits: Vec<(usize, f64, f64, f64)>,
    /// Colliding pairs: a robot link and what it touches.
    pub collisions: Vec<(String, Part)>,
}

impl StateReport {
    pub fn is_valid(&self) -> bool {
        self.out_of_limits.is_empty() && self.collisions.is_empty()
    }
}

impl std::fmt::Display for StateReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_valid() {
            return write!(f, "valid");
        }
        let mut parts = Vec::new();
        for (i, v, lo, hi) in &self.out_of_limits {
            parts.push(format!("joint {i} = {v} outside [{lo}, {hi}]"));
        }
        for (link, other) in &self.collisions {
            parts.push(format!("link `{link}` collides with {other}"));
        }
        write!(f, "{}", parts.join("; "))
    }
}

/// Robot model + allowed-collision matrix + scene (see the module doc).
///
/// ```
/// use std::sync::Arc;
/// use kinplan_core::collision::*;
/// use nalgebra::{Isometry3, Vector3};
///
/// let chain = kinplan_core::robot::builtin_chain("planar_2").unwrap();
/// let model = Arc::new(RobotModel::new(chain).unwrap());
/// let acm = AllowedCollisions::adjacent(&model);
/// // A 10 cm cube 0.8 m along x: the stretched arm (reach 1 m) hits it,
/// // the arm turned to +y misses it.
/// let cube = Obstacle::new(
///     "cube",
///     Isometry3::translation(0.8, 0.0, 0.0),
///     Geometry::Box { half_extents: Vector3::repeat(0.05) },
/// );
/// let scene = Scene::new(vec![cube], &SceneLimits::default()).unwrap();
/// let world = Arc::new(SceneGeometry::build(&scene).unwrap());
/// let checker = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
/// assert!(!checker.is_valid(&[0.0, 0.0]));
/// assert!(checker.is_valid(&[std::f64::consts::FRAC_PI_2, 0.0]));
/// let report = checker.report(&[0.0, 0.0]).unwrap();
/// assert!(report.to_string().contains("obstacle `cube`"));
/// ```
#[derive(Debug, Clone)]
pub struct SceneChecker {
    model: Arc<RobotModel>,
    world: Arc<SceneGeometry>,
    /// Body pairs tested for self-collision, `a < b`.
    self_pairs: Vec<(u16, u16)>,
    /// Per self pair, its index in the model's `PairTable`s, if it has one.
    tables: Vec<Option<u16>>,
    /// Bodies tested against the scene, distal first (the likeliest to hit
    /// something): every body but those no state can bring to an obstacle
    /// ([`scene_bodies`]).
    scene_bodies: Vec<u16>,
    params: CheckerParams,
    /// How far bodies move per joint step (`None`: unbounded, cannot pad).
    sweep: Option<SweepBound>,
    /// The sphere model and the scene laid out for eight states or pieces in
    /// `f32` lanes ([`StateChecker::states_valid`],
    /// [`StateChecker::padded_free_batch`]); `None` unbatched or beyond the
    /// lanes' limits.
    lanes8: Option<Lanes8>,
}

impl SceneChecker {
    /// A checker for `model` in `world`; `acm` must be over `model`'s bodies.
    pub fn new(
        model: Arc<RobotModel>,
        acm: &AllowedCollisions,
        world: Arc<SceneGeometry>,
        params: CheckerParams,
    ) -> Result<Self, CollisionError> {
        params.validate()?;
        if acm.size() != model.body_count() {
            return Err(CollisionError::OutOfRange {
                field: "acm.size".into(),
                value: acm.size() as f64,
                lower: model.body_count() as f64,
                upper: model.body_count() as f64,
            });
        }
        let self_pairs: Vec<(u16, u16)> = acm.checked_pairs().map(|(a, b)| (a as u16, b as u16)).collect();
        let all_tables = model.pair_tables();
        let tables = self_pairs
            .iter()
            .map(|&(a, b)| {
                let found = all_tables
                    .iter()
                    .position(|t| (t.a, t.b) == (a as usize, b as usize));
                found.map(|i| i as u16)
            })
            .collect();
        let sweep = SweepBound::new(&model);
        if params.padded_motion && sweep.is_none() {
            return Err(CollisionError::CannotPad);
        }
        let scene_bodies = scene_bodies(&model, &world, sweep.as_ref());
        let spheres = params.batched.then(|| model.lane_spheres()).flatten();
        let lanes8 = spheres.and_then(|s| Lanes8::new(&model, s, &world));
        Ok(SceneChecker {
            model,
            world,
            self_pairs,
            tables,
            scene_bodies,
            params,
            sweep,
            lanes8,
        })
    }

    pub fn model(&self) -> &Arc<RobotModel> {
        &self.model
    }

    pub fn world(&self) -> &Arc<SceneGeometry> {
        &self.world
    }

    /// True when `q` has `dof` finite values within the joint limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        let joints = self.model.chain().joints();
        q.len() == joints.len()
            && q.iter()
                .zip(joints)
                .all(|(v, j)| v.is_finite() && *v >= j.lower && *v <= j.upper)
    }

    /// True when some body overlaps an obstacle or a checked body (limits
    /// not considered). `q` must hold `dof` finite values.
    pub fn in_collision(&self, q: &[f64]) -> bool {
        if self.model.body_count() <= SMALL_MODEL {
            let mut poses = [Isometry3::identity(); SMALL_MODEL];
            self.model.body_poses(q, &mut poses);
            self.hits(q, &poses)
        } else {
            let mut poses = [Isometry3::identity(); MAX_BODIES];
            self.model.body_poses(q, &mut poses);
            self.hits(q, &poses)
        }
    }

    /// [`StateChecker::states_valid`] in batches of [`WIDTH`] states: the
    /// limits, then forward kinematics and the sphere model against the
    /// scene for the whole batch in `f32` lanes (`Lanes8::unsure`); a state
    /// the spheres leave unsure is checked exactly for the bodies and pairs
    /// they did not clear ([`SceneChecker::hits_flagged`]), so the answer is
    /// the exact check's. `portable` forces the baseline build of the batch
    /// code. `None` when the checker has no batched form.
    pub(crate) fn states_valid_in_lanes(&self, rows: &[f64], portable: bool) -> Option<bool> {
        let lanes = self.lanes8.as_ref()?;
        let dof = lanes.dof();
        if dof == 0 || !rows.len().is_multiple_of(dof) {
            return None;
        }
        let mut flags = Flags::default();
        for batch in rows.chunks(WIDTH * dof) {
            let n = batch.len() / dof;
            let mut q = [[0.0f32; WIDTH]; MAX_DOF8];
            for (l, row) in batch.chunks_exact(dof).enumerate() {
                // the limits also keep every value within what the lanes take
                if !self.within_limits(row) {
                    return Some(false);
                }
                for (j, &v) in row.iter().enumerate() {
                    q[j][l] = v as f32;
                }
            }
            // unused lanes repeat the last state
            for qj in q[..dof].iter_mut() {
                let last = qj[n - 1];
                qj[n..].fill(last);
            }
            // the pairs the tables prove apart in every state stay out of the lanes
            let mut kept = Kept::default();
            let n_kept = self.pairs_left(batch, dof, &[], &mut kept);
            let pairs = n_kept.map_or(&self.self_pairs[..], |n| &kept.pairs[..n]);
            let unsure = lanes.unsure(&q[..dof], &self.scene_bodies, pairs, &mut flags, portable);
            for (l, row) in batch.chunks_exact(dof).enumerate() {
                if unsure & (1 << l) == 0 {
                    continue;
                }
                // the lanes' pair bits name kept pairs; the check names all
                let pairs = match n_kept {
                    None => flags.pairs[l],
                    Some(n) => (0..n)
                        .filter(|&k| flags.pairs[l] & (1 << k) != 0)
                        .fold(0u64, |bits, k| bits | 1 << kept.index[k]),
                };
                if self.hits_flagged(row, flags.bodies[l], pairs) {
                    return Some(false);
                }
            }
        }
        Some(true)
    }

    /// True when `q` collides, testing only the scene around the bodies of
    /// `bodies` (bit `b`: body `b`) and the checked self pairs of `pairs`
    /// (bit `i`: pair `i`; bit 63: every pair from the 63rd on). `q` must
    /// hold `dof` finite values.
    pub(crate) fn hits_flagged(&self, q: &[f64], bodies: u32, pairs: u64) -> bool {
        // the eight lanes exist only for models of at most MAX_BODIES8 bodies
        debug_assert!(self.model.body_count() <= MAX_BODIES8);
        let mut poses = [Isometry3::identity(); MAX_BODIES8];
        self.model.body_poses(q, &mut poses);
        let all = &self.model.bodies;
        let mut bits = bodies;
        // the last bodies first, as in `scene_bodies`: a state that
        // collides mostly does so at the tool's end
        while bits != 0 {
            let b = (u32::BITS - 1 - bits.leading_zeros()) as usize;
            bits &= !(1 << b);
            if self.body_hits_scene(b, &poses[b], &sphere_center(&all[b], &poses[b])) {
                return true;
            }
        }
        self.self_pairs.iter().enumerate().any(|(i, &(a, b))| {
            let (a, b) = (a as usize, b as usize);
            pairs & (1 << i.min(63)) != 0
                && !self.pair_proved(i, q, &[])
                && body_body_intersect(&all[a], &poses[a], &all[b], &poses[b])
        })
    }

    /// The eight-lane form (tests).
    #[cfg(test)]
    pub(crate) fn lanes8(&self) -> Option<&Lanes8> {
        self.lanes8.as_ref()
    }

    /// The bodies tested against the scene and the checked self pairs
    /// (tests).
    #[cfg(test)]
    pub(crate) fn checked_parts(&self) -> (&[u16], &[(u16, u16)]) {
        (&self.scene_bodies, &self.self_pairs)
    }

    /// True when body `b` at `pose` (bounding-sphere centre `center`) touches
    /// the scene: the leaves near its sphere, each by its exact test.
    #[inline]
    fn body_hits_scene(&self, b: usize, pose: &Isometry3<f64>, center: &Vector3<f64>) -> bool {
        let body = &self.model.bodies[b];
        // the query's sphere is the body's: leaves arrive culled by it
        !self.world.bvh.for_each_near(center, body.radius, |leaf| {
            !shapes_intersect_leaf(body, pose, &self.world.leaves[leaf as usize])
        })
    }

    /// The bodies' bounding-sphere centres at `poses` (`N` ≥ the body count).
    fn centers<const N: usize>(&self, poses: &[Isometry3<f64>; N]) -> [Vector3<f64>; N] {
        let mut centers = [Vector3::zeros(); N];
        for (b, body) in self.model.bodies.iter().enumerate() {
            centers[b] = sphere_center(body, &poses[b]);
        }
        centers
    }

    /// True when self pair `i`'s `PairTable` proves it apart at every state
    /// within `half` of `q` (`half` empty: at `q`).
    fn pair_proved(&self, i: usize, q: &[f64], half: &[f64]) -> bool {
        self.tables[i].is_some_and(|t| self.model.pair_tables()[t as usize].proves_apart(q, half))
    }

    /// The self pairs some row of `rows` (states of `dof` values; with
    /// `half`, the middles of pieces) needs checked: those the tables do not
    /// prove apart at every row, into `kept[..n]`, with their indices in
    /// `self_pairs` into `index`; returns `n`. `None` when there are more
    /// than `KEPT` pairs (the lanes' bits could not name them all): then
    /// every pair goes to the lanes.
    fn pairs_left(&self, rows: &[f64], dof: usize, half: &[f64], kept: &mut Kept) -> Option<usize> {
        if self.self_pairs.len() > KEPT {
            return None;
        }
        let mut n = 0;
        for (i, &pair) in self.self_pairs.iter().enumerate() {
            let proved =
                self.tables[i].is_some() && rows.chunks_exact(dof).all(|row| self.pair_proved(i, row, half));
            if !proved {
                kept.pairs[n] = pair;
                kept.index[n] = i as u16;
                n += 1;
            }
        }
        Some(n)
    }

    /// [`SceneChecker::in_collision`] at `q` on bodies already posed (`N` ≥
    /// the body count).
    fn hits<const N: usize>(&self, q: &[f64], poses: &[Isometry3<f64>; N]) -> bool {
        let bodies = &self.model.bodies;
        let centers = self.centers(poses);
        for &b in &self.scene_bodies {
            let (b, c) = (b as usize, &centers[b as usize]);
            // the query's sphere is the body's: leaves arrive culled by it
            let free = self.world.bvh.for_each_near(c, bodies[b].radius, |leaf| {
                !shapes_intersect_leaf(&bodies[b], &poses[b], &self.world.leaves[leaf as usize])
            });
            if !free {
                return true;
            }
        }
        self.self_pairs.iter().enumerate().any(|(i, &(a, b))| {
            let (a, b) = (a as usize, b as usize);
            let reach = bodies[a].radius + bodies[b].radius;
            (centers[a] - centers[b]).norm_squared() <= reach * reach
                && !self.pair_proved(i, q, &[])
                && body_body_intersect(&bodies[a], &poses[a], &bodies[b], &poses[b])
        })
    }

    /// True when some body comes closer than its pad to an obstacle, or two
    /// checked bodies closer than the sum of their pads (touching included):
    /// with `pads[b]` the farthest body `b` can move, no state within that
    /// motion of `q` collides when this is false. `q` must hold `dof` finite
    /// values.
    pub fn in_collision_padded(&self, q: &[f64], pads: &[f64; MAX_BODIES]) -> bool {
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        self.model.body_poses(q, &mut poses);
        self.hits_padded(&poses, pads, |b| pads[b], None, &mut 0) != PadHit::Clear
    }

    /// [`SceneChecker::in_collision_padded`] on bodies already posed, with
    /// the pads in two grades: `coarse[b]`, cheap and never below the pad,
    /// finds what a body might touch; `fine(b)`, the pad itself, is asked
    /// (at most once per body) only for bodies that have something within
    /// their coarse pad — in a cell most bodies have nothing near. Once an
    /// obstacle is found within a body's pad, that body's further obstacles
    /// are only tested without pads, and once a self pair is found within
    /// its pads, so are the further self pairs ([`PadHit::Touches`] ends the
    /// check), so a state in collision is refused at once.
    ///
    /// `piece` (the state `q` at the middle and the half step), when the
    /// pads cover a piece of a motion, lets the `PairTable`s prove self
    /// pairs apart over it.
    ///
    /// `proved` lists what is already proved free over the piece the pads
    /// cover and need not be checked: bit `b` the scene around body `b`,
    /// [`SELF_PAIRS`] every self pair. What this check proves is added:
    /// after a body is found near something the other bodies are still
    /// checked, so that the halves of the piece check only what is left.
    fn hits_padded<const N: usize>(
        &self,
        poses: &[Isometry3<f64>; N],
        coarse: &[f64; N],
        mut fine: impl FnMut(usize) -> f64,
        piece: Option<(&[f64], &[f64])>,
        proved: &mut u64,
    ) -> PadHit {
        let bodies = &self.model.bodies;
        // A zero pad still counts touching: growing by a hair keeps `≤ 0` a hit.
        let margin = |pad: f64| pad.max(f64::MIN_POSITIVE);
        let mut fine_pads = [f64::NAN; N];
        let mut fine_pad = |b: usize| {
            if fine_pads[b].is_nan() {
                fine_pads[b] = margin(fine(b));
            }
            fine_pads[b]
        };
        let centers = self.centers(poses);
        let mut found = PadHit::Clear;
        for &b in &self.scene_bodies {
            let (b, c) = (b as usize, &centers[b as usize]);
            if *proved & (1 << b) != 0 {
                continue;
            }
            let (body, pose) = (&bodies[b], &poses[b]);
            // once a leaf is within the pad the body is not proved; the
            // rest of its leaves are only asked whether they touch it
            let (mut near, mut touches) = (false, false);
            self.world
                .bvh
                .for_each_near(c, body.radius + margin(coarse[b]), |leaf| {
                    let leaf = &self.world.leaves[leaf as usize];
                    if near || body_leaf_within(body, pose, c, leaf, fine_pad(b)) {
                        near = true;
                        touches = body_leaf_intersect(body, pose, c, leaf);
                    }
                    !touches
                });
            if touches {
                return PadHit::Touches;
            }
            if near {
                found = PadHit::Near;
            } else {
                *proved |= 1 << b;
            }
        }
        if *proved & SELF_PAIRS != 0 {
            return found;
        }
        let mut self_near = false;
        for (i, &(a, b)) in self.self_pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            if piece.is_some_and(|(q, half)| self.pair_proved(i, q, half)) {
                continue;
            }
            let (ra, rb) = (bodies[a].radius, bodies[b].radius);
            let pad = if self_near {
                0.0
            } else {
                margin(coarse[a] + coarse[b])
            };
            let reach = ra + rb + pad;
            if (centers[a] - centers[b]).norm_squared() > reach * reach {
                continue;
            }
            if self_near
                || body_body_within(
                    &bodies[a],
                    &poses[a],
                    &bodies[b],
                    &poses[b],
                    margin(fine_pad(a) + fine_pad(b)),
                )
            {
                if body_body_intersect(&bodies[a], &poses[a], &bodies[b], &poses[b]) {
                    return PadHit::Touches;
                }
                self_near = true;
                found = PadHit::Near;
            }
        }
        if self_near {
            return found;
        }
        *proved |= SELF_PAIRS;
        found
    }

    /// The nearest pair within `max_distance` (m), with witness points, or
    /// `None` when everything is farther. Bad `q` is an error.
    pub fn proximity(&self, q: &[f64], max_distance: f64) -> Result<Option<Proximity>, CollisionError> {
        self.check_q(q)?;
        if max_distance.is_nan() {
            return Err(CollisionError::NonFinite {
                field: "max_distance".into(),
            });
        }
        Ok(self.nearest(q, max_distance).map(|(w, link, other)| Proximity {
            distance: w.distance,
            link: self.model.bodies[link].name.clone(),
            other: self.part(other),
            point_on_link: w.a,
            point_on_other: w.b,
        }))
    }

    /// Every limit violation and colliding pair of `q`.
    pub fn report(&self, q: &[f64]) -> Result<StateReport, CollisionError> {
        self.check_q(q)?;
        let mut report = StateReport::default();
        for (i, (v, j)) in q.iter().zip(self.model.chain().joints()).enumerate() {
            if *v < j.lower || *v > j.upper {
                report.out_of_limits.push((i, *v, j.lower, j.upper));
            }
        }
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        self.model.body_poses(q, &mut poses);
        let bodies = &self.model.bodies;
        for (b, body) in bodies.iter().enumerate() {
            let c = sphere_center(body, &poses[b]);
            let mut hits = Vec::new();
            self.world
                .bvh
                .for_each_overlap(&Aabb::around_sphere(&c, body.radius), |leaf| {
                    let l = &self.world.leaves[leaf as usize];
                    if body_leaf_intersect(body, &poses[b], &c, l) {
                        hits.push(l.obstacle as usize);
                    }
                    true
                });
            hits.sort_unstable();
            hits.dedup();
            for o in hits {
                report
                    .collisions
                    .push((body.name.clone(), self.part(Other::Obstacle(o))));
            }
        }
        for &(a, b) in &self.self_pairs {
            let (a, b) = (a as usize, b as usize);
            if body_body_intersect(&bodies[a], &poses[a], &bodies[b], &poses[b]) {
                report
                    .collisions
                    .push((bodies[a].name.clone(), Part::Link(bodies[b].name.clone())));
            }
        }
        Ok(report)
    }

    fn check_q(&self, q: &[f64]) -> Result<(), CollisionError> {
        let dof = self.model.chain().dof();
        if q.len() != dof {
            return Err(CollisionError::OutOfRange {
                field: "q.len".into(),
                value: q.len() as f64,
                lower: dof as f64,
                upper: dof as f64,
            });
        }
        match q.iter().position(|v| !v.is_finite()) {
            Some(i) => Err(CollisionError::NonFinite {
                field: format!("q[{i}]"),
            }),
            None => Ok(()),
        }
    }

    fn part(&self, other: Other) -> Part {
        match other {
            Other::Body(b) => Part::Link(self.model.bodies[b].name.clone()),
            Other::Obstacle(index) => Part::Obstacle {
                index,
                name: self.world.obstacle_name(index),
            },
        }
    }

    /// Smallest signed distance below `margin`: the witness, the robot body
    /// and the other part.
    fn nearest(&self, q: &[f64], margin: f64) -> Option<(Witness, usize, Other)> {
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        self.model.body_poses(q, &mut poses);
        self.nearest_posed(&poses, margin)
    }

    /// [`SceneChecker::nearest`] on bodies already posed.
    fn nearest_posed(
        &self,
        poses: &[Isometry3<f64>; MAX_BODIES],
        margin: f64,
    ) -> Option<(Witness, usize, Other)> {
        let bodies = &self.model.bodies;
        let mut best: Option<(Witness, usize, Other)> = None;
        let consider =
            |w: Option<Witness>, body: usize, other: Other, best: &mut Option<(Witness, usize, Other)>| {
                if let Some(w) = w
                    && best.as_ref().is_none_or(|(bw, _, _)| w.distance < bw.distance)
                {
                    *best = Some((w, body, other));
                }
            };
        for (b, body) in bodies.iter().enumerate() {
            let c = sphere_center(body, &poses[b]);
            // The search radius shrinks as closer pairs are found.
            let reach = best.as_ref().map_or(margin, |(w, _, _)| w.distance.min(margin));
            let query = Aabb::around_sphere(&c, body.radius + reach.max(0.0));
            self.world.bvh.for_each_overlap(&query, |leaf| {
                let l = &self.world.leaves[leaf as usize];
                let m = best.as_ref().map_or(margin, |(w, _, _)| w.distance.min(margin));
                let w = body_leaf_contact(body, &poses[b], &c, l, m);
                consider(w, b, Other::Obstacle(l.obstacle as usize), &mut best);
                true
            });
        }
        for &(a, b) in &self.self_pairs {
            let (a, b) = (a as usize, b as usize);
            let m = best.as_ref().map_or(margin, |(w, _, _)| w.distance.min(margin));
            let w = body_body_contact(&bodies[a], &poses[a], &bodies[b], &poses[b], m);
            consider(w, a, Other::Body(b), &mut best);
        }
        best
    }
}

/// The bodies a [`SceneChecker`] tests against the scene, distal first.
/// Left out are the bodies no state can bring to an obstacle:
///
/// * a body fixed to the base that is clear of every obstacle by both the
///   plain and the padded test (touching counts, as in the checks); one
///   that touches stays, so every state is found in collision;
/// * a moving body whose reach is clear of every obstacle's box: when the
///   first joint turns, every point of body `b` stays within its lever
///   `L_{0,b}` ([`SweepBound`]) of that joint's origin, whatever the
///   state, so a body whose sphere of that radius meets no box never
///   touches the scene (a shoulder link far from a shelf; padded checks
///   then accept at least what they accepted with it).
fn scene_bodies(model: &RobotModel, world: &SceneGeometry, sweep: Option<&SweepBound>) -> Vec<u16> {
    let chain = model.chain();
    let links = chain.links();
    let mut poses = [Isometry3::identity(); MAX_BODIES];
    let mut axes = vec![JointAxis::default(); chain.dof()];
    model.body_poses_and_axes(&vec![0.0; chain.dof()], &mut poses, &mut axes);
    // The first joint's origin, where every moving body's reach is centred
    // (no joint moves it), when that joint turns.
    let anchor = chain
        .joints()
        .first()
        .filter(|j| j.kind != JointKind::Prismatic)
        .and(axes.first().map(|a| a.point));
    (0..model.bodies.len())
        .rev()
        .filter(|&b| {
            let body = &model.bodies[b];
            if links[body.link].after_joint.is_some() {
                let reach = sweep.map(|s| s.lever(b, 0)).filter(|r| *r > 0.0);
                return match (anchor, reach) {
                    (Some(anchor), Some(reach)) => !world.bvh.for_each_near(&anchor, reach, |_| false),
                    _ => true,
                };
            }
            let c = sphere_center(body, &poses[b]);
            let clear = world
                .bvh
                .for_each_near(&c, body.radius + f64::MIN_POSITIVE, |leaf| {
                    let leaf = &world.leaves[leaf as usize];
                    !body_leaf_intersect(body, &poses[b], &c, leaf)
                        && !body_leaf_within(body, &poses[b], &c, leaf, f64::MIN_POSITIVE)
                });
            !clear
        })
        .map(|b| b as u16)
        .collect()
}

/// The bit of a padded check's `proved` parts that stands for every self
/// pair (the bits below [`MAX_BODIES`] are the bodies).
pub(crate) const SELF_PAIRS: u64 = 1 << 63;

/// Most self pairs [`SceneChecker::pairs_left`] sorts (the lanes name each
/// pair by a bit of a `u64`).
const KEPT: usize = 63;

/// The self pairs left for the lanes, and their indices among all.
struct Kept {
    pairs: [(u16, u16); KEPT],
    index: [u16; KEPT],
}

impl Default for Kept {
    fn default() -> Self {
        Kept {
            pairs: [(0, 0); KEPT],
            index: [0; KEPT],
        }
    }
}

/// What [`SceneChecker::hits_padded`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PadHit {
    /// Nothing within the pads.
    Clear,
    /// A pair within its pads, and none found touching without them.
    Near,
    /// A pair within its pads that also touches without them.
    Touches,
}

#[derive(Debug, Clone, Copy)]
enum Other {
    Body(usize),
    Obstacle(usize),
}

impl StateChecker for SceneChecker {
    fn dof(&self) -> usize {
        self.model.chain().dof()
    }

    fn is_valid(&self, q: &[f64]) -> bool {
        self.within_limits(q) && !self.in_collision(q)
    }

    /// Batches of [`WIDTH`] states through the sphere model in `f32` lanes,
    /// the unsure ones checked exactly (`SceneChecker::states_valid_in_lanes`).
    fn states_valid(&self, rows: &[f64]) -> bool {
        match self.states_valid_in_lanes(rows, false) {
            Some(valid) => valid,
            None => {
                let dof = self.model.chain().dof();
                dof > 0 && rows.chunks_exact(dof).all(|q| self.is_valid(q))
            }
        }
    }

    /// Signed clearance (m), capped at `max_distance`; `-inf` for a `q` of
    /// the wrong length or with non-finite values.
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
        if self.check_q(q).is_err() || max_distance.is_nan() {
            return f64::NEG_INFINITY;
        }
        self.nearest(q, max_distance)
            .map_or(max_distance, |(w, _, _)| w.distance.min(max_distance))
    }

    /// One pose of the robot for both answers.
    fn valid_and_clearance(&self, q: &[f64], max_distance: f64) -> (bool, f64) {
        if self.check_q(q).is_err() || max_distance.is_nan() {
            return (false, f64::NEG_INFINITY);
        }
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        self.model.body_poses(q, &mut poses);
        let valid = self.within_limits(q) && !self.hits(q, &poses);
        let clearance = self
            .nearest_posed(&poses, max_distance)
            .map_or(max_distance, |(w, _, _)| w.distance.min(max_distance));
        (valid, clearance)
    }

    /// Within the limits and, every body padded by its [`SweepBound`] over
    /// `half_step`, free of collisions; `None` without a finite bound.
    fn padded_valid(&self, q: &[f64], half_step: &[f64]) -> Option<bool> {
        Some(self.padded_verdict(q, half_step)? == PadVerdict::Free)
    }

    /// One pose of the robot answers both questions: the padded check with
    /// the tight pads along the piece (`SweepBound::pad_along`) asked only for bodies that
    /// have something within their global pads ([`SweepBound::pads`]); when
    /// it fails, only the pairs it met are tested without pads (see
    /// `SceneChecker::hits_padded`; a full plain check here only adds work,
    /// since the proofs' states are rarely in collision).
    fn padded_verdict(&self, q: &[f64], half_step: &[f64]) -> Option<PadVerdict> {
        self.padded_verdict_sparing(q, half_step, &mut 0)
    }

    /// [`StateChecker::padded_verdict`] with the parts of
    /// `SceneChecker::hits_padded`: bit `b` the scene around body `b`,
    /// `SELF_PAIRS` (bit 63) all self pairs.
    fn padded_verdict_sparing(&self, q: &[f64], half_step: &[f64], proved: &mut u64) -> Option<PadVerdict> {
        if self.model.body_count() <= SMALL_MODEL {
            self.padded_verdict_in::<SMALL_MODEL>(q, half_step, proved)
        } else {
            self.padded_verdict_in::<MAX_BODIES>(q, half_step, proved)
        }
    }

    /// Batches of [`WIDTH`] midpoints through the sphere model in `f32`
    /// lanes, every sphere grown by how far the body points inside it can
    /// move along its piece (`Lanes8::unsure_padded`): a piece whose grown
    /// spheres are clear is free at every state. Pieces whose midpoint is
    /// outside the limits are left out.
    fn padded_free_batch(&self, rows: &[f64], half_step: &[f64], cleared: &mut [u64]) -> Option<u32> {
        let (lanes, sweep) = (self.lanes8.as_ref()?, self.sweep.as_ref()?);
        let dof = lanes.dof();
        if dof == 0
            || half_step.len() != dof
            || !rows.len().is_multiple_of(dof)
            || rows.len() / dof > 32
            || cleared.len() < rows.len() / dof
        {
            return None;
        }
        // the pairs the tables prove apart over every piece stay out of the
        // lanes: a lane clearing the others proves all self pairs
        let mut kept = Kept::default();
        let n_kept = self.pairs_left(rows, dof, half_step, &mut kept);
        let pairs = n_kept.map_or(&self.self_pairs[..], |n| &kept.pairs[..n]);
        let terms = lanes.pad_terms(sweep, half_step, &self.scene_bodies, pairs)?;
        let mut free = 0u32;
        for (k, batch) in rows.chunks(WIDTH * dof).enumerate() {
            let n = batch.len() / dof;
            let mut q = [[0.0f32; WIDTH]; MAX_DOF8];
            let mut inside = 0u32;
            for (l, row) in batch.chunks_exact(dof).enumerate() {
                // the limits also keep every value within what the lanes
                // take; a lane outside them stays at zero, left out
                if self.within_limits(row) {
                    inside |= 1 << l;
                    for (j, &v) in row.iter().enumerate() {
                        q[j][l] = v as f32;
                    }
                }
            }
            let mut parts = [0u64; WIDTH];
            let unsure = lanes.unsure_padded(&q[..dof], &terms, &mut parts, false);
            free |= (!unsure & inside & ((1 << n) - 1)) << (k * WIDTH);
            for (l, c) in cleared[k * WIDTH..k * WIDTH + n].iter_mut().enumerate() {
                *c = if inside & (1 << l) != 0 { parts[l] } else { 0 };
            }
        }
        Some(free)
    }

    fn motion_check(&self) -> MotionCheck {
        let resolution = self.params.motion_resolution;
        match self.params.padded_motion {
            false => MotionCheck::Interpolated { resolution },
            true => MotionCheck::Padded { resolution },
        }
    }
}

impl SceneChecker {
    /// [`StateChecker::padded_verdict_sparing`] with poses and pads in
    /// buffers of `N` ≥ the body count.
    fn padded_verdict_in<const N: usize>(
        &self,
        q: &[f64],
        half_step: &[f64],
        proved: &mut u64,
    ) -> Option<PadVerdict> {
        let sweep = self.sweep.as_ref()?;
        if !self.within_limits(q) || half_step.len() != q.len() {
            return Some(PadVerdict::Collides);
        }
        let mut poses = [Isometry3::identity(); N];
        // Axes on the stack, sized for the usual arm: a 96-joint buffer would
        // be zeroed on every check for chains that are almost always ≤ 16.
        let (mut small, mut large);
        let axes: &mut [JointAxis] = if q.len() <= SMALL_CHAIN {
            small = [JointAxis::default(); SMALL_CHAIN];
            &mut small[..q.len()]
        } else {
            large = [JointAxis::default(); MAX_LINKS];
            large.get_mut(..q.len())?
        };
        self.model.body_poses_and_axes(q, &mut poses, axes);
        let mut coarse = [0.0; N];
        sweep.pads(half_step, &mut coarse);
        // the piece's prefix sums, once, when a first body needs its tight pad
        let mut sums = None;
        let tight = |b: usize| {
            let pad = match sums.get_or_insert_with(|| sweep.piece_sums(axes, half_step)) {
                Some(sums) => sweep.pad_along_with(&self.model, b, &poses[b], axes, half_step, sums),
                None => sweep.pad_along(&self.model, b, &poses[b], axes, half_step),
            };
            pad.min(coarse[b])
        };
        Some(
            match self.hits_padded(&poses, &coarse, tight, Some((q, half_step)), proved) {
                PadHit::Clear => PadVerdict::Free,
                PadHit::Touches => PadVerdict::Collides,
                PadHit::Near => PadVerdict::Unproved,
            },
        )
    }
}
