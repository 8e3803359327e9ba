//! The navigator's modal state and its token bounds: what a vector-distance step needs from
//! the past, carried between stateless calls by the domain's one token codec
//! ([`encode_token`] / [`decode_token`]).

use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

use super::{NavMode, TurnSide};
use crate::mobile::error::MobileError;
use crate::mobile::pose::{MAX_COORDINATE, MAX_RATE, Point2};
use crate::mobile::token::{ControllerMemory, decode_token, encode_token};

/// The navigator's modal state: everything a step needs from the past.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VdfState {
    /// Current mode.
    pub mode: NavMode,
    /// Current turning side.
    pub side: TurnSide,
    /// World direction of w'_0 locked in L mode, rad.
    pub locked_direction: f64,
    /// Hit point H of the current T episode.
    pub hit_point: Option<Point2>,
    /// |HG| when H was set, m.
    pub hit_distance: f64,
    /// The robot has moved away from H since the hit.
    pub left_hit_zone: bool,
    /// A turning side has been chosen before (it is kept through short R episodes).
    pub side_chosen: bool,
    /// Steps spent in the current mode (saturates at [`MAX_TOKEN_STEPS`]).
    pub steps_in_mode: u64,
    /// Distances to the goal over the last n + 1 steps (L mode), m.
    pub history: VecDeque<f64>,
    /// Best distance to the goal in the current T episode, m.
    pub best_distance: Option<f64>,
    /// Steps since `best_distance` last improved by c2 (saturates at [`MAX_TOKEN_STEPS`]).
    pub steps_since_progress: u64,
    /// The other turning side has been tried for the current H ([`VdfParams::retry_other_side`](super::VdfParams::retry_other_side)).
    #[serde(default)]
    pub side_retried: bool,
}

const MAX_TOKEN_HISTORY: usize = 100_000;
/// Largest step counter a token may carry: counters saturate here, and a forged
/// `u64::MAX` is refused rather than trusted.
pub const MAX_TOKEN_STEPS: u64 = 1 << 40;

impl ControllerMemory for VdfState {
    type Context = ();

    /// Finite angles within ±[`MAX_RATE`]; distances finite, non-negative and within a world
    /// of coordinates within ±[`MAX_COORDINATE`]; the hit point inside that world; at most
    /// 100,000 history entries; counters at most [`MAX_TOKEN_STEPS`].
    fn check(&self, _: &()) -> Result<(), &'static str> {
        let max_distance = 4.0 * MAX_COORDINATE;
        let distance_ok = |d: f64| (0.0..=max_distance).contains(&d);
        let coordinate_ok = |c: f64| c.abs() <= MAX_COORDINATE;
        if !(self.locked_direction.is_finite() && self.locked_direction.abs() <= MAX_RATE) {
            return Err("locked direction not finite or out of range");
        }
        if !distance_ok(self.hit_distance) {
            return Err("hit distance not finite, negative or out of range");
        }
        if self
            .hit_point
            .is_some_and(|h| !(coordinate_ok(h.x) && coordinate_ok(h.y)))
        {
            return Err("hit point not finite or out of the world");
        }
        if self.history.len() > MAX_TOKEN_HISTORY || !self.history.iter().all(|d| distance_ok(*d)) {
            return Err("history too long, or a distance not finite, negative or out of range");
        }
        if self.best_distance.is_some_and(|d| !distance_ok(d)) {
            return Err("best distance not finite, negative or out of range");
        }
        if self.steps_in_mode > MAX_TOKEN_STEPS || self.steps_since_progress > MAX_TOKEN_STEPS {
            return Err("step counter out of range");
        }
        Ok(())
    }
}

impl VdfState {
    /// Serialises to an opaque token ([`encode_token`]). Fails (never an empty token) if the
    /// state holds a value a token cannot carry.
    pub fn to_token(&self) -> Result<Vec<u8>, MobileError> {
        encode_token(self, &())
    }

    /// Decodes and checks a token produced by [`VdfState::to_token`] ([`decode_token`]): every
    /// field within its bounds ([`ControllerMemory::check`]); empty → a fresh state.
    pub fn from_token(token: &[u8]) -> Result<Self, MobileError> {
        decode_token(token, &())
    }
}
