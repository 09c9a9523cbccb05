//! A short history of odometry poses, so that a scan is placed in odom with the pose the robot
//! had when the scan was taken, not the latest one (a robot turning at 1.5 rad/s turns 0.15 rad
//! in the 0.1 s a scan may lag the odometry: a point 3 m away lands 0.45 m off).
//!
//! - [`PoseHistory::push`] adds a pose at its time (s); time going backwards (a clock reset)
//!   empties the history first. The oldest poses beyond `capacity` are dropped.
//! - [`PoseHistory::at`] gives the pose at a time: interpolated (x, y linearly, the heading along
//!   the shorter way round) between the two poses around it when they lie at most `2·max_gap`
//!   apart, else the nearest pose when it lies within `max_gap`; otherwise none (the caller
//!   refuses the scan). It never extrapolates beyond `max_gap`.
//! - [`PoseHistory::placed_at`] says which of the two it was ([`Placement`]): only a pose
//!   between two odometry poses (or at one's own stamp) is exact enough to judge what a scan
//!   sees through; a held pose (the scan's stamp beyond the newest odometry, up to `max_gap`)
//!   may be a turn's worth off.

use std::collections::VecDeque;

use mobil_geom::{wrap, Pose2};

/// How a pose was found for a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// Interpolated between the two odometry poses around the time, or an odometry pose at
    /// exactly that time.
    Interpolated,
    /// The nearest odometry pose, held (up to `max_gap` away in time): the robot may have
    /// moved since.
    Held,
}

/// Poses by time, oldest first (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseHistory {
    samples: VecDeque<(f64, Pose2)>,
    capacity: usize,
}

impl PoseHistory {
    /// An empty history keeping at most `capacity` poses (at least 2).
    pub fn new(capacity: usize) -> Self {
        PoseHistory {
            samples: VecDeque::with_capacity(capacity.max(2)),
            capacity: capacity.max(2),
        }
    }

    /// Adds `pose` at time `t` (s). A non-finite time is ignored; a time before the last one
    /// empties the history first (the clock was reset); a time equal to the last one replaces it.
    pub fn push(&mut self, t: f64, pose: Pose2) {
        if !t.is_finite() {
            return;
        }
        match self.samples.back() {
            Some(&(last, _)) if t < last => self.samples.clear(),
            Some(&(last, _)) if t == last => {
                self.samples.pop_back();
            }
            _ => {}
        }
        if self.samples.len() == self.capacity {
            self.samples.pop_front();
        }
        self.samples.push_back((t, pose));
    }

    /// The number of poses held.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether no pose is held.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Empties the history.
    pub fn clear(&mut self) {
        self.samples.clear();
    }

    /// The pose at time `t` (module docs), or `None` when no pose lies within `max_gap` (s).
    pub fn at(&self, t: f64, max_gap: f64) -> Option<Pose2> {
        self.placed_at(t, max_gap).map(|(p, _)| p)
    }

    /// The pose at time `t` as [`Self::at`] gives it, and how it was found.
    pub fn placed_at(&self, t: f64, max_gap: f64) -> Option<(Pose2, Placement)> {
        if !t.is_finite() {
            return None;
        }
        let after = self.samples.partition_point(|&(s, _)| s < t);
        let before = after.checked_sub(1).and_then(|i| self.samples.get(i));
        let next = self.samples.get(after);
        if let (Some(&(t0, p0)), Some(&(t1, p1))) = (before, next)
            && t1 - t0 <= 2.0 * max_gap
        {
            let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            let pose = Pose2::new(
                p0.x + f * (p1.x - p0.x),
                p0.y + f * (p1.y - p0.y),
                p0.yaw + f * wrap(p1.yaw - p0.yaw),
            );
            return Some((pose, Placement::Interpolated));
        }
        [before, next]
            .into_iter()
            .flatten()
            .map(|&(s, p)| ((s - t).abs(), p))
            .filter(|&(gap, _)| gap <= max_gap)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(gap, p)| {
                let placement = if gap == 0.0 {
                    Placement::Interpolated
                } else {
                    Placement::Held
                };
                (p, placement)
            })
    }
}
