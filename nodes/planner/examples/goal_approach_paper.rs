//! The goal approach (004 §4.2.1) run as the paper ran it for §4.3.1: MOBIL-II (wheelbase 0.60 m,
//! steering within ±70°) from S = [−1, 1, 3π/4] to G = [0, 0], full steps of 0.5 m, the step
//! halved to Z/2 once the goal is nearer than a step, no capture circle (Z_crit → 0), ended by
//! the progress rule. Prints the closest approach, which the paper gives as "about 16 cm", then
//! the same for shorter steps down to mobil's default 0.02 m, and for the paper's step from the
//! docking comparison's other starts.
//!
//! `cargo run --release -p mobil_planner --example goal_approach_paper`

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use mobil_geom::Pose2;
use mobil_planner::{approach, ApproachConfig, Motion, Steering};
use nalgebra::Point2;

/// The approach from `start` to G = (0, 0) in full steps of `step`, with no capture circle.
fn closest(motion: &Motion, start: Pose2, step: f64) -> mobil_planner::ApproachRun {
    let config = ApproachConfig {
        step_length: step,
        critical_distance: 1e-9,
        ..ApproachConfig::default()
    };
    approach(&start, &Point2::new(0.0, 0.0), motion, &config).expect("valid run")
}

fn main() {
    let steering = Steering::new(0.60, 70f64.to_radians()).expect("valid steering");
    let motion = Motion::Steered(steering);
    let run = |start: Pose2, step: f64| closest(&motion, start, step);
    let paper = Pose2::new(-1.0, 1.0, 3.0 * FRAC_PI_4);
    println!(
        "MOBIL-II, wheelbase 0.60 m, steering ±70° (R_min {:.3} m), G = (0, 0)",
        steering.min_radius()
    );
    println!("| start | full step (m) | steps | closest approach (m) | at the end (m) | why it ended | path (m) |");
    println!("|---|---:|---:|---:|---:|---|---:|");
    let show = |name: &str, start: Pose2, step: f64| {
        let r = run(start, step);
        println!(
            "| {name} | {step} | {} | {:.3} | {:.3} | {:?} | {:.2} |",
            r.path.len() - 1,
            r.closest,
            r.final_distance,
            r.end,
            r.travelled
        );
    };
    for step in [0.5, 0.4, 0.3, 0.25, 0.2, 0.1, 0.05, 0.02] {
        show("paper's S (−1, 1, 3π/4)", paper, step);
    }
    // The suite's own MOBIL-II (params/mobil2.yaml): δ_eff 39.4°, R_min 0.73 m.
    let suite = Steering::new(0.60, (0.60f64 / 0.73).atan()).expect("valid steering");
    let suite_motion = Motion::Steered(suite);
    let suite_run = |start: Pose2, step: f64| closest(&suite_motion, start, step);
    for (name, start) in [
        ("(−0.7, 0, 0)", Pose2::new(-0.7, 0.0, 0.0)),
        ("(−1, 0.5, 0)", Pose2::new(-1.0, 0.5, 0.0)),
        ("(−1.5, −1, π/2)", Pose2::new(-1.5, -1.0, FRAC_PI_2)),
        ("(−2, 0.8, −π/6)", Pose2::new(-2.0, 0.8, -PI / 6.0)),
        ("(0, 1, −π/2)", Pose2::new(0.0, 1.0, -FRAC_PI_2)),
    ] {
        for step in [0.5, 0.02] {
            show(name, start, step);
        }
    }
    println!();
    println!(
        "the suite's MOBIL-II: δ_eff {:.1}°, R_min {:.3} m",
        suite.limit().to_degrees(),
        suite.min_radius()
    );
    println!("| start | full step (m) | steps | closest approach (m) | at the end (m) | why it ended | path (m) |");
    println!("|---|---:|---:|---:|---:|---|---:|");
    for (name, start) in [
        ("paper's S (−1, 1, 3π/4)", paper),
        ("(−0.7, 0, 0)", Pose2::new(-0.7, 0.0, 0.0)),
        ("(−1, 0.5, 0)", Pose2::new(-1.0, 0.5, 0.0)),
        ("(−1.5, −1, π/2)", Pose2::new(-1.5, -1.0, FRAC_PI_2)),
        ("(−2, 0.8, −π/6)", Pose2::new(-2.0, 0.8, -PI / 6.0)),
        ("(0, 1, −π/2)", Pose2::new(0.0, 1.0, -FRAC_PI_2)),
    ] {
        for step in [0.5, 0.02] {
            let r = suite_run(start, step);
            println!(
                "| {name} | {step} | {} | {:.3} | {:.3} | {:?} | {:.2} |",
                r.path.len() - 1,
                r.closest,
                r.final_distance,
                r.end,
                r.travelled
            );
        }
    }
}
