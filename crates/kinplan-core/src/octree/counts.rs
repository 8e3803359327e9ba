//! Known depth-16 cells below every node, built in one pass, so that a query can
//! take the unknown volume of a whole subtree in closed form (docs/exploration.md#information-gain:
//! the frustum count of unknown cells).

use super::key::TREE_DEPTH;
use super::tree::{Node, NodeRef, Octree};

/// `known(n)` for every node `n` of one tree: the depth-16 cells covered by leaves in
/// the subtree of `n`, `known(leaf at depth d) = 8^(16−d)`, `known(inner) = Σ known(child)`.
/// The unknown cells of a node's cube at depth d are then `8^(16−d) − known(n)`.
/// Stored per block of eight siblings (one `u64` per child slot, 64 bytes per block),
/// valid for the tree it was built from while that tree is not changed.
#[derive(Debug, Clone, Default)]
pub struct KnownCellCounts {
    root: u64,
    blocks: Vec<[u64; 8]>,
}

impl KnownCellCounts {
    /// One pass over `tree` (an explicit stack, at most 16 levels deep).
    pub fn new(tree: &Octree) -> Self {
        let mut blocks = vec![[0u64; 8]; tree.blocks.len()];
        let Some(root) = tree.root else {
            return Self { root: 0, blocks };
        };
        // post-order: (node, depth, parent's block and slot, children pushed)
        let top = u32::MAX;
        let mut stack: Vec<(Node, u8, u32, u8, bool)> = Vec::with_capacity(8 * (TREE_DEPTH as usize + 1));
        stack.push((root, 0, top, 0, false));
        let mut root_count = 0u64;
        while let Some(&(n, d, pb, slot, pushed)) = stack.last() {
            if !n.has_children() {
                stack.pop();
                continue;
            }
            let b = &tree.blocks[n.block as usize];
            if !pushed {
                stack.last_mut().expect("non-empty").4 = true;
                for (i, &c) in b.nodes.iter().enumerate() {
                    if b.mask & (1 << i) == 0 {
                        continue;
                    }
                    if c.has_children() {
                        stack.push((c, d + 1, n.block, i as u8, false));
                    } else {
                        blocks[n.block as usize][i] = 1u64 << (3 * TREE_DEPTH.saturating_sub(d + 1) as u32);
                    }
                }
                continue;
            }
            stack.pop();
            // children done: their sum goes into the parent's slot (or the root)
            let sum: u64 = blocks[n.block as usize].iter().sum();
            if pb == top {
                root_count = sum;
            } else {
                blocks[pb as usize][slot as usize] = sum;
            }
        }
        if !root.has_children() {
            root_count = 1u64 << (3 * TREE_DEPTH as u32);
        }
        Self {
            root: root_count,
            blocks,
        }
    }

    /// Known cells below the root (0 for an empty tree).
    #[inline]
    pub fn root(&self) -> u64 {
        self.root
    }

    /// Known cells below child `i` of `n` (0 when `n` is a leaf or the child is absent).
    #[inline]
    pub fn child(&self, n: NodeRef, i: usize) -> u64 {
        if !n.0.has_children() || i >= 8 {
            return 0;
        }
        self.blocks.get(n.0.block as usize).map_or(0, |b| b[i])
    }
}
