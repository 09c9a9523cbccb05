//! Every transition of the mode machine on hand-built scans (SPEC §2), with the default
//! configuration: d_sa 0.8, hysteresis 0.2, ds 0.05, n 40, c1 0.3, hit radius 0.4, tolerance 0.1.

use approx::assert_relative_eq;
use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{InputError, Mode, MotionLimits, NavConfig, Navigator, NoPathReason, Side, VelocityCommand};
use nalgebra::Point2;
use std::f64::consts::PI;

/// A 360° scan, one beam per degree from −180°, laser at the centre: `range(deg)` per beam,
/// `None` for nothing in range (+inf).
fn scan(range: impl Fn(i32) -> Option<f64>) -> Scan {
    let ranges = (-180..180)
        .map(|deg| range(deg).map_or(f32::INFINITY, |r| r as f32))
        .collect();
    Scan::new(
        -PI,
        PI - PI / 180.0,
        PI / 180.0,
        0.05,
        10.0,
        ranges,
        vec![],
        Pose2::identity(),
    )
    .unwrap()
}

/// An obstacle at `r` m on the beams within ±5° of `bearing_deg` (base frame), free elsewhere.
fn blocked(bearing_deg: f64, r: f64) -> Scan {
    scan(|deg| {
        let off = (f64::from(deg) - bearing_deg + 540.0).rem_euclid(360.0) - 180.0;
        (off.abs() <= 5.0).then_some(r)
    })
}

fn navigator(config: NavConfig) -> Navigator {
    let mut nav = Navigator::new(config, MotionLimits::from_chassis(&ChassisParams::omr3())).unwrap();
    nav.set_goal(Point2::new(5.0, 0.0)).unwrap();
    nav
}

/// Bearing (deg, base frame at yaw 0) from `p` to the goal (5, 0).
fn goal_bearing_deg(p: Point2<f64>) -> f64 {
    (-p.y).atan2(5.0 - p.x).to_degrees()
}

#[test]
fn rotate_stays_while_the_goal_sector_is_clear_beyond_d_sa() {
    let mut nav = navigator(NavConfig::default());
    // 0.85 m ahead: inside nothing (d_sa = 0.8).
    let out = nav.step(Pose2::identity(), &blocked(0.0, 0.85));
    assert_eq!(out.mode, Mode::Rotate);
    // Every sector ≥ d_sa: all-clear rule, straight for G at full speed (0.5 m/s).
    assert_relative_eq!(out.direction.y, 0.0, epsilon = 1e-12);
    assert!(out.direction.x > 0.0);
    assert_relative_eq!(out.command.vx, 0.5, epsilon = 1e-12);
}

#[test]
fn rotate_uses_symmetric_weights_when_not_all_clear() {
    let mut nav = navigator(NavConfig::default());
    // 0.5 m on the right (−90°, sector 2), the rest free: |f| = 0.8 except f2 = 0.5.
    // Symmetric weights ws_i = (w'_i + w'_{8−i})/2: ws0 = 1, ws1 = 0.58125, ws2 = 0.4125,
    // ws3 = 0.24375, ws4 = 0.1. The full ring gives x = 0.8·(1 − 0.1 + 2c·(0.58125 − 0.24375))
    // = 0.8·(0.9 + 0.477297) = 1.101838, y = 0; the missing 0.3 on the right adds
    // y = +0.3·0.4125 = 0.12375 (a pull away from the obstacle).
    let out = nav.step(Pose2::identity(), &blocked(-90.0, 0.5));
    assert_eq!(out.mode, Mode::Rotate);
    assert_relative_eq!(out.direction.x, 1.101_838, epsilon = 1e-6);
    assert_relative_eq!(out.direction.y, 0.123_75, epsilon = 1e-9);
}

#[test]
fn rotate_to_lock_and_the_side_choice() {
    // Symmetric: tie → left.
    let mut nav = navigator(NavConfig::default());
    let out = nav.step(Pose2::identity(), &blocked(0.0, 0.5));
    assert_eq!(out.mode, Mode::Lock(Side::Left));
    assert_eq!(out.changed_from, Some(Mode::Rotate));
    // A wall 1 m away on the left (45°…135°): the right has more free distance.
    let mut nav = navigator(NavConfig::default());
    let s = scan(|deg| {
        if deg.abs() <= 5 {
            Some(0.5)
        } else if (45..=135).contains(&deg) {
            Some(1.0)
        } else {
            None
        }
    });
    assert_eq!(nav.step(Pose2::identity(), &s).mode, Mode::Lock(Side::Right));
}

#[test]
fn lock_is_fixed_in_the_world_and_released_with_hysteresis() {
    let mut nav = navigator(NavConfig::default());
    assert_eq!(
        nav.step(Pose2::identity(), &blocked(0.0, 0.5)).mode,
        Mode::Lock(Side::Left)
    );
    // Moved to (0, 1): G is now at −11.3°, but the lock stays on world 0°, blocked at 0.5 m:
    // still locked.
    let p = Pose2::new(0.0, 1.0, 0.0);
    assert_eq!(nav.step(p, &blocked(0.0, 0.5)).mode, Mode::Lock(Side::Left));
    // World 0° at 0.9 m: beyond d_sa (0.8) but not beyond d_sa + hysteresis (1.0): locked.
    assert_eq!(nav.step(p, &blocked(0.0, 0.9)).mode, Mode::Lock(Side::Left));
    // The robot turned by +90°: world 0° is now base −90°. A 1.1 m reading there clears it.
    let turned = Pose2::new(0.0, 1.0, PI / 2.0);
    let out = nav.step(turned, &blocked(-90.0, 1.1));
    assert_eq!(out.mode, Mode::Rotate);
    assert_eq!(out.changed_from, Some(Mode::Lock(Side::Left)));
}

/// Drives a navigator from the origin into L-mode and then 0.0501 m per call to +y, the goal
/// sector blocked, until T-mode; returns it with the hit point.
fn into_track(config: NavConfig) -> (Navigator, Point2<f64>) {
    let mut nav = navigator(config);
    assert_eq!(
        nav.step(Pose2::identity(), &blocked(0.0, 0.5)).mode,
        Mode::Lock(Side::Left)
    );
    for k in 1..=40 {
        let p = Point2::new(0.0, 0.0501 * f64::from(k));
        let out = nav.step(Pose2::new(p.x, p.y, 0.0), &blocked(goal_bearing_deg(p), 0.5));
        // Steps: ⌊k·0.0501 / 0.05⌋ = k. The window closes at step n = 40: progress
        // 5 − √(25 + 2.004²) = 5 − 5.38670 = −0.387 < c1 = 0.3 → H here.
        if k < 40 {
            assert_eq!(out.mode, Mode::Lock(Side::Left), "step {k}");
        } else {
            assert_eq!(out.mode, Mode::Track(Side::Left));
            assert_eq!(out.hit_point, Some(p));
            return (nav, p);
        }
    }
    unreachable!("the loop returns at k = 40")
}

#[test]
fn lock_to_track_after_n_steps_without_progress() {
    let (_, h) = into_track(NavConfig::default());
    assert_relative_eq!(h.y, 2.004, epsilon = 1e-12);
}

#[test]
fn lock_progressing_stays_locked() {
    // Moving 0.0501 per call straight toward G (x), with the locked sector blocked: after 40
    // steps the progress is 40·0.0501 = 2.004 ≥ c1, so no hit point.
    let mut nav = navigator(NavConfig::default());
    nav.step(Pose2::identity(), &blocked(0.0, 0.5));
    for k in 1..=45 {
        let out = nav.step(Pose2::new(0.0501 * f64::from(k), 0.0, 0.0), &blocked(0.0, 0.5));
        assert_eq!(out.mode, Mode::Lock(Side::Left), "step {k}");
    }
}

#[test]
fn track_leaves_where_the_path_crosses_hg_nearer_g() {
    let (mut nav, h) = into_track(NavConfig::default());
    // H = (0, 2.004), G = (5, 0). HG at x = 2.5 is at y = 2.004·(1 − 2.5/5) = 1.002.
    let a = Point2::new(2.5, 1.5);
    assert_eq!(
        nav.step(Pose2::new(a.x, a.y, 0.0), &blocked(goal_bearing_deg(a), 0.5))
            .mode,
        Mode::Track(Side::Left)
    );
    let b = Point2::new(2.5, 0.5);
    let out = nav.step(Pose2::new(b.x, b.y, 0.0), &blocked(goal_bearing_deg(b), 0.5));
    assert_eq!(out.mode, Mode::Rotate);
    let l = out.leave_point.unwrap();
    assert_relative_eq!(l.x, 2.5, epsilon = 1e-12);
    assert_relative_eq!(l.y, 1.002, epsilon = 1e-12);
    assert_eq!(out.hit_point, Some(h));
}

#[test]
fn track_leaves_when_the_goal_sector_clears_nearer_g_than_h() {
    let (mut nav, _) = into_track(NavConfig::default());
    // Farther from G than H (|HG| = 5.3867): (−1, 3) is 6.708 away. Everything clear: stays.
    let far = Pose2::new(-1.0, 3.0, 0.0);
    assert_eq!(nav.step(far, &scan(|_| None)).mode, Mode::Track(Side::Left));
    // (0.5, 3.6): 5.763 from G, still farther: stays. At (3, 3) (3.606 from G, nearer) and
    // clear: R-mode, leave point here. The path (0.5, 3.6) → (3, 3) stays above HG
    // (y = 2.004·(1 − x/5) ≤ 1.81 there): no crossing.
    let near = Pose2::new(3.0, 3.0, 0.0);
    assert_eq!(
        nav.step(Pose2::new(0.5, 3.6, 0.0), &scan(|_| None)).mode,
        Mode::Track(Side::Left)
    );
    // Goal sector blocked at 0.9 (not beyond d_sa + hysteresis): stays.
    let toward = goal_bearing_deg(near.position());
    assert_eq!(nav.step(near, &blocked(toward, 0.9)).mode, Mode::Track(Side::Left));
    let out = nav.step(near, &blocked(toward, 1.1));
    assert_eq!(out.mode, Mode::Rotate);
    assert_eq!(out.leave_point, Some(Point2::new(3.0, 3.0)));
}

#[test]
fn track_returning_to_h_is_no_path_and_stops() {
    let (mut nav, h) = into_track(NavConfig::default());
    let goal_blocked = |p: Point2<f64>| blocked(goal_bearing_deg(p), 0.5);
    // 0.5 m from H (not yet twice the 0.4 m radius away), back to 0.2 m: not a return.
    for p in [Point2::new(-0.5, h.y), Point2::new(-0.2, h.y)] {
        assert_eq!(
            nav.step(Pose2::new(p.x, p.y, 0.0), &goal_blocked(p)).mode,
            Mode::Track(Side::Left)
        );
    }
    // Out to 1 m (> 0.8), then back within 0.4 m of H (0.316 m), away from G: NO_PATH.
    let p = Point2::new(-1.0, h.y);
    assert_eq!(
        nav.step(Pose2::new(p.x, p.y, 0.0), &goal_blocked(p)).mode,
        Mode::Track(Side::Left)
    );
    let p = Point2::new(-0.3, h.y + 0.1);
    let out = nav.step(Pose2::new(p.x, p.y, 0.0), &goal_blocked(p));
    assert_eq!(out.mode, Mode::NoPath(NoPathReason::ReturnedToHitPoint));
    assert_eq!(out.command, VelocityCommand::ZERO);
    // Stays stopped.
    let out = nav.step(Pose2::new(3.0, 0.0, 0.0), &scan(|_| None));
    assert_eq!(out.mode, Mode::NoPath(NoPathReason::ReturnedToHitPoint));
    assert_eq!(out.command, VelocityCommand::ZERO);
}

#[test]
fn track_without_progress_over_m_steps_is_no_path() {
    let config = NavConfig {
        track_steps: 10,
        ..NavConfig::default()
    };
    let (mut nav, h) = into_track(config);
    // Away from G along −x, 0.0501 per call: the window of m = 10 steps closes at call 10 with
    // progress −(√((5 + 0.501)² + 2.004²) − 5.3867) = −0.467 < c2 = 0.5.
    for k in 1..=10 {
        let p = Point2::new(-0.0501 * f64::from(k), h.y);
        let out = nav.step(Pose2::new(p.x, p.y, 0.0), &blocked(goal_bearing_deg(p), 0.5));
        let expect = if k < 10 {
            Mode::Track(Side::Left)
        } else {
            Mode::NoPath(NoPathReason::NoProgress)
        };
        assert_eq!(out.mode, expect, "step {k}");
    }
}

#[test]
fn goal_reached_stops() {
    let mut nav = navigator(NavConfig::default());
    let out = nav.step(Pose2::new(4.95, 0.05, 1.0), &scan(|_| None));
    // 0.0707 m < 0.10.
    assert_eq!(out.mode, Mode::Reached);
    assert_eq!(out.command, VelocityCommand::ZERO);
    // Near (0.3 m): slowed to 0.5·0.3/0.6 = 0.25 m/s.
    let mut nav = navigator(NavConfig::default());
    let out = nav.step(Pose2::new(4.7, 0.0, 0.0), &scan(|_| None));
    assert_relative_eq!(out.command.vx, 0.25, epsilon = 1e-12);
}

#[test]
fn bad_input_gives_zero_and_keeps_the_mode() {
    let mut nav = navigator(NavConfig::default());
    assert_eq!(nav.set_goal(Point2::new(f64::NAN, 0.0)), Err(InputError::Goal));
    let out = nav.step(Pose2::new(f64::NAN, 0.0, 0.0), &scan(|_| None));
    assert_eq!(out.input_error, Some(InputError::Pose));
    assert_eq!(out.command, VelocityCommand::ZERO);
    assert_eq!(out.mode, Mode::Rotate);
    let bad_laser = Scan::new(
        -PI,
        PI - PI / 180.0,
        PI / 180.0,
        0.05,
        10.0,
        vec![1.0; 360],
        vec![],
        Pose2::new(f64::INFINITY, 0.0, 0.0),
    )
    .unwrap();
    assert_eq!(
        nav.step(Pose2::identity(), &bad_laser).input_error,
        Some(InputError::LaserPose)
    );
    // Without a goal: idle, zero.
    nav.cancel();
    let out = nav.step(Pose2::identity(), &scan(|_| None));
    assert_eq!((out.mode, out.command), (Mode::Idle, VelocityCommand::ZERO));
}

#[test]
fn lock_that_cannot_move_makes_the_hit_point_at_once() {
    let mut nav = navigator(NavConfig::default());
    assert_eq!(
        nav.step(Pose2::identity(), &blocked(0.0, 0.5)).mode,
        Mode::Lock(Side::Left)
    );
    // Boxed in ahead: every beam within ±100° at 0.36 m. Any direction the field can take
    // has at most 0.36 m free (0.01 m beyond the 0.35 m stop): speed ≤ 0.5·0.01/0.45 =
    // 0.011 m/s < the 0.02 m/s stall speed, though only one step of path has passed.
    let p = Pose2::new(0.0, 0.06, 0.0);
    let out = nav.step(p, &scan(|deg| (deg.abs() <= 100).then_some(0.36)));
    assert_eq!(out.mode, Mode::Track(Side::Left));
    assert_eq!(out.changed_from, Some(Mode::Lock(Side::Left)));
    assert_eq!(out.hit_point, Some(p.position()));
}

#[test]
fn omni_turns_toward_a_goal_behind_its_field_of_view() {
    // A 270° scanner (±135°), nothing in range; G straight behind at (−5, 0).
    let fov = 0.75 * PI;
    let empty = Scan::new(
        -fov,
        fov,
        fov / 270.0,
        0.05,
        10.0,
        vec![f32::INFINITY; 541],
        vec![],
        Pose2::identity(),
    )
    .unwrap();
    let mut nav = Navigator::new(NavConfig::default(), MotionLimits::from_chassis(&ChassisParams::omr3())).unwrap();
    nav.set_goal(Point2::new(-5.0, 0.0)).unwrap();
    // Sector 0 (180° ± 22.5°) is unseen and blocked. F = the clear ring minus sector 0's pull,
    // symmetric weights: along the goal 0.8·(0.9 + 0.477297 − 1) = 0.301838 — toward G, which
    // is blind: no translation, turn at 1.5·π → ω_max = 1.5 rad/s.
    let out = nav.step(Pose2::identity(), &empty);
    assert_eq!(out.mode, Mode::Rotate);
    assert_relative_eq!(out.direction.x, -0.301_838, epsilon = 1e-6);
    assert_eq!(
        out.command,
        VelocityCommand {
            vx: 0.0,
            vy: 0.0,
            omega: 1.5
        }
    );
    // Turned to face +y: G is at +90°, seen and clear: straight for it along base +y.
    let out = nav.step(Pose2::new(0.0, 0.0, PI / 2.0), &empty);
    assert_relative_eq!(out.command.vx, 0.0, epsilon = 1e-12);
    assert_relative_eq!(out.command.vy, 0.5, epsilon = 1e-12);
    assert_eq!(out.command.omega, 0.0);
}

#[test]
fn as_a_goal_law_it_commands_the_navigators_command_and_ends_at_the_goal() {
    use mobil_motion::{GoalLaw, Step, StepInput};
    let free = scan(|_| None);
    let mut nav = navigator(NavConfig::default());
    let mut twin = nav.clone();
    let at = |x: f64| StepInput::new(0.0, 0.05, Pose2::new(x, 0.0, 0.0));
    // In open space the goal law's twist is the navigator's own command, straight at G.
    let own = twin.step(Pose2::new(0.0, 0.0, 0.0), &free).command;
    match GoalLaw::step(&mut nav, &at(0.0), &free) {
        Step::Command { twist, feedback } => {
            assert_eq!((twist.vx, twist.vy, twist.wz), (own.vx, own.vy, own.omega));
            assert!(twist.vx > 0.0 && twist.vy.abs() < 1e-9 && twist.wz.abs() < 1e-9);
            assert_eq!(feedback.mode, Mode::Rotate);
            assert_relative_eq!(feedback.goal_distance, 5.0, epsilon = 1e-12);
        }
        other => panic!("{other:?}"),
    }
    // A non-finite pose is refused; the goal goes on.
    let nan = StepInput::new(0.0, 0.05, Pose2::new(f64::NAN, 0.0, 0.0));
    assert!(matches!(GoalLaw::step(&mut nav, &nan, &free), Step::Refused(_)));
    // Within the 0.1 m tolerance of (5, 0): the end, succeeded.
    match GoalLaw::step(&mut nav, &at(4.95), &free) {
        Step::End(end) => {
            assert!(end.outcome.is_success(), "{:?}", end.outcome);
            assert_eq!(end.report.mode, Mode::Reached);
        }
        other => panic!("{other:?}"),
    }
}
