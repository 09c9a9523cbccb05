//! The paper's six rows (SPEC §7, forward reading, the default configuration), one complete
//! search each: time per plan and expansions per second (criterion's throughput, elements =
//! states expanded). Budget: every row under 50 ms on one core. Measured by the thread's CPU
//! time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), which a loaded machine does not inflate with
//! the time the thread waits for a core; the wall-clock time of the same runs beside it.
//!
//!     cargo bench -p mobil_gait --bench gait

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mobil_gait::{plan, BodyPose, Evaluation, GaitConfig, GaitState, QuadrupedModel, RuleSet};
use nalgebra::Point2;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// CPU time the calling thread has run (ns), if the clock exists.
fn thread_cpu_ns() -> Option<u64> {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer to a local.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
}

fn bench(c: &mut Criterion) {
    let cfg = GaitConfig::default();
    let model = QuadrupedModel::paper(cfg.reading);
    let goal = Point2::new(-10.0, 10.0);
    let mut group = c.benchmark_group("paper table");
    group.sample_size(10).measurement_time(Duration::from_secs(3));
    for set in [RuleSet::A, RuleSet::B] {
        for eval in [Evaluation::One, Evaluation::Two, Evaluation::Three] {
            let phi = if set == RuleSet::A { PI / 4.0 } else { 1.5 * PI };
            let start = GaitState::nominal(&model, BodyPose { x: 0.0, y: 0.0, phi });
            let run = || plan(&model, &cfg, &start, goal, set, eval, 0, &mut || false);
            let p = run();
            assert!(p.success, "{set},({}) finds a plan", eval.number());
            group.throughput(Throughput::Elements(u64::from(p.expanded)));
            let name = format!("{set},({}) {} expanded", eval.number(), p.expanded);
            group.bench_function(format!("{name}, thread CPU time"), |b| {
                b.iter_custom(|iters| {
                    let (start, wall) = (thread_cpu_ns(), Instant::now());
                    for _ in 0..iters {
                        black_box(run());
                    }
                    match (start, thread_cpu_ns()) {
                        (Some(s), Some(e)) => Duration::from_nanos(e.saturating_sub(s)),
                        _ => wall.elapsed(),
                    }
                })
            });
            group.bench_function(format!("{name}, wall time"), |b| b.iter(|| black_box(run())));
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
