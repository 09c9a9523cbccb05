//! One scan's processing: sectors + F + one mode step for a 1081-beam scan (budget < 50 µs).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{MotionLimits, NavConfig, Navigator};
use nalgebra::Point2;

fn scan() -> Scan {
    // 270°, 1081 beams: a wall 1.5 m ahead (x = 1.5), open elsewhere.
    let fov = 0.75 * std::f64::consts::PI;
    let inc = 2.0 * fov / 1080.0;
    let ranges = (0..1081)
        .map(|i| {
            let a = -fov + i as f64 * inc;
            if a.cos() > 0.2 {
                (1.5 / a.cos()).min(10.0) as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    Scan::new(-fov, fov, inc, 0.05, 10.0, ranges, vec![], Pose2::identity()).expect("valid scan")
}

fn bench(c: &mut Criterion) {
    let scan = scan();
    let limits = MotionLimits::from_chassis(&ChassisParams::omr3());
    let mut nav = Navigator::new(NavConfig::default(), limits).expect("valid config");
    nav.set_goal(Point2::new(5.0, 0.3)).expect("finite goal");
    let mut x = 0.0;
    c.bench_function("local_nav step, 1081 beams (sectors + F + mode)", |b| {
        b.iter(|| {
            x += 1e-4;
            black_box(nav.step(Pose2::new(black_box(x), 0.0, 0.0), black_box(&scan)))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
