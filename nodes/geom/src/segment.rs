//! The point of a segment nearest a point: what a polyline's projection, a segment's distance
//! and a swept circle's (a capsule's) test are made of.
//!
//! ```
//! use mobil_geom::segment::nearest_on_segment;
//! use nalgebra::Point2;
//! let (q, t) = nearest_on_segment(Point2::new(0.0, 0.0), Point2::new(4.0, 0.0), Point2::new(1.0, 2.0));
//! assert_eq!((q, t), (Point2::new(1.0, 0.0), 0.25));
//! ```

use nalgebra::Point2;

/// The point of segment ab nearest `p`, and its parameter t in [0, 1] (a + t·(b − a)); a
/// segment of zero length gives a, t = 0.
pub fn nearest_on_segment(a: Point2<f64>, b: Point2<f64>, p: Point2<f64>) -> (Point2<f64>, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t, t)
}

/// The distance from `p` to segment ab.
pub fn segment_distance(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    (p - nearest_on_segment(a, b, p).0).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Beyond either end the end is nearest; a point segment is its own nearest point.
    #[test]
    fn ends_hold_and_a_point_segment_works() {
        let (a, b) = (Point2::new(1.0, 1.0), Point2::new(3.0, 1.0));
        assert_eq!(nearest_on_segment(a, b, Point2::new(0.0, 0.0)), (a, 0.0));
        assert_eq!(nearest_on_segment(a, b, Point2::new(5.0, 2.0)), (b, 1.0));
        assert_eq!(nearest_on_segment(a, a, Point2::new(5.0, 2.0)), (a, 0.0));
        // (2, 4) is 3 above the middle.
        assert_eq!(segment_distance(Point2::new(2.0, 4.0), a, b), 3.0);
        // (4, 5): 5 from b, the 3-4-5 triangle.
        assert_eq!(segment_distance(Point2::new(6.0, 5.0), a, b), 5.0);
    }
}
