//! The demo's fourth act (`terrain_demo`): `terrain/assessment` over the hexapod's walk flat →
//! slope → rough, its one-line summary and its figure: σ, α12 and α13 over the walk on a
//! background coloured by class, with the thresholds as lines and the advised gait as a strip.
//! Everything here works on the recorded assessments; the binary only fills the [`Sample`]s.
//!
//! The thresholds drawn are the library's defaults, which `params/hexapod.yaml` holds (a test of
//! `mobil_terrain` checks they agree).

use std::fmt::Write as _;

use mobil_terrain::TerrainConfig;

use crate::plot::escape;

/// One recorded assessment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Stamp (s).
    pub t: f64,
    /// σ (m).
    pub sigma: f64,
    /// α12 (rad).
    pub alpha12: f64,
    /// α13 (rad).
    pub alpha13: f64,
    /// The terrain class, an index of [`CLASS_NAMES`] (the message's `terrain_class`).
    pub class: u8,
    /// The advised gait, an index of [`GAIT_NAMES`] (the message's `advised_gait`).
    pub gait: u8,
}

/// The terrain classes by their number in `mobil_msgs/TerrainAssessment`.
pub const CLASS_NAMES: [&str; 4] = ["FLAT", "SLOPE", "UNEVEN", "BEYOND_LIMITS"];
const CLASS_FILL: [&str; 4] = ["#E5F5E0", "#DEEBF7", "#FEE6CE", "#FCBBA1"];
/// The advised gaits by their number in `mobil_msgs/TerrainAssessment`.
pub const GAIT_NAMES: [&str; 4] = ["tripod", "ripple", "wave", "reroute"];
const GAIT_FILL: [&str; 4] = ["#1B9E77", "#E69F00", "#D55E00", "#000000"];

/// Appends `sample` to the record unless it equals the last one: an identical assessment is
/// the last one republished with new counts, or a tripod's feet landing on level ground, and
/// one point is enough. True when it was appended.
pub fn push_new(samples: &mut Vec<Sample>, sample: Sample) -> bool {
    if samples.last() == Some(&sample) {
        return false;
    }
    samples.push(sample);
    true
}

fn name<'a>(names: &[&'a str; 4], k: u8) -> &'a str {
    names.get(usize::from(k)).copied().unwrap_or("?")
}

/// Runs of equal values: (first index, value).
fn runs(values: impl Iterator<Item = u8>) -> Vec<(usize, u8)> {
    let mut out: Vec<(usize, u8)> = Vec::new();
    for (i, v) in values.enumerate() {
        if out.last().is_none_or(|&(_, last)| last != v) {
            out.push((i, v));
        }
    }
    out
}

/// One curve: panel, its top value, the value of a sample, colour, label.
type Curve = (usize, f64, fn(&Sample) -> f64, &'static str, &'static str);

/// Width of the plotting area (px), left margin, panel height, gap.
const W: f64 = 800.0;
const LEFT: f64 = 70.0;
const PANEL: f64 = 200.0;
const GAP: f64 = 40.0;
const TOP: f64 = 40.0;
const STRIP: f64 = 24.0;

/// The plot: σ (cm) on top with σ_flat, σ_wave and σ_max; α12 and α13 (°) below with ε_α and
/// tilt_max; both on a background coloured by class; the advised gait as a strip underneath.
/// Time runs from the first to the last sample; each sample's class and gait hold until the next.
pub fn figure(samples: &[Sample], config: &TerrainConfig, title: &str) -> String {
    let t0 = samples.first().map_or(0.0, |s| s.t);
    let t1 = samples.last().map_or(1.0, |s| s.t).max(t0 + 1e-9);
    let px = |t: f64| LEFT + (t - t0) / (t1 - t0) * W;
    let sigma_top = (config.sigma_max * 100.0 * 1.25).max(samples.iter().fold(0.0f64, |m, s| m.max(s.sigma * 100.0)));
    let angle_top = (config.tilt_max.to_degrees() * 1.25).max(
        samples
            .iter()
            .fold(0.0f64, |m, s| m.max(s.alpha12.to_degrees()).max(s.alpha13.to_degrees())),
    );
    let panel_y = [TOP, TOP + PANEL + GAP];
    let py = |panel: usize, v: f64, top: f64| panel_y[panel] + PANEL * (1.0 - (v / top).clamp(0.0, 1.0));
    let strip_y = TOP + 2.0 * PANEL + GAP + 12.0;
    let (width, height) = (LEFT + W + 150.0, strip_y + STRIP + 50.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(s, r#"<text x="{LEFT}" y="22" font-size="16">{}</text>"#, escape(title));
    // Class bands behind both panels, and the gait strip.
    let end = |k: usize, list: &[(usize, u8)]| list.get(k + 1).map_or(t1, |&(i, _)| samples[i].t);
    let classes = runs(samples.iter().map(|s| s.class));
    for (k, &(i, c)) in classes.iter().enumerate() {
        let (a, b) = (px(samples[i].t), px(end(k, &classes)));
        for y in panel_y {
            let _ = writeln!(
                s,
                r#"<rect x="{a:.1}" y="{y:.1}" width="{:.1}" height="{PANEL:.1}" fill="{}"><title>{}</title></rect>"#,
                (b - a).max(0.0),
                CLASS_FILL.get(usize::from(c)).copied().unwrap_or("#FFFFFF"),
                name(&CLASS_NAMES, c)
            );
        }
    }
    let gaits = runs(samples.iter().map(|s| s.gait));
    for (k, &(i, g)) in gaits.iter().enumerate() {
        let (a, b) = (px(samples[i].t), px(end(k, &gaits)));
        let _ = writeln!(
            s,
            r#"<rect x="{a:.1}" y="{strip_y:.1}" width="{:.1}" height="{STRIP:.1}" fill="{}"><title>{}</title></rect>"#,
            (b - a).max(0.0),
            GAIT_FILL.get(usize::from(g)).copied().unwrap_or("#FFFFFF"),
            name(&GAIT_NAMES, g)
        );
        if b - a > 40.0 {
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{:.1}" fill="white">{}</text>"#,
                a + 4.0,
                strip_y + 17.0,
                name(&GAIT_NAMES, g)
            );
        }
    }
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="end">gait</text>"#,
        LEFT - 6.0,
        strip_y + 17.0
    );
    // Frames, threshold lines, axis labels.
    let thresholds: [(usize, f64, f64, &str); 5] = [
        (0, config.sigma_flat * 100.0, sigma_top, "σ_flat"),
        (0, config.sigma_wave * 100.0, sigma_top, "σ_wave"),
        (0, config.sigma_max * 100.0, sigma_top, "σ_max"),
        (1, config.epsilon_alpha.to_degrees(), angle_top, "ε_α"),
        (1, config.tilt_max.to_degrees(), angle_top, "tilt_max"),
    ];
    for (panel, v, top, label) in thresholds {
        let y = py(panel, v, top);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#555555" stroke-dasharray="5 4"/><text x="{:.1}" y="{:.1}">{label} {v:.3}</text>"##,
            LEFT + W,
            LEFT + W + 6.0,
            y + 4.0
        );
    }
    for (panel, top, unit) in [(0, sigma_top, "σ [cm]"), (1, angle_top, "angle [°]")] {
        let y = panel_y[panel];
        let _ = writeln!(
            s,
            r#"<rect x="{LEFT}" y="{y:.1}" width="{W}" height="{PANEL}" fill="none" stroke="black"/><text x="{:.1}" y="{:.1}" text-anchor="end">{top:.1}</text><text x="{:.1}" y="{:.1}" text-anchor="end">0</text><text x="{:.1}" y="{:.1}" text-anchor="end">{unit}</text>"#,
            LEFT - 6.0,
            y + 12.0,
            LEFT - 6.0,
            y + PANEL,
            LEFT - 6.0,
            y + PANEL / 2.0
        );
    }
    // The three curves.
    let line = |panel: usize, top: f64, f: fn(&Sample) -> f64| -> String {
        samples
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p.t), py(panel, f(p), top)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let curves: [Curve; 3] = [
        (0, sigma_top, |p| p.sigma * 100.0, "#000000", "σ"),
        (1, angle_top, |p| p.alpha12.to_degrees(), "#D55E00", "α12"),
        (1, angle_top, |p| p.alpha13.to_degrees(), "#0072B2", "α13"),
    ];
    for (k, (panel, top, f, stroke, label)) in curves.into_iter().enumerate() {
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{stroke}" stroke-width="1.8"/>"#,
            line(panel, top, f)
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" fill="{stroke}">{label}</text>"#,
            LEFT + 8.0 + 50.0 * k as f64,
            panel_y[panel] + 16.0
        );
    }
    // Time axis and the class legend.
    let base = strip_y + STRIP + 18.0;
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="{base:.1}">{t0:.1} s</text><text x="{:.1}" y="{base:.1}" text-anchor="end">{t1:.1} s (simulated)</text>"#,
        LEFT + W
    );
    let mut x = LEFT + 150.0;
    for (c, fill) in CLASS_NAMES.iter().zip(CLASS_FILL) {
        let _ = writeln!(
            s,
            r#"<rect x="{x:.1}" y="{:.1}" width="14" height="14" fill="{fill}" stroke="black"/><text x="{:.1}" y="{base:.1}">{c}</text>"#,
            base - 12.0,
            x + 18.0
        );
        x += 30.0 + 9.0 * c.len() as f64;
    }
    s.push_str("</svg>\n");
    s
}

/// Share of the walk's time (each sample holding until the next) per value 0…3 of a field.
pub fn shares(samples: &[Sample], field: fn(&Sample) -> u8) -> [f64; 4] {
    let mut time = [0.0; 4];
    for w in samples.windows(2) {
        if let Some(slot) = time.get_mut(usize::from(field(&w[0]))) {
            *slot += w[1].t - w[0].t;
        }
    }
    let total: f64 = time.iter().sum();
    if total > 0.0 {
        time.map(|t| t / total)
    } else {
        time
    }
}

/// "FLAT 25 %, SLOPE 31 %" for the values with a share.
pub fn share_text(names: &[&str; 4], shares: [f64; 4]) -> String {
    names
        .iter()
        .zip(shares)
        .filter(|&(_, f)| f > 0.0)
        .map(|(n, f)| format!("{n} {:.0} %", f * 100.0))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The figure's title: the walk, the assessments, the classes' shares.
pub fn title(samples: &[Sample]) -> String {
    format!(
        "hexapod walking flat → slope → rough: {} assessments; classes {}",
        samples.len(),
        share_text(&CLASS_NAMES, shares(samples, |s| s.class))
    )
}

/// The act's line: the walk's simulated span and its wall time (`wall_s`), the assessments,
/// the classes' and the advised gaits' shares of the walk's time, the plot.
pub fn summary(samples: &[Sample], wall_s: f64, svg: &str) -> String {
    let classes = share_text(&CLASS_NAMES, shares(samples, |s| s.class));
    let gaits = share_text(&GAIT_NAMES, shares(samples, |s| s.gait));
    let span = samples.last().map_or(0.0, |s| s.t) - samples.first().map_or(0.0, |s| s.t);
    format!(
        "demo: hexapod walked flat → slope → rough for {span:.1} simulated s ({wall_s:.1} s wall), {} assessments: {classes}; gaits {gaits}; plot {svg}",
        samples.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, sigma: f64, class: u8, gait: u8) -> Sample {
        Sample {
            t,
            sigma,
            alpha12: 0.0,
            alpha13: 5f64.to_radians(),
            class,
            gait,
        }
    }

    #[test]
    fn runs_of_equal_values() {
        let v = [0u8, 0, 1, 1, 2, 1];
        assert_eq!(runs(v.into_iter()), vec![(0, 0), (2, 1), (4, 2), (5, 1)]);
        assert_eq!(name(&GAIT_NAMES, 7), "?");
    }

    /// FLAT from 0 to 10 s, SLOPE from 10 to 40 s (the last sample holds no time): 25 % and 75 %.
    #[test]
    fn shares_of_the_walks_time() {
        let samples = [
            sample(0.0, 0.0, 0, 0),
            sample(10.0, 0.02, 1, 2),
            sample(40.0, 0.02, 2, 2),
        ];
        assert_eq!(shares(&samples, |s| s.class), [0.25, 0.75, 0.0, 0.0]);
        assert_eq!(
            share_text(&GAIT_NAMES, shares(&samples, |s| s.gait)),
            "tripod 25 %, wave 75 %"
        );
    }

    /// Samples at t = 0 (FLAT) and 10 s (SLOPE) over 800 px from x = 70: the band of the FLAT
    /// run covers [70, 870) (it holds until the next sample, which is the last); σ_top is
    /// 1.25 · 4 cm = 5 cm, so σ = 2 cm on the top panel (y 40 … 240) is at 240 − 200 · 2/5 = 160;
    /// α13 = 5° with angle_top 1.25 · 15° = 18.75° is at 480 − 200 · 5/18.75 = 426.7.
    #[test]
    fn svg_places_bands_curves_and_thresholds_by_hand() {
        let samples = [sample(0.0, 0.0, 0, 0), sample(10.0, 0.02, 1, 2)];
        let s = figure(&samples, &TerrainConfig::default(), "t <&>");
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        assert!(
            s.contains(r##"<rect x="70.0" y="40.0" width="800.0" height="200.0" fill="#E5F5E0">"##),
            "{s}"
        );
        assert!(s.contains(r#"points="70.0,240.0 870.0,160.0""#), "{s}");
        assert!(s.contains("870.0,426.7"), "{s}");
        // σ_wave = 2.5 cm: the dashed line at y = 240 − 200 · 2.5/5 = 140.
        assert!(s.contains(r#"y1="140.0""#), "{s}");
        assert!(s.contains("t &lt;&amp;&gt;"));
    }

    #[test]
    fn a_repeated_assessment_is_one_point() {
        let mut samples = Vec::new();
        assert!(push_new(&mut samples, sample(0.0, 0.0, 0, 0)));
        assert!(!push_new(&mut samples, sample(0.0, 0.0, 0, 0)));
        assert!(push_new(&mut samples, sample(0.5, 0.0, 0, 0)));
        assert_eq!(samples.len(), 2);
    }

    #[test]
    fn the_line_gives_the_span_the_shares_and_the_plot() {
        let samples = [
            sample(2.0, 0.0, 0, 0),
            sample(12.0, 0.02, 1, 1),
            sample(42.0, 0.02, 2, 1),
        ];
        assert_eq!(
            summary(&samples, 5.06, "x.svg"),
            "demo: hexapod walked flat → slope → rough for 40.0 simulated s (5.1 s wall), 3 assessments: \
             FLAT 25 %, SLOPE 75 %; gaits tripod 25 %, ripple 75 %; plot x.svg"
        );
        assert_eq!(
            title(&samples),
            "hexapod walking flat → slope → rough: 3 assessments; classes FLAT 25 %, SLOPE 75 %"
        );
    }
}
