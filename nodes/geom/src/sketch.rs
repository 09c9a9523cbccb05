//! What a node draws, ROS-free: a [`Sketch`] is a list of named, numbered shapes in the plane
//! (lines, dots, spheres, discs, arrows, texts), each with its colour. A law crate decides what
//! to show and how much of it (the budgets of a marker array are decisions, tested without
//! DDS); the ROS kit turns the sketch into RViz markers, one marker per shape.
//!
//! ```
//! use mobil_geom::sketch::{Rgba, Shape, Sketch};
//! use nalgebra::Point2;
//!
//! let mut s = Sketch::default();
//! s.line("route", 0, vec![Point2::new(0.0, 0.0), Point2::new(1.0, 0.5)], 0.02, Rgba::rgb(0.2, 0.6, 1.0));
//! s.sphere("goal", 0, Point2::new(1.0, 0.5), 0.15, Rgba::rgb(0.0, 0.8, 0.0));
//! assert_eq!(s.items.len(), 2);
//! assert_eq!(s.points(), 2);
//! assert!(matches!(s.items[1].shape, Shape::Sphere { diameter, .. } if diameter == 0.15));
//! ```

use crate::Pose2;
use nalgebra::Point2;

/// A colour and its opacity, each in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rgba {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity.
    pub a: f32,
}

impl Rgba {
    /// An opaque colour.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        Rgba { r, g, b, a: 1.0 }
    }

    /// A colour with its opacity.
    pub const fn new(r: f32, g: f32, b: f32, a: f32) -> Self {
        Rgba { r, g, b, a }
    }
}

/// One shape in the plane.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A line through `points`, `width` wide.
    Line {
        /// Its vertices, in order.
        points: Vec<Point2<f64>>,
        /// Its width.
        width: f64,
    },
    /// A dot of `diameter` at each of `points`.
    Dots {
        /// The dots' centres.
        points: Vec<Point2<f64>>,
        /// Their diameter.
        diameter: f64,
    },
    /// A sphere of `diameter` at `at`.
    Sphere {
        /// Its centre.
        at: Point2<f64>,
        /// Its diameter.
        diameter: f64,
    },
    /// A flat disc of `radius`, `height` thick, centred at `at`.
    Disc {
        /// Its centre.
        at: Point2<f64>,
        /// Its radius.
        radius: f64,
        /// Its thickness.
        height: f64,
    },
    /// An arrow at `pose` along its heading, `length` long and `width` wide.
    Arrow {
        /// Its tail and heading.
        pose: Pose2,
        /// Its length.
        length: f64,
        /// Its width.
        width: f64,
    },
    /// `text`, `height` tall, facing the viewer at `at`, `z` above the ground.
    Text {
        /// Where it stands.
        at: Point2<f64>,
        /// Its height above the ground.
        z: f64,
        /// The letters' height.
        height: f64,
        /// What it says.
        text: String,
    },
}

/// A shape with its namespace and id (a later sketch's item of the same pair replaces it) and
/// its colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    /// The namespace.
    pub ns: &'static str,
    /// The id within the namespace.
    pub id: i32,
    /// The shape.
    pub shape: Shape,
    /// Its colour.
    pub colour: Rgba,
}

/// Shapes to draw, in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sketch {
    /// The shapes, in the order they are drawn.
    pub items: Vec<Item>,
}

impl Sketch {
    /// Adds `shape` as `ns`/`id` in `colour`.
    pub fn add(&mut self, ns: &'static str, id: i32, shape: Shape, colour: Rgba) {
        self.items.push(Item { ns, id, shape, colour });
    }

    /// A line through `points`, `width` wide.
    pub fn line(&mut self, ns: &'static str, id: i32, points: Vec<Point2<f64>>, width: f64, colour: Rgba) {
        self.add(ns, id, Shape::Line { points, width }, colour);
    }

    /// A dot of `diameter` at each of `points`.
    pub fn dots(&mut self, ns: &'static str, id: i32, points: Vec<Point2<f64>>, diameter: f64, colour: Rgba) {
        self.add(ns, id, Shape::Dots { points, diameter }, colour);
    }

    /// A sphere of `diameter` at `at`.
    pub fn sphere(&mut self, ns: &'static str, id: i32, at: Point2<f64>, diameter: f64, colour: Rgba) {
        self.add(ns, id, Shape::Sphere { at, diameter }, colour);
    }

    /// A flat disc of `radius`, `height` thick, at `at`.
    pub fn disc(&mut self, ns: &'static str, id: i32, at: Point2<f64>, (radius, height): (f64, f64), colour: Rgba) {
        self.add(ns, id, Shape::Disc { at, radius, height }, colour);
    }

    /// An arrow at `pose`, `length` long and `width` wide.
    pub fn arrow(&mut self, ns: &'static str, id: i32, pose: Pose2, (length, width): (f64, f64), colour: Rgba) {
        self.add(ns, id, Shape::Arrow { pose, length, width }, colour);
    }

    /// `text`, `height` tall, at `at`, `z` above the ground.
    pub fn text(
        &mut self,
        ns: &'static str,
        id: i32,
        (at, z): (Point2<f64>, f64),
        height: f64,
        colour: Rgba,
        text: String,
    ) {
        self.add(ns, id, Shape::Text { at, z, height, text }, colour);
    }

    /// The points of every line and dot list together (each one costs a marker array 24 bytes).
    pub fn points(&self) -> usize {
        self.items
            .iter()
            .map(|i| match &i.shape {
                Shape::Line { points, .. } | Shape::Dots { points, .. } => points.len(),
                _ => 0,
            })
            .sum()
    }
}

/// An `i32` id of index `i` (saturating: an id past `i32::MAX` is never reached by a budget).
pub fn id(i: usize) -> i32 {
    i32::try_from(i).unwrap_or(i32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_keep_their_order_names_and_colours() {
        let mut s = Sketch::default();
        s.dots("a", 3, vec![Point2::new(0.0, 0.0); 4], 0.1, Rgba::rgb(1.0, 0.0, 0.0));
        s.arrow(
            "b",
            0,
            Pose2::new(1.0, 2.0, 0.5),
            (0.4, 0.06),
            Rgba::new(0.0, 0.0, 1.0, 0.5),
        );
        s.text(
            "c",
            1,
            (Point2::new(1.0, 1.0), 0.3),
            0.12,
            Rgba::rgb(1.0, 1.0, 1.0),
            "x".into(),
        );
        assert_eq!(
            s.items.iter().map(|i| (i.ns, i.id)).collect::<Vec<_>>(),
            [("a", 3), ("b", 0), ("c", 1)]
        );
        assert_eq!(s.items[1].colour.a, 0.5);
        assert_eq!(s.points(), 4);
        assert_eq!((id(7), id(usize::MAX)), (7, i32::MAX));
    }
}
