//! Bit addresses over a scan's key box in the order the tree is descended
//! (docs/octree.md#whole-frame-insertion).
//!
//! The box is widened to whole blocks of 32³ cells aligned to multiples of 32 keys
//! (each block is one depth-11 node of the tree). Blocks follow each other x fastest;
//! inside a block a cell's bit is the Morton code of its low five key bits per axis,
//! `Σ_b (bit_b(k_x) + 2·bit_b(k_y) + 4·bit_b(k_z))·8^b`. So the set bits of a bitset,
//! read in ascending order, visit each block's cells in Morton order — the depth-first
//! order of the octree below the block — and an update walk that shares its descent
//! between consecutive keys (`BatchUpdate`) enters every node of a block once.
//!
//! The address is a sum of one term per axis, `A_x(k_x) + A_y(k_y) + A_z(k_z)` with
//! `A_a(k) = ⌊(k − lo_a)/32⌋·S_a·32768 + spread(k mod 32) << a` (`S` the block strides),
//! so a walk that moves one key along one axis updates one term with one table load.

use super::key::{OcKey, unmorton};
use super::ray::CellAddress;

/// Key bits per axis inside a block.
const BLOCK_BITS: u32 = 5;
/// Cells of a block: bits of one block of the bitset.
const BLOCK_CELLS: usize = 1 << (3 * BLOCK_BITS);
/// Keys per axis.
const KEYS: usize = 1 << 16;
/// Words (u64) of one block.
pub(crate) const BLOCK_WORDS: usize = BLOCK_CELLS / 64;

/// Spreads the low five bits of `v` to every third bit (bit `b` to bit `3b`).
#[inline]
fn spread5(v: usize) -> usize {
    (0..BLOCK_BITS as usize).fold(0, |acc, b| acc | (((v >> b) & 1) << (3 * b)))
}

/// The bit addresses of a key box (module docs).
pub(crate) struct BlockGrid {
    /// Smallest key of the first block (multiples of 32).
    lo: OcKey,
    /// Blocks per axis.
    blocks: [usize; 3],
    /// Per axis, the address term `A_a` of every key (indexed by the key itself, so
    /// a lookup needs no range check; 0 outside the box). Addresses fit in u32: a
    /// dense grid has at most `ScanParams::dense_limit_cells` bits, and `new`
    /// refuses more than 2^32.
    terms: [Box<[u32; KEYS]>; 3],
}

impl BlockGrid {
    /// Cells (bits) the grid over the key box `[lo, hi]` (inclusive) would take,
    /// without building it; `None` past `usize`.
    pub(crate) fn cells_for(lo: &OcKey, hi: &OcKey) -> Option<usize> {
        (0..3).try_fold(1usize, |acc, a| {
            let n = ((hi[a] | 31) as usize - (lo[a] & !31) as usize + 1) >> BLOCK_BITS;
            acc.checked_mul(n)?.checked_mul(32)
        })
    }

    /// The grid over the key box `[lo, hi]` (inclusive, `lo ≤ hi` per axis).
    pub(crate) fn new(lo: &OcKey, hi: &OcKey) -> Self {
        let lo = lo.map(|k| k & !31);
        let blocks = [0, 1, 2].map(|a| ((hi[a] | 31) as usize - lo[a] as usize + 1) >> BLOCK_BITS);
        let strides = [1, blocks[0], blocks[0] * blocks[1]];
        assert!(
            blocks.iter().product::<usize>() * BLOCK_CELLS <= 1 << 32,
            "a dense grid holds at most 2^32 cells"
        );
        let terms = [0, 1, 2].map(|a| {
            let mut t: Box<[u32; KEYS]> = vec![0u32; KEYS]
                .into_boxed_slice()
                .try_into()
                .expect("KEYS entries");
            for i in 0..blocks[a] << BLOCK_BITS {
                t[lo[a] as usize + i] =
                    ((i >> BLOCK_BITS) * strides[a] * BLOCK_CELLS + (spread5(i & 31) << a)) as u32;
            }
            t
        });
        BlockGrid { lo, blocks, terms }
    }

    /// Bits of a bitset over the grid (a multiple of 64).
    pub(crate) fn cells(&self) -> usize {
        self.blocks.iter().product::<usize>() * BLOCK_CELLS
    }

    /// Bit address of a key in the box.
    #[inline]
    pub(crate) fn index(&self, k: &OcKey) -> usize {
        self.term(0, k[0]) + self.term(1, k[1]) + self.term(2, k[2])
    }

    /// Smallest key of block `b` (blocks x fastest).
    #[inline]
    pub(crate) fn block_base(&self, b: usize) -> OcKey {
        let (bx, by) = (self.blocks[0], self.blocks[1]);
        let c = [b % bx, (b / bx) % by, b / (bx * by)];
        [0, 1, 2].map(|a| self.lo[a] + (c[a] << BLOCK_BITS) as u16)
    }

    /// Key of bit `bit` (< 32768) of the block with smallest key `base`.
    #[inline]
    pub(crate) fn key_in_block(&self, base: &OcKey, bit: usize) -> OcKey {
        let d = unmorton((bit & (BLOCK_CELLS - 1)) as u64);
        [base[0] + d[0], base[1] + d[1], base[2] + d[2]]
    }
}

impl CellAddress for BlockGrid {
    /// Address term of key `k` along `axis`; 0 outside the grid (a walk may step one
    /// key past its end before it stops, and visits no such cell).
    #[inline]
    fn term(&self, axis: usize, k: u16) -> usize {
        self.terms[axis][k as usize] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::octree::morton;

    #[test]
    fn addresses_are_distinct_and_invert_to_their_keys() {
        // a box straddling the 32768 boundary on x and two blocks on z
        let (lo, hi) = ([32700u16, 100, 40], [32800u16, 110, 70]);
        let g = BlockGrid::new(&lo, &hi);
        // x: 32672..=32831 = 5 blocks, y: 96..=127 = 1, z: 32..=95 = 2
        assert_eq!(g.blocks, [5, 1, 2]);
        assert_eq!(g.cells(), 10 * 32768);
        assert_eq!(BlockGrid::cells_for(&lo, &hi), Some(10 * 32768));
        let mut seen = vec![false; g.cells()];
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let i = g.index(&[x, y, z]);
                    assert!(!seen[i], "address {i} twice");
                    seen[i] = true;
                    let base = g.block_base(i / 32768);
                    assert_eq!(g.key_in_block(&base, i % 32768), [x, y, z]);
                }
            }
        }
    }

    #[test]
    fn ascending_addresses_inside_a_block_are_ascending_morton_codes() {
        let g = BlockGrid::new(&[64, 64, 64], &[95, 95, 95]);
        let base = g.block_base(0);
        assert_eq!(base, [64, 64, 64]);
        let codes: Vec<u64> = (0..32768).map(|i| morton(&g.key_in_block(&base, i))).collect();
        assert!(codes.windows(2).all(|w| w[0] < w[1]));
        // bit 1 is one key along x, bit 2 along y, bit 4 along z, bit 8 two along x
        assert_eq!(g.key_in_block(&base, 1), [65, 64, 64]);
        assert_eq!(g.key_in_block(&base, 2), [64, 65, 64]);
        assert_eq!(g.key_in_block(&base, 4), [64, 64, 65]);
        assert_eq!(g.key_in_block(&base, 8), [66, 64, 64]);
    }
}
