//! The frame tree against hand-worked transforms and tf2's behaviour at the edges.

use approx::assert_relative_eq;
use mobil_tf::{At, FrameTree, GoalFrames, TfError};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::time::Duration;

const S: u64 = 1_000_000_000;

/// A planar transform: (x, y) and a yaw.
fn planar(x: f64, y: f64, yaw: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(x, y, 0.0),
        UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), yaw),
    )
}

fn tree() -> FrameTree {
    FrameTree::new(Duration::from_secs(10))
}

/// Between two samples, as tf2: the translation linearly, the rotation by slerp. odom → base at
/// 1 s (0, 0, 0) and 3 s (2, 0, π/2): at 2 s half of each, (1, 0, π/4); at 1.5 s a quarter.
#[test]
fn interpolates_between_samples() {
    let mut t = tree();
    t.insert("odom", "base_link", &planar(0.0, 0.0, 0.0), Some(S)).unwrap();
    t.insert("odom", "base_link", &planar(2.0, 0.0, FRAC_PI_2), Some(3 * S))
        .unwrap();
    let half = t.planar("odom", "base_link", At::Nanos(2 * S)).unwrap();
    assert_relative_eq!(half.x, 1.0, epsilon = 1e-12);
    assert_relative_eq!(half.y, 0.0, epsilon = 1e-12);
    assert_relative_eq!(half.yaw, FRAC_PI_4, epsilon = 1e-12);
    let quarter = t.planar("odom", "base_link", At::Nanos(3 * S / 2)).unwrap();
    assert_relative_eq!(quarter.x, 0.5, epsilon = 1e-12);
    assert_relative_eq!(quarter.yaw, FRAC_PI_4 / 2.0, epsilon = 1e-12);
    // At a sample, the sample; the latest is the newest.
    let latest = t.planar("odom", "base_link", At::Latest).unwrap();
    assert_relative_eq!(latest.x, 2.0, epsilon = 1e-12);
    assert_relative_eq!(latest.yaw, FRAC_PI_2, epsilon = 1e-12);
}

/// No extrapolation, either way: after the newest sample and before the oldest, refused.
#[test]
fn refuses_to_extrapolate() {
    let mut t = tree();
    t.insert("odom", "base_link", &planar(0.0, 0.0, 0.0), Some(S)).unwrap();
    t.insert("odom", "base_link", &planar(2.0, 0.0, 0.0), Some(3 * S))
        .unwrap();
    for at in [7 * S / 2, S / 2] {
        match t.lookup("odom", "base_link", At::Nanos(at)) {
            Err(TfError::Extrapolation { requested_s, .. }) => assert_relative_eq!(requested_s, at as f64 * 1e-9),
            other => panic!("{at}: {other:?}"),
        }
    }
}

/// Four frames, map → odom (dynamic) → base_link (dynamic) → laser (static), worked by hand:
/// odom in map (1, 2, π/2); base_link in odom (3, 0, 0), so in map R(π/2)·(3, 0) + (1, 2) =
/// (1, 5), yaw π/2; laser in base_link (0.2, 0, π), so in map (1, 5) + R(π/2)·(0.2, 0) =
/// (1, 5.2), yaw π/2 + π = −π/2. A point 1 m ahead of the laser is at (1, 4.2) in map; the
/// reverse lookup takes it back.
#[test]
fn chains_four_frames() {
    let mut t = tree();
    t.insert("map", "odom", &planar(1.0, 2.0, FRAC_PI_2), Some(10 * S))
        .unwrap();
    t.insert("odom", "base_link", &planar(3.0, 0.0, 0.0), Some(10 * S))
        .unwrap();
    t.insert("base_link", "laser", &planar(0.2, 0.0, PI), None).unwrap();
    let laser = t.planar("map", "laser", At::Nanos(10 * S)).unwrap();
    assert_relative_eq!(laser.x, 1.0, epsilon = 1e-12);
    assert_relative_eq!(laser.y, 5.2, epsilon = 1e-12);
    assert_relative_eq!(laser.yaw.abs(), FRAC_PI_2, epsilon = 1e-12);
    assert!(laser.yaw < 0.0, "{}", laser.yaw);
    let ahead = t.lookup("map", "laser", At::Latest).unwrap() * Point3::new(1.0, 0.0, 0.0);
    assert_relative_eq!(ahead, Point3::new(1.0, 4.2, 0.0), epsilon = 1e-12);
    let back = t.lookup("laser", "map", At::Latest).unwrap() * ahead;
    assert_relative_eq!(back, Point3::new(1.0, 0.0, 0.0), epsilon = 1e-12);
    // Leading slashes are stripped (tf2 strips them on insert and refuses them in a lookup).
    assert!(t.lookup("/map", "/laser", At::Latest).is_ok());
}

/// A static edge is valid at any instant; a dynamic one in the same chain bounds the chain: the
/// latest common instant is the dynamic edge's newest, and beyond it the chain extrapolates.
#[test]
fn static_and_dynamic_in_one_chain() {
    let mut t = tree();
    t.insert("base_link", "laser", &planar(0.2, 0.0, 0.0), None).unwrap();
    assert_eq!(t.latest_time("base_link", "laser"), Ok(None));
    assert!(t.lookup("base_link", "laser", At::Nanos(123 * S)).is_ok());
    t.insert("odom", "base_link", &planar(1.0, 0.0, 0.0), Some(4 * S))
        .unwrap();
    t.insert("odom", "base_link", &planar(2.0, 0.0, 0.0), Some(5 * S))
        .unwrap();
    assert_eq!(t.latest_time("odom", "laser"), Ok(Some(5 * S)));
    let at = t.planar("odom", "laser", At::Nanos(9 * S / 2)).unwrap();
    assert_relative_eq!(at.x, 1.7, epsilon = 1e-12);
    assert!(matches!(
        t.lookup("odom", "laser", At::Nanos(6 * S)),
        Err(TfError::Extrapolation { .. })
    ));
}

/// tf2's other failures: an unknown frame, two unconnected trees, a sample older than the
/// cache behind the newest (dropped), a frame given a second parent (refused), a non-finite
/// transform (refused).
#[test]
fn unknown_disconnected_cached_and_refused() {
    let mut t = tree();
    t.insert("odom", "base_link", &planar(0.0, 0.0, 0.0), Some(20 * S))
        .unwrap();
    t.insert("map2", "other", &planar(0.0, 0.0, 0.0), Some(20 * S)).unwrap();
    assert_eq!(
        t.lookup("odom", "nowhere", At::Latest),
        Err(TfError::UnknownFrame("nowhere".into()))
    );
    assert!(matches!(
        t.lookup("odom", "other", At::Latest),
        Err(TfError::Disconnected { .. })
    ));
    // 10 s of cache behind the newest sample (20 s): a sample at 5 s is dropped, so 5 s
    // cannot be looked up.
    let _ = t.insert("odom", "base_link", &planar(0.0, 0.0, 0.0), Some(5 * S));
    assert!(matches!(
        t.lookup("odom", "base_link", At::Nanos(5 * S)),
        Err(TfError::Extrapolation { .. })
    ));
    assert!(matches!(
        t.insert("map", "base_link", &planar(0.0, 0.0, 0.0), Some(21 * S)),
        Err(TfError::Rejected { .. })
    ));
    let bad = Isometry3::from_parts(Translation3::new(f64::NAN, 0.0, 0.0), UnitQuaternion::identity());
    assert!(matches!(
        t.insert("odom", "base_link", &bad, Some(21 * S)),
        Err(TfError::Rejected { .. })
    ));
    assert!(matches!(
        t.insert("/", "base_link", &planar(0.0, 0.0, 0.0), Some(21 * S)),
        Err(TfError::Rejected { .. })
    ));
}

/// ROS time going back (a restarted simulation) clears the dynamic history, so the new time's
/// samples are taken rather than dropped 10 s behind the old ones; a static edge stays.
#[test]
fn a_clock_jump_back_clears_the_dynamic_history() {
    let mut t = tree();
    t.insert("base_link", "laser", &planar(0.2, 0.0, 0.0), None).unwrap();
    t.observe_time(100 * S);
    t.insert("odom", "base_link", &planar(5.0, 0.0, 0.0), Some(100 * S))
        .unwrap();
    assert!(!t.observe_time(101 * S));
    assert!(!t.observe_time(0), "a simulated clock not started yet tells nothing");
    assert!(t.observe_time(S), "back to 1 s");
    // A sample of the old time still in flight, 99 s ahead of the new: refused, so it cannot
    // pin the history at 100 s.
    assert!(matches!(
        t.insert("odom", "base_link", &planar(5.0, 0.0, 0.0), Some(100 * S)),
        Err(TfError::Rejected { .. })
    ));
    t.insert("odom", "base_link", &planar(1.0, 0.0, 0.0), Some(S)).unwrap();
    assert_eq!(t.latest_time("odom", "laser"), Ok(Some(S)));
    let p = t.planar("odom", "laser", At::Latest).unwrap();
    assert_relative_eq!(p.x, 1.2, epsilon = 1e-12);
}

/// A robot's odometry pose in a goal's frame: odom in map (1, 2, π/2) at 10 s, the robot at
/// (3, 0, 0) in odom is at (1, 5, π/2) in map. Fresh within the tolerance (0.1 s) of now, a
/// transform dated ahead of now too; stale beyond it; a static one never; the odometry frame
/// itself needs no transform at all.
#[test]
fn a_pose_in_the_goal_frame_needs_a_fresh_transform() {
    let mut t = tree();
    t.insert("map", "odom", &planar(1.0, 2.0, FRAC_PI_2), Some(10 * S))
        .unwrap();
    let robot = mobil_geom::Pose2::new(3.0, 0.0, 0.0);
    let tol = Duration::from_millis(100);
    let p = t.pose_in("map", "odom", &robot, 10 * S + 50_000_000, tol).unwrap();
    assert_relative_eq!(p.x, 1.0, epsilon = 1e-12);
    assert_relative_eq!(p.y, 5.0, epsilon = 1e-12);
    assert_relative_eq!(p.yaw, FRAC_PI_2, epsilon = 1e-12);
    assert!(t.pose_in("map", "odom", &robot, 9 * S, tol).is_ok(), "dated ahead");
    // Dated more than the cache (10 s) ahead, 20 s: a clock that jumped back under it.
    let mut ahead = tree();
    ahead
        .insert("map", "odom", &planar(1.0, 2.0, 0.0), Some(30 * S))
        .unwrap();
    assert!(ahead.pose_in("map", "odom", &robot, 21 * S, tol).is_ok(), "9 s ahead");
    assert!(matches!(
        ahead.pose_in("map", "odom", &robot, 10 * S, tol),
        Err(TfError::Stale { .. })
    ));
    match t.pose_in("map", "odom", &robot, 10 * S + 200_000_000, tol) {
        Err(TfError::Stale { age_s, .. }) => assert_relative_eq!(age_s, 0.2, epsilon = 1e-9),
        other => panic!("{other:?}"),
    }
    assert_eq!(t.pose_in("odom", "odom", &robot, 0, tol), Ok(robot));
    assert_eq!(
        t.pose_in("elsewhere", "odom", &robot, 10 * S, tol),
        Err(TfError::UnknownFrame("elsewhere".into()))
    );
    let mut fixed = tree();
    fixed.insert("map", "odom", &planar(1.0, 0.0, 0.0), None).unwrap();
    assert!(fixed.pose_in("map", "odom", &robot, 1_000 * S, tol).is_ok());
}

/// A goal's frame: empty is odom, a leading `/` dropped; the robot's odometry pose (1, 1, 0)
/// seen from `map` when odom sits at (−2, 3, π) in map: (−2 − 1, 3 − 1, π) = (−3, 2, π).
/// Stale beyond the tolerance, unknown frames refused, odom itself always fine.
#[test]
fn goal_frames_see_the_robot_from_the_goal_s_frame() {
    let frames = GoalFrames::new("odom", Duration::from_millis(100));
    assert_eq!(frames.frame_of(""), "odom");
    assert_eq!(frames.frame_of("/map"), "map");
    assert!(frames.is_odom("/odom") && !frames.is_odom("map"));
    let mut t = tree();
    t.insert("map", "odom", &planar(-2.0, 3.0, PI), Some(5 * S)).unwrap();
    let robot = mobil_geom::Pose2::new(1.0, 1.0, 0.0);
    let p = frames.robot(&t, "map", &robot, 5 * S + 99_000_000).unwrap();
    assert_relative_eq!(p.x, -3.0, epsilon = 1e-12);
    assert_relative_eq!(p.y, 2.0, epsilon = 1e-12);
    assert_relative_eq!(p.yaw.abs(), PI, epsilon = 1e-12);
    assert!(matches!(
        frames.robot(&t, "map", &robot, 5 * S + 101_000_000),
        Err(TfError::Stale { .. })
    ));
    assert_eq!(
        frames.robot(&t, "earth", &robot, 5 * S),
        Err(TfError::UnknownFrame("earth".into()))
    );
    assert_eq!(frames.robot(&t, "odom", &robot, 0), Ok(robot));
}
