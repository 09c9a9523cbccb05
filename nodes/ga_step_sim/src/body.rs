//! The Nao-sized body: its links, masses, motors and the floor, with every figure's source.
//!
//! Frames: x forward, y left, z up (ROS's and Nao's), gravity −9.81 m/s² along z. Angles follow
//! Nao's sign convention (NAOqi, Webots): pitch turns about +y (a positive hip or knee pitch moves
//! the foot backwards), roll about +x.

use mobil_ga_step::Servo;

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

/// The body's figures. Lengths are Nao's published link lengths (Aldebaran, "H25 Links"):
/// HipOffsetY 50 mm, HipOffsetZ 85 mm, ThighLength 100 mm, TibiaLength 102.9 mm,
/// FootHeight 45.19 mm.
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
    /// Sole length (m): Nao's foot is about 160 mm long ...
    pub foot_length: f64,
    /// ... and about 90 mm wide (m) ...
    pub foot_width: f64,
    /// ... with the ankle 20 mm behind the sole's centre (m): the sole reaches about 100 mm in
    /// front of the ankle and 60 mm behind it.
    pub foot_forward: f64,
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
    /// Continuous torque of the pitch joints (hip, knee, ankle pitch; N·m): Nao's leg motor
    /// (RE-Max 24, nominal torque 12.3 mN·m) through the type B reduction 130.85 gives 1.61 N·m
    /// (Aldebaran, "Motors", without the gearbox's efficiency). The motor delivers it
    /// continuously; the stall torque is a momentary figure that would burn the winding.
    pub pitch_max_torque: f64,
    /// Continuous torque of the roll joints (hip, ankle roll; N·m): the same motor through the
    /// type A reduction 201.3, 2.47 N·m as Aldebaran's motor table prints it (see docs/ga_step.md,
    /// "The physics evaluator").
    pub roll_max_torque: f64,
    /// Stall torque of the pitch joints (N·m): 59.5 mN·m × 130.85 = 7.78 N·m. It only fixes the
    /// slope of the DC motor's torque–speed line, τ_stall·(1 − ω/ω₀), which caps the torque
    /// above the nominal speed (290.25 °/s, where the line passes 1.62 N·m, the nominal torque).
    pub pitch_stall_torque: f64,
    /// Stall torque of the roll joints (N·m): 59.5 mN·m × 201.3 = 11.97 N·m.
    pub roll_stall_torque: f64,
    /// No-load speed of the pitch joints (rad/s): 366.83 °/s = 6.40 rad/s (same page). The
    /// servo's target moves no faster.
    pub pitch_max_speed: f64,
    /// No-load speed of the roll joints (rad/s): 238.45 °/s = 4.16 rad/s.
    pub roll_max_speed: f64,
    /// Servo stiffness (N·m/rad): the stall torque at 0.05 rad of error (pitch); the continuous
    /// torque is reached at 0.01 rad.
    pub servo_stiffness: f64,
    /// Servo damping (N·m·s/rad), about critical for a leg's inertia about the hip.
    pub servo_damping: f64,
    /// Coulomb friction between sole and floor (both materials; rubber sole on a hard floor).
    pub friction: f64,
    /// Simulation step (s).
    pub dt: f64,
    /// Solver iterations per step (rapier's `num_solver_iterations`: substeps of the
    /// soft-constraint solver).
    pub solver_iterations: usize,
    /// Projected Gauss–Seidel passes within each solver iteration (rapier's
    /// `num_internal_pgs_iterations`).
    pub pgs_iterations: usize,
}

impl Default for BodyParams {
    fn default() -> Self {
        let leg = LegMasses {
            hip: 0.13530,
            thigh: 0.39421,
            tibia: 0.29159,
            ankle: 0.13892,
            foot: 0.16304,
        };
        BodyParams {
            hip_offset_y: 0.050,
            hip_offset_z: 0.085,
            thigh_length: 0.100,
            tibia_length: 0.1029,
            foot_height: 0.04519,
            foot_length: 0.160,
            foot_width: 0.090,
            foot_forward: 0.020,
            sole_thickness: 0.015,
            torso_mass: WHOLE_ROBOT_MASS - 2.0 * leg.total(),
            torso_com_z: 0.060,
            torso_box: [0.10, 0.20, 0.30],
            leg,
            limb_radius: 0.030,
            pitch_max_torque: 1.61,
            roll_max_torque: 2.47,
            pitch_stall_torque: 7.78,
            roll_stall_torque: 11.97,
            pitch_max_speed: 366.83_f64.to_radians(),
            roll_max_speed: 238.45_f64.to_radians(),
            servo_stiffness: 7.78 / 0.05,
            servo_damping: 3.0,
            friction: 0.8,
            dt: 0.005,
            solver_iterations: 4,
            pgs_iterations: 2,
        }
    }
}

impl BodyParams {
    /// The joint's continuous torque limit (N·m).
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

    /// The torque the joint's motor can give at joint speed `omega` (rad/s): the continuous
    /// torque, cut by the DC motor's line τ_stall·(1 − |ω|/ω₀) while it drives the joint the
    /// way it turns (`driving`), to 0 at the no-load speed ω₀. While it brakes, the continuous
    /// torque.
    pub fn torque_limit(&self, servo: Servo, omega: f64, driving: bool) -> f64 {
        let max = self.max_torque(servo);
        if driving {
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
