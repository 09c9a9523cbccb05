//! Terrain irregularity of a hexapod from its posture (SPEC §6; Luneckas, source 001), and a
//! tripod-gait hexapod walking over a height map to feed it. ROS-free: no ROS types, no clock,
//! no I/O (`tests/check_ros_free.sh` proves it). The feet (body frame) are the input; σ, the
//! angles between the three planes, each plane's tilt, the class and the advised gait are the
//! output, field for field `mobil_msgs/TerrainAssessment`. `terrain_node` wires it to topics.
//!
//! - [`leg`]: the legs by the paper's names (KP … DG), in the message's order, with a parser.
//! - [`assess`]: σ (population; the sample σ beside it), planes 1 (KP, KG, DV), 2 (DP, DG, KV)
//!   and 3 (body points), α12, α23, α13 by eq. 17–19 with |N_i·N_j|, tilts, the class by the
//!   SPEC's corrected rule and the advice.
//! - [`tracker`]: [`FootTracker`], the latest touchdown of each leg, an assessment at every
//!   touchdown once all six are known, refused inputs counted.
//! - [`config`]: [`TerrainConfig`] (thresholds, body points, frame) and [`HexapodGeometry`]
//!   (footholds, body height), every default justified; `params/hexapod.yaml` holds them.
//! - [`ground`], [`walker`]: height maps (flat, a plane in any direction, seeded rough ground, a
//!   course of sections) and the walking hexapod.
//!
//! Choices beyond the SPEC:
//! - **A step between the tripods is UNEVEN, level or on a slope** (a departure from the
//!   SPEC's Decision, which sees only the angles). Two tripods on parallel planes at different
//!   heights have α12 = 0, so the SPEC's rule calls them FLAT (level) or SLOPE (tilted), though
//!   the feet are not coplanar. When α12 ≤ ε_α the assessment also measures the planes'
//!   offset, the larger distance of each tripod's foot centroid from the other tripod's plane
//!   ([`plane_offset`]), and classes the stance UNEVEN above `plane_offset_max` (1 cm). Tripod A
//!   on z = tan 10°·x − 0.10 and tripod B 3 cm lower: offset 3 cm · cos 10° = 2.95 cm, UNEVEN
//!   (the SPEC's rule: SLOPE).
//! - **FLAT also needs σ ≤ σ_flat**, a cap on the height spread the tripod gait must clear.
//!   σ_flat (1 cm) lies above the σ of any plane tilted within ε_α with the default footholds
//!   (0.70 cm), so a coplanar stance within ε_α is still FLAT; with the default thresholds the
//!   angle and offset tests already keep σ under 0.94 cm on FLAT ground, so it binds only for
//!   a larger ε_α or plane_offset_max.
//! - **Ripple or wave by σ_wave**, a fifth threshold: SLOPE and UNEVEN get ripple up to
//!   σ_wave (2.5 cm: above a plain 10° slope's 2.16–2.37 cm, below Table 1's large column's
//!   2.77 cm), wave above; FLAT keeps the tripod
//!   gait; BEYOND_LIMITS advises another route.
//! - **tilt** (the message's) is the larger inclination of planes 1 and 2 to the body's
//!   xy-plane; tilt_max bounds it.
//! - **Planes** carry a unit normal (a, b, c) turned to c ≥ 0 (upward); d = −N·P1. Its
//!   horizontal part points downhill, so θ_x = atan2(a, c) > 0 when the ground falls toward
//!   +x (ground rising 10° ahead gives θ_x = −10°), θ_y = atan2(b, c) > 0 when it falls toward
//!   +y (left), and downhill = atan2(b, a) is the direction of steepest descent in the body's
//!   xy-plane; a level plane's is atan2(0, 0) = 0.
//! - **Angles** are computed as atan2(|N_i × N_j|, |N_i·N_j|), the arccos of eq. 17–19 with the
//!   SPEC's absolute value without its loss of precision near 0 (1e-8 rad for arccos).
//! - **Degenerate input**: a coordinate beyond ±1 km or not finite, two points of a plane
//!   closer than 1 µm, or three points whose edges at the first vertex make an angle with
//!   sine below 1e-5: a typed [`TerrainError`], never a NaN.
//! - **Each stored foot is in the body frame of its own touchdown** (SPEC §6: the control stores
//!   each foot as it lands). The tracker does not move older feet into the current frame: it has
//!   no odometry, and on a plane walked at a constant height above it the frames agree exactly.
//!   On rough ground the other tripod's feet are up to half a gait period old, and the body's
//!   height has changed by a few millimetres since; that is part of the measured σ.
//! - **The walker's body stays level** (as a levelling controller keeps it), at a set height
//!   above the mean ground under its footholds; see [`walker`]. It lives here, not in
//!   `mobil_sim` (the wheeled chassis and its 2D world): it shares the legs, the footholds and
//!   the assessment its tests check against, and a hexapod simulator node depends on this
//!   ROS-free crate alone.
//!
//! ```
//! use mobil_terrain::{Assessor, Gait, HexapodGeometry, TerrainClass, TerrainConfig};
//!
//! let assessor = Assessor::new(TerrainConfig::default()).unwrap();
//! // The standing hexapod on flat ground: σ = 0, every plane parallel to the body.
//! let a = assessor.assess(&HexapodGeometry::default().standing_feet()).unwrap();
//! assert_eq!(a.sigma, 0.0);
//! assert_eq!((a.class, a.advice), (TerrainClass::Flat, Gait::Tripod));
//! ```

#![warn(missing_docs)]

pub mod assess;
pub mod config;
pub mod error;
pub mod ground;
pub mod leg;
pub mod tracker;
pub mod walker;

pub use assess::{
    advise, angle_between, classify, plane_offset, sigma_of_heights, Assessment, Assessor, Gait, Measures, PlaneTilt,
    TerrainClass,
};
pub use config::{Footholds, HexapodGeometry, TerrainConfig};
pub use error::{PlaneId, TerrainError, COORDINATE_LIMIT, MIN_EDGE, MIN_SINE};
pub use ground::{Course, Ground, RoughGround, Section};
pub use leg::{Leg, Tripod};
pub use tracker::FootTracker;
pub use walker::{BodyPose, Touchdown, Walker, WalkerConfig};
