//! The demo's second act (`nav_demo`): `local_nav_node` takes the robot to one goal. The record
//! (the true path and the points where the navigator's mode changed), the one-line summary and
//! the figure: the world's obstacles, the path, the goal and each mode change, coloured by mode
//! (R blue, L orange, T red). Everything here works on recorded data; the binary only fills a
//! [`NavRun`].

use mobil_world::World;

use crate::plot::{MapView, Stroke, Svg};
use crate::route::path_length;

/// R, L or T from the status' mode text ("rotate", "lock_left", "T", ...).
pub fn mode_letter(mode: &str) -> Option<char> {
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
#[derive(Debug, Clone, PartialEq)]
pub struct NavRun {
    /// The true path (`ground_truth`).
    pub path: Vec<(f64, f64)>,
    /// Where the mode became `letter`.
    pub changes: Vec<(f64, f64, char)>,
    /// The goal sent.
    pub goal: (f64, f64),
}

impl NavRun {
    /// An empty record of the run to `goal`.
    pub fn new(goal: (f64, f64)) -> NavRun {
        NavRun {
            path: Vec::new(),
            changes: Vec::new(),
            goal,
        }
    }

    /// Takes the mode of a status of the active goal: where its letter differs from the last
    /// one marked (or is the first), the change is marked at the robot's last true position.
    /// A mode that is none of R, L, T marks nothing.
    pub fn mode(&mut self, mode: &str) {
        if let Some(letter) = mode_letter(mode)
            && self.changes.last().map(|c| c.2) != Some(letter)
        {
            let &(x, y) = self.path.last().unwrap_or(&(f64::NAN, f64::NAN));
            self.changes.push((x, y, letter));
        }
    }

    /// The modes in the order they were entered ("RLR").
    pub fn modes(&self) -> String {
        self.changes.iter().map(|c| c.2).collect()
    }

    /// The figure's title: the node, the goal, the outcome, the modes.
    pub fn title(&self, node: &str, outcome: &str) -> String {
        format!(
            "{node}: local_nav to ({}, {}), {outcome}; modes {}",
            self.goal.0,
            self.goal.1,
            self.modes()
        )
    }

    /// The act's line: the outcome, the goal, the simulated seconds from the goal's acceptance
    /// (`sim_s`), the length of the true path, the modes in order, the plot.
    pub fn summary(&self, outcome: &str, sim_s: f64, svg: &str) -> String {
        format!(
            "demo: local_nav {outcome} goal ({}, {}) in {sim_s:.1} simulated s, {:.2} m driven, modes {}; plot {svg}",
            self.goal.0,
            self.goal.1,
            path_length(&self.path),
            self.modes().chars().map(String::from).collect::<Vec<_>>().join("→")
        )
    }
}

/// How the goal ended, as the line and the title say it: `reached`, or `failed (reason)`.
pub fn outcome_text(succeeded: bool, reason: &str) -> String {
    if succeeded {
        "reached".to_string()
    } else {
        format!("failed ({reason})")
    }
}

/// The plot: 1 m = 60 px, y up, everything in view with a 0.5 m margin, the caption below.
pub fn figure(world: &World, run: &NavRun, title: &str) -> String {
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
        let run = NavRun {
            path: vec![(0.0, 0.0), (4.0, 0.0)],
            changes: vec![(1.0, 0.0, 'L'), (3.0, 0.0, 'R')],
            goal: (4.0, 0.0),
        };
        let s = figure(&world, &run, "t <&>");
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

    #[test]
    fn a_mode_change_is_marked_where_the_robot_is_and_the_line_lists_them() {
        let mut run = NavRun::new((3.0, 4.0));
        run.mode("rotate");
        run.path.extend([(0.0, 0.0), (3.0, 0.0)]);
        run.mode("rotate");
        run.mode("reached");
        run.mode("lock_left");
        run.path.push((3.0, 4.0));
        run.mode("lock_right");
        run.mode("rotate");
        // The first mark before any true point: at NaN, as the figure skips it.
        assert_eq!(run.modes(), "RLR");
        assert!(run.changes[0].0.is_nan());
        assert_eq!(&run.changes[1..], &[(3.0, 0.0, 'L'), (3.0, 4.0, 'R')]);
        assert_eq!(
            run.summary(&outcome_text(true, ""), 13.26, "x.svg"),
            "demo: local_nav reached goal (3, 4) in 13.3 simulated s, 7.00 m driven, modes R→L→R; plot x.svg"
        );
        assert_eq!(
            run.title("/nav_demo", &outcome_text(false, "STUCK")),
            "/nav_demo: local_nav to (3, 4), failed (STUCK); modes RLR"
        );
    }
}
