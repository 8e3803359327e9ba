//! The arena octree: nodes stored by value in blocks of eight siblings, no `Box` per
//! node, OctoMap's update / expand / prune rules (docs/octree.md#values-and-updates).

use super::OctreeError;
use super::key::{OcKey, TREE_DEPTH, child_index};
use super::params::{LogOddsModel, SensorModel};

/// "No block": the node is a leaf.
pub(crate) const NONE: u32 = u32::MAX;
/// Location of the root in [`Loc`] form.
pub(crate) const ROOT: u32 = u32::MAX;

/// One node: its log-odds and the block holding its children (`NONE` = leaf).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Node {
    pub value: f32,
    pub block: u32,
}

impl Node {
    pub(crate) const fn leaf(value: f32) -> Self {
        Self { value, block: NONE }
    }
    #[inline]
    pub(crate) fn has_children(&self) -> bool {
        self.block != NONE
    }
}

/// The eight children of one inner node; bit `i` of `mask` says child `i` exists.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Block {
    pub nodes: [Node; 8],
    pub mask: u8,
}

/// Where a node lives: `ROOT`, or `block · 8 + slot`.
pub(crate) type Loc = u32;

/// A read-only handle to one node, for traversals outside the room (copied out of the
/// arena; valid until the tree is next changed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeRef(pub(crate) Node);

/// The path of the last lookup, so that a lookup of a nearby key (the next DDA step)
/// resumes at the deepest ancestor both keys share instead of at the root. Valid for
/// one tree while it is not changed; [`SearchCache::default`] starts empty.
#[derive(Debug, Clone, Default)]
pub struct SearchCache {
    key: OcKey,
    nodes: [Option<Node>; TREE_DEPTH as usize + 1],
    /// Depth at which the last lookup ended: the node found, or the missing child.
    end: u8,
    result: Option<(f32, u8)>,
    valid: bool,
}

/// Occupancy of a cell as OctoMap classifies it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellState {
    /// No node covers the cell.
    Unknown,
    /// A node covers it with probability ≤ the occupancy threshold.
    Free,
    /// A node covers it with probability > the occupancy threshold.
    Occupied,
}

/// An OctoMap-compatible occupancy octree (`OcTree`): depth 16, cubic cells of
/// `resolution` metres at depth 16, `res · 2^(16−d)` at depth d, the root centred on
/// the origin of the map frame; f32 log-odds per node, inner nodes holding the
/// maximum of their children.
#[derive(Debug, Clone, PartialEq)]
pub struct Octree {
    pub(crate) resolution: f64,
    pub(crate) resolution_factor: f64,
    pub(crate) sensor: SensorModel,
    pub(crate) model: LogOddsModel,
    pub(crate) root: Option<Node>,
    pub(crate) blocks: Vec<Block>,
    pub(crate) free_blocks: Vec<u32>,
    pub(crate) num_nodes: usize,
    /// True when every value is clamp_min or clamp_max and nothing can be pruned, so
    /// `write_bt` can skip its max-likelihood copy.
    pub(crate) max_likelihood_pruned: bool,
}

/// Smallest cell size (m): a tenth of a millimetre.
pub const MIN_RESOLUTION: f64 = 1e-4;
/// Largest cell size (m): the cube then spans 65,536 km, and volumes stay finite.
pub const MAX_RESOLUTION: f64 = 1e3;

impl Octree {
    /// An empty tree of cell size `resolution` (m, within [`MIN_RESOLUTION`],
    /// [`MAX_RESOLUTION`]) with OctoMap's default sensor model.
    pub fn new(resolution: f64) -> Result<Self, OctreeError> {
        Self::with_sensor_model(resolution, SensorModel::default())
    }

    /// An empty tree with the given sensor model.
    pub fn with_sensor_model(resolution: f64, sensor: SensorModel) -> Result<Self, OctreeError> {
        if !(MIN_RESOLUTION..=MAX_RESOLUTION).contains(&resolution) {
            return Err(OctreeError::BadResolution(resolution));
        }
        sensor.validate()?;
        Ok(Self {
            resolution,
            resolution_factor: 1.0 / resolution,
            sensor,
            model: sensor.log_odds(),
            root: None,
            blocks: Vec::new(),
            free_blocks: Vec::new(),
            num_nodes: 0,
            max_likelihood_pruned: true,
        })
    }

    /// Cell size at depth 16 (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The sensor model used by updates and by the occupancy threshold.
    pub fn sensor_model(&self) -> &SensorModel {
        &self.sensor
    }

    /// The root, if the tree has nodes.
    #[inline]
    pub fn root_ref(&self) -> Option<NodeRef> {
        self.root.map(NodeRef)
    }

    /// True when the node has children (else it is a leaf, possibly a pruned cube).
    #[inline]
    pub fn has_children(&self, n: NodeRef) -> bool {
        n.0.has_children()
    }

    /// Child `i` (0–7, `x + 2y + 4z`) of `n`, if it exists.
    #[inline]
    pub fn child_ref(&self, n: NodeRef, i: usize) -> Option<NodeRef> {
        if !n.0.has_children() || i >= 8 {
            return None;
        }
        let b = &self.blocks[n.0.block as usize];
        (b.mask & (1 << i) != 0).then(|| NodeRef(b.nodes[i]))
    }

    /// Log-odds of a node.
    #[inline]
    pub fn log_odds_of(&self, n: NodeRef) -> f32 {
        n.0.value
    }

    /// The occupancy threshold as log-odds (a node is occupied above it).
    #[inline]
    pub fn threshold_log_odds(&self) -> f32 {
        self.model.threshold
    }

    /// Nodes, inner and leaves (OctoMap's `size()`).
    pub fn num_nodes(&self) -> usize {
        self.num_nodes
    }

    /// True when the tree has no node.
    pub fn is_empty(&self) -> bool {
        self.root.is_none()
    }

    /// Edge of a cell at `depth` (m): `res · 2^(16 − depth)`.
    pub fn node_size(&self, depth: u8) -> f64 {
        self.resolution * (1u64 << (TREE_DEPTH - depth.min(TREE_DEPTH))) as f64
    }

    /// Approximate heap bytes held by the arena.
    pub fn memory_bytes(&self) -> usize {
        self.blocks.capacity() * std::mem::size_of::<Block>() + self.free_blocks.capacity() * 4
    }

    #[inline]
    pub(crate) fn node(&self, loc: Loc) -> &Node {
        if loc == ROOT {
            self.root.as_ref().expect("root exists when addressed")
        } else {
            &self.blocks[(loc >> 3) as usize].nodes[(loc & 7) as usize]
        }
    }

    #[inline]
    pub(crate) fn node_mut(&mut self, loc: Loc) -> &mut Node {
        if loc == ROOT {
            self.root.as_mut().expect("root exists when addressed")
        } else {
            &mut self.blocks[(loc >> 3) as usize].nodes[(loc & 7) as usize]
        }
    }

    pub(crate) fn alloc_block(&mut self, block: Block) -> u32 {
        if let Some(i) = self.free_blocks.pop() {
            self.blocks[i as usize] = block;
            i
        } else {
            self.blocks.push(block);
            (self.blocks.len() - 1) as u32
        }
    }

    #[inline]
    pub(crate) fn is_occupied_value(&self, v: f32) -> bool {
        v > self.model.threshold
    }

    /// The deepest node on the path to `key` down to `depth` (0–16): the node at that
    /// depth, or a leaf above it (a pruned cube); `None` where the space is unknown.
    /// Returns the node and its depth (OctoMap's `search`).
    #[inline]
    pub fn search_key(&self, key: &OcKey, depth: u8) -> Option<(f32, u8)> {
        let mut node = self.root.as_ref()?;
        let depth = depth.min(TREE_DEPTH);
        for d in 0..depth {
            if !node.has_children() {
                return Some((node.value, d));
            }
            let b = &self.blocks[node.block as usize];
            let i = child_index(key, d);
            if b.mask & (1 << i) == 0 {
                return None;
            }
            node = &b.nodes[i];
        }
        Some((node.value, depth))
    }

    /// [`search_key`](Self::search_key) at depth 16 resuming from `cache`: keys sharing
    /// their top `c` bits share the path down to depth `c`, and a key inside the cube
    /// where the last lookup ended gets the same answer without any descent.
    #[inline]
    pub fn search_key_cached(&self, key: &OcKey, cache: &mut SearchCache) -> Option<(f32, u8)> {
        let root = self.root.as_ref()?;
        let mut start = 0u8;
        if cache.valid {
            let c = cache
                .key
                .iter()
                .zip(key)
                .map(|(a, b)| (a ^ b).leading_zeros() as u8)
                .fold(TREE_DEPTH, u8::min);
            if c >= cache.end {
                cache.key = *key;
                return cache.result;
            }
            start = c;
        } else {
            cache.nodes[0] = Some(*root);
        }
        cache.valid = true;
        cache.key = *key;
        let mut node = cache.nodes[start as usize].expect("cached path node");
        for d in start..TREE_DEPTH {
            if !node.has_children() {
                cache.end = d;
                cache.result = Some((node.value, d));
                return cache.result;
            }
            let b = &self.blocks[node.block as usize];
            let i = child_index(key, d);
            if b.mask & (1 << i) == 0 {
                cache.end = d + 1;
                cache.result = None;
                return None;
            }
            node = b.nodes[i];
            cache.nodes[d as usize + 1] = Some(node);
        }
        cache.end = TREE_DEPTH;
        cache.result = Some((node.value, TREE_DEPTH));
        cache.result
    }

    /// State of the cell with `key` at depth 16.
    #[inline]
    pub fn state_of_key(&self, key: &OcKey) -> CellState {
        match self.search_key(key, TREE_DEPTH) {
            None => CellState::Unknown,
            Some((v, _)) if self.is_occupied_value(v) => CellState::Occupied,
            Some(_) => CellState::Free,
        }
    }

    /// Adds `delta` (log-odds) to the depth-16 cell `key` with OctoMap's
    /// `updateNode(key, log_odds_update, lazy_eval = false)` semantics: the value is
    /// clamped to `[clamp_min, clamp_max]`; a leaf already at the clamp in the update's
    /// direction is left alone; a pruned leaf on the way is expanded into eight
    /// children carrying its value; a new node starts at log-odds 0; on the way back
    /// each ancestor is pruned when its eight children are childless with equal values,
    /// otherwise it takes the maximum of its children.
    pub fn update_key(&mut self, key: &OcKey, delta: f32) {
        if let Some((v, _)) = self.search_key(key, TREE_DEPTH)
            && ((delta >= 0.0 && v >= self.model.clamp_max) || (delta <= 0.0 && v <= self.model.clamp_min))
        {
            return;
        }
        self.max_likelihood_pruned = false;
        let mut just_created = false;
        if self.root.is_none() {
            self.root = Some(Node::leaf(0.0));
            self.num_nodes += 1;
            just_created = true;
        }
        let mut path = [ROOT; TREE_DEPTH as usize + 1];
        for depth in 0..TREE_DEPTH {
            let loc = path[depth as usize];
            let node = *self.node(loc);
            let pos = child_index(key, depth);
            let mut created = false;
            let block = if !node.has_children() {
                let b = if just_created {
                    created = true;
                    self.num_nodes += 1;
                    let mut blk = Block {
                        nodes: [Node::leaf(0.0); 8],
                        mask: 1 << pos,
                    };
                    blk.nodes[pos] = Node::leaf(0.0);
                    self.alloc_block(blk)
                } else {
                    self.num_nodes += 8;
                    self.alloc_block(Block {
                        nodes: [Node::leaf(node.value); 8],
                        mask: 0xff,
                    })
                };
                self.node_mut(loc).block = b;
                b
            } else {
                let b = node.block;
                let blk = &mut self.blocks[b as usize];
                if blk.mask & (1 << pos) == 0 {
                    blk.mask |= 1 << pos;
                    blk.nodes[pos] = Node::leaf(0.0);
                    self.num_nodes += 1;
                    created = true;
                }
                b
            };
            path[depth as usize + 1] = block * 8 + pos as u32;
            just_created = created;
        }
        let (lo, hi) = (self.model.clamp_min, self.model.clamp_max);
        let leaf = self.node_mut(path[TREE_DEPTH as usize]);
        leaf.value = (leaf.value + delta).clamp(lo, hi);
        for depth in (0..TREE_DEPTH as usize).rev() {
            self.prune_or_refresh(path[depth]);
        }
    }

    /// Prunes the node at `loc` when its eight children are childless with equal values
    /// (OctoMap's `pruneNode`), otherwise sets it to the maximum child value
    /// (`updateOccupancyChildren`). Returns true when it pruned.
    pub(crate) fn prune_or_refresh(&mut self, loc: Loc) -> bool {
        let node = *self.node(loc);
        if !node.has_children() {
            return false;
        }
        let blk = &self.blocks[node.block as usize];
        let first = blk.nodes[0].value;
        let collapsible = blk.mask == 0xff && blk.nodes.iter().all(|c| !c.has_children() && c.value == first);
        if collapsible {
            self.free_blocks.push(node.block);
            self.num_nodes -= 8;
            *self.node_mut(loc) = Node::leaf(first);
            true
        } else {
            let mut m = f32::NEG_INFINITY;
            for i in 0..8 {
                if blk.mask & (1 << i) != 0 {
                    m = m.max(blk.nodes[i].value);
                }
            }
            self.node_mut(loc).value = m;
            false
        }
    }

    /// Sets every node to `clamp_max` when occupied and `clamp_min` otherwise
    /// (OctoMap's `toMaxLikelihood`), then prunes bottom-up (`prune`).
    pub fn to_max_likelihood_pruned(&mut self) {
        if self.root.is_none() {
            return;
        }
        let (lo, hi, th) = (self.model.clamp_min, self.model.clamp_max, self.model.threshold);
        let ml = |v: f32| if v > th { hi } else { lo };
        if let Some(r) = self.root.as_mut() {
            r.value = ml(r.value);
        }
        for b in self.blocks.iter_mut() {
            for n in b.nodes.iter_mut() {
                n.value = ml(n.value);
            }
        }
        // post-order over inner nodes with an explicit stack (depth ≤ 16)
        let mut stack: Vec<(Loc, u8)> = Vec::with_capacity(TREE_DEPTH as usize + 1);
        stack.push((ROOT, 0));
        while let Some(&mut (loc, ref mut next)) = stack.last_mut() {
            let node = *self.node(loc);
            if !node.has_children() {
                stack.pop();
                continue;
            }
            let mask = self.blocks[node.block as usize].mask;
            let mut pushed = false;
            while *next < 8 {
                let i = *next as usize;
                *next += 1;
                if mask & (1 << i) != 0 && self.blocks[node.block as usize].nodes[i].has_children() {
                    stack.push((node.block * 8 + i as u32, 0));
                    pushed = true;
                    break;
                }
            }
            if !pushed {
                self.prune_or_refresh(loc);
                stack.pop();
            }
        }
        self.max_likelihood_pruned = true;
    }

    /// Leaves (nodes without children) as `(occupied, free)` counts.
    pub fn leaf_counts(&self) -> (usize, usize) {
        let (mut occ, mut free) = (0, 0);
        let mut count = |n: &Node| {
            if !n.has_children() {
                if self.is_occupied_value(n.value) {
                    occ += 1;
                } else {
                    free += 1;
                }
            }
        };
        if let Some(r) = &self.root {
            count(r);
            let mut stack = vec![*r];
            while let Some(n) = stack.pop() {
                if n.has_children() {
                    let b = &self.blocks[n.block as usize];
                    for i in 0..8 {
                        if b.mask & (1 << i) != 0 {
                            count(&b.nodes[i]);
                            stack.push(b.nodes[i]);
                        }
                    }
                }
            }
        }
        (occ, free)
    }
}
