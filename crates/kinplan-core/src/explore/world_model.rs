//! What the robot knows of its world, as the planner and the stop rule see
//! it: the octree's occupied cells as obstacles, and the known share of the
//! cells that can be observed at all.

use nalgebra::Point3;

use crate::collision::{Obstacle, SceneGeometry, octree_cells};
use crate::octree::{CellState, OcKey, Octree, OctreeError, TREE_DEPTH};

/// The occupied cubes of `tree` overlapping `[min, max]` as obstacles, at
/// most `limit` cubes; `None` when there are more.
pub fn occupied_obstacles(
    tree: &Octree,
    min: &Point3<f64>,
    max: &Point3<f64>,
    limit: usize,
) -> Result<Option<Vec<Obstacle>>, OctreeError> {
    Ok(octree_cells(tree, min, max, false, limit)?.map(|cells| {
        cells
            .into_iter()
            .map(|g| Obstacle::new("octree cells", nalgebra::Isometry3::identity(), g))
            .collect()
    }))
}

/// The cells of a region that a camera could observe: depth-16 cells whose
/// centre lies in the region and outside every obstacle of the true scene
/// (an obstacle's inside is never seen). The known ratio counts these.
#[derive(Debug, Clone)]
pub struct ObservableCells {
    keys: Vec<OcKey>,
}

impl ObservableCells {
    /// Enumerates the cells of `tree`'s grid with centres in `[min, max]`
    /// and keeps those outside `truth`'s obstacles.
    pub fn new(
        tree: &Octree,
        min: &Point3<f64>,
        max: &Point3<f64>,
        truth: &SceneGeometry,
    ) -> Result<Self, OctreeError> {
        let res = tree.resolution();
        // first and last key whose cell centre lies inside [min, max]
        let lo = tree.key_of(&min.map(|v| v + 0.5 * res))?;
        let hi = tree.key_of(&max.map(|v| v - 0.5 * res))?;
        let mut keys = Vec::new();
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let key = [x, y, z];
                    let c = tree.key_center(&key, TREE_DEPTH);
                    if !truth.contains_point(&c) {
                        keys.push(key);
                    }
                }
            }
        }
        Ok(ObservableCells { keys })
    }

    pub fn len(&self) -> usize {
        self.keys.len()
    }

    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// Share of the cells that `tree` knows (free or occupied), in [0, 1];
    /// 1 for an empty set.
    pub fn known_ratio(&self, tree: &Octree) -> f64 {
        if self.keys.is_empty() {
            return 1.0;
        }
        let known = self
            .keys
            .iter()
            .filter(|k| tree.state_of_key(k) != CellState::Unknown)
            .count();
        known as f64 / self.keys.len() as f64
    }
}
