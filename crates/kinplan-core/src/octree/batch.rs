//! Many cell updates in a row with the descent shared between consecutive keys
//! (docs/octree.md#values-and-updates).
//!
//! [`Octree::update_key`] walks from the root to depth 16 and back for every key,
//! pruning or refreshing all sixteen ancestors each time. Keys that follow each other
//! in a scan's update set share most of that path (two keys share the nodes down to
//! the depth of their first differing key bit), so the batch keeps the last path,
//! descends only below the shared part, and prunes or refreshes an ancestor once,
//! when the walk leaves it. The tree that comes out is the one of the same
//! `update_key` calls in the same order: a search reads only leaves, whose values the
//! deferred refresh does not touch; a node the per-key rule would have pruned and
//! then expanded again for a later key ends with the same childless children of the
//! same value; and every node left is pruned or refreshed bottom-up, children first,
//! as the per-key rule leaves it.

use super::Octree;
use super::key::{OcKey, TREE_DEPTH, child_index};
use super::tree::{Block, Loc, Node, ROOT};

/// The walk's state between two updates (see the module docs).
pub(crate) struct BatchUpdate {
    /// Nodes of the last key's path by depth, valid down to `depth`.
    path: [Loc; TREE_DEPTH as usize + 1],
    key: OcKey,
    /// Deepest valid entry of `path`; `None` before the first update.
    depth: Option<u8>,
}

impl BatchUpdate {
    pub(crate) fn new() -> Self {
        BatchUpdate {
            path: [ROOT; TREE_DEPTH as usize + 1],
            key: [0; 3],
            depth: None,
        }
    }

    /// Prunes or refreshes the nodes of the last path below depth `keep` (deepest first).
    fn leave(&mut self, tree: &mut Octree, keep: u8) {
        if let Some(d) = self.depth {
            let deepest = d.min(TREE_DEPTH - 1);
            for depth in (keep..=deepest).rev() {
                tree.prune_or_refresh(self.path[depth as usize]);
            }
            self.depth = if keep == 0 { None } else { Some(d.min(keep - 1)) };
        }
    }

    /// Finishes the batch: every node on the last path is pruned or refreshed.
    pub(crate) fn finish(&mut self, tree: &mut Octree) {
        self.leave(tree, 0);
    }

    /// Updates the cells below one depth-15 node, its children `i` (`x + 2y + 4z`)
    /// with bit `i` of `free` (by `miss`) or of `occupied` (by `hit`; the two masks
    /// disjoint), in ascending child order: the tree of one [`update`](Self::update)
    /// per cell in that order. `first` is the key of child 0 (lowest key bit clear on
    /// every axis). The descent to the depth-15 node is shared by the siblings; a
    /// pruned leaf above depth 15 (whose expansion depends on each cell's update)
    /// hands the cells to `update` one by one.
    pub(crate) fn update_siblings(
        &mut self,
        tree: &mut Octree,
        first: &OcKey,
        free: u8,
        occupied: u8,
        hit: f32,
        miss: f32,
    ) {
        const PARENT: u8 = TREE_DEPTH - 1;
        let child = |pos: u32| {
            [
                first[0] | (pos & 1) as u16,
                first[1] | (pos >> 1 & 1) as u16,
                first[2] | (pos >> 2) as u16,
            ]
        };
        let delta = |pos: u32| if occupied >> pos & 1 != 0 { hit } else { miss };
        let shared = self.shared_depth(first);
        self.leave(tree, shared + 1);
        self.key = *first;
        let mut just_created = self.enter_root(tree);
        for depth in shared..PARENT {
            let loc = self.path[depth as usize];
            let node = *tree.node(loc);
            if !node.has_children() && !just_created {
                // a pruned leaf: whether it expands depends on each cell's update
                let mut cells = free | occupied;
                while cells != 0 {
                    let pos = cells.trailing_zeros();
                    cells &= cells - 1;
                    self.update(tree, &child(pos), delta(pos));
                }
                return;
            }
            just_created = self.step_down(tree, loc, node, child_index(first, depth), depth, just_created);
        }
        let (lo, hi) = (tree.model.clamp_min, tree.model.clamp_max);
        let loc = self.path[PARENT as usize];
        let cells = free | occupied;
        let last = 7 - cells.leading_zeros();
        let node = *tree.node(loc);
        if node.has_children() || just_created {
            // the children exist or are all created here (at 0): each one's rule in
            // turn without a change of path, which ends at the last child
            let block = if node.has_children() {
                node.block
            } else {
                tree.num_nodes += cells.count_ones() as usize;
                let block = tree.alloc_block(Block {
                    nodes: [Node::leaf(0.0); 8],
                    mask: 0,
                });
                tree.node_mut(loc).block = block;
                block
            };
            let blk = &mut tree.blocks[block as usize];
            let mut left = cells;
            while left != 0 {
                let pos = left.trailing_zeros() as usize;
                left &= left - 1;
                let d = delta(pos as u32);
                let leaf = &mut blk.nodes[pos];
                if blk.mask & (1 << pos) == 0 {
                    blk.mask |= 1 << pos;
                    *leaf = Node::leaf(0.0);
                    tree.num_nodes += usize::from(node.has_children());
                } else if (d >= 0.0 && leaf.value >= hi) || (d <= 0.0 && leaf.value <= lo) {
                    continue;
                }
                leaf.value = (leaf.value + d).clamp(lo, hi);
                tree.max_likelihood_pruned = false;
            }
            self.path[TREE_DEPTH as usize] = block * 8 + last;
            self.depth = Some(TREE_DEPTH);
            self.key = child(last);
            return;
        }
        // a pruned depth-15 leaf: it expands for the first cell not at the clamp
        let mut left = cells;
        while left != 0 {
            let pos = left.trailing_zeros();
            left &= left - 1;
            let d = delta(pos);
            let at_clamp = |v: f32| (d >= 0.0 && v >= hi) || (d <= 0.0 && v <= lo);
            self.key = child(pos);
            let node = *tree.node(loc);
            if !node.has_children() && at_clamp(node.value) {
                self.depth = Some(PARENT);
                continue;
            }
            self.step_down(tree, loc, node, pos as usize, PARENT, false);
            let leaf = tree.node_mut(self.path[TREE_DEPTH as usize]);
            if at_clamp(leaf.value) {
                continue;
            }
            leaf.value = (leaf.value + d).clamp(lo, hi);
            tree.max_likelihood_pruned = false;
        }
    }

    /// Adds `delta` (log-odds) to the depth-16 cell `key` with the rule of
    /// [`Octree::update_key`]; returns false when the cell was already at the clamp
    /// in the update's direction (nothing changed).
    pub(crate) fn update(&mut self, tree: &mut Octree, key: &OcKey, delta: f32) -> bool {
        let shared = self.shared_depth(key);
        self.leave(tree, shared + 1);
        self.key = *key;
        let (lo, hi) = (tree.model.clamp_min, tree.model.clamp_max);
        let at_clamp = |v: f32| (delta >= 0.0 && v >= hi) || (delta <= 0.0 && v <= lo);
        let mut just_created = self.enter_root(tree);
        for depth in shared..TREE_DEPTH {
            let loc = self.path[depth as usize];
            let node = *tree.node(loc);
            // a pruned leaf above depth 16: its value is the cell's
            if !node.has_children() && !just_created && at_clamp(node.value) {
                return false;
            }
            just_created = self.step_down(tree, loc, node, child_index(key, depth), depth, just_created);
        }
        let leaf = tree.node_mut(self.path[TREE_DEPTH as usize]);
        if !just_created && at_clamp(leaf.value) {
            return false;
        }
        leaf.value = (leaf.value + delta).clamp(lo, hi);
        tree.max_likelihood_pruned = false;
        true
    }

    /// The depth down to which the last path is also `key`'s (the nodes both share:
    /// depths 0..=shared, at most the path's deepest valid entry); 0 before the first
    /// update.
    #[inline]
    fn shared_depth(&self, key: &OcKey) -> u8 {
        match self.depth {
            Some(d) => {
                let common = self
                    .key
                    .iter()
                    .zip(key)
                    .map(|(a, b)| (a ^ b).leading_zeros() as u8)
                    .fold(TREE_DEPTH, u8::min);
                common.min(d)
            }
            None => 0,
        }
    }

    /// Starts the path at the root when none is held, creating the root (value 0) in
    /// an empty tree; true when it was just created.
    #[inline]
    fn enter_root(&mut self, tree: &mut Octree) -> bool {
        let mut just_created = false;
        if self.depth.is_none() {
            if tree.root.is_none() {
                tree.root = Some(Node::leaf(0.0));
                tree.num_nodes += 1;
                just_created = true;
            }
            self.path[0] = ROOT;
            self.depth = Some(0);
        }
        just_created
    }

    /// Moves the path from `node` (at `loc`, depth `depth`) to its child `pos`: a
    /// missing child is created at value 0, a childless node gets a block of
    /// children (only `pos` when the node was `just_created`, otherwise all eight
    /// at the node's value: a pruned leaf expanded). True when the child was created.
    #[inline]
    fn step_down(
        &mut self,
        tree: &mut Octree,
        loc: Loc,
        node: Node,
        pos: usize,
        depth: u8,
        just_created: bool,
    ) -> bool {
        let mut created = false;
        let block = if !node.has_children() {
            let block = if just_created {
                created = true;
                tree.num_nodes += 1;
                tree.alloc_block(Block {
                    nodes: [Node::leaf(0.0); 8],
                    mask: 1 << pos,
                })
            } else {
                tree.num_nodes += 8;
                tree.alloc_block(Block {
                    nodes: [Node::leaf(node.value); 8],
                    mask: 0xff,
                })
            };
            tree.node_mut(loc).block = block;
            block
        } else {
            let b = node.block;
            let blk = &mut tree.blocks[b as usize];
            if blk.mask & (1 << pos) == 0 {
                blk.mask |= 1 << pos;
                blk.nodes[pos] = Node::leaf(0.0);
                tree.num_nodes += 1;
                created = true;
            }
            b
        };
        self.path[depth as usize + 1] = block * 8 + pos as u32;
        self.depth = Some(depth + 1);
        created
    }
}
