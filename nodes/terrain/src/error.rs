//! Errors of the terrain library: each names what was refused and why.

use thiserror::Error;

/// Which of the three planes (SPEC §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaneId {
    /// Plane 1, through the feet KP, KG, DV.
    Feet1,
    /// Plane 2, through the feet DP, DG, KV.
    Feet2,
    /// Plane 3, through the three body points.
    Body,
}

impl std::fmt::Display for PlaneId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PlaneId::Feet1 => "plane 1 (KP, KG, DV)",
            PlaneId::Feet2 => "plane 2 (DP, DG, KV)",
            PlaneId::Body => "plane 3 (body points)",
        })
    }
}

/// Why an input, a configuration or an assessment was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TerrainError {
    /// A leg name other than KP, KV, KG, DP, DV, DG.
    #[error("unknown leg `{0}` (expected KP, KV, KG, DP, DV or DG)")]
    UnknownLeg(String),
    /// A coordinate is NaN or infinite.
    #[error("{what} is not finite: ({x}, {y}, {z})")]
    NonFinite {
        /// What the point is (a leg's name, `body point 2`, …).
        what: String,
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// z (m).
        z: f64,
    },
    /// A coordinate lies further than [`COORDINATE_LIMIT`] from the body's origin.
    #[error("{what} is out of range: ({x}, {y}, {z}); every coordinate must lie within ±{limit} m")]
    OutOfRange {
        /// What the point is.
        what: String,
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// z (m).
        z: f64,
        /// The bound, [`COORDINATE_LIMIT`].
        limit: f64,
    },
    /// Two of a plane's three points coincide (closer than [`MIN_EDGE`]).
    #[error("{plane}: two of its points coincide (closer than {min_edge} m)")]
    CoincidentPoints {
        /// The plane.
        plane: PlaneId,
        /// The bound, [`MIN_EDGE`].
        min_edge: f64,
    },
    /// A plane's three points are (nearly) on one line: the plane is undefined.
    #[error("{plane}: its three points are collinear (sine of the angle between its edges {sine:e})")]
    CollinearPoints {
        /// The plane.
        plane: PlaneId,
        /// |e1 × e2| / (|e1|·|e2|), below [`MIN_SINE`].
        sine: f64,
    },
    /// A configuration value is out of range or inconsistent with another.
    #[error("{name} = {value}: {reason}")]
    InvalidConfig {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: &'static str,
    },
}

/// Largest |x|, |y|, |z| (m) of a foot or body point: 1 km, far beyond any leg's reach, and far
/// below where the products of the plane equations would overflow.
pub const COORDINATE_LIMIT: f64 = 1e3;

/// Shortest edge (m) of a plane's triangle: 1 µm, below any leg kinematics' resolution.
pub const MIN_EDGE: f64 = 1e-6;

/// Smallest sine of the angle between a triangle's two edges at its first vertex (≈ 0.0006°):
/// below it the points count as collinear, and the normal's direction would be noise.
pub const MIN_SINE: f64 = 1e-5;

/// Refuses a non-finite or out-of-range point.
pub(crate) fn check_point(what: impl FnOnce() -> String, x: f64, y: f64, z: f64) -> Result<(), TerrainError> {
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        return Err(TerrainError::NonFinite { what: what(), x, y, z });
    }
    if x.abs() > COORDINATE_LIMIT || y.abs() > COORDINATE_LIMIT || z.abs() > COORDINATE_LIMIT {
        return Err(TerrainError::OutOfRange {
            what: what(),
            x,
            y,
            z,
            limit: COORDINATE_LIMIT,
        });
    }
    Ok(())
}
