//! The peer for comparison: Nav2's docking law (opennav_docking on `nav2_graceful_controller`'s
//! smooth control law, ROS 2 Jazzy), ported line by line from `smooth_control_law.cpp`,
//! `ego_polar_coords.hpp` and `opennav_docking`'s `controller.cpp` / `docking_server.cpp` /
//! `simple_charging_dock.cpp` (jazzy branch). Not part of the library's API: it exists to
//! measure our docking against.
//!
//! Differences from the C++: f64 throughout (Nav2 keeps the egocentric coordinates in f32);
//! forward docking only (`dock_backwards` false); no costmap collision check.

#![allow(dead_code)]

use mobil_geom::{wrap, Pose2};

/// opennav_docking's controller parameters and their Jazzy defaults.
#[derive(Debug, Clone, Copy)]
pub struct Graceful {
    /// `controller.k_phi` (3.0).
    pub k_phi: f64,
    /// `controller.k_delta` (2.0).
    pub k_delta: f64,
    /// `controller.beta` (0.4).
    pub beta: f64,
    /// `controller.lambda` (2.0).
    pub lambda: f64,
    /// `controller.slowdown_radius` (0.25 m).
    pub slowdown_radius: f64,
    /// `controller.v_linear_min` (0.1 m/s).
    pub v_linear_min: f64,
    /// `controller.v_linear_max` (0.25 m/s).
    pub v_linear_max: f64,
    /// `controller.v_angular_max` (0.75 rad/s).
    pub v_angular_max: f64,
    /// `docking_server.cpp` projects the target this far beyond the dock (0.25 m) so the robot
    /// never reaches the end of the spiral before touching the dock.
    pub backward_projection: f64,
    /// `simple_charging_dock.docking_threshold` (0.05 m): docked when the robot is this near
    /// the dock pose (position only; the heading is not checked).
    pub docking_threshold: f64,
}

impl Default for Graceful {
    fn default() -> Self {
        Graceful {
            k_phi: 3.0,
            k_delta: 2.0,
            beta: 0.4,
            lambda: 2.0,
            slowdown_radius: 0.25,
            v_linear_min: 0.1,
            v_linear_max: 0.25,
            v_angular_max: 0.75,
            backward_projection: 0.25,
            docking_threshold: 0.05,
        }
    }
}

/// `EgocentricPolarCoordinates(target, current, backward = false)`: (r, φ, δ).
pub fn ego_polar(target: &Pose2, current: &Pose2) -> (f64, f64, f64) {
    let dx = target.x - current.x;
    let dy = target.y - current.y;
    let line_of_sight = (-dy).atan2(dx);
    let r = dx.hypot(dy);
    let phi = wrap(target.yaw + line_of_sight);
    let delta = wrap(current.yaw + line_of_sight);
    (r, phi, delta)
}

impl Graceful {
    /// `SmoothControlLaw::calculateCurvature(r, phi, delta)`.
    pub fn curvature(&self, r: f64, phi: f64, delta: f64) -> f64 {
        let prop_term = self.k_delta * (delta - (-self.k_phi * phi).atan());
        let feedback_term = (1.0 + self.k_phi / (1.0 + (self.k_phi * phi).powi(2))) * delta.sin();
        -1.0 / r * (prop_term + feedback_term)
    }

    /// `SmoothControlLaw::calculateRegularVelocity(target, current, backward = false)`: (v, ω).
    pub fn velocity(&self, target: &Pose2, current: &Pose2) -> (f64, f64) {
        let (r, phi, delta) = ego_polar(target, current);
        let curvature = self.curvature(r, phi, delta);
        let mut v = self.v_linear_max / (1.0 + self.beta * curvature.abs().powf(self.lambda));
        v = (self.v_linear_max * (r / self.slowdown_radius)).min(v);
        v = v.clamp(self.v_linear_min, self.v_linear_max);
        let w = curvature * v;
        let w_bound = w.clamp(-self.v_angular_max, self.v_angular_max);
        v = if curvature != 0.0 { w_bound / curvature } else { v };
        (v, w_bound)
    }

    /// `DockingServer::approachDock`'s target: the dock pose moved `backward_projection` along
    /// its own heading.
    pub fn target(&self, dock: &Pose2) -> Pose2 {
        dock.ahead(self.backward_projection)
    }

    /// `SimpleChargingDock::isDocked` without stall detection: within the threshold of the dock.
    pub fn is_docked(&self, dock: &Pose2, robot: &Pose2) -> bool {
        (dock.x - robot.x).hypot(dock.y - robot.y) < self.docking_threshold
    }
}
