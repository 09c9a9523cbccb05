//! The Nao-sized body: its links, masses, motors and the floor, with every figure's source.
//!
//! Frames: x forward, y left, z up (ROS's and Nao's), gravity −9.81 m/s² along z. Angles follow
//! Nao's sign convention (NAOqi, Webots): pitch turns about +y (a positive hip or knee pitch moves
//! the foot backwards), roll about +x.

use crate::{SolverSetting, CHECK_SETTING};
use mobil_ga_step::{PhysicsModel, Servo};

/// Whole robot (kg), Nao H25 V3.3 "Masses" page of Aldebaran's documentation.
pub const WHOLE_ROBOT_MASS: f64 = 4.996;
/// The Torso solid alone (kg), same page (1.03948 kg); part of the lumped torso.
pub const TORSO_SOLID_MASS: f64 = 1.03948;

/// One leg's links below the pelvis with Nao's masses (kg, Aldebaran H25 V3.3/V4 "Masses"
/// pages, rounded to the gram): Hip (between hip roll and hip pitch) 0.135, Thigh 0.394,
/// Tibia 0.292, Ankle (between ankle pitch and ankle roll) 0.139, Foot 0.163.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegMasses {
    /// The hip link between hip roll and hip pitch (kg).
    pub hip: f64,
    /// The thigh (kg).
    pub thigh: f64,
    /// The tibia (kg).
    pub tibia: f64,
    /// The ankle link between ankle pitch and ankle roll (kg).
    pub ankle: f64,
    /// The foot (kg).
    pub foot: f64,
}

impl LegMasses {
    /// The leg's mass below the pelvis (kg).
    pub fn total(&self) -> f64 {
        self.hip + self.thigh + self.tibia + self.ankle + self.foot
    }
}

/// How a servo turns its target angle into torque.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ServoKind {
    /// Webots' position control of a `RotationalMotor` (docs/reference/motor.md, "Motor
    /// Control"): every step the velocity V = P·(target − position) is asked for, clamped to
    /// ±maxVelocity, and reached by ODE's joint motor, whose torque is at most maxTorque. The
    /// target is the motion's angle at that instant; nothing limits how fast it moves.
    Webots,
    /// A torque-limited PD spring (stiffness, damping) whose limit is Nao's motor's continuous
    /// torque, cut above the nominal speed by the DC motor's torque–speed line; the target
    /// moves towards the motion's angle no faster than the no-load speed.
    DcMotor,
}

/// The body's figures. Lengths are Nao's published link lengths (Aldebaran, "H25 Links", the
/// same in Webots' Nao.proto): HipOffsetY 50 mm, HipOffsetZ 85 mm, ThighLength 100 mm,
/// TibiaLength 102.9 mm.
///
/// Two settings: [`BodyParams::webots`] (the default), calibrated to the Nao of Webots, the
/// source's simulator (every figure's file and line: docs/ga_step.md, "Calibration"), and
/// [`BodyParams::dc_motor`], the earlier model built from Aldebaran's motor datasheet.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyParams {
    /// Lateral distance of each hip joint from the torso frame (m).
    pub hip_offset_y: f64,
    /// Height of the torso frame above the hip joints (m).
    pub hip_offset_z: f64,
    /// Hip pitch to knee (m).
    pub thigh_length: f64,
    /// Knee to ankle pitch (m).
    pub tibia_length: f64,
    /// Ankle to sole (m).
    pub foot_height: f64,
    /// Sole length (m) ...
    pub foot_length: f64,
    /// ... and width (m) ...
    pub foot_width: f64,
    /// ... with the sole's centre this far in front of the ankle (m) ...
    pub foot_forward: f64,
    /// ... and this far outward of it (m, ≥ 0: to the right of the right ankle, to the left of
    /// the left one).
    pub foot_outward: f64,
    /// Thickness of the sole box (m); its bottom face is the sole.
    pub sole_thickness: f64,
    /// The lumped torso (kg): everything above the hips, i.e. the whole robot less both legs
    /// below the pelvis; the arms and head are held at their standing pose and the hip
    /// yaw-pitch joint is not evolved, so torso, head, neck, arms and both pelvis links move as
    /// one rigid body.
    pub torso_mass: f64,
    /// Height of the lumped torso's centre of mass above the torso frame (m): the Torso solid's
    /// is 43 mm (Aldebaran's figure); with the head above and the hanging arms beside it, the
    /// lump's is taken at 60 mm.
    pub torso_com_z: f64,
    /// The lumped torso's box for its inertia and collisions: depth, width, height (m), a
    /// uniform box of Nao's trunk-with-arms size (100 × 200 × 300 mm).
    pub torso_box: [f64; 3],
    /// One leg's link masses.
    pub leg: LegMasses,
    /// Radius of the thigh and tibia capsules (m) for their inertia and collisions.
    pub limb_radius: f64,
    /// How the servos act.
    pub servo: ServoKind,
    /// P of Webots' position controller (1/s): the velocity asked for per radian of error
    /// ([`ServoKind::Webots`] only).
    pub p_gain: f64,
    /// Torque limit of the pitch joints (hip, knee, ankle pitch; N·m): Webots' `maxTorque`, or
    /// the DC motor's continuous torque.
    pub pitch_max_torque: f64,
    /// Torque limit of the roll joints (hip, ankle roll; N·m).
    pub roll_max_torque: f64,
    /// Stall torque of the pitch joints (N·m, [`ServoKind::DcMotor`] only): it fixes the slope
    /// of the DC motor's torque–speed line, τ_stall·(1 − ω/ω₀).
    pub pitch_stall_torque: f64,
    /// Stall torque of the roll joints (N·m, [`ServoKind::DcMotor`] only).
    pub roll_stall_torque: f64,
    /// Speed limit of the pitch joints (rad/s): Webots' `maxVelocity`, Nao's no-load speed.
    pub pitch_max_speed: f64,
    /// Speed limit of the roll joints (rad/s).
    pub roll_max_speed: f64,
    /// Servo stiffness (N·m/rad, [`ServoKind::DcMotor`] only).
    pub servo_stiffness: f64,
    /// Servo damping (N·m·s/rad, [`ServoKind::DcMotor`] only).
    pub servo_damping: f64,
    /// Coulomb friction between sole and floor.
    pub friction: f64,
    /// Restitution of a sole's impact on the floor (0: none).
    pub restitution: f64,
    /// The contacts' softness: the natural frequency (Hz) and damping ratio of the spring a
    /// contact acts as; `None` keeps rapier's defaults (30 Hz between moving bodies, 60 Hz
    /// against the floor, damping ratio 10).
    pub contact_softness: Option<[f64; 2]>,
    /// Whether friction is solved in every solver pass, with the motors and the contacts' push
    /// out of the floor, as ODE solves all constraints together. rapier's default (`false`)
    /// leaves friction out of its biased pass, where hard motors then slide the feet: a standing
    /// robot with Webots' motors crept 2–14 cm in 10 s and fell, against 0.3 mm with it on.
    pub friction_every_pass: bool,
    /// Simulation step (s).
    pub dt: f64,
    /// Solver iterations per step (rapier's `num_solver_iterations`: substeps of the
    /// soft-constraint solver).
    pub solver_iterations: usize,
    /// Projected Gauss–Seidel passes within each solver iteration (rapier's
    /// `num_internal_pgs_iterations`).
    pub pgs_iterations: usize,
    /// The robust score's second setting ([`mobil_ga_step::FitnessConfig::robust_check`]).
    pub check: SolverSetting,
}

/// Nao's leg link masses (kg): Aldebaran's H25 V3.3 "Masses" page, which Webots' Nao.proto
/// repeats for `version "V3.3"` (the foot there 0.08118 kg plus its 0.08057 kg sole plate,
/// 1.3 g less than this).
pub const LEG_MASSES: LegMasses = LegMasses {
    hip: 0.13530,
    thigh: 0.39421,
    tibia: 0.29159,
    ankle: 0.13892,
    foot: 0.16304,
};

impl Default for BodyParams {
    fn default() -> Self {
        BodyParams::webots()
    }
}

impl BodyParams {
    /// The body of a named physics model.
    pub fn named(model: PhysicsModel) -> BodyParams {
        match model {
            PhysicsModel::Webots => BodyParams::webots(),
            PhysicsModel::DcMotor => BodyParams::dc_motor(),
        }
    }

    /// The Nao of Webots, the source's simulator: its motors, their position control, the
    /// foot's contact box and the floor contact of its Nao worlds (docs/ga_step.md,
    /// "Calibration", gives each figure's file and line).
    pub fn webots() -> BodyParams {
        BodyParams {
            // The sole plate (`RFsr`'s `FOOT_Box`, 147 × 89 × 10 mm) is the foot's lowest part:
            // its bottom 41 + 5 mm below the ankle, its centre 20 mm ahead and 7 mm outward.
            foot_height: 0.046,
            foot_length: 0.147,
            foot_width: 0.089,
            foot_forward: 0.020,
            foot_outward: 0.007,
            sole_thickness: 0.010,
            servo: ServoKind::Webots,
            // RotationalMotor's default controlPID (Nao.proto sets none).
            p_gain: 10.0,
            // Nao.proto's maxTorque for `version "V3.3"`, the Nao of the source's time.
            pitch_max_torque: 8.0,
            roll_max_torque: 12.0,
            pitch_stall_torque: 8.0,
            roll_stall_torque: 12.0,
            pitch_max_speed: 6.40239,
            roll_max_speed: 4.16174,
            servo_stiffness: 0.0,
            servo_damping: 0.0,
            // nao_robocup.wbt's ContactProperties for "NAO foot material" on the floor.
            friction: 7.0,
            restitution: 0.3,
            // ODE's soft contact (softERP 0.2, softCFM 0.001 at 20 ms: 10 kN/m and 800 N·s/m a
            // contact point), four points a flat sole: on both feet 20.1 Hz, damping ratio 5.06.
            contact_softness: Some([20.1, 5.06]),
            friction_every_pass: true,
            // Webots' basicTimeStep in nao_robocup.wbt, the source's world; the cheapest
            // setting whose scores agree with the finer one (docs/ga_step.md, "Convergence").
            dt: 0.020,
            solver_iterations: 4,
            pgs_iterations: 2,
            // The convergence check's finer setting: half the step, twice the iterations.
            check: SolverSetting {
                dt: 0.010,
                solver_iterations: 8,
                pgs_iterations: 2,
            },
            ..BodyParams::dc_motor()
        }
    }

    /// The earlier model, from Aldebaran's motor datasheet: a PD spring limited to the motor's
    /// continuous torque (the RE-Max 24's 12.3 mN·m through the reductions 130.85 and 201.3:
    /// 1.61 and 2.47 N·m), cut above the nominal speed by its torque–speed line (stall 7.78 /
    /// 11.97 N·m, no-load speed 6.40 / 4.16 rad/s); a 160 × 90 mm sole, μ 0.8, rapier's contacts,
    /// 5 ms steps (docs/experiments/ga-step-physics.md).
    pub fn dc_motor() -> BodyParams {
        let leg = LEG_MASSES;
        BodyParams {
            hip_offset_y: 0.050,
            hip_offset_z: 0.085,
            thigh_length: 0.100,
            tibia_length: 0.1029,
            foot_height: 0.04519,
            foot_length: 0.160,
            foot_width: 0.090,
            foot_forward: 0.020,
            foot_outward: 0.0,
            sole_thickness: 0.015,
            torso_mass: WHOLE_ROBOT_MASS - 2.0 * leg.total(),
            torso_com_z: 0.060,
            torso_box: [0.10, 0.20, 0.30],
            leg,
            limb_radius: 0.030,
            servo: ServoKind::DcMotor,
            p_gain: 0.0,
            pitch_max_torque: 1.61,
            roll_max_torque: 2.47,
            pitch_stall_torque: 7.78,
            roll_stall_torque: 11.97,
            pitch_max_speed: 366.83_f64.to_radians(),
            roll_max_speed: 238.45_f64.to_radians(),
            servo_stiffness: 7.78 / 0.05,
            servo_damping: 3.0,
            friction: 0.8,
            restitution: 0.0,
            contact_softness: None,
            friction_every_pass: false,
            dt: 0.005,
            solver_iterations: 4,
            pgs_iterations: 2,
            check: CHECK_SETTING,
        }
    }

    /// The joint's torque limit (N·m).
    pub fn max_torque(&self, servo: Servo) -> f64 {
        if is_roll(servo) {
            self.roll_max_torque
        } else {
            self.pitch_max_torque
        }
    }

    /// The joint's stall torque (N·m), the torque–speed line's value at rest.
    pub fn stall_torque(&self, servo: Servo) -> f64 {
        if is_roll(servo) {
            self.roll_stall_torque
        } else {
            self.pitch_stall_torque
        }
    }

    /// The torque the joint's motor can give at joint speed `omega` (rad/s). Webots' motor: its
    /// maxTorque at any speed. The DC motor: the continuous torque, cut by the line
    /// τ_stall·(1 − |ω|/ω₀) while it drives the joint the way it turns (`driving`), to 0 at
    /// the no-load speed ω₀; while it brakes, the continuous torque.
    pub fn torque_limit(&self, servo: Servo, omega: f64, driving: bool) -> f64 {
        let max = self.max_torque(servo);
        if driving && self.servo == ServoKind::DcMotor {
            max.min(self.stall_torque(servo) * (1.0 - omega.abs() / self.max_speed(servo)).max(0.0))
        } else {
            max
        }
    }

    /// The joint's speed limit (rad/s).
    pub fn max_speed(&self, servo: Servo) -> f64 {
        if is_roll(servo) {
            self.roll_max_speed
        } else {
            self.pitch_max_speed
        }
    }

    /// The servo's target for this step when the motion asks for `wanted` and the last target
    /// was `last` (rad): Webots' motor takes the motion's angle as it is; the DC motor's target
    /// moves towards it by at most the no-load speed times the step. Clamped into the servo's
    /// limits.
    pub fn next_target(&self, servo: Servo, last: f64, wanted: f64) -> f64 {
        match self.servo {
            ServoKind::Webots => servo.clamp(wanted),
            ServoKind::DcMotor => {
                let max_move = self.max_speed(servo) * self.dt;
                servo.clamp(last + (wanted - last).clamp(-max_move, max_move))
            }
        }
    }

    /// Webots' position controller: the joint velocity (rad/s) asked for at `angle` with the
    /// target `target`, P·(target − angle) clamped to ±maxVelocity.
    pub fn webots_velocity(&self, servo: Servo, target: f64, angle: f64) -> f64 {
        let vmax = self.max_speed(servo);
        (self.p_gain * (target - angle)).clamp(-vmax, vmax)
    }

    /// The robot's total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.torso_mass + 2.0 * self.leg.total()
    }
}

/// Whether the servo turns about x (roll) rather than y (pitch).
pub fn is_roll(servo: Servo) -> bool {
    matches!(
        servo,
        Servo::RHipRoll | Servo::LHipRoll | Servo::RAnkleRoll | Servo::LAnkleRoll
    )
}

/// The leg's five servos from the torso outwards: hip roll, hip pitch, knee, ankle pitch, ankle
/// roll (Nao's chain order; hip yaw-pitch is held at 0 and merged into the torso).
pub fn leg_chain(left: bool) -> [Servo; 5] {
    if left {
        [
            Servo::LHipRoll,
            Servo::LHipPitch,
            Servo::LKneePitch,
            Servo::LAnklePitch,
            Servo::LAnkleRoll,
        ]
    } else {
        [
            Servo::RHipRoll,
            Servo::RHipPitch,
            Servo::RKneePitch,
            Servo::RAnklePitch,
            Servo::RAnkleRoll,
        ]
    }
}

/// One leg's five angles (rad, Nao's convention) in chain order: hip roll, hip pitch, knee
/// pitch, ankle pitch, ankle roll.
pub type LegAngles = [f64; 5];

impl BodyParams {
    /// Where the ankle joint lies relative to its hip joint (m; x forward, y left, z up, in the
    /// torso's frame) with the leg at `q`: the leg turned by the hip roll about x, in that plane
    /// the thigh at the hip pitch from straight down and the tibia at hip plus knee pitch
    /// (positive pitch swings the lower link backwards). The ankle angles do not move the ankle.
    pub fn ankle_from_hip(&self, q: &LegAngles) -> [f64; 3] {
        let (roll, hip, knee) = (q[0], q[1], q[2]);
        let x = -self.thigh_length * hip.sin() - self.tibia_length * (hip + knee).sin();
        let down = self.thigh_length * hip.cos() + self.tibia_length * (hip + knee).cos();
        [x, down * roll.sin(), -down * roll.cos()]
    }

    /// The leg angles that put the ankle at `ankle` relative to the hip (m, as
    /// [`ankle_from_hip`](Self::ankle_from_hip) gives it) with the knee bent backwards and the
    /// sole parallel to the torso's xy plane (ankle pitch −(hip + knee), ankle roll −hip roll);
    /// `None` out of the leg's reach (farther than thigh plus tibia, or nearer than their
    /// difference) or with the ankle above the hip.
    pub fn leg_angles(&self, ankle: [f64; 3]) -> Option<LegAngles> {
        let [x, y, z] = ankle;
        if z >= 0.0 {
            return None;
        }
        let roll = y.atan2(-z);
        let down = y.hypot(z);
        let (l1, l2) = (self.thigh_length, self.tibia_length);
        let d2 = x * x + down * down;
        let cos_knee = (d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
        if !(-1.0..=1.0).contains(&cos_knee) {
            return None;
        }
        let knee = cos_knee.acos();
        // The hip-to-ankle line's angle from straight down (positive: ankle behind the hip),
        // less the thigh's angle from that line.
        let line = (-x).atan2(down);
        let hip = line - (l2 * knee.sin()).atan2(l1 + l2 * knee.cos());
        Some([roll, hip, knee, -(hip + knee), -roll])
    }
}
