//! Sphere models of the built-in robots: per robot the fine spheres over all
//! bodies, the largest overshoot beyond a body, and the build time at model
//! load (median of 201 builds), for a few `SphereParams`.
//!
//! ```text
//! cargo run --release -p kinplan-core --example sphere_model
//! ```

use std::time::Instant;

use kinplan_core::collision::{RobotModel, SphereModel, SphereParams};
use kinplan_core::robot::{BUILTIN_NAMES, builtin_chain, builtin_urdf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // (0.02, 16) is the eight-lane checks' setting
    let settings = [(0.005, 64), (0.01, 64), (0.02, 32), (0.02, 16), (0.05, 8)];
    println!(
        "| robot | bodies | max overshoot (m) / per shape | fine spheres | largest overshoot (mm) | build (µs, median of 201) |"
    );
    println!("|---|---|---|---|---|---|");
    for name in BUILTIN_NAMES {
        if name.starts_with("planar") {
            continue;
        }
        let chain = builtin_chain(name)?;
        let model = RobotModel::of_urdf(chain, builtin_urdf(name)?, &[], &[])?;
        for (max_overshoot, max_per_shape) in settings {
            let params = SphereParams {
                max_overshoot,
                max_per_shape,
            };
            let mut times = Vec::with_capacity(201);
            let mut spheres = SphereModel::build(&model, &params)?;
            for _ in 0..201 {
                let t = Instant::now();
                spheres = SphereModel::build(&model, &params)?;
                times.push(t.elapsed().as_secs_f64() * 1e6);
            }
            times.sort_by(f64::total_cmp);
            let worst = (0..spheres.body_count())
                .map(|b| spheres.overshoot(b))
                .fold(0.0, f64::max);
            println!(
                "| {name} | {} | {max_overshoot} / {max_per_shape} | {} | {:.1} | {:.1} |",
                model.body_count(),
                spheres.fine_count(),
                worst * 1e3,
                times[100]
            );
        }
    }
    Ok(())
}
