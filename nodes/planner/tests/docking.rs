//! The Lyapunov docking law against hand-worked numbers and the paper's run (SPEC §3).

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_4, PI, SQRT_2};

use approx::assert_relative_eq;
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_planner::{
    polar_error, simulate_docking, sinc, DockingConfig, DockingController, DockingFailure, DockingGains, DockingPhase,
    DockingRun, Finish, Kinematics, PlannerError, Residual, Velocity, VelocityLimits,
};
use proptest::prelude::*;

fn paper_start() -> Pose2 {
    Pose2::new(-1.0, 1.0, 3.0 * FRAC_PI_4)
}

fn controller(limits: VelocityLimits, finish: Finish) -> DockingController {
    DockingController::new(
        DockingGains::paper(),
        DockingConfig::default(),
        limits,
        finish,
        Pose2::identity(),
    )
    .expect("valid settings")
}

/// Largest rise of V between consecutive approach samples (≤ 0 when V never increases).
fn largest_rise(run: &DockingRun) -> f64 {
    run.samples
        .windows(2)
        .filter(|w| w[1].output.phase == DockingPhase::Approach)
        .map(|w| w[1].output.lyapunov - w[0].output.lyapunov)
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn paper_start_by_hand() {
    // S = [−1, 1, 3π/4], G = [0, 0, 0]:
    //   e = √(1² + 1²) = √2 = 1.414214;
    //   Ω = atan2(0 − 1, 0 − (−1)) = atan2(−1, 1) = −π/4;
    //   α = Ω − ϑ = −π/4 − 3π/4 = −π (exactly the tie: the Decision keeps −π);
    //   Θ = Ω − ϑ_G = −π/4.
    //   v₀ = γ·e·cos α = 0.5 · √2 · (−1) = −0.707107 m/s (reverse first);
    //   ω₀ = k·α + γ·cos α·(sin α/α)·(α + hΘ) = 0.3·(−π) + 0.5·(−1)·(0/π)·(…) = −0.3π = −0.942478;
    //   V₀ = ½(λe² + α² + hΘ²) = ½(0.55·2 + π² + 0.5·π²/16) = ½(1.1 + 9.869604 + 0.308425) = 5.639015.
    let gains = DockingGains::paper();
    let p = polar_error(&paper_start(), &Pose2::identity());
    assert_relative_eq!(p.e, SQRT_2, epsilon = 1e-12);
    assert_eq!(p.alpha, -PI);
    assert_relative_eq!(p.theta, -FRAC_PI_4, epsilon = 1e-12);
    let cmd = gains.law(&p);
    assert_relative_eq!(cmd.v, -FRAC_1_SQRT_2, epsilon = 1e-12);
    assert_relative_eq!(cmd.omega, -0.942_477_796, epsilon = 1e-9);
    assert_relative_eq!(gains.lyapunov(&p), 5.639_015, epsilon = 1e-6);
    // V̇₀ = −λγe²cos²α − kα² = −0.55·0.5·2·1 − 0.3·π² = −0.55 − 2.960881 = −3.510881.
    assert_relative_eq!(gains.lyapunov_rate(&p, 1.0), -3.510_881, epsilon = 1e-6);
}

#[test]
fn paper_run_reverses_then_docks_with_v_never_increasing() {
    for h in [0.01, 0.005] {
        let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
        let run = simulate_docking(&mut c, Kinematics::Unicycle, paper_start(), h, 120.0).expect("valid run");
        let first = run.samples[0].output.command;
        assert_relative_eq!(first.v, -FRAC_1_SQRT_2, epsilon = 1e-12);
        assert_relative_eq!(first.omega, -0.3 * PI, epsilon = 1e-12);
        // It reverses first, then drives forward: v changes sign from − to + exactly once
        // during the approach (cos α crosses 0 once as |α| falls below π/2).
        let signs: Vec<bool> = run
            .samples
            .iter()
            .filter(|s| s.output.phase == DockingPhase::Approach && s.output.command.v.abs() > 1e-9)
            .map(|s| s.output.command.v > 0.0)
            .collect();
        let changes = signs.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(!signs[0] && *signs.last().unwrap(), "reverse first, forward last");
        assert_eq!(changes, 1, "h = {h}");
        // V never increases while the law drives (rounding aside: 1e-12 of V₀ ≈ 5.6).
        let rise = largest_rise(&run);
        assert!(rise <= 1e-12, "h = {h}: V rose by {rise}");
        assert_eq!(run.end, DockingPhase::Docked, "h = {h}");
        let end = polar_error(&run.final_pose, &Pose2::identity());
        assert!(end.e < 0.02 && run.final_pose.yaw.abs() < 0.03, "{:?}", run.final_pose);
        println!(
            "paper run h = {h}: docked after {:.2} s, path {:.3} m, final e {:.4} m, heading {:.4} rad",
            run.time, run.path_length, end.e, run.final_pose.yaw
        );
    }
}

#[test]
fn commands_held_for_a_control_period_still_never_raise_v() {
    // A node holds each command for its period (exact arcs): at 10, 20 and 50 ms the paper's
    // run still has V falling at every step until the in-place rotation takes over.
    for period in [0.01, 0.02, 0.05] {
        let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
        let mut pose = paper_start();
        let mut previous = f64::INFINITY;
        let mut steps = 0;
        loop {
            let out = c.update(&pose, steps as f64 * period).expect("finite");
            if out.phase != DockingPhase::Approach {
                assert_eq!(out.phase, DockingPhase::Rotate, "period {period}");
                break;
            }
            assert!(out.lyapunov < previous, "period {period}, step {steps}: V rose");
            previous = out.lyapunov;
            pose = mobil_planner::advance(&pose, &out.command.to_twist(), period);
            steps += 1;
            assert!(steps as f64 * period < 60.0, "period {period}: no convergence");
        }
    }
}

#[test]
fn lyapunov_rate_matches_a_finite_difference_of_v() {
    // A second method for eq. (3.48): V̇ from a central difference of V along the closed loop.
    let gains = DockingGains::paper();
    let goal = Pose2::new(0.5, -0.2, 0.4);
    for start in [
        Pose2::new(-1.0, 0.7, 0.3),
        Pose2::new(2.0, 1.0, -2.5),
        Pose2::new(0.1, -1.5, 1.0),
    ] {
        let f = |q: &Pose2| gains.law(&polar_error(q, &goal)).to_twist();
        let h = 1e-4;
        let ahead = mobil_planner::rk4_step(&start, h, f);
        let behind = mobil_planner::rk4_step(&start, -h, f);
        let v = |q: &Pose2| gains.lyapunov(&polar_error(q, &goal));
        let numeric = (v(&ahead) - v(&behind)) / (2.0 * h);
        let analytic = gains.lyapunov_rate(&polar_error(&start, &goal), 1.0);
        assert_relative_eq!(numeric, analytic, epsilon = 1e-6, max_relative = 1e-6);
        assert!(analytic < 0.0);
    }
}

#[test]
fn alpha_tie_at_plus_and_minus_pi_takes_minus_pi() {
    let gains = DockingGains::paper();
    // Facing exactly away from G along x, on either side: Ω − ϑ = 0 − π = −π and π − 0 = π.
    for start in [Pose2::new(-1.0, 0.0, PI), Pose2::new(1.0, 0.0, 0.0)] {
        let p = polar_error(&start, &Pose2::identity());
        assert_eq!(p.alpha, -PI, "{start:?}");
        let cmd = gains.law(&p);
        // v = γ·1·cos(−π) = −0.5; ω = k·(−π) (sin π = 0 kills the second term) = −0.942478.
        assert_relative_eq!(cmd.v, -0.5, epsilon = 1e-12);
        assert_relative_eq!(cmd.omega, -0.3 * PI, epsilon = 1e-12);
    }
    // Just short of the tie α keeps its sign: the tie rule is for exactly ±π only.
    let near = polar_error(&Pose2::new(1.0, 0.0, 1e-9), &Pose2::identity());
    assert_relative_eq!(near.alpha, PI - 1e-9, epsilon = 1e-15);
}

#[test]
fn alpha_zero_uses_sinc() {
    let gains = DockingGains::paper();
    // S = [−1, −1, π/4] looks straight at G: Ω = atan2(1, 1) = π/4, α = 0, Θ = π/4;
    // v = 0.5·√2·1 = 0.707107; ω = 0 + 0.5·1·1·(0 + 0.5·π/4) = 0.196350.
    let p = polar_error(&Pose2::new(-1.0, -1.0, FRAC_PI_4), &Pose2::identity());
    assert_eq!(p.alpha, 0.0);
    let cmd = gains.law(&p);
    assert_relative_eq!(cmd.v, FRAC_1_SQRT_2, epsilon = 1e-12);
    assert_relative_eq!(cmd.omega, 0.196_349_541, epsilon = 1e-9);
    // Continuous through 0: at α = ±1e-7 ω moves by about (k + γ)·1e-7 only.
    for a in [1e-7, -1e-7] {
        let nudged = Pose2::new(-1.0, -1.0, FRAC_PI_4 - a);
        let w = gains.law(&polar_error(&nudged, &Pose2::identity())).omega;
        assert!((w - cmd.omega).abs() < 1e-6, "α = {a}: {w}");
    }
    // sinc against sin a / a and its series: 1 − a²/6 + a⁴/120.
    assert_eq!(sinc(0.0), 1.0);
    assert_relative_eq!(sinc(1e-3), (1e-3f64).sin() / 1e-3, epsilon = 1e-15);
    assert_relative_eq!(sinc(5e-5), 1.0 - 2.5e-9 / 6.0, epsilon = 1e-16);
    assert_relative_eq!(sinc(PI / 2.0), 2.0 / PI, epsilon = 1e-15);
}

#[test]
fn limits_scale_v_and_omega_by_one_factor() {
    let limits = VelocityLimits::new(0.2, 0.3).expect("valid");
    // Paper start: v = −0.707107, ω = −0.942478; s = min(0.2/0.707107, 0.3/0.942478)
    // = min(0.282843, 0.318310) = 0.282843 → v = −0.2, ω = −0.942478·0.282843 = −0.266573.
    let (cmd, s) = limits.apply(Velocity::new(-FRAC_1_SQRT_2, -0.3 * PI));
    assert_relative_eq!(s, 0.282_842_712, epsilon = 1e-9);
    assert_relative_eq!(cmd.v, -0.2, epsilon = 1e-9);
    assert_relative_eq!(cmd.omega, -0.266_572_976, epsilon = 1e-9);
    // Only ω over its limit: s = 0.3/0.6 = 0.5 on both.
    let (cmd, s) = limits.apply(Velocity::new(0.1, 0.6));
    assert_eq!((s, cmd.v, cmd.omega), (0.5, 0.05, 0.3));
    // Within limits: unchanged.
    assert_eq!(limits.apply(Velocity::new(0.1, -0.2)), (Velocity::new(0.1, -0.2), 1.0));
    assert_eq!(limits.factor(Velocity::new(f64::NAN, 0.0)), 0.0);
}

#[test]
fn clipping_omega_alone_would_raise_v() {
    // V̇ for any (v, ω), from the kinematics (ė = −v cos α, α̇ = −ω + v sin α / e,
    // Θ̇ = v sin α / e): V̇ = −λev cos α + α(−ω + v sin α/e) + hΘ·v sin α/e.
    let (lambda, h) = (0.55, 0.5);
    let p = mobil_planner::PolarError {
        e: 0.1,
        alpha: 0.1,
        theta: 3.0,
    };
    let rate = |v: f64, w: f64| {
        let s = v * p.alpha.sin() / p.e;
        -lambda * p.e * v * p.alpha.cos() + p.alpha * (-w + s) + h * p.theta * s
    };
    // The law: v = 0.5·0.1·cos 0.1 = 0.0497502; ω = 0.03 + 0.5·cos 0.1·sinc 0.1·(0.1 + 1.5)
    // = 0.824678.
    let law = DockingGains::paper().law(&p);
    assert_relative_eq!(law.v, 0.049_750_2, epsilon = 1e-7);
    assert_relative_eq!(law.omega, 0.824_678, epsilon = 1e-6);
    // ω clipped alone to 0.2: V̇ = −0.0027225 − 0.0150333 + 0.0745009 = +0.0567451 > 0.
    assert_relative_eq!(rate(law.v, 0.2), 0.056_745_1, epsilon = 1e-6);
    // One common factor s = 0.2/0.824678 = 0.242519: V̇ = s·(−0.0057226) = −0.0013878 < 0.
    let (cmd, s) = VelocityLimits::new(1.0, 0.2).expect("valid").apply(law);
    assert_relative_eq!(s, 0.242_519, epsilon = 1e-6);
    assert_relative_eq!(rate(cmd.v, cmd.omega), -0.001_387_8, epsilon = 1e-6);
    assert_relative_eq!(
        rate(cmd.v, cmd.omega),
        DockingGains::paper().lyapunov_rate(&p, s),
        epsilon = 1e-12
    );
}

#[test]
fn v_never_increases_under_tight_limits() {
    let limits = VelocityLimits::new(0.1, 0.2).expect("valid");
    let mut c = controller(limits, Finish::RotateInPlace);
    let run = simulate_docking(&mut c, Kinematics::Unicycle, paper_start(), 0.01, 300.0).expect("valid run");
    let rise = largest_rise(&run);
    assert!(rise <= 1e-12, "V rose by {rise}");
    for s in &run.samples {
        assert!(s.output.command.v.abs() <= 0.1 + 1e-12 && s.output.command.omega.abs() <= 0.2 + 1e-12);
    }
    // The reported V̇ (the limited command's) against a second method: the change of V between
    // consecutive approach samples over h, compared with the trapezoid mean of V̇ at both ends
    // (exact to O(h²·V̈); the scale factor has kinks where the binding limit changes).
    let mut checked = 0;
    for w in run.samples.windows(2) {
        if w[0].output.phase != DockingPhase::Approach || w[1].output.phase != DockingPhase::Approach {
            continue;
        }
        let h = w[1].t - w[0].t;
        let difference = (w[1].output.lyapunov - w[0].output.lyapunov) / h;
        let trapezoid = 0.5 * (w[0].output.lyapunov_rate + w[1].output.lyapunov_rate);
        assert!(
            (difference - trapezoid).abs() <= 1e-3 * trapezoid.abs() + 1e-5,
            "t = {}: ΔV/h = {difference}, mean V̇ = {trapezoid}",
            w[0].t
        );
        checked += 1;
    }
    assert!(checked > 1000, "{checked}");
    // The limit binds at the start: s₀ = min(0.1/0.707107, 0.2/0.942478) = 0.141421.
    assert_relative_eq!(run.samples[0].output.scale, 0.141_421_356, epsilon = 1e-9);
    assert_eq!(run.end, DockingPhase::Docked);
    println!("tight limits (0.1 m/s, 0.2 rad/s): docked after {:.2} s", run.time);
}

#[test]
fn omni_chassis_docks_with_a_final_rotation() {
    let params = ChassisParams::omr3();
    let mut c = controller(VelocityLimits::from_chassis(&params), Finish::for_chassis(&params));
    let run = simulate_docking(&mut c, Kinematics::Chassis(params), paper_start(), 0.01, 120.0).expect("valid run");
    assert_eq!(run.end, DockingPhase::Docked);
    assert!(run.samples.iter().any(|s| s.output.phase == DockingPhase::Rotate));
    let end = polar_error(&run.final_pose, &Pose2::identity());
    assert!(end.e < 0.02 && run.final_pose.yaw.abs() < 0.03, "{:?}", run.final_pose);
    assert!(largest_rise(&run) <= 1e-12);
}

#[test]
fn car_like_chassis_reports_its_residual() {
    // MOBIL-II cannot follow the law: from the paper's start the law reverses and turns
    // (v₀ = −0.707, ω₀ = −0.942: radius 0.75 m), then v = γe·cos α falls to 0 as |α| → π/2
    // while ω stays ≠ 0 — a cusp, a turn in place. The car-like LOW-LEVEL keeps the curvature
    // within 1/0.73 m⁻¹, so near the cusp it barely moves: V stops falling, and after
    // stall_time_s (5 s) of V falling by less than 0.1 % the docking fails as not converging,
    // far from the goal (e ≫ ε_e), with |α| near π/2. The residual reported is the final pose's.
    let params = ChassisParams::mobil2();
    let mut c = controller(VelocityLimits::from_chassis(&params), Finish::for_chassis(&params));
    let run = simulate_docking(&mut c, Kinematics::Chassis(params), paper_start(), 0.01, 120.0).expect("valid run");
    let last = run.samples.last().expect("samples").output;
    assert_eq!(run.end, DockingPhase::Failed(DockingFailure::NotConverging));
    assert!(last.polar.e > 0.1, "{:?}", last.polar);
    assert!(last.polar.alpha.cos().abs() < 0.05, "{:?}", last.polar);
    // The stall window: over the last 5 s V fell by less than 0.1 %.
    let v_end = last.lyapunov;
    let before = run
        .samples
        .iter()
        .rev()
        .find(|s| s.t <= run.time - 5.0)
        .expect("longer than 5 s")
        .output
        .lyapunov;
    assert!(v_end >= 0.999 * before, "V {before} → {v_end}");
    // The residual: e = |G − q| and wrap(0 − ϑ) of the final pose, computed here.
    let residual = last.residual.expect("a failure carries its residual");
    assert_relative_eq!(residual.e, run.final_pose.x.hypot(run.final_pose.y), epsilon = 1e-12);
    assert_relative_eq!(residual.heading, mobil_geom::wrap(-run.final_pose.yaw), epsilon = 1e-12);
    println!(
        "MOBIL-II docking from the paper's start: {:?} after {:.2} s, residual e = {:.3} m, heading {:.3} rad",
        run.end, run.time, residual.e, residual.heading
    );
}

#[test]
fn heading_residual_failure_carries_e_and_heading() {
    // A chassis that cannot turn in place, 0.01 m short of G (e < ε_e = 0.02) with the heading
    // 0.5 rad off (> ε_ϑ = 0.03): FAILED with the residual (0.01, wrap(0 − 0.5) = −0.5), and the
    // same residual on every later step, wherever the robot is.
    let mut c = controller(VelocityLimits::unlimited(), Finish::ReportResidual);
    let out = c.update(&Pose2::new(-0.01, 0.0, 0.5), 0.0).expect("finite");
    assert_eq!(out.phase, DockingPhase::Failed(DockingFailure::HeadingResidual));
    assert_eq!(out.command, Velocity::ZERO);
    let expected = Residual { e: 0.01, heading: -0.5 };
    assert_eq!(out.residual, Some(expected));
    let later = c.update(&Pose2::new(1.0, 0.0, 0.0), 0.1).expect("finite");
    assert_eq!(later.residual, Some(expected));
}

#[test]
fn rotation_reports_its_real_scale() {
    // In place 0.005 m from G (< ε_e) with the heading 2 rad off: ω = 1.5·2 = 3 rad/s, limit
    // 0.5 rad/s → s = 0.5 / 3 = 1/6, ω = 0.5.
    let mut c = controller(VelocityLimits::new(1.0, 0.5).expect("valid"), Finish::RotateInPlace);
    let out = c.update(&Pose2::new(0.005, 0.0, -2.0), 0.0).expect("finite");
    assert_eq!(out.phase, DockingPhase::Rotate);
    assert_relative_eq!(out.scale, 1.0 / 6.0, epsilon = 1e-15);
    assert_relative_eq!(out.command.omega, 0.5, epsilon = 1e-15);
    assert_eq!(out.command.v, 0.0);
}

#[test]
fn drifting_out_of_the_position_tolerance_with_the_heading_right_goes_back_to_the_law() {
    // Rotating (e = 0.01 < ε_e, heading 0.5 rad off), the robot is then found 1.5·ε_e = 0.03 m
    // behind G with the heading already right: the rotation would command ω = 1.5·0 = 0 and
    // stall. Back to the law instead: α = Θ = 0, v = γe = 0.5·0.03 = 0.015 m/s, ω = 0; driving
    // straight, e = 0.03·e^(−0.5t) falls below ε_e = 0.02 at t = 2 ln 1.5 = 0.8109 s: docked.
    let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
    let out = c.update(&Pose2::new(-0.01, 0.0, 0.5), 0.0).expect("finite");
    assert_eq!(out.phase, DockingPhase::Rotate);
    let run = simulate_docking(&mut c, Kinematics::Unicycle, Pose2::new(-0.03, 0.0, 0.0), 0.01, 10.0).expect("valid");
    let first = run.samples[0].output;
    assert_eq!(first.phase, DockingPhase::Approach);
    assert_relative_eq!(first.command.v, 0.015, epsilon = 1e-15);
    assert_eq!(first.command.omega, 0.0);
    assert_eq!(run.end, DockingPhase::Docked);
    // Docked at the first 10 ms sample after 0.8109 s.
    assert_relative_eq!(run.time, 0.82, epsilon = 1e-9);
}

#[test]
fn huge_but_finite_poses_and_simulation_lengths_are_refused() {
    // e² overflows above about 1.3e154 m: such a pose gave V = ∞ and V̇ = NaN. Refused now.
    let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
    for pose in [
        Pose2::new(1e154, 0.0, 0.0),
        Pose2::new(0.0, -2e6, 0.0),
        Pose2 {
            x: 0.0,
            y: 0.0,
            yaw: 1e7,
        },
    ] {
        assert!(
            matches!(c.update(&pose, 0.0), Err(PlannerError::OutOfRange { .. })),
            "{pose:?}"
        );
    }
    // One million sub-steps at most: 10 000 s at 10 ms is accepted as a bound, a hair more is
    // refused before any memory is taken.
    let refused = simulate_docking(&mut c, Kinematics::Unicycle, paper_start(), 0.01, 10_000.1);
    assert!(
        matches!(refused, Err(PlannerError::InvalidConfig { name: "max_time", .. })),
        "{refused:?}"
    );
}

#[test]
fn gains_refused_unless_positive_and_finite_and_warned_outside_the_printed_ranges() {
    for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        for (i, name) in ["gamma", "k", "h", "lambda"].into_iter().enumerate() {
            let mut g = [0.5, 0.3, 0.5, 0.55];
            g[i] = bad;
            let err = DockingGains::new(g[0], g[1], g[2], g[3]).unwrap_err();
            assert!(
                matches!(err, PlannerError::InvalidGain { name: n, .. } if n == name),
                "{name} = {bad}: {err}"
            );
        }
    }
    assert!(DockingGains::paper().warnings().is_empty());
    let w = DockingGains::new(1.5, 7.0, 0.5, 0.55).expect("positive").warnings();
    let names: Vec<_> = w.iter().map(|w| w.name).collect();
    assert_eq!(names, ["gamma", "k"]);
    assert_eq!(w[1].range, (0.0, 6.0));
}

#[test]
fn time_limit_and_stall_end_in_failed_with_a_zero_command() {
    let config = DockingConfig {
        time_limit_s: 1.0,
        ..DockingConfig::default()
    };
    let mut c = DockingController::new(
        DockingGains::paper(),
        config,
        VelocityLimits::unlimited(),
        Finish::RotateInPlace,
        Pose2::identity(),
    )
    .expect("valid");
    let run = simulate_docking(&mut c, Kinematics::Unicycle, paper_start(), 0.01, 10.0).expect("valid run");
    assert_eq!(run.end, DockingPhase::Failed(DockingFailure::TimeLimit));
    assert_relative_eq!(run.time, 1.01, epsilon = 1e-9);
    assert_eq!(run.samples.last().unwrap().output.command, Velocity::ZERO);

    // A robot that never moves (commands ignored): V stays, so after stall_time_s (5 s) FAILED.
    let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
    let mut end = None;
    for i in 0..1000 {
        let out = c.update(&paper_start(), i as f64 * 0.1).expect("finite");
        if out.phase.is_terminal() {
            end = Some((i, out.phase));
            break;
        }
    }
    // Progress last at t = 0; 5.1 s > 5 s first at step 51.
    assert_eq!(end, Some((51, DockingPhase::Failed(DockingFailure::NotConverging))));
    assert!(c.update(&Pose2::new(f64::NAN, 0.0, 0.0), 6.0).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_starts_converge_with_v_never_increasing(
        x in -3.0..3.0f64, y in -3.0..3.0f64, yaw in -PI..PI, gx in -1.0..1.0f64, gy in -1.0..1.0f64,
        gyaw in -PI..PI,
    ) {
        let goal = Pose2::new(gx, gy, gyaw);
        let start = Pose2::new(x, y, yaw);
        prop_assume!((start.x - goal.x).hypot(start.y - goal.y) > 0.05);
        let mut c = DockingController::new(
            DockingGains::paper(), DockingConfig::default(), VelocityLimits::unlimited(), Finish::RotateInPlace, goal,
        ).unwrap();
        let run = simulate_docking(&mut c, Kinematics::Unicycle, start, 0.01, 100.0).unwrap();
        // Θ = wrap(Ω − ϑ_G) jumps from ∓π to ±π when the line of sight swings past the goal's
        // back; ω = … + γ·cos α·sinc α·hΘ jumps with it by up to 2πγh = 1.571 rad/s. V itself is
        // continuous there and falls on both sides, but an RK4 step straddling the jump has an
        // O(h) error: up to h·Δω = 0.0157 rad in α, so V may rise by up to
        // |α|·0.0157 + 0.0157²/2 ≤ π·0.0157 + 0.000123 = 0.0495 on that one step. Everywhere else V
        // never rises.
        let v0 = run.samples[0].output.lyapunov.max(1.0);
        for w in run.samples.windows(2) {
            if w[1].output.phase != DockingPhase::Approach {
                continue;
            }
            let rise = w[1].output.lyapunov - w[0].output.lyapunov;
            let wrapped = (w[1].output.polar.theta - w[0].output.polar.theta).abs() > PI;
            let bound = if wrapped { 0.0495 } else { 1e-12 * v0 };
            prop_assert!(rise <= bound, "V rose by {} at t = {} (Θ wrapped: {})", rise, w[0].t, wrapped);
        }
        prop_assert_eq!(run.end, DockingPhase::Docked);
        prop_assert!(run.time < 100.0);
    }
}

/// Every field of a docking output is finite (the residual, if any, too).
fn output_is_finite(o: &mobil_planner::DockingOutput) -> bool {
    [
        o.command.v,
        o.command.omega,
        o.scale,
        o.polar.e,
        o.polar.alpha,
        o.polar.theta,
        o.lyapunov,
        o.lyapunov_rate,
        o.heading_error,
    ]
    .iter()
    .all(|v| v.is_finite())
        && o.residual.is_none_or(|r| r.e.is_finite() && r.heading.is_finite())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]
    #[test]
    fn arbitrary_poses_and_goals_never_give_nan(
        x in proptest::num::f64::ANY, y in proptest::num::f64::ANY, yaw in proptest::num::f64::ANY,
        gx in proptest::num::f64::ANY, gy in proptest::num::f64::ANY, gyaw in proptest::num::f64::ANY,
        t in proptest::num::f64::ANY,
    ) {
        let mut c = controller(VelocityLimits::unlimited(), Finish::RotateInPlace);
        // Either the goal is refused, or every output is finite (or the pose/time refused).
        if c.set_goal(Pose2::new(gx, gy, gyaw)).is_ok()
            && let Ok(out) = c.update(&Pose2::new(x, y, yaw), t)
        {
            prop_assert!(output_is_finite(&out), "{:?}", out);
        }
    }
}
