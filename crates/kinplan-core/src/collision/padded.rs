//! The conservative motion check, [`super::MotionCheck::Padded`].

use std::collections::VecDeque;

use super::{PadVerdict, StateChecker};
use crate::Deadline;

/// Most joints the check handles (stack buffers): as many as a chain with a
/// collision model can have.
const MAX_DOF: usize = super::MAX_LINKS;
/// A piece whose largest joint span is below this (rad or m) is not halved
/// further: the motion is refused (it grazes an obstacle, or touches it).
pub const MIN_PIECE: f64 = 1e-5;
/// Most padded states checked per initial piece before the motion is
/// refused: bounds the cost of a motion that runs along an obstacle.
pub const MAX_CHECKS_PER_PIECE: usize = 64;
/// Longest first piece, in resolutions: a piece is proved with pads that
/// grow with its length, so longer pieces are cheaper to prove than several
/// short ones while the halving refines them where obstacles are near;
/// shorter pieces are proved by the batch more often (the length tried
/// against others on the MotionBenchMaker problems: `benches/RESULTS.md`).
const FIRST_PIECE: f64 = 2.0;
/// Pieces proved together, breadth first (bounds the queue at
/// `WINDOW · (MAX_CHECKS_PER_PIECE + 1)` entries whatever the motion's length).
const WINDOW: usize = 64;
/// Pieces offered to [`StateChecker::padded_free_batch`] at once (the
/// batched check's lanes).
const BATCH: usize = 8;

/// True when no state of the straight motion `a → b` collides (the motion
/// check of docs/planning.md#collision-cost-and-motion-checks, made conservative), proved piece
/// by piece (conservative advancement over joint space, Schwarzer, Saha and
/// Latombe's idea with the distance test replaced by a padded overlap test):
///
/// the motion is cut into `2^k ≥ span/(2·resolution)` equal pieces; a piece
/// `[s, t]` with midpoint `m` and signed half vector `h = (b − a)·(t − s)/2`
/// is accepted when the robot at `q(m)` is within its limits and free with
/// every body padded by its sweep bound `δ_b(h)` along the piece
/// (`SweepBound::pad_along`) — every state of the piece is
/// `q(m) + σh` with `|σ| ≤ 1`, so no point of body `b` is farther than
/// `δ_b(h)` from where it is at `q(m)`. A piece that fails is refused if `q(m)`
/// is found to collide ([`PadVerdict::Collides`]), else halved; the halves
/// skip the robot parts the check proved free over the whole piece
/// ([`StateChecker::padded_verdict_sparing`]: a body clear of the scene
/// over a piece is clear over its halves). Pieces below [`MIN_PIECE`] or more than
/// [`MAX_CHECKS_PER_PIECE`] checks per initial piece refuse the motion.
/// Pieces are visited breadth first (all midpoints before any half), in
/// windows of 64 pieces in bisection order. A checker with a batched proof
/// ([`StateChecker::padded_free_batch`]) is offered a window's first pieces
/// eight at a time; those it leaves are checked one by one right after
/// their batch, sparing what it cleared.
///
/// The ends are not checked here (a straight motion between two states
/// within the limits stays within them). `None` when `deadline` expires
/// (asked every 32 checks); `Some(false)` when the checker cannot
/// pad or the chain has more than `MAX_LINKS` joints.
pub fn padded_motion_valid<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    deadline: Deadline<'_>,
) -> Option<bool> {
    match padded_motion(checker, a, b, resolution, deadline) {
        PaddedMotion::Free => Some(true),
        PaddedMotion::Refused { .. } => Some(false),
        PaddedMotion::Interrupted => None,
    }
}

/// What [`padded_motion`] found about a straight motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PaddedMotion {
    /// Proved free.
    Free,
    /// Refused; `at` (in [0, 1], from `a` to `b`) is the midpoint of the
    /// piece that refused it: a state found in collision, or a piece that
    /// could not be proved within the limits of the check (0.5 for a
    /// malformed motion).
    Refused { at: f64 },
    /// The deadline expired.
    Interrupted,
}

/// [`padded_motion_valid`], saying where a refused motion was refused.
pub fn padded_motion<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    deadline: Deadline<'_>,
) -> PaddedMotion {
    let refused = |at: f64| PaddedMotion::Refused { at };
    let n = a.len();
    if n != b.len() || n > MAX_DOF || resolution.is_nan() || resolution <= 0.0 {
        return refused(0.5);
    }
    let mut delta = [0.0; MAX_DOF];
    for (d, (x, y)) in delta.iter_mut().zip(a.iter().zip(b)) {
        *d = y - x;
    }
    let delta = &delta[..n];
    let span = delta.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    if !span.is_finite() {
        return refused(0.5);
    }
    let pieces = (span / (FIRST_PIECE * resolution)).ceil().max(1.0);
    if pieces > 1e7 {
        return refused(0.5);
    }
    let pieces = (pieces as usize).next_power_of_two();
    let (mut q, mut half) = ([0.0; MAX_DOF], [0.0; MAX_DOF]);
    let mut checks = 0usize;
    // Pieces in bisection order (the middle one first), a window of them at
    // a time, breadth first: every piece's midpoint is checked before any
    // piece is halved, so a motion through an obstacle is refused at the
    // first midpoint inside it rather than after halving a grazing piece to
    // its limit. Entries: (s, t, piece in the window).
    let mut order = bisection_order(pieces).peekable();
    let mut queue = VecDeque::new();
    let mut spent = [0usize; WINDOW];
    let first_half: Vec<f64> = delta.iter().map(|d| 0.5 * d / pieces as f64).collect();
    let mut rows = vec![0.0; BATCH * n];
    // One piece's padded check: `Err` ends the motion, else the halves of
    // an unproved piece join the queue.
    let mut check = |(s, t, slot, mut proved): (f64, f64, usize, u64),
                     queue: &mut VecDeque<(f64, f64, usize, u64)>,
                     spent: &mut [usize; WINDOW],
                     checks: &mut usize|
     -> Result<(), PaddedMotion> {
        *checks += 1;
        let m = 0.5 * (s + t);
        if checks.is_multiple_of(32) && deadline.expired() {
            return Err(PaddedMotion::Interrupted);
        }
        if spent[slot] == MAX_CHECKS_PER_PIECE {
            return Err(refused(m));
        }
        spent[slot] += 1;
        for j in 0..n {
            q[j] = a[j] + m * delta[j];
            half[j] = 0.5 * (t - s) * delta[j];
        }
        match checker.padded_verdict_sparing(&q[..n], &half[..n], &mut proved) {
            None | Some(PadVerdict::Collides) => Err(refused(m)),
            Some(PadVerdict::Free) => Ok(()),
            Some(PadVerdict::Unproved) if (t - s) * span < MIN_PIECE => Err(refused(m)),
            Some(PadVerdict::Unproved) => {
                queue.extend([(s, m, slot, proved), (m, t, slot, proved)]);
                Ok(())
            }
        }
    };
    let piece = |i: usize| (i as f64 / pieces as f64, (i + 1) as f64 / pieces as f64);
    while order.peek().is_some() {
        spent.fill(0);
        let window: Vec<usize> = order.by_ref().take(WINDOW).collect();
        // the window's pieces offered to the batched proof a batch at a
        // time; those it leaves are checked one by one at once (a motion
        // through an obstacle is refused at its first batch), and their
        // halves wait for the whole window
        let mut batched = true;
        for (k, batch) in window.chunks(BATCH).enumerate() {
            let (mut free, mut cleared) = (0u32, [0u64; BATCH]);
            if batched {
                // a batch counts as a check per piece against the deadline
                let asked = checks / 32;
                checks += batch.len();
                if checks / 32 != asked && deadline.expired() {
                    return PaddedMotion::Interrupted;
                }
                for (row, &i) in rows.chunks_exact_mut(n).zip(batch) {
                    let m = (i as f64 + 0.5) / pieces as f64;
                    for ((v, x), d) in row.iter_mut().zip(a).zip(delta) {
                        *v = x + m * d;
                    }
                }
                let parts = &mut cleared[..batch.len()];
                match checker.padded_free_batch(&rows[..batch.len() * n], &first_half, parts) {
                    Some(proved) => free = proved,
                    None => batched = false,
                }
            }
            for (l, &i) in batch.iter().enumerate() {
                if free & (1 << l) == 0 {
                    let (s, t) = piece(i);
                    let entry = (s, t, k * BATCH + l, cleared[l]);
                    if let Err(end) = check(entry, &mut queue, &mut spent, &mut checks) {
                        return end;
                    }
                }
            }
        }
        while let Some(entry) = queue.pop_front() {
            if let Err(end) = check(entry, &mut queue, &mut spent, &mut checks) {
                return end;
            }
        }
    }
    PaddedMotion::Free
}

/// `0..count` (a power of two) in bisection order: 0, then the odd
/// multiples of count/2, of count/4, … (8: 0, 4, 2, 6, 1, 3, 5, 7).
pub(crate) fn bisection_order(count: usize) -> impl Iterator<Item = usize> {
    let strides = std::iter::successors(Some(count), |s| (*s > 1).then_some(s / 2)).take_while(|s| *s > 1);
    std::iter::once(0).chain(strides.flat_map(move |stride| (stride / 2..count).step_by(stride)))
}

#[cfg(test)]
mod tests {
    use super::bisection_order;

    #[test]
    fn bisection_order_visits_every_piece_once() {
        for count in [1usize, 2, 4, 8, 64] {
            let mut seen: Vec<usize> = bisection_order(count).collect();
            assert_eq!(seen.len(), count, "{count}: {seen:?}");
            seen.sort_unstable();
            assert_eq!(seen, (0..count).collect::<Vec<_>>());
        }
        assert_eq!(bisection_order(8).collect::<Vec<_>>(), [0, 4, 2, 6, 1, 3, 5, 7]);
    }
}
