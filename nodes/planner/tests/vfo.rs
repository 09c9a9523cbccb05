//! The VFO waypoint follower (SPEC §5): the potential and the field's derivative against
//! finite differences, convergence, the sides σ = ±1 pass on, Algorithm 2 on the paper's
//! layouts (Fig. 2, Fig. 4/5), Algorithm 3, the cycle check, the merge, the caps, the online
//! follower and obstacles from a scan. Expected numbers are worked out by hand in the comments
//! or by a second method in the test itself.

use std::f64::consts::{FRAC_PI_2, PI};

use approx::assert_relative_eq;
use mobil_geom::{wrap, Pose2};
use mobil_planner::vfo::{
    convergence_field, field_rate, find_sigmas, integrate_unicycle, path_time_limit, potential, potential_derivative,
    simulate_uninterrupted, Obstacle, OptimiseConfig, OptimiseWarning, PathFate, PathIndices, QualityWeights, RobotEnd,
    Segment, Sigma, VfoController, VfoEnd, VfoEvent, VfoFollower, VfoGains, VfoOutput, VfoWaypoint, MAX_SETTLE_S,
    REST_INTERVALS, REST_SPEED,
};
use mobil_planner::PlannerError;
use nalgebra::{Point2, Vector2};

fn ob(x: f64, y: f64, r: f64, big_r: f64) -> Obstacle {
    Obstacle::new(Point2::new(x, y), r, big_r).expect("valid obstacle")
}

fn wp(x: f64, y: f64, heading: f64) -> VfoWaypoint {
    VfoWaypoint::new(x, y, heading, 0.5).expect("valid waypoint")
}

fn controller() -> VfoController {
    VfoController::new(VfoGains::default()).expect("valid gains")
}

/// Drives a unicycle with the follower at `dt` (s) per tick. The test integrates on its own,
/// a second method: ten Euler sub-steps per tick of the held command. Returns the poses and
/// every event, and how it ended (None: `max_t` ran out).
fn drive(
    follower: &mut VfoFollower,
    start: Pose2,
    dt: f64,
    max_t: f64,
    mut on_tick: impl FnMut(f64, &mut VfoFollower),
) -> (Vec<Pose2>, Vec<VfoEvent>, Option<VfoEnd>) {
    let mut pose = start;
    let mut poses = vec![pose];
    let mut events = Vec::new();
    let mut t = 0.0;
    while t < max_t {
        on_tick(t, follower);
        let out = follower.update(&pose, t).expect("valid tick");
        events.extend(out.events.iter().cloned());
        if out.end.is_some() {
            return (poses, events, out.end);
        }
        for _ in 0..10 {
            let h = dt / 10.0;
            pose = Pose2::new(
                pose.x + out.v * pose.yaw.cos() * h,
                pose.y + out.v * pose.yaw.sin() * h,
                pose.yaw + out.omega * h,
            );
        }
        poses.push(pose);
        t += dt;
    }
    (poses, events, None)
}

fn clearance(poses: &[Pose2], o: &Obstacle) -> f64 {
    poses
        .iter()
        .map(|p| o.distance(&p.position()))
        .fold(f64::INFINITY, f64::min)
}

/// Ψ_z of every candidate worked out again here from their χ's (eq. 20–22), a second method.
fn scores_by_hand(indices: &[PathIndices], k: &QualityWeights) -> Vec<f64> {
    let max = |f: fn(&PathIndices) -> f64| indices.iter().map(f).fold(0.0, f64::max);
    let (md, mb, me, ms) = (
        max(|x| x.length),
        max(|x| x.danger),
        max(|x| x.control),
        max(|x| x.smoothness),
    );
    let psi = |x: f64, m: f64| if m == 0.0 { 0.0 } else { 1.0 - x / m };
    indices
        .iter()
        .map(|x| {
            k.length * psi(x.length, md)
                + k.danger * psi(x.danger, mb)
                + k.control * psi(x.control, me)
                + k.smoothness * psi(x.smoothness, ms)
        })
        .collect()
}

fn polyline_length(points: &[Point2<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

#[test]
fn potential_and_its_derivative_match_hand_values_and_finite_differences() {
    // r = 0.5, R = 1, d = 0.75: (0.5625 − 1)/(0.5625 − 0.25) = −1.4, V = 1.96;
    // V' = 4·0.75·0.75·(−0.4375)/0.3125³ = −0.984375/0.030517578125 = −32.256.
    assert_relative_eq!(potential(0.75, 0.5, 1.0), 1.96, epsilon = 1e-12);
    assert_relative_eq!(potential_derivative(0.75, 0.5, 1.0), -32.256, epsilon = 1e-9);
    assert_eq!(potential(1.0, 0.5, 1.0), 0.0);
    assert_eq!(potential(1.5, 0.5, 1.0), 0.0);
    assert_eq!(potential(0.5, 0.5, 1.0), f64::INFINITY);
    assert_eq!(potential_derivative(1.2, 0.5, 1.0), 0.0);
    // Central differences over the zone (away from r, where V' blows up).
    for i in 1..100 {
        let d = 0.55 + 0.45 * i as f64 / 100.0;
        let h = 1e-6;
        let fd = (potential(d + h, 0.5, 1.0) - potential(d - h, 0.5, 1.0)) / (2.0 * h);
        let an = potential_derivative(d, 0.5, 1.0);
        assert!(
            (fd - an).abs() <= 1e-5 * (1.0 + an.abs()),
            "d {d}: fd {fd} analytic {an}"
        );
    }
}

#[test]
fn the_fields_derivative_matches_finite_differences() {
    // Ḣ* = (∂H*/∂q*)·q̇* against (H*(q + εq̇) − H*(q − εq̇))/2ε at points inside one or two
    // zones, σ of either sign, every direction of motion.
    let obstacles = [ob(2.0, 0.3, 0.4, 1.2), ob(2.6, -0.6, 0.3, 1.0)];
    let w = VfoWaypoint::new(4.0, 0.5, 0.7, 0.6).expect("valid");
    for sigmas in [
        [Sigma::Right, Sigma::Left],
        [Sigma::Left, Sigma::Left],
        [Sigma::Right, Sigma::Right],
    ] {
        for (x, y) in [(1.3, 0.0), (2.0, -0.5), (1.6, 1.0), (3.0, 0.2), (0.0, 0.0)] {
            let q = Point2::new(x, y);
            for a in 0..8 {
                let vel = 0.3 * Vector2::new((a as f64 * 0.8).cos(), (a as f64 * 0.8).sin());
                let f = convergence_field(&q, &w, 1.3, &obstacles, &sigmas);
                assert!(f.collision.is_none());
                let an = field_rate(&f, &q, &vel, &w, 1.3, &obstacles, &sigmas);
                let e = 1e-7;
                let plus = convergence_field(&(q + e * vel), &w, 1.3, &obstacles, &sigmas).big_h;
                let minus = convergence_field(&(q - e * vel), &w, 1.3, &obstacles, &sigmas).big_h;
                let fd = (plus - minus) / (2.0 * e);
                assert!(
                    (fd - an).norm() <= 1e-5 * (1.0 + an.norm()),
                    "at ({x}, {y}) σ {sigmas:?}: fd {fd:?} analytic {an:?}"
                );
            }
        }
    }
}

#[test]
fn with_no_obstacles_the_robot_converges_to_one_point() {
    // One waypoint behind and to the left, facing north: ‖q_N − q‖ < ϵ = 0.05 (heading in rad,
    // position in m), measured here from the test's own integration.
    let goal = wp(-1.0, 2.0, FRAC_PI_2);
    let mut f =
        VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), vec![goal], Vec::new()).expect("valid");
    let (poses, events, end) = drive(&mut f, Pose2::new(0.0, 0.0, 0.3), 0.01, 120.0, |_, _| {});
    assert_eq!(end, Some(VfoEnd::Done));
    let last = poses.last().expect("poses");
    let error = (wrap(FRAC_PI_2 - last.yaw).powi(2) + (last.x + 1.0).powi(2) + (last.y - 2.0).powi(2)).sqrt();
    assert!(error < 0.05, "final error {error}");
    // No zone on the way: one optimisation, Ψ_z = 0 (|D| = 1).
    let optimised: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            VfoEvent::Optimised { score, .. } => Some(*score),
            _ => None,
        })
        .collect();
    assert_eq!(optimised, vec![Some(0.0)]);
    // Once done, the command stays zero.
    let out = f.update(last, 1000.0).expect("valid");
    assert_eq!((out.v, out.omega, out.end), (0.0, 0.0, Some(VfoEnd::Done)));
}

#[test]
fn intermediate_waypoints_switch_within_their_epsilon() {
    // Three waypoints, no obstacles: each intermediate one is passed within ϵ_i = 0.05 m
    // (Algorithm 1), the last one reached within ϵ.
    let route = vec![wp(2.0, 0.0, 0.0), wp(3.0, 2.0, FRAC_PI_2), wp(1.0, 3.0, PI)];
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        route.clone(),
        Vec::new(),
    )
    .expect("valid");
    let (poses, events, end) = drive(&mut f, Pose2::identity(), 0.01, 200.0, |_, _| {});
    assert_eq!(end, Some(VfoEnd::Done));
    let reached: Vec<usize> = events
        .iter()
        .filter_map(|e| match e {
            VfoEvent::Reached { index, vortex: false } => Some(*index),
            _ => None,
        })
        .collect();
    assert_eq!(reached, vec![0, 1, 2]);
    for w in &route[..2] {
        let closest = poses
            .iter()
            .map(|p| (p.position() - w.position).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(closest < 0.05 + 0.003, "closest {closest} to {:?}", w.position);
    }
}

#[test]
fn sigma_plus_one_passes_on_the_right_and_minus_one_on_the_left() {
    // Heading +x toward (4, 0) with an obstacle on the line at (2, 0): the robot's right is
    // −y. σ = +1 must pass below the obstacle (y < −r where x = 2), σ = −1 above.
    let obstacles = [ob(2.0, 0.0, 0.5, 1.0)];
    let segment = Segment {
        waypoint: wp(4.0, 0.0, 0.0),
        last: true,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig::default();
    for (sigma, side) in [(Sigma::Right, -1.0), (Sigma::Left, 1.0)] {
        let (_, path, end) =
            simulate_uninterrupted(&Pose2::identity(), &controller(), &segment, &[sigma], &config).expect("valid");
        assert_eq!(end, RobotEnd::Reached { vortex: false }, "σ {sigma:?}");
        let abeam = path
            .windows(2)
            .find(|w| w[0].x <= 2.0 && w[1].x > 2.0)
            .expect("passes x = 2");
        assert!(side * abeam[0].y > 0.5, "σ {sigma:?}: at x = 2, y = {}", abeam[0].y);
        let closest = path
            .iter()
            .map(|p| obstacles[0].distance(p))
            .fold(f64::INFINITY, f64::min);
        assert!(closest > 0.5, "σ {sigma:?} came within {closest}");
    }
}

/// A layout like the paper's Fig. 2: p1 just left of the straight way, p2 beyond it on the
/// left, p3 far to the right, out of reach.
fn fig2() -> [Obstacle; 3] {
    [ob(2.0, 0.15, 0.4, 0.9), ob(2.6, 1.3, 0.4, 0.9), ob(4.0, -2.5, 0.4, 0.9)]
}

#[test]
fn algorithm_2_on_the_papers_fig_2_explores_three_paths_and_drops_the_collision() {
    let obstacles = fig2();
    let segment = Segment {
        waypoint: wp(5.0, 0.0, 0.0),
        last: false,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig::default();
    let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    use Sigma::{Left, Right, Undecided};
    // W1 to p1's zone; W2 (σ1 = +1) reaches; W3 (σ1 = −1) to p2's zone; W4 (σ2 = +1) reaches;
    // W5 (σ2 = −1) collides with p2. σ3 is never decided.
    assert_eq!(r.robots.len(), 5);
    assert_eq!(r.paths.len(), 3);
    let fates: Vec<(Vec<Sigma>, &PathFate)> = r.paths.iter().map(|p| (p.sigmas.clone(), &p.fate)).collect();
    assert_eq!(
        fates,
        vec![
            (
                vec![Right, Undecided, Undecided],
                &PathFate::Candidate { vortex: false }
            ),
            (vec![Left, Right, Undecided], &PathFate::Candidate { vortex: false }),
            (vec![Left, Left, Undecided], &PathFate::Collided { obstacle: 1 }),
        ]
    );
    assert_eq!(r.robots[0].end, RobotEnd::Entry { obstacle: 0 });
    assert_eq!(r.robots[2].end, RobotEnd::Entry { obstacle: 1 });
    assert_eq!(r.paths[1].robots, vec![0, 2, 3]);
    // The better of the two by Ψ_z worked out again from the χ's.
    let indices = [r.paths[0].indices, r.paths[1].indices];
    let by_hand = scores_by_hand(&indices, &config.weights);
    for (p, s) in r.paths.iter().zip(&by_hand) {
        assert_relative_eq!(p.score.expect("candidate"), s, epsilon = 1e-12);
    }
    let best = if by_hand[0] > by_hand[1] { 0 } else { 1 };
    assert_eq!(r.best, Some(best));
    assert_eq!(r.sigmas, r.paths[best].sigmas);
    // The right way round p1 is the paper's optimum too: shorter and further from p2.
    assert_eq!(best, 0);
    // χ_D against the length of the drawn path (points every 5 cm on curves of radius ≥ 0.1 m:
    // chords shorter than the arcs by < 0.2 %).
    for p in &r.paths[..2] {
        let drawn = polyline_length(&r.path_points(p));
        assert_relative_eq!(p.indices.length, drawn, max_relative = 0.003);
    }
    // The right way stays right of p1 (below y = 0.15 − 0.4), the left way left of it.
    let ys = |i: usize| r.path_points(&r.paths[i]).iter().map(|p| p.y).collect::<Vec<f64>>();
    assert!(ys(0).iter().all(|&y| y <= 1e-9) && ys(0).iter().any(|&y| y < -0.25));
    assert!(ys(1).iter().all(|&y| y >= -1e-9) && ys(1).iter().any(|&y| y > 0.55));
}

#[test]
fn merged_indices_equal_one_uninterrupted_run() {
    // Each candidate of Fig. 2 driven again with its Σ fixed and no stops: the same χ's (the
    // stops do not change the integration; merge adds lengths and costs, takes maxima).
    let obstacles = fig2();
    let segment = Segment {
        waypoint: wp(5.0, 0.0, 0.0),
        last: false,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig::default();
    let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    let mut checked = 0;
    for p in r.paths.iter().filter(|p| p.score.is_some()) {
        let (x, path, end) =
            simulate_uninterrupted(&Pose2::identity(), &controller(), &segment, &p.sigmas, &config).expect("valid");
        assert_eq!(end, RobotEnd::Reached { vortex: false });
        assert_relative_eq!(x.length, p.indices.length, max_relative = 1e-12);
        assert_relative_eq!(x.control, p.indices.control, max_relative = 1e-12);
        assert_eq!(x.danger, p.indices.danger);
        assert_eq!(x.smoothness, p.indices.smoothness);
        assert_eq!(path.last(), r.path_points(p).last());
        checked += 1;
    }
    assert_eq!(checked, 2);
}

/// Two obstacles with overlapping zones; the gap between them lies a little right of the
/// straight way (the paper's Fig. 4/5 layout, our coordinates).
fn fig45() -> [Obstacle; 2] {
    [ob(2.5, 0.3, 0.3, 1.6), ob(2.5, -1.1, 0.3, 1.6)]
}

fn choose_with(weights: QualityWeights) -> (Vec<Sigma>, Vec<Point2<f64>>) {
    let obstacles = fig45();
    let segment = Segment {
        waypoint: wp(5.0, 0.0, 0.0),
        last: false,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig {
        weights,
        ..OptimiseConfig::default()
    };
    let r = find_sigmas(&Pose2::new(0.0, 0.05, 0.0), &controller(), &segment, &config).expect("valid");
    // The choice is the largest Ψ_z worked out again from the χ's.
    let cands: Vec<usize> = (0..r.paths.len()).filter(|&i| r.paths[i].score.is_some()).collect();
    let by_hand = scores_by_hand(&cands.iter().map(|&i| r.paths[i].indices).collect::<Vec<_>>(), &weights);
    let top = by_hand.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let best = cands[by_hand.iter().position(|&s| s == top).expect("a best")];
    assert_eq!(r.best, Some(best));
    (r.sigmas.clone(), r.best_path())
}

#[test]
fn weights_choose_the_short_way_between_or_the_safer_way_round() {
    // Fig. 4: {K_B = 2, K_D = 1, K_S = 1} (K_E = 0, SPEC Decision): between the two obstacles
    // (p1 on the robot's left: σ1 = +1; p2 on its right: σ2 = −1).
    let fig4 = QualityWeights {
        length: 1.0,
        danger: 2.0,
        control: 0.0,
        smoothness: 1.0,
    };
    let (sigmas, path) = choose_with(fig4);
    assert_eq!(sigmas, vec![Sigma::Right, Sigma::Left]);
    let abeam = path.iter().find(|p| p.x >= 2.5).expect("passes x = 2.5");
    assert!(
        abeam.y < 0.3 - 0.3 && abeam.y > -1.1 + 0.3,
        "between: y {} at x = 2.5",
        abeam.y
    );
    let short = polyline_length(&path);
    // Fig. 5: {K_B = 2, K_D = 0, K_S = 1.5}: round p1 on its left (north), longer and safer.
    let fig5 = QualityWeights {
        length: 0.0,
        danger: 2.0,
        control: 0.0,
        smoothness: 1.5,
    };
    let (sigmas, path) = choose_with(fig5);
    assert_eq!(sigmas[0], Sigma::Left);
    let abeam = path.iter().find(|p| p.x >= 2.5).expect("passes x = 2.5");
    assert!(abeam.y > 0.3 + 0.3, "round the north side: y {} at x = 2.5", abeam.y);
    assert!(polyline_length(&path) > short + 0.5);
}

#[test]
fn a_cyclic_decision_path_is_cut_by_the_cycle_check() {
    // The last waypoint sits just outside p2's forbidden zone, behind p1: the virtual robots
    // that go round p2 on its left orbit the waypoint, leaving and re-entering p1's zone with
    // the same Σ. The second such entry repeats an edge: the path is dropped as cyclic long
    // before the path's time limit (without the check it would run into it).
    let obstacles = [ob(3.18, -1.49, 0.29, 1.03), ob(3.52, -0.78, 0.26, 1.06)];
    let segment = Segment {
        waypoint: wp(3.78, -0.83, 0.0),
        last: true,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig::default();
    let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    // 3 × 3.88 m / 0.3 m/s + 20 s = 58.8 s.
    let limit = path_time_limit(&Pose2::identity(), &segment, &controller(), &config);
    assert_relative_eq!(limit, 3.0 * (3.78f64.hypot(0.83)) / 0.3 + 20.0, epsilon = 1e-9);
    let cyclic: Vec<_> = r
        .paths
        .iter()
        .filter(|p| matches!(p.fate, PathFate::Cyclic { .. }))
        .collect();
    assert_eq!(cyclic.len(), 2, "{:#?}", r.paths);
    for p in &cyclic {
        let PathFate::Cyclic { edge } = &p.fate else {
            unreachable!()
        };
        // Re-entering p1's zone from p1's own stop, with Σ already complete.
        assert_eq!((edge.from, edge.to), (Some(0), 0));
        assert!(edge.sigmas.iter().all(|s| *s != Sigma::Undecided));
        assert!(p.time < 0.5 * limit, "cut at {} s of {limit}", p.time);
    }
    assert!(!r.paths.iter().any(|p| p.fate == PathFate::TimeCap));
    assert_eq!(r.best, None);
    assert!(r.warnings.contains(&OptimiseWarning::NoSafeSigma));
}

#[test]
fn caps_return_the_best_so_far_with_a_warning() {
    // Fig. 2 with at most two virtual robots: W1, then the top of the stack, σ1 = +1, which
    // reaches the waypoint; σ1 = −1 is left pending.
    let obstacles = fig2();
    let segment = Segment {
        waypoint: wp(5.0, 0.0, 0.0),
        last: false,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig {
        max_virtual_robots: 2,
        ..OptimiseConfig::default()
    };
    let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    assert_eq!(r.robots.len(), 2);
    assert_eq!(
        r.warnings,
        vec![OptimiseWarning::VirtualRobotCap { limit: 2, pending: 1 }]
    );
    assert_eq!(r.sigmas, vec![Sigma::Right, Sigma::Undecided, Sigma::Undecided]);
    // A path time cap drops the path with a warning.
    let config = OptimiseConfig {
        max_path_time_s: 5.0,
        ..OptimiseConfig::default()
    };
    let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    assert!(r
        .paths
        .iter()
        .all(|p| p.fate == PathFate::TimeCap || matches!(p.fate, PathFate::Collided { .. })));
    assert!(r.warnings.contains(&OptimiseWarning::PathTimeCap { path: 0 }));
    assert!(r.warnings.contains(&OptimiseWarning::NoSafeSigma));
}

#[test]
fn the_result_does_not_depend_on_the_number_of_threads() {
    // Twelve obstacles scattered over the way: the whole result, every virtual robot and every
    // path, is the same on one thread and on two, three or four — also when a cap cuts the
    // search short, while helper threads are working ahead of it.
    let mut seed: u64 = 7;
    let mut rnd = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let obstacles: Vec<Obstacle> = (0..12)
        .map(|_| {
            let r = 0.2 + 0.15 * rnd();
            ob(1.0 + 6.0 * rnd(), -1.5 + 3.0 * rnd(), r, r + 0.5)
        })
        .filter(|o| o.distance(&Point2::origin()) > o.influence_radius())
        .collect();
    let segment = Segment {
        waypoint: wp(8.0, 0.0, 0.0),
        last: true,
        obstacles: &obstacles,
    };
    let run =
        |config: OptimiseConfig| find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    let full = OptimiseConfig::default();
    let one = run(OptimiseConfig { threads: 1, ..full });
    // Helpers start at the eighth virtual robot.
    assert!(one.robots.len() > 30, "too few virtual robots: {}", one.robots.len());
    for threads in [2, 3, 4] {
        assert_eq!(one, run(OptimiseConfig { threads, ..full }), "{threads} threads");
    }
    // Caps in the middle of the search: the same cut on every thread count.
    let by_robots = OptimiseConfig {
        max_virtual_robots: one.robots.len() / 2,
        ..full
    };
    let by_time = OptimiseConfig {
        max_total_time_s: one.simulated_time / 3.0,
        ..full
    };
    for capped in [by_robots, by_time] {
        let serial = run(OptimiseConfig { threads: 1, ..capped });
        assert!(serial.robots.len() < one.robots.len());
        assert!(serial.warnings.iter().any(|w| matches!(
            w,
            OptimiseWarning::VirtualRobotCap { pending, .. } | OptimiseWarning::TotalTimeCap { pending, .. } if *pending > 0
        )));
        for threads in [2, 3] {
            assert_eq!(
                serial,
                run(OptimiseConfig { threads, ..capped }),
                "{threads} threads, capped"
            );
        }
    }
}

#[test]
fn algorithm_3_escapes_a_vortex_and_the_robot_still_reaches_the_end() {
    // Waypoint 1 lies 0.5 m from p1's centre (r 0.4, R 1): at d = 0.5 V = (0.75/0.09)² ≈ 69,
    // far above √99 ≈ 9.95, where ‖h*‖² < 0.01‖H*‖². Close to it the field whirls round p1;
    // Algorithm 3 switches early (ϵ_1 = 2‖e*_1‖) and the robot goes on through the clutter
    // to the last waypoint, reached within ϵ = 0.05.
    let obstacles = vec![
        ob(3.0, 0.5, 0.4, 1.0),
        ob(1.5, -0.9, 0.3, 0.8),
        ob(4.4, -0.6, 0.3, 0.8),
        ob(4.0, 1.9, 0.35, 0.9),
        ob(5.6, 0.9, 0.3, 0.8),
    ];
    let route = vec![wp(3.0, 0.0, 0.0), wp(6.5, 0.0, 0.0)];
    let mut f =
        VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), route, obstacles.clone()).expect("valid");
    let (poses, events, end) = drive(&mut f, Pose2::identity(), 0.01, 200.0, |_, _| {});
    assert!(
        events.contains(&VfoEvent::Reached { index: 0, vortex: true }),
        "{events:#?}"
    );
    assert_eq!(end, Some(VfoEnd::Done));
    let last = poses.last().expect("poses");
    let error = (wrap(-last.yaw).powi(2) + (last.x - 6.5).powi(2) + last.y.powi(2)).sqrt();
    assert!(error < 0.05, "final error {error}");
    for o in &obstacles {
        assert!(clearance(&poses, o) > o.forbidden_radius(), "{o:?}");
    }
}

#[test]
fn a_new_obstacle_reoptimises_the_segment_and_is_avoided() {
    // Straight to (5, 0); at t = 2 s an obstacle appears on the way at (3, 0).
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(5.0, 0.0, 0.0)],
        Vec::new(),
    )
    .expect("valid");
    let blocker = ob(3.0, 0.0, 0.5, 1.0);
    let (poses, events, end) = drive(&mut f, Pose2::identity(), 0.01, 120.0, |t, f| {
        if (t - 2.0).abs() < 0.005 {
            f.add_obstacle(blocker);
        }
    });
    assert_eq!(end, Some(VfoEnd::Done));
    let reasons: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            VfoEvent::Optimised { reason, .. } => Some(*reason),
            _ => None,
        })
        .collect();
    use mobil_planner::vfo::Reoptimised::{NewObstacle, SegmentStart};
    assert_eq!(reasons, vec![SegmentStart, NewObstacle]);
    assert!(clearance(&poses, &blocker) > 0.5);
    let last = f.last_optimisation().expect("optimised");
    assert_eq!(last.candidates(), 2);
    assert_ne!(f.sigmas()[0], Sigma::Undecided);
}

#[test]
fn bad_input_is_refused() {
    assert!(VfoWaypoint::new(1.0, 0.0, 0.0, 1.0).is_err());
    assert!(VfoWaypoint::new(f64::NAN, 0.0, 0.0, 0.5).is_err());
    assert!(Obstacle::new(Point2::new(0.0, 0.0), 0.5, 0.5).is_err());
    assert!(Obstacle::new(Point2::new(0.0, f64::INFINITY), 0.5, 1.0).is_err());
    assert!(VfoController::new(VfoGains {
        k_a: 0.0,
        ..VfoGains::default()
    })
    .is_err());
    assert!(matches!(
        VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), Vec::new(), Vec::new()),
        Err(PlannerError::EmptyRoute)
    ));
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(1.0, 0.0, 0.0)],
        Vec::new(),
    )
    .expect("valid");
    assert!(f.update(&Pose2::new(f64::NAN, 0.0, 0.0), 0.0).is_err());
    assert!(f.update(&Pose2::identity(), 1.0).is_ok());
    assert!(f.update(&Pose2::identity(), 0.5).is_err(), "time went backwards");
    // Inside a forbidden zone: zero command and the route ends.
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(3.0, 0.0, 0.0)],
        vec![ob(0.2, 0.0, 0.5, 1.0)],
    )
    .expect("valid");
    let out = f.update(&Pose2::identity(), 0.0).expect("valid");
    assert_eq!((out.v, out.omega), (0.0, 0.0));
    assert_eq!(out.end, Some(VfoEnd::Collision { obstacle: 0 }));
}

#[test]
fn entering_a_zone_the_optimisation_did_not_foresee_reoptimises() {
    // The straight way to (5, 0) meets no zone (p at (2.5, 2), R = 1), so its σ stays
    // undecided. Pushed sideways to (2.5, 1.2) — 0.8 m from p, inside R, outside r — the robot
    // is in a zone with no decision: the follower re-optimises from there and decides it.
    let obstacles = vec![ob(2.5, 2.0, 0.5, 1.0)];
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(5.0, 0.0, 0.0)],
        obstacles,
    )
    .expect("valid");
    let first = f.update(&Pose2::identity(), 0.0).expect("valid");
    assert_eq!(f.sigmas(), &[Sigma::Undecided]);
    assert_eq!(first.events.len(), 1);
    // Inside the zone the robot is first brought to rest: zero, settling, no optimisation.
    let at = Pose2::new(2.5, 1.2, 0.0);
    let held = f.update(&at, 0.01).expect("valid");
    assert!(held.events.is_empty() && f.is_settling() && (held.v, held.omega) == (0.0, 0.0));
    // Standing still: REST_INTERVALS intervals later it optimises from there.
    let mut pushed = held;
    for k in 1..=REST_INTERVALS {
        pushed = f.update(&at, 0.01 + f64::from(k) * 0.02).expect("valid");
        assert_eq!(pushed.events.is_empty(), k < REST_INTERVALS, "tick {k}");
    }
    assert!(
        pushed.events.iter().any(|e| matches!(
            e,
            VfoEvent::Optimised {
                reason: mobil_planner::vfo::Reoptimised::UndecidedZone,
                ..
            }
        )),
        "{:?}",
        pushed.events
    );
    assert_ne!(f.sigmas()[0], Sigma::Undecided);
    assert!(pushed.end.is_none() && pushed.v != 0.0);
}

#[test]
fn a_segment_begun_inside_a_zone_is_optimised_from_where_the_robot_comes_to_rest() {
    // The layout of the vortex test: Algorithm 3 passes waypoint 0 early, 0.5 m from p1's centre,
    // deep in its zone. The robot here answers its commands with a lag (first order, τ = 0.2 s,
    // as drives do), so at the switch it still moves at about U_2 toward p1. The follower then
    // commands zero and optimises the next segment only once the robot stands (it moved less
    // than REST_SPEED·Δt in a tick), from the pose it stands at: the first virtual robot starts
    // there. The route still ends within ϵ, outside every r.
    let obstacles = vec![
        ob(3.0, 0.5, 0.4, 1.0),
        ob(1.5, -0.9, 0.3, 0.8),
        ob(4.4, -0.6, 0.3, 0.8),
        ob(4.0, 1.9, 0.35, 0.9),
        ob(5.6, 0.9, 0.3, 0.8),
    ];
    let route = vec![wp(3.0, 0.0, 0.0), wp(6.5, 0.0, 0.0)];
    let mut f =
        VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), route, obstacles.clone()).expect("valid");
    let (dt, tau) = (0.01, 0.2);
    let (mut pose, mut v, mut omega) = (Pose2::identity(), 0.0, 0.0);
    let mut poses = vec![pose];
    let mut switch: Option<(f64, f64)> = None; // time and speed at the switch
    let mut optimised_at: Option<(f64, Pose2, f64)> = None; // time, pose and speed
    let mut end = None;
    let mut t = 0.0;
    while t < 200.0 {
        let out = f.update(&pose, t).expect("valid tick");
        for e in &out.events {
            match e {
                VfoEvent::Reached { index: 0, vortex } => {
                    assert!(*vortex);
                    switch = Some((t, v));
                    // The switch's tick: zero, no optimisation yet.
                    assert_eq!((out.v, out.omega), (0.0, 0.0));
                    assert!(f.is_settling());
                }
                VfoEvent::Optimised { index: 1, .. } if optimised_at.is_none() => {
                    let start = f
                        .last_optimisation()
                        .and_then(|o| o.robots.first())
                        .and_then(|r| r.path.first().copied());
                    assert_eq!(
                        start,
                        Some(pose.position()),
                        "the virtual robots start where the robot stands"
                    );
                    optimised_at = Some((t, pose, v));
                }
                _ => {}
            }
        }
        if out.end.is_some() {
            end = out.end;
            break;
        }
        let a = dt / (tau + dt);
        v += a * (out.v - v);
        omega += a * (out.omega - omega);
        pose = integrate_unicycle(&pose, v, omega, dt);
        poses.push(pose);
        t += dt;
    }
    let (t_switch, v_switch) = switch.expect("Algorithm 3 passed waypoint 0");
    assert!(v_switch > 0.2, "moving at the switch: {v_switch}");
    let (t_opt, _, v_opt) = optimised_at.expect("segment 1 optimised");
    // Coming to rest takes a few τ: from 0.3 m/s to below 0.01 m/s is ln(30)·τ ≈ 0.68 s.
    assert!(
        t_opt - t_switch > 0.4 && t_opt - t_switch < MAX_SETTLE_S,
        "{t_switch} → {t_opt}"
    );
    assert!(v_opt.abs() < REST_SPEED, "{v_opt}");
    assert_eq!(end, Some(VfoEnd::Done));
    for o in &obstacles {
        assert!(clearance(&poses, o) > o.forbidden_radius(), "{o:?}");
    }
}

#[test]
fn decisions_follow_their_obstacles_when_the_map_drops_one() {
    // A far obstacle (index 0) and one on the way to (4, 0) (index 1): the optimisation decides
    // σ_1 only. The map then forgets the far one and adds one elsewhere: the one on the way is
    // now index 0 and keeps its σ; the new one is undecided; without new obstacles reported, no
    // re-optimisation.
    let far = ob(10.0, 10.0, 0.3, 0.8);
    let on_way = ob(2.0, 0.0, 0.5, 1.0);
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(4.0, 0.0, 0.0)],
        vec![far, on_way],
    )
    .expect("valid");
    f.update(&Pose2::identity(), 0.0).expect("valid");
    let decided = f.sigmas()[1];
    assert_eq!(f.sigmas()[0], Sigma::Undecided);
    assert_ne!(decided, Sigma::Undecided);
    let elsewhere = ob(-5.0, 5.0, 0.3, 0.8);
    f.set_obstacles_mapped(vec![on_way, elsewhere], &[Some(1), None], false);
    assert_eq!(f.sigmas(), &[decided, Sigma::Undecided]);
    let out = f.update(&Pose2::identity(), 0.01).expect("valid");
    assert!(out.events.is_empty(), "{:?}", out.events);
    assert_eq!(f.obstacles()[0], on_way);
}

/// A dense layout for the interrupt tests: 24 obstacles in a staggered grid across the way from
/// (0, 0) to (12, 0), each zone overlapping its neighbours', so Algorithm 2 simulates hundreds
/// of virtual robots.
fn dense() -> Vec<Obstacle> {
    (0..8)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| {
            let x = 1.5 + 1.3 * f64::from(i);
            let y = -1.3 + 1.3 * f64::from(j) + if i % 2 == 0 { 0.0 } else { 0.65 };
            ob(x, y, 0.3, 0.8)
        })
        .collect()
}

#[test]
fn a_cancelled_optimisation_returns_promptly_and_a_spent_budget_keeps_the_best_so_far() {
    use mobil_planner::vfo::{find_sigmas_until, Interrupt, INTERRUPT_CHECK_STEPS};
    use std::sync::atomic::{AtomicUsize, Ordering};
    let obstacles = dense();
    let segment = Segment {
        waypoint: wp(12.0, 0.0, 0.0),
        last: true,
        obstacles: &obstacles,
    };
    let config = OptimiseConfig {
        threads: 1,
        ..OptimiseConfig::default()
    };
    let full = find_sigmas(&Pose2::identity(), &controller(), &segment, &config).expect("valid");
    assert!(full.robots.len() > 50, "{} virtual robots", full.robots.len());
    let steps_full = (full.simulated_time / config.time_step).round() as usize;
    // Cancel after 20 questions: at most 20 checks of 32 steps (plus one batch start each) are
    // simulated, a small part of the full run's steps.
    let asked = AtomicUsize::new(0);
    let cancel = || (asked.fetch_add(1, Ordering::Relaxed) >= 20).then_some(Interrupt::Cancel);
    let r = find_sigmas_until(&Pose2::identity(), &controller(), &segment, &config, &cancel);
    assert_eq!(r, Err(mobil_planner::PlannerError::Stopped));
    let questions = asked.load(Ordering::Relaxed);
    assert!(questions <= 22, "{questions} questions after the cancel");
    assert!(
        21 * INTERRUPT_CHECK_STEPS < steps_full / 10,
        "{steps_full} steps in the full run"
    );
    // How many questions the full run asks; a budget spent half-way: the best so far (the
    // first candidates end early), fewer virtual robots, a warning.
    let asked = AtomicUsize::new(0);
    let count = || {
        asked.fetch_add(1, Ordering::Relaxed);
        None
    };
    find_sigmas_until(&Pose2::identity(), &controller(), &segment, &config, &count).expect("valid");
    let half = asked.load(Ordering::Relaxed) / 2;
    let asked = AtomicUsize::new(0);
    let budget = || (asked.fetch_add(1, Ordering::Relaxed) >= half).then_some(Interrupt::Budget);
    let r = find_sigmas_until(&Pose2::identity(), &controller(), &segment, &config, &budget).expect("best so far");
    assert!(r.robots.len() < full.robots.len());
    assert!(
        r.best.is_some(),
        "a candidate found before the budget ran out is returned"
    );
    assert!(!r.warnings.contains(&OptimiseWarning::NoSafeSigma), "{:?}", r.warnings);
    assert!(
        r.warnings
            .iter()
            .any(|w| matches!(w, OptimiseWarning::WallTimeBudget { pending } if *pending > 0)),
        "{:?}",
        r.warnings
    );
    assert!(r.robots.iter().all(|v| v.end != RobotEnd::Interrupted));
    // Spent before the start: nothing simulated, no candidate, and nothing proven unsafe (no
    // NoSafeSigma).
    let r = find_sigmas_until(&Pose2::identity(), &controller(), &segment, &config, &|| {
        Some(Interrupt::Budget)
    })
    .expect("valid");
    assert_eq!(r.robots.len(), 0);
    assert!(r.best.is_none());
    assert_eq!(r.warnings, vec![OptimiseWarning::WallTimeBudget { pending: 1 }]);
    // The follower starved by the budget holds zero and retries: not NoSafePath; the third
    // starved optimisation in a row ends the route as BudgetExhausted.
    let spent = || Some(Interrupt::Budget);
    let mut f =
        VfoFollower::new(VfoGains::default(), config, vec![wp(12.0, 0.0, 0.0)], obstacles.clone()).expect("valid");
    for k in 0..3 {
        let out = f
            .update_until(&Pose2::identity(), f64::from(k) * 0.05, &spent)
            .expect("valid");
        assert_eq!((out.v, out.omega), (0.0, 0.0));
        assert!(matches!(
            out.events.as_slice(),
            [VfoEvent::Optimised { score: None, .. }]
        ));
        let expected = (k == 2).then_some(VfoEnd::BudgetExhausted { index: 0 });
        assert_eq!(out.end, expected, "tick {k}");
    }
    // Starved twice, then given time: the third optimisation runs in full and the robot drives.
    let mut f =
        VfoFollower::new(VfoGains::default(), config, vec![wp(12.0, 0.0, 0.0)], obstacles.clone()).expect("valid");
    for k in 0..2 {
        f.update_until(&Pose2::identity(), f64::from(k) * 0.05, &spent)
            .expect("valid");
    }
    let out = f.update(&Pose2::identity(), 0.1).expect("valid");
    assert!(out.end.is_none() && out.v > 0.0, "{out:?}");
    assert_eq!(f.last_optimisation().map(|o| o.robots.len()), Some(full.robots.len()));
    // The follower: a cancel leaves the segment due for optimisation at the next tick.
    let mut f =
        VfoFollower::new(VfoGains::default(), config, vec![wp(12.0, 0.0, 0.0)], obstacles.clone()).expect("valid");
    let r = f.update_until(&Pose2::identity(), 0.0, &|| Some(Interrupt::Cancel));
    assert_eq!(r, Err(mobil_planner::PlannerError::Stopped));
    assert!(f.last_optimisation().is_none());
    let out = f.update(&Pose2::identity(), 0.01).expect("valid");
    assert!(matches!(out.events.first(), Some(VfoEvent::Optimised { .. })));
    assert_eq!(f.last_optimisation().map(|o| o.robots.len()), Some(full.robots.len()));
}

#[test]
fn a_collision_ends_the_route_while_the_follower_holds() {
    // Waypoint 0 at the start pose is reached on the first tick, inside the zone of the obstacle
    // at (0, 0.8) (d = 0.8 < R = 1): the follower holds zero until rest. The robot still slides
    // toward it: at (0, 0.45) it is 0.35 m from the centre, outside r = 0.3, still held; at
    // (0, 0.55) it is 0.25 m away, inside r: COLLISION, though holding.
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(0.0, 0.0, 0.0), wp(3.0, 0.0, 0.0)],
        vec![ob(0.0, 0.8, 0.3, 1.0)],
    )
    .expect("valid");
    let out = f.update(&Pose2::identity(), 0.0).expect("valid");
    assert!(matches!(out.events.last(), Some(VfoEvent::Reached { index: 0, .. })));
    assert!(f.is_settling() && out.end.is_none());
    let out = f.update(&Pose2::new(0.0, 0.45, 0.0), 0.05).expect("valid");
    assert!(f.is_settling() && out.end.is_none());
    let out = f.update(&Pose2::new(0.0, 0.55, 0.0), 0.1).expect("valid");
    assert_eq!((out.v, out.omega), (0.0, 0.0));
    assert_eq!(out.end, Some(VfoEnd::Collision { obstacle: 0 }));
}

#[test]
fn a_republished_pose_is_no_rest_and_rest_needs_consecutive_still_intervals() {
    // As the zone test above: at (2.5, 1.2) inside the zone of (2.5, 2) with σ undecided, the
    // follower holds until rest, timed by the poses' stamps.
    let mut f = VfoFollower::new(
        VfoGains::default(),
        OptimiseConfig::default(),
        vec![wp(5.0, 0.0, 0.0)],
        vec![ob(2.5, 2.0, 0.5, 1.0)],
    )
    .expect("valid");
    f.update(&Pose2::identity(), 0.0).expect("valid");
    let optimised = |o: &VfoOutput| o.events.iter().any(|e| matches!(e, VfoEvent::Optimised { .. }));
    // Moving at 0.2 m/s along x, odometry stamped every 0.02 s.
    let moving = |k: u32| Pose2::new(2.5 + 0.004 * f64::from(k), 1.2, 0.0);
    let out = f.update_stamped(&moving(0), 0.02, 0.02, &|| None).expect("valid");
    assert!(f.is_settling() && !optimised(&out));
    // The same sample arrives again and again, later (arrival 0.04 … 0.12 s), stamp unchanged: no
    // interval, no rest, however long it took to arrive.
    for k in 0..5 {
        let out = f
            .update_stamped(&moving(0), 0.04 + f64::from(k) * 0.02, 0.02, &|| None)
            .expect("valid");
        assert!(f.is_settling() && !optimised(&out), "repeat {k}");
    }
    // Two still intervals (each under REST_SPEED), then a moving one: the run restarts.
    let out = f.update_stamped(&moving(0), 0.14, 0.04, &|| None).expect("valid");
    assert!(!optimised(&out));
    let out = f.update_stamped(&moving(0), 0.16, 0.06, &|| None).expect("valid");
    assert!(!optimised(&out));
    let out = f.update_stamped(&moving(1), 0.18, 0.08, &|| None).expect("valid");
    assert!(
        f.is_settling() && !optimised(&out),
        "0.004 m in 0.02 s is 0.2 m/s: moving"
    );
    // Three still intervals in a row: rest, the zone is optimised.
    for (k, stamp) in [0.10, 0.12].into_iter().enumerate() {
        let out = f
            .update_stamped(&moving(1), 0.2 + k as f64 * 0.02, stamp, &|| None)
            .expect("valid");
        assert!(!optimised(&out), "still interval {}", k + 1);
    }
    let out = f.update_stamped(&moving(1), 0.24, 0.14, &|| None).expect("valid");
    assert!(optimised(&out) && !f.is_settling());
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 24, ..Default::default() })]

    /// Eq. 23 of the VFO paper (source 002): the decision graph holds at most 2^Np paths. Each
    /// path decides every obstacle at most once, on entering its zone, so the paths are the
    /// leaves of a binary tree whose depth is the number of obstacles decided: at most
    /// 2^(obstacles decided on any path) ≤ 2^(obstacles). Random fields of 1–6 obstacles between
    /// the start and the waypoint.
    #[test]
    fn the_decision_graph_holds_at_most_two_to_the_obstacles_decided(
        field in proptest::collection::vec((1.0f64..5.0, -1.5f64..1.5, 0.15f64..0.4), 1..7)
    ) {
        let obstacles: Vec<Obstacle> = field.iter().map(|&(x, y, r)| ob(x, y, r, r + 0.5)).collect();
        let segment = Segment {
            waypoint: wp(6.0, 0.0, 0.0),
            last: true,
            obstacles: &obstacles,
        };
        let r = find_sigmas(&Pose2::identity(), &controller(), &segment, &OptimiseConfig::default())
            .expect("valid");
        let decided = (0..obstacles.len())
            .filter(|&k| r.paths.iter().any(|p| p.sigmas[k] != Sigma::Undecided))
            .count();
        proptest::prop_assert!(!r.paths.is_empty());
        proptest::prop_assert!(r.paths.len() <= 1 << decided, "{} paths, {} obstacles decided", r.paths.len(), decided);
        proptest::prop_assert!(r.candidates() <= r.paths.len());
        proptest::prop_assert!(decided <= obstacles.len());
    }
}
