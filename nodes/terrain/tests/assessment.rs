//! The assessment on hand-made stances: a tilted plane, a step between the tripods, beyond the
//! limits, degenerate input, and the foot tracker. Expected numbers are worked out in the
//! comments from the geometry, not from the library.

use mobil_terrain::{
    Assessor, FootTracker, Gait, HexapodGeometry, Leg, PlaneId, TerrainClass, TerrainConfig, TerrainError,
};
use nalgebra::Point3;
use std::f64::consts::PI;

fn assessor() -> Assessor {
    Assessor::new(TerrainConfig::default()).unwrap()
}

/// The default footholds on z = −0.10 + tan(slope)·(x cos φ + y sin φ): a plane rising toward
/// φ in the body frame.
fn on_plane(slope_deg: f64, uphill_deg: f64) -> [Point3<f64>; 6] {
    let (t, phi) = (slope_deg.to_radians().tan(), uphill_deg.to_radians());
    HexapodGeometry::default()
        .standing_feet()
        .map(|p| Point3::new(p.x, p.y, -0.10 + t * (p.x * phi.cos() + p.y * phi.sin())))
}

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w - 2.0 * PI
    } else {
        w
    }
}

/// On a plane z = p·x + q·y + r the normal is (−p, −q, 1): θ_x = atan2(−p, 1),
/// θ_y = atan2(−q, 1), downhill = atan2(−q, −p) = φ + π (the ground falls opposite to where it
/// rises). The feet are coplanar (α12 = 0) and both foot planes make the slope's angle with the
/// body's xy-plane (α13 = α23 = slope). σ = tan(slope)·√(var_x cos²φ + var_y sin²φ) with the
/// footholds' var_x = 0.015, var_y = 0.018133 m², covariance 0: 2.1596 cm for 10° along x.
#[test]
fn a_tilted_plane_is_slope_with_its_downhill_direction() {
    let a = assessor();
    for uphill in [0.0, 90.0, 135.0, -60.0, 180.0] {
        let feet = on_plane(10.0, uphill);
        let r = a.assess(&feet).unwrap();
        let phi = f64::to_radians(uphill);
        let t = 10f64.to_radians().tan();
        let (p, q) = (t * phi.cos(), t * phi.sin());
        assert!(r.alpha12 < 1e-9, "α12 {}", r.alpha12);
        for alpha in [r.alpha13, r.alpha23, r.tilt] {
            assert!((alpha - 10f64.to_radians()).abs() < 1e-9, "uphill {uphill}: {alpha}");
        }
        for plane in &r.planes[..2] {
            assert!((plane.theta_x - (-p).atan2(1.0)).abs() < 1e-9);
            assert!((plane.theta_y - (-q).atan2(1.0)).abs() < 1e-9);
            assert!(
                wrap(plane.downhill - (phi + PI)).abs() < 1e-9,
                "uphill {uphill}: {}",
                plane.downhill
            );
            assert!(plane.c > 0.0);
        }
        let sigma = t * (0.015 * phi.cos().powi(2) + 0.018_133_333_333 * phi.sin().powi(2)).sqrt();
        assert!((r.sigma - sigma).abs() < 1e-9, "σ {} vs {sigma}", r.sigma);
        assert_eq!(r.class, TerrainClass::Slope, "uphill {uphill}");
        // σ = 2.16–2.37 cm ≤ σ_wave (2.5 cm): the ripple gait.
        assert_eq!(r.advice, Gait::Ripple);
    }
    let r = a.assess(&on_plane(10.0, 0.0)).unwrap();
    assert!((r.sigma - 0.021_596).abs() < 1e-6);
    // The body plane is the xy-plane: a = b = 0, c = 1, d = 0; downhill atan2(0, 0) = 0.
    let p3 = r.planes[2];
    assert_eq!((p3.a, p3.b, p3.c, p3.d, p3.downhill), (0.0, 0.0, 1.0, 0.0, 0.0));
}

/// A 2° plane is within ε_α (3°) and its σ (at most 0.1347 · tan 2° = 0.47 cm) within σ_flat:
/// FLAT. 8° along x: σ = 0.1225 · tan 8° = 1.72 cm ≤ σ_wave: SLOPE, ripple.
#[test]
fn gentle_tilts_are_flat_and_moderate_ones_slope() {
    let a = assessor();
    let r = a.assess(&on_plane(2.0, 90.0)).unwrap();
    assert_eq!((r.class, r.advice), (TerrainClass::Flat, Gait::Tripod));
    let r = a.assess(&on_plane(8.0, 0.0)).unwrap();
    assert!((r.sigma - 0.122_474 * 8f64.to_radians().tan()).abs() < 1e-6);
    assert_eq!((r.class, r.advice), (TerrainClass::Slope, Gait::Ripple));
}

/// Tripod A level at −0.10 m, tripod B level at −0.13 m: every angle 0, σ = 1.5 cm (three
/// feet 1.5 cm above the mean −0.115, three below); the planes z = −0.10 and z = −0.13 are
/// 3 cm apart > plane_offset_max (1 cm): UNEVEN, ripple.
#[test]
fn a_step_between_the_tripods_is_uneven() {
    let mut feet = HexapodGeometry::default().standing_feet();
    for leg in Leg::PLANE2 {
        feet[leg.index()].z = -0.13;
    }
    let r = assessor().assess(&feet).unwrap();
    assert!(r.alpha12 < 1e-12 && r.alpha13 < 1e-12 && r.alpha23 < 1e-12);
    assert!((r.sigma - 0.015).abs() < 1e-12);
    assert!((r.plane_offset - 0.03).abs() < 1e-12);
    assert_eq!((r.class, r.advice), (TerrainClass::Uneven, Gait::Ripple));
}

/// A 0.9 cm step is within plane_offset_max: still FLAT (σ = 0.45 cm ≤ σ_flat); 1.2 cm is
/// beyond it: UNEVEN, though σ = 0.6 cm ≤ σ_flat (the σ gate alone let steps up to 2 cm pass).
#[test]
fn a_level_step_is_uneven_from_plane_offset_max_on() {
    for (step, class) in [(0.009, TerrainClass::Flat), (0.012, TerrainClass::Uneven)] {
        let mut feet = HexapodGeometry::default().standing_feet();
        for leg in Leg::PLANE2 {
            feet[leg.index()].z = -0.10 - step;
        }
        let r = assessor().assess(&feet).unwrap();
        assert!((r.sigma - step / 2.0).abs() < 1e-12);
        assert!((r.plane_offset - step).abs() < 1e-12);
        assert_eq!(r.class, class, "step {step}");
    }
}

/// Tripod A on z = t·x − 0.10 (t = tan 10° = 0.176327), tripod B 3 cm lower, z = t·x − 0.13:
/// parallel planes, α12 = 0, α13 = α23 = tilt = 10°. Unit normal (−t, 0, 1)/√(1 + t²), so A's
/// centroid (0, 0.02667, −0.10) lies 0.03 · cos 10° = 0.029544 m from plane 2 (and B's from
/// plane 1 the same). σ² = t²·var(x) + var(step) (x and the tripod are uncorrelated: each
/// tripod has x = 0.15, −0.15, 0) = 0.031091 · 0.015 + 0.015² = 6.9137e-4, σ = 2.6294 cm.
/// Feet not coplanar: UNEVEN (the SPEC's angle rule alone said SLOPE); σ > σ_wave (2.5 cm): wave.
#[test]
fn a_step_between_the_tripods_on_a_slope_is_uneven() {
    let t = 10f64.to_radians().tan();
    let mut feet = HexapodGeometry::default().standing_feet();
    for (k, f) in feet.iter_mut().enumerate() {
        let lower = if Leg::PLANE2.contains(&Leg::ALL[k]) { 0.03 } else { 0.0 };
        f.z = t * f.x - 0.10 - lower;
    }
    let r = assessor().assess(&feet).unwrap();
    assert!(r.alpha12 < 1e-9);
    assert!((r.alpha13 - 10f64.to_radians()).abs() < 1e-9);
    assert!((r.alpha23 - 10f64.to_radians()).abs() < 1e-9);
    assert!((r.plane_offset - 0.029_544).abs() < 1e-6, "offset {}", r.plane_offset);
    assert!((r.sigma - 0.026_294).abs() < 1e-6, "σ {}", r.sigma);
    assert_eq!((r.class, r.advice), (TerrainClass::Uneven, Gait::Wave));
}

/// The same slope without the step: all six feet on z = t·x − 0.10, offset 0: SLOPE.
#[test]
fn a_plain_slope_has_no_plane_offset() {
    let r = assessor().assess(&on_plane(10.0, 0.0)).unwrap();
    assert!(r.plane_offset < 1e-12);
    assert_eq!(r.class, TerrainClass::Slope);
}

/// 16° along x: tilt 16° > 15° while σ = 0.1225 · tan 16° = 3.51 cm < σ_max: BEYOND by tilt.
/// Table 1's large column doubled: σ = 2 · 2.769 = 5.54 cm > 4 cm, α12 still large: BEYOND by σ.
#[test]
fn beyond_limits_by_tilt_or_by_sigma() {
    let a = assessor();
    let r = a.assess(&on_plane(16.0, 0.0)).unwrap();
    assert!((r.sigma - 0.122_474 * 16f64.to_radians().tan()).abs() < 1e-6);
    assert!(r.sigma < 0.04);
    assert_eq!((r.class, r.advice), (TerrainClass::BeyondLimits, Gait::Reroute));
    let mut feet = HexapodGeometry::default().standing_feet();
    for (f, z) in feet.iter_mut().zip([8.0, -6.0, 2.0, -8.0, 0.0, 4.0]) {
        f.z = -0.10 + z / 100.0;
    }
    let r = a.assess(&feet).unwrap();
    assert!((r.sigma - 0.055_377_5).abs() < 1e-6);
    assert_eq!((r.class, r.advice), (TerrainClass::BeyondLimits, Gait::Reroute));
}

#[test]
fn degenerate_stances_are_typed_errors() {
    let a = assessor();
    let good = HexapodGeometry::default().standing_feet();
    // DV moved onto the line through KP (0.15, 0.12) and KG (−0.15, 0.12): plane 1 collinear.
    let mut feet = good;
    feet[Leg::DV.index()] = Point3::new(0.0, 0.12, -0.10);
    assert!(matches!(
        a.assess(&feet),
        Err(TerrainError::CollinearPoints {
            plane: PlaneId::Feet1,
            ..
        })
    ));
    // DG on DP: plane 2 has coincident points.
    let mut feet = good;
    feet[Leg::DG.index()] = feet[Leg::DP.index()];
    assert!(matches!(
        a.assess(&feet),
        Err(TerrainError::CoincidentPoints {
            plane: PlaneId::Feet2,
            ..
        })
    ));
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut feet = good;
        feet[Leg::KV.index()].z = bad;
        assert!(matches!(a.assess(&feet), Err(TerrainError::NonFinite { ref what, .. }) if what == "foot KV"));
    }
    let mut feet = good;
    feet[Leg::KG.index()].x = 1e6;
    assert!(matches!(a.assess(&feet), Err(TerrainError::OutOfRange { .. })));
    // Collinear body points: no assessor.
    let config = TerrainConfig {
        body_points: [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, -0.1, 0.0, 0.0],
        ..TerrainConfig::default()
    };
    assert!(matches!(
        Assessor::new(config),
        Err(TerrainError::CollinearPoints {
            plane: PlaneId::Body,
            ..
        })
    ));
}

#[test]
fn the_tracker_assesses_once_all_six_feet_are_known() {
    let mut t = FootTracker::new(assessor());
    let feet = on_plane(10.0, 0.0);
    for leg in &Leg::ALL[..5] {
        assert_eq!(t.touchdown(*leg, feet[leg.index()]), Ok(None));
    }
    assert!(t.last().is_none());
    let r = t.touchdown_named("DG", feet[Leg::DG.index()]).unwrap().unwrap();
    assert_eq!(r.class, TerrainClass::Slope);
    assert_eq!(t.last(), Some(&r));
    // Refused inputs change nothing and are counted.
    assert_eq!(
        t.touchdown_named("XX", Point3::origin()),
        Err(TerrainError::UnknownLeg("XX".into()))
    );
    assert!(t.touchdown(Leg::KP, Point3::new(f64::NAN, 0.0, 0.0)).is_err());
    assert_eq!(t.rejected(), 2);
    assert_eq!(t.foot(Leg::KP), Some(feet[Leg::KP.index()]));
    assert_eq!(t.last(), Some(&r));
    // A degenerate stance keeps the foot, is counted, and keeps the last good assessment.
    assert!(matches!(
        t.touchdown(Leg::DV, Point3::new(0.0, 0.12, -0.10)),
        Err(TerrainError::CollinearPoints { .. })
    ));
    assert_eq!(t.failed(), 1);
    assert_eq!(t.last(), Some(&r));
    // DV back where it was: the same stance, the same assessment. Then KP 2.64 cm lower
    // (z = −0.10 instead of −0.10 + 0.15 · tan 10°): plane 1 turns away from plane 2, UNEVEN.
    let r2 = t.touchdown(Leg::DV, feet[Leg::DV.index()]).unwrap().unwrap();
    assert_eq!(r2, r);
    let mut flat = HexapodGeometry::default().standing_feet()[Leg::KP.index()];
    flat.z = -0.10;
    let r3 = t.touchdown(Leg::KP, flat).unwrap().unwrap();
    assert_eq!(r3.class, TerrainClass::Uneven);
    assert_eq!(r3.feet[Leg::KP.index()], flat);
}
