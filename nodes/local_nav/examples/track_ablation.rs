//! T-mode's two methods and the ablation of 004 §4.3.3 on the five local_nav scenarios, for
//! OMR-III and MOBIL-II, in the ROS-free closed loop of `tests/harness` (sim_node's 40 Hz scan,
//! one scan late, 0.05 s motor lag):
//!
//! - T-mode by the tangent follower, by the vector-distance function (eq. 3.50), and off
//!   (rotate + lock only), with the 270° scanner;
//! - the same three with a 180° scanner;
//! - a disc crossing the goal line at three speeds.
//!
//! Prints the tables of docs/experiments/local-nav.md. Run:
//! `cargo run --release -p mobil_local_nav --example track_ablation`

#[path = "../tests/harness/mod.rs"]
mod harness;

use harness::{config_for, drive_config, mode_letters, scenarios, Ending, Plant, Run, Shape, World, FOV_270, SIM};
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_local_nav::TrackMethod;
use nalgebra::{Point2, Vector2};

/// Simulated seconds a run may take (every reached goal takes under 80 s).
const LIMIT_S: f64 = 180.0;

fn cell(run: &Run) -> String {
    let ending = Ending::of(run);
    let abort = match run.first_abort {
        Some(t) => format!("{t:.0} s"),
        None => "–".to_string(),
    };
    let time = match ending {
        Ending::Reached | Ending::NoPath => format!("{:.1} s", run.time),
        _ => format!("> {LIMIT_S:.0} s"),
    };
    let closest = if run.min_clearance.is_finite() {
        format!("{:.2} m", run.min_clearance)
    } else {
        "–".to_string()
    };
    // The centre came nearer a surface than the robot's radius: the body touched it (the loop
    // lets it drive on through).
    let touched = if run.contact_speed.is_some() { ", touched" } else { "" };
    format!(
        "{}{touched} | {time} | {:.1} m | {closest} | {} | {abort}",
        ending.word(),
        run.path,
        mode_letters(&run.modes)
    )
}

fn run(chassis: &ChassisParams, method: TrackMethod, world: &World, goal: Point2<f64>, plant: Plant) -> Run {
    let config = mobil_local_nav::NavConfig {
        track_method: method,
        ..config_for(chassis)
    };
    let steps = (LIMIT_S / plant.dt).round() as usize;
    drive_config(world, *chassis, config, Pose2::identity(), goal, steps, plant)
}

fn main() {
    let chassis = [
        ("OMR-III", ChassisParams::omr3()),
        ("MOBIL-II", ChassisParams::mobil2()),
    ];
    let methods = [TrackMethod::Tangent, TrackMethod::VectorDistance, TrackMethod::Off];
    let header = "| chassis | scenario | T-mode | end | time | path | closest | modes | progress checker |\n\
                  |---|---|---|---|---|---|---|---|---|";
    let mut tally = std::collections::BTreeMap::new();
    for (fov_name, fov) in [("270°", FOV_270), ("180°", std::f64::consts::PI)] {
        println!("\n### Scanner {fov_name}\n\n{header}");
        let plant = Plant { fov, ..SIM };
        for (name, c) in &chassis {
            for s in scenarios(c.model().is_nonholonomic()) {
                for m in methods {
                    let r = run(c, m, &s.world, s.goal, plant);
                    let ending = Ending::of(&r);
                    let expected = if s.name == "enclosed" {
                        Ending::NoPath
                    } else {
                        Ending::Reached
                    };
                    let right = ending == expected && r.contact_speed.is_none();
                    *tally.entry((fov_name, m.name())).or_insert(0) += usize::from(right);
                    println!("| {name} | {} | {} | {} |", s.name, m.name(), cell(&r));
                }
            }
        }
    }
    println!("\n### Right ends (reached, or no path in the enclosure, without touching) of 10\n");
    println!("| scanner | tangent | vector_distance | off |\n|---|---|---|---|");
    for fov_name in ["270°", "180°"] {
        let get = |m: TrackMethod| tally.get(&(fov_name, m.name())).copied().unwrap_or(0);
        println!(
            "| {fov_name} | {} | {} | {} |",
            get(TrackMethod::Tangent),
            get(TrackMethod::VectorDistance),
            get(TrackMethod::Off)
        );
    }

    // A disc of radius 0.3 m crossing the goal line x from (0, 0) to G (6, 0) at x = 3, from
    // the right, timed to be on the line at 6 s, when a robot at 0.5 m/s would be there.
    println!("\n### A disc (r 0.3 m) crossing the goal line at x = 3 m, on it at t = 6 s (270°)\n");
    println!("| chassis | disc speed | T-mode | end | time | path | closest | modes | progress checker | robot speed at the touch |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, c) in &chassis {
        for speed in [0.25, 0.5, 1.0] {
            let world = World(vec![Shape::Moving(
                Point2::new(3.0, -6.0 * speed),
                Vector2::new(0.0, speed),
                0.3,
            )]);
            for m in [TrackMethod::Tangent, TrackMethod::VectorDistance] {
                let r = run(c, m, &world, Point2::new(6.0, 0.0), SIM);
                // The disc touched the body (the centre came nearer it than the robot's radius):
                // the robot's own speed then.
                let touched = match r.contact_speed {
                    Some(v) => format!("at {v:.2} m/s"),
                    None => "no".to_string(),
                };
                println!("| {name} | {speed} m/s | {} | {} | {touched} |", m.name(), cell(&r));
            }
        }
    }
}
