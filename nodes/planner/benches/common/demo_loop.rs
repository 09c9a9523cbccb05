//! The demo loop of the default world as a waypoint route (shared by the benches and the
//! route tests).

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::Point2;

/// A point (x, y) in metres.
type Xy = (f64, f64);

/// The demo loop of the default world (a rounded rectangle x ∈ [−1, 3], y ∈ [0, 3], 1 m corner
/// radii, anticlockwise from (0, 0) facing east), as `n` waypoints evenly spaced along its
/// 6 + 2π = 12.28 m; the last is the start. Its radius (1 m) is above MOBIL-II's 0.73 m and it
/// keeps 1.2 m from every surface.
pub fn demo_loop(n: usize) -> Vec<Point2<f64>> {
    // Each side: a 1 or 2 m straight, then a quarter circle about the corner's centre.
    let sides: [(Xy, Xy, Xy); 4] = [
        ((0.0, 0.0), (2.0, 0.0), (2.0, 1.0)),
        ((3.0, 1.0), (3.0, 2.0), (2.0, 2.0)),
        ((2.0, 3.0), (0.0, 3.0), (0.0, 2.0)),
        ((-1.0, 2.0), (-1.0, 1.0), (0.0, 1.0)),
    ];
    let total = 6.0 + 2.0 * PI;
    (1..=n)
        .map(|k| {
            let mut s = total * k as f64 / n as f64;
            for (i, (a, b, c)) in sides.iter().enumerate() {
                let len = (b.0 - a.0).hypot(b.1 - a.1);
                if s <= len {
                    let f = s / len;
                    return Point2::new(a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
                }
                s -= len;
                if s <= FRAC_PI_2 || i == 3 {
                    let phi = -FRAC_PI_2 + FRAC_PI_2 * i as f64 + s.min(FRAC_PI_2);
                    return Point2::new(c.0 + phi.cos(), c.1 + phi.sin());
                }
                s -= FRAC_PI_2;
            }
            Point2::new(0.0, 0.0)
        })
        .collect()
}
