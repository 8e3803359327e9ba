//! State checks of the Franka Panda (7 joints, 8 collision bodies) against
//! 50 random primitives (boxes, spheres, cylinders, capsules), seeded.
//! `cargo bench -p kinplan-core --bench collision`; figures go to
//! benches/COLLISION_RESULTS.md.
//!
//! Side effect: writes the scene, the robot's shapes, the world pose of
//! every robot shape at each benchmark state, the self-collision pairs and
//! our verdicts to `target/collision_bench/scene.json`, which
//! `benches/collision_coal.py` reads to time coal on the same shapes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::collision::{
    AcmParams, AllowReason, AllowedCollisions, CheckerParams, Geometry, Obstacle, RobotModel, Scene,
    SceneChecker, SceneGeometry, SceneLimits, StateChecker, builtin_mesh,
};
use kinplan_core::robot::{Shape, builtin_chain};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// Counts heap allocations, to show that the queries allocate nothing.
struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const OBSTACLES: usize = 50;
const STATES: usize = 1024;

/// 50 primitives of 3–10 cm half size, centres 0.3–0.9 m from the base at
/// heights 0–1 m, random orientation.
fn scene(rng: &mut ChaCha8Rng) -> Vec<Obstacle> {
    (0..OBSTACLES)
        .map(|i| {
            let r = rng.random_range(0.3..0.9);
            let a = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            let z = rng.random_range(0.0..1.0);
            let rot = UnitQuaternion::from_euler_angles(
                rng.random_range(-3.1..3.1),
                rng.random_range(-3.1..3.1),
                rng.random_range(-3.1..3.1),
            );
            let pose = Isometry3::from_parts(Translation3::new(r * a.cos(), r * a.sin(), z), rot);
            let s = |rng: &mut ChaCha8Rng| rng.random_range(0.03..0.1);
            let g = match i % 4 {
                0 => Geometry::Box {
                    half_extents: Vector3::new(s(rng), s(rng), s(rng)),
                },
                1 => Geometry::Sphere { radius: s(rng) },
                2 => Geometry::Cylinder {
                    radius: s(rng),
                    length: 2.0 * s(rng),
                },
                _ => Geometry::Capsule {
                    radius: s(rng),
                    length: 2.0 * s(rng),
                },
            };
            Obstacle::new(format!("o{i}"), pose, g)
        })
        .collect()
}

fn pose_json(p: &Isometry3<f64>) -> Value {
    let q = p.rotation.quaternion().coords;
    json!({"t": p.translation.vector.as_slice(), "q_xyzw": [q.x, q.y, q.z, q.w]})
}

fn geometry_json(g: &Geometry) -> Value {
    match g {
        Geometry::Box { half_extents } => json!({"box": half_extents.as_slice()}),
        Geometry::Sphere { radius } => json!({"sphere": radius}),
        Geometry::Cylinder { radius, length } => json!({"cylinder": [radius, length]}),
        Geometry::Capsule { radius, length } => json!({"capsule": [radius, length]}),
        _ => unreachable!("the bench scene has primitives only"),
    }
}

/// The full checker (scene + self pairs of the sampled ACM), the scene-only
/// checker (every robot pair allowed, as in the coal comparison) and the states.
fn setup() -> (SceneChecker, SceneChecker, Vec<Vec<f64>>) {
    let chain = builtin_chain("franka_panda").unwrap();
    let model = Arc::new(RobotModel::new(chain.clone()).unwrap());
    let acm = AllowedCollisions::builtin(&model, "franka_panda", &AcmParams::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let obstacles = scene(&mut rng);
    let scene = Scene::new(obstacles.clone(), &SceneLimits::default()).unwrap();
    let world = Arc::new(SceneGeometry::build(&scene).unwrap());
    let checker = SceneChecker::new(model.clone(), &acm, world.clone(), CheckerParams::default()).unwrap();
    let mut all = AllowedCollisions::adjacent(&model);
    for a in 0..model.body_count() {
        for b in 0..model.body_count() {
            all.allow(a, b, AllowReason::User);
        }
    }
    let scene_only = SceneChecker::new(model.clone(), &all, world, CheckerParams::default()).unwrap();
    let states: Vec<Vec<f64>> = (0..STATES)
        .map(|_| chain.limits().map(|(lo, hi)| rng.random_range(lo..=hi)).collect())
        .collect();

    // Dump for the coal comparison.
    let names: Vec<&str> = model.body_names().collect();
    let mut frames = Vec::new();
    let shapes: Vec<Value> = chain
        .collision()
        .iter()
        .flat_map(|lc| {
            lc.shapes.iter().map(move |s| {
                let g = match &s.shape {
                    Shape::Box { half_extents } => json!({"box": half_extents.as_slice()}),
                    Shape::Sphere { radius } => json!({"sphere": radius}),
                    Shape::Cylinder { radius, length } => json!({"cylinder": [radius, length]}),
                    Shape::Capsule { radius, length } => json!({"capsule": [radius, length]}),
                    Shape::MeshReference { filename, scale } => {
                        // the built-in Panda's polytopes are embedded meshes
                        let mesh = builtin_mesh(filename).expect("the built-in Panda's meshes are embedded");
                        let vertices: Vec<[f64; 3]> = mesh
                            .vertices
                            .iter()
                            .map(|p| p.coords.component_mul(scale).into())
                            .collect();
                        json!({"mesh": {"vertices": vertices, "indices": mesh.indices}})
                    }
                };
                json!({"link": lc.link, "geometry": g, "origin": pose_json(&s.origin)})
            })
        })
        .collect();
    let poses: Vec<Value> = states
        .iter()
        .map(|q| {
            chain.link_frames_into(q, &mut frames);
            let links: serde_json::Map<String, Value> = chain
                .links()
                .iter()
                .zip(&frames)
                .map(|(l, f)| (l.name.clone(), pose_json(f)))
                .collect();
            json!({"q": q, "links": links, "valid": checker.is_valid(q), "scene_valid": scene_only.is_valid(q)})
        })
        .collect();
    let pairs: Vec<[&str; 2]> = acm.checked_pairs().map(|(a, b)| [names[a], names[b]]).collect();
    let dump = json!({
        "obstacles": obstacles.iter().map(|o| json!({"name": o.name, "pose": pose_json(&o.pose), "geometry": geometry_json(&o.geometry)})).collect::<Vec<_>>(),
        "robot_shapes": shapes,
        "self_pairs": pairs,
        "states": poses,
    });
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/collision_bench");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.json"), serde_json::to_string(&dump).unwrap()).unwrap();
    (checker, scene_only, states)
}

/// CPU time this thread has run (ns), from `/proc/thread-self/schedstat`:
/// unlike wall time it excludes time spent descheduled on a loaded machine.
fn thread_cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Mean CPU time per call of `f` over `n` calls (ns), when schedstat exists.
fn cpu_per_call(n: usize, mut f: impl FnMut(usize) -> bool) -> Option<f64> {
    let t0 = thread_cpu_ns()?;
    let mut hits = 0;
    for i in 0..n {
        hits += f(i) as usize;
    }
    black_box(hits);
    Some((thread_cpu_ns()? - t0) as f64 / n as f64)
}

fn state_checks(c: &mut Criterion) {
    let (checker, scene_only, states) = setup();
    let valid = states.iter().filter(|q| checker.is_valid(q)).count();
    let scene_valid = states.iter().filter(|q| scene_only.is_valid(q)).count();
    eprintln!("{valid} of {STATES} benchmark states are valid ({scene_valid} free of the scene)");
    let count = |f: &dyn Fn(usize)| {
        let before = ALLOCS.load(Ordering::Relaxed);
        (0..STATES).for_each(f);
        ALLOCS.load(Ordering::Relaxed) - before
    };
    eprintln!(
        "heap allocations over {STATES} states: is_valid {}, clearance {} (on the valid states only: {}), motion_valid {}",
        count(&|i| {
            black_box(checker.is_valid(&states[i]));
        }),
        count(&|i| {
            black_box(checker.clearance(&states[i], 0.5));
        }),
        count(&|i| {
            if checker.is_valid(&states[i]) {
                black_box(checker.clearance(&states[i], 0.5));
            }
        }),
        count(&|i| {
            black_box(checker.motion_valid(&states[i], &states[(i + 1) % STATES]));
        }),
    );
    let n = 400_000;
    let full = cpu_per_call(n, |i| checker.is_valid(black_box(&states[i % STATES])));
    let only = cpu_per_call(n, |i| scene_only.is_valid(black_box(&states[i % STATES])));
    if let (Some(full), Some(only)) = (full, only) {
        eprintln!(
            "thread CPU time per is_valid over {n} calls: {:.3} µs (scene + self), {:.3} µs (scene only)",
            full / 1e3,
            only / 1e3
        );
    }
    let mut i = 0;
    c.bench_function("is_valid/panda_50_primitives", |b| {
        b.iter(|| {
            i = (i + 1) % STATES;
            checker.is_valid(black_box(&states[i]))
        })
    });
    let mut i = 0;
    c.bench_function("is_valid_scene_only/panda_50_primitives", |b| {
        b.iter(|| {
            i = (i + 1) % STATES;
            scene_only.is_valid(black_box(&states[i]))
        })
    });
    let mut i = 0;
    c.bench_function("clearance/panda_50_primitives", |b| {
        b.iter(|| {
            i = (i + 1) % STATES;
            checker.clearance(black_box(&states[i]), 0.5)
        })
    });
    let mut i = 0;
    c.bench_function("motion_valid/panda_50_primitives", |b| {
        b.iter(|| {
            i = (i + 1) % STATES;
            checker.motion_valid(black_box(&states[i]), black_box(&states[(i + 1) % STATES]))
        })
    });
}

criterion_group!(benches, state_checks);
criterion_main!(benches);
