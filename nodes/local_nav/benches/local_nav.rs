//! One scan's processing: sectors + F + one mode step for a 1081-beam scan (budget < 50 µs).
//! The navigator is cloned before each step (outside the timing), so every sample is the same
//! step from the same state.

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};
use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{Mode, MotionLimits, NavConfig, Navigator};
use nalgebra::Point2;

/// 270°, 1081 beams: a wall square to the heading `wall` m ahead, open elsewhere.
fn scan(wall: f64) -> Scan {
    let fov = 0.75 * std::f64::consts::PI;
    let inc = 2.0 * fov / 1080.0;
    let ranges = (0..1081)
        .map(|i| {
            let a = -fov + i as f64 * inc;
            if a.cos() > 0.05 {
                (wall / a.cos()).min(10.0) as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    Scan::new(-fov, fov, inc, 0.05, 10.0, ranges, vec![], Pose2::identity()).expect("valid scan")
}

fn bench(c: &mut Criterion) {
    let limits = MotionLimits::from_chassis(&ChassisParams::omr3());
    for (name, wall, mode) in [("rotate", 1.5, "R"), ("lock", 0.6, "L")] {
        let scan = scan(wall);
        let mut nav = Navigator::new(NavConfig::default(), limits).expect("valid config");
        nav.set_goal(Point2::new(5.0, 0.3)).expect("finite goal");
        let first = nav.step(Pose2::identity(), &scan);
        let expected = if mode == "R" {
            matches!(first.mode, Mode::Rotate)
        } else {
            matches!(first.mode, Mode::Lock(_))
        };
        assert!(expected, "{name}: {:?}", first.mode);
        let pose = Pose2::new(0.01, 0.0, 0.0);
        c.bench_function(
            &format!("local_nav step, 1081 beams, {name} mode (sectors + F + mode)"),
            |b| {
                b.iter_batched(
                    || nav.clone(),
                    |mut n| black_box(n.step(black_box(pose), black_box(&scan))),
                    BatchSize::SmallInput,
                )
            },
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
