//! Known depth-16 cells below every node, built in one pass, so that a query can
//! take the unknown volume of a whole subtree in closed form (docs/exploration.md#information-gain:
//! the frustum count of unknown cells).

use super::key::TREE_DEPTH;
use super::tree::{Node, Octree};

/// The eight children of one inner node as a walk needs them: per child slot the
/// known cells below it and what it is ([`CountBlock::ABSENT`], [`CountBlock::LEAF`] or the index of its own
/// block in [`KnownCellCounts::block`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(C, align(32))]
pub struct CountBlock {
    /// Known depth-16 cells below each child (0 when absent).
    pub known: [u64; 8],
    /// Each child: [`CountBlock::ABSENT`], [`CountBlock::LEAF`] or a block index.
    pub child: [u32; 8],
}

impl CountBlock {
    /// A child slot that holds no node: unknown space.
    pub const ABSENT: u32 = u32::MAX;
    /// A child slot that holds a leaf: every cell below it is known.
    pub const LEAF: u32 = u32::MAX - 1;
}

/// `known(n)` for every node `n` of one tree: the depth-16 cells covered by leaves in
/// the subtree of `n`, `known(leaf at depth d) = 8^(16−d)`, `known(inner) = Σ known(child)`.
/// The unknown cells of a node's cube at depth d are then `8^(16−d) − known(n)`.
///
/// A copy of the tree's shape without the values, one [`CountBlock`] per inner node,
/// laid out in the order a depth-first walk that visits child 7 first meets them (a
/// block's first child subtree follows it in memory), so that a walk reads mostly
/// forward. Valid for the tree it was built from while that tree is not changed.
#[derive(Debug, Clone, Default)]
pub struct KnownCellCounts {
    root: u64,
    root_child: u32,
    blocks: Vec<CountBlock>,
}

impl KnownCellCounts {
    /// Two passes over the inner nodes of `tree`: one assigns the walk order (an
    /// explicit stack), one sums the known cells from the last block back to the
    /// first (a child's block always comes after its parent's).
    pub fn new(tree: &Octree) -> Self {
        let Some(root) = tree.root else {
            return Self {
                root: 0,
                root_child: CountBlock::ABSENT,
                blocks: Vec::new(),
            };
        };
        if !root.has_children() {
            return Self {
                root: 1u64 << (3 * TREE_DEPTH as u32),
                root_child: CountBlock::LEAF,
                blocks: Vec::new(),
            };
        }
        let inner = tree.blocks.len().saturating_sub(tree.free_blocks.len());
        let mut blocks: Vec<CountBlock> = Vec::with_capacity(inner);
        // depth of each block's children
        let mut depth: Vec<u8> = Vec::with_capacity(inner);
        // (tree node, its depth, parent's new block and slot)
        let top = u32::MAX;
        let mut stack: Vec<(Node, u8, u32, u8)> = Vec::with_capacity(8 * (TREE_DEPTH as usize + 1));
        stack.push((root, 0, top, 0));
        while let Some((n, d, pb, slot)) = stack.pop() {
            let id = blocks.len() as u32;
            if pb != top {
                blocks[pb as usize].child[slot as usize] = id;
            }
            let b = &tree.blocks[n.block as usize];
            let mut cb = CountBlock {
                known: [0; 8],
                child: [CountBlock::ABSENT; 8],
            };
            for (i, c) in b.nodes.iter().enumerate() {
                if b.mask & (1 << i) == 0 {
                    continue;
                }
                if c.has_children() {
                    stack.push((*c, d + 1, id, i as u8));
                } else {
                    cb.child[i] = CountBlock::LEAF;
                }
            }
            blocks.push(cb);
            depth.push(d + 1);
        }
        for id in (0..blocks.len()).rev() {
            let full = 1u64 << (3 * TREE_DEPTH.saturating_sub(depth[id]) as u32);
            for i in 0..8 {
                let k = match blocks[id].child[i] {
                    CountBlock::ABSENT => 0,
                    CountBlock::LEAF => full,
                    c => blocks[c as usize].known.iter().sum(),
                };
                blocks[id].known[i] = k;
            }
        }
        Self {
            root: blocks[0].known.iter().sum(),
            root_child: 0,
            blocks,
        }
    }

    /// Known cells below the root (0 for an empty tree).
    #[inline]
    pub fn root(&self) -> u64 {
        self.root
    }

    /// What the root is: [`CountBlock::ABSENT`] (empty tree), [`CountBlock::LEAF`] or the block of its children (0).
    #[inline]
    pub fn root_child(&self) -> u32 {
        self.root_child
    }

    /// The children of the inner node whose block is `id` (from [`root_child`](Self::root_child)
    /// or a [`CountBlock::child`]).
    #[inline]
    pub fn block(&self, id: u32) -> &CountBlock {
        &self.blocks[id as usize]
    }
}
