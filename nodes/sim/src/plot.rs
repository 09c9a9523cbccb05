//! SVG plots of runs: the world's obstacles (filled grey) and any number of labelled tracks,
//! metres on both axes at the same scale.
#![warn(missing_docs)]

use plotters::coord::Shift;
use plotters::prelude::*;
use thiserror::Error;

use crate::world::{Obstacle, World};

/// Image size (px).
const SIZE: (u32, u32) = (900, 700);
/// Free space around the world and the tracks (m).
const MARGIN_M: f64 = 0.5;

/// One polyline of the plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// Legend text.
    pub label: String,
    /// Points (x, y) (m) in the world frame; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line colour (r, g, b).
    pub color: (u8, u8, u8),
}

/// A plot that could not be drawn or written.
#[derive(Debug, Error)]
pub enum PlotError {
    /// plotters failed to draw.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// The file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}

fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

type Range2 = ((f64, f64), (f64, f64));

/// The plotted area: every obstacle and every track point, plus a margin, widened to the aspect
/// ratio of the plotting area (`width` × `height` px) so that a metre is as long on both axes.
fn view(world: &World, tracks: &[Track], width: u32, height: u32) -> Range2 {
    let bounds = world.obstacles.iter().map(Obstacle::bounds);
    let points = tracks
        .iter()
        .flat_map(|t| t.points.iter().map(|&(x, y)| ([x, y], [x, y])));
    let (lo, hi) = bounds
        .chain(points)
        .filter(|(lo, hi)| lo.iter().chain(hi).all(|v| v.is_finite()))
        .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), (a, b)| {
            ([lo[0].min(a[0]), lo[1].min(a[1])], [hi[0].max(b[0]), hi[1].max(b[1])])
        });
    let (lo, hi) = if lo[0] <= hi[0] { (lo, hi) } else { ([0.0; 2], [0.0; 2]) };
    let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    let mut w = (hi[0] - lo[0]).max(1.0) + 2.0 * MARGIN_M;
    let mut h = (hi[1] - lo[1]).max(1.0) + 2.0 * MARGIN_M;
    let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
    if w / h > aspect {
        h = w / aspect;
    } else {
        w = h * aspect;
    }
    ((cx - 0.5 * w, cx + 0.5 * w), (cy - 0.5 * h, cy + 0.5 * h))
}

fn chart_builder<'a, 'b, DB: DrawingBackend>(area: &'a DrawingArea<DB, Shift>) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder.margin(15).x_label_area_size(40).y_label_area_size(50);
    builder
}

/// Draws the plot into `svg`; returns the scale actually drawn, px per metre on x and on y.
fn render(svg: &mut String, world: &World, tracks: &[Track], title: &str) -> Result<(f64, f64), PlotError> {
    let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let area = root.titled(title, ("sans-serif", 20)).map_err(draw_err)?;
    // Measure the plotting area left by the labels, then fit the view to its aspect ratio.
    let (width, height) = chart_builder(&area)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)
        .map_err(draw_err)?
        .plotting_area()
        .dim_in_pixel();
    let ((x0, x1), (y0, y1)) = view(world, tracks, width, height);
    let mut chart = chart_builder(&area)
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
        let outline: Vec<(f64, f64)> = match o {
            Obstacle::Circle { center, radius } => {
                let n = 48;
                (0..n)
                    .map(|i| {
                        let a = f64::from(i) / f64::from(n) * std::f64::consts::TAU;
                        (center[0] + radius * a.cos(), center[1] + radius * a.sin())
                    })
                    .collect()
            }
            Obstacle::Polygon { points } => points.iter().map(|p| (p[0], p[1])).collect(),
        };
        chart
            .draw_series(std::iter::once(Polygon::new(outline, grey)))
            .map_err(draw_err)?;
    }
    for t in tracks {
        let color = RGBColor(t.color.0, t.color.1, t.color.2);
        let points = t.points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite());
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(2)))
            .map_err(draw_err)?
            .label(t.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    if !tracks.is_empty() {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(draw_err)?;
    }
    let (a, b) = (chart.backend_coord(&(x0, y0)), chart.backend_coord(&(x1, y1)));
    let scale = (f64::from(b.0 - a.0) / (x1 - x0), f64::from(a.1 - b.1) / (y1 - y0));
    root.present().map_err(draw_err)?;
    Ok(scale)
}

/// Renders the plot as SVG text (900 × 700 px).
pub fn render_svg_string(world: &World, tracks: &[Track], title: &str) -> Result<String, PlotError> {
    let mut svg = String::new();
    render(&mut svg, world, tracks, title)?;
    Ok(svg)
}

/// Writes the plot to an SVG file at `path` (see [`render_svg_string`]).
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

    fn tracks() -> [Track; 2] {
        [
            Track {
                label: "ground truth".into(),
                points: vec![(0.0, 0.0), (1.0, 0.5), (2.0, 0.0)],
                color: (0, 90, 181),
            },
            Track {
                label: "odometry <&>".into(),
                points: vec![(0.0, 0.0), (f64::NAN, 1.0), (1.0, 0.6)],
                color: (220, 50, 32),
            },
        ]
    }

    /// The `points` attributes of the polylines drawn in `stroke`.
    fn polylines(svg: &str, stroke: &str) -> Vec<usize> {
        svg.split("<polyline")
            .skip(1)
            .filter(|p| p.contains(&format!("stroke=\"{stroke}\"")))
            .filter_map(|p| p.split("points=\"").nth(1)?.split('"').next())
            .map(|pts| pts.split_whitespace().count())
            .collect()
    }

    #[test]
    fn svg_has_title_labels_tracks_and_obstacles() {
        let svg = render_svg_string(&World::builtin(), &tracks(), "demo run").unwrap();
        assert!(svg.starts_with("<svg"));
        for text in ["demo run", "ground truth", "odometry &lt;&amp;&gt;", "x [m]", "y [m]"] {
            assert!(svg.contains(text), "missing {text}");
        }
        // Per track: the line itself (all finite points) and its legend sample (2 points).
        let mut blue = polylines(&svg, "#005AB5");
        blue.sort();
        assert_eq!(blue, vec![2, 3]);
        let mut red = polylines(&svg, "#DC3220");
        red.sort();
        assert_eq!(red, vec![2, 2], "the NaN point is skipped");
        // One filled grey polygon per obstacle.
        let grey = svg
            .split("<polygon")
            .skip(1)
            .filter(|p| p.contains("fill=\"#969696\""))
            .count();
        assert_eq!(grey, World::builtin().obstacles.len());
    }

    #[test]
    fn metres_are_square_and_the_view_fits_everything() {
        let mut svg = String::new();
        let (sx, sy) = render(&mut svg, &World::builtin(), &tracks(), "t").unwrap();
        assert!((sx / sy - 1.0).abs() < 0.01, "{sx} px/m on x, {sy} on y");
        // The room (12.2 m × 8.2 m outside) plus 0.5 m margins fills the plotting width:
        // (900 − 2·15 − 50) px / 13.2 m = 62.1 px/m, give or take a pixel.
        assert!((sx - 820.0 / 13.2).abs() < 0.2, "{sx}");
        // A track far outside the room widens the view to include it.
        let far = [Track {
            label: "far".into(),
            points: vec![(20.0, 30.0)],
            color: (0, 0, 255),
        }];
        let ((x0, x1), (y0, y1)) = view(&World::builtin(), &far, 800, 600);
        assert!(x0 <= -5.1 && x1 >= 20.0 && y0 <= -2.6 && y1 >= 30.0);
        assert!(((x1 - x0) / (y1 - y0) - 800.0 / 600.0).abs() < 1e-12);
        assert!(
            (y1 - y0 - (32.6 + 1.0)).abs() < 1e-12,
            "the taller side plus the margins"
        );
        // Nothing to show: a 2 m × 2 m view around the origin, widened to the aspect ratio.
        let ((x0, x1), (y0, y1)) = view(&World::default(), &[], 800, 800);
        assert_eq!(((x0, x1), (y0, y1)), ((-1.0, 1.0), (-1.0, 1.0)));
    }

    #[test]
    fn write_svg_writes_the_file_or_says_why_not() {
        let path = std::env::temp_dir().join(format!("mobil_sim_plot_{}.svg", std::process::id()));
        write_svg(&path, &World::builtin(), &tracks(), "file").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(text, render_svg_string(&World::builtin(), &tracks(), "file").unwrap());
        let err = write_svg(
            std::path::Path::new("/nonexistent/dir/x.svg"),
            &World::default(),
            &[],
            "x",
        )
        .unwrap_err();
        assert!(matches!(err, PlotError::Write { .. }) && err.to_string().contains("/nonexistent/dir/x.svg"));
    }
}
