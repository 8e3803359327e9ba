//! The depth camera: field of view, range, ray grid, and its view frustum.

use nalgebra::{Isometry3, Point3, Rotation3, UnitQuaternion, Vector3};

use super::NbvError;

/// A pinhole depth camera. Its frame is the optical frame: +z along the view, +x to
/// the image's right, +y down. Defaults: Kinect v2 (S0's sensor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraModel {
    /// Horizontal field of view (rad, in (0, π)). Default 70.6° (1.2322 rad).
    pub hfov: f64,
    /// Vertical field of view (rad, in (0, π)). Default 60° (1.0472 rad).
    pub vfov: f64,
    /// Nearest measured depth along +z (m, > 0). Default 0.5.
    pub near: f64,
    /// Farthest measured depth along +z (m, > near). Default 4.5.
    pub far: f64,
    /// Rays per image row (count ≥ 1). Default 512.
    pub width: usize,
    /// Image rows (count ≥ 1). Default 424.
    pub height: usize,
}

impl Default for CameraModel {
    fn default() -> Self {
        Self {
            hfov: 70.6f64.to_radians(),
            vfov: 60f64.to_radians(),
            near: 0.5,
            far: 4.5,
            width: 512,
            height: 424,
        }
    }
}

impl CameraModel {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), NbvError> {
        let pi = std::f64::consts::PI;
        let bad = |field, value, reason| Err(NbvError::InvalidParam { field, value, reason });
        if !(self.hfov > 0.0 && self.hfov < pi) {
            return bad("hfov", self.hfov, "must lie in (0, π)");
        }
        if !(self.vfov > 0.0 && self.vfov < pi) {
            return bad("vfov", self.vfov, "must lie in (0, π)");
        }
        if !(self.near.is_finite() && self.near > 0.0) {
            return bad("near", self.near, "must be finite and > 0");
        }
        if !(self.far.is_finite() && self.far > self.near) {
            return bad("far", self.far, "must be finite and > near");
        }
        if self.width == 0 {
            return bad("width", 0.0, "must be at least 1");
        }
        if self.height == 0 {
            return bad("height", 0.0, "must be at least 1");
        }
        if self.width.saturating_mul(self.height) > crate::octree::MAX_DEPTH_PIXELS {
            return bad("width", self.width as f64, "width · height must be at most 2^24");
        }
        Ok(())
    }

    /// Volume of the frustum between `near` and `far` (m³):
    /// `4·tan(h/2)·tan(v/2)·(far³ − near³)/3`.
    pub fn frustum_volume(&self) -> f64 {
        4.0 * (self.hfov / 2.0).tan() * (self.vfov / 2.0).tan() * (self.far.powi(3) - self.near.powi(3)) / 3.0
    }

    /// The pinhole intrinsics of this model's pixel grid (pixels): pixel centres spread
    /// from edge to edge of the field of view ([`ray_direction`](Self::ray_direction)),
    /// so `fx = (width − 1) / (2·tan(hfov/2))`, `cx = (width − 1)/2`, and likewise `fy`,
    /// `cy` with `vfov` and `height` (a single column or row looks along the axis).
    pub fn intrinsics(&self) -> crate::octree::PinholeIntrinsics {
        let axis = |n: usize, fov: f64| {
            let half = (n.max(2) - 1) as f64 / 2.0;
            (half / (fov / 2.0).tan(), (n.max(1) - 1) as f64 / 2.0)
        };
        let (fx, cx) = axis(self.width, self.hfov);
        let (fy, cy) = axis(self.height, self.vfov);
        crate::octree::PinholeIntrinsics { fx, fy, cx, cy }
    }

    /// Unit direction (camera frame) of the ray through pixel `(u, v)`, pixel centres
    /// spread evenly so the first and last rays lie on the field-of-view edges.
    pub fn ray_direction(&self, u: usize, v: usize) -> Vector3<f64> {
        self.ray_direction_with(self.half_tangents(), u, v)
    }

    /// `(tan(hfov/2), tan(vfov/2))`, for [`ray_direction_with`](Self::ray_direction_with).
    pub fn half_tangents(&self) -> (f64, f64) {
        ((self.hfov / 2.0).tan(), (self.vfov / 2.0).tan())
    }

    /// [`ray_direction`](Self::ray_direction) with the half-angle tangents computed once
    /// by [`half_tangents`](Self::half_tangents) (the same value, bit for bit).
    #[inline]
    pub fn ray_direction_with(&self, (th, tv): (f64, f64), u: usize, v: usize) -> Vector3<f64> {
        let x = if self.width > 1 {
            -th + 2.0 * th * u as f64 / (self.width - 1) as f64
        } else {
            0.0
        };
        let y = if self.height > 1 {
            -tv + 2.0 * tv * v as f64 / (self.height - 1) as f64
        } else {
            0.0
        };
        Vector3::new(x, y, 1.0).normalize()
    }
}

/// The six planes of a view frustum in the map frame, as `n·p + d ≥ 0` inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    pub planes: [(Vector3<f64>, f64); 6],
    /// Corners (map frame, m): near four then far four.
    pub corners: [Point3<f64>; 8],
}

impl Frustum {
    /// The frustum of `camera` at `pose` (camera optical frame → map).
    pub fn new(camera: &CameraModel, pose: &Isometry3<f64>) -> Self {
        let (th, tv) = ((camera.hfov / 2.0).tan(), (camera.vfov / 2.0).tan());
        // camera-frame inward normals: z ≥ near, z ≤ far, x ≤ th·z, −x ≤ th·z, y…, −y…
        let local = [
            (Vector3::new(0.0, 0.0, 1.0), -camera.near),
            (Vector3::new(0.0, 0.0, -1.0), camera.far),
            (Vector3::new(-1.0, 0.0, th), 0.0),
            (Vector3::new(1.0, 0.0, th), 0.0),
            (Vector3::new(0.0, -1.0, tv), 0.0),
            (Vector3::new(0.0, 1.0, tv), 0.0),
        ];
        let r = pose.rotation;
        let t = pose.translation.vector;
        let planes = local.map(|(n, d)| {
            let len = n.norm();
            let nm = r * (n / len);
            (nm, d / len - nm.dot(&t))
        });
        let mut corners = [Point3::origin(); 8];
        for (i, z) in [camera.near, camera.far].into_iter().enumerate() {
            for (j, (sx, sy)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .into_iter()
                .enumerate()
            {
                corners[i * 4 + j] = pose * Point3::new(sx * th * z, sy * tv * z, z);
            }
        }
        Self { planes, corners }
    }

    /// True when `p` (map frame) is inside or on the frustum.
    #[inline]
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        self.planes.iter().all(|(n, d)| n.dot(&p.coords) + d >= 0.0)
    }
}

/// Camera pose looking along `dir` from `position`: optical +z = `dir`, image +x
/// horizontal (perpendicular to the map's +z; the map's +x when looking straight up or
/// down), image +y = z × x.
pub fn look_along(position: &Point3<f64>, dir: &Vector3<f64>) -> Option<Isometry3<f64>> {
    let z = dir.try_normalize(1e-12)?;
    let up = Vector3::z();
    let x = z.cross(&up).try_normalize(1e-9).unwrap_or_else(Vector3::x);
    let y = z.cross(&x);
    let rot = Rotation3::from_basis_unchecked(&[x, y, z]);
    Some(Isometry3::from_parts(
        position.coords.into(),
        UnitQuaternion::from_rotation_matrix(&rot),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: a zero height was reported as the width.
    #[test]
    fn a_zero_size_names_its_own_field() {
        for (width, height, field) in [(0, 424, "width"), (512, 0, "height"), (1 << 13, 1 << 12, "width")] {
            let cam = CameraModel {
                width,
                height,
                ..CameraModel::default()
            };
            match cam.validate() {
                Err(NbvError::InvalidParam { field: f, .. }) => assert_eq!(f, field, "{width} x {height}"),
                other => panic!("{width} x {height}: {other:?}"),
            }
        }
    }

    #[test]
    fn frustum_planes_and_corners_agree() {
        let cam = CameraModel::default();
        let pose = look_along(&Point3::new(1.0, 2.0, 0.5), &Vector3::new(1.0, 1.0, 0.2)).unwrap();
        let f = Frustum::new(&cam, &pose);
        let centre = f.corners.iter().fold(Vector3::zeros(), |a, c| a + c.coords) / 8.0;
        assert!(f.contains(&Point3::from(centre)));
        for c in &f.corners {
            // corners lie on three planes each and inside the rest (tolerance 1e-9)
            let on = f
                .planes
                .iter()
                .filter(|(n, d)| (n.dot(&c.coords) + d).abs() < 1e-9)
                .count();
            assert_eq!(on, 3);
            assert!(f.planes.iter().all(|(n, d)| n.dot(&c.coords) + d > -1e-9));
        }
        assert!(!f.contains(&pose.translation.vector.into()));
        // looking along +x: image right is −y, image down is −z
        let p = look_along(&Point3::origin(), &Vector3::x()).unwrap();
        assert!((p * Vector3::x() - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
        assert!((p * Vector3::y() - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
        // volume: 4·tan(35.3°)·tan(30°)·(4.5³ − 0.5³)/3
        let v = 4.0 * 0.708_039_47 * 0.577_350_27 * (91.125 - 0.125) / 3.0;
        assert!(
            (cam.frustum_volume() - v).abs() < 1e-3,
            "{}",
            cam.frustum_volume()
        );
    }
}
