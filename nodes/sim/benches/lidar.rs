//! Budget: one 1081-beam scan of the built-in world well under 1 ms.
//!
//! `cargo bench -p mobil_sim --bench lidar -- --warm-up-time 1 --measurement-time 2`

use criterion::{criterion_group, criterion_main, Criterion};
use mobil_sim::lidar::{Lidar, LidarConfig};
use mobil_world::World;
use nalgebra::Point2;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let world = World::builtin();
    // On the demo loop, looking north-east across the room: most beams hit walls 5–7 m away.
    let pose = (0.5, 0.2, 0.3);
    let mut lidar = Lidar::new(LidarConfig::default(), 1);
    c.bench_function("lidar_scan_1081_beams_builtin_world", |b| {
        b.iter(|| lidar.scan(black_box(&world), black_box(pose)))
    });
    let mut noisy = Lidar::new(
        LidarConfig {
            noise_std: 0.01,
            ..LidarConfig::default()
        },
        1,
    );
    c.bench_function("lidar_scan_1081_beams_builtin_world_noisy", |b| {
        b.iter(|| noisy.scan(black_box(&world), black_box(pose)))
    });
    c.bench_function("world_ray_distance_builtin", |b| {
        b.iter(|| world.ray_distance(black_box(Point2::new(0.5, 0.2)), black_box(0.7), 10.0))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
