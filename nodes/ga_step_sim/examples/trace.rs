//! Prints the torso's path for the best individual of a `ga_step` checkpoint, every 50 ms:
//! `cargo run --release -p mobil_ga_step_sim --example trace -- DIR/checkpoint.json`, under
//! the checkpoint's physics model at its default setting.
use mobil_ga_step_sim::{BodyParams, PhysicsEvaluator};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: trace CHECKPOINT")?;
    let state = mobil_ga_step::read_checkpoint(std::path::Path::new(&path))?;
    let ev = PhysicsEvaluator::with_checks(
        state.setup.model.clone(),
        state.setup.fitness.clone(),
        BodyParams::named(state.setup.fitness.physics),
        &[],
    )?;
    let best = &state.best().individual;
    let mut n = 0;
    let o = ev.simulate_observed(best, 3.0, &mut |s| {
        n += 1;
        if n % 10 == 0 {
            println!(
                "t {:.2}  x {:+.3}  y {:+.3}  z {:.3}  tilt {:.3}",
                s.t, s.x, s.y, s.z, s.tilt
            );
        }
    });
    println!("{o:?}");
    Ok(())
}
