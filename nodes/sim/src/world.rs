//! A 2D world of obstacles (circles and polygons), read from YAML or built in.
//!
//! ```yaml
//! obstacles:
//!   - circle: { center: [2.0, 1.0], radius: 0.3 }
//!   - polygon: { points: [[0, 0], [1, 0], [1, 1]] }
//! ```

use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// One obstacle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Obstacle {
    /// A disc.
    Circle { center: [f64; 2], radius: f64 },
    /// A closed simple polygon (the last point connects to the first).
    Polygon { points: Vec<[f64; 2]> },
}

/// The world: a list of obstacles.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct World {
    /// The obstacles; in YAML each is a one-key map (`circle: {…}` or `polygon: {…}`).
    #[serde(with = "serde_norway::with::singleton_map_recursive")]
    pub obstacles: Vec<Obstacle>,
}

/// A world that could not be read.
#[derive(Debug, Error)]
pub enum WorldError {
    #[error("cannot read world file {path}: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("world is not valid YAML: {0}")]
    Yaml(#[from] serde_norway::Error),
    #[error("obstacle {index}: {reason}")]
    Invalid { index: usize, reason: String },
}

fn segment_distance(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Distance along a ray (origin o, unit direction d) to segment ab, if it hits.
fn ray_segment(o: Point2<f64>, d: Vector2<f64>, a: Point2<f64>, b: Point2<f64>) -> Option<f64> {
    let e = b - a;
    let denom = d.perp(&e);
    if denom.abs() < 1e-15 {
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
        (0..n).map(move |i| {
            let a = points[i];
            let b = points[(i + 1) % n];
            (Point2::new(a[0], a[1]), Point2::new(b[0], b[1]))
        })
    }

    fn check(&self) -> Result<(), String> {
        match self {
            Obstacle::Circle { center, radius } => {
                if !(center.iter().all(|c| c.is_finite()) && radius.is_finite()) {
                    return Err("non-finite circle".into());
                }
                if *radius <= 0.0 {
                    return Err(format!("radius {radius} must be positive"));
                }
            }
            Obstacle::Polygon { points } => {
                if points.len() < 3 {
                    return Err(format!("a polygon needs at least 3 points, got {}", points.len()));
                }
                if points.iter().flatten().any(|c| !c.is_finite()) {
                    return Err("non-finite polygon point".into());
                }
            }
        }
        Ok(())
    }

    /// Whether a point lies inside (or on) the obstacle.
    pub fn contains(&self, p: Point2<f64>) -> bool {
        match self {
            Obstacle::Circle { center, radius } => (p - Point2::new(center[0], center[1])).norm() <= *radius,
            Obstacle::Polygon { points } => {
                // Even-odd rule.
                let mut inside = false;
                for (a, b) in Self::edges(points) {
                    if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                        inside = !inside;
                    }
                }
                inside
            }
        }
    }

    /// Distance from a point to the obstacle's boundary (0 on it; positive inside too).
    pub fn boundary_distance(&self, p: Point2<f64>) -> f64 {
        match self {
            Obstacle::Circle { center, radius } => ((p - Point2::new(center[0], center[1])).norm() - radius).abs(),
            Obstacle::Polygon { points } => Self::edges(points)
                .map(|(a, b)| segment_distance(p, a, b))
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Nearest hit of a ray (origin, unit direction) with the boundary.
    pub fn ray_hit(&self, o: Point2<f64>, d: Vector2<f64>) -> Option<f64> {
        match self {
            Obstacle::Circle { center, radius } => ray_circle(o, d, Point2::new(center[0], center[1]), *radius),
            Obstacle::Polygon { points } => Self::edges(points)
                .filter_map(|(a, b)| ray_segment(o, d, a, b))
                .min_by(f64::total_cmp),
        }
    }
}

impl World {
    /// Parses a world from YAML text, refusing invalid geometry.
    pub fn from_yaml_str(text: &str) -> Result<World, WorldError> {
        let world: World = serde_norway::from_str(text)?;
        for (index, o) in world.obstacles.iter().enumerate() {
            o.check().map_err(|reason| WorldError::Invalid { index, reason })?;
        }
        Ok(world)
    }

    /// Reads a world file.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<World, WorldError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| WorldError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_yaml_str(&text)
    }

    /// The built-in world (also `params/worlds/default.yaml`): a 12 m × 8 m walled room around the
    /// origin with pillars, a box and an L-shaped block, leaving a clear 4 m × 3 m loop
    /// (x ∈ [−1, 3], y ∈ [0, 3]) with at least 0.5 m margin for a car-like robot.
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
                // Pillars.
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

    /// Nearest hit of a ray from `origin` at `angle` within `max_range`.
    pub fn ray_distance(&self, origin: Point2<f64>, angle: f64, max_range: f64) -> Option<f64> {
        let d = Vector2::new(angle.cos(), angle.sin());
        self.obstacles
            .iter()
            .filter_map(|o| o.ray_hit(origin, d))
            .filter(|t| *t <= max_range)
            .min_by(f64::total_cmp)
    }

    /// Signed distance to the nearest obstacle surface: negative inside an obstacle.
    pub fn distance_to(&self, p: Point2<f64>) -> f64 {
        self.obstacles
            .iter()
            .map(|o| {
                if o.contains(p) {
                    -o.boundary_distance(p)
                } else {
                    o.boundary_distance(p)
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether a disc of `radius` at `p` touches any obstacle.
    pub fn collides(&self, p: Point2<f64>, radius: f64) -> bool {
        self.distance_to(p) < radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn ray_hits_by_hand() {
        let w = World::from_yaml_str(
            "obstacles:\n  - polygon: { points: [[3, -10], [4, -10], [4, 10], [3, 10]] }\n  - circle: { center: [-2, 0], radius: 0.5 }\n",
        )
        .unwrap();
        let o = Point2::origin();
        assert!((w.ray_distance(o, 0.0, 10.0).unwrap() - 3.0).abs() < 1e-12);
        assert!((w.ray_distance(o, PI / 4.0, 10.0).unwrap() - 3.0 * 2f64.sqrt()).abs() < 1e-12);
        assert!((w.ray_distance(o, PI, 10.0).unwrap() - 1.5).abs() < 1e-12);
        assert_eq!(w.ray_distance(o, PI / 2.0, 10.0), None);
        assert_eq!(w.ray_distance(o, 0.0, 2.9), None);
        assert!((w.distance_to(Point2::new(0.0, 0.0)) - 1.5).abs() < 1e-12);
        assert!(w.distance_to(Point2::new(3.5, 0.0)) < 0.0);
        assert!(w.collides(Point2::new(2.6, 0.0), 0.5));
        assert!(!w.collides(Point2::new(2.4, 0.0), 0.5));
    }

    #[test]
    fn invalid_worlds_are_refused() {
        assert!(World::from_yaml_str("obstacles:\n  - circle: { center: [0, 0], radius: -1 }\n").is_err());
        assert!(World::from_yaml_str("obstacles:\n  - polygon: { points: [[0, 0], [1, 1]] }\n").is_err());
        assert!(World::from_yaml_str("obstacles:\n  - circle: { center: [.nan, 0], radius: 1 }\n").is_err());
        assert!(World::from_yaml_str("obstacles: 3").is_err());
        assert!(World::load("/nonexistent/world.yaml").is_err());
    }

    #[test]
    fn builtin_world_equals_the_shipped_file_and_leaves_the_loop_clear() {
        let file = World::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/worlds/default.yaml")).unwrap();
        assert_eq!(file, World::builtin());
        // The demo loop: straights and radius-1 m corners of the box x ∈ [−1, 3], y ∈ [0, 3].
        let w = World::builtin();
        let mut samples = Vec::new();
        for i in 0..=100 {
            let s = i as f64 / 100.0;
            samples.push((2.0 * s, 0.0));
            samples.push((3.0, 1.0 + s));
            samples.push((2.0 - 2.0 * s, 3.0));
            samples.push((-1.0, 2.0 - s));
            let a = s * PI / 2.0;
            samples.push((2.0 + a.sin(), 1.0 - a.cos()));
            samples.push((2.0 + a.cos(), 2.0 + a.sin()));
            samples.push((-a.sin(), 2.0 + a.cos()));
            samples.push((-a.cos(), 1.0 - a.sin()));
        }
        for (x, y) in samples {
            assert!(w.distance_to(Point2::new(x, y)) > 0.5 + 0.53, "({x}, {y}) too close");
        }
    }
}
