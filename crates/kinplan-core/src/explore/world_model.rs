//! What the robot knows of its world, as the planner and the stop rule see
//! it: the octree's occupied cells as obstacles, and the known share of the
//! cells that can be observed at all.

use nalgebra::Point3;

use crate::collision::{Geometry, Obstacle, SceneGeometry};
use crate::octree::{CellState, OcKey, Octree, OctreeError, StateFilter, TREE_DEPTH};

/// The occupied cubes of `tree` overlapping `[min, max]`, one
/// [`Geometry::OccupiedCells`] per cube size (pruned leaves stand for larger
/// cubes), at most `limit` cubes; `None` when there are more.
pub fn occupied_obstacles(
    tree: &Octree,
    min: &Point3<f64>,
    max: &Point3<f64>,
    limit: usize,
) -> Result<Option<Vec<Obstacle>>, OctreeError> {
    let mut by_depth: Vec<Vec<Point3<f64>>> = vec![Vec::new(); TREE_DEPTH as usize + 1];
    let mut count = 0usize;
    let filter = StateFilter {
        free: false,
        occupied: true,
        unknown: false,
    };
    tree.for_each_in_box(min, max, TREE_DEPTH, filter, |cell| {
        count += 1;
        if count <= limit {
            by_depth[cell.depth as usize].push(cell.center);
        }
    })?;
    if count > limit {
        return Ok(None);
    }
    Ok(Some(
        by_depth
            .into_iter()
            .enumerate()
            .filter(|(_, c)| !c.is_empty())
            .map(|(depth, centers)| {
                Obstacle::new(
                    format!("octree cells {:.3} m", tree.node_size(depth as u8)),
                    nalgebra::Isometry3::identity(),
                    Geometry::OccupiedCells {
                        size: tree.node_size(depth as u8),
                        centers,
                    },
                )
            })
            .collect(),
    ))
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
