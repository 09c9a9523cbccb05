//! SVG plots of runs: the world's obstacles and any number of tracks, metres on both axes at the
//! same scale.

use plotters::prelude::*;
use thiserror::Error;

use crate::world::{Obstacle, World};

/// One polyline of the plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: (u8, u8, u8),
}

/// A plot that could not be drawn or written.
#[derive(Debug, Error)]
pub enum PlotError {
    #[error("drawing failed: {0}")]
    Draw(String),
    #[error("cannot write {path}: {source}")]
    Write { path: String, source: std::io::Error },
}

fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// The plotted area: the tracks with a 1 m margin, widened to the obstacles near them, then to
/// the aspect ratio of the image so metres are square.
fn view(world: &World, tracks: &[Track], width: u32, height: u32) -> ((f64, f64), (f64, f64)) {
    let mut xs: Vec<f64> = tracks.iter().flat_map(|t| t.points.iter().map(|p| p.0)).collect();
    let mut ys: Vec<f64> = tracks.iter().flat_map(|t| t.points.iter().map(|p| p.1)).collect();
    for o in &world.obstacles {
        match o {
            Obstacle::Circle { center, radius } => {
                xs.extend([center[0] - radius, center[0] + radius]);
                ys.extend([center[1] - radius, center[1] + radius]);
            }
            Obstacle::Polygon { points } => {
                xs.extend(points.iter().map(|p| p[0]));
                ys.extend(points.iter().map(|p| p[1]));
            }
        }
    }
    let finite = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
    };
    let (mut x0, mut x1) = finite(&xs);
    let (mut y0, mut y1) = finite(&ys);
    if !(x0.is_finite() && y0.is_finite()) {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (mut w, mut h) = ((x1 - x0).max(1.0) + 1.0, (y1 - y0).max(1.0) + 1.0);
    let aspect = f64::from(width) / f64::from(height);
    if w / h > aspect {
        h = w / aspect;
    } else {
        w = h * aspect;
    }
    ((cx - 0.5 * w, cx + 0.5 * w), (cy - 0.5 * h, cy + 0.5 * h))
}

/// Renders the plot as SVG text.
pub fn render_svg_string(world: &World, tracks: &[Track], title: &str) -> Result<String, PlotError> {
    let (width, height) = (900u32, 700u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let ((x0, x1), (y0, y1)) = view(world, tracks, width - 80, height - 100);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("x [m]")
            .y_desc("y [m]")
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(draw_err)?;
        let grey = RGBColor(150, 150, 150).filled();
        for o in &world.obstacles {
            match o {
                Obstacle::Circle { center, radius } => {
                    let n = 48;
                    let pts: Vec<(f64, f64)> = (0..n)
                        .map(|i| {
                            let a = i as f64 / n as f64 * std::f64::consts::TAU;
                            (center[0] + radius * a.cos(), center[1] + radius * a.sin())
                        })
                        .collect();
                    chart
                        .draw_series(std::iter::once(Polygon::new(pts, grey)))
                        .map_err(draw_err)?;
                }
                Obstacle::Polygon { points } => {
                    let pts: Vec<(f64, f64)> = points.iter().map(|p| (p[0], p[1])).collect();
                    chart
                        .draw_series(std::iter::once(Polygon::new(pts, grey)))
                        .map_err(draw_err)?;
                }
            }
        }
        for t in tracks {
            let color = RGBColor(t.color.0, t.color.1, t.color.2);
            chart
                .draw_series(LineSeries::new(t.points.iter().copied(), color.stroke_width(2)))
                .map_err(draw_err)?
                .label(t.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(draw_err)?;
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Writes the plot to an SVG file.
pub fn write_svg(path: &std::path::Path, world: &World, tracks: &[Track], title: &str) -> Result<(), PlotError> {
    let svg = render_svg_string(world, tracks, title)?;
    std::fs::write(path, svg).map_err(|source| PlotError::Write {
        path: path.display().to_string(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_has_labels_tracks_and_obstacles() {
        let tracks = [
            Track {
                label: "ground truth".into(),
                points: vec![(0.0, 0.0), (1.0, 0.5), (2.0, 0.0)],
                color: (0, 0, 0),
            },
            Track {
                label: "odometry".into(),
                points: vec![(0.0, 0.0), (1.0, 0.6)],
                color: (220, 50, 32),
            },
        ];
        let svg = render_svg_string(&World::builtin(), &tracks, "run").unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("ground truth") && svg.contains("odometry") && svg.contains("x [m]"));
        assert!(svg.matches("<polyline").count() >= 2, "one polyline per track");
        assert!(svg.matches("<polygon").count() >= World::builtin().obstacles.len());
        let ((x0, x1), (y0, y1)) = view(&World::default(), &tracks, 800, 600);
        assert!(((x1 - x0) / (y1 - y0) - 800.0 / 600.0).abs() < 1e-9, "square metres");
    }
}
