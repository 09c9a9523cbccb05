//! The convergence check of a solver setting: `cargo run --release -p mobil_ga_step_sim --example
//! agreement -- [DT_MS:ITERATIONS:PASSES] [N] [SEED] [GENTLE]`. Scores the standing robot, the hand-made
//! step (`params/motions/hand_step.motion`'s plan) and N random individuals (the GA's
//! initialisation: inner knots uniform over each servo's range, seed SEED; default 100, seed 1)
//! under the setting (default: the body's own) and under the finer one (half the step, twice the
//! iterations), and GENTLE gentle random motions (inner knots within 5 % of each servo's range
//! about the standing pose; default 0), each without the robust score, and prints how far they agree and the cost of
//! each setting in simulated seconds per wall second.
use mobil_ga_step::{FitnessConfig, NaoModel};
use mobil_ga_step_sim::motions::{forward_step, StepPlan};
use mobil_ga_step_sim::{agreement, BodyParams, PhysicsEvaluator, SolverSetting};
use rand::SeedableRng;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut body = BodyParams::default();
    let mut rest = args.as_slice();
    if let Some(first) = rest.first().filter(|a| a.contains(':')) {
        let p: Vec<&str> = first.split(':').collect();
        if p.len() != 3 {
            return Err("expected DT_MS:ITERATIONS:PASSES".into());
        }
        body.dt = p[0].parse::<f64>()? / 1e3;
        body.solver_iterations = p[1].parse()?;
        body.pgs_iterations = p[2].parse()?;
        rest = &rest[1..];
    }
    let n: usize = rest.first().map_or(Ok(100), |s| s.parse())?;
    let seed: u64 = rest.get(1).map_or(Ok(1), |s| s.parse())?;
    let gentle: usize = rest.get(2).map_or(Ok(0), |s| s.parse())?;
    let model = NaoModel::default();
    let fitness = FitnessConfig {
        robust_check: false,
        ..FitnessConfig::default()
    };
    let fine = SolverSetting::of(&body).finer().apply(&body);
    let a = PhysicsEvaluator::with_checks(model.clone(), fitness.clone(), body.clone(), &[])?;
    let b = PhysicsEvaluator::with_checks(model.clone(), fitness, fine.clone(), &[])?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut inds = vec![model.standing()];
    inds.extend(forward_step(&model, &body, &StepPlan::default()));
    inds.extend((0..n).map(|_| model.random_individual(&mut rng)));
    let mut uniform = || rand::Rng::random::<f64>(&mut rng);
    inds.extend((0..gentle).map(|_| mobil_ga_step_sim::motions::gentle(&model, 0.05, &mut uniform)));
    let mut simulated = [0.0; 2];
    let mut wall = [0.0; 2];
    for (k, ev) in [&a, &b].into_iter().enumerate() {
        let t0 = Instant::now();
        for ind in &inds {
            simulated[k] += ev.simulate(ind).t_end;
        }
        wall[k] = t0.elapsed().as_secs_f64();
    }
    let r = agreement(&a, &b, &inds);
    for ind in &inds[..2] {
        let (oa, ob) = (a.simulate(ind), b.simulate(ind));
        println!(
            "fell {} / {}, t {:.2} / {:.2} s, dx {:.4} / {:.4} m",
            oa.fell, ob.fell, oa.t_end, ob.t_end, oa.forward_distance, ob.forward_distance
        );
    }
    println!(
        "{} vs {} ms/{}/{}: same verdict {}/{} ({:.1} %), upright under both {}, worst fitness gap {:.2} %, worst dx gap {:.4} m",
        body.dt * 1e3,
        fine.dt * 1e3,
        fine.solver_iterations,
        fine.pgs_iterations,
        r.same_verdict,
        r.individuals,
        100.0 * r.verdict_share(),
        r.upright_both,
        100.0 * r.worst_upright_gap,
        r.worst_upright_dx_gap
    );
    println!(
        "cost: {:.0} and {:.0} simulated s per wall s (one core)",
        simulated[0] / wall[0],
        simulated[1] / wall[1]
    );
    Ok(())
}
