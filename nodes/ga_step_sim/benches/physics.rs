//! Speed of the physics evaluator (a bench binary: `cargo bench -p mobil_ga_step_sim`):
//! simulated seconds per wall second for one evaluation of a standing robot (3 s simulated),
//! individuals per second over every core on a random initial population, and the wall time of
//! one generation of 100 (offspring of an evaluated random population, BLX-α), under the
//! robust score (the default and the check setting) and under the default setting alone; and
//! both on a batch of gentle motions that mostly stay up, as a late generation's do. Budget: 5
//! simulated seconds per wall second on one core under the robust score, so that a generation
//! of 100 upright individuals (300 robot-seconds) takes at most 30 s on two cores and a run of
//! 200 generations under two hours.

use mobil_ga_step::{evaluate_all, resolve_threads, FitnessConfig, GaSetup, GaState, NaoModel};
use mobil_ga_step_sim::{motions, PhysicsEvaluator};
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() {
    let model = NaoModel::default();
    let ev = PhysicsEvaluator::new(model.clone(), FitnessConfig::default()).expect("default figures are valid");
    let single = PhysicsEvaluator::new(
        model.clone(),
        FitnessConfig {
            robust_check: false,
            ..FitnessConfig::default()
        },
    )
    .expect("default figures are valid");
    let standing = model.standing();
    let runs = 5;
    for (name, e) in [("default setting alone", &single), ("robust score", &ev)] {
        let t = Instant::now();
        let mut simulated = 0.0;
        for _ in 0..runs {
            simulated += e.robust_simulate(&standing).t_end;
        }
        let wall = t.elapsed().as_secs_f64();
        println!(
            "one evaluation (standing, 3 s simulated), {name}: {:.1} ms, {:.1} simulated s per wall s",
            1e3 * wall / runs as f64,
            simulated / wall
        );
    }

    // Gentle motions (inner knots within 5 % of each range about standing): most stay up for
    // the whole 3 s, as a late generation's individuals do.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let gentle: Vec<_> = (0..20)
        .map(|_| motions::gentle(&model, 0.05, &mut || rng.random::<f64>()))
        .collect();
    let threads = resolve_threads(0);
    for (name, e) in [("default setting alone", &single), ("robust score", &ev)] {
        let t = Instant::now();
        let evals = evaluate_all(e, &gentle, 0);
        let wall = t.elapsed().as_secs_f64();
        let up = evals.iter().filter(|x| !x.fell).count();
        println!(
            "20 gentle motions on {threads} threads, {name}: {:.1} per s ({up} upright), {:.1} s per 100",
            gentle.len() as f64 / wall,
            100.0 * wall / gentle.len() as f64
        );
    }

    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let batch: Vec<_> = (0..100).map(|_| model.random_individual(&mut rng)).collect();
    let t = Instant::now();
    let evals = evaluate_all(&ev, &batch, 0);
    let wall = t.elapsed().as_secs_f64();
    let mean_t = evals.iter().map(|e| e.t_fall).sum::<f64>() / evals.len() as f64;
    println!(
        "random individuals on {threads} threads: {:.0} per s (they fall after {mean_t:.2} s on average)",
        batch.len() as f64 / wall
    );

    let setup = GaSetup::default();
    let mut state = GaState::start(setup, 1, &ev, 0).expect("default setup is valid");
    for g in 1..=3 {
        let t = Instant::now();
        state.next_generation(&ev, 0);
        let s = &state.history[state.generation as usize];
        println!(
            "generation {g} of 100 on {threads} threads: {:.2} s wall (best {:.3}, mean {:.3})",
            t.elapsed().as_secs_f64(),
            s.max,
            s.mean
        );
    }
}
