//! Global planning on an occupancy grid: A* over 8-connected cells of a world inflated by the
//! robot's radius plus a margin, then line-of-sight shortcutting. Not in S1; added as the
//! global planner for pure-pursuit navigation (the Nav2 pattern).

use serde::{Deserialize, Serialize};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::error::{MobileError, check_positive, check_range};
use super::field::{AstarField, MobileField};
use super::pose::Point2;
use super::world::World;
use crate::Deadline;

/// Grid A* parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridAstarParams {
    /// Cell size, m (default 0.05).
    pub resolution: f64,
    /// A cell is blocked when its centre is closer than this to an obstacle, m
    /// (default 0.32 = 0.22 m robot radius + 0.10 m margin).
    pub inflation: f64,
    /// Padding of the grid around start, goal and obstacles, m (default 1.0).
    pub padding: f64,
    /// Largest grid accepted, cells (default 4 000 000).
    pub max_cells: usize,
}

impl Default for GridAstarParams {
    fn default() -> Self {
        Self {
            resolution: 0.05,
            inflation: 0.32,
            padding: 1.0,
            max_cells: 4_000_000,
        }
    }
}

impl GridAstarParams {
    /// Positive resolution; non-negative inflation and padding; at least 4 cells.
    pub fn validate(&self) -> Result<(), MobileError> {
        check_positive(MobileField::Astar(AstarField::Resolution), self.resolution)?;
        check_range(
            MobileField::Astar(AstarField::Inflation),
            self.inflation,
            0.0,
            1e6,
        )?;
        check_range(MobileField::Astar(AstarField::Padding), self.padding, 0.0, 1e6)?;
        super::error::check_count(MobileField::Astar(AstarField::MaxCells), self.max_cells, 4)
    }
}

#[derive(PartialEq)]
struct Open(f64, usize);
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

struct Grid {
    x0: f64,
    y0: f64,
    res: f64,
    nx: usize,
    ny: usize,
    blocked: Vec<bool>,
}

impl Grid {
    fn cell(&self, p: Point2) -> (usize, usize) {
        let i = ((p.x - self.x0) / self.res)
            .floor()
            .clamp(0.0, (self.nx - 1) as f64) as usize;
        let j = ((p.y - self.y0) / self.res)
            .floor()
            .clamp(0.0, (self.ny - 1) as f64) as usize;
        (i, j)
    }
    fn centre(&self, i: usize, j: usize) -> Point2 {
        Point2::new(
            self.x0 + (i as f64 + 0.5) * self.res,
            self.y0 + (j as f64 + 0.5) * self.res,
        )
    }
    fn free_line(&self, a: Point2, b: Point2) -> bool {
        let n = (a.distance(b) / (0.5 * self.res)).ceil().max(1.0) as usize;
        (0..=n).all(|k| {
            let t = k as f64 / n as f64;
            let (i, j) = self.cell(Point2::new(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)));
            !self.blocked[j * self.nx + i]
        })
    }
}

/// Plans a collision-free polyline from `start` to `goal`, or `None` when the inflated grid has
/// no path. A*: 8-connected, step costs 1 and √2 (× resolution), octile heuristic
/// h = res·(max(dx,dy) + (√2 − 1)·min(dx,dy)) (admissible, so the grid path is shortest), no
/// corner cutting. The start and goal cells are always treated as free. The cell path is then
/// shortened greedily by line-of-sight checks at half-cell steps.
///
/// ```
/// use kinplan_core::mobile::{plan_grid_astar, GridAstarParams, Obstacle, Point2, World};
/// let w = World::new(vec![Obstacle::circle(2.0, 0.0, 0.5)]).unwrap();
/// let p = plan_grid_astar(&w, Point2::new(0.0, 0.0), Point2::new(4.0, 0.0), &GridAstarParams::default()).unwrap().unwrap();
/// assert!(p.windows(2).map(|s| s[0].distance(s[1])).sum::<f64>() > 4.0);
/// ```
pub fn plan_grid_astar(
    world: &World,
    start: Point2,
    goal: Point2,
    params: &GridAstarParams,
) -> Result<Option<Vec<Point2>>, MobileError> {
    plan_grid_astar_until(world, start, goal, params, Deadline::none())
}

/// [`plan_grid_astar`], polling `deadline` every grid cell while the grid is
/// built and every 1024 expansions while it is searched; `None` when stopped.
pub fn plan_grid_astar_until(
    world: &World,
    start: Point2,
    goal: Point2,
    params: &GridAstarParams,
    deadline: Deadline<'_>,
) -> Result<Option<Vec<Point2>>, MobileError> {
    params.validate()?;
    start.validate(MobileField::Start)?;
    goal.validate(MobileField::Goal)?;
    let (mut lo, mut hi) = (
        Point2::new(start.x.min(goal.x), start.y.min(goal.y)),
        Point2::new(start.x.max(goal.x), start.y.max(goal.y)),
    );
    for o in world.obstacles() {
        let (c, r) = o.bounding_circle();
        lo = Point2::new(lo.x.min(c.x - r), lo.y.min(c.y - r));
        hi = Point2::new(hi.x.max(c.x + r), hi.y.max(c.y + r));
    }
    let res = params.resolution;
    let x0 = lo.x - params.padding;
    let y0 = lo.y - params.padding;
    // Sized in floating point first: a far-away point (1e308) would otherwise
    // saturate or wrap the cast and leave a grid too small for its indices.
    let nxf = ((hi.x + params.padding - x0) / res).ceil() + 1.0;
    let nyf = ((hi.y + params.padding - y0) / res).ceil() + 1.0;
    let cells = nxf * nyf;
    // NaN (from infinite inputs) is refused too.
    if cells.is_nan() || cells > params.max_cells as f64 {
        return Err(MobileError::OutOfRange {
            field: MobileField::Astar(AstarField::GridCells),
            value: cells,
            min: 4.0,
            max: params.max_cells as f64,
        });
    }
    let (nx, ny) = (nxf as usize, nyf as usize);
    let mut g = Grid {
        x0,
        y0,
        res,
        nx,
        ny,
        blocked: vec![false; nx * ny],
    };
    for j in 0..ny {
        for i in 0..nx {
            // One distance query costs O(obstacle edges): ask after each.
            if deadline.expired() {
                return Ok(None);
            }
            g.blocked[j * nx + i] = world.distance(g.centre(i, j)).0 < params.inflation;
        }
    }
    let (si, sj) = g.cell(start);
    let (gi, gj) = g.cell(goal);
    g.blocked[sj * nx + si] = false;
    g.blocked[gj * nx + gi] = false;
    let idx = |i: usize, j: usize| j * nx + i;
    let hfun = |i: usize, j: usize| {
        let dx = (i as f64 - gi as f64).abs();
        let dy = (j as f64 - gj as f64).abs();
        res * (dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy))
    };
    let mut cost = vec![f64::INFINITY; nx * ny];
    let mut parent = vec![usize::MAX; nx * ny];
    let mut heap = BinaryHeap::new();
    cost[idx(si, sj)] = 0.0;
    heap.push(Open(hfun(si, sj), idx(si, sj)));
    let goal_idx = idx(gi, gj);
    let mut found = false;
    let mut expanded = 0u32;
    while let Some(Open(f, c)) = heap.pop() {
        expanded = expanded.wrapping_add(1);
        if expanded.is_multiple_of(1024) && deadline.expired() {
            return Ok(None);
        }
        if c == goal_idx {
            found = true;
            break;
        }
        let (i, j) = (c % nx, c / nx);
        if f > cost[c] + hfun(i, j) + 1e-12 {
            continue;
        }
        for (di, dj) in [
            (-1i64, 0i64),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (-1, 1),
            (1, -1),
            (1, 1),
        ] {
            let (ni, nj) = (i as i64 + di, j as i64 + dj);
            if ni < 0 || nj < 0 || ni >= nx as i64 || nj >= ny as i64 {
                continue;
            }
            let (ni, nj) = (ni as usize, nj as usize);
            if g.blocked[idx(ni, nj)] {
                continue;
            }
            if di != 0 && dj != 0 && (g.blocked[idx(ni, j)] || g.blocked[idx(i, nj)]) {
                continue;
            }
            let step = if di != 0 && dj != 0 {
                std::f64::consts::SQRT_2 * res
            } else {
                res
            };
            let nc = cost[c] + step;
            let n = idx(ni, nj);
            if nc < cost[n] {
                cost[n] = nc;
                parent[n] = c;
                heap.push(Open(nc + hfun(ni, nj), n));
            }
        }
    }
    if !found {
        return Ok(None);
    }
    let mut cells = vec![goal_idx];
    while let Some(&c) = cells.last() {
        if parent[c] == usize::MAX {
            break;
        }
        cells.push(parent[c]);
    }
    cells.reverse();
    let mut pts: Vec<Point2> = cells.iter().map(|&c| g.centre(c % nx, c / nx)).collect();
    if let Some(f) = pts.first_mut() {
        *f = start;
    }
    if let Some(l) = pts.last_mut() {
        *l = goal;
    }
    // Greedy line-of-sight shortcutting.
    let mut out = vec![pts[0]];
    let mut k = 0;
    while k + 1 < pts.len() {
        let mut far = k + 1;
        for m in (k + 2..pts.len()).rev() {
            if g.free_line(pts[k], pts[m]) {
                far = m;
                break;
            }
        }
        out.push(pts[far]);
        k = far;
    }
    Ok(Some(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mobile::world::Obstacle;

    #[test]
    fn open_world_gives_the_straight_segment() {
        let p = plan_grid_astar(
            &World::default(),
            Point2::new(0.0, 0.0),
            Point2::new(3.0, 4.0),
            &GridAstarParams::default(),
        )
        .unwrap()
        .unwrap();
        assert_eq!(p, vec![Point2::new(0.0, 0.0), Point2::new(3.0, 4.0)]);
    }

    #[test]
    fn detour_is_close_to_the_tangent_path() {
        // Disc of radius 1 (+0.32 inflation → 1.32) centred between start and goal 4 m apart:
        // the shortest path is tangent–arc–tangent, length 2√(2² − 1.32²) + 1.32·(π − 2·acos(1.32/2))
        // = 3.0049 + 1.32 · (π − 2·0.8501) = 3.0049 + 1.9026 = 4.9075 m. A polyline outside the
        // inflated disc is a little longer.
        let w = World::new(vec![Obstacle::circle(2.0, 0.0, 1.0)]).unwrap();
        let p = plan_grid_astar(
            &w,
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 0.0),
            &GridAstarParams::default(),
        )
        .unwrap()
        .unwrap();
        let len: f64 = p.windows(2).map(|s| s[0].distance(s[1])).sum();
        assert!(len > 4.9075 - 0.02 && len < 4.9075 + 0.15, "{len}");
        for s in p.windows(2) {
            for k in 0..=20 {
                let t = k as f64 / 20.0;
                let q = Point2::new(s[0].x + t * (s[1].x - s[0].x), s[0].y + t * (s[1].y - s[0].y));
                assert!(w.distance(q).0 > 0.25);
            }
        }
    }

    #[test]
    fn far_points_never_index_out_of_bounds() {
        // Regression: start.x = 1e308 sized the grid by a saturated cast and
        // indexed out of bounds.
        let w = World::new(vec![Obstacle::circle(2.0, 0.0, 0.5)]).unwrap();
        let p = GridAstarParams::default();
        assert!(plan_grid_astar(&w, Point2::new(1e308, 0.0), Point2::new(4.0, 0.0), &p).is_err());
        // Far but in-world points: a grid too large is refused, never allocated.
        let far = plan_grid_astar(&w, Point2::new(-9e5, -9e5), Point2::new(9e5, 9e5), &p);
        assert!(matches!(far, Err(MobileError::OutOfRange { .. })), "{far:?}");
    }

    #[test]
    fn enclosed_goal_has_no_path() {
        let w = World::new(vec![Obstacle::polygon(&[
            (-1.0, -1.0),
            (1.0, -1.0),
            (1.0, 1.0),
            (-1.0, 1.0),
        ])])
        .unwrap();
        // Goal inside the square, start outside: blocked cells surround the goal cell.
        let r = plan_grid_astar(
            &w,
            Point2::new(3.0, 0.0),
            Point2::new(0.0, 0.0),
            &GridAstarParams::default(),
        )
        .unwrap();
        assert!(r.is_none());
    }
}
