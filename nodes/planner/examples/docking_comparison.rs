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
//! A third table runs the law alone from every start. Last, a sweep of the gains within the
//! paper's printed ranges under any reading of them: which let the law alone bring the heading
//! within 0.03 rad by the time e first falls below 0.02 m, from the paper's start and from all
//! six.
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
    controller_with(DockingGains::paper(), limits)
}

/// Our docking controller with `gains`, the default thresholds and `limits`.
fn controller_with(gains: DockingGains, limits: VelocityLimits) -> DockingController {
    let config = DockingConfig {
        time_limit_s: TIME_LIMIT + 1.0,
        ..DockingConfig::default()
    };
    DockingController::new(gains, config, limits, Finish::RotateInPlace, Pose2::identity()).expect("valid settings")
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

/// The law alone (the paper's gains, no rotation) from every start: when e first falls below
/// 0.02 m and the heading error then, next to the whole docking's.
fn law_alone_from_every_start(starts: &[(&str, Pose2)]) {
    println!("| start (x, y, ϑ) | setting | law alone: e < 0.02 m at (s) | heading error then | with the rotation: time (s) | final heading error |");
    println!("|---|---|---|---|---|---|");
    let settings = [
        ("Nav2's limits, held 20 ms", nav2_limits(), Motion::Held),
        ("unlimited, RK4 10 ms", VelocityLimits::unlimited(), Motion::Rk4(0.01)),
    ];
    for (name, start) in starts {
        for (setting, limits, motion) in settings {
            let alone = law_alone(&controller(limits), *start, motion, &[0.02])[0];
            let whole = with_rotation(limits, *start, motion);
            let alone = match alone {
                Some((t, heading)) => format!("{t:.2} | {}", angle(heading)),
                None => "not within the time limit | —".to_string(),
            };
            println!(
                "| {name} ({:.1}, {:.1}, {:.2}) | {setting} | {alone} | {:.2} | {} |",
                start.x,
                start.y,
                start.yaw,
                whole.time,
                angle(whole.heading_error)
            );
        }
    }
}

/// Gain values for the sweep: within (0, 1) in steps of 0.05, and within (1, 6) in steps of 0.25.
fn sweep_values(wide: bool) -> Vec<f64> {
    let mut v: Vec<f64> = (1..20).map(|i| f64::from(i) * 0.05).collect();
    if wide {
        v.extend((5..24).map(|i| f64::from(i) * 0.25));
    }
    v
}

/// Which gains, within the paper's printed ranges under any reading of them (each of γ, k, h
/// within (0, 1), or one of them within (0, 6); λ enters neither v nor ω), let the law alone
/// bring the heading within 0.03 rad by the time e first falls below 0.02 m, from the paper's
/// start, unlimited (RK4, 10 ms); the best ones then checked under Nav2's limits and from every
/// start.
fn gain_sweep(starts: &[(&str, Pose2)]) {
    const HEADING: f64 = 0.03;
    let paper = starts[0].1;
    let mut tried = 0u32;
    let mut met: Vec<(f64, f64, f64, f64, f64)> = Vec::new(); // (|heading|, t, γ, k, h)
    let mut best: Option<(f64, f64, f64, f64, f64)> = None;
    for gamma in sweep_values(true) {
        for k in sweep_values(true) {
            for h in sweep_values(true) {
                if [gamma, k, h].iter().filter(|g| **g > 1.0).count() > 1 {
                    continue; // only one gain has the (0, 6) range, whichever it is
                }
                let Ok(gains) = DockingGains::new(gamma, k, h, 0.55) else {
                    continue;
                };
                tried += 1;
                let c = controller_with(gains, VelocityLimits::unlimited());
                if let Some((t, heading)) = law_alone(&c, paper, Motion::Rk4(0.01), &[0.02])[0] {
                    let row = (heading.abs(), t, gamma, k, h);
                    if best.is_none_or(|b| row.0 < b.0) {
                        best = Some(row);
                    }
                    if heading.abs() <= HEADING {
                        met.push(row);
                    }
                }
            }
        }
    }
    println!(
        "gain sweep, paper's start, unlimited RK4 10 ms: {tried} gain sets; {} bring the heading within {HEADING} rad when e first < 0.02 m",
        met.len()
    );
    let by_reading = |pred: &dyn Fn(f64, f64, f64) -> bool| met.iter().filter(|m| pred(m.2, m.3, m.4)).count();
    println!(
        "  of them: all of γ, k, h within (0, 1): {}; γ > 1: {}; k > 1: {}; h > 1: {}",
        by_reading(&|g, k, h| g < 1.0 && k < 1.0 && h < 1.0),
        by_reading(&|g, _, _| g > 1.0),
        by_reading(&|_, k, _| k > 1.0),
        by_reading(&|_, _, h| h > 1.0)
    );
    if let Some((heading, t, gamma, k, h)) = best {
        println!(
            "  the smallest heading error: {} at {t:.2} s with γ {gamma:.2}, k {k:.2}, h {h:.2}",
            angle(heading)
        );
    }
    // Each set that meets it there, from every start and in both settings: its worst heading
    // error when e first < 0.02 m (π when e never does).
    let worst = |gamma: f64, k: f64, h: f64| -> f64 {
        let Ok(gains) = DockingGains::new(gamma, k, h, 0.55) else {
            return PI;
        };
        let mut worst: f64 = 0.0;
        for (_, start) in starts {
            for (limits, motion) in [
                (VelocityLimits::unlimited(), Motion::Rk4(0.01)),
                (nav2_limits(), Motion::Held),
            ] {
                worst = worst.max(
                    match law_alone(&controller_with(gains, limits), *start, motion, &[0.02])[0] {
                        Some((_, heading)) => heading.abs(),
                        None => PI,
                    },
                );
            }
        }
        worst
    };
    let mut ranked: Vec<(f64, f64, f64, f64)> = met.iter().map(|m| (worst(m.2, m.3, m.4), m.2, m.3, m.4)).collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "  of those, {} meet it from all six starts in both settings; the smallest worst case: {}",
        ranked.iter().filter(|r| r.0 <= HEADING).count(),
        ranked.first().map_or("none".to_string(), |r| format!(
            "{} with γ {:.2}, k {:.2}, h {:.2}",
            angle(r.0),
            r.1,
            r.2,
            r.3
        ))
    );
    let all_six =
        |pred: &dyn Fn(f64, f64, f64) -> bool| ranked.iter().filter(|r| r.0 <= HEADING && pred(r.1, r.2, r.3)).count();
    println!(
        "  of those from all six: all of γ, k, h within (0, 1): {}; γ > 1: {}; k > 1: {}; h > 1: {}",
        all_six(&|g, k, h| g < 1.0 && k < 1.0 && h < 1.0),
        all_six(&|g, _, _| g > 1.0),
        all_six(&|_, k, _| k > 1.0),
        all_six(&|_, _, h| h > 1.0)
    );
    let narrow: Vec<&(f64, f64, f64, f64)> = ranked.iter().filter(|r| r.1 < 1.0 && r.2 < 1.0 && r.3 < 1.0).collect();
    println!(
        "  with all of γ, k, h within (0, 1): {} from all six starts; the smallest worst case: {}",
        narrow.iter().filter(|r| r.0 <= HEADING).count(),
        narrow.first().map_or("none".to_string(), |r| format!(
            "{} with γ {:.2}, k {:.2}, h {:.2}",
            angle(r.0),
            r.1,
            r.2,
            r.3
        ))
    );
    println!("| γ, k, h | start | setting | e < 0.02 m at (s) | heading error then |");
    println!("|---|---|---|---|---|");
    for &(_, gamma, k, h) in ranked.iter().take(1).chain(narrow.iter().take(1).copied()) {
        let Ok(gains) = DockingGains::new(gamma, k, h, 0.55) else {
            continue;
        };
        for (name, start) in starts {
            for (setting, limits, motion) in [
                ("unlimited, RK4 10 ms", VelocityLimits::unlimited(), Motion::Rk4(0.01)),
                ("Nav2's limits, held 20 ms", nav2_limits(), Motion::Held),
            ] {
                let cell = match law_alone(&controller_with(gains, limits), *start, motion, &[0.02])[0] {
                    Some((t, heading)) => format!("{t:.2} | {}", angle(heading)),
                    None => "not within the time limit | —".to_string(),
                };
                println!("| {gamma:.2}, {k:.2}, {h:.2} | {name} | {setting} | {cell} |");
            }
        }
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
    println!();
    law_alone_from_every_start(&starts);
    println!();
    gain_sweep(&starts);
}
