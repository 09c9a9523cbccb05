//! Fuzz test of the world-file loader: thousands of seeded garbage, malformed and degenerate
//! world texts. Every text is either refused with a one-line reason or gives a world whose
//! geometry answers every query with a number (never NaN), and nothing panics.
//!
//! The seed is printed; `MOBIL_FUZZ_SEED=<n>` replays a run. For the generated worlds the test
//! predicts the outcome itself (which obstacle is the first invalid one, or that the YAML has
//! the wrong shape) and compares it with the loader's answer.

use mobil_sim::lidar::{Lidar, LidarConfig};
use mobil_world::{Obstacle, World, WorldError};
use nalgebra::Point2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::time::Instant;

/// The largest coordinate magnitude (m) the loader accepts (see `World::MAX_COORDINATE`).
const LIMIT: f64 = 1e6;

fn seed() -> u64 {
    let seed = std::env::var("MOBIL_FUZZ_SEED")
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(20_261_129);
    println!("world fuzz seed {seed} (replay with MOBIL_FUZZ_SEED={seed})");
    seed
}

/// A number for a world file, as YAML text, and whether the loader must accept it as a
/// coordinate (finite and within ±LIMIT).
fn number(rng: &mut ChaCha8Rng) -> (String, f64) {
    let x: f64 = match rng.random_range(0..14) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => 1e308,
        4 => -1e308,
        5 => 5e-324,
        6 => -0.0,
        7 => 0.0,
        8 => 2.0e6,
        9 => -LIMIT,
        10 => f64::MIN_POSITIVE,
        11 => rng.random_range(-1e5..1e5),
        _ => rng.random_range(-10.0..10.0),
    };
    let text = if x.is_nan() {
        ".nan".to_owned()
    } else if x == f64::INFINITY {
        ".inf".to_owned()
    } else if x == f64::NEG_INFINITY {
        "-.inf".to_owned()
    } else {
        format!("{x:?}")
    };
    (text, x)
}

fn coordinate_ok(x: f64) -> bool {
    x.is_finite() && x.abs() <= LIMIT
}

/// What the loader must answer for a generated text.
#[derive(Debug, PartialEq)]
enum Expect {
    /// A world of this many obstacles.
    Ok(usize),
    /// Refused for the obstacle at this index.
    Invalid(usize),
    /// Refused as YAML of the wrong shape.
    Shape,
}

/// A world file of random obstacles, some invalid, some of the wrong shape.
fn generated_world(rng: &mut ChaCha8Rng) -> (String, Expect) {
    let n = rng.random_range(0..12);
    let mut text = String::from("obstacles:\n");
    let mut first_invalid = None;
    let mut shape_error = false;
    for i in 0..n {
        let valid;
        if rng.random_bool(0.5) {
            let (cx, x) = number(rng);
            let (cy, y) = number(rng);
            let (r_text, r) = match rng.random_range(0..6) {
                0 => ("0".to_owned(), 0.0),
                1 => ("-1.5".to_owned(), -1.5),
                2 => ("-0.0".to_owned(), -0.0),
                _ => number(rng),
            };
            valid = coordinate_ok(x) && coordinate_ok(y) && coordinate_ok(r) && r > 0.0;
            match rng.random_range(0..30) {
                // Wrong shapes: a misspelt or missing field, an extra one, three coordinates,
                // a string, the wrong kind of obstacle.
                0 => {
                    let _ = writeln!(text, "  - circle: {{ centre: [{cx}, {cy}], radius: {r_text} }}");
                    shape_error = true;
                }
                1 => {
                    let _ = writeln!(text, "  - circle: {{ center: [{cx}, {cy}] }}");
                    shape_error = true;
                }
                2 => {
                    let _ = writeln!(text, "  - circle: {{ center: [{cx}, {cy}, 1], radius: {r_text} }}");
                    shape_error = true;
                }
                3 => {
                    let _ = writeln!(text, "  - circle: {{ center: [{cx}, {cy}], radius: \"big\" }}");
                    shape_error = true;
                }
                4 => {
                    let _ = writeln!(text, "  - square: {{ center: [{cx}, {cy}], side: {r_text} }}");
                    shape_error = true;
                }
                5 => {
                    let _ = writeln!(
                        text,
                        "  - circle: {{ center: [{cx}, {cy}], radius: {r_text}, height: 2 }}"
                    );
                    shape_error = true;
                }
                _ => {
                    let _ = writeln!(text, "  - circle: {{ center: [{cx}, {cy}], radius: {r_text} }}");
                }
            }
        } else {
            let k = rng.random_range(0..7);
            let mut all_ok = true;
            let mut points = Vec::new();
            match rng.random_range(0..4) {
                // A bow tie (self-intersecting) or all points on one spot: degenerate but valid.
                0 if k >= 4 => {
                    let s = rng.random_range(0.1..5.0);
                    points.extend([
                        "[0, 0]".to_owned(),
                        format!("[{s}, {s}]"),
                        format!("[{s}, 0]"),
                        format!("[0, {s}]"),
                    ]);
                }
                1 => {
                    let (p, x) = number(rng);
                    all_ok &= coordinate_ok(x);
                    points.extend((0..k).map(|_| format!("[{p}, {p}]")));
                }
                _ => {
                    for _ in 0..k {
                        let (px, x) = number(rng);
                        let (py, y) = number(rng);
                        all_ok &= coordinate_ok(x) && coordinate_ok(y);
                        points.push(format!("[{px}, {py}]"));
                    }
                }
            }
            valid = all_ok && points.len() >= 3;
            if rng.random_range(0..30) == 0 && !points.is_empty() {
                // A point of one coordinate.
                points[0] = "[1]".to_owned();
                shape_error = true;
            }
            let _ = writeln!(text, "  - polygon: {{ points: [{}] }}", points.join(", "));
        }
        if !valid && first_invalid.is_none() {
            first_invalid = Some(i);
        }
    }
    if n == 0 {
        text = "obstacles: []\n".to_owned();
    }
    let expect = if shape_error {
        Expect::Shape
    } else if let Some(i) = first_invalid {
        Expect::Invalid(i)
    } else {
        Expect::Ok(n)
    };
    (text, expect)
}

/// Random bytes, or the shipped world with bytes flipped, cut or inserted.
fn garbage(rng: &mut ChaCha8Rng, base: &[u8]) -> Vec<u8> {
    match rng.random_range(0..4) {
        0 => (0..rng.random_range(0..300)).map(|_| rng.random()).collect(),
        1 => base[..rng.random_range(0..base.len())].to_vec(),
        _ => {
            let mut v = base.to_vec();
            for _ in 0..rng.random_range(1..8) {
                let i = rng.random_range(0..v.len());
                match rng.random_range(0..3) {
                    0 => v[i] = rng.random(),
                    1 => {
                        v.remove(i);
                    }
                    _ => v.insert(
                        i,
                        *b"-[]{}:,.e9n\n #&*!|>'\"".get(rng.random_range(0..21)).unwrap_or(&b' '),
                    ),
                }
            }
            v
        }
    }
}

/// Every query on a loaded world gives a number: distances are never NaN, ray hits lie in
/// [0, range], the collision test agrees with the distance, a LIDAR scan has no NaN.
fn check_geometry(world: &World, rng: &mut ChaCha8Rng, lidar: &mut Lidar, what: &str) {
    for o in &world.obstacles {
        let (lo, hi) = o.bounds();
        assert!(
            lo.iter().chain(&hi).all(|x| x.is_finite()) && lo[0] <= hi[0] && lo[1] <= hi[1],
            "{what}: bounds {lo:?} {hi:?} of {o:?}"
        );
        match o {
            Obstacle::Circle { center, radius } => {
                assert!(coordinate_ok(center[0]) && coordinate_ok(center[1]) && coordinate_ok(*radius) && *radius > 0.0)
            }
            Obstacle::Polygon { points } => {
                assert!(points.len() >= 3 && points.iter().all(|p| coordinate_ok(p[0]) && coordinate_ok(p[1])))
            }
        }
    }
    for _ in 0..3 {
        let p = Point2::new(rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0));
        let d = world.distance_to(p);
        assert!(!d.is_nan(), "{what}: distance_to({p}) is NaN");
        assert!(
            world.obstacles.is_empty() || d.is_finite(),
            "{what}: distance_to({p}) = {d}"
        );
        let r = rng.random_range(0.0..2.0);
        assert_eq!(
            world.collides(p, r),
            d < r,
            "{what}: collides({p}, {r}) with distance {d}"
        );
        let angle = rng.random_range(-4.0..4.0);
        if let Some(t) = world.ray_distance(p, angle, 10.0) {
            assert!((0.0..=10.0).contains(&t), "{what}: ray from {p} at {angle} hits at {t}");
        }
    }
    let scan = lidar.scan(world, (0.5, -0.5, 0.3));
    assert!(scan.ranges.iter().all(|r| !r.is_nan()), "{what}: NaN in a scan");
}

fn one_line_reason(e: &WorldError, what: &str) {
    let s = e.to_string();
    assert!(
        !s.is_empty() && !s.contains('\n'),
        "{what}: the reason is not one line: {s:?}"
    );
}

#[test]
fn world_loader_survives_thousands_of_bad_files() {
    let seed = seed();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut lidar = Lidar::new(
        LidarConfig {
            beams: 37,
            ..LidarConfig::default()
        },
        seed,
    );
    let base =
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/worlds/default.yaml")).unwrap_or_default();
    assert!(!base.is_empty(), "params/worlds/default.yaml is missing");
    let started = Instant::now();
    let (mut accepted, mut invalid, mut shape) = (0, 0, 0);
    const GENERATED: usize = 4000;
    for case in 0..GENERATED {
        let (text, expect) = generated_world(&mut rng);
        let what = format!("seed {seed}, generated case {case}:\n{text}");
        match (World::from_yaml_str(&text), &expect) {
            (Ok(w), Expect::Ok(n)) => {
                assert_eq!(w.obstacles.len(), *n, "{what}");
                check_geometry(&w, &mut rng, &mut lidar, &what);
                accepted += 1;
            }
            (Err(e @ WorldError::Invalid { index, .. }), Expect::Invalid(i)) => {
                assert_eq!(index, *i, "{what}: {e}");
                one_line_reason(&e, &what);
                invalid += 1;
            }
            (Err(e @ WorldError::Yaml(_)), Expect::Shape) => {
                one_line_reason(&e, &what);
                shape += 1;
            }
            (got, expect) => panic!("{what}: expected {expect:?}, got {got:?}"),
        }
    }
    const GARBAGE: usize = 3000;
    let (mut garbage_ok, mut garbage_refused) = (0, 0);
    for case in 0..GARBAGE {
        let bytes = garbage(&mut rng, &base);
        let text = String::from_utf8_lossy(&bytes);
        let what = format!("seed {seed}, garbage case {case}: {text:?}");
        match World::from_yaml_str(&text) {
            Ok(w) => {
                check_geometry(&w, &mut rng, &mut lidar, &what);
                garbage_ok += 1;
            }
            Err(e) => {
                one_line_reason(&e, &what);
                garbage_refused += 1;
            }
        }
    }
    println!(
        "{GENERATED} generated worlds: {accepted} accepted, {invalid} refused for an invalid obstacle, {shape} \
         refused for their shape; {GARBAGE} garbage texts: {garbage_ok} accepted, {garbage_refused} refused; \
         {:.2} s",
        started.elapsed().as_secs_f64()
    );
    // Each kind of answer must have been exercised.
    assert!(accepted > 100 && invalid > 100 && shape > 100 && garbage_refused > 100);
}

#[test]
fn degenerate_and_garbage_world_files_by_hand() {
    let err = |text: &str| {
        World::from_yaml_str(text)
            .map(|w| w.obstacles.len())
            .map_err(|e| e.to_string())
    };
    // Empty file, a bare scalar, a list at the top, binary junk.
    for text in [
        "",
        "3",
        "- circle: {}\n",
        "\u{0}\u{1}\u{fffd}\u{7f}",
        "obstacles:\n  - circle: ~\n",
    ] {
        let e = err(text).unwrap_err();
        assert!(e.contains("YAML") && !e.contains('\n'), "{text:?}: {e}");
    }
    // A bow tie and a polygon with every point on one spot are valid (harmless) worlds.
    assert_eq!(
        err("obstacles:\n  - polygon: { points: [[0, 0], [1, 1], [1, 0], [0, 1]] }\n"),
        Ok(1)
    );
    let w = World::from_yaml_str("obstacles:\n  - polygon: { points: [[2, 2], [2, 2], [2, 2]] }\n").unwrap();
    // Distance from the origin to the point (2, 2): 2√2.
    assert!((w.distance_to(Point2::origin()) - 8f64.sqrt()).abs() < 1e-12);
    assert_eq!(
        w.ray_distance(Point2::origin(), std::f64::consts::FRAC_PI_4, 10.0),
        None
    );
    // Huge coordinates are refused: 1e308 − (−1e308) overflows, and every distance would be NaN.
    let e = err("obstacles:\n  - polygon: { points: [[-1e308, 0], [1e308, 0], [0, 1]] }\n").unwrap_err();
    assert!(e.contains("obstacle 0") && e.contains("1e6"), "{e}");
    let e = err("obstacles:\n  - circle: { center: [0, 0], radius: 1e300 }\n").unwrap_err();
    assert!(e.contains("obstacle 0") && e.contains("1e6"), "{e}");
    assert_eq!(
        err("obstacles:\n  - circle: { center: [-1e6, 1e6], radius: 1e6 }\n"),
        Ok(1)
    );
}

#[test]
fn a_world_of_100k_obstacles_loads_in_bounded_time() {
    let mut text = String::from("obstacles:\n");
    for i in 0..100_000 {
        let (x, y) = ((i % 1000) as f64 * 0.5, (i / 1000) as f64 * 0.5);
        let _ = writeln!(text, "  - circle: {{ center: [{x}, {y}], radius: 0.1 }}");
    }
    let started = Instant::now();
    let w = World::from_yaml_str(&text).unwrap();
    let load = started.elapsed().as_secs_f64();
    assert_eq!(w.obstacles.len(), 100_000);
    // The grid's spacing is 0.5 m: (0.25, 0.25) lies √(0.25² + 0.25²) − 0.1 from the four
    // nearest centres.
    let d = w.distance_to(Point2::new(0.25, 0.25));
    assert!((d - (0.125f64.sqrt() - 0.1)).abs() < 1e-12, "{d}");
    println!("100k obstacles loaded in {load:.2} s");
    assert!(load < 20.0, "loading took {load:.1} s");
}
