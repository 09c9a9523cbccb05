//! Replays motions under several solver settings, to see at which the outcome stops changing:
//! `cargo run --release -p mobil_ga_step_sim --example converge -- [SETTINGS...] MOTION...`.
//! A MOTION is `stand`, `bob` (both legs bobbing in place, ±0.15 rad at 1.25 Hz), `knees` (both
//! knees fully bent at once), `ramp:INDEX=ANGLE,...` (servos by genome index ramped to the
//! angles over 0.5 s and held), `random:N:FRACTION` (N gentle random motions, every inner knot
//! uniform within FRACTION of its servo's range about the standing pose, seed 5) or a `ga_step`
//! checkpoint (its best individual). `perturb=RAD` moves the inner RHipPitch knots of every
//! motion by RAD. A SETTINGS argument `DT_MS:ITERATIONS:PGS` (e.g. `5:4:1`) replaces the default
//! list (the columns of the solver table of docs/experiments/ga-step-physics.md, 5:4:1 5:4:2
//! 5:8:2 2.5:8:2 2.5:16:2 1.25:16:4; the last is the reference). Prints per motion and setting:
//! fall or not (and why), fall time, Δx, Δy, and the cost in simulated seconds per wall second.
//! The body is the DC-motor model (`physics: dc-motor`), that table's; `--example agreement`
//! is the same check for the Webots model.
use mobil_ga_step::{FitnessConfig, Individual, NaoModel, Servo};
use mobil_ga_step_sim::{motions, BodyParams, PhysicsEvaluator};
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut settings: Vec<(f64, usize, usize)> = Vec::new();
    let mut sources: Vec<(String, NaoModel, FitnessConfig, Individual)> = Vec::new();
    let model = NaoModel::default();
    let mut perturb = 0.0;
    for arg in std::env::args().skip(1) {
        if let Some(p) = arg.strip_prefix("perturb=") {
            perturb = p.parse()?;
            continue;
        }
        let parts: Vec<&str> = arg.split(':').collect();
        if parts.len() == 3 && parts[0].parse::<f64>().is_ok() {
            settings.push((parts[0].parse::<f64>()? / 1e3, parts[1].parse()?, parts[2].parse()?));
            continue;
        }
        let ind = match arg.as_str() {
            "stand" => model.standing(),
            "bob" => motions::knee_bob(&model, 0.15, 0.8),
            "knees" => motions::ramp_to(&model, &[(Servo::RKneePitch, 2.2689), (Servo::LKneePitch, 2.2689)], 1),
            spec if spec.starts_with("ramp:") => {
                // ramp:INDEX=ANGLE,... (genome order), reached over 0.5 s and held.
                let mut angles = Vec::new();
                for item in spec["ramp:".len()..].split(',') {
                    let (i, a) = item.split_once('=').ok_or("ramp:INDEX=ANGLE,...")?;
                    let i: usize = i.parse()?;
                    angles.push((*Servo::ALL.get(i).ok_or("servo index 0..9")?, a.parse::<f64>()?));
                }
                motions::ramp_to(&model, &angles, 5)
            }
            spec if spec.starts_with("random:") => {
                // random:N:FRACTION: N individuals with inner knots uniform within FRACTION of
                // each servo's range around the standing pose (seed 5).
                let (n, f) = spec["random:".len()..].split_once(':').ok_or("random:N:FRACTION")?;
                let (n, f): (usize, f64) = (n.parse()?, f.parse()?);
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
                for j in 0..n {
                    let ind = motions::gentle(&model, f, &mut || rng.random::<f64>());
                    sources.push((format!("random {j}"), model.clone(), FitnessConfig::default(), ind));
                }
                continue;
            }
            path => {
                let state = mobil_ga_step::read_checkpoint(std::path::Path::new(path))?;
                sources.push((
                    path.to_string(),
                    state.setup.model.clone(),
                    state.setup.fitness.clone(),
                    state.best().individual.clone(),
                ));
                continue;
            }
        };
        sources.push((arg.clone(), model.clone(), FitnessConfig::default(), ind));
    }
    // perturb=RAD: every later motion's inner RHipPitch knots moved by RAD, to compare the
    // solver's effect with that of a motion hardly changed.
    if perturb != 0.0 {
        for (_, model, _, ind) in sources.iter_mut() {
            let i = Servo::RHipPitch.index();
            for k in 1..mobil_ga_step::KNOTS - 1 {
                ind.knots[i][k] = Servo::RHipPitch.clamp(ind.knots[i][k] + perturb);
            }
            let _ = model;
        }
    }
    if settings.is_empty() {
        // The solver table of docs/experiments/ga-step-physics.md: one pass (physics 1's
        // solver), the default, then finer; the last is the reference the others are compared
        // with.
        settings = vec![
            (0.005, 4, 1),
            (0.005, 4, 2),
            (0.005, 8, 2),
            (0.0025, 8, 2),
            (0.0025, 16, 2),
            (0.00125, 16, 4),
        ];
    }
    let mut table: Vec<Vec<mobil_ga_step_sim::SimOutcome>> = Vec::new();
    let mut cost = vec![(0.0f64, 0.0f64); settings.len()];
    for (name, model, fitness, ind) in &sources {
        println!("{name}");
        let mut row = Vec::new();
        for &(dt, iterations, pgs) in &settings {
            let body = BodyParams {
                dt,
                solver_iterations: iterations,
                pgs_iterations: pgs,
                ..BodyParams::dc_motor()
            };
            let ev = PhysicsEvaluator::with_checks(model.clone(), fitness.clone(), body, &[])?;
            let t = Instant::now();
            let mut lowest: f64 = f64::INFINITY;
            let o = ev.simulate_observed(ind, fitness.sim_time(ev.model().step_time), &mut |s| {
                lowest = lowest.min(s.z)
            });
            let wall = t.elapsed().as_secs_f64();
            let j = row.len();
            cost[j].0 += o.t_end;
            cost[j].1 += wall;
            row.push(o);
            println!(
                "  dt {:5.3} ms  it {:2}  pgs {}: {:<22} t {:.3} s  dx {:+.4} m  dy {:+.4} m  z {:.3} m (lowest {:.3} m)  {:6.1} sim s/wall s",
                dt * 1e3,
                iterations,
                pgs,
                if o.fell { format!("falls ({:?})", o.cause) } else { "upright".to_string() },
                o.t_end,
                o.forward_distance,
                o.lateral_distance,
                o.end_height,
                lowest,
                o.t_end / wall
            );
        }
        table.push(row);
    }
    // Each setting against the last (the finest): verdicts that differ, fall times and Δx.
    println!("against the last setting, over {} motions:", table.len());
    for (j, &(dt, iterations, pgs)) in settings.iter().enumerate() {
        let (mut differ, mut dt_fall, mut dx_up, mut n_fall, mut n_up) = (0, Vec::new(), Vec::new(), 0, 0);
        for row in &table {
            let (a, r) = (&row[j], &row[row.len() - 1]);
            if a.fell != r.fell {
                differ += 1;
            } else if a.fell {
                n_fall += 1;
                dt_fall.push((a.t_end - r.t_end).abs());
            } else {
                n_up += 1;
                dx_up.push((a.forward_distance - r.forward_distance).abs());
            }
        }
        let med = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            if v.is_empty() {
                (f64::NAN, f64::NAN)
            } else {
                (v[v.len() / 2], v[v.len() - 1])
            }
        };
        let (tm, tx) = med(&mut dt_fall);
        let (xm, xx) = med(&mut dx_up);
        println!(
            "  dt {:5.3} ms it {:2} pgs {}: verdict differs {differ}; both fall {n_fall}: |Δt_fall| median {tm:.3} max {tx:.3} s; both upright {n_up}: |ΔΔx| median {xm:.4} max {xx:.4} m; {:.1} sim s/wall s",
            dt * 1e3, iterations, pgs, cost[j].0 / cost[j].1
        );
    }
    Ok(())
}
