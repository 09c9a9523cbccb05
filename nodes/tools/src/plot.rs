//! The demo's SVG figures, shared by `demo_driver`, `nav_demo` and `plan_demo`: a map panel (the
//! world's obstacles at one scale on both axes, y up, metre ticks) and time-series panels,
//! written as plain SVG text. Callers place everything in world metres (map) or in their
//! series' units; non-finite points are skipped, never drawn.

use std::fmt::Write as _;

use mobil_world::{Obstacle, World};

/// Fill of the world's obstacles.
pub const OBSTACLE_FILL: &str = "#969696";

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    /// SVG colour, e.g. `#141414`.
    pub color: &'static str,
    /// Width (px).
    pub width: f64,
    /// SVG dash pattern (`stroke-dasharray`), `None` for a solid line.
    pub dash: Option<&'static str>,
}

impl Stroke {
    /// A solid line.
    pub const fn solid(color: &'static str, width: f64) -> Self {
        Stroke {
            color,
            width,
            dash: None,
        }
    }

    /// A dashed line (8 px on, 5 px off).
    pub const fn dashed(color: &'static str, width: f64) -> Self {
        Stroke {
            color,
            width,
            dash: Some("8 5"),
        }
    }

    /// The stroke for an open shape (no fill).
    fn attributes(&self) -> String {
        format!(r#"fill="none" {}"#, self.outline())
    }

    /// The stroke alone, for a shape that sets its own fill.
    fn outline(&self) -> String {
        let mut a = format!(r#"stroke="{}" stroke-width="{}""#, self.color, self.width);
        if let Some(d) = self.dash {
            let _ = write!(a, r#" stroke-dasharray="{d}""#);
        }
        a
    }
}

/// A map panel: world coordinates (m) to pixels, one scale on both axes, y up. The panel spans
/// the fitted bounds plus a margin on every side; its top left corner is at `origin` (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapView {
    lo: [f64; 2],
    hi: [f64; 2],
    scale: f64,
    margin: f64,
    origin: (f64, f64),
}

impl MapView {
    /// A panel showing every obstacle of `world` and every finite point of `points`, with
    /// `margin` (m) of space around, at `scale` px per metre, its top left corner at (0, 0) px.
    /// With nothing to show it spans [−1, 1] m on both axes.
    pub fn fit(world: &World, points: impl IntoIterator<Item = (f64, f64)>, scale: f64, margin: f64) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut grow = |x: f64, y: f64| {
            if x.is_finite() && y.is_finite() {
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
            }
        };
        for o in &world.obstacles {
            let (a, b) = o.bounds();
            grow(a[0], a[1]);
            grow(b[0], b[1]);
        }
        for (x, y) in points {
            grow(x, y);
        }
        if lo[0] > hi[0] {
            (lo, hi) = ([-1.0; 2], [1.0; 2]);
        }
        MapView {
            lo,
            hi,
            scale,
            margin,
            origin: (0.0, 0.0),
        }
    }

    /// The same panel with its top left corner at (`x`, `y`) px.
    pub fn at(self, x: f64, y: f64) -> Self {
        MapView { origin: (x, y), ..self }
    }

    /// Pixel column of world x.
    pub fn x(&self, x: f64) -> f64 {
        self.origin.0 + (x - self.lo[0] + self.margin) * self.scale
    }

    /// Pixel row of world y (y up).
    pub fn y(&self, y: f64) -> f64 {
        self.origin.1 + (self.hi[1] + self.margin - y) * self.scale
    }

    /// Pixels per metre.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Width of the panel (px).
    pub fn width(&self) -> f64 {
        (self.hi[0] - self.lo[0] + 2.0 * self.margin) * self.scale
    }

    /// Height of the panel (px).
    pub fn height(&self) -> f64 {
        (self.hi[1] - self.lo[1] + 2.0 * self.margin) * self.scale
    }

    /// The world range shown, ((x_min, x_max), (y_min, y_max)) in metres, margins included.
    pub fn range(&self) -> ((f64, f64), (f64, f64)) {
        (
            (self.lo[0] - self.margin, self.hi[0] + self.margin),
            (self.lo[1] - self.margin, self.hi[1] + self.margin),
        )
    }
}

/// A time-series panel: the rectangle (`x`, `y`, `width`, `height`) px showing `t` on the
/// horizontal axis and the values on the vertical one, both ranges given by the caller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesPanel {
    x: f64,
    y: f64,
    width: f64,
    height: f64,
    t: (f64, f64),
    v: (f64, f64),
}

impl SeriesPanel {
    /// A panel spanning the finite points of `series`: t from the earliest to the latest, values
    /// from 0 (or the least, if negative) to the largest. An empty or flat range is widened to
    /// one unit, so that every panel can be drawn.
    pub fn fit(x: f64, y: f64, width: f64, height: f64, series: &[&[(f64, f64)]]) -> Self {
        let finite = || {
            series
                .iter()
                .flat_map(|s| s.iter())
                .filter(|(t, v)| t.is_finite() && v.is_finite())
        };
        let t0 = finite().map(|p| p.0).fold(f64::INFINITY, f64::min);
        let t1 = finite().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        let v0 = finite().map(|p| p.1).fold(0.0, f64::min);
        let v1 = finite().map(|p| p.1).fold(0.0, f64::max);
        let widen = |a: f64, b: f64| {
            if a.is_finite() && b > a {
                (a, b)
            } else if a.is_finite() {
                (a, a + 1.0)
            } else {
                (0.0, 1.0)
            }
        };
        SeriesPanel {
            x,
            y,
            width,
            height,
            t: widen(t0, t1),
            v: widen(v0, v1),
        }
    }

    /// Pixel column of time `t`.
    pub fn px(&self, t: f64) -> f64 {
        self.x + (t - self.t.0) / (self.t.1 - self.t.0) * self.width
    }

    /// Pixel row of value `v`.
    pub fn py(&self, v: f64) -> f64 {
        self.y + (self.v.1 - v) / (self.v.1 - self.v.0) * self.height
    }

    /// The time range shown.
    pub fn t_range(&self) -> (f64, f64) {
        self.t
    }

    /// The value range shown.
    pub fn v_range(&self) -> (f64, f64) {
        self.v
    }
}

/// Tick positions over `[lo, hi]`: multiples of a step of 1, 2 or 5 × 10ⁿ giving at most
/// `max_ticks` ticks (at least one step over the range).
pub fn ticks(lo: f64, hi: f64, max_ticks: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) || max_ticks == 0 {
        return Vec::new();
    }
    let raw = (hi - lo) / max_ticks as f64;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| (hi - lo) / s <= max_ticks as f64)
        .unwrap_or(10.0 * power);
    // A bound on a tick (0.3 / 0.1 = 2.9999999999999996) is one.
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    // Integer multiples of the power of ten, divided by its inverse below 1, so that the third
    // tick of 0.1 is 0.3 and not 0.30000000000000004.
    let k = (step / power).round() as i64;
    (first..=last)
        .map(|i| {
            if power >= 1.0 {
                (i * k) as f64 * power
            } else {
                (i * k) as f64 / (1.0 / power).round()
            }
        })
        .collect()
}

/// Text for a tick value: no trailing zeros, at most 4 decimals.
fn tick_label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Escapes text for SVG.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// An SVG document being drawn: a white page of `width` × `height` px, sans-serif text.
#[derive(Debug, Clone)]
pub struct Svg {
    width: f64,
    height: f64,
    body: String,
}

impl Svg {
    /// An empty white page.
    pub fn new(width: f64, height: f64) -> Self {
        let mut body = String::new();
        let _ = writeln!(body, r#"<rect width="100%" height="100%" fill="white"/>"#);
        Svg { width, height, body }
    }

    /// The world's obstacles, filled grey.
    pub fn world(&mut self, view: &MapView, world: &World) {
        for o in &world.obstacles {
            match o {
                Obstacle::Circle { center, radius } => {
                    let _ = writeln!(
                        self.body,
                        r#"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="{OBSTACLE_FILL}"/>"#,
                        view.x(center[0]),
                        view.y(center[1]),
                        radius * view.scale()
                    );
                }
                Obstacle::Polygon { points } => {
                    let pts: Vec<String> = points
                        .iter()
                        .map(|p| format!("{:.1},{:.1}", view.x(p[0]), view.y(p[1])))
                        .collect();
                    let _ = writeln!(
                        self.body,
                        r#"<polygon points="{}" fill="{OBSTACLE_FILL}"/>"#,
                        pts.join(" ")
                    );
                }
            }
        }
    }

    /// A frame round the map panel with a tick and its label at every whole metre (x along the
    /// bottom, y along the left edge, inside the panel) and the axis names.
    pub fn metre_axes(&mut self, view: &MapView) {
        self.axes(view, "m");
    }

    /// [`Svg::metre_axes`] for a map in another unit: ticks at every whole `unit`, the axes
    /// named "x [`unit`]" and "y [`unit`]" (e.g. "j", the quadruped's unit).
    pub fn axes(&mut self, view: &MapView, unit: &str) {
        let ((x0, x1), (y0, y1)) = view.range();
        let (left, top) = (view.x(x0), view.y(y1));
        let (right, bottom) = (view.x(x1), view.y(y0));
        let _ = writeln!(
            self.body,
            r##"<rect x="{left:.1}" y="{top:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#505050" stroke-width="1"/>"##,
            right - left,
            bottom - top
        );
        let max = |span: f64| (span.ceil() as usize).max(1);
        for t in ticks(x0, x1, max(x1 - x0)) {
            let x = view.x(t);
            let _ = writeln!(
                self.body,
                r##"<line x1="{x:.1}" y1="{bottom:.1}" x2="{x:.1}" y2="{:.1}" stroke="#505050"/><text x="{x:.1}" y="{:.1}" font-size="10" text-anchor="middle" fill="#505050">{}</text>"##,
                bottom - 5.0,
                bottom - 8.0,
                tick_label(t)
            );
        }
        for t in ticks(y0, y1, max(y1 - y0)) {
            let y = view.y(t);
            let _ = writeln!(
                self.body,
                r##"<line x1="{left:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#505050"/><text x="{:.1}" y="{:.1}" font-size="10" fill="#505050">{}</text>"##,
                left + 5.0,
                left + 7.0,
                y + 3.5,
                tick_label(t)
            );
        }
        let _ = writeln!(
            self.body,
            r##"<text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end" fill="#505050">x [{unit}] →, y [{unit}] ↑</text>"##,
            right - 4.0,
            top + 13.0
        );
    }

    /// A circle of `radius` (m) round the world point (`x`, `y`): outlined in `stroke`, filled
    /// with `fill` (an SVG colour or `none`) at `opacity`.
    pub fn circle(
        &mut self,
        view: &MapView,
        (x, y): (f64, f64),
        radius: f64,
        stroke: Stroke,
        fill: &str,
        opacity: f64,
    ) {
        let _ = writeln!(
            self.body,
            r#"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="{fill}" fill-opacity="{opacity}" {}/>"#,
            view.x(x),
            view.y(y),
            radius * view.scale(),
            stroke.outline()
        );
    }

    /// A polyline through the world points `points` (non-finite ones skipped).
    pub fn path(&mut self, view: &MapView, points: &[(f64, f64)], stroke: Stroke) {
        let px: Vec<(f64, f64)> = points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| (view.x(x), view.y(y)))
            .collect();
        self.polyline(&px, stroke);
    }

    /// A polyline through pixel points.
    pub fn polyline(&mut self, px: &[(f64, f64)], stroke: Stroke) {
        let pts: Vec<String> = px.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        let _ = writeln!(
            self.body,
            r#"<polyline points="{}" {}/>"#,
            pts.join(" "),
            stroke.attributes()
        );
    }

    /// A filled dot of radius `r` px at the pixel (`x`, `y`) with a black outline; `title` shows
    /// on hover.
    pub fn dot(&mut self, x: f64, y: f64, r: f64, fill: &str, title: Option<&str>) {
        let _ = write!(
            self.body,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r}" fill="{fill}" stroke="black">"#
        );
        if let Some(t) = title {
            let _ = write!(self.body, "<title>{}</title>", escape(t));
        }
        let _ = writeln!(self.body, "</circle>");
    }

    /// A closed polygon through the world points `points`, filled with `fill` at `opacity`,
    /// outlined by `stroke` if given (non-finite points skipped).
    pub fn polygon(&mut self, view: &MapView, points: &[(f64, f64)], fill: &str, opacity: f64, stroke: Option<Stroke>) {
        let pts: Vec<String> = points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| format!("{:.1},{:.1}", view.x(x), view.y(y)))
            .collect();
        let outline = stroke.map_or_else(|| r#"stroke="none""#.to_owned(), |s| s.outline());
        let _ = writeln!(
            self.body,
            r#"<polygon points="{}" fill="{fill}" fill-opacity="{opacity}" {outline}/>"#,
            pts.join(" ")
        );
    }

    /// A diagonal cross (✕) of half-size `half` px at the pixel (`x`, `y`).
    pub fn cross(&mut self, x: f64, y: f64, half: f64, color: &str, width: f64) {
        let _ = writeln!(
            self.body,
            r#"<path d="M {:.1} {:.1} L {:.1} {:.1} M {:.1} {:.1} L {:.1} {:.1}" stroke="{color}" stroke-width="{width}"/>"#,
            x - half,
            y - half,
            x + half,
            y + half,
            x - half,
            y + half,
            x + half,
            y - half
        );
    }

    /// An arrow from the world point (`x`, `y`) along `yaw` (rad, world frame), `length` m long,
    /// with a head at its tip.
    pub fn arrow(&mut self, view: &MapView, (x, y, yaw): (f64, f64, f64), length: f64, color: &str) {
        let (tx, ty) = (x + length * yaw.cos(), y + length * yaw.sin());
        let head = 0.35 * length;
        let wing = |side: f64| {
            let a = yaw + std::f64::consts::PI + side * 0.45;
            (view.x(tx + head * a.cos()), view.y(ty + head * a.sin()))
        };
        let (l, r) = (wing(1.0), wing(-1.0));
        let _ = writeln!(
            self.body,
            r#"<path d="M {:.1} {:.1} L {:.1} {:.1} M {:.1} {:.1} L {:.1} {:.1} L {:.1} {:.1}" fill="none" stroke="{color}" stroke-width="3" stroke-linejoin="round"/>"#,
            view.x(x),
            view.y(y),
            view.x(tx),
            view.y(ty),
            l.0,
            l.1,
            view.x(tx),
            view.y(ty),
            r.0,
            r.1
        );
    }

    /// Text at the pixel (`x`, `y`) (its baseline's start), escaped.
    pub fn text(&mut self, x: f64, y: f64, size: f64, text: &str) {
        let _ = writeln!(
            self.body,
            r#"<text x="{x:.1}" y="{y:.1}" font-size="{size}">{}</text>"#,
            escape(text)
        );
    }

    /// A frame round a series panel, ticks with labels on both axes, and the axis names.
    pub fn series_axes(&mut self, panel: &SeriesPanel, t_label: &str, v_label: &str) {
        let (t0, t1) = panel.t_range();
        let (v0, v1) = panel.v_range();
        let (left, right, top, bottom) = (panel.px(t0), panel.px(t1), panel.py(v1), panel.py(v0));
        let _ = writeln!(
            self.body,
            r##"<rect x="{left:.1}" y="{top:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#505050" stroke-width="1"/>"##,
            right - left,
            bottom - top
        );
        for t in ticks(t0, t1, 8) {
            let x = panel.px(t);
            let _ = writeln!(
                self.body,
                r##"<line x1="{x:.1}" y1="{bottom:.1}" x2="{x:.1}" y2="{:.1}" stroke="#505050"/><text x="{x:.1}" y="{:.1}" font-size="10" text-anchor="middle" fill="#505050">{}</text>"##,
                bottom + 4.0,
                bottom + 15.0,
                tick_label(t)
            );
        }
        for v in ticks(v0, v1, 4) {
            let y = panel.py(v);
            let _ = writeln!(
                self.body,
                r##"<line x1="{:.1}" y1="{y:.1}" x2="{left:.1}" y2="{y:.1}" stroke="#505050"/><text x="{:.1}" y="{:.1}" font-size="10" text-anchor="end" fill="#505050">{}</text>"##,
                left - 4.0,
                left - 6.0,
                y + 3.5,
                tick_label(v)
            );
        }
        let _ = writeln!(
            self.body,
            r#"<text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end">{}</text>"#,
            right,
            bottom + 28.0,
            escape(t_label)
        );
        let _ = writeln!(
            self.body,
            r#"<text x="{:.1}" y="{:.1}" font-size="12">{}</text>"#,
            left + 6.0,
            top + 14.0,
            escape(v_label)
        );
    }

    /// A series (t, value) as a polyline in `panel` (non-finite points skipped).
    pub fn series(&mut self, panel: &SeriesPanel, points: &[(f64, f64)], stroke: Stroke) {
        let px: Vec<(f64, f64)> = points
            .iter()
            .filter(|(t, v)| t.is_finite() && v.is_finite())
            .map(|&(t, v)| (panel.px(t), panel.py(v)))
            .collect();
        self.polyline(&px, stroke);
    }

    /// The finished document.
    pub fn finish(self) -> String {
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.0} {h:.0}\" font-family=\"sans-serif\">\n{}</svg>\n",
            self.body,
            w = self.width,
            h = self.height
        )
    }
}

/// The world a figure draws: the file `world_file` names, or the built-in world when it is empty
/// (the demo executables' `world_file` parameter).
pub fn world_to_draw(world_file: &str) -> Result<World, mobil_world::WorldError> {
    if world_file.is_empty() {
        Ok(World::builtin())
    } else {
        World::load(world_file)
    }
}

/// Writes `text` to `path`, creating its directory.
pub fn write_file(path: &str, text: &str) -> std::io::Result<()> {
    if let Some(dir) = std::path::Path::new(path).parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(path, text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_world_file_is_the_built_in_world() {
        assert_eq!(world_to_draw("").expect("built in"), World::builtin());
        assert!(world_to_draw("/nonexistent/world.yaml").is_err());
    }

    #[test]
    fn map_view_by_hand() {
        // A disc r 0.5 at (2, 0) and the point (0, 0): x ∈ [0, 2.5], y ∈ [−0.5, 0.5]; with a
        // 0.5 m margin at 60 px/m x = 0 is at 30 px and y = 0.5 at 30 px, y = 0 at 60 px.
        let world = World {
            obstacles: vec![Obstacle::Circle {
                center: [2.0, 0.0],
                radius: 0.5,
            }],
        };
        let v = MapView::fit(&world, [(0.0, 0.0), (f64::NAN, 9.0)], 60.0, 0.5);
        assert_eq!((v.x(0.0), v.y(0.0), v.y(0.5)), (30.0, 60.0, 30.0));
        assert_eq!((v.width(), v.height()), (3.5 * 60.0, 2.0 * 60.0));
        assert_eq!(v.range(), ((-0.5, 3.0), (-1.0, 1.0)));
        let moved = v.at(10.0, 100.0);
        assert_eq!((moved.x(0.0), moved.y(0.0)), (40.0, 160.0));
        // Nothing to show: [−1, 1] on both axes.
        let empty = MapView::fit(&World { obstacles: vec![] }, [], 10.0, 0.0);
        assert_eq!((empty.width(), empty.height(), empty.x(-1.0)), (20.0, 20.0, 0.0));
    }

    #[test]
    fn ticks_by_hand() {
        assert_eq!(ticks(0.0, 10.0, 5), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(ticks(-0.5, 3.0, 3), vec![0.0, 2.0]);
        assert_eq!(ticks(-0.5, 3.0, 4), vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(ticks(0.0, 1.43, 4), vec![0.0, 0.5, 1.0]);
        assert_eq!(ticks(0.0, 0.3, 3), vec![0.0, 0.1, 0.2, 0.3]);
        assert_eq!(ticks(3.0, 1.0, 4), Vec::<f64>::new());
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(-0.0), "0");
        assert_eq!(tick_label(12.0), "12");
    }

    #[test]
    fn series_panel_by_hand() {
        // t 2..6 over 400 px from x = 50; values 0..2 over 100 px from y = 10.
        let s: &[(f64, f64)] = &[(2.0, 2.0), (4.0, 1.0), (6.0, 0.5), (f64::NAN, 7.0)];
        let p = SeriesPanel::fit(50.0, 10.0, 400.0, 100.0, &[s]);
        assert_eq!((p.t_range(), p.v_range()), ((2.0, 6.0), (0.0, 2.0)));
        assert_eq!((p.px(2.0), p.px(4.0), p.py(2.0), p.py(1.0)), (50.0, 250.0, 10.0, 60.0));
        let mut svg = Svg::new(500.0, 150.0);
        svg.series(&p, s, Stroke::dashed("#000", 1.0));
        let text = svg.finish();
        assert!(
            text.contains(r##"points="50.0,10.0 250.0,60.0 450.0,85.0" fill="none" stroke="#000" stroke-width="1" stroke-dasharray="8 5""##),
            "{text}"
        );
        // No data: one unit each way.
        let empty = SeriesPanel::fit(0.0, 0.0, 10.0, 10.0, &[]);
        assert_eq!((empty.t_range(), empty.v_range()), ((0.0, 1.0), (0.0, 1.0)));
    }

    #[test]
    fn arrow_points_along_its_yaw() {
        // From (0, 0) along +y, 1 m at 100 px/m in a view whose y = 0 is at row 100: the tip is
        // 100 px up; the head's wings sit 0.35·cos(0.45) = 0.315 m back and 0.35·sin(0.45) = 0.152 m aside,
        // the first to the right (+x) of an arrow pointing up.
        let world = World { obstacles: vec![] };
        let v = MapView::fit(&world, [(-1.0, 0.0), (1.0, 1.0)], 100.0, 0.0);
        let mut svg = Svg::new(200.0, 100.0);
        svg.arrow(&v, (0.0, 0.0, std::f64::consts::FRAC_PI_2), 1.0, "red");
        let text = svg.finish();
        let (dx, dy) = (0.35 * 0.45f64.sin() * 100.0, 0.35 * 0.45f64.cos() * 100.0);
        let expect = format!(
            "M 100.0 100.0 L 100.0 0.0 M {:.1} {:.1} L 100.0 0.0 L {:.1} {:.1}",
            100.0 + dx,
            dy,
            100.0 - dx,
            dy
        );
        assert!(text.contains(&expect), "{expect}\n{text}");
    }

    #[test]
    fn filled_shapes_with_a_stroke_name_their_fill_once() {
        // An attribute given twice makes the whole SVG invalid XML (viewers refuse it).
        let world = World { obstacles: vec![] };
        let v = MapView::fit(&world, [(-1.0, -1.0), (1.0, 1.0)], 100.0, 0.0);
        let mut svg = Svg::new(200.0, 200.0);
        svg.circle(&v, (0.0, 0.0), 0.5, Stroke::dashed("#c01818", 1.0), "#e04040", 0.35);
        svg.polygon(
            &v,
            &[(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)],
            "#e04040",
            0.35,
            Some(Stroke::solid("#000", 1.0)),
        );
        let text = svg.finish();
        let shapes: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("<circle") || l.starts_with("<polygon"))
            .collect();
        assert_eq!(shapes.len(), 2, "{text}");
        for shape in shapes {
            assert_eq!(shape.matches(" fill=").count(), 1, "{shape}");
            assert_eq!(shape.matches(" stroke=").count(), 1, "{shape}");
        }
    }
}
