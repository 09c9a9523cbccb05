//! Measures which second solver setting catches the motions whose verdict holds only at the
//! default: `cargo run --release -p mobil_ga_step_sim --example check_settings -- SOURCE...`.
//! A SOURCE is a `ga_step` checkpoint (its whole population), a Webots motion file as
//! `ga_step` writes it (knots rebuilt as `--example replay` does) or `random:N:FRACTION` (N
//! gentle motions, inner knots uniform within FRACTION of each range about standing, seed 5).
//! The body is the DC-motor model (`physics: dc-motor`), whose robust check this chose.
//! Every motion is simulated at its default (5 ms, 4 iterations, 2 passes), at each candidate
//! (5 ms/8/2, 4 ms/4/2, 2.5 ms/8/2, μ 0.7 at the default's solver) and at the reference
//! (1.25 ms/16/4). Prints per candidate: of the motions upright at the default, how many it
//! turns into falls and how many of those the reference also calls falls; how many the pair
//! (the default and it, a fall under either a fall) calls falls that the reference calls
//! upright (false alarms) and how many reference falls upright at the default it misses; its
//! cost in simulated s per wall s, and the pair's wall time over the default's alone (without
//! the robust score's cut at the default's fall). Checkpoints give the robot and fitness too
//! (all must share them); without one, the defaults.
use mobil_ga_step::{FitnessConfig, Individual, NaoModel};
use mobil_ga_step_sim::{motions, BodyParams, PhysicsEvaluator};
use rand::{Rng, SeedableRng};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// The individual of a motion file as `ga_step` writes it.
fn from_motion(path: &str, model: &NaoModel) -> Result<Individual, Box<dyn std::error::Error>> {
    let file = std::io::BufReader::new(std::fs::File::open(path)?);
    Ok(mobil_ga_step::read_motion(file)?
        .to_individual(model)
        .map_err(|e| format!("{path}: {e}"))?)
}

/// A setting: its name and the body with that solver (and friction).
fn settings() -> Vec<(String, BodyParams)> {
    let s = |dt: f64, it: usize, passes: usize, mu: f64| BodyParams {
        dt,
        solver_iterations: it,
        pgs_iterations: passes,
        friction: mu,
        ..BodyParams::dc_motor()
    };
    vec![
        ("5 ms/4/2 (default)".into(), s(0.005, 4, 2, 0.8)),
        ("5 ms/8/2".into(), s(0.005, 8, 2, 0.8)),
        ("4 ms/4/2".into(), s(0.004, 4, 2, 0.8)),
        ("2.5 ms/8/2".into(), s(0.0025, 8, 2, 0.8)),
        ("5 ms/4/2, μ 0.7".into(), s(0.005, 4, 2, 0.7)),
        ("1.25 ms/16/4 (reference)".into(), s(0.00125, 16, 4, 0.8)),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // The robot and fitness of the first checkpoint given (every checkpoint must share them),
    // the defaults without one; one setting at a time, so without the robust score.
    let mut setup = None;
    for arg in args
        .iter()
        .filter(|a| !a.starts_with("random:") && !a.ends_with(".motion"))
    {
        let state = mobil_ga_step::read_checkpoint(std::path::Path::new(arg))?;
        // Compared without the robust score's switch, which is off here anyway.
        let theirs = (
            state.setup.model,
            FitnessConfig {
                robust_check: false,
                ..state.setup.fitness
            },
        );
        match &setup {
            None => setup = Some(theirs),
            Some(s) if *s != theirs => {
                return Err(format!("{arg}: another robot or fitness than the first checkpoint's").into())
            }
            Some(_) => {}
        }
    }
    let (model, fitness) = setup.unwrap_or_else(|| {
        let fitness = FitnessConfig {
            robust_check: false,
            ..FitnessConfig::default()
        };
        (NaoModel::default(), fitness)
    });
    let mut motions: Vec<(String, Individual)> = Vec::new();
    for arg in args {
        if let Some(spec) = arg.strip_prefix("random:") {
            let (n, f) = spec.split_once(':').ok_or("random:N:FRACTION")?;
            let (n, f): (usize, f64) = (n.parse()?, f.parse()?);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
            for j in 0..n {
                let ind = motions::gentle(&model, f, &mut || rng.random::<f64>());
                motions.push((format!("random {j}"), ind));
            }
        } else if arg.ends_with(".motion") {
            motions.push((arg.clone(), from_motion(&arg, &model)?));
        } else {
            let state = mobil_ga_step::read_checkpoint(std::path::Path::new(&arg))?;
            for (i, s) in state.population.iter().enumerate() {
                motions.push((format!("{arg} #{i}"), s.individual.clone()));
            }
        }
    }
    let settings = settings();
    let duration = fitness.sim_time(model.step_time);
    let evaluators: Vec<PhysicsEvaluator> = settings
        .iter()
        .map(|(_, b)| PhysicsEvaluator::with_checks(model.clone(), fitness.clone(), b.clone(), &[]))
        .collect::<Result<_, _>>()?;
    // (fell, t_end, dx) per motion and setting; simulated and wall seconds per setting.
    let results = Mutex::new(vec![Vec::new(); motions.len()]);
    let cost = Mutex::new(vec![(0.0f64, 0.0f64); settings.len()]);
    let next = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some((_, ind)) = motions.get(i) else { break };
                let mut row = Vec::new();
                for (k, ev) in evaluators.iter().enumerate() {
                    let t0 = Instant::now();
                    let o = ev.simulate_for(ind, duration);
                    let wall = t0.elapsed().as_secs_f64();
                    if let Ok(mut c) = cost.lock() {
                        c[k].0 += o.t_end;
                        c[k].1 += wall;
                    }
                    row.push((o.fell, o.t_end, o.forward_distance));
                }
                if let Ok(mut r) = results.lock() {
                    r[i] = row;
                }
            });
        }
    });
    let results = results.into_inner().map_err(|_| "poisoned")?;
    let cost = cost.into_inner().map_err(|_| "poisoned")?;
    let reference = settings.len() - 1;
    for ((name, _), row) in motions.iter().zip(&results) {
        let cells: Vec<String> = row
            .iter()
            .map(|&(fell, t, dx)| {
                if fell {
                    format!("F{t:.3}")
                } else {
                    format!("U{:+.4}", dx)
                }
            })
            .collect();
        println!("{name}: {}", cells.join(" "));
    }
    let upright_default: Vec<usize> = (0..motions.len()).filter(|&i| !results[i][0].0).collect();
    let ref_falls_of_those = upright_default.iter().filter(|&&i| results[i][reference].0).count();
    println!(
        "\n{} motions; {} upright at the default, of which the reference calls {} falls; {} upright at the reference",
        motions.len(),
        upright_default.len(),
        ref_falls_of_those,
        (0..motions.len()).filter(|&i| !results[i][reference].0).count()
    );
    println!("| setting | default-upright turned into falls | of which the reference also calls falls | reference-upright called falls by the pair (false alarms) | default-upright reference-falls the pair misses | sim s / wall s | the pair's wall time over the default's (no cut) |");
    println!("|---|---|---|---|---|---|---|");
    for (k, (name, _)) in settings.iter().enumerate() {
        let turned: Vec<usize> = upright_default.iter().copied().filter(|&i| results[i][k].0).collect();
        let confirmed = turned.iter().filter(|&&i| results[i][reference].0).count();
        // The robust pair (the default and this setting) calls a fall where either falls.
        let false_alarms = (0..motions.len())
            .filter(|&i| !results[i][reference].0 && (results[i][0].0 || results[i][k].0))
            .count();
        // Caught by the robust pair (default and this): upright at the default, falling at the
        // reference, and not turned into a fall here.
        let missed = upright_default
            .iter()
            .filter(|&&i| results[i][reference].0 && !results[i][k].0)
            .count();
        println!(
            "| {name} | {} | {confirmed} | {false_alarms} | {missed} | {:.1} | {:.2} |",
            turned.len(),
            cost[k].0 / cost[k].1.max(1e-9),
            (cost[0].1 + if k == 0 { 0.0 } else { cost[k].1 }) / cost[0].1.max(1e-9)
        );
    }
    Ok(())
}
