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
//! The lattices come in steps of √2 in spacing: for `a = 2^l` the square lattice
//! `L_l` of stride `a`, and between `L_(l+1)` and `L_l` the quincunx lattice `Q_l`
//! (`L_(l+1)` and the centres of its squares, spacing `√2·a`, largest empty circle
//! of radius `a`). A pixel of level `l` (its coordinates' common power-of-two factor,
//! at most [`LEVELS`]; the image's border rows and columns get the top level) is a
//! *diagonal* pixel when `u/a` and `v/a` are both odd (a centre, in `Q_l`) and an
//! *edge* pixel otherwise (in `L_l` only). Its beam is traced from
//!
//! `t_start = min(s·f/2^(l+1) − m, c)` (diagonal), `min(s·f/(√2·2^l) − m, c)` (edge),
//! at least 0,
//!
//! the ranges where `L_(l+1)`, respectively `Q_l`, becomes sparser than `s`, less
//! the margin `m = √3·res` (a cell's diagonal). `c` is the least clear range of the
//! four beams around the pixel in the coarser lattice: the corners `(u ± a, v ± a)`
//! of the square a diagonal pixel centres, the corners `(u ± a, v)`, `(u, v ± a)` of
//! the diamond an edge pixel centres. A beam's length is its range, `max_range` for
//! a cut beam, 0 without a return (or for a point outside the tree); its clear
//! range is its length, or 0 when one of its own four corners has no beam. So a
//! beam ending early (a near object) makes the finer beams around it start where it
//! ends, since the coarser lattice no longer covers what lies beyond, and a missing
//! beam, a hole in the coarser lattice at every range, makes the finer beams around
//! it and around those traced from the camera. Beams of the top level and of the
//! border are traced
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
/// Cost: one pass over the pixels per level, no allocation beyond the output.
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
    if width < 3 || height < 3 {
        return starts;
    }
    // per pixel its length and its clear range, side by side
    let mut lc: Vec<[f32; 2]> = beams.iter().map(|b| [b.covered; 2]).collect();
    let (w, last_u, last_v) = (width, width - 1, height - 1);
    for l in (0..LEVELS).rev() {
        let (a, big) = (1usize << l, 1usize << (l + 1));
        // diagonal pixels (u/a, v/a both odd): the centres of the squares of L_(l+1)
        let nominal = spacing * focal / big as f64 - margin;
        for v in (a..last_v).step_by(big) {
            let (r0, r1) = ((v - a) * w, (v + a).min(last_v) * w);
            for u in (a..last_u).step_by(big) {
                let (u0, u1) = (u - a, (u + a).min(last_u));
                let corners = [r0 + u0, r0 + u1, r1 + u0, r1 + u1];
                settle(&mut lc, beams, &mut starts, v * w + u, corners, nominal);
            }
        }
        // edge pixels (one of u/a, v/a odd): the centres of the diamonds of Q_l
        let nominal = spacing * focal / (std::f64::consts::SQRT_2 * a as f64) - margin;
        for v in (a..last_v).step_by(a) {
            let u_first = if (v / a) % 2 == 1 { big } else { a };
            let (r, r0, r1) = (v * w, (v - a) * w, (v + a).min(last_v) * w);
            for u in (u_first..last_u).step_by(big) {
                let corners = [r + u - a, r + (u + a).min(last_u), r0 + u, r1 + u];
                settle(&mut lc, beams, &mut starts, r + u, corners, nominal);
            }
        }
    }
    starts
}

/// Pixel `i`'s start from its four `corners` (pixel indices) and the nominal start
/// of its kind, and its clear range: 0 when a corner has no beam (length 0).
#[inline(always)]
fn settle(
    lc: &mut [[f32; 2]],
    beams: &[PixelBeam],
    starts: &mut [f32],
    i: usize,
    corners: [usize; 4],
    nominal: f64,
) {
    let (mut direct, mut c) = (f32::INFINITY, f32::INFINITY);
    for j in corners {
        let [length, clear] = lc[j];
        direct = direct.min(length);
        c = c.min(clear);
    }
    if direct <= 0.0 {
        lc[i][1] = 0.0;
    }
    let p = beams[i].point;
    if p != u32::MAX {
        starts[p as usize] = nominal.min(c as f64).max(0.0) as f32;
    }
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
        // 40 × 40 pixels all at 10 m, f = 100, s = 0.04, m = 0.1: a diagonal pixel of
        // level l starts at 4/2^(l+1) − 0.1, an edge pixel at 4/(√2·2^l) − 0.1
        let (w, h) = (40, 40);
        let st = near_field_starts(&beams(w, h, |_, _| 10.0), w, h, w * h, 100.0, 0.04, 0.1);
        let at = |u: usize, v: usize| st[v * w + u] as f64;
        assert_eq!(at(16, 16), 0.0); // top level
        assert_eq!(at(0, 5), 0.0); // border
        assert_eq!(at(39, 5), 0.0);
        assert_eq!(at(5, 39), 0.0);
        let diagonal = [1.9, 0.9, 0.4, 0.15];
        let edge = [2.728_427_1, 1.314_213_6, 0.607_106_8, 0.253_553_4];
        for (u, v, want) in [
            (1, 1, diagonal[0]),
            (3, 5, diagonal[0]),
            (3, 2, edge[0]),
            (2, 7, edge[0]),
            (2, 2, diagonal[1]),
            (6, 4, edge[1]),
            (4, 6, edge[1]),
            (4, 4, diagonal[2]),
            (8, 4, edge[2]),
            (8, 8, diagonal[3]),
            (24, 8, diagonal[3]),
            (16, 8, edge[3]),
            (8, 32, edge[3]),
        ] {
            assert!(
                (at(u, v) - want).abs() < 1e-6,
                "pixel ({u}, {v}): {} != {want}",
                at(u, v)
            );
        }
    }

    #[test]
    fn a_short_corner_beam_pulls_the_finer_starts_in() {
        // pixel (16, 16) (top level) ends at 0.5 m, every other beam at 10 m;
        // f = 100, s = 0.04, m = 0.1: nominal starts 1.9, 0.9, 0.4, 0.15 (diagonal)
        // and 2.728, 1.314, 0.607, 0.254 (edge) for levels 0–3
        let (w, h) = (40, 40);
        let b = beams(w, h, |u, v| if (u, v) == (16, 16) { 0.5 } else { 10.0 });
        let st = near_field_starts(&b, w, h, w * h, 100.0, 0.04, 0.1);
        let at = |u: usize, v: usize| st[v * w + u] as f64;
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        // (16, 16) itself is traced whole
        assert_eq!(at(16, 16), 0.0);
        // level 3 diagonal (8, 8): square corners (0|16, 0|16): min(0.15, 0.5)
        assert!(near(at(8, 8), 0.15) && near(at(24, 24), 0.15));
        // level 3 edge (16, 8): diamond corners (8, 8), (24, 8), (16, 0), (16, 16)
        assert!(near(at(16, 8), 0.253_553_4));
        // level 2 diagonal (12, 12): min(0.4, 0.5); edge (16, 12): min(0.607, 0.5)
        assert!(near(at(12, 12), 0.4) && near(at(20, 20), 0.4));
        assert!(near(at(16, 12), 0.5) && near(at(20, 16), 0.5));
        // level 1 diagonal (18, 18) and edge (16, 14): 0.5
        assert!(near(at(18, 18), 0.5) && near(at(14, 14), 0.5) && near(at(16, 14), 0.5));
        // level 0 diagonal (17, 17) and edge (17, 16), (16, 15): 0.5
        assert!(near(at(17, 17), 0.5) && near(at(17, 16), 0.5) && near(at(16, 15), 0.5));
        // only the beams with (16, 16) as a corner: (19, 19) is level 0 with corners
        // (18|20, 18|20), all at 10 m (a short beam is no hole: (18, 18) keeps its
        // clear range of 10 m)
        assert!(near(at(19, 19), 1.9));
        // far from (16, 16): (33, 1) level 0 diagonal, (34, 2) level 1 diagonal
        assert!(near(at(33, 1), 1.9) && near(at(34, 2), 0.9));
        // a pixel without a return (length 0) makes its finer neighbours start at 0
        let b = beams(w, h, |u, v| if (u, v) == (8, 8) { 0.0 } else { 10.0 });
        let st = near_field_starts(&b, w, h, w * h, 100.0, 0.04, 0.1);
        assert_eq!(st[9 * w + 9], 0.0);
        assert_eq!(st[8 * w + 9], 0.0);
        // and those with such a neighbour as a corner: (11, 9) has corner (10, 8),
        // whose diamond has (8, 8) as a corner
        assert_eq!(st[9 * w + 11], 0.0);
        assert!((st[9 * w + 25] as f64 - 1.9).abs() < 1e-6);
    }
}
