//! Development set for the vector-distance navigator: seeded BARN-like worlds generated here
//! (cellular-automaton clutter of 0.075 m cylinders on a 0.15 m grid inside a 4.5 m wide
//! corridor), used to choose d_sa without looking at the BARN worlds.
//!
//! Usage: cargo run --release --example clutter_dev -- [n_worlds] [retry]
//! (`retry`: also with `VdfParams::retry_other_side`)

#![allow(clippy::needless_range_loop)]

use kinplan_core::mobile::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn world(seed: u64) -> Option<World> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (nx, ny) = (28usize, 30usize); // interior cells, x in (-4.35, -0.15), y in [5.0, 9.5)
    let fill = rng.random_range(0.15..0.35);
    let mut g: Vec<Vec<bool>> = (0..ny)
        .map(|_| (0..nx).map(|_| rng.random_bool(fill)).collect())
        .collect();
    for _ in 0..rng.random_range(1..4) {
        let old = g.clone();
        for j in 0..ny {
            for i in 0..nx {
                let mut c = 0;
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (a, b) = (i as i64 + di, j as i64 + dj);
                        if a >= 0
                            && b >= 0
                            && (a as usize) < nx
                            && (b as usize) < ny
                            && old[b as usize][a as usize]
                        {
                            c += 1;
                        }
                    }
                }
                g[j][i] = c >= 5;
            }
        }
    }
    let mut obs = Vec::new();
    for k in 0..64 {
        let y = 0.075 + 0.15 * k as f64;
        obs.push(Obstacle::circle(-0.075, y, 0.075));
        obs.push(Obstacle::circle(-4.425, y, 0.075));
    }
    for i in 1..29 {
        obs.push(Obstacle::circle(-0.075 - 0.15 * i as f64, 0.075, 0.075));
    }
    for (j, row) in g.iter().enumerate() {
        for (i, &b) in row.iter().enumerate() {
            if b {
                obs.push(Obstacle::circle(
                    -0.225 - 0.15 * i as f64,
                    5.025 + 0.15 * j as f64,
                    0.075,
                ));
            }
        }
    }
    let w = World::new(obs).ok()?;
    let p = GridAstarParams {
        inflation: 0.25,
        ..GridAstarParams::default()
    };
    plan_grid_astar(&w, Point2::new(-2.25, 3.0), Point2::new(-2.25, 13.0), &p).ok()??;
    Some(w)
}

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(60);
    let worlds: Vec<World> = (0..).filter_map(world).take(n).collect();
    let chassis = Chassis::Differential(DifferentialParams::default());
    let start = Pose::new(-2.25, 3.0, 1.57);
    let goal = Point2::new(-2.25, 13.0);
    let retries: Vec<bool> = match std::env::args().nth(2).as_deref() {
        Some("retry") => vec![false, true],
        _ => vec![false],
    };
    for d_sa in [0.1, 0.15, 0.2, 0.3] {
        for (guard, retry) in [false, true]
            .into_iter()
            .flat_map(|g| retries.iter().map(move |&r| (g, r)))
        {
            let nav = NavigateParams {
                sim: SimParams {
                    robot_radius: 0.22,
                    dt: 0.05,
                    max_time: 100.0,
                },
                vdf: VdfParams {
                    goal_tolerance: 1.0,
                    safe_distance: d_sa,
                    release_distance: 2.0 * d_sa,
                    avoid_blocked_heading: guard,
                    retry_other_side: retry,
                    ..VdfParams::default()
                },
                ..NavigateParams::default()
            };
            let (mut ok, mut col, mut np, mut to) = (0, 0, 0, 0);
            for w in &worlds {
                match navigate(&chassis, start, goal, w, &nav, kinplan_core::Deadline::none())
                    .expect("valid")
                    .outcome
                {
                    Outcome::Reached => ok += 1,
                    Outcome::Collision => col += 1,
                    Outcome::NoPath => np += 1,
                    _ => to += 1,
                }
            }
            println!(
                "d_sa={d_sa:.2} release={:.2} guard={guard} retry_other_side={retry}: reached {ok}/{n} collision {col} no_path {np} timeout {to}",
                2.0 * d_sa
            );
        }
    }
}
