//! Scripted routes (timed body-velocity segments) and odometry-versus-truth bookkeeping.

/// One segment of a scripted route: hold this body twist for `duration` seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub v: f64,
    pub omega: f64,
    pub duration: f64,
}

/// Parses `[v, ω, duration, v, ω, duration, …]`; durations must be positive, values finite.
pub fn parse_route(flat: &[f64]) -> Result<Vec<Segment>, String> {
    if flat.is_empty() || !flat.len().is_multiple_of(3) {
        return Err(format!(
            "a route is a list of (v, omega, duration) triples, got {} numbers",
            flat.len()
        ));
    }
    flat.chunks_exact(3)
        .map(|c| {
            if c.iter().any(|x| !x.is_finite()) || c[2] <= 0.0 {
                Err(format!(
                    "bad segment {c:?}: values must be finite and the duration positive"
                ))
            } else {
                Ok(Segment {
                    v: c[0],
                    omega: c[1],
                    duration: c[2],
                })
            }
        })
        .collect()
}

/// The twist to command `t` seconds after the route started; `None` once it is over.
pub fn twist_at(route: &[Segment], t: f64) -> Option<(f64, f64)> {
    let mut start = 0.0;
    for s in route {
        if t >= start && t < start + s.duration {
            return Some((s.v, s.omega));
        }
        start += s.duration;
    }
    None
}

/// The route a car-like robot with a 0.73 m minimum turning radius can drive in the built-in
/// world: a rounded rectangle, 4 m × 3 m, at 0.4 m/s, turning on 1 m radii.
pub fn default_loop() -> Vec<f64> {
    let v = 0.4;
    let quarter = std::f64::consts::FRAC_PI_2 / (v / 1.0);
    vec![
        v,
        0.0,
        2.0 / v, // 2 m east
        v,
        v,
        quarter, // quarter turn left, radius 1 m
        v,
        0.0,
        1.0 / v, // 1 m north
        v,
        v,
        quarter, //
        v,
        0.0,
        2.0 / v, // 2 m west
        v,
        v,
        quarter, //
        v,
        0.0,
        1.0 / v, // 1 m south
        v,
        v,
        quarter, // back to the start, facing east
    ]
}

/// Length of a polyline.
pub fn path_length(points: &[(f64, f64)]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_loop_closes() {
        // Integrate the loop exactly: it returns to the origin facing east.
        let route = parse_route(&default_loop()).unwrap();
        let (mut x, mut y, mut th) = (0.0f64, 0.0f64, 0.0f64);
        for s in &route {
            if s.omega == 0.0 {
                x += s.v * s.duration * th.cos();
                y += s.v * s.duration * th.sin();
            } else {
                let th2 = th + s.omega * s.duration;
                x += s.v / s.omega * (th2.sin() - th.sin());
                y -= s.v / s.omega * (th2.cos() - th.cos());
                th = th2;
            }
        }
        assert!(x.abs() < 1e-9 && y.abs() < 1e-9, "({x}, {y})");
        assert!((th - 2.0 * std::f64::consts::PI).abs() < 1e-9);
        // 2·2 m + 2·1 m straights + a full circle of radius 1 m.
        let length: f64 = route.iter().map(|s| s.v * s.duration).sum();
        assert!((length - (6.0 + 2.0 * std::f64::consts::PI)).abs() < 1e-9);
    }

    #[test]
    fn segments_in_time() {
        let r = parse_route(&[0.1, 0.0, 1.0, 0.2, 0.5, 2.0]).unwrap();
        assert_eq!(twist_at(&r, 0.5), Some((0.1, 0.0)));
        assert_eq!(twist_at(&r, 1.0), Some((0.2, 0.5)));
        assert_eq!(twist_at(&r, 3.0), None);
        assert!(parse_route(&[1.0, 2.0]).is_err());
        assert!(parse_route(&[1.0, 2.0, 0.0]).is_err());
        assert!(parse_route(&[f64::NAN, 2.0, 1.0]).is_err());
        assert_eq!(path_length(&[(0.0, 0.0), (3.0, 4.0), (3.0, 5.0)]), 6.0);
    }
}
