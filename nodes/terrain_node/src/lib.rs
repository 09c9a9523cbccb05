//! The ROS side of [`mobil_terrain`]: the `terrain_node` executable (src/main.rs), the walking
//! hexapod `hexapod_sim` (src/bin/hexapod_sim.rs), and what their shells do that can be checked
//! without DDS — the configurations (every parameter declared once), the touchdown message's
//! checks, the assessment and marker messages; and, in [`hexapod_sim`], the simulator's
//! configuration, ground and messages.
//!
//! The method (σ, the planes, the angles, the class, the advice) and the walker are in
//! [`mobil_terrain`]; nothing here judges the ground.
//!
//! What `terrain_node` does with each `terrain/touchdown` ([`TerrainState::touchdown`]):
//! - **frame_id** must be the configured body frame (a leading `/` is ignored, as tf2 does);
//!   another frame, or none, is refused: the node has no transforms, and a foot in another
//!   frame would silently bend the planes.
//! - **an unknown leg name** or **a non-finite or out-of-range coordinate** is refused.
//! - a refusal changes no foot and is counted in `rejected_touchdowns`; a stance that cannot be
//!   assessed (three collinear feet) keeps the foot, is counted in `failed_assessments`, and
//!   the last good assessment stays. Either way the last good assessment is published again
//!   with the new counts (same stamp, so a reader sees it is not a new one).
//! - **a stamp older than the leg's previous touchdown is accepted** (and logged): on a
//!   reliable topic one writer's samples arrive in order, so an older stamp means the sender's
//!   clock went back (a simulator restarted, a bag looped), and the new touchdown is where the
//!   foot is now. Dropping it would freeze that leg until the clock caught up again.
//!
//! Why `hexapod_sim` lives in this crate and not in `sim_node`: it is the walker of
//! [`mobil_terrain`] with a clock, and it writes the very message this crate reads;
//! `sim_node` is the wheeled chassis' plant and would gain the terrain crate for nothing.

#![warn(missing_docs)]

pub mod hexapod_sim;

use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::Point;
use mobil_msgs::mobil_msgs::msg::{FootTouchdown, PlaneTilt as PlaneTiltMsg, TerrainAssessment};
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::markers::{rgb, rgba, Markers};
use mobil_terrain::{Assessment, Assessor, FootTracker, Leg, PlaneTilt, TerrainConfig, TerrainError};
use nalgebra::{Point3, Vector3 as V3};
use thiserror::Error;

/// Declares the assessment's parameters: thresholds (the params file's `terrain` section), body
/// points and body frame (its `/**` section).
fn declare_terrain(d: &mut Decl<TerrainConfig>) {
    let c = TerrainConfig::default();
    d.double(
        "sigma_flat",
        c.sigma_flat,
        "σ_flat: FLAT needs σ ≤ σ_flat, every angle within ε_α and the foot planes within plane_offset_max [m]",
        |c, v| c.sigma_flat = v,
    )
    .above(0.0);
    d.double(
        "plane_offset_max",
        c.plane_offset_max,
        "foot planes 1 and 2 parallel within ε_α but further apart than this are UNEVEN (a step between the tripods) [m]",
        |c, v| c.plane_offset_max = v,
    )
    .above(0.0);
    d.double(
        "sigma_wave",
        c.sigma_wave,
        "SLOPE and UNEVEN ground: ripple gait up to this σ, wave above [m]",
        |c, v| c.sigma_wave = v,
    )
    .above(0.0);
    d.double(
        "sigma_max",
        c.sigma_max,
        "σ_max: above it BEYOND_LIMITS (another route) [m]",
        |c, v| c.sigma_max = v,
    )
    .above(0.0);
    d.double(
        "epsilon_alpha",
        c.epsilon_alpha,
        "ε_α: angles within it count as 0 [rad]",
        |c, v| c.epsilon_alpha = v,
    )
    .above(0.0);
    d.double(
        "tilt_max",
        c.tilt_max,
        "a foot plane inclined more than this is BEYOND_LIMITS [rad]",
        |c, v| c.tilt_max = v,
    )
    .above(0.0);
    d.doubles(
        "body_points",
        c.body_points,
        "body points 1, 2, 3 of plane 3 in the body frame, x1 y1 z1 x2 y2 z2 x3 y3 z3 [m]",
        |c, v| c.body_points = v,
    );
    d.string(
        "body_frame",
        &c.body_frame,
        "frame of the touchdowns and of the assessment (the body frame)",
        |c, v| c.body_frame = v,
    );
}

/// `terrain_node`'s configuration: the assessment's thresholds, body points and body frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TerrainNodeConfig {
    /// Thresholds, body points and frame.
    pub terrain: TerrainConfig,
}

impl Config for TerrainNodeConfig {
    fn declare(d: &mut Decl<Self>) {
        d.nest(|c: &mut TerrainNodeConfig| &mut c.terrain, declare_terrain);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        Assessor::new(self.terrain.clone())
            .map(|_| ())
            .map_err(ConfigError::inconsistent)
    }
}

/// Why a touchdown message was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TouchdownRefusal {
    /// frame_id is not the body frame.
    #[error("touchdown of {leg} in frame `{got}`, expected the body frame `{expected}` (the node has no transforms)")]
    WrongFrame {
        /// The leg name as sent.
        leg: String,
        /// The message's frame_id.
        got: String,
        /// The configured body frame.
        expected: String,
    },
    /// Unknown leg, non-finite or out-of-range position.
    #[error("{0}")]
    Invalid(TerrainError),
}

/// What one touchdown led to. One lives at a time, returned and matched at once, so the size of
/// the assessment in it costs nothing worth a box.
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum TouchdownOutcome {
    /// A new assessment (all six feet known).
    Assessed(Assessment),
    /// Stored; this many legs have touched down so far (fewer than six).
    Waiting(usize),
    /// Refused; nothing changed but the counter.
    Refused(TouchdownRefusal),
    /// Stored, but the stance could not be assessed; the last good assessment stays.
    Failed(TerrainError),
}

/// The node's memory: the feet (by [`FootTracker`]), the stamp of the last good assessment and
/// of each leg's latest touchdown, and the refusals the tracker does not see (wrong frame).
#[derive(Debug, Clone)]
pub struct TerrainState {
    tracker: FootTracker,
    stamps: [Option<Time>; 6],
    last_stamp: Time,
    wrong_frame: u64,
    /// Counts carried over from trackers replaced by a reconfiguration …
    carried: (u64, u64),
    /// … and the current tracker's counts from replaying the feet into it (not counted).
    offset: (u64, u64),
    /// The last good assessment carried over a reconfiguration whose replay of the stored
    /// feet assessed nothing (a degenerate stance stored): the last good one stays.
    kept: Option<Assessment>,
}

fn nanos(t: &Time) -> i128 {
    i128::from(t.sec) * 1_000_000_000 + i128::from(t.nanosec)
}

impl TerrainState {
    /// A state that knows no foot; refuses an invalid configuration.
    pub fn new(config: TerrainConfig) -> Result<Self, TerrainError> {
        Ok(TerrainState {
            tracker: FootTracker::new(Assessor::new(config)?),
            stamps: Default::default(),
            last_stamp: Time::default(),
            wrong_frame: 0,
            carried: (0, 0),
            offset: (0, 0),
            kept: None,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &TerrainConfig {
        self.tracker.assessor().config()
    }

    /// Handles one touchdown message (see the crate docs for every rule), and tells whether the
    /// leg's stamp went backwards (accepted; the caller logs it).
    pub fn touchdown(&mut self, msg: &FootTouchdown) -> (TouchdownOutcome, bool) {
        let expected = &self.tracker.assessor().config().body_frame;
        if msg.header.frame_id.trim_start_matches('/') != expected.trim_start_matches('/') {
            self.wrong_frame += 1;
            let refusal = TouchdownRefusal::WrongFrame {
                leg: msg.leg.clone(),
                got: msg.header.frame_id.clone(),
                expected: expected.clone(),
            };
            return (TouchdownOutcome::Refused(refusal), false);
        }
        let p = Point3::new(msg.position.x, msg.position.y, msg.position.z);
        let result = self.tracker.touchdown_named(&msg.leg, p);
        if let Err(
            e @ (TerrainError::UnknownLeg(_) | TerrainError::NonFinite { .. } | TerrainError::OutOfRange { .. }),
        ) = &result
        {
            return (TouchdownOutcome::Refused(TouchdownRefusal::Invalid(e.clone())), false);
        }
        // Stored: the leg parsed.
        let mut backwards = false;
        if let Ok(leg) = Leg::parse(&msg.leg) {
            let slot = &mut self.stamps[leg.index()];
            backwards = slot.as_ref().is_some_and(|old| nanos(&msg.header.stamp) < nanos(old));
            *slot = Some(msg.header.stamp.clone());
        }
        let outcome = match result {
            Ok(Some(a)) => {
                self.last_stamp = msg.header.stamp.clone();
                TouchdownOutcome::Assessed(a)
            }
            Ok(None) => TouchdownOutcome::Waiting(self.stamps.iter().filter(|s| s.is_some()).count()),
            Err(e) => TouchdownOutcome::Failed(e),
        };
        (outcome, backwards)
    }

    /// Takes a new configuration: the stored feet are assessed again with it (the counts go on).
    /// Returns the new assessment when all six feet are known and assessable.
    pub fn reconfigure(&mut self, config: TerrainConfig) -> Result<Option<Assessment>, TerrainError> {
        let mut tracker = FootTracker::new(Assessor::new(config)?);
        let mut last = None;
        for leg in Leg::ALL {
            if let Some(p) = self.tracker.foot(leg) {
                last = tracker.touchdown(leg, p).ok().flatten();
            }
        }
        // The stored stance could not be assessed: the last good assessment stays, its feet
        // assessed again with the new configuration where they can be.
        self.kept = match (&last, self.last().map(|(a, _)| *a)) {
            (None, Some(old)) => Some(tracker.assessor().assess(&old.feet).unwrap_or(old)),
            _ => None,
        };
        if last.is_none() {
            last = self.kept;
        }
        // The counts go on from their totals; the replay's own (none for stored feet, which
        // were valid) are not added.
        self.carried = (self.rejected_touchdowns_u64(), self.failed_assessments_u64());
        self.offset = (tracker.rejected(), tracker.failed());
        self.wrong_frame = 0;
        self.tracker = tracker;
        Ok(last)
    }

    fn rejected_touchdowns_u64(&self) -> u64 {
        self.carried.0 + self.tracker.rejected().saturating_sub(self.offset.0) + self.wrong_frame
    }

    fn failed_assessments_u64(&self) -> u64 {
        self.carried.1 + self.tracker.failed().saturating_sub(self.offset.1)
    }

    /// Touchdowns refused so far (wrong frame, unknown leg, bad coordinate).
    pub fn rejected_touchdowns(&self) -> u32 {
        u32::try_from(self.rejected_touchdowns_u64()).unwrap_or(u32::MAX)
    }

    /// Stances that could not be assessed so far.
    pub fn failed_assessments(&self) -> u32 {
        u32::try_from(self.failed_assessments_u64()).unwrap_or(u32::MAX)
    }

    /// The last good assessment and the stamp of the touchdown that made it.
    pub fn last(&self) -> Option<(&Assessment, &Time)> {
        self.tracker
            .last()
            .or(self.kept.as_ref())
            .map(|a| (a, &self.last_stamp))
    }

    /// The last good assessment as a message with the current counts.
    pub fn last_message(&self) -> Option<TerrainAssessment> {
        self.last().map(|(a, stamp)| {
            assessment_message(
                a,
                stamp.clone(),
                &self.config().body_frame,
                self.rejected_touchdowns(),
                self.failed_assessments(),
            )
        })
    }
}

pub(crate) fn point(p: &Point3<f64>) -> Point {
    Point { x: p.x, y: p.y, z: p.z }
}

fn plane_message(p: &PlaneTilt) -> PlaneTiltMsg {
    PlaneTiltMsg {
        a: p.a,
        b: p.b,
        c: p.c,
        d: p.d,
        theta_x: p.theta_x,
        theta_y: p.theta_y,
        downhill: p.downhill,
    }
}

/// `terrain/assessment` from an assessment, field for field, with the counts.
pub fn assessment_message(a: &Assessment, stamp: Time, frame: &str, rejected: u32, failed: u32) -> TerrainAssessment {
    TerrainAssessment {
        header: Header {
            stamp,
            frame_id: frame.to_owned(),
        },
        feet: a.feet.map(|p| point(&p)),
        sigma: a.sigma,
        alpha12: a.alpha12,
        alpha23: a.alpha23,
        alpha13: a.alpha13,
        planes: a.planes.map(|p| plane_message(&p)),
        tilt: a.tilt,
        terrain_class: a.class.as_u8(),
        advised_gait: a.advice.as_u8(),
        rejected_touchdowns: rejected,
        failed_assessments: failed,
    }
}

/// The namespace of every terrain marker.
const NS: &str = "terrain";

/// Length of the drawn normals (m).
pub const NORMAL_LENGTH: f64 = 0.08;

/// `terrain/markers`, in the body frame: the three planes as triangles through their points
/// (ids 0–2: plane 1 blue, plane 2 orange, plane 3 grey, half transparent), their unit normals
/// as arrows of [`NORMAL_LENGTH`] from each triangle's centroid (ids 3–5), and the six feet as
/// spheres (id 6: tripod A blue, tripod B orange). Seven markers, 21 points: about 2 KB.
pub fn markers(a: &Assessment, body_points: &[Point3<f64>; 3], stamp: Time, frame: &str) -> MarkerArray {
    let mut m = Markers::new(stamp, frame);
    let foot = |leg: Leg| a.feet[leg.index()];
    let triangles = [Leg::PLANE1.map(foot), Leg::PLANE2.map(foot), *body_points];
    let blue = |alpha| rgba(0.0, 0.35, 0.71, alpha);
    let orange = |alpha| rgba(0.9, 0.62, 0.0, alpha);
    let colors = [blue(0.5), orange(0.5), rgba(0.6, 0.6, 0.6, 0.5)];
    // Markers' line and dot builders take points of the plane; these are in 3D, so each marker
    // is added bare and given its points.
    for (i, (tri, c)) in triangles.iter().zip(&colors).enumerate() {
        let triangle = m.add(NS, i as i32, Marker::TRIANGLE_LIST, [1.0; 3], c.clone());
        triangle.points = tri.iter().map(point).collect();
    }
    for (i, (tri, c)) in triangles.iter().zip(colors).enumerate() {
        let centroid = Point3::from((tri[0].coords + tri[1].coords + tri[2].coords) / 3.0);
        let n: V3<f64> = a.planes[i].normal();
        let opaque = rgb(c.r, c.g, c.b);
        let arrow = m.add(NS, 3 + i as i32, Marker::ARROW, [0.006, 0.012, 0.015], opaque);
        arrow.points = vec![point(&centroid), point(&(centroid + n * NORMAL_LENGTH))];
    }
    let feet = m.add(NS, 6, Marker::SPHERE_LIST, [0.02; 3], rgb(1.0, 1.0, 1.0));
    feet.points = a.feet.iter().map(point).collect();
    feet.colors = Leg::ALL
        .iter()
        .map(|l| {
            if Leg::PLANE1.contains(l) {
                blue(1.0)
            } else {
                orange(1.0)
            }
        })
        .collect();
    m.array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hexapod_sim::{touchdown_message, HexapodSimConfig};
    use mobil_msgs::mobil_msgs::msg::TerrainAssessment as TA;
    use mobil_ros::params::ParamValues;
    use mobil_terrain::HexapodGeometry;

    /// Table 1's small column (cm) at the default footholds, 0.10 m below the body.
    const SMALL: [f64; 6] = [2.0, -1.0, -2.0, 0.0, 1.0, 0.0];

    fn td(leg: &str, x: f64, y: f64, z: f64, sec: i32) -> FootTouchdown {
        FootTouchdown {
            header: Header {
                stamp: Time { sec, nanosec: 0 },
                frame_id: "base_link".into(),
            },
            leg: leg.into(),
            position: Point { x, y, z },
        }
    }

    fn column(z_cm: [f64; 6]) -> Vec<FootTouchdown> {
        let g = HexapodGeometry::default();
        Leg::ALL
            .iter()
            .zip(z_cm)
            .map(|(&leg, z)| {
                let p = g.footholds.get(leg);
                td(leg.name(), p.x, p.y, -0.10 + z / 100.0, 1)
            })
            .collect()
    }

    fn state() -> TerrainState {
        TerrainState::new(TerrainConfig::default()).unwrap()
    }

    #[test]
    fn the_defaults_load_from_parameters() {
        let defaults = ParamValues::defaults(&Decl::<TerrainNodeConfig>::of().specs());
        let c: TerrainNodeConfig = mobil_ros::config::load(&defaults).unwrap();
        assert_eq!(c.terrain, TerrainConfig::default());
    }

    #[test]
    fn inconsistent_thresholds_and_collinear_body_points_are_refused() {
        let mut values = ParamValues::defaults(&Decl::<TerrainNodeConfig>::of().specs());
        values.set("sigma_max", ros2_client::ParameterValue::Double(0.015));
        let e = mobil_ros::config::load::<TerrainNodeConfig>(&values).unwrap_err();
        assert!(e.to_string().contains("sigma_max"), "{e}");
        let mut values = ParamValues::defaults(&Decl::<TerrainNodeConfig>::of().specs());
        let line = vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0];
        values.set("body_points", ros2_client::ParameterValue::DoubleArray(line));
        let e = mobil_ros::config::load::<TerrainNodeConfig>(&values).unwrap_err();
        assert!(e.to_string().contains("collinear"), "{e}");
    }

    #[test]
    fn nothing_is_assessed_before_all_six_feet() {
        let mut s = state();
        let msgs = column([0.0; 6]);
        for (k, m) in msgs.iter().take(5).enumerate() {
            assert_eq!(s.touchdown(m).0, TouchdownOutcome::Waiting(k + 1));
        }
        assert!(s.last_message().is_none());
        assert!(matches!(s.touchdown(&msgs[5]).0, TouchdownOutcome::Assessed(_)));
    }

    /// Table 1's small column through the message path: σ √(10/6) = 1.2910 cm, UNEVEN (α12
    /// 7.590° > 3°, worked out by Cramer's rule in the library's tests/table1.rs), ripple.
    #[test]
    fn table1_small_column_becomes_the_message() {
        let mut s = state();
        let mut last = None;
        for m in column(SMALL) {
            last = Some(s.touchdown(&m).0);
        }
        assert!(matches!(last, Some(TouchdownOutcome::Assessed(_))));
        let msg = s.last_message().unwrap();
        assert!((msg.sigma - (10.0f64 / 6.0).sqrt() / 100.0).abs() < 1e-12);
        assert!((msg.alpha12.to_degrees() - 7.590).abs() < 1e-3);
        assert_eq!((msg.terrain_class, msg.advised_gait), (TA::UNEVEN, TA::GAIT_RIPPLE));
        assert_eq!(msg.header.frame_id, "base_link");
        assert_eq!(msg.header.stamp.sec, 1);
        // KG (index 2) at z = −0.10 − 0.02.
        assert!((msg.feet[2].z + 0.12).abs() < 1e-15 && (msg.feet[2].x + 0.15).abs() < 1e-15);
        // Plane 3 is the body plane: normal (0, 0, 1), level.
        assert_eq!((msg.planes[2].c, msg.planes[2].theta_x), (1.0, 0.0));
        assert_eq!((msg.rejected_touchdowns, msg.failed_assessments), (0, 0));
    }

    #[test]
    fn refusals_are_counted_and_keep_the_last_good_assessment() {
        let mut s = state();
        for m in column(SMALL) {
            s.touchdown(&m);
        }
        let good = s.last_message().unwrap();
        let bad = [
            td("XX", 0.1, 0.1, -0.1, 2),
            td("kp", 0.1, 0.1, -0.1, 2),
            td("KP", f64::NAN, 0.1, -0.1, 2),
            td("KV", 0.0, 0.16, f64::INFINITY, 2),
            td("DG", 0.0, 0.16, 2e3, 2),
        ];
        for (k, m) in bad.iter().enumerate() {
            let (outcome, _) = s.touchdown(m);
            assert!(
                matches!(outcome, TouchdownOutcome::Refused(TouchdownRefusal::Invalid(_))),
                "{m:?}"
            );
            assert_eq!(s.rejected_touchdowns(), k as u32 + 1);
        }
        let mut wrong = td("KP", 0.15, 0.12, -0.1, 2);
        wrong.header.frame_id = "odom".into();
        let (outcome, _) = s.touchdown(&wrong);
        let TouchdownOutcome::Refused(r) = outcome else {
            panic!("accepted a foot in odom")
        };
        assert!(
            r.to_string().contains("`odom`") && r.to_string().contains("`base_link`"),
            "{r}"
        );
        wrong.header.frame_id = String::new();
        assert!(matches!(s.touchdown(&wrong).0, TouchdownOutcome::Refused(_)));
        let after = s.last_message().unwrap();
        assert_eq!((after.rejected_touchdowns, after.failed_assessments), (7, 0));
        // Everything else is the last good assessment, stamp included.
        let strip = |mut m: TerrainAssessment| {
            m.rejected_touchdowns = 0;
            m
        };
        assert_eq!(strip(after), good);
        // A leading slash is the same frame (tf2 ignores it).
        let mut slash = td("KP", 0.15, 0.12, -0.08, 3);
        slash.header.frame_id = "/base_link".into();
        assert!(matches!(s.touchdown(&slash).0, TouchdownOutcome::Assessed(_)));
    }

    /// KP moved onto the line through KG and DV: plane 1 is undefined. The foot is stored, the
    /// failure counted, and the last good assessment stays.
    #[test]
    fn a_degenerate_stance_keeps_the_last_assessment() {
        let mut s = state();
        for m in column([0.0; 6]) {
            s.touchdown(&m);
        }
        let good = s.last_message().unwrap();
        // KG (−0.15, 0.12, −0.10), DV (0, −0.16, −0.10): the point beyond DV by the same step is
        // (0.15, −0.44, −0.10).
        let (outcome, _) = s.touchdown(&td("KP", 0.15, -0.44, -0.10, 2));
        assert!(matches!(
            outcome,
            TouchdownOutcome::Failed(TerrainError::CollinearPoints { .. })
        ));
        let after = s.last_message().unwrap();
        assert_eq!((after.rejected_touchdowns, after.failed_assessments), (0, 1));
        assert_eq!(after.header.stamp.sec, 1, "the last good one's stamp");
        assert_eq!(after.sigma, good.sigma);
    }

    #[test]
    fn a_stamp_going_back_is_accepted_and_reported() {
        let mut s = state();
        for m in column([0.0; 6]) {
            s.touchdown(&m);
        }
        let (outcome, backwards) = s.touchdown(&td("KP", 0.15, 0.12, -0.09, 0));
        assert!(backwards);
        let TouchdownOutcome::Assessed(a) = outcome else {
            panic!("not assessed")
        };
        assert!((a.feet[0].z + 0.09).abs() < 1e-15);
        assert!(
            !s.touchdown(&td("KP", 0.15, 0.12, -0.09, 0)).1,
            "same stamp: not backwards"
        );
    }

    /// Σ_max lowered below the small column's σ (1.29 cm): the stored feet become BEYOND_LIMITS
    /// at once, and the counts go on.
    #[test]
    fn a_new_configuration_reassesses_the_stored_feet() {
        let mut s = state();
        for m in column(SMALL) {
            s.touchdown(&m);
        }
        s.touchdown(&td("XX", 0.0, 0.0, 0.0, 2));
        let c = TerrainConfig {
            sigma_flat: 0.005,
            sigma_wave: 0.008,
            sigma_max: 0.012,
            ..TerrainConfig::default()
        };
        let a = s.reconfigure(c).unwrap().unwrap();
        assert_eq!(a.class, mobil_terrain::TerrainClass::BeyondLimits);
        assert_eq!(s.last_message().unwrap().terrain_class, TA::BEYOND_LIMITS);
        assert_eq!(s.rejected_touchdowns(), 1);
    }

    /// Flat feet, then KP on the line through KG (−0.15, 0.12, −0.10) and DV (0, −0.16, −0.10)
    /// (one more step beyond DV: (0.15, −0.44, −0.10)) stored, then new thresholds: the replay
    /// assesses nothing, so the last good assessment stays (σ 0, FLAT) and the counts still
    /// publish.
    #[test]
    fn a_new_configuration_over_a_degenerate_stance_keeps_the_last_assessment() {
        let mut s = state();
        for m in column([0.0; 6]) {
            s.touchdown(&m);
        }
        let good = s.last_message().unwrap();
        assert!(matches!(
            s.touchdown(&td("KP", 0.15, -0.44, -0.10, 2)).0,
            TouchdownOutcome::Failed(TerrainError::CollinearPoints { .. })
        ));
        let c = TerrainConfig {
            sigma_flat: 0.005,
            sigma_wave: 0.008,
            sigma_max: 0.012,
            ..TerrainConfig::default()
        };
        let a = s.reconfigure(c).unwrap().unwrap();
        assert_eq!((a.class, a.sigma), (mobil_terrain::TerrainClass::Flat, 0.0));
        let kept = s.last_message().unwrap();
        assert_eq!(kept.terrain_class, TA::FLAT);
        assert_eq!((kept.sigma, kept.failed_assessments), (good.sigma, 1));
        assert_eq!(kept.header.stamp.sec, 1, "the last good one's stamp");
        s.touchdown(&td("XX", 0.0, 0.0, 0.0, 3));
        assert_eq!(s.last_message().unwrap().rejected_touchdowns, 1);
    }

    #[test]
    fn markers_draw_three_planes_their_normals_and_the_feet() {
        let mut s = state();
        for m in column([0.0; 6]) {
            s.touchdown(&m);
        }
        let (a, _) = s.last().unwrap();
        let body = s.config().body_points();
        let m = markers(a, &body, Time::default(), "base_link");
        assert_eq!(m.markers.len(), 7);
        // Plane 1's triangle is KP, KG, DV.
        let t = &m.markers[0];
        assert_eq!(t.r#type, Marker::TRIANGLE_LIST);
        assert_eq!((t.points[1].x, t.points[1].y), (-0.15, 0.12));
        // Level ground: plane 1's normal is +z from its centroid ((0.15 − 0.15 + 0)/3,
        // (0.12 + 0.12 − 0.16)/3, −0.10).
        let n = &m.markers[3];
        assert_eq!(n.r#type, Marker::ARROW);
        assert!((n.points[0].y - 0.08 / 3.0).abs() < 1e-15);
        assert!((n.points[1].z - (-0.10 + NORMAL_LENGTH)).abs() < 1e-15);
        assert_eq!(m.markers[6].points.len(), 6);
        assert!(m.markers.iter().all(|k| k.header.frame_id == "base_link"));
        // One namespace, ids 0–6 in order, all added unrotated.
        let ids: Vec<i32> = m.markers.iter().map(|k| k.id).collect();
        assert_eq!(ids, (0..7).collect::<Vec<_>>());
        assert!(m.markers.iter().all(|k| k.ns == "terrain"
            && k.action == Marker::ADD
            && (k.pose.orientation.z, k.pose.orientation.w) == (0.0, 1.0)));
        // The triangles half transparent, their normals the same colour opaque.
        let rgb_of = |k: &Marker| (k.color.r, k.color.g, k.color.b);
        let colours = [(0.0, 0.35, 0.71), (0.9, 0.62, 0.0), (0.6, 0.6, 0.6)];
        for (i, c) in colours.into_iter().enumerate() {
            let (tri, normal) = (&m.markers[i], &m.markers[3 + i]);
            assert_eq!((rgb_of(tri), tri.color.a, tri.points.len()), (c, 0.5, 3));
            assert_eq!((rgb_of(normal), normal.color.a, normal.points.len()), (c, 1.0, 2));
            assert_eq!((tri.scale.x, tri.scale.y, tri.scale.z), (1.0, 1.0, 1.0));
            assert_eq!((normal.scale.x, normal.scale.y, normal.scale.z), (0.006, 0.012, 0.015));
        }
        // Plane 3's triangle is the body points.
        let third: Vec<Point3<f64>> = m.markers[2].points.iter().map(|p| Point3::new(p.x, p.y, p.z)).collect();
        assert_eq!(third, body.to_vec());
        // The feet: 2 cm spheres, where they stand, tripod A blue and tripod B orange.
        let feet = &m.markers[6];
        assert_eq!(
            (feet.r#type, feet.scale.x, feet.scale.z),
            (Marker::SPHERE_LIST, 0.02, 0.02)
        );
        assert_eq!(feet.points, a.feet.map(|p| point(&p)).to_vec());
        for (leg, c) in Leg::ALL.iter().zip(&feet.colors) {
            let tripod = if Leg::PLANE1.contains(leg) {
                (0.0, 0.35, 0.71)
            } else {
                (0.9, 0.62, 0.0)
            };
            assert_eq!((c.r, c.g, c.b, c.a), (tripod.0, tripod.1, tripod.2, 1.0), "{leg:?}");
        }
        assert_eq!(feet.colors.len(), 6);
    }

    /// The walker's first touchdowns, turned into messages and fed back: the node's own check
    /// accepts what the simulator sends, and six feet on flat ground are FLAT, σ 0.
    #[test]
    fn the_simulators_touchdowns_are_what_the_node_accepts() {
        let c: HexapodSimConfig =
            mobil_ros::config::load(&ParamValues::defaults(&Decl::<HexapodSimConfig>::of().specs())).unwrap();
        let w = c.walker().unwrap();
        let mut s = state();
        let mut last = None;
        for td in w.touchdowns_in(-1.0, 0.0) {
            last = Some(s.touchdown(&touchdown_message(&td, Time::default(), &c.body_frame)).0);
        }
        let Some(TouchdownOutcome::Assessed(a)) = last else {
            panic!("not assessed: {last:?}")
        };
        assert_eq!(a.sigma, 0.0);
        assert_eq!(a.class, mobil_terrain::TerrainClass::Flat);
    }
}
