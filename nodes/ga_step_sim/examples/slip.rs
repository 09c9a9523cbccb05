//! Replays the best individual of a `ga_step` checkpoint and measures how far each loaded foot
//! slides over the floor: `cargo run --release -p mobil_ga_step_sim --example slip --
//! DIR/checkpoint.json [LOAD_N]`. A foot counts as loaded while the floor pushes it with more
//! than LOAD_N newtons (default 5 N, a tenth of the robot's weight). Optional further arguments
//! replay under another body: `MU SOLVER_ITERATIONS DT`. The body is the checkpoint's
//! physics model (`physics`), at its default setting.
use mobil_ga_step_sim::PhysicsEvaluator;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: slip CHECKPOINT [LOAD_N]")?;
    let load: f64 = std::env::args().nth(2).map_or(Ok(5.0), |s| s.parse())?;
    let state = mobil_ga_step::read_checkpoint(std::path::Path::new(&path))?;
    let mut body = mobil_ga_step_sim::BodyParams::named(state.setup.fitness.physics);
    if let Some(mu) = std::env::args().nth(3) {
        body.friction = mu.parse()?;
    }
    if let Some(it) = std::env::args().nth(4) {
        body.solver_iterations = it.parse()?;
    }
    if let Some(dt) = std::env::args().nth(5) {
        body.dt = dt.parse()?;
    }
    let ev = PhysicsEvaluator::with_checks(state.setup.model.clone(), state.setup.fitness.clone(), body, &[])?;
    let dt = ev.body().dt;
    let best = &state.best().individual;
    let mut slid = [0.0f64; 2];
    let mut loaded_time = [0.0f64; 2];
    let mut max_slip = [0.0f64; 2];
    let mut fast_slip_time = [0.0f64; 2];
    let mut n = 0;
    let friction = ev.body().friction;
    let mut slid_gripping = [0.0f64; 2];
    let mut airborne = 0.0;
    let mut ratios: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    let o = ev.simulate_with_feet(best, 3.0, &mut |s, feet| {
        n += 1;
        if feet.iter().all(|f| f.normal_force <= load) {
            airborne += dt;
        }
        for (k, f) in feet.iter().enumerate() {
            if f.normal_force > load {
                slid[k] += f.slip_speed * dt;
                if f.friction_force < 0.5 * friction * f.normal_force {
                    slid_gripping[k] += f.slip_speed * dt;
                }
                loaded_time[k] += dt;
                max_slip[k] = max_slip[k].max(f.slip_speed);
                if f.slip_speed > 0.02 {
                    fast_slip_time[k] += dt;
                    ratios[k].push(f.friction_force / f.normal_force);
                }
            }
        }
        if n % 20 == 0 {
            println!(
                "t {:.2}  x {:+.3}  z {:.3}  R N {:6.1} F {:6.1} slip {:.3} m/s   L N {:6.1} F {:6.1} slip {:.3} m/s",
                s.t,
                s.x,
                s.z,
                feet[0].normal_force,
                feet[0].friction_force,
                feet[0].slip_speed,
                feet[1].normal_force,
                feet[1].friction_force,
                feet[1].slip_speed
            );
        }
    });
    println!("{o:?}");
    for (k, name) in ["right", "left"].iter().enumerate() {
        println!(
            "{name} foot: loaded {:.2} s, slid {:.3} m while loaded (mean {:.3} m/s, max {:.3} m/s, {:.2} s above 2 cm/s)",
            loaded_time[k],
            slid[k],
            slid[k] / loaded_time[k].max(dt),
            max_slip[k],
            fast_slip_time[k]
        );
        println!(
            "  slid {:.3} m while loaded with friction below half of μ·N",
            slid_gripping[k]
        );
        let r = &mut ratios[k];
        r.sort_by(f64::total_cmp);
        if !r.is_empty() {
            println!(
                "  friction/normal while sliding above 2 cm/s: min {:.3} median {:.3} max {:.3}",
                r[0],
                r[r.len() / 2],
                r[r.len() - 1]
            );
        }
    }
    println!("neither foot loaded for {airborne:.2} s");
    println!("friction coefficient {} (both materials)", ev.body().friction);
    Ok(())
}
