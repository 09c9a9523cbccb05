//! Planner speed: one docking control step (budget < 1 µs), a whole simulated docking
//! (steps/s), a route pre-check of 20 waypoints in the default world (budget < 10 ms).

#[path = "common/demo_loop.rs"]
mod demo_loop;
#[path = "common/graceful.rs"]
mod graceful;

use std::f64::consts::FRAC_PI_4;

use demo_loop::demo_loop;

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_planner::{
    check_route, simulate_docking, DockingConfig, DockingController, DockingGains, DockingPhase, Finish, Kinematics,
    RouteCheckConfig, VelocityLimits,
};
use mobil_world::World;

fn bench(c: &mut Criterion) {
    // One control step: polar error, law, common factor, V, V̇, phase logic.
    let controller = DockingController::new(
        DockingGains::paper(),
        DockingConfig::default(),
        VelocityLimits::from_chassis(&ChassisParams::omr3()),
        Finish::RotateInPlace,
        Pose2::identity(),
    )
    .expect("valid settings");
    let pose = Pose2::new(-1.0, 1.0, 3.0 * FRAC_PI_4 - 0.1);
    c.bench_function("docking control step (DockingController::update)", |b| {
        b.iter_batched(
            || controller.clone(),
            |mut ctl| black_box(ctl.update(black_box(&pose), black_box(0.5))),
            BatchSize::SmallInput,
        )
    });

    // A whole docking from the paper's start, unicycle, RK4 sub-steps of 10 ms.
    let mut probe = DockingController::new(
        DockingGains::paper(),
        DockingConfig::default(),
        VelocityLimits::unlimited(),
        Finish::RotateInPlace,
        Pose2::identity(),
    )
    .expect("valid settings");
    let start = Pose2::new(-1.0, 1.0, 3.0 * FRAC_PI_4);
    let run = simulate_docking(&mut probe.clone(), Kinematics::Unicycle, start, 0.01, 120.0).expect("valid");
    assert_eq!(run.end, DockingPhase::Docked);
    let mut group = c.benchmark_group("simulated docking");
    group.throughput(Throughput::Elements(run.samples.len() as u64));
    group.bench_function(format!("paper run, {} steps of 10 ms (RK4)", run.samples.len()), |b| {
        b.iter(|| {
            probe.set_goal(Pose2::identity()).expect("finite");
            black_box(simulate_docking(
                &mut probe,
                Kinematics::Unicycle,
                black_box(start),
                0.01,
                120.0,
            ))
        })
    });
    group.finish();

    // Route pre-check: 20 waypoints round the demo loop, MOBIL-II (footprint 0.53 m). Every
    // waypoint is reached; a few corner ones are reported as tighter than R_min from where the
    // previous one was taken (tests/route.rs), which does not change the work done.
    let world =
        World::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/worlds/default.yaml")).expect("default world");
    let route = demo_loop(20);
    let config = RouteCheckConfig::new(0.53);
    let params = ChassisParams::mobil2();
    let report = check_route(&Pose2::identity(), &route, &params, &world, &config).expect("valid");
    assert!(report.reached.iter().all(|r| *r), "{:?}", report.problems);
    c.bench_function("route pre-check, 20 waypoints, default world, MOBIL-II", |b| {
        b.iter(|| {
            black_box(check_route(
                &Pose2::identity(),
                black_box(&route),
                &params,
                &world,
                &config,
            ))
        })
    });

    // The peer's control step, for scale.
    let g = graceful::Graceful::default();
    let target = g.target(&Pose2::identity());
    c.bench_function("Nav2 graceful control step (peer)", |b| {
        b.iter(|| black_box(g.velocity(black_box(&target), black_box(&pose))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
