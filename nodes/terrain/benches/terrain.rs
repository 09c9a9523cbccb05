//! One assessment of six feet: σ, three planes (plane 3 prebuilt), three angles, tilts, class and
//! advice (budget < 2 µs).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mobil_terrain::{Assessor, HexapodGeometry, TerrainClass, TerrainConfig};

fn bench(c: &mut Criterion) {
    let assessor = Assessor::new(TerrainConfig::default()).expect("default config is valid");
    // Table 1's "large" column (cm) at the default footholds: an UNEVEN stance.
    let mut feet = HexapodGeometry::default().standing_feet();
    for (f, z) in feet.iter_mut().zip([4.0, -3.0, 1.0, -4.0, 0.0, 2.0]) {
        f.z = -0.10 + z / 100.0;
    }
    let a = assessor.assess(&feet).expect("non-degenerate stance");
    assert_eq!(a.class, TerrainClass::Uneven);
    c.bench_function("terrain assessment (six feet, Table 1 large)", |b| {
        b.iter(|| black_box(assessor.assess(black_box(&feet))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
