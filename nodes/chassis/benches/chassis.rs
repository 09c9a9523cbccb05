//! Per-call cost of odometry updates, inverse/forward kinematics and command clamping.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use mobil_chassis::{clamp_command, forward, inverse, BodyTwist, ChassisParams, Odometry, OdometryNoise};

fn presets() -> [(&'static str, ChassisParams, BodyTwist); 3] {
    [
        ("tricycle", ChassisParams::tricycle(), BodyTwist::new(0.4, 0.0, 0.3)),
        ("car_like", ChassisParams::mobil2(), BodyTwist::new(0.4, 0.0, 0.3)),
        ("omni", ChassisParams::omr3(), BodyTwist::new(0.3, 0.2, 0.5)),
    ]
}

fn odometry(c: &mut Criterion) {
    let mut group = c.benchmark_group("odometry_update");
    for (name, twist) in [
        ("arc", BodyTwist::new(0.4, 0.0, 0.3)),
        ("straight", BodyTwist::new(0.4, 0.0, 0.0)),
    ] {
        group.bench_function(name, |b| {
            let Ok(mut odom) = Odometry::new(0.3, OdometryNoise::default()) else {
                return;
            };
            b.iter(|| {
                let _ = odom.update(black_box(twist), black_box(0.02));
            });
        });
    }
    group.finish();
}

fn kinematics(c: &mut Criterion) {
    let mut group = c.benchmark_group("inverse");
    for (name, params, twist) in presets() {
        group.bench_function(name, |b| b.iter(|| inverse(&params, black_box(twist))));
    }
    group.finish();

    let mut group = c.benchmark_group("forward");
    for (name, params, twist) in presets() {
        let wheels = inverse(&params, twist);
        group.bench_function(name, |b| b.iter(|| forward(&params, black_box(&wheels))));
    }
    group.finish();

    let mut group = c.benchmark_group("clamp_command");
    for (name, params, _) in presets() {
        let request = BodyTwist::new(0.8, 0.1, 1.2);
        group.bench_function(name, |b| b.iter(|| clamp_command(&params, black_box(request))));
    }
    group.finish();
}

criterion_group!(benches, odometry, kinematics);
criterion_main!(benches);
