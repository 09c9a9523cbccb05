//! `nav_demo`: the demo's second act. Sends one goal to `local_nav_node` (`goal_pose`, in `odom`),
//! records the true path (`ground_truth`) and the navigator's modes (`local_nav/status`) until
//! the goal succeeds or fails, then writes an SVG of the world's obstacles, the path, the goal and
//! each point where the mode changed, coloured by mode (R blue, L orange, T red), and prints a
//! one-line summary.

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_ros::params::ParamValues;
use mobil_ros::time::stamp_from_nanos;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_sim::world::{Obstacle, World};
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::info;

fn decl() -> NodeDecl {
    NodeDecl::new(
        "nav_demo",
        "Sends a goal to local_nav_node, records the path and the modes, plots them",
    )
    .param(ParamSpec::doubles("goal", &[3.0, 4.0], "goal x, y in odom [m]"))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/local_nav.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::string(
        "world_file",
        "",
        "world to draw (empty: the built-in world)",
    ))
    .param(ParamSpec::double("timeout_s", 60.0, "wall time allowed for the whole run [s]").above(0.0))
    .check(|p: &ParamValues| match p.f64s("goal")?.as_slice() {
        [x, y] if x.is_finite() && y.is_finite() => Ok(()),
        _ => Err("goal must be two finite numbers [x, y]".into()),
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

/// R, L or T from the status' mode text ("rotate", "lock_left", "T", ...).
fn mode_letter(mode: &str) -> Option<char> {
    let m = mode.trim().to_ascii_lowercase();
    [('R', "rotate"), ('L', "lock"), ('T', "track")]
        .into_iter()
        .find(|(letter, word)| {
            m.starts_with(word)
                || (m.starts_with(letter.to_ascii_lowercase())
                    && !m[1..].starts_with(|c: char| c.is_ascii_alphabetic()))
        })
        .map(|(letter, _)| letter)
}

/// Colour of a mode's marks.
fn mode_color(letter: char) -> &'static str {
    match letter {
        'R' => "#005AB5",
        'L' => "#E69F00",
        _ => "#DC3220",
    }
}

/// A recorded run, in odom (= world) coordinates.
struct Run {
    path: Vec<(f64, f64)>,
    /// Where the mode became `letter`.
    changes: Vec<(f64, f64, char)>,
    goal: (f64, f64),
}

/// The plot as plain SVG: 1 m = `scale` px, y up, everything in view with a 0.5 m margin.
fn svg(world: &World, run: &Run, title: &str) -> String {
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
    for &(x, y) in run.path.iter().chain(std::iter::once(&run.goal)) {
        grow(x, y);
    }
    if lo[0] > hi[0] {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    let margin = 0.5;
    let scale = 60.0;
    let (w, h) = (hi[0] - lo[0] + 2.0 * margin, hi[1] - lo[1] + 2.0 * margin);
    let px = |x: f64| (x - lo[0] + margin) * scale;
    let py = |y: f64| (hi[1] + margin - y) * scale;
    let (width, height) = (w * scale, h * scale + 60.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for o in &world.obstacles {
        match o {
            Obstacle::Circle { center, radius } => {
                let _ = writeln!(
                    s,
                    r##"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="#969696"/>"##,
                    px(center[0]),
                    py(center[1]),
                    radius * scale
                );
            }
            Obstacle::Polygon { points } => {
                let pts: Vec<String> = points
                    .iter()
                    .map(|p| format!("{:.1},{:.1}", px(p[0]), py(p[1])))
                    .collect();
                let _ = writeln!(s, r##"<polygon points="{}" fill="#969696"/>"##, pts.join(" "));
            }
        }
    }
    let pts: Vec<String> = run
        .path
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
        .collect();
    let _ = writeln!(
        s,
        r##"<polyline points="{}" fill="none" stroke="#141414" stroke-width="2"/>"##,
        pts.join(" ")
    );
    for &(x, y, letter) in &run.changes {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="6" fill="{}" stroke="black"><title>{letter}</title></circle>"#,
            px(x),
            py(y),
            mode_color(letter)
        );
    }
    let (gx, gy) = (px(run.goal.0), py(run.goal.1));
    let _ = writeln!(
        s,
        r#"<path d="M {:.1} {:.1} L {:.1} {:.1} M {:.1} {:.1} L {:.1} {:.1}" stroke="black" stroke-width="3"/>"#,
        gx - 8.0,
        gy - 8.0,
        gx + 8.0,
        gy + 8.0,
        gx - 8.0,
        gy + 8.0,
        gx + 8.0,
        gy - 8.0
    );
    let base = h * scale;
    let _ = writeln!(
        s,
        r#"<text x="10" y="{:.0}" font-size="16">{}</text>"#,
        base + 22.0,
        escape(title)
    );
    let mut x = 10.0;
    for (letter, label) in [('R', "R: rotate"), ('L', "L: lock"), ('T', "T: track")] {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.0}" cy="{:.0}" r="6" fill="{}" stroke="black"/><text x="{:.0}" y="{:.0}" font-size="14">{label}</text>"#,
            x + 6.0,
            base + 44.0,
            mode_color(letter),
            x + 16.0,
            base + 49.0
        );
        x += 110.0;
    }
    let _ = writeln!(
        s,
        r#"<text x="{x:.0}" y="{:.0}" font-size="14">✕ goal; line: ground truth; dot: mode entered there</text>"#,
        base + 49.0
    );
    s.push_str("</svg>\n");
    s
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let goal = match p.f64s("goal").map_err(map_err)?.as_slice() {
        [x, y] => (*x, *y),
        _ => anyhow::bail!("goal must be [x, y]"),
    };
    let out = p.string("output_svg").map_err(map_err)?;
    let world_file = p.string("world_file").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    let world = if world_file.is_empty() {
        World::builtin()
    } else {
        World::load(&world_file)?
    };

    let goal_pub = node.publisher::<PoseStamped>("goal_pose", &qos::default_qos())?;
    let truth_sub = node.subscription::<Odometry>("ground_truth", &qos::default_qos())?;
    let status_sub = node.subscription::<NavStatus>("local_nav/status", &qos::latched())?;
    let truth = truth_sub.async_stream();
    let status = status_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut resend = tokio::time::interval(Duration::from_millis(500));
    tokio::pin!(truth, status, shutdown);

    let started = Instant::now();
    let mut record = Run {
        path: Vec::new(),
        changes: Vec::new(),
        goal,
    };
    let mut accepted_at: Option<i64> = None;
    let mut last_letter: Option<char> = None;
    let (final_state, reason) = loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if started.elapsed() > timeout {
                    anyhow::bail!("local_nav did not finish within {timeout:?} (is local_nav_node running on this ROS_DOMAIN_ID?)");
                }
                // Repeated until the navigator shows it active: the first may be lost in discovery.
                if accepted_at.is_none() && !record.path.is_empty() {
                    let mut msg = PoseStamped::default();
                    msg.header.frame_id = "odom".into();
                    msg.header.stamp = stamp_from_nanos(node.now_nanos());
                    msg.pose.position.x = goal.0;
                    msg.pose.position.y = goal.1;
                    msg.pose.orientation.w = 1.0;
                    let _ = goal_pub.publish(msg);
                }
            }
            Some(Ok((m, _))) = truth.next() => {
                record.path.push((m.pose.pose.position.x, m.pose.pose.position.y));
            }
            Some(Ok((s, _))) = status.next() => {
                let ours = (s.goal.position.x - goal.0).hypot(s.goal.position.y - goal.1) < 1e-6;
                if s.state == NavStatus::ACTIVE && ours && accepted_at.is_none() {
                    info!("goal ({}, {}) accepted", goal.0, goal.1);
                    accepted_at = Some(node.now_nanos());
                }
                if accepted_at.is_none() {
                    continue;
                }
                if s.state == NavStatus::ACTIVE {
                    if let Some(letter) = mode_letter(&s.mode)
                        && last_letter != Some(letter)
                    {
                        let &(x, y) = record.path.last().unwrap_or(&(f64::NAN, f64::NAN));
                        record.changes.push((x, y, letter));
                        last_letter = Some(letter);
                    }
                } else if s.state == NavStatus::SUCCEEDED || s.state == NavStatus::FAILED {
                    break (s.state, s.reason);
                }
            }
        }
    };
    let sim_s = accepted_at.map_or(0.0, |t| (node.now_nanos() - t) as f64 * 1e-9);
    let length: f64 = record
        .path
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum();
    let modes: String = record.changes.iter().map(|c| c.2).collect();
    let outcome = if final_state == NavStatus::SUCCEEDED {
        "reached".to_string()
    } else {
        format!("failed ({reason})")
    };
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).ok();
    }
    let title = format!(
        "{}: local_nav to ({}, {}), {outcome}; modes {modes}",
        node.names().fully_qualified_node(),
        goal.0,
        goal.1
    );
    std::fs::write(&out, svg(&world, &record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!(
        "demo: local_nav {outcome} goal ({}, {}) in {sim_s:.1} simulated s, {length:.2} m driven, modes {}; plot {out}",
        goal.0,
        goal.1,
        modes.chars().map(String::from).collect::<Vec<_>>().join("→")
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_letters_from_status_text() {
        assert_eq!(mode_letter("rotate"), Some('R'));
        assert_eq!(mode_letter("lock_left"), Some('L'));
        assert_eq!(mode_letter("Track right"), Some('T'));
        assert_eq!(mode_letter("T"), Some('T'));
        assert_eq!(mode_letter("L-left"), Some('L'));
        assert_eq!(mode_letter("reached"), None);
        assert_eq!(mode_letter("running"), None, "an R word that is not rotate");
        assert_eq!(mode_letter(""), None);
    }

    #[test]
    fn svg_places_obstacles_path_and_marks_by_hand() {
        // A disc r 0.5 at (2, 0); path (0, 0) → (4, 0); bounds x [0, 4], y [-0.5, 0.5], so with
        // the 0.5 m margin x = 0 is at 30 px and y = 0 at (0.5 + 0.5) · 60 = 60 px.
        let world = World {
            obstacles: vec![Obstacle::Circle {
                center: [2.0, 0.0],
                radius: 0.5,
            }],
        };
        let run = Run {
            path: vec![(0.0, 0.0), (4.0, 0.0)],
            changes: vec![(1.0, 0.0, 'L'), (3.0, 0.0, 'R')],
            goal: (4.0, 0.0),
        };
        let s = svg(&world, &run, "t <&>");
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        // Width (4 + 1) m · 60 = 300 px; height (1 + 1) m · 60 + 60 = 180 px.
        assert!(s.contains(r#"width="300" height="180""#), "{s}");
        assert!(
            s.contains(r##"<circle cx="150.0" cy="60.0" r="30.0" fill="#969696"/>"##),
            "{s}"
        );
        assert!(s.contains(r#"points="30.0,60.0 270.0,60.0""#), "{s}");
        // The mode marks at x = 1 (90 px, orange L) and x = 3 (210 px, blue R).
        assert!(s.contains(r##"cx="90.0" cy="60.0" r="6" fill="#E69F00""##), "{s}");
        assert!(s.contains(r##"cx="210.0" cy="60.0" r="6" fill="#005AB5""##), "{s}");
        assert!(s.contains("t &lt;&amp;&gt;"));
    }
}
