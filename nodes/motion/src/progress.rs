//! The progress checker as Nav2 users know it (`nav2_controller::SimpleProgressChecker`): the
//! robot must move at least `required_movement_radius` from where it last made progress within
//! `movement_time_allowance`, or the goal is aborted. Time is an input (seconds of ROS time, so
//! the allowance is simulated seconds under a simulated clock); no clock inside.

use nalgebra::Point2;

use crate::{nav2, Outcome};

/// Nav2's two progress parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgressSettings {
    /// Distance (m) from the last progress point that counts as progress. Nav2's default 0.5.
    pub required_movement_radius: f64,
    /// Time (s) allowed to make that progress. Nav2's default 10.
    pub movement_time_allowance: f64,
}

impl Default for ProgressSettings {
    fn default() -> Self {
        ProgressSettings {
            required_movement_radius: 0.5,
            movement_time_allowance: 10.0,
        }
    }
}

/// What [`ProgressChecker::check`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress {
    /// Moving, or still within the allowance.
    Ok,
    /// No movement beyond the radius for longer than the allowance: the time (s) since the
    /// last progress point.
    Stuck {
        /// Seconds since the robot was last at least the radius away from its anchor.
        since: f64,
    },
}

/// Progress since the last anchor (the pose where the robot last moved the radius).
#[derive(Debug, Clone, PartialEq)]
pub struct ProgressChecker {
    settings: ProgressSettings,
    anchor: Option<(Point2<f64>, f64)>,
}

impl ProgressChecker {
    /// A checker with no anchor yet (the first check sets it).
    pub fn new(settings: ProgressSettings) -> Self {
        ProgressChecker { settings, anchor: None }
    }

    /// The settings.
    pub fn settings(&self) -> ProgressSettings {
        self.settings
    }

    /// Forgets the anchor (a new goal).
    pub fn reset(&mut self) {
        self.anchor = None;
    }

    /// Checks the robot at `position` at ROS time `now` (s). The anchor moves to the robot each
    /// time it is farther than the radius from it. Time going backwards (a restarted simulation,
    /// a clock reset) or a non-finite input restarts the window at the new time: no stale
    /// anchor can abort a goal, and no clock reset can keep one alive for ever.
    pub fn check(&mut self, position: Point2<f64>, now: f64) -> Progress {
        if !(position.x.is_finite() && position.y.is_finite() && now.is_finite()) {
            return Progress::Ok;
        }
        match self.anchor {
            Some((anchor, since))
                if now >= since && (position - anchor).norm() <= self.settings.required_movement_radius =>
            {
                let elapsed = now - since;
                if elapsed > self.settings.movement_time_allowance {
                    Progress::Stuck { since: elapsed }
                } else {
                    Progress::Ok
                }
            }
            _ => {
                self.anchor = Some((position, now));
                Progress::Ok
            }
        }
    }
}

/// How the progress checker ends a goal: `ABORTED` with Nav2's `FAILED_TO_MAKE_PROGRESS`,
/// after `since` seconds within `radius` metres (two decimals, so 1.04 s against an allowance
/// of 1 s does not print "1.0 s").
pub fn no_progress(since: f64, radius: f64) -> Outcome {
    Outcome::failed(
        "ABORTED",
        format!("no progress: moved less than {radius} m in {since:.2} s"),
        nav2::follow_path::FAILED_TO_MAKE_PROGRESS,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> ProgressChecker {
        ProgressChecker::new(ProgressSettings {
            required_movement_radius: 0.5,
            movement_time_allowance: 10.0,
        })
    }

    #[test]
    fn standing_still_beyond_the_allowance_is_stuck() {
        let mut c = checker();
        assert_eq!(c.check(Point2::new(1.0, 1.0), 100.0), Progress::Ok);
        // 0.4 m away at 109 s: inside the radius and the allowance.
        assert_eq!(c.check(Point2::new(1.4, 1.0), 109.0), Progress::Ok);
        assert_eq!(c.check(Point2::new(1.4, 1.0), 110.0), Progress::Ok);
        // 10.5 s after the anchor at (1, 1), still 0.4 m from it: stuck, since 10.5 s.
        assert_eq!(c.check(Point2::new(1.4, 1.0), 110.5), Progress::Stuck { since: 10.5 });
    }

    #[test]
    fn moving_the_radius_moves_the_anchor() {
        let mut c = checker();
        c.check(Point2::new(0.0, 0.0), 0.0);
        // (0.3, 0.4) is 0.5 m away: not beyond the radius, the anchor stays at 0 s.
        assert_eq!(c.check(Point2::new(0.3, 0.4), 9.0), Progress::Ok);
        // (0.3, 0.5) is 0.583 m away: progress, the anchor moves there at 9.5 s.
        assert_eq!(c.check(Point2::new(0.3, 0.5), 9.5), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.3, 0.5), 19.5), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.3, 0.5), 19.75), Progress::Stuck { since: 10.25 });
    }

    #[test]
    fn time_going_backwards_restarts_the_window() {
        let mut c = checker();
        c.check(Point2::new(0.0, 0.0), 50.0);
        // The simulation restarted at 2 s: the window starts again there, not stuck at 2 + 10.
        assert_eq!(c.check(Point2::new(0.0, 0.0), 2.0), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.0, 0.0), 12.0), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.0, 0.0), 12.5), Progress::Stuck { since: 10.5 });
        // NaN never aborts and leaves the anchor alone.
        assert_eq!(c.check(Point2::new(f64::NAN, 0.0), 13.0), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.0, 0.0), f64::NAN), Progress::Ok);
        assert_eq!(c.check(Point2::new(0.0, 0.0), 13.0), Progress::Stuck { since: 11.0 });
        c.reset();
        assert_eq!(c.check(Point2::new(0.0, 0.0), 13.0), Progress::Ok);
    }
}
