//! The allowed-collision matrix: body pairs the checker never tests.
//!
//! Built as MoveIt's setup assistant does, once per robot model, with one
//! rule left out:
//! 1. **adjacent** pairs (parent and child in the kinematic tree, links
//!    without geometry skipped) are always allowed;
//! 2. **always**: pairs in collision in at least `always_fraction` of
//!    `samples` uniformly random states;
//! 3. **never**: pairs in collision in none of the samples.
//!
//! Before sampling, a pair whose relative pose one or two joints change is
//! allowed as **proved** when its table (`pair_table`) proves it apart in
//! every cell of those joints' ranges, whatever the other joints, and so is
//! a pair whose relative pose no joint changes (a finger held beside the
//! hand) when one exact test finds it apart; such a pair is apart in every
//! state, not only in the samples (and one that test finds in collision is
//! in collision in every sample: "always"). In the other tables a proved
//! cell answers a sample without the exact test. The pairs left to the
//! "never" rule are those three or more joints move relative to each other.
//! A pair already seen both in and out of collision often enough that it can
//! be neither "never" nor "always" is not tested in the later samples.
//!
//! Steps 2–3 are a sampling heuristic: a pair that collides in fewer than
//! about 1/`samples` of the joint space is allowed as "never" (MoveIt's
//! default density of 10 000 samples has the same blind spot). The result
//! depends only on the model and the parameters (seeded ChaCha8).
//!
//! The setup assistant also allows every pair in collision at the default
//! state. Not here: collision shapes that hold the real parts (covers,
//! convex hulls) are larger than them, so a pair can touch at the default
//! state in the model while the real links are apart and collide elsewhere
//! in the joint space — allowing it would call real collisions free.
//! Designed contacts come from the robot's MoveIt configuration instead: an
//! SRDF's `disable_collisions` pairs ([`AllowedCollisions::allow_named`]),
//! which the built-in Panda carries (`robot::builtin_srdf`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::CollisionError;
use super::model::{MAX_BODIES, RobotModel};
use super::narrow::{body_body_intersect, body_body_within};
use super::pair_table::PairTable;
use super::sweep::SweepBound;
use crate::{Deadline, Stop};
use nalgebra::Isometry3;

/// Why a pair of bodies is not checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AllowReason {
    Adjacent,
    Always,
    Never,
    /// Proved apart in every state within the joint limits: the pair's
    /// table (`pair_table`) proves every cell free, or no joint moves one
    /// body relative to the other and they are apart.
    Proved,
    /// Allowed by the caller (an SRDF's `disable_collisions`, a built-in's).
    User,
}

/// Symmetric matrix over a model's bodies (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct AllowedCollisions {
    n: usize,
    reasons: Vec<Option<AllowReason>>,
}

/// Parameters of the sampling step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcmParams {
    /// Random states sampled (MoveIt setup assistant default: 10 000).
    pub samples: usize,
    /// Fraction of samples in collision from which a pair counts as
    /// always colliding, in (0, 1] (setup assistant default: 0.95).
    pub always_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Default for AcmParams {
    fn default() -> Self {
        AcmParams {
            samples: 10_000,
            always_fraction: 0.95,
            seed: 0,
        }
    }
}

/// Most body-pair tests one sampled matrix may cost (samples × pairs). The
/// sampling does not look at a deadline, so a caller that builds matrices
/// for models it did not choose (the server, for any URDF a client sends)
/// bounds the cost with [`AcmParams::samples_within`]: a 7-body arm keeps
/// 10,000 samples (210,000 tests); a 96-body URDF gets 438 samples instead
/// of 45.6 million tests.
pub const MAX_ACM_PAIR_TESTS: usize = 2_000_000;

impl AcmParams {
    /// `wanted` samples for a model of `bodies` bodies, capped so that
    /// samples × body pairs stays within [`MAX_ACM_PAIR_TESTS`] (at least one
    /// sample).
    ///
    /// ```
    /// use kinplan_core::collision::{AcmParams, MAX_ACM_PAIR_TESTS};
    /// assert_eq!(AcmParams::samples_within(7, 10_000), 10_000); // 21 pairs
    /// assert_eq!(AcmParams::samples_within(96, 10_000), 438); // 4,560 pairs
    /// assert!(438 * 4_560 <= MAX_ACM_PAIR_TESTS);
    /// assert_eq!(AcmParams::samples_within(0, 10_000), 10_000);
    /// assert_eq!(AcmParams::samples_within(100_000, 10_000), 1);
    /// ```
    pub fn samples_within(bodies: usize, wanted: usize) -> usize {
        let pairs = (bodies * bodies.saturating_sub(1) / 2).max(1);
        wanted.min(MAX_ACM_PAIR_TESTS / pairs).max(1)
    }

    pub fn validate(&self) -> Result<(), CollisionError> {
        if self.samples == 0 || self.samples > 10_000_000 {
            return Err(CollisionError::OutOfRange {
                field: "acm.samples".into(),
                value: self.samples as f64,
                lower: 1.0,
                upper: 1e7,
            });
        }
        if !(self.always_fraction > 0.0 && self.always_fraction <= 1.0) {
            return Err(CollisionError::OutOfRange {
                field: "acm.always_fraction".into(),
                value: self.always_fraction,
                lower: 0.0,
                upper: 1.0,
            });
        }
        Ok(())
    }
}

impl AllowedCollisions {
    /// Only adjacent pairs allowed.
    pub fn adjacent(model: &RobotModel) -> Self {
        let n = model.body_count();
        let mut acm = AllowedCollisions {
            n,
            reasons: vec![None; n * n],
        };
        for a in 0..n {
            for b in a + 1..n {
                if model.adjacent(a, b) {
                    acm.allow(a, b, AllowReason::Adjacent);
                }
            }
        }
        acm
    }

    /// Adjacent pairs plus the default, always and never pairs found by
    /// sampling (see the module doc). Samples are checked on the rayon pool.
    pub fn sampled(model: &RobotModel, params: &AcmParams) -> Result<Self, CollisionError> {
        Self::sampled_until(model, params, Deadline::none())
    }

    /// [`Self::sampled`], stopping with [`CollisionError::Stopped`] once
    /// `deadline` says so (polled before every sample, and while the model's
    /// pair tables are built, which the sampling uses).
    pub fn sampled_until(
        model: &RobotModel,
        params: &AcmParams,
        deadline: Deadline<'_>,
    ) -> Result<Self, CollisionError> {
        params.validate()?;
        let mut acm = Self::adjacent(model);
        let chain = model.chain();
        let bounds: Vec<(f64, f64)> = chain
            .limits()
            .map(|(lo, hi)| {
                if lo.is_finite() && hi.is_finite() {
                    (lo, hi)
                } else {
                    (-std::f64::consts::PI, std::f64::consts::PI)
                }
            })
            .collect();
        // A pair whose table proves every cell free is apart everywhere; in
        // the other tables a proved cell spares the exact test. A pair that
        // no joint moves relative to each other (the same last joint) keeps
        // one relative pose, so one test decides it for every state.
        let sweep = SweepBound::new(model);
        let rigid = |a: usize, b: usize| sweep.as_ref().is_some_and(|s| s.last(a) == s.last(b));
        let mut poses = [Isometry3::identity(); MAX_BODIES];
        model.body_poses(&chain.mid_limits(), &mut poses);
        let apart_here = |a: usize, b: usize| {
            !body_body_within(
                &model.bodies[a],
                &poses[a],
                &model.bodies[b],
                &poses[b],
                f64::MIN_POSITIVE,
            )
        };
        let tables = model
            .pair_tables_until(deadline)
            .map_err(|stop| CollisionError::Stopped {
                what: "proving the robot's self pairs apart (pair tables)".into(),
                stop,
            })?;
        let touching_here = |a: usize, b: usize| {
            body_body_intersect(&model.bodies[a], &poses[a], &model.bodies[b], &poses[b])
        };
        let mut pairs: Vec<(usize, usize, Option<&PairTable>)> = Vec::new();
        for (a, b) in acm.checked_pairs().collect::<Vec<_>>() {
            match tables.iter().find(|t| (t.a, t.b) == (a, b)) {
                Some(table) if table.all_free() => acm.allow(a, b, AllowReason::Proved),
                None if rigid(a, b) && apart_here(a, b) => acm.allow(a, b, AllowReason::Proved),
                // in collision in this pose, so in every sample
                None if rigid(a, b) && touching_here(a, b) => acm.allow(a, b, AllowReason::Always),
                table => pairs.push((a, b, table)),
            }
        }
        // Random states, drawn sequentially so the set does not depend on
        // the thread count.
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
        let dof = bounds.len().max(1);
        let states: Vec<f64> = (0..params.samples * bounds.len())
            .map(|i| {
                let (lo, hi) = bounds[i % bounds.len()];
                rng.random_range(lo..=hi)
            })
            .collect();
        let always = (params.always_fraction * params.samples as f64).ceil() as u32;
        let counts =
            sample_counts(model, &pairs, &states, dof, params.samples, always, deadline).map_err(|stop| {
                CollisionError::Stopped {
                    what: "sampling the allowed-collision matrix".into(),
                    stop,
                }
            })?;
        for (k, &(a, b, _)) in pairs.iter().enumerate() {
            if counts[k] >= always {
                acm.allow(a, b, AllowReason::Always);
            } else if counts[k] == 0 {
                acm.allow(a, b, AllowReason::Never);
            }
        }
        Ok(acm)
    }

    /// Number of bodies.
    pub fn size(&self) -> usize {
        self.n
    }

    /// Why `a`–`b` is allowed, or `None` when the pair is checked.
    pub fn reason(&self, a: usize, b: usize) -> Option<AllowReason> {
        if a == b {
            return Some(AllowReason::Adjacent);
        }
        self.reasons.get(a * self.n + b).copied().flatten()
    }

    pub fn is_allowed(&self, a: usize, b: usize) -> bool {
        self.reason(a, b).is_some()
    }

    /// Marks `a`–`b` (both orders) allowed. Out-of-range indices are ignored.
    pub fn allow(&mut self, a: usize, b: usize, reason: AllowReason) {
        if a < self.n && b < self.n {
            self.reasons[a * self.n + b] = Some(reason);
            self.reasons[b * self.n + a] = Some(reason);
        }
    }

    /// The matrix of a built-in robot's model: [`Self::sampled`], and the
    /// designed contacts of its MoveIt configuration
    /// ([`crate::robot::builtin_srdf`]) allowed.
    pub fn builtin(model: &RobotModel, builtin: &str, params: &AcmParams) -> Result<Self, CollisionError> {
        let mut acm = Self::sampled(model, params)?;
        if let Some(srdf) = crate::robot::builtin_srdf_parsed(builtin) {
            acm.allow_named(
                model,
                srdf.disabled_collisions
                    .iter()
                    .map(|(a, b)| (a.as_str(), b.as_str())),
                AllowReason::User,
            );
        }
        Ok(acm)
    }

    /// Allows every pair of `pairs` named by body (an SRDF's
    /// `disable_collisions`), for `reason`; names the model does not hold
    /// are left out (an SRDF may name links beyond the modelled chain).
    pub fn allow_named<'a>(
        &mut self,
        model: &RobotModel,
        pairs: impl IntoIterator<Item = (&'a str, &'a str)>,
        reason: AllowReason,
    ) {
        let index: std::collections::HashMap<&str, usize> =
            model.body_names().enumerate().map(|(i, n)| (n, i)).collect();
        for (a, b) in pairs {
            if let (Some(&i), Some(&j)) = (index.get(a), index.get(b)) {
                self.allow(i, j, reason);
            }
        }
    }

    /// The pairs `a < b` the checker tests.
    pub fn checked_pairs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.n)
            .flat_map(move |a| (a + 1..self.n).map(move |b| (a, b)))
            .filter(|&(a, b)| !self.is_allowed(a, b))
    }
}

/// Samples tested at a time before the pairs already decided leave.
const SAMPLE_BLOCK: usize = 1_000;

/// For each of `pairs`, in how many of the `samples` states (`dof` values
/// each) its bodies are in collision (a proved cell of its table answers
/// "apart" without the exact test), as far as the verdict needs it.
///
/// The states go in blocks of [`SAMPLE_BLOCK`]. A pair seen in collision
/// that has also been apart in more than `samples − always` states can be
/// neither "never" (count 0) nor "always" (count ≥ `always`) any more, so
/// it leaves the later blocks: its count stays partial, and every verdict
/// is the one all the samples give.
fn sample_counts(
    model: &RobotModel,
    pairs: &[(usize, usize, Option<&PairTable>)],
    states: &[f64],
    dof: usize,
    samples: usize,
    always: u32,
    deadline: Deadline<'_>,
) -> Result<Vec<u32>, Stop> {
    let misses_to_decide = samples.saturating_sub(always as usize);
    let mut counts = vec![0u32; pairs.len()];
    let mut open: Vec<usize> = (0..pairs.len()).collect();
    let mut seen = 0;
    for block in states.chunks(dof * SAMPLE_BLOCK) {
        if open.is_empty() {
            break;
        }
        let hits = block
            .par_chunks(dof * 64)
            .map(|chunk| {
                let mut hits = vec![0u32; open.len()];
                let mut poses = [Isometry3::identity(); MAX_BODIES];
                for q in chunk.chunks(dof) {
                    if let Some(stop) = deadline.stop() {
                        return Err(stop);
                    }
                    model.body_poses(q, &mut poses);
                    for (hit, &k) in hits.iter_mut().zip(&open) {
                        let (a, b, table) = pairs[k];
                        *hit += (!table.is_some_and(|t| t.proves_apart(q, &[]))
                            && body_body_intersect(&model.bodies[a], &poses[a], &model.bodies[b], &poses[b]))
                            as u32;
                    }
                }
                Ok(hits)
            })
            .try_reduce(
                || vec![0u32; open.len()],
                |mut x, y| {
                    x.iter_mut().zip(y).for_each(|(a, b)| *a += b);
                    Ok(x)
                },
            )?;
        seen += block.len() / dof;
        for (&k, h) in open.iter().zip(hits) {
            counts[k] += h;
        }
        open.retain(|&k| counts[k] == 0 || seen - counts[k] as usize <= misses_to_decide);
    }
    Ok(counts)
}
