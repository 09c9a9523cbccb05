//! Angle helpers.

use std::f64::consts::{PI, TAU};

/// Wraps an angle to (−π, π] (SPEC: `wrap(a)`); −π maps to π, non-finite input gives NaN.
pub fn wrap(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    if !a.is_finite() {
        return f64::NAN;
    }
    // r ∈ [0, 2π] (2π only by rounding); r − 2π ∈ (−π, 0] when r > π.
    let r = a.rem_euclid(TAU);
    if r > PI {
        r - TAU
    } else {
        r
    }
}
