//! Budget: one plant step (200 Hz physics) well under 10 µs: one RK4 sub-step, three
//! least-squares solves over the car-like chassis' six wheel constraints, a collision query. The LIDAR has its own bench
//! (`benches/lidar.rs`).

use criterion::{criterion_group, criterion_main, Criterion};
use mobil_chassis::{inverse, BodyTwist, ChassisParams};
use mobil_sim::plant::{Plant, PlantConfig};
use mobil_world::World;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let world = World::builtin();
    let params = ChassisParams::mobil2();
    let mut plant = Plant::new(
        PlantConfig {
            params,
            motor_time_constant: 0.05,
            wheel_speed_noise: 0.01,
            wheel_slip: 0.0,
            robot_radius: 0.53,
        },
        nalgebra::Vector3::zeros(),
        1,
    );
    let accepted = plant.command(&inverse(&params, BodyTwist::new(0.1, 0.0, 0.1)));
    assert!(accepted.is_ok(), "{accepted:?}");
    c.bench_function("plant_step_car_like", |b| {
        b.iter(|| plant.step(black_box(0.005), black_box(&world)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
