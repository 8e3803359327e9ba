//! What a scan will trace, worked out point by point before any beam is: each beam's
//! difference, squared length and end key, the key box all beams lie in, and the
//! chunks of beams with their cell counts (docs/octree.md#rays-and-scans).

use super::key::OcKey;
use super::{Octree, OctreeError, ScanParams};

/// Cells traced between two looks at the stop flag (a chunk of beams), so a
/// stop is seen within about a millisecond of tracing.
pub(crate) const CHUNK_CELLS: u64 = 1 << 16;

/// Where a beam's end point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EndPoint {
    /// In the tree's cube: `Beam::end` is its key.
    InTree,
    /// Finite but outside the cube: only its beam cut at `max_range` can count.
    Outside,
    /// Not finite: skipped.
    NonFinite,
}

/// One beam from the scan's origin `o` to a point `p`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Beam {
    /// `p − o` in f32 (OctoMap's `point3d` arithmetic).
    pub diff: [f32; 3],
    /// The beam's length (m): `√(diff · diff)` with the squares summed in f32 and
    /// the root in f64, as OctoMap's `norm()`; worked out once here, where the
    /// points stream by, rather than on each walk's chain of dependent operations.
    pub norm: f64,
    /// Key of `p` when `kind` is [`EndPoint::InTree`].
    pub end: OcKey,
    pub kind: EndPoint,
}

/// A scan's beams, key box and chunks.
pub(crate) struct ScanPlan {
    /// Key box of the origin and every usable end point (inclusive): all beams lie
    /// inside it.
    pub lo: OcKey,
    pub hi: OcKey,
    /// One beam per point, in point order.
    pub beams: Vec<Beam>,
    /// Consecutive beam ranges of at most [`CHUNK_CELLS`] cells each (a single
    /// longer beam is a chunk of its own), with their cell counts.
    pub chunks: Vec<(std::ops::Range<usize>, u64)>,
}

/// Builds a [`ScanPlan`] one point at a time: each beam's cost is the cells it can
/// cross, `‖key(p) − key(o)‖₁ + 1`, at most the cut beam's `3·max_range/res + 4`,
/// and 0 for a point that is skipped.
pub(crate) struct PlanBuilder<'a> {
    tree: &'a Octree,
    origin: [f32; 3],
    ko: OcKey,
    max_range: f64,
    cut_bound: u64,
    plan: ScanPlan,
    total: u64,
    chunk_cells: u64,
    chunk_start: usize,
    any_outside: bool,
}

impl<'a> PlanBuilder<'a> {
    /// An empty plan for beams from `origin`, room for `capacity` points; refuses an
    /// origin outside the tree's cube.
    pub(crate) fn new(
        tree: &'a Octree,
        origin: &[f32; 3],
        params: &ScanParams,
        capacity: usize,
    ) -> Result<Self, OctreeError> {
        let ko = tree
            .key_of_f32(origin)
            .ok_or(OctreeError::OutOfBounds { field: "origin" })?;
        let max_range = params.max_range;
        let cut_bound = if max_range > 0.0 {
            3 * (max_range * tree.resolution_factor).min(1e15) as u64 + 4
        } else {
            u64::MAX
        };
        Ok(PlanBuilder {
            tree,
            origin: *origin,
            ko,
            max_range,
            cut_bound,
            plan: ScanPlan {
                lo: ko,
                hi: ko,
                beams: Vec::with_capacity(capacity),
                chunks: Vec::new(),
            },
            total: 0,
            chunk_cells: 0,
            chunk_start: 0,
            any_outside: false,
        })
    }

    /// Adds the beam to point `p`.
    #[inline]
    pub(crate) fn push(&mut self, p: &[f32; 3]) {
        let o = &self.origin;
        let diff = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
        let sumsq = diff[0] * diff[0] + diff[1] * diff[1] + diff[2] * diff[2];
        let finite = p.iter().all(|v| v.is_finite());
        let key = if finite { self.tree.key_of_f32(p) } else { None };
        self.push_parts(diff, (sumsq as f64).sqrt(), key, finite);
    }

    /// Adds the beam to a point given as its difference from the origin, the
    /// beam's length `‖diff‖` (squares summed in f32, root in f64), its key (`None`
    /// outside the tree's cube or not finite) and whether it is finite.
    #[inline(always)]
    pub(crate) fn push_parts(&mut self, diff: [f32; 3], norm: f64, key: Option<OcKey>, finite: bool) {
        let (kind, end, cost) = match key {
            Some(k) => {
                let l1: u64 = (0..3)
                    .map(|a| (k[a] as i64 - self.ko[a] as i64).unsigned_abs())
                    .sum();
                (EndPoint::InTree, k, (l1 + 1).min(self.cut_bound))
            }
            None if finite => {
                self.any_outside = true;
                // a far point still casts its cut beam
                let cost = if self.max_range > 0.0 { self.cut_bound } else { 0 };
                (EndPoint::Outside, [0; 3], cost)
            }
            None => (EndPoint::NonFinite, [0; 3], 0),
        };
        let i = self.plan.beams.len();
        self.total = self.total.saturating_add(cost);
        if self.chunk_cells > 0 && self.chunk_cells + cost > CHUNK_CELLS {
            self.plan.chunks.push((self.chunk_start..i, self.chunk_cells));
            (self.chunk_start, self.chunk_cells) = (i, 0);
        }
        self.chunk_cells += cost;
        self.plan.beams.push(Beam {
            diff,
            norm,
            end,
            kind,
        });
    }

    /// The plan; refuses it when its cells pass `params.max_traced_cells`.
    pub(crate) fn finish(self, params: &ScanParams) -> Result<ScanPlan, OctreeError> {
        // the key box of the origin and the end points, in one pass over the beams
        // (kept in registers, where per point it was a load and store of the box
        // each point's update had to wait for)
        let (mut lo, mut hi) = (self.ko, self.ko);
        for b in &self.plan.beams {
            let k = if b.kind == EndPoint::InTree {
                b.end
            } else {
                self.ko
            };
            for a in 0..3 {
                lo[a] = lo[a].min(k[a]);
                hi[a] = hi[a].max(k[a]);
            }
        }
        self.finish_in_box(params, &lo, &hi)
    }

    /// [`finish`](Self::finish) given the key box `[lo, hi]` (inclusive; `lo > hi`
    /// for none) of the end points in the tree, worked out by the caller; the
    /// origin's key is added here.
    pub(crate) fn finish_in_box(
        mut self,
        params: &ScanParams,
        lo: &OcKey,
        hi: &OcKey,
    ) -> Result<ScanPlan, OctreeError> {
        let n = self.plan.beams.len();
        if self.chunk_start < n {
            self.plan.chunks.push((self.chunk_start..n, self.chunk_cells));
        }
        if self.total > params.max_traced_cells {
            return Err(OctreeError::ScanTooLarge {
                cells: self.total,
                limit: params.max_traced_cells,
            });
        }
        let lo = [0, 1, 2].map(|a| lo[a].min(self.ko[a]));
        let hi = [0, 1, 2].map(|a| hi[a].max(self.ko[a]));
        (self.plan.lo, self.plan.hi) = (lo, hi);
        // a cut beam of a far point can leave the end points' box: widen it by the cut
        if self.max_range > 0.0 && self.any_outside {
            let reach = (self.cut_bound / 3).min(65535) as u16;
            let plan = &mut self.plan;
            for ((lo, hi), &k) in plan.lo.iter_mut().zip(plan.hi.iter_mut()).zip(&self.ko) {
                *lo = (*lo).min(k.saturating_sub(reach));
                *hi = (*hi).max(k.saturating_add(reach));
            }
        }
        Ok(self.plan)
    }
}
