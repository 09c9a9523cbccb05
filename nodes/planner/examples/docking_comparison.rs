//! Our Lyapunov docking next to Nav2 Jazzy's docking law (opennav_docking on the graceful
//! controller, `benches/common/graceful.rs`) from the same start poses, on an ideal unicycle.
//!
//! Both run as a node would: a control decision every 20 ms (opennav_docking's
//! `controller_frequency` 50 Hz), the command held over the period (exact arcs), within Nav2's
//! default limits v ≤ 0.25 m/s, ω ≤ 0.75 rad/s (ours scales both by one factor; Nav2's law
//! bounds ω and recomputes v from the curvature). Each stops by its own rule: ours when
//! e < 0.02 m and the heading is within 0.03 rad (after an in-place rotation); Nav2's when the
//! robot is within 0.05 m of the dock (`docking_threshold`; the heading is not checked). Both
//! have 60 s. The dock is G = (0, 0, 0).
//!
//! `cargo run --release -p mobil_planner --example docking_comparison`

#[path = "../benches/common/graceful.rs"]
mod graceful;

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use graceful::Graceful;
use mobil_geom::{wrap, Pose2};
use mobil_planner::{
    advance, DockingConfig, DockingController, DockingGains, DockingPhase, Finish, Velocity, VelocityLimits,
};

const PERIOD: f64 = 0.02;
const TIME_LIMIT: f64 = 60.0;

/// One run's figures.
struct Outcome {
    docked: bool,
    time: f64,
    position_error: f64,
    heading_error: f64,
    path: f64,
}

fn drive(start: Pose2, mut control: impl FnMut(&Pose2, f64) -> Option<Velocity>) -> Outcome {
    let dock = Pose2::identity();
    let mut pose = start;
    let mut path = 0.0;
    let mut t = 0.0;
    let docked = loop {
        match control(&pose, t) {
            None => break true,
            Some(_) if t >= TIME_LIMIT => break false,
            Some(cmd) => {
                let next = advance(&pose, &cmd.to_twist(), PERIOD);
                path += (next.x - pose.x).hypot(next.y - pose.y);
                pose = next;
                t += PERIOD;
            }
        }
    };
    Outcome {
        docked,
        time: t,
        position_error: (pose.x - dock.x).hypot(pose.y - dock.y),
        heading_error: wrap(dock.yaw - pose.yaw).abs(),
        path,
    }
}

fn lyapunov(start: Pose2) -> Outcome {
    let config = DockingConfig {
        time_limit_s: TIME_LIMIT + 1.0,
        ..DockingConfig::default()
    };
    let limits = VelocityLimits::new(0.25, 0.75).expect("positive limits");
    let mut c = DockingController::new(
        DockingGains::paper(),
        config,
        limits,
        Finish::RotateInPlace,
        Pose2::identity(),
    )
    .expect("valid settings");
    drive(start, |pose, t| {
        let out = c.update(pose, t).expect("finite pose");
        match out.phase {
            DockingPhase::Docked => None,
            DockingPhase::Failed(_) => Some(Velocity::ZERO),
            _ => Some(out.command),
        }
    })
}

fn nav2(start: Pose2) -> Outcome {
    let g = Graceful::default();
    let dock = Pose2::identity();
    let target = g.target(&dock);
    drive(start, |pose, _| {
        if g.is_docked(&dock, pose) {
            None
        } else {
            let (v, w) = g.velocity(&target, pose);
            Some(Velocity::new(v, w))
        }
    })
}

fn main() {
    let starts = [
        ("paper S (faces away)", Pose2::new(-1.0, 1.0, 3.0 * FRAC_PI_4)),
        ("staging, on the axis", Pose2::new(-0.7, 0.0, 0.0)),
        ("1 m out, 0.5 m aside", Pose2::new(-1.0, 0.5, 0.0)),
        ("1.5 m out, facing across", Pose2::new(-1.5, -1.0, FRAC_PI_2)),
        ("2 m out, 30° off", Pose2::new(-2.0, 0.8, -PI / 6.0)),
        ("beside the dock", Pose2::new(0.0, 1.0, -FRAC_PI_2)),
    ];
    println!("| start (x, y, ϑ) | law | docked | time (s) | final e (m) | final heading error (rad) | path (m) |");
    println!("|---|---|---|---|---|---|---|");
    for (name, start) in starts {
        for (law, out) in [("Lyapunov (ours)", lyapunov(start)), ("Nav2 graceful", nav2(start))] {
            println!(
                "| {name} ({:.1}, {:.1}, {:.2}) | {law} | {} | {:.2} | {:.3} | {:.3} | {:.2} |",
                start.x,
                start.y,
                start.yaw,
                if out.docked { "yes" } else { "no" },
                out.time,
                out.position_error,
                out.heading_error,
                out.path
            );
        }
    }
}
