//! `terrain_demo`: the demo's fourth act. Records `terrain/assessment` while `hexapod_sim` walks
//! the course flat → slope → rough and `terrain_node` assesses its touchdowns, until an
//! assessment is stamped `walk_s` simulated seconds or later; then writes an SVG of σ, α12 and
//! α13 over the walk on a background coloured by class, with the thresholds as lines and the
//! advised gait as a strip, and prints a one-line summary.
//!
//! The thresholds drawn are the library's defaults, which `params/hexapod.yaml` holds (a test of
//! `mobil_terrain` checks they agree).

use futures::StreamExt;
use mobil_msgs::mobil_msgs::msg::TerrainAssessment;
use mobil_ros::time::secs_from_stamp;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_terrain::TerrainConfig;
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::{Duration, Instant};

fn decl() -> NodeDecl {
    NodeDecl::new(
        "terrain_demo",
        "Records terrain/assessment over a hexapod's walk and plots σ, α12, α13, class and gait",
    )
    .param(ParamSpec::double("walk_s", 40.0, "stop at the first assessment stamped this late [s]").above(0.0))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/hexapod_terrain.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::double("timeout_s", 60.0, "wall time allowed for the whole run [s]").above(0.0))
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

/// One recorded assessment.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sample {
    /// Stamp (s).
    t: f64,
    /// σ (m).
    sigma: f64,
    /// α12 (rad).
    alpha12: f64,
    /// α13 (rad).
    alpha13: f64,
    class: u8,
    gait: u8,
}

const CLASS_NAMES: [&str; 4] = ["FLAT", "SLOPE", "UNEVEN", "BEYOND_LIMITS"];
const CLASS_FILL: [&str; 4] = ["#E5F5E0", "#DEEBF7", "#FEE6CE", "#FCBBA1"];
const GAIT_NAMES: [&str; 4] = ["tripod", "ripple", "wave", "reroute"];
const GAIT_FILL: [&str; 4] = ["#1B9E77", "#E69F00", "#D55E00", "#000000"];

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
fn svg(samples: &[Sample], config: &TerrainConfig, title: &str) -> String {
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

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Share of the walk's time (each sample holding until the next) per value 0…3 of a field.
fn shares(samples: &[Sample], field: fn(&Sample) -> u8) -> [f64; 4] {
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
fn share_text(names: &[&str; 4], shares: [f64; 4]) -> String {
    names
        .iter()
        .zip(shares)
        .filter(|&(_, f)| f > 0.0)
        .map(|(n, f)| format!("{n} {:.0} %", f * 100.0))
        .collect::<Vec<_>>()
        .join(", ")
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let walk_s = p.f64("walk_s").map_err(map_err)?;
    let out = p.string("output_svg").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    // Every assessment: depth 100 matches the latched writer and keeps a tripod's burst.
    let sub = node.subscription::<TerrainAssessment>(
        "terrain/assessment",
        &qos::reliable(100).durability(ros2_client::qos::Durability::TransientLocal),
    )?;
    let stream = sub.async_stream();
    let shutdown = shutdown_signal();
    let deadline = tokio::time::sleep(timeout);
    tokio::pin!(stream, shutdown, deadline);
    let started = Instant::now();
    let mut samples: Vec<Sample> = Vec::new();
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = &mut deadline => anyhow::bail!(
                "no assessment stamped {walk_s} s within {timeout:?} ({} recorded; are hexapod_sim and terrain_node running on this ROS_DOMAIN_ID?)",
                samples.len()
            ),
            Some(m) = stream.next() => {
                let Ok((a, _)) = m else { continue };
                let Some(t) = secs_from_stamp(&a.header.stamp) else { continue };
                let sample = Sample {
                    t,
                    sigma: a.sigma,
                    alpha12: a.alpha12,
                    alpha13: a.alpha13,
                    class: a.terrain_class,
                    gait: a.advised_gait,
                };
                // An identical one is the last assessment republished with new counts, or a
                // tripod's feet landing on level ground: one point is enough.
                if samples.last() == Some(&sample) {
                    continue;
                }
                samples.push(sample);
                if t >= walk_s {
                    break;
                }
            }
        }
    }
    let config = TerrainConfig::default();
    let classes = share_text(&CLASS_NAMES, shares(&samples, |s| s.class));
    let gaits = share_text(&GAIT_NAMES, shares(&samples, |s| s.gait));
    let span = samples.last().map_or(0.0, |s| s.t) - samples.first().map_or(0.0, |s| s.t);
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).ok();
    }
    let title = format!(
        "hexapod walking flat → slope → rough: {} assessments; classes {classes}",
        samples.len()
    );
    std::fs::write(&out, svg(&samples, &config, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!(
        "demo: hexapod walked flat → slope → rough for {span:.1} simulated s ({:.1} s wall), {} assessments: {classes}; gaits {gaits}; plot {out}",
        started.elapsed().as_secs_f64(),
        samples.len()
    );
    Ok(())
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
        let s = svg(&samples, &TerrainConfig::default(), "t <&>");
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
}
