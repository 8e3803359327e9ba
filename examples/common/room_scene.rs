//! A seeded synthetic room for the octree / NBV benchmarks (the Rust twin of
//! `benches/octomap/scene.py`): a 6 × 5 × 3 m box room with two boxes and a sphere;
//! a simulated depth camera returns the first surface along each beam.

#![allow(dead_code)]

use nalgebra::{Point3, Vector3};

pub const ROOM_MIN: [f64; 3] = [-3.0, -2.5, 0.0];
pub const ROOM_MAX: [f64; 3] = [3.0, 2.5, 3.0];
const BOXES: [([f64; 3], [f64; 3]); 2] = [
    ([0.8, -1.2, 0.0], [1.6, -0.2, 1.1]),
    ([-2.2, 0.6, 0.0], [-1.4, 1.8, 0.7]),
];
const SPHERE: ([f64; 3], f64) = ([0.5, 1.2, 1.4], 0.45);

fn box_entry(o: &Point3<f64>, d: &Vector3<f64>, lo: &[f64; 3], hi: &[f64; 3]) -> f64 {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..3 {
        if d[i] == 0.0 {
            if o[i] < lo[i] || o[i] > hi[i] {
                return f64::INFINITY;
            }
            continue;
        }
        let (a, b) = ((lo[i] - o[i]) / d[i], (hi[i] - o[i]) / d[i]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t1 >= t0 && t0 > 0.0 { t0 } else { f64::INFINITY }
}

/// Distance along the unit ray to the first surface of the room.
pub fn hit_distance(o: &Point3<f64>, d: &Vector3<f64>) -> f64 {
    let mut t = f64::INFINITY;
    for i in 0..3 {
        if d[i] != 0.0 {
            let a = (ROOM_MIN[i] - o[i]) / d[i];
            let b = (ROOM_MAX[i] - o[i]) / d[i];
            let exit = a.max(b);
            if exit > 0.0 {
                t = t.min(exit);
            }
        }
    }
    for (lo, hi) in &BOXES {
        t = t.min(box_entry(o, d, lo, hi));
    }
    let (c, r) = SPHERE;
    let oc = o.coords - Vector3::from(c);
    let b = oc.dot(d);
    let disc = b * b - (oc.dot(&oc) - r * r);
    if disc > 0.0 {
        let ts = -b - disc.sqrt();
        if ts > 0.0 {
            t = t.min(ts);
        }
    }
    t
}

/// End points (f32) of a `width × height` beam fan from `origin` looking along yaw
/// (about +z) and pitch (rad), fields of view `hfov × vfov` (rad).
pub fn beams(
    origin: [f64; 3],
    yaw: f64,
    pitch: f64,
    width: usize,
    height: usize,
    hfov: f64,
    vfov: f64,
) -> Vec<[f32; 3]> {
    let o = Point3::from(origin);
    let (cy, sy, cp, sp) = (yaw.cos(), yaw.sin(), pitch.cos(), pitch.sin());
    let mut out = Vec::with_capacity(width * height);
    for v in 0..height {
        let b = ((-vfov / 2.0) + vfov * v as f64 / (height - 1).max(1) as f64).tan();
        for u in 0..width {
            let a = ((-hfov / 2.0) + hfov * u as f64 / (width - 1).max(1) as f64).tan();
            // camera: forward x, left y, up z; pitch about y, then yaw about z
            let dc = Vector3::new(1.0, -a, -b).normalize();
            let dp = Vector3::new(cp * dc.x - sp * dc.z, dc.y, sp * dc.x + cp * dc.z);
            let d = Vector3::new(cy * dp.x - sy * dp.y, sy * dp.x + cy * dp.y, dp.z);
            let t = hit_distance(&o, &d);
            let p = o + d * t;
            out.push([p.x as f32, p.y as f32, p.z as f32]);
        }
    }
    out
}

/// The benchmark scans: four seeded sensor poses around the room, Kinect-v2 sized.
pub fn scan_poses() -> Vec<([f64; 3], f64, f64)> {
    vec![
        ([0.1, 0.2, 1.3], 0.3, 0.0),
        ([-0.7, -0.4, 1.0], 2.2, 0.2),
        ([1.5, 1.0, 1.6], -2.3, -0.3),
        ([-1.0, 1.5, 1.2], -0.9, 0.1),
    ]
}
