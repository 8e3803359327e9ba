//! OctoMap's discrete addressing: keys, child indices and key ↔ coordinate maps
//! (docs/octree.md#layout-and-keys).

/// Levels below the root; a key has 16 bits per axis.
pub const TREE_DEPTH: u8 = 16;
/// Key of the cell whose lower corner is the origin: `2^15`.
pub const TREE_MAX_VAL: i32 = 32768;

/// A cell address at depth 16: one `u16` per axis, `k = ⌊c · (1/res)⌋ + 32768`.
pub type OcKey = [u16; 3];

/// Index (0–7) of the child containing `key` below a node at depth `depth` (0 = root):
/// bit `15 − depth` of the x, y, z keys gives `x + 2y + 4z`.
#[inline]
pub fn child_index(key: &OcKey, depth: u8) -> usize {
    let bit = 15 - depth as u32;
    (((key[0] >> bit) & 1) | (((key[1] >> bit) & 1) << 1) | (((key[2] >> bit) & 1) << 2)) as usize
}

/// Key of one axis as OctoMap's `coordToKeyChecked` computes it: `⌊c · f⌋ + 32768`
/// with `f = 1/res` in f64; `None` outside `[0, 65536)`.
#[inline]
pub fn coord_to_key_axis(c: f64, resolution_factor: f64) -> Option<u16> {
    let s = c * resolution_factor;
    // ⌊s⌋ ∈ [−32768, 32768) ⇔ s ∈ [−32768, 32768); NaN fails both
    if !(s >= -(TREE_MAX_VAL as f64) && s < TREE_MAX_VAL as f64) {
        return None;
    }
    Some((floor_to_i32(s) + TREE_MAX_VAL) as u16)
}

/// `⌊s⌋` for `|s| < 2^51` without a libm call (any other `s`, NaN included, gives
/// some value and no panic): adding 1.5·2^52 rounds s to the nearest integer n (exact
/// for |s| < 2^51) and leaves n in the low bits of the sum's mantissa, in two's
/// complement (the mantissa is 2^51 + n); removing it again gives n as a float, and
/// ⌊s⌋ is one less where n > s. Reading n from the bits spares the saturating
/// float-to-int conversion.
#[inline(always)]
pub(crate) fn floor_to_i32(s: f64) -> i32 {
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let y = s + ROUND;
    let n = y.to_bits() as u32 as i32;
    n.wrapping_sub((y - ROUND > s) as i32)
}

/// Centre of a depth-16 key along one axis (m): `(k − 32768 + ½) · res`.
#[inline]
pub fn key_to_coord_axis(k: u16, resolution: f64) -> f64 {
    ((k as i32 - TREE_MAX_VAL) as f64 + 0.5) * resolution
}

/// Centre of the depth-`depth` cell containing key `k` along one axis (m), as
/// OctoMap's `keyToCoord(key, depth)`: the cell spans `2^(16−depth)` keys.
#[inline]
pub fn key_to_coord_axis_at(k: u16, depth: u8, resolution: f64) -> f64 {
    if depth == 0 {
        return 0.0;
    }
    if depth >= TREE_DEPTH {
        return key_to_coord_axis(k, resolution);
    }
    let shift = (TREE_DEPTH - depth) as u32;
    let base = ((k as i32) >> shift) << shift;
    let half = 1i32 << (shift - 1);
    ((base + half - TREE_MAX_VAL) as f64) * resolution
}

/// `key` with its lowest `16 − depth` bits cleared: the smallest key of the
/// depth-`depth` cell containing it.
#[inline]
pub fn key_at_depth(key: &OcKey, depth: u8) -> OcKey {
    if depth >= TREE_DEPTH {
        return *key;
    }
    let shift = (TREE_DEPTH - depth) as u32;
    let mask = if shift >= 16 {
        0
    } else {
        (0xffffu32 << shift) as u16
    };
    [key[0] & mask, key[1] & mask, key[2] & mask]
}

/// Key of the child `i` of the cell with smallest key `base` at depth `depth`.
#[inline]
pub fn child_key(base: &OcKey, depth: u8, i: usize) -> OcKey {
    let bit = 1u16 << (15 - depth as u32);
    [
        base[0] | if i & 1 != 0 { bit } else { 0 },
        base[1] | if i & 2 != 0 { bit } else { 0 },
        base[2] | if i & 4 != 0 { bit } else { 0 },
    ]
}

/// Probability → log-odds `ln(p / (1 − p))`, as OctoMap computes it (f32).
#[inline]
pub fn logodds(p: f64) -> f32 {
    (p / (1.0 - p)).ln() as f32
}

/// Log-odds → probability `1 − 1/(1 + eˡ)`.
#[inline]
pub fn probability(l: f32) -> f64 {
    1.0 - 1.0 / (1.0 + (l as f64).exp())
}

/// Morton code of a key (x in bit 0): sorting by it makes successive updates share
/// their path from the root.
#[inline]
pub(crate) fn morton(k: &OcKey) -> u64 {
    #[inline]
    fn spread(v: u16) -> u64 {
        let mut x = v as u64;
        x = (x | (x << 32)) & 0x001F_0000_0000_FFFF;
        x = (x | (x << 16)) & 0x001F_0000_FF00_00FF;
        x = (x | (x << 8)) & 0x100F_00F0_0F00_F00F;
        x = (x | (x << 4)) & 0x10C3_0C30_C30C_30C3;
        x = (x | (x << 2)) & 0x1249_2492_4924_9249;
        x
    }
    spread(k[0]) | (spread(k[1]) << 1) | (spread(k[2]) << 2)
}

#[inline]
pub(crate) fn unmorton(m: u64) -> OcKey {
    #[inline]
    fn squeeze(mut x: u64) -> u16 {
        x &= 0x1249_2492_4924_9249;
        x = (x ^ (x >> 2)) & 0x10C3_0C30_C30C_30C3;
        x = (x ^ (x >> 4)) & 0x100F_00F0_0F00_F00F;
        x = (x ^ (x >> 8)) & 0x001F_0000_FF00_00FF;
        x = (x ^ (x >> 16)) & 0x001F_0000_0000_FFFF;
        x = (x ^ (x >> 32)) & 0x001F_FFFF;
        x as u16
    }
    [squeeze(m), squeeze(m >> 1), squeeze(m >> 2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_octomap_formula() {
        let f = 1.0 / 0.1;
        // ⌊0.05·10⌋ = 0 → 32768; ⌊−0.05·10⌋ = −1 → 32767; ⌊1.23·10⌋ = 12 → 32780
        assert_eq!(coord_to_key_axis(0.05, f), Some(32768));
        assert_eq!(coord_to_key_axis(-0.05, f), Some(32767));
        assert_eq!(coord_to_key_axis(1.23, f), Some(32780));
        assert_eq!(coord_to_key_axis(-3276.8, f), Some(0));
        assert_eq!(coord_to_key_axis(3276.8, f), None);
        assert_eq!(coord_to_key_axis(f64::NAN, f), None);
        assert!((key_to_coord_axis(32780, 0.1) - 1.25).abs() < 1e-12);
        assert!((key_to_coord_axis(32767, 0.1) + 0.05).abs() < 1e-12);
    }

    #[test]
    fn keys_floor_like_libm_at_halves_integers_and_tiny_negatives() {
        // the key is ⌊c·f⌋ + 32768; f64::floor (libm) is the reference
        let f = 20.0;
        let mut cs: Vec<f64> = vec![
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            -1e-30,
            2.5 / f,
            3.5 / f,
            -2.5 / f,
            -3.5 / f,
        ];
        for k in -40..40 {
            let c = k as f64 / f;
            cs.extend([c, c.next_up(), c.next_down(), (c as f32) as f64]);
        }
        cs.extend([-1638.4, 1638.3999, -1638.3999]);
        // and a spread over the whole cube, fractions of every size (a fixed LCG)
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            cs.push((u * 2.0 - 1.0) * 1638.39);
        }
        for c in cs {
            let want = ((c * f).floor() as i32 + TREE_MAX_VAL) as u16;
            assert_eq!(coord_to_key_axis(c, f), Some(want), "c = {c:e}");
        }
    }

    #[test]
    fn child_index_reads_bit_15_minus_depth() {
        // key x = 32768 (bit 15 set), y = 0, z = 32768 + 1 (bits 15 and 0)
        let k = [32768u16, 0, 32769];
        assert_eq!(child_index(&k, 0), 1 + 4);
        assert_eq!(child_index(&k, 15), 4);
        assert_eq!(child_index(&k, 7), 0);
    }

    #[test]
    fn coarse_cell_centres() {
        // depth 15 cell of key 32768 spans keys 32768–32769: centre at 1 · res
        assert!((key_to_coord_axis_at(32769, 15, 0.1) - 0.1).abs() < 1e-12);
        // depth 1 cell of key 40000 spans keys 32768–65535: centre at 16384 · res
        assert!((key_to_coord_axis_at(40000, 1, 0.1) - 1638.4).abs() < 1e-9);
        assert_eq!(key_at_depth(&[40001, 7, 65535], 14), [40000, 4, 65532]);
        assert_eq!(child_key(&[40000, 4, 65532], 14, 5), [40002, 4, 65534]);
    }

    #[test]
    fn logodds_of_defaults() {
        assert!((logodds(0.7) - 0.847_297_9).abs() < 1e-6);
        assert!((probability(logodds(0.4)) - 0.4).abs() < 1e-6);
    }

    #[test]
    fn morton_round_trips() {
        for k in [[0u16, 0, 0], [65535, 1, 32768], [12345, 54321, 7]] {
            assert_eq!(unmorton(morton(&k)), k);
        }
        assert_eq!(morton(&[1, 0, 0]), 1);
        assert_eq!(morton(&[0, 1, 0]), 2);
        assert_eq!(morton(&[0, 0, 1]), 4);
        assert_eq!(morton(&[2, 0, 0]), 8);
        assert_eq!(
            morton(&[0xffff, 0, 0]),
            0x1249_2492_4924_9249 & ((1u64 << 48) - 1)
        );
    }
}
