//! The tree growth of RRT-Connect (Kuffner & LaValle 2000): two trees of
//! joint states, from start and goal, grown towards random samples until
//! they meet. Shortcutting and the padded proof live in `rrt_connect`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::RrtParams;
use super::clock::Clock;
use super::column_scan::ColumnScan;
use super::costs::{edge_valid_as, interior_valid_as};
use super::kd_index::KdIndex;
use super::rrt_connect::{RrtStop, stop_of};
use crate::collision::StateChecker;

/// A tree of joint states: flat row-major storage and parent indices, so
/// an extension appends to a few `Vec`s and allocates nothing else; nearest
/// neighbours come from a [`ColumnScan`] of the rows while the tree is
/// small, from a [`KdIndex`] over them beyond [`ColumnScan::LARGEST`] rows
/// (both answer the first nearest row, so the switch changes no answer).
/// Each index holds only the rows it may be asked about: the scan the first
/// `LARGEST`, the k-d tree all of them once the tree outgrows the scan.
struct Tree {
    q: Vec<f64>,
    parent: Vec<u32>,
    dof: usize,
    scan: ColumnScan,
    index: KdIndex,
}

enum Extend {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

impl Tree {
    fn new(root: &[f64], capacity: usize) -> Self {
        let mut q = Vec::with_capacity(capacity * root.len());
        q.extend_from_slice(root);
        let mut scan = ColumnScan::new(root.len(), capacity.min(ColumnScan::LARGEST));
        scan.push(root);
        Self {
            q,
            parent: vec![u32::MAX],
            dof: root.len(),
            scan,
            index: KdIndex::default(),
        }
    }
    fn len(&self) -> usize {
        self.parent.len()
    }
    fn node(&self, i: usize) -> &[f64] {
        &self.q[i * self.dof..(i + 1) * self.dof]
    }
    fn push(&mut self, q: &[f64], parent: usize) -> usize {
        self.q.extend_from_slice(q);
        self.parent.push(parent as u32);
        if self.scan.len() < ColumnScan::LARGEST {
            self.scan.push(q);
        }
        self.len() - 1
    }
    /// Nearest node by Euclidean joint distance (the first of equals, as a
    /// linear scan would answer).
    fn nearest(&mut self, target: &[f64]) -> usize {
        let found = if self.len() <= ColumnScan::LARGEST {
            self.scan.nearest(target)
        } else {
            // rows are indexed in order, the first time and as they come
            while self.index.len() < self.len() {
                self.index.insert(&self.q, self.dof);
            }
            self.index.nearest(&self.q, self.dof, target)
        };
        found.unwrap_or(0)
    }
}

struct Search<'a, C: ?Sized> {
    checker: &'a C,
    range: f64,
    resolution: f64,
    /// Tree edges checked padded (conservative) or as interpolated states.
    padded: bool,
    q_new: Vec<f64>,
    buf: Vec<f64>,
}

impl<C: StateChecker + ?Sized> Search<'_, C> {
    /// One step of at most `range` from the nearest node towards `target`.
    fn extend(&mut self, tree: &mut Tree, target: &[f64], clock: &Clock<'_>) -> Extend {
        let near = tree.nearest(target);
        let from = tree.node(near);
        let dist = from
            .iter()
            .zip(target)
            .map(|(a, b)| (b - a) * (b - a))
            .sum::<f64>()
            .sqrt();
        let reached = dist <= self.range;
        let s = if reached { 1.0 } else { self.range / dist };
        for ((v, a), b) in self.q_new.iter_mut().zip(from).zip(target) {
            *v = a + s * (b - a);
        }
        if reached {
            self.q_new.copy_from_slice(target);
        }
        if edge_valid_as(
            self.checker,
            from,
            &self.q_new,
            self.resolution,
            self.padded,
            &mut self.buf,
            clock,
        ) != Some(true)
        {
            return Extend::Trapped;
        }
        let i = tree.push(&self.q_new, near);
        if reached {
            Extend::Reached(i)
        } else {
            Extend::Advanced(i)
        }
    }

    /// Extends repeatedly towards `target` until reached or trapped.
    fn connect(&mut self, tree: &mut Tree, target: &[f64], clock: &Clock<'_>) -> Extend {
        loop {
            match self.extend(tree, target, clock) {
                Extend::Advanced(_) => {
                    if clock.interrupted().is_some() {
                        return Extend::Trapped;
                    }
                }
                other => return other,
            }
        }
    }
}

/// What one growth of the trees found.
pub(super) struct Grown {
    /// The joined path (start and goal kept exactly, row-major), or why
    /// there is none.
    pub path: Result<Vec<f64>, RrtStop>,
    /// Random samples drawn.
    pub samples: usize,
    /// Nodes in both trees.
    pub nodes: usize,
}

/// Grows trees from `start` and `goal` (valid states) until they meet, for at
/// most `budget` samples: each sample `q_rand` (uniform in `bounds`, from
/// `rng`) extends one tree by at most `params.range` (Euclidean) and the
/// other tree connects greedily towards the new node; the trees swap roles
/// each sample. Tree edges are checked `padded` or as interpolated states,
/// with pieces or steps of at most `resolution`. The straight motion is
/// tried first when `try_straight` (callers that know it blocked say
/// `false`). The clock is asked every sample and every connect step.
#[allow(clippy::too_many_arguments)]
pub(super) fn grow<C: StateChecker + ?Sized>(
    checker: &C,
    bounds: &[(f64, f64)],
    start: &[f64],
    goal: &[f64],
    params: &RrtParams,
    padded: bool,
    try_straight: bool,
    resolution: f64,
    budget: usize,
    rng: &mut ChaCha8Rng,
    clock: &Clock<'_>,
) -> Grown {
    let dof = start.len();
    let mut search = Search {
        checker,
        range: params.range,
        resolution,
        padded,
        q_new: vec![0.0; dof],
        buf: vec![0.0; dof],
    };
    let straight = try_straight
        && interior_valid_as(
            checker,
            start,
            goal,
            search.resolution,
            padded,
            &mut search.buf,
            clock,
        ) == Some(true);
    if straight {
        let mut path = start.to_vec();
        path.extend_from_slice(goal);
        return Grown {
            path: Ok(path),
            samples: 0,
            nodes: 2,
        };
    }
    let cap = budget.min(4096);
    let mut a = Tree::new(start, cap);
    let mut b = Tree::new(goal, cap);
    let mut a_is_start = true;
    let mut q_rand = vec![0.0; dof];
    let mut target = vec![0.0; dof];
    let mut samples = 0;
    let path = loop {
        if samples >= budget {
            break Err(RrtStop::SampleBudget);
        }
        if let Some(i) = clock.interrupted() {
            break Err(stop_of(i));
        }
        samples += 1;
        for (v, &(lo, hi)) in q_rand.iter_mut().zip(bounds) {
            *v = if hi > lo { rng.random_range(lo..=hi) } else { lo };
        }
        let new = match search.extend(&mut a, &q_rand, clock) {
            Extend::Trapped => None,
            Extend::Reached(i) | Extend::Advanced(i) => Some(i),
        };
        if let Some(ia) = new {
            target.copy_from_slice(a.node(ia));
            if let Extend::Reached(ib) = search.connect(&mut b, &target, clock) {
                let (s_tree, s_end, g_tree, g_end) = if a_is_start {
                    (&a, ia, &b, ib)
                } else {
                    (&b, ib, &a, ia)
                };
                break Ok(joined(s_tree, s_end, g_tree, g_end, start, goal));
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    };
    Grown {
        path,
        samples,
        nodes: a.len() + b.len(),
    }
}

/// The path root → `s_end` in the start tree, then `g_end`'s ancestors in
/// the goal tree (`g_end` duplicates `s_end`'s state), with the ends set to
/// `start` and `goal` exactly.
fn joined(s_tree: &Tree, s_end: usize, g_tree: &Tree, g_end: usize, start: &[f64], goal: &[f64]) -> Vec<f64> {
    let dof = start.len();
    let mut path = Vec::new();
    let mut i = s_end;
    let mut rows = Vec::new();
    loop {
        rows.push(i);
        if s_tree.parent[i] == u32::MAX {
            break;
        }
        i = s_tree.parent[i] as usize;
    }
    for &r in rows.iter().rev() {
        path.extend_from_slice(s_tree.node(r));
    }
    let mut i = g_end;
    while g_tree.parent[i] != u32::MAX {
        i = g_tree.parent[i] as usize;
        path.extend_from_slice(g_tree.node(i));
    }
    path[..dof].copy_from_slice(start);
    let last = path.len() - dof;
    path[last..].copy_from_slice(goal);
    path
}
