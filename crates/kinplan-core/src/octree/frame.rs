//! Shared near field of a depth image: where each pixel's beam starts to be traced
//! when neighbouring beams already cover the cells close to the camera
//! (docs/octree.md#whole-frame-insertion).
//!
//! Close to the camera the beams of a depth image are far denser than the cells: at
//! range `r` neighbouring pixels are about `r/f` apart (`f` the focal length in
//! pixels), so at 0.05 m cells and `f ≈ 365` the beams 0.5 m away are 1.4 mm apart,
//! some 36 across each cell. Tracing all of them there marks the same cells again and
//! again. A
//! pixel lattice of stride `S` is `S·r/f` apart at range `r`; while that spacing is at
//! most `s` (the spacing parameter, below the cell size), every cell whose inscribed
//! ball (radius `res/2`) lies in the lattice's fan is crossed by some lattice beam
//! (the largest empty circle of a square lattice of spacing `s` has radius `s/√2`).
//! So each pixel is given a level `l` (its coordinates' common power-of-two factor,
//! at most [`LEVELS`]; the image's border rows and columns get the top level) and its
//! beam is traced from
//!
//! `t_start = min(s·f/2^(l+1) − m, c)`, at least 0,
//!
//! where `m = √3·res` (a cell's diagonal, the margin) and `c` is the least "clear
//! range" of the four pixels of level `> l` at the corners of the `2^(l+1)` block
//! around it: a pixel's clear range is its beam's length, lowered to its own corners'
//! clear range, so a beam ending early (a near object, a pixel without a return)
//! makes the finer beams around it start where it ends: the coarser beams no longer
//! cover what lies beyond. Beams of the top level and of the border are traced
//! whole. Cells can be lost only where a skipped stretch grazes a cell that no
//! coarser beam crosses (at a fan's edge, or where beams of very different lengths
//! meet); the insert tests and the benchmark count them against the exact insert.
//!
//! The idea of casting fewer beams where they are dense is OctoMap's `discretize`
//! (Hornung et al., "OctoMap: an efficient probabilistic 3D mapping framework based
//! on octrees", Autonomous Robots 34, 2013, §5.1); the lattice with its coverage bound
//! is this module's.

use super::Octree;

/// Pixel levels: the beams of pixels whose coordinates are both multiples of
/// `2^LEVELS`, and those of the border, are traced from the camera.
pub(crate) const LEVELS: u32 = 4;

/// One pixel's beam as the near-field rule sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PixelBeam {
    /// Length the beam covers (m): its range, `max_range` for a cut beam, 0 for a
    /// pixel without a return or a point outside the tree.
    pub covered: f32,
    /// Index of its point in the scan, `u32::MAX` when it has none.
    pub point: u32,
}

/// Start parameters (m from the camera) of the beams of a `width × height` image,
/// one per scan point (module docs). `beams` is row-major; `focal` is `min(fx, fy)`
/// in pixels; `spacing` is the lattice spacing `s` (m), `margin` the margin `m` (m).
/// Cost: one pass over the pixels per level, no allocation beyond the two outputs.
pub(crate) fn near_field_starts(
    beams: &[PixelBeam],
    width: usize,
    height: usize,
    points: usize,
    focal: f64,
    spacing: f64,
    margin: f64,
) -> Vec<f32> {
    let mut starts = vec![0f32; points];
    let mut clear: Vec<f32> = beams.iter().map(|b| b.covered).collect();
    if width < 3 || height < 3 {
        return starts;
    }
    for l in (0..LEVELS).rev() {
        let (s, big) = (1usize << l, 1usize << (l + 1));
        let nominal = spacing * focal / big as f64 - margin;
        for v in (s..height - 1).step_by(s) {
            let v0 = v & !(big - 1);
            let v1 = (v0 + big).min(height - 1);
            // pixels of level exactly l: on the s lattice, not both on the 2s one
            let (u_first, u_step) = if v % big == 0 { (s, big) } else { (s, s) };
            for u in (u_first..width - 1).step_by(u_step) {
                let u0 = u & !(big - 1);
                let u1 = (u0 + big).min(width - 1);
                let c = clear[v0 * width + u0]
                    .min(clear[v0 * width + u1])
                    .min(clear[v1 * width + u0])
                    .min(clear[v1 * width + u1]);
                let p = v * width + u;
                clear[p] = clear[p].min(c);
                let beam = beams[p];
                if beam.point != u32::MAX {
                    starts[beam.point as usize] = nominal.min(c as f64).max(0.0) as f32;
                }
            }
        }
    }
    starts
}

impl Octree {
    /// The margin `m` of [`near_field_starts`]: a cell's diagonal (m).
    pub(crate) fn near_field_margin(&self) -> f64 {
        3f64.sqrt() * self.resolution
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beams(w: usize, h: usize, range: impl Fn(usize, usize) -> f32) -> Vec<PixelBeam> {
        (0..w * h)
            .map(|i| PixelBeam {
                covered: range(i % w, i / w),
                point: i as u32,
            })
            .collect()
    }

    #[test]
    fn levels_start_where_the_coarser_lattice_is_too_sparse() {
        // 40 × 40 pixels all at 10 m, f = 100, s = 0.04, m = 0.1:
        // level l starts at 0.04·100/2^(l+1) − 0.1
        let (w, h) = (40, 40);
        let st = near_field_starts(&beams(w, h, |_, _| 10.0), w, h, w * h, 100.0, 0.04, 0.1);
        let at = |u: usize, v: usize| st[v * w + u];
        assert_eq!(at(16, 16), 0.0); // top level
        assert_eq!(at(0, 5), 0.0); // border
        assert_eq!(at(39, 5), 0.0);
        assert_eq!(at(5, 39), 0.0);
        for (u, v, l) in [
            (1, 1, 0),
            (3, 2, 0),
            (2, 2, 1),
            (6, 4, 1),
            (4, 4, 2),
            (8, 8, 3),
            (24, 8, 3),
        ] {
            let want = 0.04 * 100.0 / (1u32 << (l + 1)) as f64 - 0.1;
            assert!(
                (at(u, v) as f64 - want).abs() < 1e-6,
                "pixel ({u}, {v}) level {l}: {}",
                at(u, v)
            );
        }
    }

    #[test]
    fn a_short_corner_beam_pulls_the_finer_starts_in() {
        // pixel (16, 16) (top level) ends at 0.5 m, every other beam at 10 m;
        // f = 100, s = 0.04, m = 0.1: nominal starts 1.9, 0.9, 0.4, 0.15 for levels 0–3
        let (w, h) = (40, 40);
        let b = beams(w, h, |u, v| if (u, v) == (16, 16) { 0.5 } else { 10.0 });
        let st = near_field_starts(&b, w, h, w * h, 100.0, 0.04, 0.1);
        let at = |u: usize, v: usize| st[v * w + u] as f64;
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        // (16, 16) itself is traced whole
        assert_eq!(at(16, 16), 0.0);
        // level 3, block 16 with corner (16, 16): min(0.15, 0.5)
        assert!(near(at(8, 8), 0.15) && near(at(24, 24), 0.15));
        // level 2, block 8 with corner (16, 16): min(0.4, 0.5)
        assert!(near(at(20, 20), 0.4) && near(at(12, 12), 0.4));
        // level 1, block 4 with corner (16, 16): min(0.9, 0.5) = 0.5
        assert!(near(at(18, 18), 0.5) && near(at(14, 16), 0.5));
        // level 0, block 2 with corner (16, 16): min(1.9, 0.5) = 0.5
        assert!(near(at(17, 17), 0.5) && near(at(15, 16), 0.5));
        // through a corner of a corner: (19, 19) is level 0 in block (18|20, 18|20),
        // whose corner (18, 18) (level 1) has (16, 16) among its corners, so its clear
        // range is 0.5 too
        assert!(near(at(19, 19), 0.5));
        // far from (16, 16): (33, 1) level 0 in block (32|34, 0|2): nominal 1.9;
        // (34, 2) level 1: nominal 0.9
        assert!(near(at(33, 1), 1.9) && near(at(34, 2), 0.9));
        // a pixel without a return (clear range 0) makes its finer neighbours start at 0
        let b = beams(w, h, |u, v| if (u, v) == (8, 8) { 0.0 } else { 10.0 });
        let st = near_field_starts(&b, w, h, w * h, 100.0, 0.04, 0.1);
        assert_eq!(st[9 * w + 9], 0.0);
        assert!((st[9 * w + 25] as f64 - 1.9).abs() < 1e-6);
    }
}
