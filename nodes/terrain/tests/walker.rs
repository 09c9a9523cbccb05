//! The walking hexapod: its gait's timing and geometry, and what the assessment makes of its
//! touchdowns on flat ground, a 10° slope, seeded rough ground and a flat → ramp → rough course.

use mobil_terrain::{
    Assessment, Assessor, Course, FootTracker, Gait, Ground, Leg, RoughGround, Section, TerrainClass, TerrainConfig,
    Touchdown, Walker, WalkerConfig,
};
use std::f64::consts::PI;

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w - 2.0 * PI
    } else {
        w
    }
}

/// Every (touchdown, assessment) of a walk of `seconds`, fed to a tracker as the node will.
fn walk(walker: &Walker, seconds: f64) -> Vec<(Touchdown, Assessment)> {
    let mut tracker = FootTracker::new(Assessor::new(TerrainConfig::default()).unwrap());
    let mut out = Vec::new();
    for td in walker.touchdowns_in(-1.0, seconds) {
        if let Some(a) = tracker.touchdown(td.leg, td.position).unwrap() {
            out.push((td, a));
        }
    }
    assert_eq!(tracker.rejected() + tracker.failed(), 0);
    out
}

/// Defaults: T = 1 s, v = 0.1 m/s, so the stride is L = v·T/2 = 0.05 m and each foot lands
/// L/2 = 0.025 m ahead of its foothold. Heading 90° (world +y), from (1, 2).
/// - Times: six at t = 0, then tripod B (KV, DP, DG) at 0.5, 1.5, …, tripod A (KP, KG, DV) at
///   1, 2, …; 6 + 4 × 3 = 18 touchdowns in (−1, 2].
/// - KV at t = 0.5: the body is at (1, 2 + 0.05); KV's landing point in the body frame is
///   (0 + 0.025, 0.16); turned by 90°: (−0.16, 0.025); in the world (0.84, 2.075).
#[test]
fn the_tripod_gait_lands_each_foot_half_a_stride_ahead() {
    let config = WalkerConfig {
        heading: PI / 2.0,
        start: [1.0, 2.0],
        ..WalkerConfig::default()
    };
    let w = Walker::new(config, Ground::Flat(0.0)).unwrap();
    assert!((w.stride() - 0.05).abs() < 1e-15);
    let all: Vec<Touchdown> = w.touchdowns_in(-1.0, 2.0).collect();
    assert_eq!(all.len(), 18);
    let times: Vec<f64> = all.iter().map(|t| t.t).collect();
    let mut expected = vec![0.0; 6];
    for t in [0.5, 1.0, 1.5, 2.0] {
        expected.extend([t; 3]);
    }
    assert_eq!(times, expected);
    let legs: Vec<Leg> = all[6..12].iter().map(|t| t.leg).collect();
    assert_eq!(legs, [Leg::KV, Leg::DP, Leg::DG, Leg::KP, Leg::KG, Leg::DV]);
    let kv = all[6];
    assert!((kv.position.x - 0.025).abs() < 1e-12 && (kv.position.y - 0.16).abs() < 1e-12);
    assert!((kv.world.x - 0.84).abs() < 1e-12 && (kv.world.y - 2.075).abs() < 1e-12);
    // Flat ground at 0, body 0.10 m above it: every foot at z = −0.10 in the body frame.
    assert!(all.iter().all(|t| (t.position.z + 0.10).abs() < 1e-15));
    // Adjoining intervals give every touchdown once.
    let mut parts: Vec<Touchdown> = w.touchdowns_in(-1.0, 0.7).collect();
    parts.extend(w.touchdowns_in(0.7, 1.5));
    parts.extend(w.touchdowns_in(1.5, 2.0));
    assert_eq!(parts, all);
    // During its stance (T/2) the body moves one stride: a foot landed at t stays where it
    // landed, which at lift-off (t + T/2) is L/2 behind its foothold in the body frame.
    let lift_off = w.body_pose(kv.t + 0.5);
    assert!((lift_off.position.y - (kv.world.y + 0.025)).abs() < 1e-12);
}

/// A clock jumping far ahead: the touchdowns up to t = 10³⁰⁰ s are produced one at a time, and
/// the first of them are those of an ordinary walk: six standing feet at 0, then tripod B
/// (KV, DP, DG) at 0.5 s and tripod A (KP, KG, DV) at 1 s. (Collected into a vector they would
/// never end.) An interval starting at 10¹⁸ s still yields touchdowns after its start. Empty,
/// reversed and non-finite intervals give none.
#[test]
fn a_huge_interval_is_walked_lazily() {
    let w = Walker::new(WalkerConfig::default(), Ground::Flat(0.0)).unwrap();
    let first: Vec<(f64, Leg)> = w.touchdowns_in(-1.0, 1e300).take(12).map(|t| (t.t, t.leg)).collect();
    let mut expected: Vec<(f64, Leg)> = Leg::ALL.iter().map(|&l| (0.0, l)).collect();
    expected.extend([Leg::KV, Leg::DP, Leg::DG].map(|l| (0.5, l)));
    expected.extend([Leg::KP, Leg::KG, Leg::DV].map(|l| (1.0, l)));
    assert_eq!(first, expected);
    let far: Vec<Touchdown> = w.touchdowns_in(1e18, 1e300).take(3).collect();
    assert_eq!(far.len(), 3);
    assert!(far.iter().all(|t| t.t > 1e18), "{far:?}");
    assert_eq!(w.touchdowns_in(1.0, 1.0).count(), 0);
    assert_eq!(w.touchdowns_in(2.0, 1.0).count(), 0);
    assert_eq!(w.touchdowns_in(f64::NAN, 1.0).count(), 0);
    assert_eq!(w.touchdowns_in(0.0, f64::INFINITY).count(), 0);
}

#[test]
fn flat_ground_is_flat() {
    let w = Walker::new(WalkerConfig::default(), Ground::Flat(0.3)).unwrap();
    let out = walk(&w, 20.0);
    // One assessment per touchdown once all six are known: the sixth at t = 0, then 3 per
    // half period.
    assert_eq!(out.len(), 1 + 40 * 3);
    for (_, a) in &out {
        assert_eq!(a.sigma, 0.0);
        assert_eq!((a.class, a.advice), (TerrainClass::Flat, Gait::Tripod));
    }
}

/// On a plane the body (level, at a fixed height above the plane's mean under the footholds)
/// sees the same plane in its own frame at every instant: z = tan 10°·(x cos φ + y sin φ) − 0.10
/// with φ = uphill − heading. Every foot, whenever stored, lies on it: α12 = 0,
/// α13 = α23 = 10°, downhill φ + π. Once every foot has stepped (after t = 1 s, when tripod A
/// has landed for the first time; at 1 s itself some of A are still the standing feet) all lie L/2 ahead of
/// their footholds, which does not change the spread, so σ = tan 10°·√(0.015 cos²φ +
/// 0.018133 sin²φ) as for the standing stance.
#[test]
fn a_10_degree_slope_is_slope_in_any_direction() {
    for (uphill_deg, heading_deg) in [(0.0, 0.0), (90.0, 30.0), (200.0, -45.0), (-120.0, 170.0)] {
        let (uphill, heading) = (f64::to_radians(uphill_deg), f64::to_radians(heading_deg));
        let ground = Ground::plane(10f64.to_radians(), uphill).unwrap();
        let config = WalkerConfig {
            heading,
            start: [0.3, -0.2],
            ..WalkerConfig::default()
        };
        let w = Walker::new(config, ground).unwrap();
        let out = walk(&w, 30.0);
        assert_eq!(out.len(), 1 + 60 * 3);
        let phi = uphill - heading;
        let t = 10f64.to_radians().tan();
        let sigma = t * (0.015 * phi.cos().powi(2) + 0.018_133_333_333 * phi.sin().powi(2)).sqrt();
        for (td, a) in &out {
            assert_eq!(
                a.class,
                TerrainClass::Slope,
                "uphill {uphill_deg}° heading {heading_deg}°: {a:?}"
            );
            assert!(a.alpha12 < 1e-9);
            assert!((a.alpha13 - 10f64.to_radians()).abs() < 1e-9);
            assert!((a.alpha23 - 10f64.to_radians()).abs() < 1e-9);
            for plane in &a.planes[..2] {
                assert!(wrap(plane.downhill - (phi + PI)).abs() < 1e-9);
            }
            if td.t > 1.0 {
                assert!((a.sigma - sigma).abs() < 1e-9, "σ {} vs {sigma}", a.sigma);
            }
        }
    }
}

/// Rough ground: node heights uniform in ±5 cm (standard deviation 2.89 cm) every 0.10 m,
/// bilinear between. Bilinear interpolation of independent nodes scales the variance by
/// (E[(1−u)² + u²])² = (2/3)², so a foot's height has a standard deviation of about 1.9 cm.
/// A foot plane's gradient then has a standard deviation of about √2 · 1.9 / 30 ≈ 0.09 per
/// component (feet 0.28–0.30 m apart), the difference of the two planes' gradients about
/// 0.125 rad per component, and α12 is about Rayleigh-distributed with scale 7°: below
/// ε_α = 3° with probability 1 − exp(−(3/7)²/2) ≈ 9 %. So about 90 % of the assessments are
/// UNEVEN; the test asks for 80 % (nearby feet share grid cells, which the estimate ignores).
/// σ stays near 1.5 cm, so BEYOND_LIMITS (σ > 4 cm or a tilt over 15°) is rare.
#[test]
fn rough_ground_is_uneven() {
    for seed in [1, 2, 3] {
        let ground = Ground::Rough(RoughGround::new(0.05, 0.10, seed).unwrap());
        let w = Walker::new(WalkerConfig::default(), ground).unwrap();
        let out = walk(&w, 100.0);
        let n = out.len() as f64;
        let count = |c| out.iter().filter(|(_, a)| a.class == c).count() as f64;
        let uneven = count(TerrainClass::Uneven) / n;
        let beyond = count(TerrainClass::BeyondLimits) / n;
        assert!(uneven >= 0.8, "seed {seed}: {uneven}");
        assert!(beyond <= 0.05, "seed {seed}: {beyond}");
        // Uneven ground gets the slower gaits.
        assert!(out
            .iter()
            .filter(|(_, a)| a.class == TerrainClass::Uneven)
            .all(|(_, a)| matches!(a.advice, Gait::Ripple | Gait::Wave)));
    }
}

/// The demo's course: 1.5 m flat, a 10° ramp 2 m long, 1 m flat at the top, 3 m rough (±5 cm).
/// Taking an assessment as belonging to the section under the body when all stored feet are
/// certainly on it (the body's x at least 0.36 m inside: feet land 0.175 m ahead of the body
/// and 0.125 m behind it, and stored feet were placed up to one stride, 0.05 m, earlier), the
/// flat part is FLAT, the ramp SLOPE at 10°, the rough part mostly UNEVEN.
#[test]
fn the_course_is_flat_then_slope_then_uneven() {
    let rough = RoughGround::new(0.05, 0.10, 4).unwrap();
    let sections = vec![
        (1.5, Section::Flat),
        (2.0, Section::Ramp(10f64.to_radians())),
        (1.0, Section::Flat),
        (3.0, Section::Rough(rough)),
    ];
    let ground = Ground::Course(Course::new(0.0, sections).unwrap());
    let w = Walker::new(WalkerConfig::default(), ground).unwrap();
    let out = walk(&w, 75.0);
    let inside = |x: f64, from: f64, to: f64| x >= from + 0.36 && x <= to - 0.36;
    let mut seen = [0usize; 3];
    let mut uneven = 0usize;
    for (td, a) in &out {
        let x = w.body_pose(td.t).position.x;
        if inside(x, -10.0, 1.5) || inside(x, 3.5, 4.5) {
            assert_eq!(a.class, TerrainClass::Flat, "x {x}");
            seen[0] += 1;
        } else if inside(x, 1.5, 3.5) {
            assert_eq!(a.class, TerrainClass::Slope, "x {x}");
            assert!((a.alpha13 - 10f64.to_radians()).abs() < 1e-9);
            seen[1] += 1;
        } else if inside(x, 4.5, 7.5) {
            seen[2] += 1;
            uneven += usize::from(a.class == TerrainClass::Uneven);
        }
    }
    // At 0.1 m/s, 3 assessments every 0.5 s (1 at t = 0, when the sixth foot is known):
    // flat x ≤ 1.14 is t ≤ 11.4 s: 1 + 22 × 3 = 67; the top, x in [3.86, 4.14], t = 39 … 41 s:
    // 5 × 3 = 15; the ramp, x in [1.86, 3.14], t = 19 … 31 s: 25 × 3 = 75; the rough part,
    // x in [4.86, 7.14], t = 49 … 71 s: 45 × 3 = 135.
    assert_eq!(seen, [67 + 15, 75, 135]);
    assert!(uneven as f64 >= 0.8 * seen[2] as f64, "{uneven} of {}", seen[2]);
}

#[test]
fn invalid_walkers_are_refused() {
    let bad = [
        WalkerConfig {
            gait_period: 0.0,
            ..WalkerConfig::default()
        },
        WalkerConfig {
            speed: -0.1,
            ..WalkerConfig::default()
        },
        WalkerConfig {
            heading: f64::NAN,
            ..WalkerConfig::default()
        },
    ];
    for c in bad {
        assert!(Walker::new(c, Ground::Flat(0.0)).is_err());
    }
}
