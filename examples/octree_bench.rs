//! Timings of the octree room on the inputs `benches/octomap/compare.py` prepares, so
//! OctoMap's figures and ours come from the same data in one run. Prints one JSON object.
//!
//! cargo run --release -p kinplan-core --example octree_bench -- GEB079.bt RAYS.bin CLOUD.bin OUT_DIR
//!
//! RAYS.bin: u32 n, then n × (f32 origin[3], f32 direction[3]).
//! CLOUD.bin: f32 origin[3], u32 n, then n × f32 point[3].

use std::time::Instant;

use kinplan_core::octree::{Octree, OctreeLimits, RayParams, ScanParams};
use nalgebra::{Point3, Vector3};

fn f32s(b: &[u8], at: usize, n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| f32::from_le_bytes(b[at + 4 * i..at + 4 * i + 4].try_into().unwrap()))
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        eprintln!("usage: octree_bench GEB079.bt RAYS.bin CLOUD.bin OUT_DIR");
        std::process::exit(2);
    }
    let geb = std::fs::read(&args[1]).expect("geb079.bt");
    let lim = OctreeLimits::default();
    // parse / write
    let mut parse = Vec::new();
    let mut write = Vec::new();
    let mut tree = Octree::read_bt(&geb, &lim).unwrap();
    for _ in 0..30 {
        let t = Instant::now();
        tree = Octree::read_bt(&geb, &lim).unwrap();
        parse.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let out = tree.write_bt();
        write.push(t.elapsed().as_secs_f64() * 1e3);
        assert!(out == geb, "write-back differs");
    }
    // rays
    let rb = std::fs::read(&args[2]).expect("rays");
    let n = u32::from_le_bytes(rb[0..4].try_into().unwrap()) as usize;
    let v = f32s(&rb, 4, 6 * n);
    let rays: Vec<(Point3<f64>, Vector3<f64>)> = (0..n)
        .map(|i| {
            let r = &v[6 * i..6 * i + 6];
            (
                Point3::new(r[0] as f64, r[1] as f64, r[2] as f64),
                Vector3::new(r[3] as f64, r[4] as f64, r[5] as f64),
            )
        })
        .collect();
    let p = RayParams::default();
    let mut ends = Vec::with_capacity(n * 13);
    let mut steps = 0u64;
    let mut best_serial = f64::INFINITY;
    for rep in 0..5 {
        let t = Instant::now();
        for (o, d) in &rays {
            let h = tree.cast_ray(o, d, &p).unwrap();
            if rep == 0 {
                steps += h.steps as u64;
                ends.extend_from_slice(&(h.end.x as f32).to_le_bytes());
                ends.extend_from_slice(&(h.end.y as f32).to_le_bytes());
                ends.extend_from_slice(&(h.end.z as f32).to_le_bytes());
                ends.push(h.hit as u8);
            }
        }
        best_serial = best_serial.min(t.elapsed().as_secs_f64());
    }
    let mut best_par = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        let r = tree.cast_rays(&rays, &p);
        best_par = best_par.min(t.elapsed().as_secs_f64());
        assert_eq!(r.len(), n);
    }
    // ray steps/s/core on long rays through unknown-free space: ignore unknown, 20 m range
    let long = RayParams {
        ignore_unknown: true,
        max_range: 20.0,
    };
    let t = Instant::now();
    let mut long_steps = 0u64;
    for (o, d) in &rays {
        long_steps += tree.cast_ray(o, d, &long).unwrap().steps as u64;
    }
    let long_s = t.elapsed().as_secs_f64();
    // insert
    let cb = std::fs::read(&args[3]).expect("cloud");
    let o = f32s(&cb, 0, 3);
    let m = u32::from_le_bytes(cb[12..16].try_into().unwrap()) as usize;
    let pv = f32s(&cb, 16, 3 * m);
    let pts: Vec<[f32; 3]> = pv.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let origin = [o[0], o[1], o[2]];
    let mut ins = Vec::new();
    let mut last = None;
    for _ in 0..7 {
        let mut t = Octree::new(0.05).unwrap();
        let s = Instant::now();
        let st = t
            .insert_scan(
                &pts,
                &origin,
                &ScanParams::default(),
                kinplan_core::Deadline::none(),
            )
            .unwrap();
        ins.push(s.elapsed().as_secs_f64() * 1e3);
        last = Some((t, st));
    }
    let (t, st) = last.unwrap();
    let out = std::path::Path::new(&args[4]);
    std::fs::write(out.join("ours_insert.ot"), t.write_ot()).unwrap();
    std::fs::write(out.join("ours_insert.bt"), t.write_bt()).unwrap();
    std::fs::write(out.join("ours_ray_ends.bin"), &ends).unwrap();
    println!(
        "{{\"parse_ms\": {:.3}, \"write_ms\": {:.3}, \"bt_bytes\": {}, \"rays\": {n}, \"cast_serial_s\": {best_serial:.6}, \"cast_par_s\": {best_par:.6}, \"cast_steps\": {steps}, \"long_steps\": {long_steps}, \"long_s\": {long_s:.6}, \"threads\": {}, \"insert_ms\": {:.3}, \"insert_trace_ms\": {:.3}, \"insert_update_ms\": {:.3}, \"points\": {m}, \"free_cells\": {}, \"occupied_cells\": {}, \"nodes\": {}}}",
        median(parse),
        median(write),
        geb.len(),
        rayon::current_num_threads(),
        median(ins),
        st.trace_us as f64 / 1e3,
        st.update_us as f64 / 1e3,
        st.free_cells,
        st.occupied_cells,
        st.nodes
    );
}
