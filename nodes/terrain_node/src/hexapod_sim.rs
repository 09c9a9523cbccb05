//! `hexapod_sim`'s configuration (every parameter declared once) and the touchdown message it
//! publishes: the shell of [`mobil_terrain::Walker`], the walking hexapod that feeds
//! `terrain_node`. The executable is `src/bin/hexapod_sim.rs`.

use crate::point;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::mobil_msgs::msg::FootTouchdown;
use mobil_msgs::std_msgs::msg::Header;
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_terrain::{
    Course, Ground, HexapodGeometry, Leg, RoughGround, Section, TerrainError, Touchdown, WalkerConfig,
};

/// The ground `hexapod_sim` walks on, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GroundKind {
    /// Level ground.
    #[default]
    Flat,
    /// A plane at `slope_deg` rising toward `slope_direction_deg`.
    Slope,
    /// Seeded rough ground.
    Rough,
    /// Flat, then a ramp at `slope_deg`, then rough, along world x.
    Course,
}

impl std::str::FromStr for GroundKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "flat" => Ok(GroundKind::Flat),
            "slope" => Ok(GroundKind::Slope),
            "rough" => Ok(GroundKind::Rough),
            "course" => Ok(GroundKind::Course),
            _ => Err(format!("unknown ground `{s}` (flat, slope, rough or course)")),
        }
    }
}

/// `hexapod_sim`'s configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HexapodSimConfig {
    /// Footholds and body height (the params file's `/**` section).
    pub geometry: HexapodGeometry,
    /// The ground.
    pub ground: GroundKind,
    /// Slope of `slope` and of the course's ramp (degrees).
    pub slope_deg: f64,
    /// Direction the `slope` ground rises toward, in the world (degrees; 0 = +x, ahead).
    pub slope_direction_deg: f64,
    /// Rough ground: node heights in ±this (m).
    pub rough_amplitude: f64,
    /// Rough ground: node spacing (m).
    pub rough_cell: f64,
    /// Rough ground's seed.
    pub seed: i64,
    /// Course: lengths of the flat, ramp and rough sections along x (m).
    pub course_lengths: [f64; 3],
    /// Body speed (m/s).
    pub speed: f64,
    /// Gait period (s).
    pub gait_period: f64,
    /// Frame of the touchdowns (the body frame).
    pub body_frame: String,
    /// Frame of the body pose (`odom`).
    pub world_frame: String,
    /// Publish `/clock` (simulated time from 0).
    pub publish_clock: bool,
    /// Simulated seconds per wall second.
    pub real_time_factor: f64,
    /// Steps per wall second: pose, clock and touchdowns are due on them.
    pub tick_rate_hz: f64,
    /// Start the walk (t = 0) only once `terrain/touchdown` has a subscriber.
    pub wait_for_subscriber: bool,
}

impl Config for HexapodSimConfig {
    fn declare(d: &mut Decl<Self>) {
        let g = HexapodGeometry::default();
        let w = WalkerConfig::default();
        for leg in Leg::ALL {
            let p = g.footholds.get(leg);
            d.doubles(
                &format!("footholds.{leg}"),
                [p.x, p.y],
                &format!("nominal foothold of {leg} (x, y) in the body frame [m]"),
                move |c: &mut HexapodSimConfig, v| match leg {
                    Leg::KP => c.geometry.footholds.KP = v,
                    Leg::KV => c.geometry.footholds.KV = v,
                    Leg::KG => c.geometry.footholds.KG = v,
                    Leg::DP => c.geometry.footholds.DP = v,
                    Leg::DV => c.geometry.footholds.DV = v,
                    Leg::DG => c.geometry.footholds.DG = v,
                },
            )
            .read_only();
        }
        d.double(
            "body_height",
            g.body_height,
            "body origin above the mean ground under the footholds [m]",
            |c, v| c.geometry.body_height = v,
        )
        .above(0.0)
        .read_only();
        d.parsed(
            "ground",
            "flat",
            "flat, slope (slope_deg toward slope_direction_deg), rough (seeded) or course (flat → ramp → rough along x)",
            |c, v| c.ground = v,
        )
        .choices(&["flat", "slope", "rough", "course"])
        .read_only();
        d.double(
            "slope_deg",
            10.0,
            "slope of `slope` and of the course's ramp [deg]",
            |c, v| c.slope_deg = v,
        )
        .within(-60.0, 60.0)
        .read_only();
        d.double(
            "slope_direction_deg",
            0.0,
            "direction the `slope` ground rises toward, world frame (0: +x, ahead) [deg]",
            |c, v| c.slope_direction_deg = v,
        )
        .within(-360.0, 360.0)
        .read_only();
        d.double(
            "rough_amplitude",
            0.03,
            "rough ground: node heights within ±this [m]",
            |c, v| c.rough_amplitude = v,
        )
        .within(0.0, 0.5)
        .read_only();
        d.double("rough_cell", 0.10, "rough ground: node spacing [m]", |c, v| {
            c.rough_cell = v
        })
        .within(0.01, 10.0)
        .read_only();
        d.integer("seed", 1, "rough ground's seed", |c, v| c.seed = v)
            .read_only();
        d.doubles(
            "course_lengths",
            [1.0, 1.5, 1.5],
            "course: lengths of the flat, ramp and rough sections along x from the start [m]",
            |c, v| c.course_lengths = v,
        )
        .read_only();
        d.double("speed", w.speed, "body speed [m/s]", |c, v| c.speed = v)
            .within(0.0, 1.0)
            .read_only();
        d.double(
            "gait_period",
            w.gait_period,
            "gait period: one step of each tripod [s]",
            |c, v| c.gait_period = v,
        )
        .within(0.1, 10.0)
        .read_only();
        d.string(
            "body_frame",
            "base_link",
            "frame of the touchdowns (the body frame)",
            |c, v| c.body_frame = v,
        )
        .read_only();
        d.string("world_frame", "odom", "frame of the body pose", |c, v| {
            c.world_frame = v
        })
        .read_only();
        d.boolean(
            "publish_clock",
            false,
            "publish /clock (simulated time from 0)",
            |c, v| c.publish_clock = v,
        )
        .read_only();
        d.double("real_time_factor", 1.0, "simulated seconds per wall second", |c, v| {
            c.real_time_factor = v
        })
        .within(0.01, 100.0);
        d.double(
            "tick_rate_hz",
            50.0,
            "steps per wall second (pose, clock; touchdowns carry their own times) [Hz]",
            |c, v| c.tick_rate_hz = v,
        )
        .within(1.0, 1000.0)
        .read_only();
        d.boolean(
            "wait_for_subscriber",
            false,
            "start the walk (t = 0) only once terrain/touchdown has a subscriber",
            |c, v| c.wait_for_subscriber = v,
        )
        .read_only();
    }

    fn validate(&self) -> Result<(), ConfigError> {
        if !self.publish_clock && self.real_time_factor != 1.0 {
            // Without /clock the stamps are the wall clock's: a faster walk would stamp its
            // touchdowns, odom and tf ever further in the future.
            return Err(ConfigError::inconsistent(format!(
                "real_time_factor {} needs publish_clock:=true (without /clock stamps are wall time, so the \
                 factor must be 1)",
                self.real_time_factor
            )));
        }
        if self.body_frame.trim_start_matches('/').is_empty()
            || self.world_frame.trim_start_matches('/').is_empty()
            || self.body_frame.trim_start_matches('/') == self.world_frame.trim_start_matches('/')
        {
            return Err(ConfigError::inconsistent(format!(
                "body_frame `{}` and world_frame `{}` must be non-empty and differ",
                self.body_frame, self.world_frame
            )));
        }
        self.walker().map(|_| ()).map_err(ConfigError::inconsistent)
    }
}

impl HexapodSimConfig {
    /// The ground named by `ground`.
    pub fn ground(&self) -> Result<Ground, TerrainError> {
        let slope = self.slope_deg.to_radians();
        let rough = || RoughGround::new(self.rough_amplitude, self.rough_cell, self.seed as u64);
        Ok(match self.ground {
            GroundKind::Flat => Ground::Flat(0.0),
            GroundKind::Slope => {
                // A negative slope is the same plane rising the other way.
                let uphill =
                    self.slope_direction_deg.to_radians() + if slope < 0.0 { std::f64::consts::PI } else { 0.0 };
                Ground::plane(slope.abs(), uphill)?
            }
            GroundKind::Rough => Ground::Rough(rough()?),
            GroundKind::Course => {
                let [flat, ramp, rough_len] = self.course_lengths;
                Ground::Course(Course::new(
                    0.0,
                    vec![
                        (flat, Section::Flat),
                        (ramp, Section::Ramp(slope)),
                        (rough_len, Section::Rough(rough()?)),
                    ],
                )?)
            }
        })
    }

    /// The walker's configuration: straight ahead along world x from the origin.
    pub fn walker_config(&self) -> WalkerConfig {
        WalkerConfig {
            geometry: self.geometry.clone(),
            gait_period: self.gait_period,
            speed: self.speed,
            heading: 0.0,
            start: [0.0, 0.0],
        }
    }

    /// The walker on the configured ground.
    pub fn walker(&self) -> Result<mobil_terrain::Walker, TerrainError> {
        mobil_terrain::Walker::new(self.walker_config(), self.ground()?)
    }
}

/// `terrain/touchdown` for one of the walker's touchdowns.
pub fn touchdown_message(td: &Touchdown, stamp: Time, body_frame: &str) -> FootTouchdown {
    FootTouchdown {
        header: Header {
            stamp,
            frame_id: body_frame.to_owned(),
        },
        leg: td.leg.name().to_owned(),
        position: point(&td.position),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_ros::params::ParamValues;

    /// Without /clock the stamps are wall time: a factor other than 1 would stamp into the
    /// future; empty or equal frames would refuse every touchdown.
    #[test]
    fn hexapod_sim_refuses_a_factor_without_clock_and_bad_frames() {
        let base: HexapodSimConfig =
            mobil_ros::config::load(&ParamValues::defaults(&Decl::<HexapodSimConfig>::of().specs())).unwrap();
        assert!(base.validate().is_ok());
        let fast = HexapodSimConfig {
            real_time_factor: 8.0,
            ..base.clone()
        };
        assert!(fast.validate().unwrap_err().to_string().contains("publish_clock"));
        assert!(HexapodSimConfig {
            publish_clock: true,
            ..fast
        }
        .validate()
        .is_ok());
        for (body, world) in [("", "odom"), ("base_link", "/"), ("base_link", "/base_link")] {
            let c = HexapodSimConfig {
                body_frame: body.into(),
                world_frame: world.into(),
                ..base.clone()
            };
            assert!(c.validate().is_err(), "{body} / {world}");
        }
    }

    /// A 10° slope rising toward +x: z = tan 10° · x; a negative slope the same plane rising
    /// toward −x. The course: flat to x = 1, the ramp to 2.5 (at x = 2 it is 1 · tan 10° high),
    /// then rough ground within ±3 cm of the ramp's top, 1.5 · tan 10° = 0.2645 m.
    #[test]
    fn grounds_by_name() {
        let mut c = HexapodSimConfig {
            ground: GroundKind::Slope,
            ..mobil_ros::config::load(&ParamValues::defaults(&Decl::<HexapodSimConfig>::of().specs())).unwrap()
        };
        let t = 10f64.to_radians().tan();
        assert!((c.ground().unwrap().height(2.0, 5.0) - 2.0 * t).abs() < 1e-12);
        c.slope_deg = -10.0;
        assert!((c.ground().unwrap().height(2.0, 5.0) + 2.0 * t).abs() < 1e-12);
        c.slope_deg = 10.0;
        c.ground = GroundKind::Course;
        let g = c.ground().unwrap();
        assert_eq!(g.height(0.5, 0.0), 0.0);
        assert!((g.height(2.0, 0.0) - t).abs() < 1e-12);
        assert!((g.height(3.2, 0.1) - 1.5 * t).abs() <= 0.03);
        assert!((g.height(3.2, 0.1) - 1.5 * t).abs() > 0.0, "rough, not level");
        assert_eq!("course".parse::<GroundKind>(), Ok(GroundKind::Course));
        assert!("hilly".parse::<GroundKind>().is_err());
    }

    #[test]
    fn the_defaults_load_from_parameters() {
        let defaults = ParamValues::defaults(&Decl::<HexapodSimConfig>::of().specs());
        let s: HexapodSimConfig = mobil_ros::config::load(&defaults).unwrap();
        assert_eq!(s.geometry, HexapodGeometry::default());
        assert_eq!((s.ground, s.speed, s.gait_period), (GroundKind::Flat, 0.10, 1.0));
    }
}
