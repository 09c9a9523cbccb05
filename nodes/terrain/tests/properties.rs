//! Algebraic identities of the assessment on random stances (feet within ±4 cm of their
//! footholds in x and y, within ±6 cm of −0.10 m in z).

use mobil_terrain::{Assessment, Assessor, HexapodGeometry, Leg, TerrainConfig};
use nalgebra::{Matrix3, Point3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

fn assessor() -> Assessor {
    Assessor::new(TerrainConfig::default()).unwrap()
}

fn stance() -> impl Strategy<Value = [Point3<f64>; 6]> {
    proptest::array::uniform6((-0.04..0.04f64, -0.04..0.04f64, -0.06..0.06f64)).prop_map(|d| {
        let mut feet = HexapodGeometry::default().standing_feet();
        for (f, (dx, dy, dz)) in feet.iter_mut().zip(d) {
            *f += Vector3::new(dx, dy, dz);
        }
        feet
    })
}

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w - 2.0 * PI
    } else {
        w
    }
}

/// A second method for the angle between two foot planes: each plane as z = p·x + q·y + r
/// (solved as a 3 × 3 linear system), normal (−p, −q, 1), then eq. 17 as printed with the
/// SPEC's absolute value, arccos(|N_i·N_j| / (|N_i||N_j|)).
fn alpha_by_eq17(a: &[Point3<f64>; 3], b: &[Point3<f64>; 3]) -> f64 {
    let normal = |p: &[Point3<f64>; 3]| {
        let m = Matrix3::new(p[0].x, p[0].y, 1.0, p[1].x, p[1].y, 1.0, p[2].x, p[2].y, 1.0);
        let s = m.lu().solve(&Vector3::new(p[0].z, p[1].z, p[2].z)).unwrap();
        Vector3::new(-s[0], -s[1], 1.0)
    };
    let (n1, n2) = (normal(a), normal(b));
    (n1.dot(&n2).abs() / (n1.norm() * n2.norm())).min(1.0).acos()
}

fn plane_feet(feet: &[Point3<f64>; 6], legs: [Leg; 3]) -> [Point3<f64>; 3] {
    legs.map(|l| feet[l.index()])
}

fn assess(feet: &[Point3<f64>; 6]) -> Assessment {
    assessor().assess(feet).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// α12 involves only the feet, so any rotation and translation of all six leaves it
    /// unchanged.
    #[test]
    fn a_rigid_motion_of_the_feet_leaves_alpha12(
        feet in stance(),
        axis in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        angle in -PI..PI,
        shift in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
    ) {
        let axis = Vector3::new(axis.0, axis.1, axis.2);
        prop_assume!(axis.norm() > 0.1);
        let r = Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle);
        let t = Vector3::new(shift.0, shift.1, shift.2);
        let moved = feet.map(|p| r * p + t);
        let (a, b) = (assess(&feet), assess(&moved));
        prop_assert!((a.alpha12 - b.alpha12).abs() < 1e-9, "{} vs {}", a.alpha12, b.alpha12);
    }

    /// σ is a spread of the z: shifting every foot by the same height changes no σ and no angle.
    #[test]
    fn a_vertical_shift_of_the_feet_leaves_sigma(feet in stance(), dz in -0.5..0.5f64) {
        let shifted = feet.map(|p| p + Vector3::new(0.0, 0.0, dz));
        let (a, b) = (assess(&feet), assess(&shifted));
        prop_assert!((a.sigma - b.sigma).abs() < 1e-12);
        prop_assert!((a.sigma_sample - b.sigma_sample).abs() < 1e-12);
        prop_assert!((a.alpha12 - b.alpha12).abs() < 1e-9);
        prop_assert!((a.alpha13 - b.alpha13).abs() < 1e-9);
        prop_assert!((a.alpha23 - b.alpha23).abs() < 1e-9);
    }

    /// Swapping which side is "left" (y → −y, and each leg takes its mirror's name) makes
    /// plane 1 the mirror image of plane 2 and back, for symmetric body points: the downhill
    /// direction and θ_y change sign, θ_x stays, α13 and α23 swap, α12, σ and the class stay.
    #[test]
    fn swapping_left_and_right_mirrors_the_downhill_direction(feet in stance()) {
        let mut mirrored = feet;
        for leg in Leg::ALL {
            let p = feet[leg.index()];
            mirrored[leg.mirrored().index()] = Point3::new(p.x, -p.y, p.z);
        }
        let (a, m) = (assess(&feet), assess(&mirrored));
        for (orig, mirror) in [(0, 1), (1, 0), (2, 2)] {
            let (p, q) = (a.planes[orig], m.planes[mirror]);
            prop_assert!(wrap(q.downhill + p.downhill).abs() < 1e-9, "{} vs {}", p.downhill, q.downhill);
            prop_assert!((q.theta_y + p.theta_y).abs() < 1e-9);
            prop_assert!((q.theta_x - p.theta_x).abs() < 1e-9);
        }
        prop_assert!((a.alpha12 - m.alpha12).abs() < 1e-9);
        prop_assert!((a.alpha13 - m.alpha23).abs() < 1e-9);
        prop_assert!((a.alpha23 - m.alpha13).abs() < 1e-9);
        prop_assert!((a.sigma - m.sigma).abs() < 1e-12);
        prop_assert_eq!(a.class, m.class);
    }

    /// The library's α12 (atan2 of cross and dot of the cross-product normals) equals eq. 17
    /// evaluated on normals found by solving for z = p·x + q·y + r; arccos near 0 is good to
    /// about 1e-8 rad, hence the tolerance.
    #[test]
    fn alpha12_agrees_with_eq17_by_a_second_method(feet in stance()) {
        let a = assess(&feet);
        let second = alpha_by_eq17(&plane_feet(&feet, Leg::PLANE1), &plane_feet(&feet, Leg::PLANE2));
        prop_assert!((a.alpha12 - second).abs() < 1e-7, "{} vs {}", a.alpha12, second);
        // Plane 3 is the xy-plane (normal (0, 0, 1)): α13 is plane 1's inclination.
        let n1 = {
            let p = plane_feet(&feet, Leg::PLANE1);
            (p[1] - p[0]).cross(&(p[2] - p[0]))
        };
        let incl = (n1.z.abs() / n1.norm()).min(1.0).acos();
        prop_assert!((a.alpha13 - incl).abs() < 1e-7);
    }

    /// Feet on a plane z = p·x + q·y + r, tripod B then raised by h: two parallel planes whose
    /// vertical gap is h, so their distance (unit normal (−p, −q, 1)/√(1 + p² + q²)) is
    /// |h| / √(1 + p² + q²); without the raise the six feet are coplanar, offset 0.
    #[test]
    fn a_raised_tripod_is_offset_by_its_raise_times_cos_tilt(
        p in -0.3..0.3f64,
        q in -0.3..0.3f64,
        r in -0.2..0.2f64,
        h in -0.05..0.05f64,
    ) {
        let on_plane = HexapodGeometry::default().standing_feet().map(|f| Point3::new(f.x, f.y, p * f.x + q * f.y + r));
        prop_assert!(assess(&on_plane).plane_offset < 1e-12);
        let mut raised = on_plane;
        for leg in Leg::PLANE2 {
            raised[leg.index()].z += h;
        }
        let a = assess(&raised);
        let expected = h.abs() / (1.0 + p * p + q * q).sqrt();
        prop_assert!((a.plane_offset - expected).abs() < 1e-12, "{} vs {expected}", a.plane_offset);
        prop_assert!(a.alpha12 < 1e-9);
    }

    /// No finite stance within range gives a NaN: either an error or finite numbers.
    #[test]
    fn finite_stances_give_finite_numbers(
        feet in proptest::array::uniform6((-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64)),
    ) {
        let feet = feet.map(|(x, y, z)| Point3::new(x, y, z));
        if let Ok(a) = assessor().assess(&feet) {
            let mut all = vec![a.sigma, a.sigma_sample, a.alpha12, a.alpha13, a.alpha23, a.tilt, a.plane_offset];
            for p in a.planes {
                all.extend([p.a, p.b, p.c, p.d, p.theta_x, p.theta_y, p.downhill]);
            }
            prop_assert!(all.iter().all(|v| v.is_finite()), "{a:?}");
            prop_assert!(a.alpha12 >= 0.0 && a.alpha12 <= PI / 2.0);
        }
    }
}
