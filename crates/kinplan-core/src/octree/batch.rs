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

    /// Adds `delta` (log-odds) to the depth-16 cell `key` with the rule of
    /// [`Octree::update_key`]; returns false when the cell was already at the clamp
    /// in the update's direction (nothing changed).
    pub(crate) fn update(&mut self, tree: &mut Octree, key: &OcKey, delta: f32) -> bool {
        // the nodes both keys share: depths 0..=shared
        let shared = match self.depth {
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
        };
        self.leave(tree, shared + 1);
        self.key = *key;
        let (lo, hi) = (tree.model.clamp_min, tree.model.clamp_max);
        let at_clamp = |v: f32| (delta >= 0.0 && v >= hi) || (delta <= 0.0 && v <= lo);
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
        for depth in shared..TREE_DEPTH {
            let loc = self.path[depth as usize];
            let node = *tree.node(loc);
            let pos = child_index(key, depth);
            let mut created = false;
            let block = if !node.has_children() {
                if just_created {
                    created = true;
                    tree.num_nodes += 1;
                    let mut blk = Block {
                        nodes: [Node::leaf(0.0); 8],
                        mask: 1 << pos,
                    };
                    blk.nodes[pos] = Node::leaf(0.0);
                    tree.alloc_block(blk)
                } else {
                    // a pruned leaf above depth 16: its value is the cell's
                    if at_clamp(node.value) {
                        return false;
                    }
                    tree.num_nodes += 8;
                    tree.alloc_block(Block {
                        nodes: [Node::leaf(node.value); 8],
                        mask: 0xff,
                    })
                }
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
            if !node.has_children() {
                tree.node_mut(loc).block = block;
            }
            self.path[depth as usize + 1] = block * 8 + pos as u32;
            self.depth = Some(depth + 1);
            just_created = created;
        }
        let leaf = tree.node_mut(self.path[TREE_DEPTH as usize]);
        if !just_created && at_clamp(leaf.value) {
            return false;
        }
        leaf.value = (leaf.value + delta).clamp(lo, hi);
        tree.max_likelihood_pruned = false;
        true
    }
}
