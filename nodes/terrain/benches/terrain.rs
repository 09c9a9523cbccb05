//! One assessment of six feet: σ, three planes (plane 3 prebuilt), three angles, tilts, class and
//! advice (budget < 2 µs). Measured twice: by wall-clock time (criterion's default), and by the
//! thread's CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), which a loaded machine does not
//! inflate with the time the thread waits for a core.

use criterion::{criterion_group, criterion_main, Criterion};
use mobil_terrain::{Assessor, HexapodGeometry, TerrainClass, TerrainConfig};
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
    let assessor = Assessor::new(TerrainConfig::default()).expect("default config is valid");
    // Table 1's "large" column (cm) at the default footholds: an UNEVEN stance.
    let mut feet = HexapodGeometry::default().standing_feet();
    for (f, z) in feet.iter_mut().zip([4.0, -3.0, 1.0, -4.0, 0.0, 2.0]) {
        f.z = -0.10 + z / 100.0;
    }
    let a = assessor.assess(&feet).expect("non-degenerate stance");
    assert_eq!(a.class, TerrainClass::Uneven);
    c.bench_function("terrain assessment (six feet, Table 1 large), wall time", |b| {
        b.iter(|| black_box(assessor.assess(black_box(&feet))))
    });
    if thread_cpu_ns().is_some() {
        c.bench_function("terrain assessment (six feet, Table 1 large), thread CPU time", |b| {
            b.iter_custom(|iters| {
                let (start, wall) = (thread_cpu_ns(), Instant::now());
                for _ in 0..iters {
                    black_box(assessor.assess(black_box(&feet))).ok();
                }
                match (start, thread_cpu_ns()) {
                    (Some(s), Some(e)) => Duration::from_nanos(e.saturating_sub(s)),
                    _ => wall.elapsed(),
                }
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
