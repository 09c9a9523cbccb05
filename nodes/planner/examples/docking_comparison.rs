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
//! A second table splits the paper's start (004 §4.3.2) into its two parts: the Lyapunov law
//! alone (no rotation), with the time and the heading error when e first falls below 0.02 m
//! and below 0.01 m, and the whole docking with the in-place rotation that follows e < 0.02 m.
//! It is run twice: with the comparison's limits and 20 ms period, and as the paper's
//! unlimited unicycle integrated by RK4 in steps of 10 ms (as `benches/planner.rs` does).
//!
//! `cargo run --release -p mobil_planner --example docking_comparison`

#[path = "../benches/common/graceful.rs"]
mod graceful;

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use graceful::Graceful;
use mobil_geom::{wrap, Pose2};
use mobil_planner::{
    advance, polar_error, rk4_step, simulate_docking, DockingConfig, DockingController, DockingGains, DockingPhase,
    Finish, Kinematics, Velocity, VelocityLimits,
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

/// Nav2's default limits, v ≤ 0.25 m/s and ω ≤ 0.75 rad/s.
fn nav2_limits() -> VelocityLimits {
    VelocityLimits::new(0.25, 0.75).expect("positive limits")
}

/// Our docking controller with the paper's gains, the default thresholds and `limits`.
fn controller(limits: VelocityLimits) -> DockingController {
    let config = DockingConfig {
        time_limit_s: TIME_LIMIT + 1.0,
        ..DockingConfig::default()
    };
    DockingController::new(
        DockingGains::paper(),
        config,
        limits,
        Finish::RotateInPlace,
        Pose2::identity(),
    )
    .expect("valid settings")
}

fn lyapunov(start: Pose2, limits: VelocityLimits) -> Outcome {
    let mut c = controller(limits);
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

/// How the robot moves between control decisions.
#[derive(Clone, Copy)]
enum Motion {
    /// Each command held over `PERIOD`: exact arcs, as a node drives.
    Held,
    /// The closed loop integrated by RK4 with this step (s): the continuous law.
    Rk4(f64),
}

impl Motion {
    fn step(self) -> f64 {
        match self {
            Motion::Held => PERIOD,
            Motion::Rk4(h) => h,
        }
    }
}

/// The first time (s) at which e < each of `thresholds` under the law alone (no rotation), and
/// the heading error wrap(ϑ_G − ϑ) (rad) then; `None` if not within `TIME_LIMIT`.
fn law_alone(c: &DockingController, start: Pose2, motion: Motion, thresholds: &[f64]) -> Vec<Option<(f64, f64)>> {
    let goal = c.goal();
    let mut found = vec![None; thresholds.len()];
    let mut pose = start;
    let mut k = 0u32;
    loop {
        let t = f64::from(k) * motion.step();
        let e = polar_error(&pose, &goal).e;
        for (slot, eps) in found.iter_mut().zip(thresholds) {
            if slot.is_none() && e < *eps {
                *slot = Some((t, wrap(goal.yaw - pose.yaw)));
            }
        }
        if t >= TIME_LIMIT || found.iter().all(Option::is_some) {
            return found;
        }
        pose = match motion {
            Motion::Held => advance(&pose, &c.approach_command(&pose).0.to_twist(), PERIOD),
            Motion::Rk4(h) => rk4_step(&pose, h, |q| c.approach_command(q).0.to_twist()),
        };
        k += 1;
    }
}

/// The whole docking with the in-place rotation: docked or not, time, e, heading error.
fn with_rotation(limits: VelocityLimits, start: Pose2, motion: Motion) -> Outcome {
    match motion {
        Motion::Held => lyapunov(start, limits),
        Motion::Rk4(h) => {
            let mut c = controller(limits);
            let run = simulate_docking(&mut c, Kinematics::Unicycle, start, h, TIME_LIMIT).expect("valid run");
            Outcome {
                docked: run.end == DockingPhase::Docked,
                time: run.time,
                position_error: polar_error(&run.final_pose, &c.goal()).e,
                heading_error: wrap(c.goal().yaw - run.final_pose.yaw).abs(),
                path: run.path_length,
            }
        }
    }
}

/// A heading error as "rad (°)".
fn angle(a: f64) -> String {
    format!("{:.3} rad ({:.1}°)", a.abs(), a.abs().to_degrees())
}

/// The paper's start split into the law alone and the docking with its final rotation.
fn paper_start_in_two_parts(start: Pose2) {
    const THRESHOLDS: [f64; 2] = [0.02, 0.01];
    let settings = [
        ("Nav2's limits, held 20 ms", nav2_limits(), Motion::Held),
        ("unlimited, RK4 10 ms", VelocityLimits::unlimited(), Motion::Rk4(0.01)),
    ];
    println!(
        "| paper S: setting | law alone: e < 0.02 m at (s) | heading error then | law alone: e < 0.01 m at (s) | heading error then | with the rotation: docked | time (s) | final e (m) | final heading error |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, limits, motion) in settings {
        let crossings = law_alone(&controller(limits), start, motion, &THRESHOLDS);
        let cells: Vec<String> = crossings
            .iter()
            .map(|c| match c {
                Some((t, heading)) => format!("{t:.2} | {}", angle(*heading)),
                None => "not within the time limit | —".to_string(),
            })
            .collect();
        let out = with_rotation(limits, start, motion);
        println!(
            "| {name} | {} | {} | {:.2} | {:.3} | {} |",
            cells.join(" | "),
            if out.docked { "yes" } else { "no" },
            out.time,
            out.position_error,
            angle(out.heading_error)
        );
    }
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
        for (law, out) in [
            ("Lyapunov (ours)", lyapunov(start, nav2_limits())),
            ("Nav2 graceful", nav2(start)),
        ] {
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
    println!();
    paper_start_in_two_parts(starts[0].1);
}
