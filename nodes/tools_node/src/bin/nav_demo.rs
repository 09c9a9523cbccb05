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
use mobil_tools::plot::{write_file, MapView, Stroke, Svg};
use mobil_world::World;
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

/// The plot: 1 m = 60 px, y up, everything in view with a 0.5 m margin, the caption below.
fn svg(world: &World, run: &Run, title: &str) -> String {
    let shown = run.path.iter().copied().chain(std::iter::once(run.goal));
    let map = MapView::fit(world, shown, 60.0, 0.5);
    let base = map.height();
    let mut s = Svg::new(map.width(), base + 60.0);
    s.world(&map, world);
    s.metre_axes(&map);
    s.path(&map, &run.path, Stroke::solid("#141414", 2.0));
    for &(x, y, letter) in &run.changes {
        s.dot(map.x(x), map.y(y), 6.0, mode_color(letter), Some(&letter.to_string()));
    }
    s.cross(map.x(run.goal.0), map.y(run.goal.1), 8.0, "black", 3.0);
    s.text(10.0, base + 22.0, 16.0, title);
    let mut x = 10.0;
    for (letter, label) in [('R', "R: rotate"), ('L', "L: lock"), ('T', "T: track")] {
        s.dot(x + 6.0, base + 44.0, 6.0, mode_color(letter), None);
        s.text(x + 16.0, base + 49.0, 14.0, label);
        x += 110.0;
    }
    s.text(
        x,
        base + 49.0,
        14.0,
        "✕ goal; line: ground truth; dot: mode entered there",
    );
    s.finish()
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
    let title = format!(
        "{}: local_nav to ({}, {}), {outcome}; modes {modes}",
        node.names().fully_qualified_node(),
        goal.0,
        goal.1
    );
    write_file(&out, &svg(&world, &record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
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
    use mobil_world::Obstacle;

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
        // Metre ticks along the bottom (y = −1 m at 120 px): x = 0 at 30 px, x = 4 at 270 px.
        assert!(s.contains(r#"<line x1="30.0" y1="120.0" x2="30.0" y2="115.0""#), "{s}");
        assert!(
            s.contains(r#"<line x1="270.0" y1="120.0" x2="270.0" y2="115.0""#),
            "{s}"
        );
        assert!(
            s.contains(r##"points="30.0,60.0 270.0,60.0" fill="none" stroke="#141414""##),
            "{s}"
        );
        // The mode marks at x = 1 (90 px, orange L) and x = 3 (210 px, blue R).
        assert!(s.contains(r##"cx="90.0" cy="60.0" r="6" fill="#E69F00""##), "{s}");
        assert!(s.contains(r##"cx="210.0" cy="60.0" r="6" fill="#005AB5""##), "{s}");
        assert!(s.contains("t &lt;&amp;&gt;"));
    }
}
