//! Information gain of a view: S0's volume intersection as an exact frustum-culled
//! count of unknown cells, and ray-cast gains (docs/exploration.md#information-gain).

use nalgebra::{Isometry3, Point3, Vector3};

use super::camera::{CameraModel, Frustum};
use super::count::FrustumCounter;
use crate::Deadline;
use crate::octree::{CellState, OcKey, Octree, SearchCache, morton};

/// How the gain of a view is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GainMethod {
    /// S0's volume intersection: unknown depth-16 cells whose centres lie in the frustum,
    /// counted exactly by culling octree cubes against the six planes (occlusion-blind).
    Intersection,
    /// Distinct unknown cells met by a `fraction` (0, 1] of the camera's rays, each ray
    /// stopping at the first occupied cell (occlusion-aware).
    Rays { fraction: f64 },
    /// ig_active_reconstruction's occlusion-aware gain on the same rays:
    /// `Σ_rays Σ_cells V·H(p)`, `V = Π_(cells before) (1 − p)`, `H` the binary entropy
    /// (nats), unknown cells at p = 0.5; normalised by `H(0.5)`.
    OcclusionAware { fraction: f64 },
    /// ig_active_reconstruction's unobserved-voxel gain: unknown cells summed over rays
    /// (a cell seen by two rays counts twice), rays stop at occupied cells.
    UnobservedVoxels { fraction: f64 },
}

impl GainMethod {
    pub(crate) fn fraction(&self) -> Option<f64> {
        match *self {
            GainMethod::Intersection => None,
            GainMethod::Rays { fraction }
            | GainMethod::OcclusionAware { fraction }
            | GainMethod::UnobservedVoxels { fraction } => Some(fraction),
        }
    }
}

/// Gain of one view.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewGain {
    /// c: unknown cells found (or the weighted sum for `OcclusionAware`).
    pub cells: f64,
    /// `Ig = c / c_max`, `c_max = frustum volume / res³`. Not clipped: counting cell
    /// centres can put an intersection count a fraction of a percent above `c_max`
    /// (cells straddling the frustum's faces), and the unobserved-voxel sum counts a
    /// cell once per ray, so it can exceed 1 by design.
    pub ig: f64,
    /// DDA steps taken (ray methods).
    pub ray_steps: u64,
}

/// Reusable buffers for ray gains.
#[derive(Debug, Default, Clone)]
pub struct GainWorkspace {
    seen: Vec<u64>,
}

/// Unknown depth-16 cells of `tree` whose centres lie inside `frustum` (docs/exploration.md#information-gain,
/// S0 eq. 4.2's c), counted exactly by culling octree cubes against the six
/// planes ([`FrustumCounter`], which see). Builds the tree's known-cell counts on every
/// call; for many views of one tree build one [`FrustumCounter`] and reuse it.
///
/// ```
/// use kinplan_core::nbv::{CameraModel, Frustum, frustum_unknown_count, look_along};
/// use kinplan_core::octree::Octree;
/// use nalgebra::{Point3, Vector3};
/// let cam = CameraModel { near: 0.2, far: 1.0, ..CameraModel::default() };
/// let pose = look_along(&Point3::new(0.01, 0.02, 0.03), &Vector3::x()).unwrap();
/// // an empty tree is all unknown: the count approaches volume / res³
/// let c = frustum_unknown_count(&Octree::new(0.05).unwrap(), &Frustum::new(&cam, &pose)) as f64;
/// let v = cam.frustum_volume() / 0.05f64.powi(3);
/// assert!((c / v - 1.0).abs() < 0.1);
/// ```
pub fn frustum_unknown_count(tree: &Octree, frustum: &Frustum) -> u64 {
    FrustumCounter::new(tree).count(frustum)
}

/// [`frustum_unknown_count`] restricted to the depth-16 cells whose keys lie in
/// the inclusive key box `keys` (`None`: no restriction).
pub fn frustum_unknown_count_in(tree: &Octree, frustum: &Frustum, keys: Option<(OcKey, OcKey)>) -> u64 {
    FrustumCounter::new(tree).count_in(frustum, keys)
}

/// Binary entropy (nats).
#[inline]
fn entropy(p: f64) -> f64 {
    if p <= 0.0 || p >= 1.0 {
        0.0
    } else {
        -p * p.ln() - (1.0 - p) * (1.0 - p).ln()
    }
}

/// Ray-cast gain of a view (see [`GainMethod`]): rays through the camera's pixel grid,
/// a deterministic `fraction` of them (pixel i is used when `⌊(i+1)·f⌋ > ⌊i·f⌋`), each
/// walked by a 3-D DDA from depth `near` to `far` (along +z). `deadline` is polled
/// every 64 rays; a stopped view returns what it found so far.
pub fn ray_gain(
    tree: &Octree,
    camera: &CameraModel,
    pose: &Isometry3<f64>,
    method: GainMethod,
    ws: &mut GainWorkspace,
    deadline: Deadline<'_>,
) -> ViewGain {
    let fraction = method.fraction().unwrap_or(1.0).clamp(0.0, 1.0);
    let origin = Point3::from(pose.translation.vector);
    ws.seen.clear();
    let mut total = 0.0f64;
    let mut steps = 0u64;
    let n = camera.width * camera.height;
    let mut used = 0usize;
    for i in 0..n {
        if ((i + 1) as f64 * fraction).floor() <= (i as f64 * fraction).floor() {
            continue;
        }
        used += 1;
        if used.is_multiple_of(64) && deadline.expired() {
            break;
        }
        let (u, v) = (i % camera.width, i / camera.width);
        let dc = camera.ray_direction(u, v);
        let (t0, t1) = (camera.near / dc.z, camera.far / dc.z);
        let dir = pose.rotation * dc;
        let mut vis = 1.0f64;
        steps += walk(tree, &origin, &dir, t0, t1, |key, state, lo| match method {
            GainMethod::Intersection | GainMethod::Rays { .. } => {
                if state == CellState::Unknown {
                    ws.seen.push(morton(key));
                }
                state != CellState::Occupied
            }
            GainMethod::UnobservedVoxels { .. } => {
                if state == CellState::Unknown {
                    total += 1.0;
                }
                state != CellState::Occupied
            }
            GainMethod::OcclusionAware { .. } => {
                let p = match lo {
                    None => 0.5,
                    Some(l) => crate::octree::probability(l),
                };
                total += vis * entropy(p) / std::f64::consts::LN_2;
                vis *= 1.0 - p;
                vis > 1e-4
            }
        });
    }
    if matches!(method, GainMethod::Intersection | GainMethod::Rays { .. }) {
        ws.seen.sort_unstable();
        ws.seen.dedup();
        total = ws.seen.len() as f64;
    }
    let c_max = camera.frustum_volume() / tree.resolution().powi(3);
    ViewGain {
        cells: total,
        ig: total / c_max,
        ray_steps: steps,
    }
}

/// Walks the cells a ray `o + t·dir` (unit `dir`, m) crosses for `t ∈ [t0, t1]` with a
/// 3-D DDA (Amanatides & Woo), calling `visit(key, state, log_odds)` per cell until it
/// returns false; returns the steps taken.
pub fn walk(
    tree: &Octree,
    o: &Point3<f64>,
    dir: &Vector3<f64>,
    t0: f64,
    t1: f64,
    visit: impl FnMut(&OcKey, CellState, Option<f32>) -> bool,
) -> u64 {
    let mut cache = SearchCache::default();
    walk_with(tree, o, dir, t0, t1, |k| tree_state(tree, k, &mut cache), visit)
}

/// State and log-odds of the depth-16 cell `key` of `tree` (`None` where unknown).
#[inline]
pub(crate) fn tree_state(tree: &Octree, key: &OcKey, cache: &mut SearchCache) -> (CellState, Option<f32>) {
    match tree.search_key_cached(key, cache) {
        None => (CellState::Unknown, None),
        Some((v, _)) => (
            if v > tree.threshold_log_odds() {
                CellState::Occupied
            } else {
                CellState::Free
            },
            Some(v),
        ),
    }
}

/// The set-up of an Amanatides–Woo voxel walk from `start`, in cell `k`, at
/// ray parameter `t0` along `dir` through cells of edge `res`: per axis the
/// step (−1, 0, 1), the ray parameter of the first cell border crossed and
/// the parameter between borders (infinite along an axis the ray does not move on).
#[inline]
pub(crate) fn dda_start(
    k: &OcKey,
    start: &Point3<f64>,
    dir: &Vector3<f64>,
    t0: f64,
    res: f64,
) -> ([i32; 3], [f64; 3], [f64; 3]) {
    let mut step = [0i32; 3];
    let mut t_max = [f64::INFINITY; 3];
    let mut t_delta = [f64::INFINITY; 3];
    for i in 0..3 {
        if dir[i] != 0.0 {
            step[i] = if dir[i] > 0.0 { 1 } else { -1 };
            let lo = (k[i] as f64 - 32768.0) * res;
            let border = if dir[i] > 0.0 { lo + res } else { lo };
            t_max[i] = t0 + (border - start[i]) / dir[i];
            t_delta[i] = res / dir[i].abs();
        }
    }
    (step, t_max, t_delta)
}

/// [`walk`] reading each cell's state and log-odds from `lookup` instead of the tree
/// (the tree gives the resolution and the key space).
pub(crate) fn walk_with(
    tree: &Octree,
    o: &Point3<f64>,
    dir: &Vector3<f64>,
    t0: f64,
    t1: f64,
    mut lookup: impl FnMut(&OcKey) -> (CellState, Option<f32>),
    mut visit: impl FnMut(&OcKey, CellState, Option<f32>) -> bool,
) -> u64 {
    let res = tree.resolution();
    let start = o + dir * t0;
    let Ok(mut k) = tree.key_of(&start) else { return 0 };
    let (step, mut t_max, t_delta) = dda_start(&k, &start, dir, t0, res);
    let mut steps = 0u64;
    loop {
        steps += 1;
        let (state, v) = lookup(&k);
        if !visit(&k, state, v) {
            return steps;
        }
        let a = if t_max[0] < t_max[1] {
            if t_max[0] < t_max[2] { 0 } else { 2 }
        } else if t_max[1] < t_max[2] {
            1
        } else {
            2
        };
        if t_max[a] > t1 {
            return steps;
        }
        let nk = k[a] as i32 + step[a];
        if !(0..65536).contains(&nk) {
            return steps;
        }
        k[a] = nk as u16;
        t_max[a] += t_delta[a];
    }
}
