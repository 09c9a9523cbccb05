//! The control experiment: a hand-made open-loop forward step (`motions::forward_step`), scored
//! by the built-in physics at its default setting and at the finer one, with what its feet did:
//! `cargo run --release -p mobil_ga_step_sim --example hand_step -- [--write FILE]
//! [LENGTH SWAY LIFT DIP]` (m; default the plan of `StepPlan::default`). `--write` also writes it
//! as a Webots motion file (the committed one is `nodes/ga_step_sim/motions/hand_step.motion`).
//! `TRACE=1` prints the torso's path every 0.1 s.
use mobil_ga_step::{write_motion, FitnessConfig, NaoModel};
use mobil_ga_step_sim::motions::{forward_step, StepPlan};
use mobil_ga_step_sim::{BodyParams, PhysicsEvaluator, SolverSetting};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut write = None;
    if args.first().map(String::as_str) == Some("--write") {
        args.remove(0);
        write = Some(args.remove(0));
    }
    let a = args.iter().map(|s| s.parse::<f64>()).collect::<Result<Vec<_>, _>>()?;
    let plan = match a[..] {
        [length, sway, lift, dip] => StepPlan {
            length,
            sway,
            lift,
            dip,
        },
        [] => StepPlan::default(),
        _ => return Err("expected LENGTH SWAY LIFT DIP".into()),
    };
    let model = NaoModel::default();
    let body = BodyParams::default();
    let ind = forward_step(&model, &body, &plan).ok_or("a knot is out of reach or limits")?;
    if let Some(path) = write {
        write_motion(std::io::BufWriter::new(std::fs::File::create(&path)?), &model, &ind)?;
        println!("wrote {path}");
    }
    let fitness = FitnessConfig {
        robust_check: false,
        ..FitnessConfig::default()
    };
    let sim_time = fitness.sim_time(model.step_time);
    for setting in [SolverSetting::of(&body), body.check] {
        let b = setting.apply(&body);
        let ev = PhysicsEvaluator::with_checks(model.clone(), fitness.clone(), b.clone(), &[])?;
        let (o, f) = ev.simulate_feet_report(&ind, sim_time);
        println!(
            "{} ms/{}/{}: fell {} ({:?}) at {:.2} s, dx {:.4} m, dy {:.4} m, max tilt {:.3} rad, fitness {:.4}",
            b.dt * 1e3,
            b.solver_iterations,
            b.pgs_iterations,
            o.fell,
            o.cause,
            o.t_end,
            o.forward_distance,
            o.lateral_distance,
            o.max_tilt,
            ev.score(&o).fitness
        );
        for (name, foot) in ["right", "left"].iter().zip(f.feet) {
            println!(
                "  {name} foot: lifted {:.4} m, moved {:.4} m, loaded {:.2} s, slid {:.4} m while loaded",
                foot.peak_height, foot.forward, foot.loaded_time, foot.slip_loaded
            );
        }
        println!("  flight: longest {:.3} s", f.longest_flight);
        if std::env::var("TRACE").is_ok() {
            let every = (0.1 / b.dt).round().max(1.0) as u64;
            let mut n = 0;
            ev.simulate_observed(&ind, sim_time, &mut |s| {
                n += 1;
                if n % every == 0 {
                    println!(
                        "  t {:.2} x {:.3} y {:.3} z {:.3} tilt {:.3}",
                        s.t, s.x, s.y, s.z, s.tilt
                    );
                }
            });
        }
    }
    Ok(())
}
