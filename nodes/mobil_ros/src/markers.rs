//! RViz markers, built the same way by every node: a [`Markers`] builder for one frame and
//! stamp, one call per marker (a line, dots, a sphere, a disc, an arrow, a text), every marker
//! added with its pose's orientation the identity and its colour opaque unless given.
//!
//! ```
//! use mobil_ros::markers::{rgb, Markers};
//! use mobil_msgs::builtin_interfaces::msg::Time;
//! use mobil_msgs::visualization_msgs::msg::Marker;
//! use nalgebra::Point2;
//!
//! let mut m = Markers::replacing(Time::default(), "odom"); // a DELETEALL first
//! let route = [Point2::new(0.0, 0.0), Point2::new(1.0, 0.5)];
//! m.line_strip("route", 0, route.iter().copied(), 0.02, rgb(0.2, 0.6, 1.0));
//! m.sphere("goal", 0, Point2::new(1.0, 0.5), 0.15, rgb(0.0, 0.8, 0.0));
//! let array = m.array();
//! assert_eq!(array.markers.len(), 3);
//! assert_eq!(array.markers[0].action, Marker::DELETEALL);
//! assert_eq!((array.markers[1].points.len(), array.markers[2].pose.position.x), (2, 1.0));
//! ```

use crate::geometry::yaw_quaternion;
use mobil_geom::sketch::{Rgba, Shape, Sketch};
use mobil_geom::Pose2;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::{Point, Vector3};
use mobil_msgs::std_msgs::msg::{ColorRGBA, Header};
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use nalgebra::Point2;

/// An opaque colour.
pub fn rgb(r: f32, g: f32, b: f32) -> ColorRGBA {
    ColorRGBA { r, g, b, a: 1.0 }
}

/// A colour with its opacity.
pub fn rgba(r: f32, g: f32, b: f32, a: f32) -> ColorRGBA {
    ColorRGBA { r, g, b, a }
}

/// The message colour of a sketch's colour.
pub fn colour(c: Rgba) -> ColorRGBA {
    ColorRGBA {
        r: c.r,
        g: c.g,
        b: c.b,
        a: c.a,
    }
}

/// A point of the plane at height `z`.
pub fn point_at(p: Point2<f64>, z: f64) -> Point {
    Point { x: p.x, y: p.y, z }
}

/// A point of the plane (z = 0).
pub fn point(p: Point2<f64>) -> Point {
    point_at(p, 0.0)
}

/// A marker array under construction, every marker in one frame with one stamp.
#[derive(Debug, Clone)]
pub struct Markers {
    header: Header,
    markers: Vec<Marker>,
}

impl Markers {
    /// Markers in `frame` stamped `stamp`.
    pub fn new(stamp: Time, frame: &str) -> Self {
        Markers {
            header: Header {
                stamp,
                frame_id: frame.to_owned(),
            },
            markers: Vec::new(),
        }
    }

    /// Markers that replace everything drawn before: a DELETEALL with no namespace first (RViz 2
    /// then clears every marker its display got from the topic, of any namespace; one with a
    /// namespace clears only that one), so nothing stale stays.
    pub fn replacing(stamp: Time, frame: &str) -> Self {
        let mut m = Markers::new(stamp, frame);
        m.add("", 0, Marker::SPHERE, [0.0; 3], rgb(0.0, 0.0, 0.0)).action = Marker::DELETEALL;
        m
    }

    /// The markers added from now on are in `frame` (a node drawing in the robot's frame and
    /// in odom's, in one array).
    pub fn set_frame(&mut self, frame: &str) {
        self.header.frame_id = frame.to_owned();
    }

    /// Adds a marker of `kind` with its namespace, id, scale and colour, at the origin; the
    /// caller sets what else it needs.
    pub fn add(&mut self, ns: &str, id: i32, kind: i32, scale: [f64; 3], color: ColorRGBA) -> &mut Marker {
        let mut m = Marker {
            header: self.header.clone(),
            ns: ns.to_owned(),
            id,
            r#type: kind,
            action: Marker::ADD,
            color,
            scale: Vector3 {
                x: scale[0],
                y: scale[1],
                z: scale[2],
            },
            ..Default::default()
        };
        m.pose.orientation = yaw_quaternion(0.0);
        self.markers.push(m);
        let last = self.markers.len() - 1;
        &mut self.markers[last]
    }

    /// Removes the marker `ns`/`id` drawn before.
    pub fn delete(&mut self, ns: &str, id: i32) {
        self.add(ns, id, Marker::SPHERE, [0.0; 3], rgb(0.0, 0.0, 0.0)).action = Marker::DELETE;
    }

    /// A line through `points`, `width` wide.
    pub fn line_strip(
        &mut self,
        ns: &str,
        id: i32,
        points: impl IntoIterator<Item = Point2<f64>>,
        width: f64,
        color: ColorRGBA,
    ) -> &mut Marker {
        self.with_points(ns, id, Marker::LINE_STRIP, [width; 3], color, points)
    }

    /// Segments between `points` taken in pairs, `width` wide.
    pub fn line_list(
        &mut self,
        ns: &str,
        id: i32,
        points: impl IntoIterator<Item = Point2<f64>>,
        width: f64,
        color: ColorRGBA,
    ) -> &mut Marker {
        self.with_points(ns, id, Marker::LINE_LIST, [width; 3], color, points)
    }

    /// A dot of `diameter` at each of `points`.
    pub fn dots(
        &mut self,
        ns: &str,
        id: i32,
        points: impl IntoIterator<Item = Point2<f64>>,
        diameter: f64,
        color: ColorRGBA,
    ) -> &mut Marker {
        self.with_points(ns, id, Marker::SPHERE_LIST, [diameter; 3], color, points)
    }

    fn with_points(
        &mut self,
        ns: &str,
        id: i32,
        kind: i32,
        scale: [f64; 3],
        color: ColorRGBA,
        points: impl IntoIterator<Item = Point2<f64>>,
    ) -> &mut Marker {
        let m = self.add(ns, id, kind, scale, color);
        m.points = points.into_iter().map(point).collect();
        m
    }

    /// A sphere of `diameter` at `at`.
    pub fn sphere(&mut self, ns: &str, id: i32, at: Point2<f64>, diameter: f64, color: ColorRGBA) -> &mut Marker {
        let m = self.add(ns, id, Marker::SPHERE, [diameter; 3], color);
        m.pose.position = point(at);
        m
    }

    /// A flat disc of `radius`, `height` thick, centred at `at`.
    pub fn disc(
        &mut self,
        ns: &str,
        id: i32,
        at: Point2<f64>,
        (radius, height): (f64, f64),
        color: ColorRGBA,
    ) -> &mut Marker {
        let m = self.add(ns, id, Marker::CYLINDER, [2.0 * radius, 2.0 * radius, height], color);
        m.pose.position = point(at);
        m
    }

    /// An arrow at `pose` along its heading, `length` long and `width` wide.
    pub fn arrow(
        &mut self,
        ns: &str,
        id: i32,
        pose: &Pose2,
        (length, width): (f64, f64),
        color: ColorRGBA,
    ) -> &mut Marker {
        let m = self.add(ns, id, Marker::ARROW, [length, width, width], color);
        m.pose.position = point(pose.position());
        m.pose.orientation = yaw_quaternion(pose.yaw);
        m
    }

    /// `text`, `height` tall, facing the viewer at `at`, `z` above the ground.
    pub fn text(
        &mut self,
        ns: &str,
        id: i32,
        (at, z): (Point2<f64>, f64),
        height: f64,
        color: ColorRGBA,
        text: String,
    ) -> &mut Marker {
        let m = self.add(ns, id, Marker::TEXT_VIEW_FACING, [height; 3], color);
        m.pose.position = point_at(at, z);
        m.text = text;
        m
    }

    /// Adds every shape of `sketch`, in order, one marker each.
    pub fn sketch(&mut self, sketch: &Sketch) -> &mut Self {
        for item in &sketch.items {
            let (ns, id, c) = (item.ns, item.id, colour(item.colour));
            match &item.shape {
                Shape::Line { points, width } => self.line_strip(ns, id, points.iter().copied(), *width, c),
                Shape::Dots { points, diameter } => self.dots(ns, id, points.iter().copied(), *diameter, c),
                Shape::Sphere { at, diameter } => self.sphere(ns, id, *at, *diameter, c),
                Shape::Disc { at, radius, height } => self.disc(ns, id, *at, (*radius, *height), c),
                Shape::Arrow { pose, length, width } => self.arrow(ns, id, pose, (*length, *width), c),
                Shape::Text { at, z, height, text } => self.text(ns, id, (*at, *z), *height, c, text.clone()),
            };
        }
        self
    }

    /// The markers added so far.
    pub fn len(&self) -> usize {
        self.markers.len()
    }

    /// Whether none was added.
    pub fn is_empty(&self) -> bool {
        self.markers.is_empty()
    }

    /// The array to publish.
    pub fn array(self) -> MarkerArray {
        MarkerArray { markers: self.markers }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_marker_has_its_kind_scale_place_and_the_header() {
        let stamp = Time { sec: 3, nanosec: 5 };
        let mut m = Markers::new(stamp.clone(), "odom");
        assert!(m.is_empty());
        m.disc(
            "zone",
            2,
            Point2::new(1.0, -1.0),
            (0.4, 0.05),
            rgba(1.0, 0.9, 0.2, 0.25),
        );
        m.arrow("dock", 0, &Pose2::new(2.0, 1.0, 0.5), (0.4, 0.06), rgb(1.0, 0.5, 0.0));
        m.text(
            "why",
            1,
            (Point2::new(0.5, 0.5), 0.3),
            0.12,
            rgb(1.0, 1.0, 1.0),
            "waypoint 1".into(),
        );
        m.delete("goal", 4);
        assert_eq!(m.len(), 4);
        let a = m.array();
        let (disc, arrow, text, gone) = (&a.markers[0], &a.markers[1], &a.markers[2], &a.markers[3]);
        assert!(a
            .markers
            .iter()
            .all(|k| k.header.frame_id == "odom" && k.header.stamp == stamp));
        // A disc of radius 0.4: a cylinder 0.8 across, at its centre.
        assert_eq!(
            (disc.r#type, disc.scale.x, disc.scale.y, disc.scale.z),
            (Marker::CYLINDER, 0.8, 0.8, 0.05)
        );
        assert_eq!(
            (disc.pose.position.x, disc.pose.position.y, disc.color.a),
            (1.0, -1.0, 0.25)
        );
        // The arrow along yaw 0.5: q = (0, 0, sin 0.25, cos 0.25).
        assert_eq!((arrow.scale.x, arrow.scale.y), (0.4, 0.06));
        assert!((arrow.pose.orientation.z - 0.25f64.sin()).abs() < 1e-12);
        assert_eq!(
            (text.pose.position.z, text.text.as_str(), text.ns.as_str()),
            (0.3, "waypoint 1", "why")
        );
        assert_eq!((gone.action, gone.ns.as_str(), gone.id), (Marker::DELETE, "goal", 4));
        assert!(a.markers.iter().take(3).all(|k| k.action == Marker::ADD));
    }

    #[test]
    fn a_sketch_draws_the_markers_its_shapes_name() {
        let (stamp, blue) = (Time { sec: 1, nanosec: 2 }, Rgba::rgb(0.2, 0.6, 1.0));
        let route = vec![Point2::new(0.0, 0.0), Point2::new(1.0, 0.5)];
        let mut s = Sketch::default();
        s.line("route", 0, route.clone(), 0.02, blue);
        s.dots("route", 1, route.clone(), 0.12, blue);
        s.sphere("p", 0, Point2::new(1.0, 0.0), 0.2, Rgba::rgb(0.9, 0.0, 0.0));
        s.disc(
            "z",
            4,
            Point2::new(2.0, 0.0),
            (0.4, 0.05),
            Rgba::new(1.0, 0.9, 0.2, 0.25),
        );
        s.arrow(
            "dock",
            0,
            Pose2::new(1.0, 2.0, 0.5),
            (0.4, 0.06),
            Rgba::rgb(1.0, 0.5, 0.0),
        );
        s.text(
            "t",
            1,
            (Point2::new(0.5, 0.5), 0.3),
            0.12,
            Rgba::rgb(1.0, 1.0, 1.0),
            "w".into(),
        );
        let mut drawn = Markers::new(stamp.clone(), "odom");
        drawn.sketch(&s);
        let mut by_hand = Markers::new(stamp, "odom");
        by_hand.line_strip("route", 0, route.iter().copied(), 0.02, rgb(0.2, 0.6, 1.0));
        by_hand.dots("route", 1, route, 0.12, rgb(0.2, 0.6, 1.0));
        by_hand.sphere("p", 0, Point2::new(1.0, 0.0), 0.2, rgb(0.9, 0.0, 0.0));
        by_hand.disc("z", 4, Point2::new(2.0, 0.0), (0.4, 0.05), rgba(1.0, 0.9, 0.2, 0.25));
        by_hand.arrow("dock", 0, &Pose2::new(1.0, 2.0, 0.5), (0.4, 0.06), rgb(1.0, 0.5, 0.0));
        by_hand.text(
            "t",
            1,
            (Point2::new(0.5, 0.5), 0.3),
            0.12,
            rgb(1.0, 1.0, 1.0),
            "w".into(),
        );
        assert_eq!(drawn.array(), by_hand.array());
    }
}
