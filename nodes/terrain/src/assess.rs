//! The assessment of SPEC §6: σ of the feet's z, the three planes, the angles between them
//! (eq. 17–19 with |N_i·N_j|), each plane's tilt, the class and the advised gait.

use crate::config::TerrainConfig;
use crate::error::{check_point, PlaneId, TerrainError, MIN_EDGE, MIN_SINE};
use crate::leg::Leg;
use nalgebra::{Point3, Vector3};

/// The terrain class (`TerrainAssessment.terrain_class`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TerrainClass {
    /// All angles within ε_α and σ ≤ σ_flat: the feet lie in one plane parallel to the body.
    Flat = 0,
    /// α12 within ε_α, α13 ≈ α23 beyond it: the feet coplanar, the plane tilted.
    Slope = 1,
    /// α12 beyond ε_α (the feet not coplanar), or the two tripods level at different heights.
    Uneven = 2,
    /// σ > σ_max or a foot plane tilted more than tilt_max: choose another route.
    BeyondLimits = 3,
}

impl TerrainClass {
    /// The message's constant (FLAT = 0 … BEYOND_LIMITS = 3).
    pub fn as_u8(self) -> u8 {
        self as u8
    }

    /// The message constant's name (`"FLAT"`, …).
    pub fn name(self) -> &'static str {
        match self {
            TerrainClass::Flat => "FLAT",
            TerrainClass::Slope => "SLOPE",
            TerrainClass::Uneven => "UNEVEN",
            TerrainClass::BeyondLimits => "BEYOND_LIMITS",
        }
    }
}

/// The advised gait (`TerrainAssessment.advised_gait`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Gait {
    /// The fastest gait, three legs at a time; reactive control (flat ground).
    Tripod = 0,
    /// Slower and safer, one leg of each side at a time; deliberative control (moderate σ).
    Ripple = 1,
    /// The slowest and safest, one leg at a time (large σ).
    Wave = 2,
    /// Beyond the limits: choose another route.
    Reroute = 3,
}

impl Gait {
    /// The message's constant (GAIT_TRIPOD = 0 … GAIT_REROUTE = 3).
    pub fn as_u8(self) -> u8 {
        self as u8
    }

    /// The message constant's name without its prefix (`"TRIPOD"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Gait::Tripod => "TRIPOD",
            Gait::Ripple => "RIPPLE",
            Gait::Wave => "WAVE",
            Gait::Reroute => "REROUTE",
        }
    }
}

/// One plane a·x + b·y + c·z + d = 0 and its inclination to the body's xy-plane
/// (`mobil_msgs/PlaneTilt`). (a, b, c) is the unit normal, oriented with c ≥ 0 (upward; c = 0
/// only for a vertical plane).
///
/// Signs: the normal's horizontal part (a, b) points downhill. Ground rising along +x
/// (z = tan 10°·x) has N ∝ (−tan 10°, 0, 1): θ_x = −10°, downhill = π. So θ_x > 0 means the
/// ground falls toward +x (descends ahead), θ_y > 0 that it falls toward +y (to the left), and
/// downhill is the body-frame direction of steepest descent, 0 (by atan2(0, 0)) for a level plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneTilt {
    /// Normal's x component.
    pub a: f64,
    /// Normal's y component.
    pub b: f64,
    /// Normal's z component (≥ 0).
    pub c: f64,
    /// −N·P1: with a unit normal, minus the signed distance of the origin from the plane along N (m).
    pub d: f64,
    /// Inclination along body x: atan2(a, c) (rad); > 0 when the ground falls toward +x
    /// (−10° for ground rising 10° ahead).
    pub theta_x: f64,
    /// Inclination along body y: atan2(b, c) (rad); > 0 when the ground falls toward +y (left).
    pub theta_y: f64,
    /// Direction of steepest descent in the body's xy-plane: atan2(b, a) (rad, from +x toward
    /// +y); 0 for a level plane.
    pub downhill: f64,
}

impl PlaneTilt {
    /// The plane through three points: N = (P2 − P1) × (P3 − P1), d = −N·P1 (SPEC §6, the
    /// paper's d with its sign corrected), N scaled to unit length and turned to c ≥ 0.
    /// A point that is not finite or has a coordinate beyond
    /// [`COORDINATE_LIMIT`](crate::error::COORDINATE_LIMIT) is refused,
    /// as are coincident points (an edge shorter than [`MIN_EDGE`]) and collinear ones (sine of
    /// the angle at P1 below [`MIN_SINE`]): the result never holds a NaN or an infinity.
    pub fn through(plane: PlaneId, p1: &Point3<f64>, p2: &Point3<f64>, p3: &Point3<f64>) -> Result<Self, TerrainError> {
        for (k, p) in [p1, p2, p3].into_iter().enumerate() {
            check_point(|| format!("point {} of {plane}", k + 1), p.x, p.y, p.z)?;
        }
        let e1 = p2 - p1;
        let e2 = p3 - p1;
        let (l1, l2, l3) = (e1.norm(), e2.norm(), (p3 - p2).norm());
        // Written so that a NaN would fail them too.
        if !(l1 >= MIN_EDGE && l2 >= MIN_EDGE && l3 >= MIN_EDGE) {
            return Err(TerrainError::CoincidentPoints {
                plane,
                min_edge: MIN_EDGE,
            });
        }
        let n = e1.cross(&e2);
        let sine = n.norm() / (l1 * l2);
        if sine.is_nan() || sine < MIN_SINE {
            return Err(TerrainError::CollinearPoints { plane, sine });
        }
        let mut n = n / n.norm();
        if n.z < 0.0 {
            n = -n;
        }
        Ok(PlaneTilt {
            a: n.x,
            b: n.y,
            c: n.z,
            d: -n.dot(&p1.coords),
            theta_x: n.x.atan2(n.z),
            theta_y: n.y.atan2(n.z),
            downhill: n.y.atan2(n.x),
        })
    }

    /// Signed distance (m) of a point from the plane, a·x + b·y + c·z + d with the unit normal:
    /// positive on the side the normal points to (above, as c ≥ 0).
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.a * p.x + self.b * p.y + self.c * p.z + self.d
    }

    /// The unit normal (a, b, c).
    pub fn normal(&self) -> Vector3<f64> {
        Vector3::new(self.a, self.b, self.c)
    }

    /// Inclination (rad) to the body's xy-plane: the angle between the normal and z,
    /// atan2(√(a² + b²), c), in [0, π/2].
    pub fn inclination(&self) -> f64 {
        (self.a * self.a + self.b * self.b).sqrt().atan2(self.c)
    }
}

/// Angle between two planes by their normals, arccos(|N_i·N_j| / (|N_i||N_j|)) (eq. 17–19 with
/// the SPEC's absolute value), in [0, π/2]. Computed as atan2(|N_i × N_j|, |N_i·N_j|), the same
/// angle without arccos' loss of precision near 0, on each normal scaled by its largest
/// component first, so that no length of normal overflows or underflows. A normal that is zero
/// or not finite has no direction: the angle is then NaN, which [`classify`] treats as
/// BEYOND_LIMITS.
pub fn angle_between(n_i: &Vector3<f64>, n_j: &Vector3<f64>) -> f64 {
    let scaled = |n: &Vector3<f64>| {
        let m = n.amax();
        if m > 0.0 && m.is_finite() {
            Some(n / m)
        } else {
            None
        }
    };
    match (scaled(n_i), scaled(n_j)) {
        (Some(a), Some(b)) => a.cross(&b).norm().atan2(a.dot(&b).abs()),
        _ => f64::NAN,
    }
}

/// Population and sample standard deviation of the six feet's z (m).
/// Heights are taken relative to the first (σ does not change), so equal heights give exactly 0
/// and a large common offset costs no precision. The differences are halved (exact in binary)
/// and scaled by their largest before squaring, so that no finite heights overflow: σ is finite
/// unless the spread itself exceeds f64's range. A height that is NaN or infinite gives NaN,
/// which [`classify`] treats as BEYOND_LIMITS ([`Assessor::assess`] refuses such feet before).
pub fn sigma_of_heights(z: &[f64; 6]) -> (f64, f64) {
    if !z.iter().all(|v| v.is_finite()) {
        return (f64::NAN, f64::NAN);
    }
    // |v/2 − z0/2| ≤ f64::MAX for finite v, z0: no difference overflows.
    let half = z.map(|v| v / 2.0 - z[0] / 2.0);
    let scale = half.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return (0.0, 0.0);
    }
    let u = half.map(|v| v / scale);
    let mean = u.iter().sum::<f64>() / 6.0;
    let ss: f64 = u.iter().map(|v| (v - mean) * (v - mean)).sum();
    // Scaled back last-but-one, so 2·scale itself cannot overflow.
    ((ss / 6.0).sqrt() * scale * 2.0, (ss / 5.0).sqrt() * scale * 2.0)
}

/// What the class is decided from, in the order of `mobil_msgs/TerrainAssessment` (σ, α12,
/// α23, α13, tilt), plus the offset between the two foot planes, which the message does not carry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measures {
    /// Population standard deviation of the feet's z (m).
    pub sigma: f64,
    /// Angle between planes 1 and 2 (rad, ≥ 0).
    pub alpha12: f64,
    /// Angle between planes 2 and 3 (rad, ≥ 0).
    pub alpha23: f64,
    /// Angle between planes 1 and 3 (rad, ≥ 0).
    pub alpha13: f64,
    /// Largest inclination of planes 1 and 2 to the body's xy-plane (rad).
    pub tilt: f64,
    /// Offset between planes 1 and 2 (m, ≥ 0): see [`plane_offset`].
    pub plane_offset: f64,
}

/// Offset (m) between the two foot planes: the larger distance of each tripod's foot centroid
/// from the other tripod's plane (unit normals). 0 when all six feet are coplanar; for two
/// parallel planes, their distance. Only meaningful when α12 is small (within ε_α), where it
/// tells a step between the tripods from one plane.
pub fn plane_offset(plane1: &PlaneTilt, feet1: &[Point3<f64>; 3], plane2: &PlaneTilt, feet2: &[Point3<f64>; 3]) -> f64 {
    let centroid = |f: &[Point3<f64>; 3]| Point3::from((f[0].coords + f[1].coords + f[2].coords) / 3.0);
    plane2
        .distance(&centroid(feet1))
        .abs()
        .max(plane1.distance(&centroid(feet2)).abs())
}

/// The class by SPEC §6's corrected rule, with the step between the tripods seen by the planes'
/// offset:
/// 1. BEYOND_LIMITS if σ > σ_max or tilt > tilt_max, or if any measure is
///    NaN, infinite or negative (an undefined stance never passes as safe ground);
/// 2. otherwise UNEVEN if α12 > ε_α (the planes cross) or the plane offset exceeds
///    `plane_offset_max` (parallel planes at different heights: a step between the tripods,
///    level or on a slope);
/// 3. otherwise FLAT if α13 ≤ ε_α, α23 ≤ ε_α and σ ≤ σ_flat, UNEVEN if only σ exceeds σ_flat,
///    else SLOPE.
pub fn classify(config: &TerrainConfig, m: &Measures) -> TerrainClass {
    let eps = config.epsilon_alpha;
    let values = [m.sigma, m.alpha12, m.alpha23, m.alpha13, m.tilt, m.plane_offset];
    // NaN fails `is_finite`, so it cannot reach the comparisons below, which it would pass.
    let defined = values.iter().all(|v| v.is_finite() && *v >= 0.0);
    if !defined || m.sigma > config.sigma_max || m.tilt > config.tilt_max {
        TerrainClass::BeyondLimits
    } else if m.alpha12 > eps || m.plane_offset > config.plane_offset_max {
        TerrainClass::Uneven
    } else if m.alpha13 <= eps && m.alpha23 <= eps {
        if m.sigma <= config.sigma_flat {
            TerrainClass::Flat
        } else {
            TerrainClass::Uneven
        }
    } else {
        TerrainClass::Slope
    }
}

/// The advised gait: FLAT → tripod (keep speed, direction and gait); SLOPE and UNEVEN → ripple
/// up to σ_wave, wave above; BEYOND_LIMITS → reroute.
pub fn advise(config: &TerrainConfig, class: TerrainClass, sigma: f64) -> Gait {
    match class {
        TerrainClass::Flat => Gait::Tripod,
        TerrainClass::Slope | TerrainClass::Uneven if sigma <= config.sigma_wave => Gait::Ripple,
        TerrainClass::Slope | TerrainClass::Uneven => Gait::Wave,
        TerrainClass::BeyondLimits => Gait::Reroute,
    }
}

/// One assessment, field for field `mobil_msgs/TerrainAssessment` (plus the sample σ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assessment {
    /// The feet (m, body frame), in [`Leg::ALL`] order.
    pub feet: [Point3<f64>; 6],
    /// Population standard deviation of the feet's z (m), the SPEC's σ.
    pub sigma: f64,
    /// Sample standard deviation (divisor 5) of the feet's z (m); not in the message.
    pub sigma_sample: f64,
    /// Angle between planes 1 and 2 (rad).
    pub alpha12: f64,
    /// Angle between planes 2 and 3 (rad).
    pub alpha23: f64,
    /// Angle between planes 1 and 3 (rad).
    pub alpha13: f64,
    /// Planes 1 (KP, KG, DV), 2 (DP, DG, KV) and 3 (body points).
    pub planes: [PlaneTilt; 3],
    /// Largest inclination of planes 1 and 2 to the body's xy-plane (rad).
    pub tilt: f64,
    /// Offset between planes 1 and 2 (m, see [`plane_offset`]); not in the message.
    pub plane_offset: f64,
    /// The class.
    pub class: TerrainClass,
    /// The advised gait.
    pub advice: Gait,
}

/// Assesses the six feet against a validated configuration; plane 3 is built once.
#[derive(Debug, Clone, PartialEq)]
pub struct Assessor {
    config: TerrainConfig,
    body_plane: PlaneTilt,
}

impl Assessor {
    /// Validates the configuration and builds plane 3 from its body points.
    pub fn new(config: TerrainConfig) -> Result<Self, TerrainError> {
        config.validate()?;
        let [p1, p2, p3] = config.body_points();
        let body_plane = PlaneTilt::through(PlaneId::Body, &p1, &p2, &p3)?;
        Ok(Assessor { config, body_plane })
    }

    /// The configuration.
    pub fn config(&self) -> &TerrainConfig {
        &self.config
    }

    /// Plane 3, through the body points.
    pub fn body_plane(&self) -> &PlaneTilt {
        &self.body_plane
    }

    /// Assesses the feet (m, body frame, [`Leg::ALL`] order). A non-finite or out-of-range foot,
    /// or a degenerate foot plane, is an error; the output holds no NaN.
    pub fn assess(&self, feet: &[Point3<f64>; 6]) -> Result<Assessment, TerrainError> {
        for (leg, p) in Leg::ALL.iter().zip(feet) {
            check_point(|| format!("foot {leg}"), p.x, p.y, p.z)?;
        }
        let foot = |leg: Leg| &feet[leg.index()];
        let [a1, a2, a3] = Leg::PLANE1.map(foot);
        let plane1 = PlaneTilt::through(PlaneId::Feet1, a1, a2, a3)?;
        let [b1, b2, b3] = Leg::PLANE2.map(foot);
        let plane2 = PlaneTilt::through(PlaneId::Feet2, b1, b2, b3)?;
        let plane3 = self.body_plane;
        let (n1, n2, n3) = (plane1.normal(), plane2.normal(), plane3.normal());
        let alpha12 = angle_between(&n1, &n2);
        let alpha23 = angle_between(&n2, &n3);
        let alpha13 = angle_between(&n1, &n3);
        let (sigma, sigma_sample) = sigma_of_heights(&feet.map(|p| p.z));
        let tilt = plane1.inclination().max(plane2.inclination());
        let offset = plane_offset(&plane1, &[*a1, *a2, *a3], &plane2, &[*b1, *b2, *b3]);
        let measures = Measures {
            sigma,
            alpha12,
            alpha23,
            alpha13,
            tilt,
            plane_offset: offset,
        };
        let class = classify(&self.config, &measures);
        let advice = advise(&self.config, class, sigma);
        Ok(Assessment {
            feet: *feet,
            sigma,
            sigma_sample,
            alpha12,
            alpha23,
            alpha13,
            planes: [plane1, plane2, plane3],
            tilt,
            plane_offset: offset,
            class,
            advice,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plane through (0,0,0), (1,0,1), (0,1,0): z = x, so N ∝ (−1, 0, 1)/√2 after turning
    /// c > 0; inclination 45° along x; downhill along −x (the normal's horizontal part): π.
    /// Ground rising along +x has θ_x < 0. Then z = y (through (0,0,0), (1,0,0), (0,1,1); the
    /// vertex order gives N ∝ (0, 1, −1), turned to (0, −1, 1)/√2): θ_y = −45°, θ_x = 0,
    /// downhill −π/2 (toward −y, the right).
    #[test]
    fn plane_through_three_points() {
        let p = PlaneTilt::through(
            PlaneId::Feet1,
            &Point3::new(0.0, 0.0, 0.0),
            &Point3::new(1.0, 0.0, 1.0),
            &Point3::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((p.a + h).abs() < 1e-15 && p.b.abs() < 1e-15 && (p.c - h).abs() < 1e-15);
        assert!(p.d.abs() < 1e-15);
        assert!((p.theta_x + std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert!((p.downhill - std::f64::consts::PI).abs() < 1e-15);
        assert!((p.inclination() - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        let p = PlaneTilt::through(
            PlaneId::Feet1,
            &Point3::new(0.0, 0.0, 0.0),
            &Point3::new(1.0, 0.0, 0.0),
            &Point3::new(0.0, 1.0, 1.0),
        )
        .unwrap();
        assert!(p.a.abs() < 1e-15 && (p.b + h).abs() < 1e-15 && (p.c - h).abs() < 1e-15);
        assert!((p.theta_y + std::f64::consts::FRAC_PI_4).abs() < 1e-15 && p.theta_x.abs() < 1e-15);
        assert!((p.downhill + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    /// With N_1 = (0,0,1) and N_2 = −(0, sin 30°, cos 30°) (opposite orientation), eq. 17 with
    /// the absolute value gives 30°, not 150°.
    #[test]
    fn angle_ignores_orientation() {
        let n1 = Vector3::new(0.0, 0.0, 1.0);
        let n2 = -Vector3::new(0.0, 0.5, 0.75f64.sqrt());
        assert!((angle_between(&n1, &n2) - 30f64.to_radians()).abs() < 1e-15);
        assert!(angle_between(&n1, &n1).abs() < 1e-15);
        assert!(angle_between(&n1, &(-n1)).abs() < 1e-15);
    }

    /// NaN or huge points: refused with a typed error, never a plane holding NaN. (Before the
    /// check, a NaN point gave Ok with NaN in every field, and 1e300 overflowed the cross
    /// product to ∞ and the normal to NaN.)
    #[test]
    fn through_refuses_nan_and_huge_points() {
        let o = Point3::new(0.0, 0.0, 0.0);
        let x = Point3::new(1.0, 0.0, 0.0);
        for bad in [
            Point3::new(f64::NAN, 1.0, 0.0),
            Point3::new(0.0, f64::NAN, f64::NAN),
            Point3::new(0.0, 1.0, f64::INFINITY),
        ] {
            assert!(matches!(
                PlaneTilt::through(PlaneId::Feet1, &o, &x, &bad),
                Err(TerrainError::NonFinite { .. })
            ));
        }
        let huge = Point3::new(0.0, 1e300, 0.0);
        assert!(matches!(
            PlaneTilt::through(PlaneId::Feet2, &o, &huge, &x),
            Err(TerrainError::OutOfRange { ref what, .. }) if what == "point 2 of plane 2 (DP, DG, KV)"
        ));
        // Just within the limit (1 km) still works: z = x through (0,0,0), (1000,0,1000),
        // (0,1000,0) is the 45° plane of `plane_through_three_points`.
        let p = PlaneTilt::through(
            PlaneId::Feet1,
            &o,
            &Point3::new(1e3, 0.0, 1e3),
            &Point3::new(0.0, 1e3, 0.0),
        )
        .unwrap();
        assert!((p.theta_x + std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    }

    /// Normals of any length give the same angle: 30° between (0, 0, 1) and (0, 1/2, √3/2)
    /// scaled by 1e300 (their cross product would overflow to ∞, atan2(∞, ∞) = 45°) or by
    /// 1e-300 (it would underflow to 0, giving 0°). A zero or NaN normal has no angle: NaN.
    #[test]
    fn angle_between_huge_tiny_and_undefined_normals() {
        let n1 = Vector3::new(0.0, 0.0, 1.0);
        let n2 = Vector3::new(0.0, 0.5, 0.75f64.sqrt());
        for s in [1e300, 1e-300, 1.0] {
            let a = angle_between(&(n1 * s), &(n2 * s));
            assert!((a - 30f64.to_radians()).abs() < 1e-15, "scale {s}: {a}");
        }
        assert!(angle_between(&n1, &Vector3::zeros()).is_nan());
        assert!(angle_between(&Vector3::new(f64::NAN, 0.0, 1.0), &n1).is_nan());
        assert!(angle_between(&n1, &Vector3::new(0.0, f64::INFINITY, 1.0)).is_nan());
    }

    /// σ of [h, −h, h, −h, h, −h]: mean 0, every deviation h, so σ = h and the sample σ
    /// = h·√(6/5). With h = 1e200 the squares (1e400) would overflow to ∞; with h = 1e308 even
    /// the differences (2e308) would. A NaN or an infinite height gives NaN.
    #[test]
    fn sigma_of_huge_and_undefined_heights() {
        for h in [0.01, 1e200, 1e308] {
            let (pop, sample) = sigma_of_heights(&[h, -h, h, -h, h, -h]);
            assert!((pop / h - 1.0).abs() < 1e-15, "h {h}: {pop}");
            assert!((sample / h - 1.2f64.sqrt()).abs() < 1e-15, "h {h}: {sample}");
        }
        for bad in [f64::NAN, f64::INFINITY] {
            let (pop, sample) = sigma_of_heights(&[bad, 0.0, 0.0, 0.0, 0.0, 0.0]);
            assert!(pop.is_nan() && sample.is_nan());
            let (pop, _) = sigma_of_heights(&[0.0, 0.0, 0.0, 0.0, 0.0, bad]);
            assert!(pop.is_nan());
        }
    }

    /// Measures in the message's order, the offset last.
    fn m(sigma: f64, alpha12: f64, alpha23: f64, alpha13: f64, tilt: f64, plane_offset: f64) -> Measures {
        Measures {
            sigma,
            alpha12,
            alpha23,
            alpha13,
            tilt,
            plane_offset,
        }
    }

    #[test]
    fn classes_at_their_boundaries() {
        let c = TerrainConfig::default();
        let e = c.epsilon_alpha;
        let o = c.plane_offset_max;
        assert_eq!(classify(&c, &m(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)), TerrainClass::Flat);
        assert_eq!(classify(&c, &m(c.sigma_flat, e, e, e, e, o)), TerrainClass::Flat);
        assert_eq!(classify(&c, &m(0.011, 0.0, 0.0, 0.0, 0.0, 0.0)), TerrainClass::Uneven);
        assert_eq!(classify(&c, &m(0.02, 0.0, 0.1, 0.1, 0.1, 0.0)), TerrainClass::Slope);
        assert_eq!(classify(&c, &m(0.02, 0.0, 0.1, 0.1, 0.1, o)), TerrainClass::Slope);
        assert_eq!(
            classify(&c, &m(0.02, 0.0, 0.1, 0.1, 0.1, o * 1.01)),
            TerrainClass::Uneven
        );
        assert_eq!(
            classify(&c, &m(0.005, 0.0, 0.0, 0.0, 0.0, o * 1.01)),
            TerrainClass::Uneven
        );
        assert_eq!(
            classify(&c, &m(0.02, e * 1.01, 0.1, 0.1, 0.1, 0.0)),
            TerrainClass::Uneven
        );
        assert_eq!(
            classify(&c, &m(0.041, 0.0, 0.0, 0.0, 0.0, 0.0)),
            TerrainClass::BeyondLimits
        );
        assert_eq!(
            classify(&c, &m(0.02, 0.0, 0.27, 0.27, 0.27, 0.0)),
            TerrainClass::BeyondLimits
        );
        assert_eq!(advise(&c, TerrainClass::Flat, 0.0), Gait::Tripod);
        // σ_wave = 2.5 cm: a 10° slope's 2.37 cm is ripple, 2.51 cm wave.
        assert_eq!(advise(&c, TerrainClass::Slope, 0.0237), Gait::Ripple);
        assert_eq!(advise(&c, TerrainClass::Slope, 0.025), Gait::Ripple);
        assert_eq!(advise(&c, TerrainClass::Uneven, 0.0251), Gait::Wave);
        assert_eq!(advise(&c, TerrainClass::BeyondLimits, 0.0), Gait::Reroute);
    }

    /// The order is the message's: α23 (plane 2 to the body) before α13. Each field reaches
    /// the rule: a NaN, an infinity or a negative value in any one of them is BEYOND_LIMITS
    /// (fails closed, never FLAT or SLOPE).
    #[test]
    fn any_undefined_measure_is_beyond_limits() {
        let c = TerrainConfig::default();
        assert_eq!(classify(&c, &m(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)), TerrainClass::Flat);
        // α13 = 0.1 rad alone: SLOPE; α23 = 0.1 rad alone: SLOPE too.
        assert_eq!(classify(&c, &m(0.01, 0.0, 0.0, 0.1, 0.1, 0.0)), TerrainClass::Slope);
        assert_eq!(classify(&c, &m(0.01, 0.0, 0.1, 0.0, 0.1, 0.0)), TerrainClass::Slope);
        for k in 0..6 {
            for bad in [f64::NAN, -1e-3, f64::INFINITY, f64::NEG_INFINITY] {
                let mut v = [0.0; 6];
                v[k] = bad;
                let x = m(v[0], v[1], v[2], v[3], v[4], v[5]);
                assert_eq!(classify(&c, &x), TerrainClass::BeyondLimits, "field {k} = {bad}");
            }
        }
    }
}
