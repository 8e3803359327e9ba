//! Nearest-neighbour index for RRT trees: an incremental point k-d tree
//! (Bentley 1975) over rows of a flat row-major array that only grows.
//!
//! Every stored row is one k-d node splitting on axis `depth mod dof`:
//! rows with `x[a] < split` go left, the rest right (equal values go right,
//! so repeated coordinates never need a rebalance or a bucket split and
//! cannot fail). A query walks the near side first and visits a far side
//! only when its lower bound (the squared distance from the target to the
//! side's cell, kept incrementally) does not exceed the best squared
//! distance so far. Ties are broken by the smaller
//! row index, so the answer equals a linear scan's first minimum — the
//! planner's output does not depend on which of the two is used.
//!
//! Expected cost O(log n) per insertion and, in low dimension, per query;
//! no rebalancing (RRT rows arrive in random order).

const NONE: u32 = u32::MAX;

#[derive(Debug, Clone, Default)]
pub(crate) struct KdIndex {
    left: Vec<u32>,
    right: Vec<u32>,
    axis: Vec<u8>,
    /// Query stack (see [`KdIndex::nearest`]), reused between queries.
    stack: Vec<f64>,
}

impl KdIndex {
    /// Rows indexed.
    pub fn len(&self) -> usize {
        self.left.len()
    }

    /// Indexes row `len()` of `rows` (`dof` values per row); rows must be
    /// inserted in order 0, 1, 2, … and never change.
    pub fn insert(&mut self, rows: &[f64], dof: usize) {
        let i = self.left.len();
        let p = &rows[i * dof..(i + 1) * dof];
        self.left.push(NONE);
        self.right.push(NONE);
        if i == 0 {
            self.axis.push(0);
            return;
        }
        let mut n = 0usize;
        loop {
            let a = self.axis[n] as usize;
            let go_left = p[a] < rows[n * dof + a];
            let slot = if go_left {
                &mut self.left[n]
            } else {
                &mut self.right[n]
            };
            if *slot == NONE {
                *slot = i as u32;
                self.axis.push(((a + 1) % dof) as u8);
                return;
            }
            n = *slot as usize;
        }
    }

    /// Row nearest to `target` by Euclidean distance (smallest index among
    /// equals); `None` when empty.
    ///
    /// Depth first, near side first; a far side is entered only when its
    /// lower bound does not exceed the best squared distance so far. The
    /// bound is incremental (Arya and Mount 1993): every stack entry keeps,
    /// per axis, the offset `o_a` from the target to the nearest splitting
    /// plane crossed on that axis, and its bound is `Σ_a o_a²` — crossing a
    /// plane on axis `a` at offset `d` replaces `o_a²` by `d²`. (Each term
    /// is a distance to a slab the subtree lies beyond, so the sum never
    /// exceeds the distance to any row in it.)
    pub fn nearest(&mut self, rows: &[f64], dof: usize, target: &[f64]) -> Option<usize> {
        if self.left.is_empty() {
            return None;
        }
        let stride = dof + 2;
        let (mut best, mut best_d) = (usize::MAX, f64::INFINITY);
        // Entries of `stride` values: node, bound, then the dof offsets.
        let stack = &mut self.stack;
        stack.clear();
        stack.push(0.0);
        stack.push(0.0);
        stack.extend(std::iter::repeat_n(0.0, dof));
        while stack.len() >= stride {
            let top = stack.len() - stride;
            let (n, bound) = (stack[top] as usize, stack[top + 1]);
            if bound > best_d {
                stack.truncate(top);
                continue;
            }
            let row = &rows[n * dof..(n + 1) * dof];
            let mut d = 0.0;
            for (a, b) in row.iter().zip(target) {
                d += (a - b) * (a - b);
                if d > best_d {
                    break;
                }
            }
            if d < best_d || (d == best_d && n < best) {
                best_d = d;
                best = n;
            }
            let a = self.axis[n] as usize;
            let diff = target[a] - row[a];
            let (near, far) = if diff < 0.0 {
                (self.left[n], self.right[n])
            } else {
                (self.right[n], self.left[n])
            };
            // The far side: this entry's offsets with axis `a` replaced.
            let old = stack[top + 2 + a];
            let far_bound = bound - old * old + diff * diff;
            if far != NONE && far_bound <= best_d {
                stack[top] = far as f64;
                stack[top + 1] = far_bound;
                stack[top + 2 + a] = diff;
                if near != NONE {
                    stack.extend_from_within(top..top + stride);
                    let last = stack.len() - stride;
                    stack[last] = near as f64;
                    stack[last + 1] = bound;
                    stack[last + 2 + a] = old;
                }
            } else if near != NONE {
                stack[top] = near as f64;
            } else {
                stack.truncate(top);
            }
        }
        Some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The first row with the smallest squared distance, by brute force.
    fn scan(rows: &[f64], dof: usize, t: &[f64]) -> usize {
        let d = |i: usize| -> f64 {
            rows[i * dof..(i + 1) * dof]
                .iter()
                .zip(t)
                .map(|(a, b)| (a - b) * (a - b))
                .sum()
        };
        (0..rows.len() / dof).fold(0, |best, i| if d(i) < d(best) { i } else { best })
    }

    #[test]
    fn the_index_answers_exactly_what_a_brute_force_scan_answers() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for dof in [1, 2, 3, 7] {
            let mut rows = Vec::new();
            let mut kd = KdIndex::default();
            for i in 0..2000 {
                // coarse grid values: many repeated coordinates and exact ties
                for _ in 0..dof {
                    rows.push(if i % 3 == 0 {
                        (rng.random_range(0..5) as f64) * 0.5
                    } else {
                        rng.random_range(-3.0..3.0)
                    });
                }
                kd.insert(&rows, dof);
                if i % 7 == 0 {
                    let t: Vec<f64> = (0..dof).map(|_| (rng.random_range(0..5) as f64) * 0.5).collect();
                    assert_eq!(
                        kd.nearest(&rows, dof, &t),
                        Some(scan(&rows, dof, &t)),
                        "dof {dof} i {i}"
                    );
                    let t: Vec<f64> = (0..dof).map(|_| rng.random_range(-4.0..4.0)).collect();
                    assert_eq!(
                        kd.nearest(&rows, dof, &t),
                        Some(scan(&rows, dof, &t)),
                        "dof {dof} i {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn identical_rows_return_the_first_and_an_empty_index_none() {
        let mut kd = KdIndex::default();
        assert_eq!(kd.nearest(&[], 2, &[0.0, 0.0]), None);
        let rows: Vec<f64> = [1.0, 1.0].repeat(100);
        for _ in 0..100 {
            kd.insert(&rows, 2);
        }
        assert_eq!(kd.nearest(&rows, 2, &[1.0, 1.0]), Some(0));
        assert_eq!(kd.nearest(&rows, 2, &[5.0, -3.0]), Some(0));
    }
}
