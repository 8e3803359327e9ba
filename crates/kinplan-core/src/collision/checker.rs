//! The joint-space queries a planner needs, independent of how the geometry
//! is checked: the robot-and-scene checker implements them with parry3d, and
//! tests implement them with closed-form toy worlds.

use super::padded::{bisection_order, padded_motion_valid};

/// Validity queries on joint states of one robot in one scene.
///
/// Joint values are radians (revolute) or metres (prismatic), one per joint
/// of the chain, in chain order. Implementations are shared between threads
/// (rollouts are evaluated in parallel), so queries take `&self` and must not
/// allocate per call.
pub trait StateChecker: Sync {
    /// Joints of the robot.
    fn dof(&self) -> usize;

    /// True when `q` lies within the joint limits and the robot is free of
    /// collisions with the scene and with itself (allowed pairs excepted).
    fn is_valid(&self, q: &[f64]) -> bool;

    /// Signed clearance at `q` (m): the smallest distance between a robot
    /// shape and an obstacle or a non-allowed robot shape, negative by the
    /// penetration depth when they overlap. Distances above `max_distance`
    /// may be reported as `max_distance` (the search stops there).
    fn clearance(&self, q: &[f64], max_distance: f64) -> f64;

    /// [`StateChecker::is_valid`] and [`StateChecker::clearance`] of one
    /// state together; implementations may answer both from one pose of the
    /// robot (the default asks each).
    fn valid_and_clearance(&self, q: &[f64], max_distance: f64) -> (bool, f64) {
        (self.is_valid(q), self.clearance(q, max_distance))
    }

    /// True when every state of `rows` (row-major, [`StateChecker::dof`]
    /// values per row; a trailing partial row is ignored) is valid, as
    /// [`StateChecker::is_valid`] says. Implementations may check several
    /// rows at once, so which invalid row is found first is not specified;
    /// the default asks `is_valid` row by row.
    fn states_valid(&self, rows: &[f64]) -> bool {
        match self.dof() {
            0 => rows.is_empty() || self.is_valid(&[]),
            dof => rows.chunks_exact(dof).all(|q| self.is_valid(q)),
        }
    }

    /// True when the straight joint-space motion from `a` to `b` is valid,
    /// as [`MotionCheck`] describes how it was checked.
    fn motion_valid(&self, a: &[f64], b: &[f64]) -> bool {
        interpolate_motion_valid(self, a, b, self.motion_check())
    }

    /// True when `q` is within the limits and every state `q + s·half_step`,
    /// `s ∈ [−1, 1]`, is free of collisions (the piece of a straight motion
    /// around `q`, `half_step` its signed half vector; the robot's bodies
    /// padded by how far they can move along it); `None` when this checker
    /// cannot bound its bodies' motion (the default).
    fn padded_valid(&self, q: &[f64], half_step: &[f64]) -> Option<bool> {
        let _ = (q, half_step);
        None
    }

    /// [`StateChecker::padded_valid`], and when the padded check fails,
    /// whether `q` itself is found invalid ([`PadVerdict::Collides`]) or
    /// only not proved free with the pads ([`PadVerdict::Unproved`]);
    /// `None` as `padded_valid`. Implementations may answer both from one
    /// pose of the robot, and may test only the pair that failed with pads
    /// (so `Unproved` does not promise a valid `q`); the default asks
    /// [`StateChecker::is_valid`] after a failure.
    fn padded_verdict(&self, q: &[f64], half_step: &[f64]) -> Option<PadVerdict> {
        Some(match self.padded_valid(q, half_step)? {
            true => PadVerdict::Free,
            false if self.is_valid(q) => PadVerdict::Unproved,
            false => PadVerdict::Collides,
        })
    }

    /// [`StateChecker::padded_verdict`] for a piece some of whose robot
    /// parts are already proved free over it: bit `i` of `proved` set means
    /// part `i` (numbered by the checker, at most 64) need not be checked.
    /// Parts the check proves free over this piece are added to `proved`,
    /// so the halves of a piece that fails check only what is left. The
    /// default ignores `proved` and proves nothing part by part.
    fn padded_verdict_sparing(&self, q: &[f64], half_step: &[f64], proved: &mut u64) -> Option<PadVerdict> {
        let _ = proved;
        self.padded_verdict(q, half_step)
    }

    /// Of the pieces of a straight motion with midpoints `rows` (row-major,
    /// [`StateChecker::dof`] values per row, at most 32 rows) and the common
    /// signed half vector `half_step`, those proved free at once as
    /// [`StateChecker::padded_valid`] would (bit `i` for row `i`); a piece
    /// left out is not proved either way and goes to the one-piece check,
    /// which may spare what `cleared[i]` says was proved clear over piece
    /// `i` (as [`StateChecker::padded_verdict_sparing`]'s `proved`; 0 when
    /// nothing). `None` when the checker has no such batched proof (the
    /// default).
    fn padded_free_batch(&self, rows: &[f64], half_step: &[f64], cleared: &mut [u64]) -> Option<u32> {
        let _ = (rows, half_step, cleared);
        None
    }

    /// How [`StateChecker::motion_valid`] checks a motion. Default: states
    /// interpolated at most 0.05 rad (or m) apart on every joint.
    fn motion_check(&self) -> MotionCheck {
        MotionCheck::Interpolated { resolution: 0.05 }
    }
}

/// What a padded check found about a state and its neighbourhood.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PadVerdict {
    /// Every state within the half step is free.
    Free,
    /// The state itself collides or lies outside the limits.
    Collides,
    /// A padded body touches something; the state itself was not found to
    /// collide (the checker may have tested only the pair that failed).
    Unproved,
}

/// How a motion between two states is checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionCheck {
    /// States along the segment, consecutive ones at most `resolution` apart
    /// on every joint (rad or m, > 0), both ends included. Not conservative:
    /// an obstacle thinner than the swept distance of one step can be missed.
    Interpolated { resolution: f64 },
    /// Conservative: pieces of at most `resolution` per joint, each accepted
    /// when its midpoint is free with every robot body padded by the
    /// farthest any of its points can move within the piece
    /// ([`super::SweepBound`]), else halved (see [`padded_motion_valid`]). An
    /// accepted motion collides nowhere.
    Padded { resolution: f64 },
}

impl MotionCheck {
    /// The largest joint step between checked states (rad or m).
    pub fn resolution(self) -> f64 {
        match self {
            MotionCheck::Interpolated { resolution } | MotionCheck::Padded { resolution } => resolution,
        }
    }

    /// True for [`MotionCheck::Padded`].
    pub fn is_padded(self) -> bool {
        matches!(self, MotionCheck::Padded { .. })
    }
}

/// Checks `a → b` at evenly spaced states no more than `resolution` apart on
/// any joint (max-norm): the segment is cut into `2^k ≥ span / resolution`
/// equal steps, visited in bisection order (midpoint first, then quarter
/// points, …) so a collision in the middle of a long motion is found after few
/// checks. Both end states are checked. At most 17 joints
/// (`MAX_DOF`); longer chains are rejected as invalid. A padded check runs
/// [`padded_motion_valid`] between the two checked ends.
pub fn interpolate_motion_valid<C: StateChecker + ?Sized>(
    checker: &C,
    a: &[f64],
    b: &[f64],
    check: MotionCheck,
) -> bool {
    const MAX_DOF: usize = 17;
    let resolution = check.resolution();
    let n = a.len();
    if n != b.len() || n > MAX_DOF || resolution.is_nan() || resolution <= 0.0 {
        return false;
    }
    if !checker.is_valid(a) || !checker.is_valid(b) {
        return false;
    }
    if check.is_padded() {
        return padded_motion_valid(checker, a, b, resolution, crate::Deadline::none()) == Some(true);
    }
    let span = a
        .iter()
        .zip(b)
        .map(|(x, y)| (y - x).abs())
        .fold(0.0_f64, f64::max);
    if !span.is_finite() {
        return false;
    }
    let segments = (span / resolution).ceil().max(1.0);
    if segments > 1e7 {
        return false;
    }
    let segments = (segments as usize).next_power_of_two();
    let mut q = [0.0; MAX_DOF];
    // the interior states: every index but 0, in bisection order
    bisection_order(segments).skip(1).all(|i| {
        let t = i as f64 / segments as f64;
        for (j, qj) in q[..n].iter_mut().enumerate() {
            *qj = a[j] + t * (b[j] - a[j]);
        }
        checker.is_valid(&q[..n])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A 2-joint world whose only obstacle is the band 0.40 < q0 < 0.42.
    struct Band {
        calls: AtomicUsize,
    }

    impl StateChecker for Band {
        fn dof(&self) -> usize {
            2
        }
        fn is_valid(&self, q: &[f64]) -> bool {
            self.calls.fetch_add(1, Ordering::Relaxed);
            !(q[0] > 0.40 && q[0] < 0.42)
        }
        fn clearance(&self, q: &[f64], max_distance: f64) -> f64 {
            let d = if q[0] <= 0.40 {
                0.40 - q[0]
            } else if q[0] >= 0.42 {
                q[0] - 0.42
            } else {
                -0.01
            };
            d.min(max_distance)
        }
        fn motion_check(&self) -> MotionCheck {
            MotionCheck::Interpolated { resolution: 0.01 }
        }
    }

    #[test]
    fn a_band_wider_than_the_resolution_is_found_and_every_state_is_visited_once() {
        let band = Band {
            calls: AtomicUsize::new(0),
        };
        assert!(!band.motion_valid(&[0.0, 0.0], &[1.0, 0.0]));
        // Crossing nowhere near the band is valid and visits all 129 states
        // (a span of 1 rad at 0.01 rad needs 100 steps, rounded up to 128).
        let band = Band {
            calls: AtomicUsize::new(0),
        };
        assert!(band.motion_valid(&[0.5, 0.0], &[1.5, 0.3]));
        assert_eq!(band.calls.load(Ordering::Relaxed), 129);
    }

    #[test]
    fn bisection_order_finds_a_middle_obstacle_first() {
        // The band sits in the middle of 0 → 0.82: the first interior check
        // (the midpoint, 0.41) hits it.
        let band = Band {
            calls: AtomicUsize::new(0),
        };
        assert!(!band.motion_valid(&[0.0, 0.0], &[0.82, 0.0]));
        assert_eq!(band.calls.load(Ordering::Relaxed), 3);
    }

    #[test]
    fn malformed_motions_are_invalid() {
        let band = Band {
            calls: AtomicUsize::new(0),
        };
        assert!(!band.motion_valid(&[0.0], &[1.0, 0.0]));
        assert!(!band.motion_valid(&[0.0, 0.0], &[f64::INFINITY, 0.0]));
        assert!(!interpolate_motion_valid(
            &band,
            &[0.0, 0.0],
            &[0.1, 0.0],
            MotionCheck::Interpolated { resolution: 0.0 }
        ));
    }
}
