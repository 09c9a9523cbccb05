//! 2D poses (SE(2)) and frame composition.

use crate::angle::wrap;
use nalgebra::{Point2, Vector2, Vector3};
use std::ops::Mul;

/// A planar pose: position (x, y) and heading `yaw` (rad, wrapped to (−π, π] by every
/// operation), of a child frame in a parent frame. As a transform it maps points from the child
/// to the parent: name it `parent_from_child`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose2 {
    /// x of the child's origin in the parent (m).
    pub x: f64,
    /// y of the child's origin in the parent (m).
    pub y: f64,
    /// Heading of the child's x axis in the parent (rad).
    pub yaw: f64,
}

impl Pose2 {
    /// A pose; `yaw` is wrapped to (−π, π].
    pub fn new(x: f64, y: f64, yaw: f64) -> Self {
        Pose2 { x, y, yaw: wrap(yaw) }
    }

    /// The identity (child frame = parent frame).
    pub fn identity() -> Self {
        Pose2::default()
    }

    /// The pose of three finite values `[x, y, yaw]` (a parameter's list); `None` for any
    /// other length or a non-finite value.
    pub fn from_values(values: &[f64]) -> Option<Self> {
        match values {
            [x, y, yaw] if x.is_finite() && y.is_finite() && yaw.is_finite() => Some(Pose2::new(*x, *y, *yaw)),
            _ => None,
        }
    }

    /// Whether x, y and yaw are all finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.yaw.is_finite()
    }

    /// The position as a point.
    pub fn position(&self) -> Point2<f64> {
        Point2::new(self.x, self.y)
    }

    /// `a_from_c = a_from_b.compose(b_from_c)`: the child's child in this pose's parent.
    pub fn compose(&self, child: &Pose2) -> Pose2 {
        let p = self.transform_point(child.position());
        Pose2::new(p.x, p.y, self.yaw + child.yaw)
    }

    /// `child_from_parent` from `parent_from_child`.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.yaw.sin_cos();
        Pose2::new(-c * self.x - s * self.y, s * self.x - c * self.y, -self.yaw)
    }

    /// A point given in the child frame, in the parent frame.
    pub fn transform_point(&self, p: Point2<f64>) -> Point2<f64> {
        Point2::new(self.x, self.y) + self.rotate(p.coords)
    }

    /// A vector given in the child frame, rotated into the parent frame.
    pub fn rotate(&self, v: Vector2<f64>) -> Vector2<f64> {
        let (s, c) = self.yaw.sin_cos();
        Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
    }

    /// The pose `d` ahead along the child's own x axis, same heading (a point on the robot's
    /// centre line, e.g. the reference point ahead of the kinematic origin; `d < 0` is behind).
    pub fn ahead(&self, d: f64) -> Pose2 {
        let (s, c) = self.yaw.sin_cos();
        Pose2 {
            x: self.x + d * c,
            y: self.y + d * s,
            yaw: self.yaw,
        }
    }

    /// `[x, y, yaw]` as a vector (the layout of the odometry and plant states).
    pub fn to_vector(&self) -> Vector3<f64> {
        Vector3::new(self.x, self.y, self.yaw)
    }

    /// From `[x, y, yaw]`; yaw is wrapped.
    pub fn from_vector(v: &Vector3<f64>) -> Self {
        Pose2::new(v.x, v.y, v.z)
    }
}

impl Mul for Pose2 {
    type Output = Pose2;

    /// Composition: `a_from_b * b_from_c = a_from_c`.
    fn mul(self, rhs: Pose2) -> Pose2 {
        self.compose(&rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn composition_by_hand() {
        // base at (2, 1) facing +y; laser 0.5 ahead and 0.1 left of base, turned by −90°.
        let odom_from_base = Pose2::new(2.0, 1.0, FRAC_PI_2);
        let base_from_laser = Pose2::new(0.5, 0.1, -FRAC_PI_2);
        let odom_from_laser = odom_from_base * base_from_laser;
        // Rot(90°)·(0.5, 0.1) = (−0.1, 0.5); + (2, 1) = (1.9, 1.5); yaw 90° − 90° = 0.
        assert_relative_eq!(odom_from_laser.x, 1.9, epsilon = 1e-12);
        assert_relative_eq!(odom_from_laser.y, 1.5, epsilon = 1e-12);
        assert_relative_eq!(odom_from_laser.yaw, 0.0, epsilon = 1e-12);
        // Headings wrap: 170° + 20° = −170°.
        let turned = Pose2::new(0.0, 0.0, 170f64.to_radians()) * Pose2::new(0.0, 0.0, 20f64.to_radians());
        assert_relative_eq!(turned.yaw, (-170f64).to_radians(), epsilon = 1e-12);
        assert_eq!(Pose2::new(0.0, 0.0, -PI).yaw, PI);
    }

    #[test]
    fn inverse_and_points_by_hand() {
        // A frame at (1, 0) turned 90° (its x is the parent's +y): the parent's origin, 1 m
        // along the parent's −x from it, lies 1 m to its left, at (0, 1).
        let inv = Pose2::new(1.0, 0.0, FRAC_PI_2).inverse();
        assert_relative_eq!(inv.x, 0.0, epsilon = 1e-12);
        assert_relative_eq!(inv.y, 1.0, epsilon = 1e-12);
        assert_relative_eq!(inv.yaw, -FRAC_PI_2, epsilon = 1e-12);
        // The point 2 m ahead of a frame at (1, 1) facing 45° is at (1 + √2, 1 + √2).
        let p = Pose2::new(1.0, 1.0, PI / 4.0).transform_point(Point2::new(2.0, 0.0));
        assert_relative_eq!(p.x, 1.0 + 2f64.sqrt(), epsilon = 1e-12);
        assert_relative_eq!(p.y, 1.0 + 2f64.sqrt(), epsilon = 1e-12);
        // 0.3 m ahead of a robot at the origin facing −90° is (0, −0.3).
        let a = Pose2::new(0.0, 0.0, -FRAC_PI_2).ahead(0.3);
        assert_relative_eq!(a.x, 0.0, epsilon = 1e-12);
        assert_relative_eq!(a.y, -0.3, epsilon = 1e-12);
    }

    fn pose() -> impl Strategy<Value = Pose2> {
        (-50.0..50.0f64, -50.0..50.0f64, -10.0..10.0f64).prop_map(|(x, y, yaw)| Pose2::new(x, y, yaw))
    }

    fn close(a: &Pose2, b: &Pose2) -> bool {
        (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9 && wrap(a.yaw - b.yaw).abs() < 1e-9
    }

    proptest! {
        #[test]
        fn composition_is_associative_and_inverse_cancels(a in pose(), b in pose(), c in pose()) {
            prop_assert!(close(&((a * b) * c), &(a * (b * c))));
            prop_assert!(close(&(a * a.inverse()), &Pose2::identity()));
            prop_assert!(close(&(a.inverse() * a), &Pose2::identity()));
            // Mapping a point through a composition equals mapping it twice.
            let p = Point2::new(b.x, c.y);
            prop_assert!(((a * b).transform_point(p) - a.transform_point(b.transform_point(p))).norm() < 1e-9);
        }
    }
}
