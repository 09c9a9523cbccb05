//! A path to follow as a sequence of sub-goals (Nav2's controller role, `FollowPath`).
//!
//! A controller that drives to one point at a time follows a path by its sub-goals along the
//! path, `lookahead` apart in arc length from the point of the path nearest the robot, the
//! path's end last. The controller takes the next sub-goal when the robot comes within
//! `lookahead / 2` of the current one, so it never stops at an intermediate sub-goal; only the
//! end is reached (within the controller's goal tolerance) and ends the goal. Between two
//! sub-goals the controller's own law drives (and avoids obstacles, if it does). The path's
//! poses (Nav2's planners give one every few centimetres) need no other resampling.
//!
//! ```
//! use mobil_geom::path::PathGoals;
//! use nalgebra::Point2;
//! let path = [Point2::new(0.0, 0.0), Point2::new(3.0, 0.0), Point2::new(3.0, 2.0)];
//! let mut goals = PathGoals::new(&path, Point2::new(0.0, 0.0), 1.0).unwrap();
//! assert_eq!(goals.goal(), Point2::new(1.0, 0.0));
//! assert!(goals.advance(Point2::new(0.6, 0.0))); // within 0.5 m: the next one
//! assert_eq!(goals.goal(), Point2::new(2.0, 0.0));
//! assert!((goals.remaining(Point2::new(0.6, 0.0)) - 4.4).abs() < 1e-12);
//! ```

use crate::segment::{nearest_on_segment, segment_distance};
use nalgebra::Point2;
use thiserror::Error;

/// Why a path cannot be followed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum PathError {
    /// No pose at all.
    #[error("the path has no poses")]
    Empty,
    /// A pose (its index) with NaN or infinity.
    #[error("pose {0} of the path is not finite")]
    NotFinite(usize),
    /// A pose (its index) farther than [`MAX_PATH_COORD`] from the origin on an axis.
    #[error("pose {0} of the path lies beyond ±{MAX_PATH_COORD} m")]
    TooFar(usize),
    /// More sub-goals than [`MAX_SUB_GOALS`] (the path's whole length over the lookahead, or
    /// at least one more than the cap once counted along the path).
    #[error("the path would make {0} sub-goals, more than {MAX_SUB_GOALS}")]
    TooLong(usize),
    /// A lookahead not above zero, or not finite.
    #[error("the lookahead must be finite and above zero")]
    Lookahead,
}

/// The largest |x| and |y| of a path's pose (m): as for any goal of the suite.
pub const MAX_PATH_COORD: f64 = 1e4;

/// The most sub-goals one path makes: 100 km at a 1 m lookahead, far beyond any path a
/// planner sends, and 1.6 MB of points.
pub const MAX_SUB_GOALS: usize = 100_000;

/// Sub-goals along a path, and which one the navigator is heading for.
#[derive(Debug, Clone, PartialEq)]
pub struct PathGoals {
    /// The path's point nearest the robot when the path came: the sub-goals follow from it.
    start: Point2<f64>,
    goals: Vec<Point2<f64>>,
    next: usize,
    switch_radius: f64,
}

impl PathGoals {
    /// Sub-goals of `path` for a robot at `from`: every `lookahead` of arc length from the
    /// path's point nearest `from` (the first such point in path order on a tie), then the end.
    pub fn new(path: &[Point2<f64>], from: Point2<f64>, lookahead: f64) -> Result<Self, PathError> {
        if !(lookahead.is_finite() && lookahead > 0.0) {
            return Err(PathError::Lookahead);
        }
        let Some(&end) = path.last() else {
            return Err(PathError::Empty);
        };
        if let Some(i) = path.iter().position(|p| !(p.x.is_finite() && p.y.is_finite())) {
            return Err(PathError::NotFinite(i));
        }
        if let Some(i) = path
            .iter()
            .position(|p| p.x.abs() > MAX_PATH_COORD || p.y.abs() > MAX_PATH_COORD)
        {
            return Err(PathError::TooFar(i));
        }
        let length: f64 = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let count = (length / lookahead).ceil();
        if count > MAX_SUB_GOALS as f64 {
            return Err(PathError::TooLong(count.min(usize::MAX as f64) as usize));
        }
        // The nearest point of the polyline: segment index and point.
        let (mut segment, mut start) = (0, path[0]);
        let mut best = (path[0] - from).norm();
        for (i, w) in path.windows(2).enumerate() {
            let (q, _) = nearest_on_segment(w[0], w[1], from);
            let d = (q - from).norm();
            if d < best {
                (segment, start, best) = (i, q, d);
            }
        }
        // Walk on from there, a goal every `lookahead`.
        let mut goals = Vec::new();
        let mut here = start;
        let mut left = lookahead;
        for &corner in &path[(segment + 1).min(path.len() - 1)..] {
            let mut leg = (corner - here).norm();
            while leg >= left {
                here += (corner - here) * (left / leg);
                if goals.len() == MAX_SUB_GOALS {
                    return Err(PathError::TooLong(MAX_SUB_GOALS + 1));
                }
                goals.push(here);
                leg -= left;
                left = lookahead;
            }
            left -= leg;
            here = corner;
        }
        if goals.last().is_none_or(|g| (g - end).norm() > 1e-9) {
            if goals.len() == MAX_SUB_GOALS {
                return Err(PathError::TooLong(MAX_SUB_GOALS + 1));
            }
            goals.push(end);
        }
        Ok(PathGoals {
            start,
            goals,
            next: 0,
            switch_radius: lookahead / 2.0,
        })
    }

    /// The sub-goal the navigator heads for.
    pub fn goal(&self) -> Point2<f64> {
        self.goals[self.next]
    }

    /// Whether the current sub-goal is the path's end.
    pub fn is_last(&self) -> bool {
        self.next + 1 == self.goals.len()
    }

    /// The sub-goals, in order.
    pub fn goals(&self) -> &[Point2<f64>] {
        &self.goals
    }

    /// Takes the next sub-goal (and the ones after it) while the robot at `position` is within
    /// `lookahead / 2` of the current one; never past the end. True when the goal changed.
    pub fn advance(&mut self, position: Point2<f64>) -> bool {
        let before = self.next;
        while !self.is_last() && (self.goals[self.next] - position).norm() < self.switch_radius {
            self.next += 1;
        }
        self.next != before
    }

    /// Keeps `current` (the sub-goal the navigator heads for, from an earlier path) as the goal
    /// when one of these sub-goals, not the end, lies within `lookahead / 2` of it: that
    /// sub-goal becomes `current` and the ones before it are skipped. A path re-planned along
    /// the same way then leaves the navigator's goal, and its mode, as they were. False
    /// (nothing changed) when none is that near, or only the end (which is never moved).
    pub fn keep(&mut self, current: Point2<f64>) -> bool {
        let near = self.goals[self.next..]
            .iter()
            .position(|g| (g - current).norm() <= self.switch_radius);
        match near {
            // The path's end is never moved: only it ends the goal.
            Some(i) if self.next + i + 1 < self.goals.len() => {
                self.next += i;
                self.goals[self.next] = current;
                true
            }
            _ => false,
        }
    }

    /// Heads for sub-goal `index` when it lies ahead of the current one (a controller that gave
    /// up a sub-goal itself, or passed it); never past the end, never back. True when the goal
    /// changed.
    pub fn pursue(&mut self, index: usize) -> bool {
        let before = self.next;
        self.next = self.next.max(index.min(self.goals.len() - 1));
        self.next != before
    }

    /// The index of the sub-goal the controller heads for.
    pub fn index(&self) -> usize {
        self.next
    }

    /// Whether `point` lies within `lookahead / 2` of the path ahead (from its point nearest
    /// the robot when it came, through the sub-goals).
    pub fn passes_near(&self, point: Point2<f64>) -> bool {
        let mut from = self.start;
        let mut nearest = (point - from).norm();
        for &g in &self.goals {
            nearest = nearest.min(segment_distance(point, from, g));
            from = g;
        }
        nearest <= self.switch_radius
    }

    /// Distance still to go: to the current sub-goal, then along the rest.
    pub fn remaining(&self, position: Point2<f64>) -> f64 {
        let rest: f64 = self.goals[self.next..].windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        (self.goal() - position).norm() + rest
    }
}

/// `points` as poses, each headed along its leg to the next point (the last along the leg
/// into it; a lone point, or one of a zero-length leg, takes the heading before it, 0 first):
/// a route drawn as a path of poses.
pub fn headed(points: &[Point2<f64>]) -> Vec<crate::Pose2> {
    let mut heading = 0.0;
    let mut poses = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let leg = match (points.get(i + 1), i.checked_sub(1).map(|j| points[j])) {
            (Some(next), _) => next - p,
            (None, Some(before)) => p - before,
            (None, None) => nalgebra::Vector2::zeros(),
        };
        if leg.norm() > 1e-12 {
            heading = leg.y.atan2(leg.x);
        }
        poses.push(crate::Pose2::new(p.x, p.y, heading));
    }
    poses
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    /// An L-shaped path from a robot beside its middle: the goals start at the foot of the
    /// perpendicular (1.5, 0) and follow the corner: 2.5 (0.5 before it), then (3, 0.5), (3, 1.5),
    /// the end (3, 2).
    #[test]
    fn goals_start_at_the_nearest_point_and_turn_corners() {
        let path = [p(0.0, 0.0), p(3.0, 0.0), p(3.0, 2.0)];
        let goals = PathGoals::new(&path, p(1.5, 0.7), 1.0).unwrap();
        let expected = [p(2.5, 0.0), p(3.0, 0.5), p(3.0, 1.5), p(3.0, 2.0)];
        assert_eq!(goals.goals().len(), expected.len());
        for (g, e) in goals.goals().iter().zip(expected) {
            assert!((g - e).norm() < 1e-12, "{g} != {e}");
        }
        // 0.7 to (2.5, 0)'s foot... remaining = |(1.5,0.7)-(2.5,0)| + 0.5·√2 + 1 + 0.5.
        let r = goals.remaining(p(1.5, 0.7));
        let by_hand = (1.0f64 + 0.49).sqrt() + 0.5f64.hypot(0.5) + 1.0 + 0.5;
        assert!((r - by_hand).abs() < 1e-12, "{r}");
    }

    /// A robot past the path's end, a one-pose path, a path shorter than the lookahead: the
    /// end is the only goal.
    #[test]
    fn the_end_is_always_the_last_goal() {
        let path = [p(0.0, 0.0), p(0.5, 0.0)];
        let goals = PathGoals::new(&path, p(-1.0, 0.0), 1.0).unwrap();
        assert_eq!(goals.goals(), &[p(0.5, 0.0)]);
        assert!(goals.is_last());
        let one = PathGoals::new(&[p(2.0, 1.0)], p(0.0, 0.0), 1.0).unwrap();
        assert_eq!(one.goals(), &[p(2.0, 1.0)]);
        let beyond = PathGoals::new(&path, p(4.0, 0.0), 1.0).unwrap();
        assert_eq!(beyond.goals(), &[p(0.5, 0.0)]);
        // Exactly two lookaheads: no duplicate end.
        let exact = PathGoals::new(&[p(0.0, 0.0), p(2.0, 0.0)], p(0.0, 0.0), 1.0).unwrap();
        assert_eq!(exact.goals(), &[p(1.0, 0.0), p(2.0, 0.0)]);
    }

    /// Advancing: within half a lookahead the next goal is taken; on a hairpin, where the next
    /// goals are near in the plane, several at once; never past the end.
    #[test]
    fn advance_switches_within_half_a_lookahead() {
        let path = [p(0.0, 0.0), p(4.0, 0.0)];
        let mut goals = PathGoals::new(&path, p(0.0, 0.0), 1.0).unwrap();
        assert!(!goals.advance(p(0.4, 0.0)), "0.6 from (1, 0)");
        assert!(goals.advance(p(0.6, 0.0)));
        assert_eq!(goals.goal(), p(2.0, 0.0));
        assert!(!goals.advance(p(3.9, 0.0)), "far past (2, 0): it heads back for it");
        assert!(goals.advance(p(1.6, 0.0)) && goals.advance(p(2.6, 0.0)));
        assert_eq!(goals.goal(), p(4.0, 0.0));
        assert!(goals.is_last());
        assert!(!goals.advance(p(4.0, 0.0)), "the end stays");
        // A hairpin 0.2 m wide, lookahead 0.5: goals (0.5, 0), (1, 0), (0.7, 0.2), (0.2, 0.2),
        // (0, 0.2). From (0.9, 0.1), (1, 0) is 0.14 away and (0.7, 0.2) 0.22: both taken.
        let hairpin = [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.2), p(0.0, 0.2)];
        let mut goals = PathGoals::new(&hairpin, p(0.0, 0.0), 0.5).unwrap();
        assert_eq!(goals.goals().len(), 5);
        assert!(goals.advance(p(0.5, 0.0)));
        assert_eq!(goals.goal(), p(1.0, 0.0));
        assert!(goals.advance(p(0.9, 0.1)));
        assert!((goals.goal() - p(0.2, 0.2)).norm() < 1e-12, "{}", goals.goal());
    }

    /// A path re-planned from a robot 0.3 m further on: its first goal (1.3, 0) is 0.3 m from
    /// the goal (1, 0) the navigator heads for, so that goal is kept, then (2.3, 0)...; a path
    /// elsewhere keeps nothing.
    #[test]
    fn a_replanned_path_keeps_the_current_goal() {
        let path = [p(0.3, 0.0), p(3.0, 0.0)];
        let mut goals = PathGoals::new(&path, p(0.3, 0.0), 1.0).unwrap();
        assert!(goals.keep(p(1.0, 0.0)));
        assert_eq!(goals.goal(), p(1.0, 0.0));
        assert!((goals.goals()[1] - p(2.3, 0.0)).norm() < 1e-12);
        let mut other = PathGoals::new(&[p(0.0, 2.0), p(3.0, 2.0)], p(0.0, 2.0), 1.0).unwrap();
        let before = other.clone();
        assert!(!other.keep(p(1.0, 0.0)));
        assert_eq!(other, before);
        // Near the end: a new end 0.4 m from the old one is not replaced by it.
        let mut end = PathGoals::new(&[p(2.6, 0.0), p(3.4, 0.0)], p(2.6, 0.0), 1.0).unwrap();
        assert!(!end.keep(p(3.0, 0.0)));
        assert_eq!(end.goal(), p(3.4, 0.0));
    }

    /// Near the path ahead: within half a lookahead of it, from its point nearest the robot
    /// on; not behind that point.
    #[test]
    fn passes_near_measures_to_the_path_ahead() {
        let goals = PathGoals::new(&[p(0.0, 0.0), p(3.0, 0.0), p(3.0, 2.0)], p(1.0, 0.2), 1.0).unwrap();
        assert!(goals.passes_near(p(1.5, 0.5)), "0.5 from (1.5, 0)");
        assert!(!goals.passes_near(p(1.5, 0.51)));
        assert!(goals.passes_near(p(3.4, 1.0)), "0.4 from the second leg");
        assert!(!goals.passes_near(p(0.3, 0.0)), "0.7 behind the start (1, 0)");
    }

    /// Headings along the legs: east, then north (the corner takes the leg out of it), the end
    /// the leg into it; a repeated point keeps the heading before it.
    #[test]
    fn points_are_headed_along_their_legs() {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let poses = headed(&[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 2.0), p(1.0, 2.0)]);
        let yaws: Vec<f64> = poses.iter().map(|q| q.yaw).collect();
        assert_eq!(yaws, [0.0, half_pi, half_pi, half_pi]);
        assert_eq!(headed(&[p(3.0, 4.0)])[0], crate::Pose2::new(3.0, 4.0, 0.0));
        assert!(headed(&[]).is_empty());
    }

    /// Pursuing: forward only, never past the end.
    #[test]
    fn pursue_moves_forward_only() {
        let mut goals = PathGoals::new(&[p(0.0, 0.0), p(3.0, 0.0)], p(0.0, 0.0), 1.0).unwrap();
        assert!(goals.pursue(1));
        assert_eq!((goals.index(), goals.goal()), (1, p(2.0, 0.0)));
        assert!(!goals.pursue(0), "never back");
        assert!(goals.pursue(7) && goals.is_last(), "never past the end");
        assert_eq!(goals.goal(), p(3.0, 0.0));
    }

    #[test]
    fn bad_paths_are_refused() {
        assert_eq!(PathGoals::new(&[], p(0.0, 0.0), 1.0), Err(PathError::Empty));
        assert_eq!(
            PathGoals::new(&[p(0.0, 0.0), p(f64::NAN, 0.0)], p(0.0, 0.0), 1.0),
            Err(PathError::NotFinite(1))
        );
        assert_eq!(
            PathGoals::new(&[p(0.0, 0.0)], p(0.0, 0.0), 0.0),
            Err(PathError::Lookahead)
        );
        // Far poses: refused before any arithmetic can overflow (±1e308 apart is infinite).
        assert_eq!(
            PathGoals::new(&[p(-1e308, 0.0), p(1e308, 0.0)], p(0.0, 0.0), 1.0),
            Err(PathError::TooFar(0))
        );
        assert_eq!(
            PathGoals::new(&[p(0.0, 0.0), p(0.0, 10_000.5)], p(0.0, 0.0), 1.0),
            Err(PathError::TooFar(1))
        );
        // 2 × 10 km there and back at 0.1 m: 200 000 sub-goals, refused; at 1 m, 20 000 taken.
        let long = [p(0.0, 0.0), p(1e4, 0.0), p(0.0, 0.0)];
        assert_eq!(
            PathGoals::new(&long, p(0.0, 0.0), 0.1),
            Err(PathError::TooLong(200_000))
        );
        assert_eq!(PathGoals::new(&long, p(0.0, 0.0), 1.0).unwrap().goals().len(), 20_000);
        assert_eq!(
            PathGoals::new(&[p(0.0, 0.0)], p(0.0, 0.0), f64::INFINITY),
            Err(PathError::Lookahead)
        );
    }

    proptest::proptest! {
        /// Consecutive goals are at most a lookahead apart along the path (so at most that apart
        /// in the plane), and the last is the path's end.
        #[test]
        fn goals_are_at_most_a_lookahead_apart(
            pts in proptest::collection::vec((-5.0f64..5.0, -5.0f64..5.0), 1..8),
            from in (-6.0f64..6.0, -6.0f64..6.0),
            lookahead in 0.1f64..2.0,
        ) {
            let path: Vec<_> = pts.iter().map(|&(x, y)| p(x, y)).collect();
            let goals = PathGoals::new(&path, p(from.0, from.1), lookahead).unwrap();
            proptest::prop_assert!((goals.goals().last().unwrap() - path.last().unwrap()).norm() < 1e-9);
            for w in goals.goals().windows(2) {
                proptest::prop_assert!((w[1] - w[0]).norm() <= lookahead + 1e-9);
            }
        }
    }
}
