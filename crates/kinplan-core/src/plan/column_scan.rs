//! Nearest-neighbour search by a plain scan over rows stored column by
//! column: the squared distances of a block of rows are summed one joint at
//! a time (loops the compiler turns into vector instructions), then the
//! block's smallest is taken, first of equals. For the tree sizes most
//! RRT-Connect problems reach (hundreds to a few thousand nodes in 7
//! dimensions) this beats a k-d tree, whose pruning is weak in 7-D and whose
//! branches do not vectorise; `rrt_tree` switches to its [`super::kd_index`]
//! beyond [`ColumnScan::LARGEST`] rows.

/// Rows of `dof` values, stored as one column per joint.
#[derive(Debug, Clone, Default)]
pub(crate) struct ColumnScan {
    columns: Vec<Vec<f64>>,
    len: usize,
}

/// Rows whose distances are summed together.
const BLOCK: usize = 128;

impl ColumnScan {
    /// Rows above which the k-d tree answers faster (chosen on the
    /// MotionBenchMaker Panda problems).
    pub const LARGEST: usize = 4096;

    pub fn new(dof: usize, capacity: usize) -> Self {
        Self {
            columns: (0..dof).map(|_| Vec::with_capacity(capacity)).collect(),
            len: 0,
        }
    }

    /// Appends a row of `dof` values.
    pub fn push(&mut self, row: &[f64]) {
        for (column, v) in self.columns.iter_mut().zip(row) {
            column.push(*v);
        }
        self.len += 1;
    }

    pub fn len(&self) -> usize {
        self.len
    }

    /// Index of the row nearest to `target` (Euclidean; the first of
    /// equals), `None` when empty. The same code built for AVX2 when the CPU
    /// has it (four rows per instruction instead of two; no multiply and add
    /// are fused, so the answers are the same).
    pub fn nearest(&self, target: &[f64]) -> Option<usize> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { self.nearest_avx2(target) };
        }
        self.nearest_in(target)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn nearest_avx2(&self, target: &[f64]) -> Option<usize> {
        self.nearest_in(target)
    }

    #[inline(always)]
    fn nearest_in(&self, target: &[f64]) -> Option<usize> {
        let (mut best, mut best_d) = (None, f64::INFINITY);
        let mut sums = [0.0_f64; BLOCK];
        for start in (0..self.len).step_by(BLOCK) {
            let len = BLOCK.min(self.len - start);
            let sums = &mut sums[..len];
            sums.fill(0.0);
            for (column, t) in self.columns.iter().zip(target) {
                for (s, x) in sums.iter_mut().zip(&column[start..start + len]) {
                    let e = x - t;
                    *s += e * e;
                }
            }
            for (i, &d) in sums.iter().enumerate() {
                if d < best_d {
                    best_d = d;
                    best = Some(start + i);
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_scan_answers_the_first_nearest_row() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let dof = 7;
        let mut scan = ColumnScan::new(dof, 0);
        let mut rows: Vec<Vec<f64>> = Vec::new();
        assert_eq!(scan.nearest(&[0.0; 7]), None);
        for n in 0..600 {
            // coarse values so that ties occur
            let row: Vec<f64> = (0..dof).map(|_| rng.random_range(-3..=3) as f64).collect();
            scan.push(&row);
            rows.push(row);
            let t: Vec<f64> = (0..dof).map(|_| rng.random_range(-3.0..3.0)).collect();
            let d = |r: &Vec<f64>| r.iter().zip(&t).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
            let expected = (0..rows.len()).fold(0, |b, i| if d(&rows[i]) < d(&rows[b]) { i } else { b });
            assert_eq!(scan.nearest(&t), Some(expected), "after {} rows", n + 1);
            // a stored row is its own nearest, unless an earlier copy exists
            let first_copy = rows.iter().position(|r| *r == rows[n]).unwrap();
            assert_eq!(scan.nearest(&rows[n]), Some(first_copy));
        }
        assert_eq!(scan.len(), 600);
    }
}
