//! Replays a run's best individual under the robust score, then at the default solver setting,
//! the check setting and two finer ones, with
//! what its feet did, to tell a found step from one that holds only at the evaluator's exact
//! numbers (motions at the edge of a fall change their verdict with the setting):
//! `cargo run --release -p mobil_ga_step_sim --example replay -- CHECKPOINT_OR_MOTION
//! [DT_MS:ITERATIONS:PASSES...]`. The argument is a `ga_step` checkpoint (its best individual,
//! its model and fitness) or a Webots motion file as `ga_step` writes it (40 ms rows, values to
//! 4 decimals: the knots between rows are rebuilt by `Motion::to_individual`, within 1.5e-4
//! rad, 7.5e-5 for the default 2 s step). Prints per setting: the verdict and why, the fall time or T_sim, Δx and Δy of the
//! torso, and per foot its peak sole height, its sole's Δx, the time it was loaded and how far
//! it slid while loaded, and the longest and total time both feet were unloaded (flight).
//!
//! `replay --check CHECKPOINT` instead re-scores the checkpoint's whole population with the
//! evaluator it records (the built-in physics at this `PHYSICS_VERSION`, refused
//! otherwise) and compares each evaluation with the stored one bit for bit (a physics change
//! that keeps `PHYSICS_VERSION` must pass this); the exit status is 1 if any differs.
use mobil_ga_step::Evaluator;
use mobil_ga_step::{EvaluatorTag, FitnessConfig, NaoModel};
use mobil_ga_step_sim::{BodyParams, PhysicsEvaluator, SolverSetting, PHYSICS_VERSION};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().map(String::as_str) == Some("--check") {
        args.next();
        let path = args.next().ok_or("usage: replay --check CHECKPOINT")?;
        return check(&path);
    }
    let path = args
        .next()
        .ok_or("usage: replay CHECKPOINT_OR_MOTION [DT_MS:ITERATIONS:PASSES...]")?;
    let mut settings = Vec::new();
    for a in args {
        let p: Vec<&str> = a.split(':').collect();
        if p.len() != 3 {
            return Err(format!("{a}: expected DT_MS:ITERATIONS:PASSES").into());
        }
        settings.push((p[0].parse::<f64>()? / 1e3, p[1].parse()?, p[2].parse()?));
    }
    let (model, fitness, ind, stored) = if path.ends_with(".motion") {
        let model = NaoModel::default();
        let file = std::io::BufReader::new(std::fs::File::open(&path)?);
        let ind = mobil_ga_step::read_motion(file)?
            .to_individual(&model)
            .map_err(|e| format!("{path}: {e}"))?;
        (model, FitnessConfig::default(), ind, None)
    } else {
        let state = mobil_ga_step::read_checkpoint(std::path::Path::new(&path))?;
        let best = state.best();
        (
            state.setup.model.clone(),
            state.setup.fitness.clone(),
            best.individual.clone(),
            Some((state.generation, best.evaluation)),
        )
    };
    println!("{path}");
    if let Some((generation, e)) = stored {
        println!(
            "  stored (generation {generation}): fitness {:.4}, {}, t {:.3} s, dx {:+.4} m",
            e.fitness,
            if e.fell { "falls" } else { "upright" },
            e.t_fall,
            e.forward_distance
        );
    }
    let duration = fitness.sim_time(model.step_time);
    let base = BodyParams::named(fitness.physics);
    if settings.is_empty() {
        // The run's model's default and check settings, then two ever finer ones.
        let check = base.check;
        for s in [SolverSetting::of(&base), check, check.finer(), check.finer().finer()] {
            settings.push((s.dt, s.solver_iterations, s.pgs_iterations));
        }
    }
    println!("  physics model: {}", fitness.physics);
    // The robust score's verdict when the fitness asks for it (the default and the check).
    if fitness.robust_check && !fitness.distance_on_fall {
        let e = PhysicsEvaluator::new(model.clone(), fitness.clone())?.evaluate(&ind);
        println!(
            "  robust score ({} ms/{}/{} and {} ms/{}/{}): fitness {:.4}, {}, t {:.3} s, dx {:+.4} m",
            base.dt * 1e3,
            base.solver_iterations,
            base.pgs_iterations,
            base.check.dt * 1e3,
            base.check.solver_iterations,
            base.check.pgs_iterations,
            e.fitness,
            if e.fell { "falls" } else { "upright" },
            e.t_fall,
            e.forward_distance
        );
    } else {
        println!(
            "  no robust score: the run's fitness has {}",
            if fitness.distance_on_fall {
                "a fall's distance counted"
            } else {
                "robust_check off"
            }
        );
    }
    // One setting at a time: without the robust score.
    let fitness = FitnessConfig {
        robust_check: false,
        ..fitness
    };
    for (dt, iterations, passes) in settings {
        let body = BodyParams {
            dt,
            solver_iterations: iterations,
            pgs_iterations: passes,
            ..base.clone()
        };
        let ev = PhysicsEvaluator::with_body(model.clone(), fitness.clone(), body)?;
        let (o, r) = ev.simulate_feet_report(&ind, duration);
        let verdict = match o.cause {
            Some(c) => format!("falls ({c:?})"),
            None => "upright".to_string(),
        };
        println!(
            "  {:5.3} ms {:2} it {} passes: {verdict:<18} t {:.3} s  dx {:+.4} m  dy {:+.4} m  flight longest {:.3} s, total {:.3} s",
            dt * 1e3,
            iterations,
            passes,
            o.t_end,
            o.forward_distance,
            o.lateral_distance,
            r.longest_flight,
            r.flight_time
        );
        for (name, f) in ["right", "left"].iter().zip(r.feet) {
            println!(
                "      {name:<5} foot: peak {:5.1} mm  sole dx {:+.4} m  loaded {:.3} s  slid while loaded {:.4} m",
                f.peak_height * 1e3,
                f.forward,
                f.loaded_time,
                f.slip_loaded
            );
        }
    }
    Ok(())
}

/// Re-scores a checkpoint's population and compares with the stored evaluations, bit for bit.
fn check(path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let (state, tag) = mobil_ga_step::read_checkpoint_tagged(std::path::Path::new(path))?;
    let ours = EvaluatorTag::Physics {
        physics_version: PHYSICS_VERSION,
    };
    if tag != ours {
        return Err(format!("{path}: scored by {tag}, not by this {ours}").into());
    }
    let ev = PhysicsEvaluator::new(state.setup.model.clone(), state.setup.fitness.clone())?;
    let mut differ = 0;
    for (i, scored) in state.population.iter().enumerate() {
        let (got, want) = (ev.evaluate(&scored.individual), scored.evaluation);
        let same = got.fell == want.fell
            && got.fitness.to_bits() == want.fitness.to_bits()
            && got.t_fall.to_bits() == want.t_fall.to_bits()
            && got.forward_distance.to_bits() == want.forward_distance.to_bits();
        if !same {
            differ += 1;
            println!("individual {i}: stored {want:?}, now {got:?}");
        }
    }
    println!(
        "{path}: generation {}, {} individuals, {} scored differently",
        state.generation,
        state.population.len(),
        differ
    );
    if differ > 0 {
        std::process::exit(1);
    }
    Ok(())
}
