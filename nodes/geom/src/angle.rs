//! Angles.

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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn wrap_golden() {
        assert_eq!(wrap(-PI), PI);
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(0.0), 0.0);
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-15);
        assert!((wrap(-3.0 * PI) - PI).abs() < 1e-15);
        assert!((wrap(1.5 * PI) + 0.5 * PI).abs() < 1e-15);
        // −7 rad is −7 + 2π = −0.7168… rad.
        assert!((wrap(-7.0) + 0.716_814_692_820_413_5).abs() < 1e-15);
        assert!(wrap(f64::NAN).is_nan());
        assert!(wrap(f64::INFINITY).is_nan());
    }

    proptest! {
        #[test]
        fn wrap_lands_in_range_and_differs_by_whole_turns(a in -1e4..1e4f64) {
            let w = wrap(a);
            prop_assert!(w > -PI && w <= PI, "{a} → {w}");
            let turns = (a - w) / TAU;
            prop_assert!((turns - turns.round()).abs() < 1e-9, "{a} → {w}");
            prop_assert_eq!(wrap(w), w);
        }
    }
}
