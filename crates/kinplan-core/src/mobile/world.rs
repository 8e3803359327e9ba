//! The 2-D world of circular and polygonal obstacles: signed distances, clearance of a disc
//! robot and ray casting for range sensors.

use serde::{Deserialize, Serialize};

use super::error::{MobileError, check_count, check_positive};
use super::field::{MobileField, ObstaclePart};
use super::pose::Point2;

/// An obstacle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Obstacle {
    /// A disc: centre (m) and radius (m).
    Circle {
        /// Centre.
        center: Point2,
        /// Radius, m.
        radius: f64,
    },
    /// A simple polygon (convex or not), vertices in order (either orientation), ≥ 3.
    Polygon {
        /// Vertices, m.
        vertices: Vec<Point2>,
    },
}

impl Obstacle {
    /// A circle.
    pub fn circle(x: f64, y: f64, radius: f64) -> Self {
        Obstacle::Circle {
            center: Point2::new(x, y),
            radius,
        }
    }

    /// A polygon from (x, y) pairs.
    pub fn polygon(vertices: &[(f64, f64)]) -> Self {
        Obstacle::Polygon {
            vertices: vertices.iter().map(|&(x, y)| Point2::new(x, y)).collect(),
        }
    }

    /// Signed distance from `p` to the boundary, m: negative inside.
    pub fn signed_distance(&self, p: Point2) -> f64 {
        match self {
            Obstacle::Circle { center, radius } => p.distance(*center) - radius,
            Obstacle::Polygon { vertices } => {
                let n = vertices.len();
                let mut best = f64::INFINITY;
                let mut inside = false;
                for i in 0..n {
                    let a = vertices[i];
                    let b = vertices[(i + 1) % n];
                    best = best.min(segment_distance(p, a, b));
                    if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                        inside = !inside;
                    }
                }
                if inside { -best } else { best }
            }
        }
    }

    /// Distance along the ray o + t·(cos a, sin a) to the first boundary crossing, if any;
    /// 0 when `o` is inside.
    pub fn ray_hit(&self, o: Point2, dir: (f64, f64)) -> Option<f64> {
        match self {
            Obstacle::Circle { center, radius } => {
                let (fx, fy) = (o.x - center.x, o.y - center.y);
                let c = fx * fx + fy * fy - radius * radius;
                if c <= 0.0 {
                    return Some(0.0);
                }
                let b = fx * dir.0 + fy * dir.1;
                if b >= 0.0 {
                    return None;
                }
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                Some(-b - disc.sqrt())
            }
            Obstacle::Polygon { vertices } => {
                if self.signed_distance(o) <= 0.0 {
                    return Some(0.0);
                }
                let n = vertices.len();
                let mut best: Option<f64> = None;
                for i in 0..n {
                    let a = vertices[i];
                    let b = vertices[(i + 1) % n];
                    let (ex, ey) = (b.x - a.x, b.y - a.y);
                    let den = dir.0 * ey - dir.1 * ex;
                    if den.abs() < 1e-15 {
                        continue;
                    }
                    let (wx, wy) = (a.x - o.x, a.y - o.y);
                    let t = (wx * ey - wy * ex) / den;
                    let u = (wx * dir.1 - wy * dir.0) / den;
                    if t >= 0.0 && (0.0..=1.0).contains(&u) {
                        best = Some(best.map_or(t, |b: f64| b.min(t)));
                    }
                }
                best
            }
        }
    }

    /// Centre and radius of a bounding circle.
    pub fn bounding_circle(&self) -> (Point2, f64) {
        match self {
            Obstacle::Circle { center, radius } => (*center, *radius),
            Obstacle::Polygon { vertices } => {
                let n = vertices.len().max(1) as f64;
                let c = Point2::new(
                    vertices.iter().map(|v| v.x).sum::<f64>() / n,
                    vertices.iter().map(|v| v.y).sum::<f64>() / n,
                );
                let r = vertices.iter().map(|v| v.distance(c)).fold(0.0, f64::max);
                (c, r)
            }
        }
    }
}

fn segment_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p.x - a.x) * dx + (p.y - a.y) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(Point2::new(a.x + t * dx, a.y + t * dy))
}

/// A set of static obstacles with cached bounding circles (build it with [`World::new`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct World {
    obstacles: Vec<Obstacle>,
    bounds: Vec<(Point2, f64)>,
}

impl World {
    /// Validates and wraps the obstacles: finite coordinates, positive radii, polygons with
    /// ≥ 3 vertices.
    pub fn new(obstacles: Vec<Obstacle>) -> Result<Self, MobileError> {
        for (i, o) in obstacles.iter().enumerate() {
            match o {
                Obstacle::Circle { center, radius } => {
                    center.validate(|c| MobileField::Obstacle {
                        index: i,
                        part: ObstaclePart::Center(c),
                    })?;
                    check_positive(
                        MobileField::Obstacle {
                            index: i,
                            part: ObstaclePart::Radius,
                        },
                        *radius,
                    )?;
                }
                Obstacle::Polygon { vertices } => {
                    check_count(
                        MobileField::Obstacle {
                            index: i,
                            part: ObstaclePart::Vertices,
                        },
                        vertices.len(),
                        3,
                    )?;
                    for (j, v) in vertices.iter().enumerate() {
                        v.validate(|part| MobileField::Obstacle {
                            index: i,
                            part: ObstaclePart::Vertex { index: j, part },
                        })?;
                    }
                }
            }
        }
        let bounds = obstacles.iter().map(Obstacle::bounding_circle).collect();
        Ok(Self { obstacles, bounds })
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Smallest signed distance from `p` to any obstacle and that obstacle's index
    /// (`(∞, None)` for an empty world).
    pub fn distance(&self, p: Point2) -> (f64, Option<usize>) {
        let mut best = (f64::INFINITY, None);
        for (i, o) in self.obstacles.iter().enumerate() {
            if let Some(&(c, r)) = self.bounds.get(i)
                && p.distance(c) - r >= best.0
            {
                continue;
            }
            let d = o.signed_distance(p);
            if d < best.0 {
                best = (d, Some(i));
            }
        }
        best
    }

    /// Collects into `out` the indices of obstacles that may lie within `range` of `p`.
    pub fn nearby(&self, p: Point2, range: f64, out: &mut Vec<usize>) {
        out.clear();
        for (i, &(c, r)) in self.bounds.iter().enumerate() {
            if p.distance(c) - r <= range {
                out.push(i);
            }
        }
    }

    /// Distance to the first obstacle along the ray from `o` at world angle `angle`, capped at
    /// `max_range`; only obstacles listed in `candidates` are tested.
    pub fn raycast(&self, o: Point2, angle: f64, max_range: f64, candidates: &[usize]) -> f64 {
        let dir = angle.sin_cos();
        let dir = (dir.1, dir.0);
        let mut best = max_range;
        for &i in candidates {
            if let Some(t) = self.obstacles[i].ray_hit(o, dir) {
                best = best.min(t);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_hand_computed() {
        let w = World::new(vec![
            Obstacle::circle(3.0, 0.0, 1.0),
            Obstacle::polygon(&[(-1.0, -1.0), (-1.0, 1.0), (-3.0, 1.0), (-3.0, -1.0)]),
        ])
        .unwrap();
        assert_eq!(w.distance(Point2::new(0.0, 0.0)), (1.0, Some(1)));
        assert!((w.obstacles()[1].signed_distance(Point2::new(-2.0, 0.0)) + 1.0).abs() < 1e-12);
        let all = [0, 1];
        assert!((w.raycast(Point2::new(0.0, 0.0), 0.0, 10.0, &all) - 2.0).abs() < 1e-12);
        assert!((w.raycast(Point2::new(0.0, 0.0), std::f64::consts::PI, 10.0, &all) - 1.0).abs() < 1e-12);
        assert_eq!(
            w.raycast(Point2::new(0.0, 0.0), std::f64::consts::FRAC_PI_2, 10.0, &all),
            10.0
        );
    }

    #[test]
    fn invalid_obstacles_are_rejected() {
        assert!(World::new(vec![Obstacle::circle(0.0, 0.0, 0.0)]).is_err());
        assert!(matches!(
            World::new(vec![Obstacle::polygon(&[(0.0, 0.0), (1.0, 0.0)])]),
            Err(MobileError::TooFew { .. })
        ));
        assert!(World::new(vec![Obstacle::circle(f64::NAN, 0.0, 1.0)]).is_err());
    }
}
