//! Two seeded reference cells for the ABB IRB 4600 in the spirit of S0's
//! Fig. 5.2 (an open cell with occluded pockets) and Fig. 5.8 (a cell behind
//! a wall). The robot stands at the origin facing +x on a plinth (not
//! modelled) whose top is 0.35 m above the floor, so the floor's top is
//! z = −0.35 (the base's collision sphere reaches z = −0.3); a room (walls
//! 2.85 m high) closes the view so every pixel returns a depth, as in S0's
//! Gazebo world. Regions start above the floor's cells.

use nalgebra::{Isometry3, Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::collision::{Geometry, Obstacle};

/// A reference scene: obstacles, the region to explore and a start state.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceScene {
    pub name: &'static str,
    /// Built-in robot the start joints belong to.
    pub robot: &'static str,
    pub obstacles: Vec<Obstacle>,
    /// The box to explore (m, base frame).
    pub region: (Point3<f64>, Point3<f64>),
    /// Start joints (rad): camera above the cell, looking into it.
    pub start: Vec<f64>,
}

fn cuboid(name: impl Into<String>, c: [f64; 3], half: [f64; 3]) -> Obstacle {
    Obstacle::new(
        name,
        Isometry3::translation(c[0], c[1], c[2]),
        Geometry::Box {
            half_extents: Vector3::new(half[0], half[1], half[2]),
        },
    )
}

fn cylinder(name: impl Into<String>, c: [f64; 3], radius: f64, length: f64) -> Obstacle {
    Obstacle::new(
        name,
        Isometry3::translation(c[0], c[1], c[2]),
        Geometry::Cylinder { radius, length },
    )
}

/// Height of the floor's top (m).
const FLOOR: f64 = -0.35;

/// Floor and room walls beyond the region.
fn room() -> Vec<Obstacle> {
    let (h, zc) = (1.425, FLOOR + 1.425);
    vec![
        cuboid("floor", [1.0, 0.0, FLOOR - 0.05], [4.0, 4.0, 0.05]),
        cuboid("back wall", [4.2, 0.0, zc], [0.1, 4.0, h]),
        cuboid("left wall", [1.0, 3.2, zc], [3.0, 0.1, h]),
        cuboid("right wall", [1.0, -3.2, zc], [3.0, 0.1, h]),
        cuboid("rear wall", [-2.2, 0.0, zc], [0.1, 4.0, h]),
    ]
}

/// Boxes of random size scattered on the floor and on the table tops,
/// drawn from `rng` inside `x`, `y` (m).
fn clutter(rng: &mut ChaCha8Rng, count: usize, x: (f64, f64), y: (f64, f64), base_z: f64) -> Vec<Obstacle> {
    (0..count)
        .map(|i| {
            let h = [
                rng.random_range(0.08..0.2),
                rng.random_range(0.08..0.2),
                rng.random_range(0.08..0.25),
            ];
            let c = [
                rng.random_range(x.0..x.1),
                rng.random_range(y.0..y.1),
                base_z + h[2],
            ];
            cuboid(format!("box {i}"), c, h)
        })
        .collect()
}

/// S0 Fig. 5.2-like open cell: two tables with boxes on and under them, a
/// tall cabinet and a drum, so that a part of the region (≈ 30 %) stays
/// hidden from the start pose and its wrist sweep.
pub fn s0_open_cell(seed: u64) -> ReferenceScene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut obstacles = room();
    // tables: tops at 0.7 m on four legs
    for (k, (cx, cy)) in [(2.3, 0.65), (2.4, -0.75)].into_iter().enumerate() {
        obstacles.push(cuboid(
            format!("table {k} top"),
            [cx, cy, FLOOR + 0.68],
            [0.35, 0.4, 0.02],
        ));
        for (dx, dy) in [(-0.3, -0.35), (-0.3, 0.35), (0.3, -0.35), (0.3, 0.35)] {
            obstacles.push(cuboid(
                format!("table {k} leg"),
                [cx + dx, cy + dy, FLOOR + 0.33],
                [0.025, 0.025, 0.33],
            ));
        }
        obstacles.extend(clutter(
            &mut rng,
            2,
            (cx - 0.2, cx + 0.2),
            (cy - 0.25, cy + 0.25),
            FLOOR + 0.7,
        ));
        obstacles.extend(clutter(
            &mut rng,
            1,
            (cx - 0.15, cx + 0.15),
            (cy - 0.2, cy + 0.2),
            FLOOR,
        ));
    }
    obstacles.push(cuboid("cabinet", [2.95, 0.0, FLOOR + 0.75], [0.2, 0.3, 0.75]));
    obstacles.push(cylinder("drum", [1.8, -1.2, FLOOR + 0.45], 0.22, 0.9));
    ReferenceScene {
        name: "s0_open_cell",
        robot: "abb_irb4600_60_205",
        obstacles,
        region: (Point3::new(1.2, -1.5, FLOOR + 0.06), Point3::new(3.2, 1.5, 1.2)),
        start: vec![0.35, -0.2, 0.3, 0.0, 0.75, 0.0],
    }
}

/// S0 Fig. 5.8-like walled cell: the same kind of clutter inside a 1.2 m
/// high wall on all four sides, so the start pose (camera below the wall
/// top, facing it) sees little (> 80 % of the region unknown afterwards).
pub fn s0_walled_cell(seed: u64) -> ReferenceScene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut obstacles = room();
    let (x0, x1, y0, y1, h) = (1.4, 3.0, -1.2, 1.2, 1.5);
    let (t, zc) = (0.05, FLOOR + h / 2.0);
    obstacles.push(cuboid(
        "front wall",
        [x0, 0.0, zc],
        [t, (y1 - y0) / 2.0 + t, h / 2.0],
    ));
    obstacles.push(cuboid(
        "far wall",
        [x1, 0.0, zc],
        [t, (y1 - y0) / 2.0 + t, h / 2.0],
    ));
    obstacles.push(cuboid(
        "side wall +y",
        [(x0 + x1) / 2.0, y1, zc],
        [(x1 - x0) / 2.0, t, h / 2.0],
    ));
    obstacles.push(cuboid(
        "side wall -y",
        [(x0 + x1) / 2.0, y0, zc],
        [(x1 - x0) / 2.0, t, h / 2.0],
    ));
    obstacles.push(cuboid("table top", [2.3, 0.5, FLOOR + 0.58], [0.35, 0.35, 0.02]));
    for (dx, dy) in [(-0.3, -0.3), (-0.3, 0.3), (0.3, -0.3), (0.3, 0.3)] {
        obstacles.push(cuboid(
            "table leg",
            [2.3 + dx, 0.5 + dy, FLOOR + 0.28],
            [0.025, 0.025, 0.28],
        ));
    }
    obstacles.extend(clutter(&mut rng, 3, (2.1, 2.5), (0.3, 0.7), FLOOR + 0.6));
    obstacles.extend(clutter(&mut rng, 4, (1.8, 2.7), (-0.9, 0.0), FLOOR));
    obstacles.push(cylinder("drum", [2.65, -0.7, FLOOR + 0.4], 0.2, 0.8));
    ReferenceScene {
        name: "s0_walled_cell",
        robot: "abb_irb4600_60_205",
        obstacles,
        region: (
            Point3::new(x0 + t, y0 + t, FLOOR + 0.06),
            Point3::new(x1 - t, y1 - t, FLOOR + h),
        ),
        start: vec![0.0, -0.3, 0.6, 0.0, 0.0, 0.0],
    }
}
