//! The one codec of controller memories: what a stateless controller step needs from the past
//! travels to the caller and back as an opaque token (JSON bytes; an empty token is a fresh
//! controller). A token comes from the caller, so decoding checks every field against its
//! bounds; encoding checks the same bounds and fails rather than hand out an empty token
//! (which the caller would take for a fresh start).

use serde::Serialize;
use serde::de::DeserializeOwned;

use super::error::MobileError;

/// Longest reason echoed from a token parser, characters.
const MAX_REASON_CHARS: usize = 128;

/// A controller state that can travel as a token.
pub trait ControllerMemory: Serialize + DeserializeOwned + Default {
    /// What the bounds of a state depend on besides the state itself (e.g. the path's length).
    type Context: ?Sized;

    /// Every field within its bounds; otherwise why not.
    fn check(&self, context: &Self::Context) -> Result<(), &'static str>;
}

/// Encodes `memory` as an opaque token. Fails with [`MobileError::TokenEncoding`] (a bug, not
/// bad input) if the state holds a value a token may not carry; never returns an empty token.
pub fn encode_token<M: ControllerMemory>(memory: &M, context: &M::Context) -> Result<Vec<u8>, MobileError> {
    let refuse = |reason: String| MobileError::TokenEncoding { reason };
    memory.check(context).map_err(|r| refuse(r.to_owned()))?;
    serde_json::to_vec(memory).map_err(|e| refuse(e.to_string()))
}

/// Decodes a token produced by [`encode_token`]: empty → the default (fresh) state; otherwise
/// it must parse and pass [`ControllerMemory::check`], else [`MobileError::BadToken`].
pub fn decode_token<M: ControllerMemory>(token: &[u8], context: &M::Context) -> Result<M, MobileError> {
    if token.is_empty() {
        return Ok(M::default());
    }
    let memory: M = serde_json::from_slice(token).map_err(|e| MobileError::BadToken {
        reason: e.to_string().chars().take(MAX_REASON_CHARS).collect(),
    })?;
    memory
        .check(context)
        .map_err(|r| MobileError::BadToken { reason: r.to_owned() })?;
    Ok(memory)
}

/// Adds one to a step counter a token carries, saturating at `max` (so a state that was
/// accepted stays encodable).
pub(crate) fn bump(counter: u64, max: u64) -> u64 {
    counter.saturating_add(1).min(max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::PathFollowState;

    #[test]
    fn path_follow_tokens_round_trip_and_are_checked_against_the_path() {
        let s = PathFollowState {
            target: 2,
            segment: 1,
        };
        let token = encode_token(&s, &3).unwrap();
        assert!(!token.is_empty());
        assert_eq!(decode_token::<PathFollowState>(&token, &3).unwrap(), s);
        // Node 2 does not exist on a two-node path.
        assert!(matches!(
            decode_token::<PathFollowState>(&token, &2),
            Err(MobileError::BadToken { .. })
        ));
        assert!(matches!(
            encode_token(&s, &2),
            Err(MobileError::TokenEncoding { .. })
        ));
        assert_eq!(
            decode_token::<PathFollowState>(b"", &1).unwrap(),
            PathFollowState::default()
        );
        assert!(matches!(
            decode_token::<PathFollowState>(br#"{"target": -1, "segment": 0}"#, &3),
            Err(MobileError::BadToken { .. })
        ));
    }

    #[test]
    fn counters_saturate_at_their_bound() {
        assert_eq!(bump(3, 10), 4);
        assert_eq!(bump(10, 10), 10);
        assert_eq!(bump(u64::MAX, 10), 10);
    }
}
