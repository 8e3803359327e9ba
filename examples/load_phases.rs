//! Where loading a robot sent with its meshes spends its time: the mesh
//! files read, the collision bodies (hulls, fitted polytopes), the pair
//! tables with the sampled allowed-collision matrix, and the sampling alone
//! (the tables kept). Median of `--rounds` loads, on pools of one and two
//! threads (or of `--threads`).
//!
//! ```text
//! cargo run --release -p kinplan-core --example load_phases -- \
//!     <urdf> <package root> <base link> <tip link> [--rounds N] [--threads N]
//! ```

use std::sync::Arc;
use std::time::Instant;

use kinplan_core::Deadline;
use kinplan_core::collision::{AcmParams, AllowedCollisions, MeshFileLimits, RobotModel, read_mesh_file};
use kinplan_core::robot::{ChainSpec, UrdfLimits, parse_chain};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [urdf_path, root, base, tip, ..] = &args[..] else {
        return Err(
            "usage: load_phases <urdf> <package root> <base link> <tip link> [--rounds N] [--threads N]"
                .into(),
        );
    };
    let option = |name: &str| args.iter().position(|a| a == name).map(|i| args.get(i + 1));
    let rounds: usize = match option("--rounds") {
        Some(value) => value.ok_or("--rounds needs a count")?.parse()?,
        None => 21,
    };
    let threads: Vec<usize> = match option("--threads") {
        Some(value) => vec![value.ok_or("--threads needs a count")?.parse()?],
        None => vec![1, 2],
    };
    let urdf = std::fs::read_to_string(urdf_path)?;
    // the meshes of <collision> elements (a client sends no visual meshes)
    let mut uris: Vec<String> = urdf
        .split("<collision")
        .skip(1)
        .filter_map(|c| c.split("</collision>").next())
        .filter_map(|c| c.split("filename=\"").nth(1))
        .filter_map(|s| s.split('"').next())
        .map(str::to_string)
        .collect();
    uris.sort();
    uris.dedup();
    let files: Vec<(String, Vec<u8>)> = uris
        .iter()
        .map(|u| {
            let path = format!("{root}/{}", u.trim_start_matches("package://"));
            std::fs::read(&path).map(|b| (u.clone(), b))
        })
        .collect::<Result<_, _>>()?;
    let spec = ChainSpec {
        base_link: Some(base.clone()),
        tip_link: Some(tip.clone()),
    };
    let chain = Arc::new(parse_chain(&urdf, &spec, UrdfLimits::default())?);
    let params = AcmParams::default();
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    for threads in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let mut phases = vec![Vec::new(); 4];
        for _ in 0..rounds {
            pool.install(|| -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
                let t = Instant::now();
                let meshes = files
                    .iter()
                    .map(|(u, b)| read_mesh_file(u, b, &MeshFileLimits::default()))
                    .collect::<Result<Vec<_>, _>>()?;
                phases[0].push(ms(t));
                let t = Instant::now();
                let model = RobotModel::of_urdf_until(chain.clone(), &urdf, &[], &meshes, Deadline::none())?;
                phases[1].push(ms(t));
                let t = Instant::now();
                let first = AllowedCollisions::sampled(&model, &params)?;
                phases[2].push(ms(t));
                let t = Instant::now();
                let again = AllowedCollisions::sampled(&model, &params)?;
                phases[3].push(ms(t));
                assert_eq!(first, again);
                Ok(())
            })
            .map_err(|e| e.to_string())?;
        }
        let [read, bodies, tables_acm, acm] = [0, 1, 2, 3].map(|k| median(phases[k].clone()));
        println!(
            "threads {threads}: read meshes {read:.2} ms, bodies {bodies:.2} ms, pair tables + sampled matrix {tables_acm:.2} ms \
             (sampling alone {acm:.2} ms), total {:.2} ms",
            read + bodies + tables_acm
        );
    }
    Ok(())
}
