//! Scripted routes (timed body-velocity segments) and odometry-versus-truth bookkeeping: the
//! demo's first act (`demo_driver`), its one-line summary ([`Drift`]) and its figure; and the
//! waypoint routes the later acts take as a parameter ([`parse_waypoints`]).

use mobil_geom::wrap;
use mobil_world::World;

use crate::plot::{MapView, Stroke, Svg};

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

/// A waypoint route from `[x0, y0, x1, y1, …]`: a non-empty list of finite pairs.
pub fn parse_waypoints(flat: &[f64]) -> Result<Vec<(f64, f64)>, String> {
    if flat.is_empty() || !flat.len().is_multiple_of(2) || !flat.iter().all(|v| v.is_finite()) {
        return Err("route must be a non-empty list of finite x, y pairs".into());
    }
    Ok(flat.chunks_exact(2).map(|c| (c[0], c[1])).collect())
}

/// A waypoint route as `[x0, y0, x1, y1, …]` (a parameter's value).
pub fn flat_waypoints(route: &[(f64, f64)]) -> Vec<f64> {
    route.iter().flat_map(|&(x, y)| [x, y]).collect()
}

/// Length of a polyline.
pub fn path_length(points: &[(f64, f64)]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum()
}

/// How far the odometry drifted from the truth over a drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drift {
    /// The true path's length (m).
    pub distance: f64,
    /// The distance between the last odometry and the last true position (m).
    pub error: f64,
    /// |wrap(odometry yaw − true yaw)| at the end (°).
    pub heading_error_deg: f64,
}

impl Drift {
    /// The drift of the odometry track `odom` from the true track `truth` (each pose x, y,
    /// yaw); `None` when either is empty.
    pub fn of(truth: &[(f64, f64, f64)], odom: &[(f64, f64, f64)]) -> Option<Drift> {
        let (o, g) = (odom.last()?, truth.last()?);
        let xy: Vec<(f64, f64)> = truth.iter().map(|p| (p.0, p.1)).collect();
        Some(Drift {
            distance: path_length(&xy),
            error: (o.0 - g.0).hypot(o.1 - g.1),
            heading_error_deg: wrap(o.2 - g.2).abs().to_degrees(),
        })
    }

    /// The act's line: the distance, the final error (also as a share of the distance), the
    /// heading error, the plot.
    pub fn line(&self, svg: &str) -> String {
        let share = if self.distance > 0.0 {
            100.0 * self.error / self.distance
        } else {
            0.0
        };
        format!(
            "demo: drove {:.2} m; final odometry error {:.3} m ({share:.2} % of distance), heading {:.2}°; plot {svg}",
            self.distance, self.error, self.heading_error_deg
        )
    }
}

/// The first act's figure: both tracks over the world at 60 px/m, the title and the legend
/// below.
pub fn figure(world: &World, truth: &[(f64, f64)], odom: &[(f64, f64)], title: &str) -> String {
    let map = MapView::fit(world, truth.iter().chain(odom).copied(), 60.0, 0.5);
    let base = map.height();
    let mut s = Svg::new(map.width(), base + 60.0);
    s.world(&map, world);
    s.metre_axes(&map);
    s.path(&map, truth, Stroke::solid("#141414", 2.0));
    s.path(&map, odom, Stroke::solid("#DC3220", 2.0));
    s.text(10.0, base + 22.0, 16.0, title);
    s.polyline(
        &[(10.0, base + 44.0), (40.0, base + 44.0)],
        Stroke::solid("#141414", 2.0),
    );
    s.text(46.0, base + 49.0, 14.0, "ground truth");
    s.polyline(
        &[(160.0, base + 44.0), (190.0, base + 44.0)],
        Stroke::solid("#DC3220", 2.0),
    );
    s.text(196.0, base + 49.0, 14.0, "odometry");
    s.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waypoints_from_a_flat_list_and_back() {
        let route = parse_waypoints(&[1.0, 2.0, -3.0, 0.5]).unwrap();
        assert_eq!(route, [(1.0, 2.0), (-3.0, 0.5)]);
        assert_eq!(flat_waypoints(&route), [1.0, 2.0, -3.0, 0.5]);
        for bad in [
            &[][..],
            &[1.0],
            &[1.0, 2.0, 3.0],
            &[1.0, f64::NAN],
            &[f64::INFINITY, 0.0],
        ] {
            assert_eq!(
                parse_waypoints(bad),
                Err("route must be a non-empty list of finite x, y pairs".to_string())
            );
        }
    }

    #[test]
    fn drift_at_the_end_of_the_tracks() {
        // Truth 3 m east then 4 m north, ending facing north; odometry 0.06 m west and 0.08 m
        // south of it (0.1 m), 2° to the left of it.
        let truth = [(0.0, 0.0, 0.0), (3.0, 0.0, 0.0), (3.0, 4.0, 1.5)];
        let odom = [(0.0, 0.0, 0.0), (2.94, 3.92, 1.5 + 2f64.to_radians())];
        let d = Drift::of(&truth, &odom).expect("both tracks");
        assert!((d.distance - 7.0).abs() < 1e-12 && (d.error - 0.1).abs() < 1e-12);
        assert!((d.heading_error_deg - 2.0).abs() < 1e-9);
        assert_eq!(
            d.line("x.svg"),
            "demo: drove 7.00 m; final odometry error 0.100 m (1.43 % of distance), heading 2.00°; plot x.svg"
        );
        assert_eq!(Drift::of(&truth, &[]), None);
        let still = Drift::of(&[(1.0, 1.0, 0.0)], &[(1.0, 1.0, 0.0)]).expect("both tracks");
        assert!(still.line("y").contains("(0.00 % of distance)"));
    }

    #[test]
    fn the_figure_draws_both_tracks_and_the_legend() {
        let truth = [(0.0, 0.0), (1.0, 0.0)];
        let odom = [(0.0, 0.0), (1.0, 0.1)];
        let svg = figure(&World::default(), &truth, &odom, "t <&>");
        // The two tracks and the two legend strokes.
        assert_eq!(svg.matches("<polyline").count(), 4);
        assert!(svg.contains("ground truth") && svg.contains("odometry") && svg.contains("t &lt;&amp;&gt;"));
    }

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
