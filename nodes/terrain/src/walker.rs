//! A tripod-gait hexapod walking in a straight line over a [`Ground`], producing what a real
//! robot's control would report: each touchdown as the foot's landing point in the body frame,
//! and the body's pose. Time is an input: every output is a function of t, so a run is
//! deterministic and can be replayed from any instant.
//!
//! The model (choices beyond the SPEC):
//! - The body moves at constant speed along a fixed heading; its origin stays `body_height`
//!   above the mean ground height under the six nominal footholds, and it stays **level** (roll
//!   = pitch = 0), as a controller levelling the body on an IMU keeps it. A body following the
//!   ground's slope would see every plane's feet parallel to its own xy-plane, and the slope
//!   would be invisible to the assessment, whose frame is the body's (SPEC §6).
//! - Tripod gait with duty factor ½ and period T: tripod A (KP, KG, DV) and tripod B (DP, DG,
//!   KV) alternate. At t = 0 the robot stands with all six feet at their nominal footholds (six
//!   touchdowns at t = 0, so the control knows every foot); tripod B lands at T/2, 3T/2, …,
//!   tripod A at T, 2T, ….
//! - A foot lands half a stride ahead of its nominal foothold (stride L = v·T/2, the distance
//!   the body moves during a stance), so during its stance it moves back from +L/2 to −L/2
//!   relative to the body. Its landing point is on the ground straight under that spot:
//!   (x, y) in the body frame are the foothold + (L/2, 0), z is the ground's height there minus
//!   the body's.

use crate::config::HexapodGeometry;
use crate::error::TerrainError;
use crate::ground::Ground;
use crate::leg::{Leg, Tripod};
use nalgebra::{Point3, Vector2};

/// How the hexapod walks.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerConfig {
    /// Footholds and body height.
    pub geometry: HexapodGeometry,
    /// Gait period T (s): one step of each tripod. Default 1.0.
    pub gait_period: f64,
    /// Body speed v (m/s, ≥ 0). Default 0.10: a stride of 5 cm at T = 1 s, a third of the 0.15 m
    /// between the middle and the front footholds, so the legs never cross.
    pub speed: f64,
    /// Heading ψ (rad, world frame): the body's x axis and the direction of travel. Default 0.
    pub heading: f64,
    /// Start of the body's origin (x, y) in the world (m). Default (0, 0).
    pub start: [f64; 2],
}

impl Default for WalkerConfig {
    fn default() -> Self {
        WalkerConfig {
            geometry: HexapodGeometry::default(),
            gait_period: 1.0,
            speed: 0.10,
            heading: 0.0,
            start: [0.0, 0.0],
        }
    }
}

/// The body's pose at one instant: level, origin in the world (m), heading (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPose {
    /// Time (s).
    pub t: f64,
    /// Origin of the body frame in the world (m).
    pub position: Point3<f64>,
    /// Heading ψ (rad); roll and pitch are 0.
    pub yaw: f64,
}

/// One touchdown as the control reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touchdown {
    /// Time (s).
    pub t: f64,
    /// The leg.
    pub leg: Leg,
    /// The foot in the body frame at that instant (m).
    pub position: Point3<f64>,
    /// The foot in the world (m), for plots and checks.
    pub world: Point3<f64>,
}

/// The walking hexapod.
#[derive(Debug, Clone, PartialEq)]
pub struct Walker {
    config: WalkerConfig,
    ground: Ground,
}

impl Walker {
    /// A walker on `ground`; refuses an invalid geometry, a non-positive period, a negative
    /// speed or a non-finite heading or start.
    pub fn new(config: WalkerConfig, ground: Ground) -> Result<Self, TerrainError> {
        config.geometry.validate()?;
        let bad = |name, value, reason| Err(TerrainError::InvalidConfig { name, value, reason });
        if !(config.gait_period.is_finite() && config.gait_period > 0.0) {
            return bad("gait_period", config.gait_period, "must be finite and > 0");
        }
        if !(config.speed.is_finite() && config.speed >= 0.0) {
            return bad("speed", config.speed, "must be finite and ≥ 0");
        }
        if !config.heading.is_finite() {
            return bad("heading", config.heading, "must be finite");
        }
        if !(config.start[0].is_finite() && config.start[1].is_finite()) {
            return bad("start", f64::NAN, "must be finite");
        }
        Ok(Walker { config, ground })
    }

    /// The configuration.
    pub fn config(&self) -> &WalkerConfig {
        &self.config
    }

    /// The ground.
    pub fn ground(&self) -> &Ground {
        &self.ground
    }

    /// The stride L = v·T/2 (m).
    pub fn stride(&self) -> f64 {
        self.config.speed * self.config.gait_period / 2.0
    }

    fn forward(&self) -> Vector2<f64> {
        Vector2::new(self.config.heading.cos(), self.config.heading.sin())
    }

    /// A point given in the (level) body frame at body position `xy`, in world (x, y).
    fn to_world(&self, xy: Vector2<f64>, p: Vector2<f64>) -> Vector2<f64> {
        let (s, c) = self.config.heading.sin_cos();
        xy + Vector2::new(c * p.x - s * p.y, s * p.x + c * p.y)
    }

    /// The body's pose at time t (s): origin at start + v·t along the heading, `body_height`
    /// above the mean ground height under the six nominal footholds, level.
    pub fn body_pose(&self, t: f64) -> BodyPose {
        let xy = Vector2::from(self.config.start) + self.forward() * (self.config.speed * t);
        let g = &self.config.geometry;
        let mean = Leg::ALL
            .iter()
            .map(|&leg| {
                let w = self.to_world(xy, g.footholds.get(leg).coords);
                self.ground.height(w.x, w.y)
            })
            .sum::<f64>()
            / 6.0;
        BodyPose {
            t,
            position: Point3::new(xy.x, xy.y, mean + g.body_height),
            yaw: self.config.heading,
        }
    }

    /// The touchdown of `leg` at time t, landing `ahead` m in front of its foothold.
    fn touchdown(&self, t: f64, leg: Leg, ahead: f64) -> Touchdown {
        let body = self.body_pose(t);
        let in_body = self.config.geometry.footholds.get(leg).coords + Vector2::new(ahead, 0.0);
        let w = self.to_world(body.position.xy().coords, in_body);
        let z = self.ground.height(w.x, w.y);
        Touchdown {
            t,
            leg,
            position: Point3::new(in_body.x, in_body.y, z - body.position.z),
            world: Point3::new(w.x, w.y, z),
        }
    }

    /// Every touchdown with t0 < t ≤ t1, in time order and, at one instant, in [`Leg::ALL`]
    /// order: the six standing feet at t = 0, then tripod B at odd multiples of T/2 and tripod A
    /// at even ones. Successive calls with adjoining intervals give each touchdown once. Lazy:
    /// nothing is computed or stored before it is asked for, so an interval of any length (a
    /// clock jumping far ahead) costs only the touchdowns taken from it. A non-finite or empty
    /// interval gives none.
    pub fn touchdowns_in(&self, t0: f64, t1: f64) -> impl Iterator<Item = Touchdown> + '_ {
        let valid = t0.is_finite() && t1.is_finite() && t1 > t0;
        let standing = valid && t0 < 0.0 && t1 >= 0.0;
        let standing = Leg::ALL
            .into_iter()
            .filter(move |_| standing)
            .map(move |leg| self.touchdown(0.0, leg, 0.0));
        let half = self.config.gait_period / 2.0;
        // Float-to-int casts saturate, and the + 1 saturates too: no overflow for any t0, t1.
        let (first, last) = if valid {
            (
                ((t0.max(0.0) / half).floor() as i64).saturating_add(1).max(1),
                (t1 / half).floor() as i64,
            )
        } else {
            (1, 0)
        };
        let ahead = self.stride() / 2.0;
        let steps = (first..=last)
            .map(move |k| (k, k as f64 * half))
            .filter(move |&(_, t)| t > t0 && t <= t1)
            .flat_map(move |(k, t)| {
                let tripod = if k % 2 == 1 { Tripod::B } else { Tripod::A };
                Leg::ALL
                    .into_iter()
                    .filter(move |l| l.tripod() == tripod)
                    .map(move |leg| self.touchdown(t, leg, ahead))
            });
        standing.chain(steps)
    }
}
