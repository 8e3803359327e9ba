//! An occupancy octree as collision geometry: its occupied cubes (and, on
//! request, its unknown ones) as [`Geometry::OccupiedCells`], one geometry
//! per cube size, since pruned leaves stand for larger cubes.

use nalgebra::Point3;

use super::Geometry;
use crate::octree::{CellState, Octree, OctreeError, StateFilter, TREE_DEPTH};

/// The occupied cubes of `tree` overlapping `[min, max]` (m), plus the
/// unknown ones with `unknown`, grouped by size; `None` when there are more
/// than `limit` cubes (nothing beyond the limit is stored).
pub fn octree_cells(
    tree: &Octree,
    min: &Point3<f64>,
    max: &Point3<f64>,
    unknown: bool,
    limit: usize,
) -> Result<Option<Vec<Geometry>>, OctreeError> {
    let mut by_depth: Vec<Vec<Point3<f64>>> = vec![Vec::new(); TREE_DEPTH as usize + 1];
    let mut count = 0usize;
    let filter = StateFilter {
        free: false,
        occupied: true,
        unknown,
    };
    tree.for_each_in_box(min, max, TREE_DEPTH, filter, |cell| {
        if cell.state == CellState::Free {
            return;
        }
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
            .map(|(depth, centers)| Geometry::OccupiedCells {
                size: tree.node_size(depth as u8),
                centers,
            })
            .collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn occupied_cells_are_found_and_unknown_ones_only_on_request() {
        let mut t = Octree::new(0.1).unwrap();
        // one beam along +x: 4 free cells, the end cell occupied
        t.insert_scan(
            &[[0.45, 0.05, 0.05]],
            &[0.05, 0.05, 0.05],
            &Default::default(),
            crate::Deadline::none(),
        )
        .unwrap();
        let (a, b) = (Point3::new(0.0, 0.0, 0.0), Point3::new(0.5, 0.1, 0.1));
        let occ = octree_cells(&t, &a, &b, false, 100).unwrap().unwrap();
        assert_eq!(occ.len(), 1);
        let Geometry::OccupiedCells { size, centers } = &occ[0] else {
            panic!("cells")
        };
        assert!((size - 0.1).abs() < 1e-12 && centers.len() == 1);
        assert!((centers[0] - Point3::new(0.45, 0.05, 0.05)).norm() < 1e-9);
        let with_unknown = octree_cells(&t, &a, &b, true, 1_000_000).unwrap().unwrap();
        let cubes: usize = with_unknown
            .iter()
            .map(|g| match g {
                Geometry::OccupiedCells { centers, .. } => centers.len(),
                _ => 0,
            })
            .sum();
        assert!(cubes > 1);
        assert!(octree_cells(&t, &a, &b, true, 1).unwrap().is_none());
    }
}
