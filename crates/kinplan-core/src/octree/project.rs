//! Back-projection of a depth image a row at a time, with what a scan's plan needs of
//! each point (docs/octree.md#rays-and-scans).
//!
//! Pixel `(u, v)` with depth `z` becomes the optical-frame point `(a_u·z, b_v·z, z)`,
//! `a_u = (u − cx)/fx`, `b_v = (v − cy)/fy` (the pinhole model), then the map-frame
//! point `p = R·p_c + t`, rounded to f32 as OctoMap's `point3d`. For the plan each
//! point also gets its difference from the scan's origin `o` (f32), the beam's length
//! `√(Σ (p_i − o_i)²)` (squares summed in f32, root in f64, OctoMap's `norm()`) and its
//! key `⌊p_i/res⌋ + 32768` (OctoMap's `coordToKey`). The row is worked out for every
//! pixel without a branch, each quantity in its own array, so the compiler can do
//! several pixels at once; the arithmetic is the same IEEE operations in the same
//! order as one pixel at a time, so every point, length and key is bit for bit that.

use nalgebra::Isometry3;

use super::key::{TREE_MAX_VAL, floor_to_i32};

/// The row buffers and the constants of one image's back-projection.
pub(crate) struct RowProjector {
    /// `a_u` per column.
    a: Vec<f64>,
    /// Rotation (row-major) and translation of the camera pose.
    r: [[f64; 3]; 3],
    t: [f64; 3],
    /// The scan's origin and `1/res`.
    origin: [f32; 3],
    factor: f64,
    /// Per pixel of the last row: a return (`z` finite and > 0).
    pub valid: Vec<bool>,
    /// The map-frame point, per axis.
    pub p: [Vec<f32>; 3],
    /// `p − o`, per axis.
    pub diff: [Vec<f32>; 3],
    /// The beam's length (m).
    pub norm: Vec<f64>,
    /// The point's key per axis, meaningful where `in_tree`.
    pub key: [Vec<u16>; 3],
    /// The point is finite and inside the tree's cube.
    pub in_tree: Vec<bool>,
    /// The point is finite.
    pub finite: Vec<bool>,
    /// Length the beam covers (m): its length, the range limit when it is longer,
    /// 0 when the point is outside the tree's cube or not finite.
    pub covered: Vec<f32>,
    /// The range limit (m), ≤ 0 for none.
    max_range: f64,
    /// Key box (inclusive) of the returns' points in the tree, of every row so far
    /// (`lo > hi` on every axis while there is none).
    pub lo: [u16; 3],
    pub hi: [u16; 3],
    /// Never take the AVX2 build (tests).
    pub portable: bool,
}

impl RowProjector {
    /// Buffers for rows of `width` pixels with intrinsics `fx, cx` (pixels), the
    /// camera pose, the scan's origin, the tree's `1/res` and the range limit (m,
    /// ≤ 0 for none).
    pub(crate) fn new(
        width: usize,
        fx: f64,
        cx: f64,
        camera_pose: &Isometry3<f64>,
        origin: &[f32; 3],
        factor: f64,
        max_range: f64,
    ) -> Self {
        let m = camera_pose.rotation.to_rotation_matrix();
        let r = [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]));
        let tv = camera_pose.translation.vector;
        let f32s = || vec![0f32; width];
        RowProjector {
            a: (0..width).map(|u| (u as f64 - cx) / fx).collect(),
            r,
            t: [tv.x, tv.y, tv.z],
            origin: *origin,
            factor,
            valid: vec![false; width],
            p: [f32s(), f32s(), f32s()],
            diff: [f32s(), f32s(), f32s()],
            norm: vec![0.0; width],
            key: [vec![0; width], vec![0; width], vec![0; width]],
            in_tree: vec![false; width],
            finite: vec![false; width],
            covered: vec![0.0; width],
            max_range,
            lo: [u16::MAX; 3],
            hi: [0; 3],
            portable: false,
        }
    }

    /// The points of one row (`depth`, `width` long) whose optical-frame `y` factor
    /// is `b = b_v`: fills `valid` and `p`. Built for AVX2 too, taken when the CPU
    /// has it (the same operations, so the same values), unless `portable`.
    pub(crate) fn points(&mut self, depth: &[f32], b: f64) {
        #[cfg(target_arch = "x86_64")]
        if !self.portable && std::is_x86_feature_detected!("avx2") {
            #[target_feature(enable = "avx2")]
            unsafe fn points_avx2(rows: &mut RowProjector, depth: &[f32], b: f64) {
                rows.points_in(depth, b)
            }
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { points_avx2(self, depth, b) };
        }
        self.points_in(depth, b)
    }

    /// [`beams`](Self::beams)'s and [`points`](Self::points)' work.
    #[inline(always)]
    fn points_in(&mut self, depth: &[f32], b: f64) {
        let (r, t) = (&self.r, &self.t);
        let [px, py, pz] = &mut self.p;
        let n = depth.len();
        let (a, valid) = (&self.a[..n], &mut self.valid[..n]);
        let (px, py, pz) = (&mut px[..n], &mut py[..n], &mut pz[..n]);
        for u in 0..n {
            let z = depth[u] as f64;
            valid[u] = z.is_finite() && z > 0.0;
            let (x, y) = (a[u] * z, b * z);
            px[u] = (r[0][0] * x + r[0][1] * y + r[0][2] * z + t[0]) as f32;
            py[u] = (r[1][0] * x + r[1][1] * y + r[1][2] * z + t[1]) as f32;
            pz[u] = (r[2][0] * x + r[2][1] * y + r[2][2] * z + t[2]) as f32;
        }
    }

    /// [`points`](Self::points) and each point's difference from the origin, beam
    /// length, key and covered length, and the key box: fills every buffer (AVX2
    /// as `points`).
    pub(crate) fn beams(&mut self, depth: &[f32], b: f64) {
        #[cfg(target_arch = "x86_64")]
        if !self.portable && std::is_x86_feature_detected!("avx2") {
            #[target_feature(enable = "avx2")]
            unsafe fn beams_avx2(rows: &mut RowProjector, depth: &[f32], b: f64) {
                rows.beams_in(depth, b)
            }
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { beams_avx2(self, depth, b) };
        }
        self.beams_in(depth, b)
    }

    #[inline(always)]
    fn beams_in(&mut self, depth: &[f32], b: f64) {
        self.points_in(depth, b);
        let n = depth.len();
        let (o, f) = (self.origin, self.factor);
        let [px, py, pz] = &self.p;
        let [dx, dy, dz] = &mut self.diff;
        let (px, py, pz) = (&px[..n], &py[..n], &pz[..n]);
        let (dx, dy, dz, norm) = (&mut dx[..n], &mut dy[..n], &mut dz[..n], &mut self.norm[..n]);
        for u in 0..n {
            let d = [px[u] - o[0], py[u] - o[1], pz[u] - o[2]];
            (dx[u], dy[u], dz[u]) = (d[0], d[1], d[2]);
            norm[u] = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
        }
        let [kx, ky, kz] = &mut self.key;
        let (kx, ky, kz) = (&mut kx[..n], &mut ky[..n], &mut kz[..n]);
        let (in_tree, finite) = (&mut self.in_tree[..n], &mut self.finite[..n]);
        let (covered, norm, max_range) = (&mut self.covered[..n], &self.norm[..n], self.max_range);
        let limit = TREE_MAX_VAL as f64;
        for u in 0..n {
            let s = [px[u] as f64 * f, py[u] as f64 * f, pz[u] as f64 * f];
            // ⌊s⌋ ∈ [−32768, 32768) ⇔ s ∈ [−32768, 32768); NaN fails
            let inside = s.iter().fold(true, |acc, &s| acc & (s >= -limit) & (s < limit));
            finite[u] = px[u].is_finite() & py[u].is_finite() & pz[u].is_finite();
            in_tree[u] = inside & finite[u];
            let k = s.map(|s| floor_to_i32(s).wrapping_add(TREE_MAX_VAL) as u16);
            (kx[u], ky[u], kz[u]) = (k[0], k[1], k[2]);
        }
        let cut_at = if max_range > 0.0 { max_range } else { f64::INFINITY };
        for u in 0..n {
            let kept = if in_tree[u] { norm[u] as f32 } else { 0.0 };
            covered[u] = if norm[u] > cut_at { max_range as f32 } else { kept };
        }
        // the key box of the returns in the tree, each key masked to the box's
        // neutral value where it does not count
        let (valid, in_tree) = (&self.valid[..n], &self.in_tree[..n]);
        for a in 0..3 {
            let k = &self.key[a][..n];
            let (mut lo, mut hi) = (self.lo[a], self.hi[a]);
            for ((&k, &v), &t) in k.iter().zip(valid).zip(in_tree) {
                let mask = 0u16.wrapping_sub(u16::from(v & t));
                lo = lo.min(k | !mask);
                hi = hi.max(k & mask);
            }
            (self.lo[a], self.hi[a]) = (lo, hi);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn rows_give_each_pixels_point_length_and_key_bit_for_bit() {
        // every quantity worked out one pixel at a time with f64::floor for the key,
        // over depths with no return (0, negative, NaN, ∞), far points outside the
        // cube, the largest f32 depth, and ordinary ones
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (w, fx, cx, cy, fy) = (37usize, 365.1, 18.3, 4.2, 366.7);
        let pose = Isometry3::from_parts(
            Translation3::new(1.3, -0.7, 1.1),
            UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
        );
        let origin = [1.3f32, -0.7, 1.1];
        let res = 0.05;
        let f = 1.0 / res;
        let mut rows = RowProjector::new(w, fx, cx, &pose, &origin, f, -1.0);
        // and with a range limit of 3 m, built without AVX2 (where the CPU has it,
        // `rows` takes the AVX2 build)
        let mut cut = RowProjector::new(w, fx, cx, &pose, &origin, f, 3.0);
        cut.portable = true;
        let (mut lo, mut hi) = ([u16::MAX; 3], [0u16; 3]);
        let m = pose.rotation.to_rotation_matrix();
        let mut checked = [0usize; 3];
        for v in 0..9 {
            let depth: Vec<f32> = (0..w)
                .map(|_| match rng.random_range(0..12) {
                    0 => 0.0,
                    1 => -1.5,
                    2 => f32::NAN,
                    3 => f32::INFINITY,
                    4 => 4000.0,
                    5 => f32::MAX,
                    _ => rng.random_range(0.3f32..9.0),
                })
                .collect();
            let b = (v as f64 - cy) / fy;
            rows.beams(&depth, b);
            cut.beams(&depth, b);
            for (u, &z) in depth.iter().enumerate() {
                let z = z as f64;
                let valid = z.is_finite() && z > 0.0;
                assert_eq!(rows.valid[u], valid, "pixel {u}, {v}");
                if !valid {
                    continue;
                }
                let pc = [(u as f64 - cx) / fx * z, b * z, z];
                let t = pose.translation.vector;
                let p: [f32; 3] = [0, 1, 2]
                    .map(|i| (m[(i, 0)] * pc[0] + m[(i, 1)] * pc[1] + m[(i, 2)] * pc[2] + t[i]) as f32);
                let d = [0, 1, 2].map(|i| p[i] - origin[i]);
                let norm = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
                for i in 0..3 {
                    assert_eq!(rows.p[i][u].to_bits(), p[i].to_bits());
                    assert_eq!(rows.diff[i][u].to_bits(), d[i].to_bits());
                }
                let finite = p.iter().all(|c| c.is_finite());
                assert_eq!(rows.finite[u], finite);
                assert!(rows.norm[u] == norm || (rows.norm[u].is_nan() && norm.is_nan()));
                let s = p.map(|c| (c as f64 * f).floor());
                let inside = s.iter().all(|&s| (-32768.0..32768.0).contains(&s));
                assert_eq!(rows.in_tree[u], inside && finite, "pixel {u}, {v}: {p:?}");
                let want = if inside && finite { norm as f32 } else { 0.0 };
                assert_eq!(rows.covered[u].to_bits(), want.to_bits());
                let want = if norm > 3.0 { 3.0 } else { want };
                assert_eq!(cut.covered[u].to_bits(), want.to_bits());
                for i in 0..3 {
                    assert_eq!(cut.p[i][u].to_bits(), p[i].to_bits());
                    assert_eq!(cut.diff[i][u].to_bits(), d[i].to_bits());
                    assert_eq!(cut.key[i][u], rows.key[i][u]);
                }
                assert_eq!(cut.norm[u].to_bits(), rows.norm[u].to_bits());
                assert_eq!((cut.finite[u], cut.in_tree[u]), (rows.finite[u], rows.in_tree[u]));
                if inside && finite {
                    for i in 0..3 {
                        let k = (s[i] as i32 + 32768) as u16;
                        assert_eq!(rows.key[i][u], k);
                        (lo[i], hi[i]) = (lo[i].min(k), hi[i].max(k));
                    }
                }
                checked[usize::from(finite) + usize::from(inside)] += 1;
            }
        }
        assert_eq!((rows.lo, rows.hi), (lo, hi));
        assert_eq!((cut.lo, cut.hi), (lo, hi));
        // finite points outside the cube and inside it both met (a depth's point
        // cannot overflow f32: ‖p − t‖ ≤ ‖p_c‖ < 1.01·z for these intrinsics)
        assert!(checked[1] > 0 && checked[2] > 0, "{checked:?}");
    }
}
