//! A 2D world of obstacles (circles and polygons), read from YAML or built in.
//!
//! ```yaml
//! obstacles:
//!   - circle: { center: [2.0, 1.0], radius: 0.3 }
//!   - polygon: { points: [[0, 0], [1, 0], [1, 1]] }
//! ```
//!
//! Geometry is exact (no grid): rays are cast against circles and polygon edges, distances are
//! measured to the nearest surface. Coordinates are metres in the world frame.
#![warn(missing_docs)]

use mobil_geom::segment::segment_distance;
use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// One obstacle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Obstacle {
    /// A disc.
    Circle {
        /// Centre [x, y] (m).
        center: [f64; 2],
        /// Radius (m), > 0.
        radius: f64,
    },
    /// A closed polygon (the last point connects to the first; even-odd rule for its inside).
    Polygon {
        /// Vertices [x, y] (m), at least 3.
        points: Vec<[f64; 2]>,
    },
}

/// The world: a list of obstacles.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// The obstacles; in YAML each is a one-key map (`circle: {…}` or `polygon: {…}`).
    #[serde(with = "serde_norway::with::singleton_map_recursive")]
    pub obstacles: Vec<Obstacle>,
}

/// A world that could not be read.
#[derive(Debug, Error)]
pub enum WorldError {
    /// The file could not be read.
    #[error("cannot read world file {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The text is not YAML of the expected shape.
    #[error("world is not valid YAML: {0}")]
    Yaml(#[from] serde_norway::Error),
    /// A world file whose text was refused (by [`WorldError::Yaml`] or [`WorldError::Invalid`]).
    #[error("world file {path}: {source}")]
    File {
        /// The file.
        path: String,
        /// Why its text was refused.
        source: Box<WorldError>,
    },
    /// An obstacle has invalid geometry (non-finite, beyond ±[`World::MAX_COORDINATE`],
    /// radius ≤ 0, fewer than 3 points).
    #[error("obstacle {index}: {reason}")]
    Invalid {
        /// Position of the obstacle in the list (from 0).
        index: usize,
        /// What is wrong.
        reason: String,
    },
}

fn point(p: [f64; 2]) -> Point2<f64> {
    Point2::new(p[0], p[1])
}

/// Distance along a ray (origin o, unit direction d) to segment ab, if it hits.
fn ray_segment(o: Point2<f64>, d: Vector2<f64>, a: Point2<f64>, b: Point2<f64>) -> Option<f64> {
    let e = b - a;
    let denom = d.perp(&e);
    if denom.abs() < 1e-15 {
        // Parallel: a ray running along the edge meets the neighbouring edges at its ends.
        return None;
    }
    let ao = a - o;
    let t = ao.perp(&e) / denom;
    let u = ao.perp(&d) / denom;
    (t >= 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
}

/// Distance along a ray to a circle's boundary, if it hits (from inside: the exit point).
fn ray_circle(o: Point2<f64>, d: Vector2<f64>, c: Point2<f64>, r: f64) -> Option<f64> {
    let oc = o - c;
    let b = oc.dot(&d);
    let disc = b * b - (oc.norm_squared() - r * r);
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [-b - s, -b + s].into_iter().find(|t| *t >= 0.0)
}

impl Obstacle {
    fn edges(points: &[[f64; 2]]) -> impl Iterator<Item = (Point2<f64>, Point2<f64>)> + '_ {
        let n = points.len();
        (0..n).map(move |i| (point(points[i]), point(points[(i + 1) % n])))
    }

    /// Checks the geometry: finite numbers within ±[`World::MAX_COORDINATE`], a positive
    /// radius, at least 3 polygon points.
    fn check(&self) -> Result<(), String> {
        let within = |x: &f64| x.abs() <= World::MAX_COORDINATE;
        match self {
            Obstacle::Circle { center, radius } => {
                if !(center.iter().all(|c| c.is_finite()) && radius.is_finite()) {
                    return Err(format!("circle center {center:?} and radius {radius} must be finite"));
                }
                if *radius <= 0.0 {
                    return Err(format!("circle radius {radius} must be positive"));
                }
                if !(center.iter().all(within) && within(radius)) {
                    return Err(format!(
                        "circle center {center:?} and radius {radius} must lie within ±{:e} m",
                        World::MAX_COORDINATE
                    ));
                }
            }
            Obstacle::Polygon { points } => {
                if points.len() < 3 {
                    return Err(format!("a polygon needs at least 3 points, got {}", points.len()));
                }
                if let Some(p) = points.iter().find(|p| !(p[0].is_finite() && p[1].is_finite())) {
                    return Err(format!("polygon point {p:?} must be finite"));
                }
                if let Some(p) = points.iter().find(|p| !p.iter().all(within)) {
                    return Err(format!(
                        "polygon point {p:?} must lie within ±{:e} m",
                        World::MAX_COORDINATE
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether a point lies inside or on the boundary of the obstacle.
    pub fn contains(&self, p: Point2<f64>) -> bool {
        self.signed_distance(p) <= 0.0
    }

    /// Signed distance to the obstacle's surface: positive outside, 0 on it, negative inside
    /// (polygons: even-odd rule).
    pub fn signed_distance(&self, p: Point2<f64>) -> f64 {
        match self {
            Obstacle::Circle { center, radius } => (p - point(*center)).norm() - radius,
            Obstacle::Polygon { points } => {
                let mut inside = false;
                let mut d = f64::INFINITY;
                for (a, b) in Self::edges(points) {
                    d = d.min(segment_distance(p, a, b));
                    if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                        inside = !inside;
                    }
                }
                if inside {
                    -d
                } else {
                    d
                }
            }
        }
    }

    /// Nearest hit of a ray (origin `o`, unit direction `d`) with the boundary, as a distance.
    pub fn ray_hit(&self, o: Point2<f64>, d: Vector2<f64>) -> Option<f64> {
        match self {
            Obstacle::Circle { center, radius } => ray_circle(o, d, point(*center), *radius),
            Obstacle::Polygon { points } => Self::edges(points)
                .filter_map(|(a, b)| ray_segment(o, d, a, b))
                .min_by(f64::total_cmp),
        }
    }

    /// Axis-aligned bounding box: ([x_min, y_min], [x_max, y_max]).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Obstacle::Circle { center, radius } => (
                [center[0] - radius, center[1] - radius],
                [center[0] + radius, center[1] + radius],
            ),
            Obstacle::Polygon { points } => points
                .iter()
                .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
                    ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
                }),
        }
    }
}

impl World {
    /// The largest coordinate or radius magnitude accepted (m): a world of ±1000 km. Near the
    /// limits of `f64` (1e308) the differences and squares of coordinates overflow, so bounding
    /// boxes become infinite and distances meaningless; no map needs more than this.
    pub const MAX_COORDINATE: f64 = 1e6;

    /// Parses a world from YAML text, refusing invalid geometry.
    pub fn from_yaml_str(text: &str) -> Result<World, WorldError> {
        let world: World = serde_norway::from_str(text)?;
        world.validate()?;
        Ok(world)
    }

    /// Reads a world file (YAML, see the module documentation). Every error names the file.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<World, WorldError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| WorldError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_yaml_str(&text).map_err(|e| WorldError::File {
            path: path.display().to_string(),
            source: Box::new(e),
        })
    }

    /// The world seen from another frame: every point `p` becomes `frame.transform_point(p)`
    /// (`frame`: this world's frame's pose in the other; a goal's frame that is not the world's).
    pub fn moved(&self, frame: &mobil_geom::Pose2) -> World {
        let at = |p: &[f64; 2]| {
            let q = frame.transform_point(Point2::new(p[0], p[1]));
            [q.x, q.y]
        };
        let obstacles = self
            .obstacles
            .iter()
            .map(|o| match o {
                Obstacle::Circle { center, radius } => Obstacle::Circle {
                    center: at(center),
                    radius: *radius,
                },
                Obstacle::Polygon { points } => Obstacle::Polygon {
                    points: points.iter().map(at).collect(),
                },
            })
            .collect();
        World { obstacles }
    }

    /// Checks every obstacle's geometry: finite numbers within ±[`World::MAX_COORDINATE`],
    /// radius > 0, at least 3 polygon points.
    pub fn validate(&self) -> Result<(), WorldError> {
        for (index, o) in self.obstacles.iter().enumerate() {
            o.check().map_err(|reason| WorldError::Invalid { index, reason })?;
        }
        Ok(())
    }

    /// The built-in world (also `params/worlds/default.yaml`; a test keeps them equal).
    ///
    /// A room of 12 m × 8 m (inner faces x ∈ [−5, 7], y ∈ [−2.5, 5.5]) with 0.1 m walls, three
    /// pillars, a box, an L-shaped block and a triangle. The origin is 1.50 m from the nearest
    /// surface (the pillar at (1, 1.5)). The demo loop — a rounded rectangle x ∈ [−1, 3],
    /// y ∈ [0, 3] with 1 m corner radii, driven anticlockwise from (0, 0) facing east — keeps at
    /// least 1.2 m from every obstacle, i.e. 0.5 m beyond MOBIL-II's 0.53 m footprint radius.
    pub fn builtin() -> World {
        let rect = |x0: f64, y0: f64, x1: f64, y1: f64| Obstacle::Polygon {
            points: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
        };
        World {
            obstacles: vec![
                // Walls, 0.1 m thick: the room spans x ∈ [−5, 7], y ∈ [−2.5, 5.5].
                rect(-5.1, -2.6, 7.1, -2.5),
                rect(-5.1, 5.5, 7.1, 5.6),
                rect(-5.1, -2.5, -5.0, 5.5),
                rect(7.0, -2.5, 7.1, 5.5),
                // Pillars; the first stands inside the demo loop.
                Obstacle::Circle {
                    center: [1.0, 1.5],
                    radius: 0.3,
                },
                Obstacle::Circle {
                    center: [5.0, 4.0],
                    radius: 0.4,
                },
                Obstacle::Circle {
                    center: [-3.5, -1.0],
                    radius: 0.35,
                },
                // A box east of the loop.
                rect(4.5, -0.5, 5.5, 1.0),
                // An L-shaped block north-west.
                Obstacle::Polygon {
                    points: vec![
                        [-4.0, 3.5],
                        [-2.0, 3.5],
                        [-2.0, 4.0],
                        [-3.5, 4.0],
                        [-3.5, 5.0],
                        [-4.0, 5.0],
                    ],
                },
                // A triangle south.
                Obstacle::Polygon {
                    points: vec![[1.5, -2.0], [3.0, -2.0], [2.25, -1.2]],
                },
            ],
        }
    }

    /// Nearest hit of the ray from `origin` at `angle` (world frame, anticlockwise from +x) with
    /// any obstacle boundary, if one lies within `max_range`.
    pub fn ray_distance(&self, origin: Point2<f64>, angle: f64, max_range: f64) -> Option<f64> {
        let d = Vector2::new(angle.cos(), angle.sin());
        self.obstacles
            .iter()
            .filter(|o| ray_may_hit(o, origin, d, max_range))
            .filter_map(|o| o.ray_hit(origin, d))
            .filter(|t| *t <= max_range)
            .min_by(f64::total_cmp)
    }

    /// Signed distance from `p` to the nearest obstacle surface: negative inside an obstacle,
    /// 0 on a surface, `+inf` in an empty world.
    pub fn distance_to(&self, p: Point2<f64>) -> f64 {
        self.obstacles
            .iter()
            .map(|o| o.signed_distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether a disc of `radius` centred at `p` overlaps an obstacle (touching does not count).
    pub fn collides(&self, p: Point2<f64>, radius: f64) -> bool {
        self.distance_to(p) < radius
    }
}

/// Early-out: false when the segment [o, o + range·d] surely misses the obstacle's bounding box
/// (slab test); true otherwise.
fn ray_may_hit(o: &Obstacle, origin: Point2<f64>, d: Vector2<f64>, range: f64) -> bool {
    if let Obstacle::Circle { .. } = o {
        // The exact test is as cheap.
        return true;
    }
    let (lo, hi) = o.bounds();
    let (mut t0, mut t1) = (0.0_f64, range);
    for axis in 0..2 {
        let (p, v) = (origin[axis], d[axis]);
        if v.abs() < 1e-300 {
            if p < lo[axis] || p > hi[axis] {
                return false;
            }
        } else {
            let (a, b) = ((lo[axis] - p) / v, (hi[axis] - p) / v);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    // (A NaN origin gives no hits anyway: `max`/`min` skip NaN, and so does `ray_hit`.)
    t0 <= t1 + 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seen from a frame in which this one sits at (2, 3) turned by π/2, (x, y) is at
    /// (2 − y, 3 + x): the circle's centre (1, 0) at (2, 4), the triangle's corners
    /// (0, 0), (1, 0), (0, 1) at (2, 3), (2, 4), (1, 3); radii kept.
    #[test]
    fn a_world_seen_from_another_frame() {
        let world = World {
            obstacles: vec![
                Obstacle::Circle {
                    center: [1.0, 0.0],
                    radius: 0.5,
                },
                Obstacle::Polygon {
                    points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                },
            ],
        };
        let moved = world.moved(&mobil_geom::Pose2::new(2.0, 3.0, FRAC_PI_2));
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;
        match &moved.obstacles[..] {
            [Obstacle::Circle { center, radius }, Obstacle::Polygon { points }] => {
                assert!(close(*center, [2.0, 4.0]) && *radius == 0.5, "{center:?}");
                let want = [[2.0, 3.0], [2.0, 4.0], [1.0, 3.0]];
                assert!(points.iter().zip(want).all(|(p, w)| close(*p, w)), "{points:?}");
            }
            other => panic!("{other:?}"),
        }
    }
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn wall_and_circle() -> World {
        World::from_yaml_str(
            "obstacles:\n  - polygon: { points: [[3, -10], [4, -10], [4, 10], [3, 10]] }\n  - circle: { center: [-2, 0], radius: 0.5 }\n",
        )
        .unwrap()
    }

    #[test]
    fn yaml_example_parses_to_exact_obstacles() {
        let w = World::from_yaml_str(
            "obstacles:\n  - circle: { center: [2.0, 1.0], radius: 0.3 }\n  - polygon: { points: [[0,0],[1,0],[1,1]] }\n",
        )
        .unwrap();
        assert_eq!(
            w.obstacles,
            vec![
                Obstacle::Circle {
                    center: [2.0, 1.0],
                    radius: 0.3
                },
                Obstacle::Polygon {
                    points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]
                },
            ]
        );
        // Serialising and reading back gives the same world.
        let text = serde_norway::to_string(&w).unwrap();
        assert_eq!(World::from_yaml_str(&text).unwrap(), w);
        assert_eq!(World::from_yaml_str("obstacles: []\n").unwrap(), World::default());
    }

    #[test]
    fn ray_hits_by_hand() {
        let w = wall_and_circle();
        let o = Point2::origin();
        assert!((w.ray_distance(o, 0.0, 10.0).unwrap() - 3.0).abs() < 1e-12);
        assert!((w.ray_distance(o, PI / 4.0, 10.0).unwrap() - 3.0 * 2f64.sqrt()).abs() < 1e-12);
        // 60°: 3 / cos 60° = 6.
        assert!((w.ray_distance(o, PI / 3.0, 10.0).unwrap() - 6.0).abs() < 1e-12);
        assert!((w.ray_distance(o, PI, 10.0).unwrap() - 1.5).abs() < 1e-12);
        // Tangent-ish: at asin(0.5/2) = 14.4775° off −x the ray grazes the circle at √(4 − 0.25).
        let graze = PI - (0.25f64).asin() + 1e-9;
        assert!((w.ray_distance(o, graze, 10.0).unwrap() - 3.75f64.sqrt()).abs() < 1e-3);
        assert_eq!(w.ray_distance(o, PI - 0.26, 10.0), None);
        assert_eq!(w.ray_distance(o, FRAC_PI_2, 10.0), None);
        // max_range is inclusive.
        assert_eq!(w.ray_distance(o, 0.0, 2.9), None);
        assert_eq!(w.ray_distance(o, 0.0, 3.0), Some(3.0));
        // From inside the circle: the exit point, 0.5 from its centre.
        assert!((w.ray_distance(Point2::new(-2.0, 0.0), FRAC_PI_2, 10.0).unwrap() - 0.5).abs() < 1e-12);
        // From inside the wall heading +x: its far face at x = 4.
        assert!((w.ray_distance(Point2::new(3.25, 0.0), 0.0, 10.0).unwrap() - 0.75).abs() < 1e-12);
        assert_eq!(World::default().ray_distance(o, 0.0, 1e9), None);
    }

    #[test]
    fn distances_by_hand() {
        let w = wall_and_circle();
        assert!((w.distance_to(Point2::new(0.0, 0.0)) - 1.5).abs() < 1e-12);
        // Inside the wall, 0.25 from its west face.
        assert!((w.distance_to(Point2::new(3.25, 0.0)) + 0.25).abs() < 1e-12);
        // The circle's centre is a radius deep.
        assert!((w.distance_to(Point2::new(-2.0, 0.0)) + 0.5).abs() < 1e-12);
        assert_eq!(w.distance_to(Point2::new(3.0, 2.0)), 0.0);
        // Past the wall's end (3, 10) diagonally: √(1 + 1).
        assert!((w.distance_to(Point2::new(2.0, 11.0)) - 2f64.sqrt()).abs() < 1e-12);
        assert!(w.collides(Point2::new(2.6, 0.0), 0.5));
        assert!(!w.collides(Point2::new(2.4, 0.0), 0.5));
        assert!(w.collides(Point2::new(3.5, 0.0), 0.0), "inside collides at any radius");
        assert_eq!(World::default().distance_to(Point2::origin()), f64::INFINITY);
        assert!(!World::default().collides(Point2::origin(), 100.0));
    }

    #[test]
    fn concave_polygon_inside_and_outside() {
        let l = match &World::builtin().obstacles[8] {
            l @ Obstacle::Polygon { .. } => l.clone(),
            other => panic!("expected the L block, got {other:?}"),
        };
        // In the L's long arm, in its short arm, and in the notch between the arms.
        assert!(l.contains(Point2::new(-3.0, 3.75)));
        assert!(l.contains(Point2::new(-3.75, 4.5)));
        assert!(!l.contains(Point2::new(-3.0, 4.5)));
        assert!((l.signed_distance(Point2::new(-3.0, 4.5)) - 0.5).abs() < 1e-12);
        assert!((l.signed_distance(Point2::new(-3.0, 3.75)) + 0.25).abs() < 1e-12);
        assert_eq!(l.bounds(), ([-4.0, 3.5], [-2.0, 5.0]));
    }

    #[test]
    fn invalid_worlds_are_refused_with_a_reason() {
        let err = |text: &str| World::from_yaml_str(text).unwrap_err().to_string();
        let e =
            err("obstacles:\n  - circle: { center: [0, 0], radius: 1 }\n  - circle: { center: [0, 0], radius: -1 }\n");
        assert!(e.contains("obstacle 1") && e.contains("radius -1"), "{e}");
        assert!(err("obstacles:\n  - circle: { center: [0, 0], radius: 0 }\n").contains("positive"));
        let e = err("obstacles:\n  - polygon: { points: [[0, 0], [1, 1]] }\n");
        assert!(e.contains("at least 3 points, got 2"), "{e}");
        assert!(err("obstacles:\n  - circle: { center: [.nan, 0], radius: 1 }\n").contains("finite"));
        assert!(err("obstacles:\n  - polygon: { points: [[0, 0], [1, .inf], [1, 1]] }\n").contains("finite"));
        assert!(err("obstacles:\n  - circle: { center: [0, 0], radius: .nan }\n").contains("finite"));
        // Finite but beyond ±1e6 m: 1e308 − (−1e308) would overflow.
        let e = err("obstacles:\n  - polygon: { points: [[-1e308, 0], [1e308, 0], [0, 1]] }\n");
        assert!(
            e.contains("obstacle 0") && e.contains("[-1e308, 0.0]") && e.contains("±1e6 m"),
            "{e}"
        );
        let e = err("obstacles:\n  - circle: { center: [0, 0], radius: 1.5e6 }\n");
        assert!(e.contains("radius 1500000") && e.contains("±1e6 m"), "{e}");
        assert!(World::from_yaml_str("obstacles:\n  - circle: { center: [-1e6, 1e6], radius: 1e6 }\n").is_ok());
        // Shape errors: not a list, an unknown kind, a misspelt field.
        assert!(err("obstacles: 3").contains("YAML"));
        assert!(err("obstacles:\n  - square: { side: 1 }\n").contains("YAML"));
        assert!(err("obstacles:\n  - circle: { centre: [0, 0], radius: 1 }\n").contains("YAML"));
        assert!(err("obstacle: []\n").contains("YAML"));
        // A file's errors name the file.
        let path = std::env::temp_dir().join(format!("mobil_world_test_{}.yaml", std::process::id()));
        std::fs::write(&path, "obstacles:\n  - circle: { center: [0, 0], radius: 0 }\n").unwrap();
        let e = World::load(&path).unwrap_err().to_string();
        let _ = std::fs::remove_file(&path);
        assert!(
            e.starts_with(&format!("world file {}: obstacle 0: ", path.display())),
            "{e}"
        );
        let e = World::load("/nonexistent/world.yaml").unwrap_err();
        assert!(matches!(e, WorldError::Read { .. }) && e.to_string().contains("/nonexistent/world.yaml"));
    }

    #[test]
    fn builtin_world_equals_the_shipped_file() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/worlds/default.yaml");
        assert_eq!(World::load(path).unwrap(), World::builtin());
        assert!(World::builtin().validate().is_ok());
    }

    #[test]
    fn builtin_room_by_hand() {
        let w = World::builtin();
        let o = Point2::origin();
        // The pillar at (1, 1.5), radius 0.3, is the nearest: √3.25 − 0.3 = 1.5028 m.
        assert!((w.distance_to(o) - (3.25f64.sqrt() - 0.3)).abs() < 1e-12);
        assert!(w.distance_to(o) >= 1.5);
        // East the box (x = 4.5), north and south the walls, west the wall (x = −5).
        for (angle, range) in [(0.0, 4.5), (FRAC_PI_2, 5.5), (PI, 5.0), (-FRAC_PI_2, 2.5)] {
            let r = w.ray_distance(o, angle, 20.0).unwrap();
            assert!((r - range).abs() < 1e-12, "angle {angle}: {r}");
        }
        // Room corners: the inner faces span 12 m × 8 m.
        let r = w.ray_distance(Point2::new(6.0, 0.0), 0.0, 20.0).unwrap();
        assert!((r - 1.0).abs() < 1e-12);
        let r = w.ray_distance(Point2::new(0.0, 5.0), -FRAC_PI_2, 20.0).unwrap();
        assert!((r - 7.5).abs() < 1e-12, "from y = 5 down to the wall at y = −2.5: {r}");
    }

    /// The demo loop: anticlockwise from (0, 0) facing east, straights and radius-1 m corners of
    /// the rounded rectangle x ∈ [−1, 3], y ∈ [0, 3] (2 m east, corner, 1 m north, corner, 2 m
    /// west, corner, 1 m south, corner). 1 m ≥ the 0.73 m minimum turning radius of MOBIL-II.
    fn demo_loop(samples_per_piece: usize) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for i in 0..=samples_per_piece {
            let s = i as f64 / samples_per_piece as f64;
            let a = s * FRAC_PI_2;
            out.extend([
                (2.0 * s, 0.0),
                (2.0 + a.sin(), 1.0 - a.cos()),
                (3.0, 1.0 + s),
                (2.0 + a.cos(), 2.0 + a.sin()),
                (2.0 - 2.0 * s, 3.0),
                (-a.sin(), 2.0 + a.cos()),
                (-1.0, 2.0 - s),
                (-a.cos(), 1.0 - a.sin()),
            ]);
        }
        out
    }

    #[test]
    fn builtin_world_leaves_the_demo_loop_clear() {
        let w = World::builtin();
        let route = demo_loop(200);
        // Consecutive samples are at most π/2/200 ≈ 7.9 mm apart on the arcs, 10 mm on the straights.
        let clearance = route
            .iter()
            .map(|&(x, y)| w.distance_to(Point2::new(x, y)))
            .fold(f64::INFINITY, f64::min);
        // MOBIL-II's footprint radius √(0.34² + 0.405²) = 0.529 m plus a 0.5 m margin.
        let footprint = 0.34f64.hypot(0.405);
        assert!(clearance > footprint + 0.5, "clearance {clearance}");
        // The tightest spot: (1, 0) and (1, 3), 1.5 m from the pillar's centre.
        assert!((clearance - 1.2).abs() < 1e-9, "clearance {clearance}");
        assert!(route.iter().any(|&(x, y)| x == 1.0 && y == 0.0));
        // And the loop is closed: it ends where it starts.
        let last = demo_loop(200)[8 * 201 - 1];
        assert!((last.0 - 0.0).abs() < 1e-12 && (last.1 - 0.0).abs() < 1e-12);
    }

    fn room_point() -> impl Strategy<Value = (f64, f64)> {
        (-4.9..6.9f64, -2.4..5.4f64)
    }

    proptest! {
        #[test]
        fn ray_hits_lie_on_a_surface_with_free_space_before_them(
            (x, y) in room_point(),
            angle in -PI..PI,
        ) {
            let w = World::builtin();
            let o = Point2::new(x, y);
            prop_assume!(w.distance_to(o) > 1e-6);
            // Inside the closed room every ray meets something within its 14.4 m diagonal.
            let t = w.ray_distance(o, angle, 20.0);
            prop_assert!(t.is_some());
            let t = t.unwrap_or_default();
            let d = Vector2::new(angle.cos(), angle.sin());
            prop_assert!(w.distance_to(o + d * t).abs() < 1e-9);
            prop_assert!(w.distance_to(o) <= t + 1e-12);
            for k in 1..20 {
                prop_assert!(w.distance_to(o + d * (t * k as f64 / 20.0)) > -1e-12);
            }
            // The bounding-box early-out never hides a hit.
            let brute = w.obstacles.iter().filter_map(|ob| ob.ray_hit(o, d)).fold(f64::INFINITY, f64::min);
            prop_assert_eq!(t, brute);
        }

        #[test]
        fn distance_is_one_lipschitz((x0, y0) in room_point(), (x1, y1) in room_point()) {
            let w = World::builtin();
            let (p, q) = (Point2::new(x0, y0), Point2::new(x1, y1));
            prop_assert!((w.distance_to(p) - w.distance_to(q)).abs() <= (p - q).norm() + 1e-12);
        }
    }
}
