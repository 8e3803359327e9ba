//! Criterion benchmarks of the octree room: geb079.bt parse / write (skipped when the
//! Debian file is absent), a 512 × 424 insert of the synthetic room at 5 cm, castRay
//! and the exact frustum count on the resulting tree; NextBestView end to end on the room
//! scanned from all its poses (1,000 frontier candidates, S0 filters, IK on the best 10).
//! Seeded, deterministic.

use criterion::{Criterion, criterion_group, criterion_main};
use kinplan_core::nbv::{
    CameraModel, Frustum, FrustumCounter, NbvParams, frustum_unknown_count, look_along, next_best_view,
};
use kinplan_core::octree::{Octree, OctreeLimits, RayParams, ScanParams};
use nalgebra::{Point3, Vector3};

#[path = "../examples/common/room_scene.rs"]
mod room_scene;

fn bench(c: &mut Criterion) {
    let geb = "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt";
    if let Ok(bytes) = std::fs::read(geb) {
        let lim = OctreeLimits::default();
        c.bench_function("octree/geb079_parse", |b| {
            b.iter(|| Octree::read_bt(&bytes, &lim).unwrap())
        });
        let t = Octree::read_bt(&bytes, &lim).unwrap();
        c.bench_function("octree/geb079_write", |b| b.iter(|| t.write_bt()));
    } else {
        println!("SKIPPED geb079 benches: {geb} not present");
    }
    let (o, yaw, pitch) = room_scene::scan_poses()[0];
    let pts = room_scene::beams(o, yaw, pitch, 512, 424, 70.6f64.to_radians(), 60f64.to_radians());
    let origin = o.map(|v| v as f32);
    c.bench_function("octree/insert_512x424_5cm", |b| {
        b.iter(|| {
            let mut t = Octree::new(0.05).unwrap();
            t.insert_scan(
                &pts,
                &origin,
                &ScanParams::default(),
                kinplan_core::Deadline::none(),
            )
            .unwrap()
        })
    });
    let mut t = Octree::new(0.05).unwrap();
    t.insert_scan(
        &pts,
        &origin,
        &ScanParams::default(),
        kinplan_core::Deadline::none(),
    )
    .unwrap();
    let p = RayParams::default();
    c.bench_function("octree/cast_ray_room", |b| {
        b.iter(|| {
            t.cast_ray(&Point3::from(o), &Vector3::new(0.9, 0.3, -0.1), &p)
                .unwrap()
        })
    });
    let cam = CameraModel::default();
    let pose = look_along(&Point3::new(0.0, -1.0, 1.2), &Vector3::new(0.3, 1.0, -0.1)).unwrap();
    let f = Frustum::new(&cam, &pose);
    // per view with the tree's known-cell counts built once, and the one-off build
    let counter = FrustumCounter::new(&t);
    c.bench_function("nbv/frustum_count_per_view_5cm", |b| b.iter(|| counter.count(&f)));
    c.bench_function("nbv/frustum_count_with_build_5cm", |b| {
        b.iter(|| frustum_unknown_count(&t, &f))
    });
    // the room of `nbv_table`'s NBV rows: every scan pose inserted at 5 cm
    let mut room = Octree::new(0.05).unwrap();
    for (o, yaw, pitch) in room_scene::scan_poses() {
        let pts = room_scene::beams(o, yaw, pitch, 512, 424, 70.6f64.to_radians(), 60f64.to_radians());
        room.insert_scan(
            &pts,
            &o.map(|v| v as f32),
            &ScanParams::default(),
            kinplan_core::Deadline::none(),
        )
        .unwrap();
    }
    let chain = kinplan_core::robot::builtin_chain("abb_irb4600_60_205").unwrap();
    let current = look_along(&Point3::new(0.1, 0.2, 1.3), &Vector3::new(1.0, 0.3, 0.0)).unwrap();
    let params = NbvParams::default();
    c.bench_function("nbv/next_best_view_room_5cm", |b| {
        b.iter(|| {
            next_best_view(
                &room,
                &params,
                &cam,
                &current,
                Some(&chain),
                kinplan_core::Deadline::none(),
            )
            .unwrap()
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
