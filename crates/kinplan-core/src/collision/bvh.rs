//! A static bounding-volume hierarchy over axis-aligned boxes: the broad
//! phase of a scene, built once and queried without allocation.
//!
//! Build: top-down, each node split at the median centroid along the axis
//! where the centroids spread most (`select_nth_unstable`, deterministic for
//! a given input order), down to leaves of at most [`LEAF_SIZE`] items. The
//! tree is balanced, so its depth is ⌈log₂(n / LEAF_SIZE)⌉ + 1 and a
//! traversal stack of [`STACK`] entries suffices for any `n < 2^60`.

use nalgebra::Vector3;

/// Items per leaf.
const LEAF_SIZE: usize = 4;
/// Traversal stack depth: a depth-first walk holds at most one entry per
/// level plus one, and item ids are `u32`, so a tree has at most
/// ⌈log₂(2³² / LEAF_SIZE)⌉ + 1 = 31 levels. (A stack of 64 was zeroed on
/// every query for nothing.)
const STACK: usize = 32;

/// An axis-aligned box `[min, max]` (metres, base frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Aabb {
    pub min: Vector3<f64>,
    pub max: Vector3<f64>,
}

impl Aabb {
    pub fn empty() -> Self {
        Aabb {
            min: Vector3::repeat(f64::INFINITY),
            max: Vector3::repeat(f64::NEG_INFINITY),
        }
    }

    /// The box around a sphere of `radius` at `center`.
    #[inline]
    pub fn around_sphere(center: &Vector3<f64>, radius: f64) -> Self {
        Aabb {
            min: center - Vector3::repeat(radius),
            max: center + Vector3::repeat(radius),
        }
    }

    pub fn merge(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&o.min),
            max: self.max.sup(&o.max),
        }
    }

    /// Whether the boxes meet (touching counts; a NaN bound counts as
    /// meeting, so a broken query is never culled). The six comparisons are
    /// combined with `&`, not `&&`: one branch instead of six hard-to-predict
    /// ones on the BVH's hottest line.
    #[inline]
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(a > b)`: true for NaN, on purpose
    pub fn intersects(&self, o: &Aabb) -> bool {
        !(self.min.x > o.max.x)
            & !(o.min.x > self.max.x)
            & !(self.min.y > o.max.y)
            & !(o.min.y > self.max.y)
            & !(self.min.z > o.max.z)
            & !(o.min.z > self.max.z)
    }

    /// Squared distance from `p` to the box (0 inside; a NaN coordinate of
    /// `p` adds nothing, so a broken query is never culled on its axis). Plain comparisons
    /// rather than `f64::max`, whose NaN rule costs extra instructions on
    /// this hot path (half the BVH's work).
    #[inline]
    pub fn distance_squared(&self, p: &Vector3<f64>) -> f64 {
        let mut d2 = 0.0;
        for k in 0..3 {
            let (below, above) = (self.min[k] - p[k], p[k] - self.max[k]);
            let e = if below > above { below } else { above };
            let e = if e > 0.0 { e } else { 0.0 };
            d2 += e * e;
        }
        d2
    }

    fn center(&self) -> Vector3<f64> {
        0.5 * (self.min + self.max)
    }
}

#[derive(Debug, Clone)]
struct Node {
    aabb: Aabb,
    /// Leaf: first item in `order`; inner: index of the left child (the
    /// right child is `start + 1`).
    start: u32,
    /// Items in a leaf, 0 for an inner node.
    count: u32,
}

/// The hierarchy: `order` lists item ids leaf by leaf.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// `boxes[order[k]]`, stored in leaf order.
    sorted: Vec<Aabb>,
}

impl Bvh {
    /// Builds the tree over `boxes` (item `i` is `boxes[i]`).
    pub fn build(boxes: &[Aabb]) -> Self {
        if boxes.is_empty() {
            return Bvh::default();
        }
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = vec![Node {
            aabb: Aabb::empty(),
            start: 0,
            count: 0,
        }];
        // (node, first, end) ranges still to split.
        let mut work = vec![(0usize, 0usize, boxes.len())];
        while let Some((node, first, end)) = work.pop() {
            let items = &mut order[first..end];
            let aabb = items
                .iter()
                .fold(Aabb::empty(), |a, &i| a.merge(&boxes[i as usize]));
            nodes[node].aabb = aabb;
            if items.len() <= LEAF_SIZE {
                nodes[node].start = first as u32;
                nodes[node].count = items.len() as u32;
                continue;
            }
            let centers = items.iter().fold(Aabb::empty(), |a, &i| {
                let c = boxes[i as usize].center();
                a.merge(&Aabb { min: c, max: c })
            });
            let axis = (centers.max - centers.min).imax();
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |&a, &b| {
                let ca = boxes[a as usize].center()[axis];
                let cb = boxes[b as usize].center()[axis];
                ca.total_cmp(&cb).then(a.cmp(&b))
            });
            let left = nodes.len();
            nodes.push(Node {
                aabb: Aabb::empty(),
                start: 0,
                count: 0,
            });
            nodes.push(Node {
                aabb: Aabb::empty(),
                start: 0,
                count: 0,
            });
            nodes[node].start = left as u32;
            work.push((left, first, first + mid));
            work.push((left + 1, first + mid, end));
        }
        let sorted = order.iter().map(|&i| boxes[i as usize]).collect();
        Bvh { nodes, order, sorted }
    }

    /// Calls `visit(item)` for every item whose box meets `query` (boxes
    /// touching count), until
    /// `visit` returns `false`. Returns `false` when stopped early.
    #[inline]
    pub fn for_each_overlap(&self, query: &Aabb, mut visit: impl FnMut(u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !node.aabb.intersects(query) {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                let e = s + node.count as usize;
                for (item, aabb) in self.order[s..e].iter().zip(&self.sorted[s..e]) {
                    if aabb.intersects(query) && !visit(*item) {
                        return false;
                    }
                }
            } else if top + 2 <= STACK {
                stack[top] = node.start;
                stack[top + 1] = node.start + 1;
                top += 2;
            }
        }
        true
    }
}

impl Bvh {
    /// Calls `visit(item)` for every item whose box lies within `radius` of
    /// `center` (the sphere test is tighter than its bounding box at the
    /// corners), until `visit` returns `false`. Returns `false` when stopped.
    /// A NaN centre coordinate matches every box along its axis and a NaN
    /// radius every box (never a silent "nothing near").
    #[inline]
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(d² > r²)`: true for NaN, on purpose
    pub fn for_each_near(
        &self,
        center: &Vector3<f64>,
        radius: f64,
        mut visit: impl FnMut(u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let r2 = radius * radius;
        // inner nodes are culled by the sphere's box (six comparisons), items
        // by the sphere itself (tighter at the corners, before narrow tests)
        let query = Aabb::around_sphere(center, radius);
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !node.aabb.intersects(&query) {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                let e = s + node.count as usize;
                for (item, aabb) in self.order[s..e].iter().zip(&self.sorted[s..e]) {
                    if !(aabb.distance_squared(center) > r2) && !visit(*item) {
                        return false;
                    }
                }
            } else if top + 2 <= STACK {
                stack[top] = node.start;
                stack[top + 1] = node.start + 1;
                top += 2;
            }
        }
        true
    }
}

impl Aabb {
    /// Entry parameter of the ray `origin + t·dir` into the box within
    /// `[0, t_max]` (slab test; `inv_dir` holds `1/dir` per axis, ±inf for a
    /// zero component), or `None` when it misses.
    #[inline]
    pub fn ray_entry(&self, origin: &Vector3<f64>, inv_dir: &Vector3<f64>, t_max: f64) -> Option<f64> {
        let (mut t0, mut t1) = (0.0f64, t_max);
        for k in 0..3 {
            let a = (self.min[k] - origin[k]) * inv_dir[k];
            let b = (self.max[k] - origin[k]) * inv_dir[k];
            // NaN (0·inf on a slab face) leaves the interval unchanged
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            if lo > t0 {
                t0 = lo;
            }
            if hi < t1 {
                t1 = hi;
            }
            if t0 > t1 {
                return None;
            }
        }
        Some(t0)
    }
}

impl Bvh {
    /// Calls `visit(item, t_max)` for every item whose box the ray
    /// `origin + t·dir`, `t ∈ [0, t_max]`, meets, where `visit` returns the new
    /// (possibly shorter) `t_max`: boxes entered beyond it are skipped, so a
    /// closest-hit search prunes as it goes. Returns the final `t_max`.
    pub fn ray_traverse(
        &self,
        origin: &Vector3<f64>,
        dir: &Vector3<f64>,
        mut t_max: f64,
        mut visit: impl FnMut(u32, f64) -> f64,
    ) -> f64 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let inv = dir.map(|d| 1.0 / d);
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.aabb.ray_entry(origin, &inv, t_max).is_none() {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                let e = s + node.count as usize;
                for (item, aabb) in self.order[s..e].iter().zip(&self.sorted[s..e]) {
                    if aabb.ray_entry(origin, &inv, t_max).is_some() {
                        t_max = visit(*item, t_max);
                    }
                }
            } else if top + 2 <= STACK {
                stack[top] = node.start;
                stack[top + 1] = node.start + 1;
                top += 2;
            }
        }
        t_max
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tree_reports_exactly_the_boxes_a_brute_force_scan_reports() {
        // A 10 × 10 × 10 grid of unit boxes with gaps, queried with boxes of
        // several sizes.
        let mut boxes = Vec::new();
        for i in 0..1000 {
            let c = Vector3::new((i % 10) as f64, ((i / 10) % 10) as f64, (i / 100) as f64) * 1.5;
            boxes.push(Aabb::around_sphere(&c, 0.5));
        }
        let bvh = Bvh::build(&boxes);
        for (k, r) in [0.1, 0.7, 2.0, 6.0].iter().enumerate() {
            let q = Aabb::around_sphere(&Vector3::new(3.3 + k as f64, 4.1, 7.9 - k as f64), *r);
            let mut found = Vec::new();
            bvh.for_each_overlap(&q, |i| {
                found.push(i);
                true
            });
            found.sort();
            let expected: Vec<u32> = (0..1000u32)
                .filter(|&i| boxes[i as usize].intersects(&q))
                .collect();
            assert_eq!(found, expected);
        }
    }

    #[test]
    fn a_sphere_query_reports_exactly_the_boxes_within_its_radius() {
        // The grid of the test above; a box is within r of c when the point
        // of the box nearest c (c clamped into it) is within r.
        let mut boxes = Vec::new();
        for i in 0..1000 {
            let c = Vector3::new((i % 10) as f64, ((i / 10) % 10) as f64, (i / 100) as f64) * 1.5;
            boxes.push(Aabb::around_sphere(&c, 0.5));
        }
        let bvh = Bvh::build(&boxes);
        let near = |c: &Vector3<f64>, r: f64| {
            let mut found = Vec::new();
            bvh.for_each_near(c, r, |i| {
                found.push(i);
                true
            });
            found.sort();
            found
        };
        for (k, r) in [0.1, 0.7, 1.3, 2.0, 6.0].iter().enumerate() {
            let c = Vector3::new(3.3 + k as f64, 4.1, 7.9 - k as f64);
            let expected: Vec<u32> = (0..1000u32)
                .filter(|&i| {
                    let b = &boxes[i as usize];
                    let nearest = c.zip_zip_map(&b.min, &b.max, |v, lo, hi| v.clamp(lo, hi));
                    (nearest - c).norm() <= *r
                })
                .collect();
            assert!(!expected.is_empty() || *r < 0.5);
            assert_eq!(near(&c, *r), expected, "r = {r}");
        }
        // a broken query is never answered "nothing near": a NaN coordinate
        // stands for any value on its axis, a NaN radius for any radius
        let all: Vec<u32> = (0..1000).collect();
        assert_eq!(near(&Vector3::repeat(f64::NAN), 0.1), all);
        assert_eq!(near(&Vector3::new(3.0, 4.0, 5.0), f64::NAN), all);
        let row: Vec<u32> = (0..10).collect(); // the boxes along x at y = z = 0
        assert_eq!(near(&Vector3::new(f64::NAN, 0.0, 0.0), 0.1), row);
    }

    #[test]
    fn point_to_box_distance_is_euclidean_outside_and_zero_inside() {
        let b = Aabb {
            min: Vector3::new(0.0, 0.0, 0.0),
            max: Vector3::new(1.0, 2.0, 3.0),
        };
        assert_eq!(b.distance_squared(&Vector3::new(0.5, 1.0, 1.0)), 0.0);
        assert!((b.distance_squared(&Vector3::new(4.0, 6.0, 3.0)) - 25.0).abs() < 1e-12);
    }

    #[test]
    fn a_ray_meets_the_boxes_a_brute_force_slab_test_meets_and_prunes_beyond_the_first_hit() {
        let mut boxes = Vec::new();
        for i in 0..200 {
            let c = Vector3::new((i % 10) as f64, ((i / 10) % 5) as f64, (i / 50) as f64) * 1.7;
            boxes.push(Aabb::around_sphere(&c, 0.45));
        }
        let bvh = Bvh::build(&boxes);
        let origin = Vector3::new(-1.0, 0.2, 0.1);
        let dir = Vector3::new(1.0, 0.35, 0.21).normalize();
        // every box the ray enters before t = 30 (no pruning)
        let mut seen = Vec::new();
        bvh.ray_traverse(&origin, &dir, 30.0, |i, t| {
            seen.push(i);
            t
        });
        seen.sort();
        // independent check: sample the ray densely and test containment
        let mut expected: Vec<u32> = (0..200u32)
            .filter(|&i| {
                let b = &boxes[i as usize];
                (0..300_000).any(|k| {
                    let p = origin + dir * (k as f64 * 1e-4);
                    (0..3).all(|a| p[a] >= b.min[a] && p[a] <= b.max[a])
                })
            })
            .collect();
        expected.sort();
        assert_eq!(seen, expected);
        assert!(!expected.is_empty());
        // pruning at the first entry keeps only boxes entered no later
        let inv = dir.map(|d| 1.0 / d);
        let first = expected
            .iter()
            .map(|&i| boxes[i as usize].ray_entry(&origin, &inv, 30.0).unwrap())
            .fold(f64::INFINITY, f64::min);
        let end = bvh.ray_traverse(&origin, &dir, 30.0, |i, t| {
            boxes[i as usize].ray_entry(&origin, &inv, t).unwrap().min(t)
        });
        assert!((end - first).abs() < 1e-12);
    }
}
