//! A simulated depth camera: a pinhole image rendered by casting one ray per
//! pixel against a scene (docs/exploration.md#the-exploration-loop; S0 §5 used a Kinect v2 in Gazebo).

use nalgebra::{Isometry3, Point3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::Deadline;
use crate::collision::SceneGeometry;
use crate::nbv::CameraModel;
use crate::plan::noise::standard_normal as gaussian;

/// How the simulated sensor samples and perturbs its image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorParams {
    /// Every `pixel_stride`-th pixel of every `pixel_stride`-th row is cast
    /// (count ≥ 1). Default 4: a Kinect v2 image of 128 × 106 rays, still
    /// ≥ 5 rays per 0.1 m cell at 2 m.
    pub pixel_stride: usize,
    /// Standard deviation of Gaussian noise added to each measured depth (m,
    /// ≥ 0). Default 0.
    pub noise_stddev: f64,
    /// The near field of the image's beams is shared when the scan is
    /// inserted ([`ScanParams::near_ray_spacing`](crate::octree::ScanParams::near_ray_spacing),
    /// docs/octree.md#whole-frame-insertion): close to the camera only a
    /// lattice of beams at most this far apart is traced (cells, in [0, 1]);
    /// 0 inserts the image's points with every beam traced from the camera
    /// (OctoMap's `insertPointCloud`). Default 0.
    pub near_ray_spacing: f64,
}

impl Default for SensorParams {
    fn default() -> Self {
        SensorParams {
            pixel_stride: 4,
            noise_stddev: 0.0,
            near_ray_spacing: 0.0,
        }
    }
}

/// A rendered depth image: `depth[v·width + u]` is the distance along the
/// optical +z axis (m), 0 where the ray met nothing between `near` and `far`
/// (a Kinect returns nothing there either).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthImage {
    pub width: usize,
    pub height: usize,
    pub depth: Vec<f32>,
}

impl DepthImage {
    /// Pixels with a return.
    pub fn returns(&self) -> usize {
        self.depth.iter().filter(|d| **d > 0.0).count()
    }
}

/// The pixel grid actually cast: columns and rows of `camera` at `stride`.
fn grid(camera: &CameraModel, stride: usize) -> (Vec<usize>, Vec<usize>) {
    let s = stride.max(1);
    (
        (0..camera.width).step_by(s).collect(),
        (0..camera.height).step_by(s).collect(),
    )
}

/// Renders the depth image seen by `camera` at `pose` (optical frame → base
/// frame) in `world`: for pixel `(u, v)` the ray `d = pose.R · ray_direction(u, v)`
/// from the camera centre meets the first surface at distance `t`; its depth
/// is `z = t · d_z` (the camera-frame z of the unit ray), kept when
/// `near ≤ z ≤ far`, plus `N(0, σ²)` noise. Rows run in parallel; each row
/// draws its noise from its own generator seeded by `(seed, row)`, so the
/// image does not depend on the thread count.
///
/// The image has `⌈width/stride⌉ × ⌈height/stride⌉` pixels.
pub fn render_depth(
    world: &SceneGeometry,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    sensor: &SensorParams,
    seed: u64,
) -> DepthImage {
    render_depth_until(world, camera, pose, sensor, seed, Deadline::none()).expect("never stopped")
}

/// [`render_depth`] that polls `deadline` before each row and returns
/// `None` once it fires (an image of up to 2^24 rays takes seconds).
pub fn render_depth_until(
    world: &SceneGeometry,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    sensor: &SensorParams,
    seed: u64,
    deadline: Deadline<'_>,
) -> Option<DepthImage> {
    let (cols, rows) = grid(camera, sensor.pixel_stride);
    let origin = Point3::from(pose.translation.vector);
    let stopped = std::sync::atomic::AtomicBool::new(false);
    // along a ray of unit length, z = t·d_z ≤ far means t ≤ far / d_z
    let depth: Vec<f32> = rows
        .par_iter()
        .enumerate()
        .flat_map_iter(|(r, &v)| {
            let skip = stopped.load(std::sync::atomic::Ordering::Relaxed) || deadline.expired();
            if skip {
                stopped.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let cols = &cols;
            let origin = &origin;
            cols.iter()
                .map(move |&u| {
                    if skip {
                        return 0.0;
                    }
                    let local = camera.ray_direction(u, v);
                    let dir = pose.rotation * local;
                    let max_t = camera.far / local.z;
                    match world.cast_ray(origin, &dir, max_t) {
                        Some(t) => {
                            let z = t * local.z;
                            if z < camera.near {
                                0.0
                            } else {
                                let noisy = if sensor.noise_stddev > 0.0 {
                                    z + sensor.noise_stddev * gaussian(&mut rng)
                                } else {
                                    z
                                };
                                noisy.max(0.0) as f32
                            }
                        }
                        None => 0.0,
                    }
                })
                .collect::<Vec<f32>>()
        })
        .collect();
    if stopped.into_inner() {
        return None;
    }
    Some(DepthImage {
        width: cols.len(),
        height: rows.len(),
        depth,
    })
}

/// The pinhole intrinsics of the pixel grid [`render_depth`] casts at `stride`:
/// image pixel `(c, r)` is camera pixel `(c·s, r·s)`, so
/// `(u − cx)/fx = (c − cx/s)/(fx/s)` and likewise in y.
pub fn strided_intrinsics(camera: &CameraModel, stride: usize) -> crate::octree::PinholeIntrinsics {
    let s = stride.max(1) as f64;
    let k = camera.intrinsics();
    crate::octree::PinholeIntrinsics {
        fx: k.fx / s,
        fy: k.fy / s,
        cx: k.cx / s,
        cy: k.cy / s,
    }
}

/// The base-frame points of `image` (rendered by [`render_depth`] with the
/// same camera, pose and stride): pixel `(u, v)` with depth `z > 0` is
/// `pose · (ray_direction(u, v) · z / d_z)`.
pub fn depth_to_points(
    image: &DepthImage,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    stride: usize,
) -> Vec<[f32; 3]> {
    let (cols, rows) = grid(camera, stride);
    let mut out = Vec::with_capacity(image.returns());
    for (r, &v) in rows.iter().enumerate() {
        for (c, &u) in cols.iter().enumerate() {
            let z = image.depth[r * image.width + c] as f64;
            if z > 0.0 {
                let local = camera.ray_direction(u, v);
                let p = pose * Point3::from(local * (z / local.z));
                out.push([p.x as f32, p.y as f32, p.z as f32]);
            }
        }
    }
    out
}
