//! Operators per second, and one generation of 100 (offspring, evaluation, replacement) with the
//! analytic test landscape as evaluator — the GA's own cost, not a physics simulation's — on one
//! thread and on every core; and a batch of 100 costlier evaluations on one thread and on
//! every core, for the parallel speed-up. Budget: a generation of 100 under 1 ms on one thread
//! with the test landscape, so that the algorithm never shows beside the physics (a generation
//! of the physics evaluator takes seconds).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use mobil_ga_step::{
    arithmetic, blx, evaluate_all, geometric, linear_candidates, mutate, one_point, resolve_threads, roulette,
    BlxVariant, Crossover, Evaluation, Evaluator, GaConfig, GaSetup, GaState, Individual, TestLandscape,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::Duration;

fn operators(c: &mut Criterion) {
    let setup = GaSetup::default();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let (p1, p2) = (
        setup.model.random_individual(&mut rng),
        setup.model.random_individual(&mut rng),
    );
    let mut g = c.benchmark_group("operator (one call: two children, three candidates or one mutant)");
    g.bench_function("blx per-knot", |b| {
        b.iter(|| black_box(blx(&p1, &p2, 0.7, BlxVariant::PerKnot, &mut rng)))
    });
    g.bench_function("blx single-draw", |b| {
        b.iter(|| black_box(blx(&p1, &p2, 0.7, BlxVariant::SingleDraw, &mut rng)))
    });
    g.bench_function("arithmetic", |b| b.iter(|| black_box(arithmetic(&p1, &p2, &mut rng))));
    g.bench_function("one-point", |b| b.iter(|| black_box(one_point(&p1, &p2, &mut rng))));
    g.bench_function("geometric", |b| b.iter(|| black_box(geometric(&p1, &p2, &mut rng))));
    g.bench_function("linear (three candidates)", |b| {
        b.iter(|| black_box(linear_candidates(&p1, &p2)))
    });
    g.bench_function("mutation (10 picks)", |b| {
        b.iter(|| black_box(mutate(&p1, 10, 1.0 / 6.0, &mut rng)))
    });
    let fitness: Vec<f64> = (0..100).map(|i| f64::from(i) * 0.01).collect();
    g.bench_function("roulette over 100", |b| {
        b.iter(|| black_box(roulette(&fitness, &mut rng)))
    });
    g.finish();
}

fn generation(c: &mut Criterion) {
    let cores = resolve_threads(0);
    let mut g = c.benchmark_group("generation of 100, test landscape evaluator");
    for crossover in [Crossover::Blx, Crossover::Arithmetic, Crossover::Linear] {
        let setup = GaSetup {
            ga: GaConfig {
                crossover,
                stop_at_step: false,
                ..GaConfig::default()
            },
            ..GaSetup::default()
        };
        let e = TestLandscape::new(setup.model.clone(), setup.fitness.clone());
        let start = GaState::start(setup, 1, &e, 1).expect("default setup is valid");
        for threads in [1, cores] {
            g.bench_function(format!("{crossover}, {threads} thread(s)"), |b| {
                b.iter_batched(
                    || start.clone(),
                    |mut s| {
                        s.next_generation(&e, threads);
                        s
                    },
                    BatchSize::SmallInput,
                )
            });
            if cores == 1 {
                break;
            }
        }
    }
    let setup = GaSetup::default();
    let e = TestLandscape::new(setup.model.clone(), setup.fitness.clone());
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let batch: Vec<Individual> = (0..100).map(|_| setup.model.random_individual(&mut rng)).collect();
    g.bench_function("evaluation only, 100 individuals, 1 thread", |b| {
        b.iter(|| black_box(evaluate_all(&e, &batch, 1)))
    });
    g.finish();

    // The parallel evaluation's speed-up once an evaluation costs more than a thread's start:
    // the landscape evaluated 200 times per individual (about 50 µs, still far below a
    // simulated step).
    struct Costly(TestLandscape);
    impl Evaluator for Costly {
        fn evaluate(&self, i: &Individual) -> Evaluation {
            let mut last = self.0.evaluate(i);
            for _ in 1..200 {
                last = self.0.evaluate(black_box(i));
            }
            last
        }
    }
    let costly = Costly(e);
    let mut g = c.benchmark_group("evaluation of 100, test landscape × 200 per individual");
    for threads in [1, cores] {
        g.bench_function(format!("{threads} thread(s)"), |b| {
            b.iter(|| black_box(evaluate_all(&costly, &batch, threads)))
        });
        if cores == 1 {
            break;
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    targets = operators, generation
}
criterion_main!(benches);
