//! Queries: state at a point and depth, bounding-box iteration over free / occupied /
//! unknown cubes at any depth, face and full neighbours, bounds and volumes.

use nalgebra::Point3;

use super::key::{
    OcKey, TREE_DEPTH, TREE_MAX_VAL, child_key, coord_to_key_axis, key_at_depth, key_to_coord_axis_at,
};
use super::tree::{CellState, Node};
use super::{Octree, OctreeError};

/// One cube reported by [`Octree::for_each_in_box`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellVisit {
    /// Smallest depth-16 key inside the cube.
    pub key: OcKey,
    /// Depth of the cube (0 = root, 16 = one cell of `resolution`).
    pub depth: u8,
    /// Centre (m, map frame).
    pub center: Point3<f64>,
    /// Edge length (m).
    pub size: f64,
    pub state: CellState,
    /// Log-odds of the node; NaN for unknown cubes.
    pub log_odds: f32,
}

/// Which states [`Octree::for_each_in_box`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StateFilter {
    pub free: bool,
    pub occupied: bool,
    pub unknown: bool,
}

impl StateFilter {
    /// All three states.
    pub const ALL: StateFilter = StateFilter {
        free: true,
        occupied: true,
        unknown: true,
    };
    #[inline]
    fn wants(&self, s: CellState) -> bool {
        match s {
            CellState::Free => self.free,
            CellState::Occupied => self.occupied,
            CellState::Unknown => self.unknown,
        }
    }
}

/// Known and unknown volume inside a box.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoxVolumes {
    /// m³ of free cells inside the box.
    pub free: f64,
    /// m³ of occupied cells.
    pub occupied: f64,
    /// m³ of the box no node covers.
    pub unknown: f64,
}

impl Octree {
    /// Depth-16 key of a point (m, map frame), `⌊c/res⌋ + 32768` per axis as OctoMap
    /// computes it; an error outside the tree's cube or for non-finite input.
    pub fn key_of(&self, p: &Point3<f64>) -> Result<OcKey, OctreeError> {
        let f = self.resolution_factor;
        let ax = |i: usize, field| {
            if !p[i].is_finite() {
                return Err(OctreeError::NonFinite { field });
            }
            coord_to_key_axis(p[i], f).ok_or(OctreeError::OutOfBounds { field })
        };
        Ok([ax(0, "x")?, ax(1, "y")?, ax(2, "z")?])
    }

    /// Centre (m) of the depth-`depth` cube containing `key`.
    pub fn key_center(&self, key: &OcKey, depth: u8) -> Point3<f64> {
        let r = self.resolution;
        Point3::new(
            key_to_coord_axis_at(key[0], depth, r),
            key_to_coord_axis_at(key[1], depth, r),
            key_to_coord_axis_at(key[2], depth, r),
        )
    }

    /// State (and log-odds) of the space at `p` seen at `depth` (0–16): the node at
    /// that depth or the pruned leaf above it; an inner node is occupied when any child
    /// is (it holds their maximum).
    pub fn state_at(&self, p: &Point3<f64>, depth: u8) -> Result<(CellState, Option<f32>), OctreeError> {
        let k = self.key_of(p)?;
        Ok(match self.search_key(&k, depth) {
            None => (CellState::Unknown, None),
            Some((v, _)) => (
                if self.is_occupied_value(v) {
                    CellState::Occupied
                } else {
                    CellState::Free
                },
                Some(v),
            ),
        })
    }

    /// Calls `visit` for every cube overlapping the axis-aligned box `[min, max]` (m)
    /// whose state passes `filter`: leaves (and inner nodes reached at `max_depth`) as
    /// free / occupied, and absent children of existing nodes (or the whole root cube
    /// when the tree is empty) as unknown, each at its natural depth (never deeper than
    /// `max_depth`). The cubes are not clipped to the box. Iterative (no recursion).
    pub fn for_each_in_box(
        &self,
        min: &Point3<f64>,
        max: &Point3<f64>,
        max_depth: u8,
        filter: StateFilter,
        mut visit: impl FnMut(&CellVisit),
    ) -> Result<(), OctreeError> {
        let (kmin, kmax) = self.box_keys(min, max)?;
        let max_depth = max_depth.min(TREE_DEPTH);
        let overlaps = |base: &OcKey, depth: u8| {
            let span = (1u32 << (TREE_DEPTH - depth)) - 1;
            (0..3).all(|i| base[i] as u32 <= kmax[i] as u32 && base[i] as u32 + span >= kmin[i] as u32)
        };
        let mut emit = |key: OcKey, depth: u8, node: Option<&Node>| {
            let (state, v) = match node {
                None => (CellState::Unknown, f32::NAN),
                Some(n) if self.is_occupied_value(n.value) => (CellState::Occupied, n.value),
                Some(n) => (CellState::Free, n.value),
            };
            if filter.wants(state) {
                visit(&CellVisit {
                    key,
                    depth,
                    center: self.key_center(&key, depth),
                    size: self.node_size(depth),
                    state,
                    log_odds: v,
                });
            }
        };
        let Some(root) = self.root else {
            emit([0; 3], 0, None);
            return Ok(());
        };
        let mut stack: Vec<(Node, OcKey, u8)> = Vec::with_capacity(8 * TREE_DEPTH as usize);
        stack.push((root, [0; 3], 0));
        while let Some((n, base, depth)) = stack.pop() {
            if !n.has_children() || depth == max_depth {
                emit(base, depth, Some(&n));
                continue;
            }
            let b = &self.blocks[n.block as usize];
            for i in (0..8).rev() {
                let ck = child_key(&base, depth, i);
                if !overlaps(&ck, depth + 1) {
                    continue;
                }
                if b.mask & (1 << i) != 0 {
                    stack.push((b.nodes[i], ck, depth + 1));
                } else {
                    emit(ck, depth + 1, None);
                }
            }
        }
        Ok(())
    }

    /// Free, occupied and unknown volume (m³) inside the box `[min, max]` (m), exact:
    /// every cube counts the part of it inside the box,
    /// `Π_i max(0, min(hi_i, max_i) − max(lo_i, min_i))` — a box of zero volume has
    /// none, and a cell that only touches the box's faces adds nothing.
    pub fn volumes_in_box(&self, min: &Point3<f64>, max: &Point3<f64>) -> Result<BoxVolumes, OctreeError> {
        let mut v = BoxVolumes::default();
        self.for_each_in_box(min, max, TREE_DEPTH, StateFilter::ALL, |c| {
            let half = c.size / 2.0;
            let mut inside = 1.0;
            for i in 0..3 {
                let lo = (c.center[i] - half).max(min[i]);
                let hi = (c.center[i] + half).min(max[i]);
                inside *= (hi - lo).max(0.0);
            }
            match c.state {
                CellState::Free => v.free += inside,
                CellState::Occupied => v.occupied += inside,
                CellState::Unknown => v.unknown += inside,
            }
        })?;
        Ok(v)
    }

    /// The depth-16 keys of the cells containing `min` and `max` on each axis (a
    /// closed box: a cell touching its upper face is visited, and counts no volume in
    /// [`volumes_in_box`](Self::volumes_in_box)). A coordinate on the cube's upper
    /// edge (`32768·res`) belongs to the last cell, so a box of the tree's whole cube
    /// is accepted; coordinates beyond the cube are errors.
    fn box_keys(&self, min: &Point3<f64>, max: &Point3<f64>) -> Result<(OcKey, OcKey), OctreeError> {
        const NAMES: [&str; 3] = ["x", "y", "z"];
        let f = self.resolution_factor;
        let edge = TREE_MAX_VAL as f64;
        let mut kmin = [0u16; 3];
        let mut kmax = [0u16; 3];
        for i in 0..3 {
            let field = NAMES[i];
            if !(min[i].is_finite() && max[i].is_finite()) {
                return Err(OctreeError::NonFinite { field });
            }
            if min[i] > max[i] {
                return Err(OctreeError::InvalidParam {
                    field: "box",
                    value: 0.0,
                    reason: "min must not exceed max",
                });
            }
            let (a, b) = ((min[i] * f).floor(), (max[i] * f).floor());
            if !(a >= -edge && b <= edge) {
                return Err(OctreeError::OutOfBounds { field });
            }
            kmin[i] = (a.min(edge - 1.0) as i32 + TREE_MAX_VAL) as u16;
            kmax[i] = (b.min(edge - 1.0) as i32 + TREE_MAX_VAL) as u16;
        }
        Ok((kmin, kmax))
    }

    /// The neighbours of the depth-`depth` cube containing `key`: its 6 face
    /// neighbours (`full = false`) or all 26, as `(key of the neighbour cube, state)`;
    /// neighbours outside the tree's cube are left out.
    pub fn neighbors(&self, key: &OcKey, depth: u8, full: bool) -> Vec<(OcKey, CellState)> {
        let depth = depth.clamp(1, TREE_DEPTH);
        let base = key_at_depth(key, depth);
        let step = 1i32 << (TREE_DEPTH - depth);
        let mut out = Vec::with_capacity(26);
        for dz in -1..=1i32 {
            for dy in -1..=1i32 {
                for dx in -1..=1i32 {
                    let n = dx.abs() + dy.abs() + dz.abs();
                    if n == 0 || (!full && n > 1) {
                        continue;
                    }
                    let k = [
                        (base[0] as i32 + dx * step),
                        (base[1] as i32 + dy * step),
                        (base[2] as i32 + dz * step),
                    ];
                    if k.iter().any(|&v| !(0..65536).contains(&v)) {
                        continue;
                    }
                    let k = [k[0] as u16, k[1] as u16, k[2] as u16];
                    let s = match self.search_key(&k, depth) {
                        None => CellState::Unknown,
                        Some((v, _)) if self.is_occupied_value(v) => CellState::Occupied,
                        Some(_) => CellState::Free,
                    };
                    out.push((k, s));
                }
            }
        }
        out
    }

    /// Axis-aligned bounds (m) of all known leaves, `None` for an empty tree.
    pub fn known_bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let big = 32768.0 * self.resolution;
        self.for_each_in_box(
            &Point3::new(-big, -big, -big),
            &Point3::new(big, big, big),
            TREE_DEPTH,
            StateFilter {
                free: true,
                occupied: true,
                unknown: false,
            },
            |c| {
                for i in 0..3 {
                    lo[i] = lo[i].min(c.center[i] - c.size / 2.0);
                    hi[i] = hi[i].max(c.center[i] + c.size / 2.0);
                }
            },
        )
        .ok()?;
        lo[0].is_finite().then(|| (Point3::from(lo), Point3::from(hi)))
    }
}
