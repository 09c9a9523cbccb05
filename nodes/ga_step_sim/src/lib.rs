//! The built-in physics evaluator of `mobil_ga_step` (SPEC §8): a Nao-sized biped simulated on
//! [rapier3d](https://rapier.rs) whose ten leg servos follow an individual's piecewise-linear
//! trajectories for the step time T and then hold the standing pose to T_sim = T + 1 s, scored
//! by the time until it falls and, without a fall, the torso's forward distance
//! ([`Evaluation::from_outcome`]). ROS-free, and a crate of its own beside the GA library so
//! that the library's tests and its ROS-free check do not compile a physics engine.
//!
//! **The body** ([`BodyParams`], every figure with its source): a lumped torso (the whole
//! robot's 4.996 kg less both legs: head, arms and pelvis links held rigid, as the hip yaw-pitch,
//! the arms and the head are not evolved) and two legs of Nao's chain torso → hip roll → hip
//! pitch → knee → ankle pitch → ankle roll, with Nao's link lengths (hips 50 mm either side of
//! and 85 mm below the torso frame, thigh 100 mm, tibia 102.9 mm) and link masses. Thighs and
//! tibias are capsules, hip and ankle links small balls, the feet boxes in Coulomb contact with a
//! flat floor; the legs collide with each other, not with the links they are jointed to.
//!
//! **Two models** ([`mobil_ga_step::PhysicsModel`]). The default, [`BodyParams::webots`], is the
//! Nao of Webots, the source's simulator (docs/ga_step.md, "Calibration", gives every figure's
//! file and line): each servo is Webots' position control, the velocity P·(target − angle)
//! (P = 10) clamped to `maxVelocity` (6.40 / 4.16 rad/s) and reached by a hard velocity motor of
//! at most `maxTorque` (8 N·m pitch, 12 N·m roll, version V3.3); the sole is Webots' 147 × 89 mm
//! plate 46 mm below the ankle; the floor contact is nao_robocup.wbt's (μ 7, bounce 0.3) with
//! ODE's contact softness; 20 ms steps, Webots' own. [`BodyParams::dc_motor`] is the earlier
//! model from Aldebaran's motor datasheet: a PD servo (156 N·m/rad, 3 N·m·s/rad) limited to the
//! motor's continuous torque (1.61 / 2.47 N·m) and its torque–speed line, a 160 × 90 mm sole,
//! μ 0.8, 5 ms steps. Joint signs are Nao's (Aldebaran, "H25 – Joints": every joint frame is the
//! torso's at the zero pose, roll turns about x, pitch about y, right-handed): a negative hip
//! pitch swings the leg forward, a positive knee bends it back, a positive ankle roll lifts the
//! foot's left edge ([`PhysicsEvaluator::reach`]).
//!
//! **A fall**, tested after every step; the simulation ends there: the torso frame below
//! `fall_height` (0.20 m; it starts about 0.32 m up), its vertical axis tilted more than
//! `fall_tilt` (0.5 rad) from the vertical, or any body but the two feet touching the floor (a
//! knee, a shank, a thigh, the torso). A non-finite state counts as a fall at that time. Δx is
//! the torso frame's displacement along x (forward) from the start to the end or the fall. The
//! contact rule lags the others by one step: rapier finds contacts (its narrow phase) at the
//! start of a step, before it integrates, so after the step at t the torso's height and tilt
//! are those at t, the contacts those at t − 5 ms. An individual that is not valid for the
//! model (a knot not finite, outside its servo's limits, or an end off the standing pose) is
//! not simulated: a fall at t = 0 ([`FallCause::Invalid`]), fitness 0.
//!
//! **The solver**: rapier's soft-constraint solver, 4 iterations (substeps) of 2 projected
//! Gauss–Seidel passes a step. The Webots model solves friction in every pass
//! ([`BodyParams::friction_every_pass`]), as ODE solves it with the motors; the scores at 20 ms
//! agree with those at 10 ms and 8 iterations (docs/ga_step.md, "Convergence").
//!
//! **The robust score** ([`FitnessConfig::robust_check`], on by default): near the edge of a
//! fall the verdict does not converge with the setting, and selection finds such edges, so
//! [`Evaluator::evaluate`] simulates at the default and at the body's
//! [`check`](BodyParams::check) setting (the Webots model: 10 ms, 8 iterations; the DC-motor
//! model: [`CHECK_SETTING`]) and keeps the worse outcome ([`PhysicsEvaluator::robust_simulate`]).
//!
//! **Determinism**: each evaluation builds its own world and steps it on the calling thread;
//! rapier is built with `enhanced-determinism`, so the same individual gives the same
//! evaluation, bit for bit, on any thread and in any order.

#![warn(missing_docs)]

pub mod body;
pub mod motions;

/// The version of the physics model (body, solver, fall test, motors). A checkpoint records it,
/// and a run made under another is not resumed: the same individual scores differently. Raise it
/// with every change that moves a score.
///
/// 4: the Nao of Webots ([`BodyParams::webots`], [`mobil_ga_step::PhysicsModel::Webots`]) by
/// default; the earlier model stays selectable as [`BodyParams::dc_motor`], scoring as at 3.
///
/// 3: the robust score ([`FitnessConfig::robust_check`], on by default): each individual is
/// simulated at the default solver setting and at [`CHECK_SETTING`] and scores the worse, so an
/// individual is upright only if it stays up under both.
///
/// 2: Nao's continuous (nominal) motor torque instead of its stall torque; two Gauss–Seidel
/// passes per solver iteration, so that friction converges (the standing robot no longer
/// creeps, motions no longer travel by sliding); a floor contact of any body but the feet is a
/// fall. 1 was the first evaluator.
pub const PHYSICS_VERSION: u32 = 4;

pub use body::{BodyParams, LegMasses, ServoKind};

use body::{is_roll, leg_chain};
use mobil_ga_step::{Evaluation, Evaluator, FitnessConfig, GaError, Individual, NaoModel, Servo, KNOTS, SERVO_COUNT};
use rapier3d::prelude::*;

/// The damping (N·m·s/rad) of rapier's velocity motor standing in for ODE's joint motor, which
/// reaches the asked velocity within the step whenever its torque limit allows: a million makes
/// the motor's softness (1/(dt·damping), 5·10⁻⁵ at 20 ms) negligible beside the inverse inertia
/// of any link about its joint (above 10 (kg·m²)⁻¹), so the motor is as hard as ODE's.
const HARD_MOTOR_DAMPING: Real = 1.0e6;

/// Why an evaluator could not be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SimError {
    /// The robot or fitness configuration is invalid.
    #[error(transparent)]
    Config(#[from] GaError),
    /// A body figure is not positive and finite.
    #[error("body parameter {name} = {value} must be positive and finite")]
    BadBody {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A solver count is outside 1 … [`MAX_SOLVER_COUNT`].
    #[error("body parameter {name} = {value} must be within 1 … {MAX_SOLVER_COUNT}")]
    BadSolverCount {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: usize,
    },
    /// A joint's stall torque is below its continuous torque: the torque–speed line would cut
    /// the continuous torque at rest.
    #[error("{joints} stall torque {stall} N·m must be at least the continuous torque {continuous} N·m")]
    StallBelowContinuous {
        /// `pitch` or `roll`.
        joints: &'static str,
        /// The stall torque (N·m).
        stall: f64,
        /// The continuous torque (N·m).
        continuous: f64,
    },
    /// The time step is outside [`DT_RANGE`].
    #[error("body parameter dt = {value} s must be within {} … {} s", DT_RANGE.0, DT_RANGE.1)]
    BadTimeStep {
        /// The time step (s).
        value: f64,
    },
    /// Check settings asked for with [`FitnessConfig::distance_on_fall`]: a fall's distance can
    /// score it above the upright outcome, so "the worse of the two" would not be the lower
    /// score, and a check could raise an individual's fitness.
    #[error("robust_check needs distance_on_fall false: with a fall's distance counted, the worse of two outcomes is not the lower score (set robust_check: false)")]
    ChecksWithDistanceOnFall,
}

/// The largest solver iteration or Gauss–Seidel pass count accepted: 64 times the default, far
/// beyond any setting that changes an outcome (the solver table of
/// docs/experiments/ga-step-physics.md), and small enough that a step cannot take unbounded time.
pub const MAX_SOLVER_COUNT: usize = 256;

/// The time steps accepted (s): 10 µs, 1/500 of the default, takes 300 000 steps for one
/// 3 s evaluation; 50 ms, ten times the default, is a quarter of the legs' swing time
/// constant, beyond which a contact is resolved once per footfall. NaN or infinite is refused.
pub const DT_RANGE: (f64, f64) = (1e-5, 0.05);

/// A solver setting: the time step and the solver's iteration counts of a [`BodyParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSetting {
    /// Time step (s).
    pub dt: f64,
    /// Solver iterations per step (rapier's substeps).
    pub solver_iterations: usize,
    /// Projected Gauss–Seidel passes per solver iteration.
    pub pgs_iterations: usize,
}

impl SolverSetting {
    /// `body` with this setting's time step and iteration counts.
    pub fn apply(&self, body: &BodyParams) -> BodyParams {
        BodyParams {
            dt: self.dt,
            solver_iterations: self.solver_iterations,
            pgs_iterations: self.pgs_iterations,
            ..body.clone()
        }
    }
}

impl SolverSetting {
    /// The setting of `body`.
    pub fn of(body: &BodyParams) -> SolverSetting {
        SolverSetting {
            dt: body.dt,
            solver_iterations: body.solver_iterations,
            pgs_iterations: body.pgs_iterations,
        }
    }

    /// The convergence check's finer setting: half the step, twice the solver iterations, the
    /// same Gauss–Seidel passes.
    pub fn finer(&self) -> SolverSetting {
        SolverSetting {
            dt: self.dt / 2.0,
            solver_iterations: self.solver_iterations * 2,
            ..*self
        }
    }
}

/// How far two evaluators agree on a set of individuals ([`agreement`]): the convergence check
/// of a solver setting against a finer one.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Agreement {
    /// Individuals compared.
    pub individuals: usize,
    /// Those with the same verdict (fall or no fall) under both.
    pub same_verdict: usize,
    /// Those upright under both.
    pub upright_both: usize,
    /// The largest relative fitness difference, |f₁ − f₂| / max(f₁, f₂), among those upright
    /// under both (0 without any).
    pub worst_upright_gap: f64,
    /// The largest difference of Δx (m) among those upright under both.
    pub worst_upright_dx_gap: f64,
}

impl Agreement {
    /// The share of individuals with the same verdict (1 for none).
    pub fn verdict_share(&self) -> f64 {
        if self.individuals == 0 {
            1.0
        } else {
            self.same_verdict as f64 / self.individuals as f64
        }
    }
}

/// Scores every individual under `a` and under `b` (each with its own robust score, if any)
/// and counts where they agree.
pub fn agreement(a: &PhysicsEvaluator, b: &PhysicsEvaluator, individuals: &[Individual]) -> Agreement {
    let mut out = Agreement {
        individuals: individuals.len(),
        ..Agreement::default()
    };
    for ind in individuals {
        let (oa, ob) = (a.robust_simulate(ind), b.robust_simulate(ind));
        if oa.fell == ob.fell {
            out.same_verdict += 1;
        }
        if !oa.fell && !ob.fell {
            out.upright_both += 1;
            let (fa, fb) = (a.score(&oa).fitness, b.score(&ob).fitness);
            out.worst_upright_gap = out.worst_upright_gap.max((fa - fb).abs() / fa.max(fb));
            out.worst_upright_dx_gap = out
                .worst_upright_dx_gap
                .max((oa.forward_distance - ob.forward_distance).abs());
        }
    }
    out
}

/// The second setting of the robust score ([`FitnessConfig::robust_check`]): 4 ms steps, 4
/// iterations of 2 passes, a step that is no multiple of the default's, so no step's numbers
/// are shared. Compared (docs/experiments/ga-step-physics.md, "The second setting of the robust
/// score") with 5 ms/8/2, 2.5 ms/8/2 and μ 0.7 against the reference 1.25 ms/16/4, on the 100
/// individuals of a physics-2 run upright at the default and 53 other motions: each of them
/// turned all 100 into falls, as the reference does, and each called the same single motion a
/// fall that the reference calls upright; 4 ms/4/2 costs the least of the solver settings: 5/4
/// of the default's steps (its time beside the default's: docs/performance.md).
pub const CHECK_SETTING: SolverSetting = SolverSetting {
    dt: 0.004,
    solver_iterations: 4,
    pgs_iterations: 2,
};

/// What ended a simulation early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FallCause {
    /// The torso frame sank below `fall_height`.
    Height,
    /// The torso's vertical axis tilted beyond `fall_tilt`.
    Tilt,
    /// A body other than a foot touched the floor (a knee, a shin, a thigh, the torso, a hip or
    /// ankle link).
    Contact,
    /// The state stopped being finite.
    NonFinite,
    /// The individual is not one of the model's, so it was not simulated: the knot `knot` of
    /// `servo` is not finite, lies outside the servo's limits, or (first or last) is not the
    /// standing pose ([`Individual::validate`] says which). The outcome is a fall at t = 0.
    Invalid {
        /// The servo with the bad knot.
        servo: Servo,
        /// The knot's index (0 … 20).
        knot: usize,
    },
}

/// What one simulated step did, in more detail than an [`Evaluation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOutcome {
    /// Whether the robot fell.
    pub fell: bool,
    /// Why it fell, if it did.
    pub cause: Option<FallCause>,
    /// Time of the fall (s), or the simulated time T_sim without one.
    pub t_end: f64,
    /// Torso frame's displacement along x (forward, m) at the end or the fall.
    pub forward_distance: f64,
    /// Torso frame's displacement along y (left, m) at the end or the fall.
    pub lateral_distance: f64,
    /// Torso frame's height at the start (m).
    pub start_height: f64,
    /// Torso frame's height at the end or the fall (m).
    pub end_height: f64,
    /// Largest tilt of the torso's vertical axis seen (rad).
    pub max_tilt: f64,
    /// Simulation steps made.
    pub steps: u64,
}

/// The torso frame's state at one instant of a simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorsoState {
    /// Time from the start (s).
    pub t: f64,
    /// Position (m), x forward, y left, z up.
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// See `x`.
    pub z: f64,
    /// Tilt of its vertical axis from the vertical (rad).
    pub tilt: f64,
}

/// One foot's contact with the floor after a simulation step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FootContact {
    /// Normal force (N) the floor pushed the sole with during the step (its contact impulse
    /// over the time step); 0 off the floor.
    pub normal_force: f64,
    /// Friction force (N) the floor pushed the sole with during the step: the length of the sum
    /// of the contact points' friction impulses over the time step. Coulomb's law bounds it by
    /// μ times the normal force; a sole slides only where it reaches that bound.
    pub friction_force: f64,
    /// Horizontal speed (m/s) of the slowest of nine points of the sole's bottom face (its
    /// corners, edge midpoints and centre). A sole resting or rolling over an edge has a point
    /// at rest, so this is the sliding speed of a loaded foot (a lower bound of it).
    pub slip_speed: f64,
    /// Height (m) above the floor of the lowest corner of the sole's bottom face: about 0 for a
    /// foot on the floor (flat or tipped over an edge), its clearance for a lifted one.
    pub sole_height: f64,
    /// Position along x (forward, m) of the centre of the sole's bottom face.
    pub sole_x: f64,
    /// Position along y (left, m) of the centre of the sole's bottom face.
    pub sole_y: f64,
}

/// The normal force (N) above which a foot counts as loaded (carrying weight): a tenth of the
/// robot's weight (4.996 kg · 9.81 = 49 N).
pub const LOADED_FORCE: f64 = 5.0;

/// What one foot did over a simulation ([`FeetReport`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FootReport {
    /// The highest [`sole_height`](FootContact::sole_height) seen (m): how far the foot was
    /// lifted off the floor.
    pub peak_height: f64,
    /// The sole centre's displacement along x (m) from the start to the end or the fall: a
    /// foot put down ahead has a positive one.
    pub forward: f64,
    /// Time (s) the foot was loaded (normal force above [`LOADED_FORCE`]).
    pub loaded_time: f64,
    /// Distance (m) the sole slid while loaded: its [`slip_speed`](FootContact::slip_speed)
    /// integrated over the loaded steps.
    pub slip_loaded: f64,
}

/// What the feet did over a simulation: whether a step was a step (a foot lifted and put down
/// ahead) or the torso got there by sliding or hopping. Worked out from the [`FootContact`]s
/// after every step by a [`FeetTracker`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FeetReport {
    /// Right foot, left foot.
    pub feet: [FootReport; 2],
    /// The longest time (s) both feet were unloaded at once (flight: the robot hopped).
    pub longest_flight: f64,
    /// The total time (s) both feet were unloaded.
    pub flight_time: f64,
}

/// Sums the feet's contacts, step by step, into a [`FeetReport`].
#[derive(Debug, Clone)]
pub struct FeetTracker {
    dt: f64,
    start_x: [f64; 2],
    last_x: [f64; 2],
    flight_run: f64,
    report: FeetReport,
}

impl FeetTracker {
    /// A tracker for steps of `dt` seconds, the feet's contacts at the start being `start`
    /// (their soles' positions).
    pub fn new(dt: f64, start: &[FootContact; 2]) -> FeetTracker {
        let start_x = [start[0].sole_x, start[1].sole_x];
        let mut report = FeetReport::default();
        for (r, c) in report.feet.iter_mut().zip(start) {
            r.peak_height = c.sole_height;
        }
        FeetTracker {
            dt,
            start_x,
            last_x: start_x,
            flight_run: 0.0,
            report,
        }
    }

    /// Adds the feet's contacts after one step.
    pub fn observe(&mut self, feet: &[FootContact; 2]) {
        for (k, (r, c)) in self.report.feet.iter_mut().zip(feet).enumerate() {
            r.peak_height = r.peak_height.max(c.sole_height);
            if c.normal_force > LOADED_FORCE {
                r.loaded_time += self.dt;
                r.slip_loaded += c.slip_speed * self.dt;
            }
            self.last_x[k] = c.sole_x;
        }
        if feet.iter().all(|c| c.normal_force <= LOADED_FORCE) {
            self.flight_run += self.dt;
            self.report.flight_time += self.dt;
            self.report.longest_flight = self.report.longest_flight.max(self.flight_run);
        } else {
            self.flight_run = 0.0;
        }
    }

    /// The report so far.
    pub fn report(&self) -> FeetReport {
        let mut r = self.report;
        for (k, f) in r.feet.iter_mut().enumerate() {
            f.forward = self.last_x[k] - self.start_x[k];
        }
        r
    }
}

/// The physics evaluator: a fresh simulation per individual.
#[derive(Debug, Clone)]
pub struct PhysicsEvaluator {
    model: NaoModel,
    fitness: FitnessConfig,
    body: BodyParams,
    /// The bodies of the check settings (empty without the robust score).
    checks: Vec<BodyParams>,
}

impl PhysicsEvaluator {
    /// An evaluator of `model`'s step scored by `fitness`, with the body of its physics model
    /// ([`FitnessConfig::physics`]).
    pub fn new(model: NaoModel, fitness: FitnessConfig) -> Result<PhysicsEvaluator, SimError> {
        let body = BodyParams::named(fitness.physics);
        PhysicsEvaluator::with_body(model, fitness, body)
    }

    /// An evaluator with a body of one's own ([`FitnessConfig::physics`] is not read).
    /// With [`FitnessConfig::robust_check`] it scores under `body` and under `body` at its
    /// [`check`](BodyParams::check) setting; without, under `body` alone.
    pub fn with_body(model: NaoModel, fitness: FitnessConfig, body: BodyParams) -> Result<PhysicsEvaluator, SimError> {
        let checks = if fitness.robust_check {
            vec![body.check]
        } else {
            Vec::new()
        };
        PhysicsEvaluator::with_checks(model, fitness, body, &checks)
    }

    /// An evaluator that scores under `body` and under `body` at each of `checks` and keeps
    /// the worst score ([`robust_simulate`](Self::robust_simulate)), whatever
    /// [`FitnessConfig::robust_check`] says; with no checks, under `body` alone. Checks with
    /// [`FitnessConfig::distance_on_fall`] are refused ([`SimError::ChecksWithDistanceOnFall`]).
    pub fn with_checks(
        model: NaoModel,
        fitness: FitnessConfig,
        body: BodyParams,
        checks: &[SolverSetting],
    ) -> Result<PhysicsEvaluator, SimError> {
        model.validate()?;
        fitness.validate()?;
        if fitness.distance_on_fall && !checks.is_empty() {
            return Err(SimError::ChecksWithDistanceOnFall);
        }
        Self::validate_body(&body)?;
        let checks: Vec<BodyParams> = checks.iter().map(|c| c.apply(&body)).collect();
        for c in &checks {
            Self::validate_body(c)?;
        }
        Ok(PhysicsEvaluator {
            model,
            fitness,
            body,
            checks,
        })
    }

    fn validate_body(body: &BodyParams) -> Result<(), SimError> {
        let b = body;
        for (name, value) in [
            ("hip_offset_y", b.hip_offset_y),
            ("hip_offset_z", b.hip_offset_z),
            ("thigh_length", b.thigh_length),
            ("tibia_length", b.tibia_length),
            ("foot_height", b.foot_height),
            ("foot_length", b.foot_length),
            ("foot_width", b.foot_width),
            ("sole_thickness", b.sole_thickness),
            ("torso_mass", b.torso_mass),
            ("limb_radius", b.limb_radius),
            ("pitch_max_torque", b.pitch_max_torque),
            ("roll_max_torque", b.roll_max_torque),
            ("pitch_max_speed", b.pitch_max_speed),
            ("roll_max_speed", b.roll_max_speed),
            ("friction", b.friction),
            ("dt", b.dt),
        ]
        .into_iter()
        .chain(match b.servo {
            ServoKind::Webots => vec![("p_gain", b.p_gain)],
            ServoKind::DcMotor => vec![
                ("pitch_stall_torque", b.pitch_stall_torque),
                ("roll_stall_torque", b.roll_stall_torque),
                ("servo_stiffness", b.servo_stiffness),
                ("servo_damping", b.servo_damping),
            ],
        })
        .chain(
            b.contact_softness
                .map(|[f, z]| [("contact natural frequency", f), ("contact damping ratio", z)])
                .into_iter()
                .flatten(),
        ) {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::BadBody { name, value });
            }
        }
        for (name, value, hi) in [
            ("foot_outward", b.foot_outward, f64::MAX),
            ("restitution", b.restitution, 1.0),
        ] {
            if !(value.is_finite() && (0.0..=hi).contains(&value)) {
                return Err(SimError::BadBody { name, value });
            }
        }
        if !(DT_RANGE.0..=DT_RANGE.1).contains(&b.dt) {
            return Err(SimError::BadTimeStep { value: b.dt });
        }
        for (name, value) in [
            ("solver_iterations", b.solver_iterations),
            ("pgs_iterations", b.pgs_iterations),
        ] {
            if !(1..=MAX_SOLVER_COUNT).contains(&value) {
                return Err(SimError::BadSolverCount { name, value });
            }
        }
        for (joints, stall, continuous) in [
            ("pitch", b.pitch_stall_torque, b.pitch_max_torque),
            ("roll", b.roll_stall_torque, b.roll_max_torque),
        ] {
            if b.servo == ServoKind::DcMotor && stall < continuous {
                return Err(SimError::StallBelowContinuous {
                    joints,
                    stall,
                    continuous,
                });
            }
        }
        Ok(())
    }

    /// The check settings' bodies, in the order they are simulated (empty without the robust
    /// score).
    pub fn check_bodies(&self) -> &[BodyParams] {
        &self.checks
    }

    /// The robust score's outcome: the individual simulated under the body's setting and each
    /// check setting, the worst outcome kept. A fall is worse than no fall; of two falls, the
    /// earlier (a tie keeps the earlier setting's); of two upright outcomes, the smaller Δx (a
    /// tie keeps the earlier setting's). That is the lower fitness, a fall's distance not
    /// counting (checks are refused with [`FitnessConfig::distance_on_fall`]). Without checks,
    /// [`simulate`](Self::simulate).
    ///
    /// A check is cut short where it cannot change the result, exactly: once the worst so far
    /// is a fall at t, a check only matters if it falls
    /// before t, and a simulation's first steps do not depend on how long it runs, so the check
    /// is simulated to t alone (its steps up to t: `round(t / dt)` ≥ `floor(t / dt)` of them). A
    /// fall at t = 0 (an invalid individual) needs no check at all.
    pub fn robust_simulate(&self, individual: &Individual) -> SimOutcome {
        let duration = self.fitness.sim_time(self.model.step_time);
        let mut worst = self.simulate_for(individual, duration);
        for body in &self.checks {
            let Some(d) = Self::check_duration(&worst, duration) else {
                break;
            };
            let o = self.run(body, individual, d, false, &mut |_| {}, &mut |_, _| {});
            if Self::worse(&o, &worst) {
                worst = o;
            }
        }
        worst
    }

    /// How long a check must be simulated when the worst outcome so far is `worst` and an
    /// evaluation lasts `duration` (the cut of [`robust_simulate`](Self::robust_simulate)):
    /// in full after an upright outcome, to the fall's time after a fall, not at all after a
    /// fall at t = 0.
    pub fn check_duration(worst: &SimOutcome, duration: f64) -> Option<f64> {
        match (worst.fell, worst.t_end) {
            (false, _) => Some(duration),
            (true, t) if t <= 0.0 => None,
            (true, t) => Some(t),
        }
    }

    /// Whether `a` scores strictly worse than `b` ([`robust_simulate`](Self::robust_simulate)).
    fn worse(a: &SimOutcome, b: &SimOutcome) -> bool {
        match (a.fell, b.fell) {
            (true, false) => true,
            (false, true) => false,
            (false, false) => a.forward_distance < b.forward_distance,
            (true, true) => a.t_end < b.t_end,
        }
    }

    /// The robot model (standing pose, T).
    pub fn model(&self) -> &NaoModel {
        &self.model
    }

    /// The body's figures.
    pub fn body(&self) -> &BodyParams {
        &self.body
    }

    /// Simulates the individual's step for T, then the standing pose held to T_sim, or until a
    /// fall, under the body's setting alone (not the robust score: see
    /// [`robust_simulate`](Self::robust_simulate)).
    pub fn simulate(&self, individual: &Individual) -> SimOutcome {
        self.simulate_for(individual, self.fitness.sim_time(self.model.step_time))
    }

    /// Like [`simulate`](Self::simulate) for `duration` seconds of simulated time.
    pub fn simulate_for(&self, individual: &Individual, duration: f64) -> SimOutcome {
        self.simulate_observed(individual, duration, &mut |_| {})
    }

    /// Like [`simulate_for`](Self::simulate_for), calling `observe` with the torso's state after
    /// every step (to trace or plot a motion).
    pub fn simulate_observed(
        &self,
        individual: &Individual,
        duration: f64,
        observe: &mut dyn FnMut(&TorsoState),
    ) -> SimOutcome {
        self.run(&self.body, individual, duration, false, &mut |_| {}, &mut |s, _| {
            observe(s)
        })
    }

    /// Like [`simulate_observed`](Self::simulate_observed), also passing each foot's contact
    /// with the floor (right, left) after every step: to check that a loaded sole grips.
    pub fn simulate_with_feet(
        &self,
        individual: &Individual,
        duration: f64,
        observe: &mut dyn FnMut(&TorsoState, &[FootContact; 2]),
    ) -> SimOutcome {
        self.run(&self.body, individual, duration, true, &mut |_| {}, observe)
    }

    /// Like [`simulate_for`](Self::simulate_for), also reporting what the feet did: each one's
    /// peak height, forward displacement and slip while loaded, and the robot's flight. The
    /// outcome is the same, bit for bit, as without the report.
    pub fn simulate_feet_report(&self, individual: &Individual, duration: f64) -> (SimOutcome, FeetReport) {
        let tracker = std::cell::RefCell::new(None);
        let o = self.run(
            &self.body,
            individual,
            duration,
            true,
            &mut |start| *tracker.borrow_mut() = Some(FeetTracker::new(self.body.dt, start)),
            &mut |_, feet| {
                if let Some(t) = tracker.borrow_mut().as_mut() {
                    t.observe(feet);
                }
            },
        );
        let report = tracker.borrow().as_ref().map(FeetTracker::report).unwrap_or_default();
        (o, report)
    }

    /// The first knot that makes `individual` invalid for the model (not finite, outside its
    /// servo's limits, or an end off the standing pose), as [`Individual::validate`] judges.
    pub fn first_bad_knot(&self, individual: &Individual) -> Option<(Servo, usize)> {
        let last = KNOTS - 1;
        Servo::ALL.into_iter().find_map(|s| {
            let (lo, hi) = s.limits();
            let stand = self.model.standing_pose[s.index()];
            individual.knots[s.index()]
                .iter()
                .enumerate()
                .find(|&(k, &q)| !(q.is_finite() && (lo..=hi).contains(&q)) || ((k == 0 || k == last) && q != stand))
                .map(|(k, _)| (s, k))
        })
    }

    /// The simulation loop; the feet's contacts are worked out only `with_feet` (the
    /// evaluation's hot path does without them) and are all zero otherwise; `start` receives
    /// them before the first step; `body` is the evaluator's or a check's. An invalid individual is not simulated: a fall at t = 0
    /// ([`FallCause::Invalid`]; heights and tilt 0).
    fn run(
        &self,
        body: &BodyParams,
        individual: &Individual,
        duration: f64,
        with_feet: bool,
        start_feet: &mut dyn FnMut(&[FootContact; 2]),
        observe: &mut dyn FnMut(&TorsoState, &[FootContact; 2]),
    ) -> SimOutcome {
        if let Some((servo, knot)) = self.first_bad_knot(individual) {
            return SimOutcome {
                fell: true,
                cause: Some(FallCause::Invalid { servo, knot }),
                t_end: 0.0,
                forward_distance: 0.0,
                lateral_distance: 0.0,
                start_height: 0.0,
                end_height: 0.0,
                max_tilt: 0.0,
                steps: 0,
            };
        }
        let mut robot = Robot::build(body, &self.model.standing_pose);
        let dt = body.dt;
        let steps = (duration / dt).round().max(0.0) as u64;
        let start = robot.torso_pose();
        let mut out = SimOutcome {
            fell: false,
            cause: None,
            t_end: duration,
            forward_distance: 0.0,
            lateral_distance: 0.0,
            start_height: start.z,
            end_height: start.z,
            max_tilt: start.tilt,
            steps: 0,
        };
        if with_feet {
            start_feet(&robot.feet(body));
        }
        let mut command = self.model.standing_pose;
        for n in 1..=steps {
            let t = n as f64 * dt;
            let wanted = individual.angles_at(t, self.model.step_time);
            for s in Servo::ALL {
                let i = s.index();
                command[i] = body.next_target(s, command[i], wanted[i]);
            }
            robot.command(&command, body);
            robot.world.step();
            let pose = robot.torso_pose();
            let feet = if with_feet {
                robot.feet(body)
            } else {
                [FootContact::default(); 2]
            };
            observe(
                &TorsoState {
                    t,
                    x: pose.x,
                    y: pose.y,
                    z: pose.z,
                    tilt: pose.tilt,
                },
                &feet,
            );
            out.steps = n;
            if !pose.is_finite() {
                out.fell = true;
                out.cause = Some(FallCause::NonFinite);
                out.t_end = t;
                break;
            }
            out.forward_distance = pose.x - start.x;
            out.lateral_distance = pose.y - start.y;
            out.end_height = pose.z;
            out.max_tilt = out.max_tilt.max(pose.tilt);
            let cause = if pose.z < self.fitness.fall_height {
                Some(FallCause::Height)
            } else if pose.tilt > self.fitness.fall_tilt {
                Some(FallCause::Tilt)
            } else if robot.touches_floor_off_the_feet() {
                Some(FallCause::Contact)
            } else {
                None
            };
            if cause.is_some() {
                out.fell = true;
                out.cause = cause;
                out.t_end = t;
                break;
            }
        }
        out
    }
}

/// Where a held leg's points end up, relative to the torso frame (m; x forward, y left, z up),
/// right leg first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegPoints {
    /// The knee joints (the tibias' origins).
    pub knees: [[f64; 3]; 2],
    /// The ankle joints (the feet's origins).
    pub ankles: [[f64; 3]; 2],
    /// The centres of the soles' bottom faces.
    pub soles: [[f64; 3]; 2],
    /// Each sole's normal (the foot's −z axis turned into the torso's frame): (0, 0, −1) for a
    /// flat foot.
    pub sole_normals: [[f64; 3]; 2],
}

impl PhysicsEvaluator {
    /// Builds the robot standing, holds its torso still in the air without gravity and drives
    /// its servos to `pose` for `seconds` through the same motors as a step: the kinematics and
    /// the joints' signs as the simulation has them, to check against Nao's convention.
    pub fn reach(&self, pose: &[f64; SERVO_COUNT], seconds: f64) -> LegPoints {
        let b = &self.body;
        let mut robot = Robot::build(b, &self.model.standing_pose);
        robot.world.gravity = v(0.0, 0.0, 0.0);
        // Out of the floor's reach: the floor is moved 1 m down, the torso fixed.
        if let Some(co) = robot.world.colliders.get_mut(robot.floor) {
            co.set_translation(v(0.0, 0.0, -1.5));
        }
        if let Some(rb) = robot.world.bodies.get_mut(robot.torso) {
            rb.set_body_type(RigidBodyType::Fixed, true);
        }
        let steps = (seconds / b.dt).round().max(1.0) as u64;
        let mut command = self.model.standing_pose;
        for _ in 0..steps {
            for s in Servo::ALL {
                let i = s.index();
                command[i] = b.next_target(s, command[i], pose[i]);
            }
            robot.command(&command, b);
            robot.world.step();
        }
        let torso = *robot.world.bodies[robot.torso].position();
        let local = |p: Vector| -> [f64; 3] {
            let q = torso.inverse_transform_point(p);
            [q.x as f64, q.y as f64, q.z as f64]
        };
        let mut out = LegPoints {
            knees: [[0.0; 3]; 2],
            ankles: [[0.0; 3]; 2],
            soles: [[0.0; 3]; 2],
            sole_normals: [[0.0; 3]; 2],
        };
        for (k, &(foot, sole)) in robot.feet.iter().enumerate() {
            out.ankles[k] = local(robot.world.bodies[foot].translation());
            let co = &robot.world.colliders[sole];
            out.soles[k] = local(co.position().transform_point(v(0.0, 0.0, -b.sole_thickness / 2.0)));
            let n = torso.rotation.inverse() * (co.position().rotation * v(0.0, 0.0, -1.0));
            out.sole_normals[k] = [n.x as f64, n.y as f64, n.z as f64];
        }
        for (k, &tibia) in robot.tibias.iter().enumerate() {
            out.knees[k] = local(robot.world.bodies[tibia].translation());
        }
        out
    }
}

impl PhysicsEvaluator {
    /// The evaluation of an outcome under this evaluator's fitness.
    pub fn score(&self, o: &SimOutcome) -> Evaluation {
        Evaluation::from_outcome(&self.fitness, self.model.step_time, o.fell, o.t_end, o.forward_distance)
    }
}

impl Evaluator for PhysicsEvaluator {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        self.score(&self.robust_simulate(individual))
    }
}

/// The torso frame's position and tilt.
#[derive(Debug, Clone, Copy)]
struct TorsoPose {
    x: f64,
    y: f64,
    z: f64,
    tilt: f64,
}

impl TorsoPose {
    fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite() && self.tilt.is_finite()
    }
}

/// A built world: the floor, the body and its ten motors.
struct Robot {
    world: PhysicsWorld,
    torso: RigidBodyHandle,
    /// Per servo (genome order): its joint, its standing angle, stiffness, damping, torque.
    motors: Vec<(MultibodyJointHandle, Servo, f64)>,
    /// The floor's collider.
    floor: ColliderHandle,
    /// Each foot's body and sole collider (right, left).
    feet: Vec<(RigidBodyHandle, ColliderHandle)>,
    /// Each tibia's body (right, left), its origin at the knee.
    tibias: Vec<RigidBodyHandle>,
    stiffness: Real,
    damping: Real,
}

fn v(x: f64, y: f64, z: f64) -> Vector {
    Vector::new(x as Real, y as Real, z as Real)
}

impl Robot {
    /// The robot in the standing pose `stand`, its lowest point on the floor (z = 0): a sole
    /// corner, or a thigh's or shank's capsule in a pose that kneels; the torso frame above the
    /// origin. Every body frame is parallel to the world's in the standing
    /// pose, so a joint's coordinate is its angle less the standing angle.
    fn build(b: &BodyParams, stand: &[f64; SERVO_COUNT]) -> Robot {
        let mut world = PhysicsWorld::new();
        world.gravity = v(0.0, 0.0, -9.81);
        world.integration_parameters.dt = b.dt as Real;
        world.integration_parameters.num_solver_iterations = b.solver_iterations.max(1);
        world.integration_parameters.num_internal_pgs_iterations = b.pgs_iterations.max(1);
        world.integration_parameters.friction_in_bias_pass = b.friction_every_pass;
        if let Some([f, z]) = b.contact_softness {
            let soft = SpringCoefficients::new(f as Real, z as Real);
            world.integration_parameters.contact_softness = soft;
            world.integration_parameters.static_contact_softness = soft;
        }

        // Forward kinematics of both legs in the standing pose, relative to the torso frame.
        struct LegGeom {
            origins: [Vector; 5],     // hip, thigh (= hip), tibia (knee), ankle, foot (= ankle)
            axes: [Vector; 5],        // joint axes in the world (= in both bodies' frames)
            rotations: [Rotation; 5], // each child link's rotation in the standing pose
            lowest_z: f64,
        }
        let leg = |left: bool| -> LegGeom {
            let side = if left { 1.0 } else { -1.0 };
            let chain = leg_chain(left);
            let hip = v(0.0, side * b.hip_offset_y, -b.hip_offset_z);
            let mut rot = Rotation::IDENTITY;
            let mut axes = [Vector::ZERO; 5];
            let mut rotations = [Rotation::IDENTITY; 5];
            for (k, s) in chain.iter().enumerate() {
                let local = if is_roll(*s) { Vector::X } else { Vector::Y };
                axes[k] = rot * local;
                rot *= Rotation::from_axis_angle(local, stand[s.index()] as Real);
                rotations[k] = rot;
            }
            let knee = hip + rotations[1] * v(0.0, 0.0, -b.thigh_length);
            let ankle = knee + rotations[2] * v(0.0, 0.0, -b.tibia_length);
            let foot_rot = rotations[4];
            // The capsules' lowest points: each ends in a ball of the limb radius whose centre
            // lies one radius inside the link's ends.
            let r = b.limb_radius;
            let mut lowest = f64::INFINITY;
            for (start, rot, length) in [
                (hip, rotations[1], b.thigh_length),
                (knee, rotations[2], b.tibia_length),
            ] {
                for along in [r, length - r] {
                    lowest = lowest.min((start + rot * v(0.0, 0.0, -along)).z as f64 - r);
                }
            }
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let c = ankle
                    + foot_rot
                        * v(
                            b.foot_forward + sx * b.foot_length / 2.0,
                            -side * b.foot_outward + sy * b.foot_width / 2.0,
                            -b.foot_height,
                        );
                lowest = lowest.min(c.z as f64);
            }
            LegGeom {
                origins: [hip, hip, knee, ankle, ankle],
                axes,
                rotations,
                lowest_z: lowest,
            }
        };
        let legs = [leg(false), leg(true)];
        let height = -legs[0].lowest_z.min(legs[1].lowest_z);
        let base = v(0.0, 0.0, height);

        let floor = world.insert_collider(
            ColliderBuilder::cuboid(50.0, 50.0, 0.5)
                .translation(v(0.0, 0.0, -0.5))
                .friction(b.friction as Real)
                .restitution(b.restitution as Real),
            None,
        );

        let dynamic = |at: Vector| RigidBodyBuilder::dynamic().translation(at).can_sleep(false);
        let torso = world.insert_body(dynamic(base));
        let [dx, dy, dz] = b.torso_box;
        let box_inertia = |m: f64, a: f64, bb: f64, c: f64| {
            v(
                m * (bb * bb + c * c) / 12.0,
                m * (a * a + c * c) / 12.0,
                m * (a * a + bb * bb) / 12.0,
            )
        };
        // The collision box sits above the thighs (its bottom 40 mm below the torso frame,
        // 45 mm above the hips); the mass acts at the lumped centre of mass.
        world.insert_collider(
            ColliderBuilder::cuboid((dx / 2.0) as Real, (dy / 2.0) as Real, (dz / 2.0) as Real)
                .translation(v(0.0, 0.0, dz / 2.0 - 0.04))
                .mass_properties(MassProperties::new(
                    v(0.0, 0.0, b.torso_com_z - (dz / 2.0 - 0.04)),
                    b.torso_mass as Real,
                    box_inertia(b.torso_mass, dx, dy, dz),
                )),
            Some(torso),
        );

        let mut motors = Vec::with_capacity(SERVO_COUNT);
        let mut feet = Vec::with_capacity(2);
        let mut tibias = Vec::with_capacity(2);
        for (g, left) in legs.iter().zip([false, true]) {
            let chain = leg_chain(left);
            let masses = [b.leg.hip, b.leg.thigh, b.leg.tibia, b.leg.ankle, b.leg.foot];
            let mut parent = torso;
            let mut parent_origin = Vector::ZERO;
            for k in 0..5 {
                let origin = g.origins[k];
                let link = world.insert_body(dynamic(base + origin));
                let r = b.limb_radius as Real;
                let collider = match k {
                    1 | 2 => {
                        let length = if k == 1 { b.thigh_length } else { b.tibia_length };
                        let rot = g.rotations[k];
                        ColliderBuilder::capsule_z((length / 2.0) as Real - r, r)
                            .position(Pose::from_parts(rot * v(0.0, 0.0, -length / 2.0), rot))
                    }
                    4 => {
                        let rot = g.rotations[4];
                        let outward = if left { b.foot_outward } else { -b.foot_outward };
                        let centre = rot * v(b.foot_forward, outward, -b.foot_height + b.sole_thickness / 2.0);
                        ColliderBuilder::cuboid(
                            (b.foot_length / 2.0) as Real,
                            (b.foot_width / 2.0) as Real,
                            (b.sole_thickness / 2.0) as Real,
                        )
                        .position(Pose::from_parts(centre, rot))
                        .friction(b.friction as Real)
                        .restitution(b.restitution as Real)
                    }
                    _ => ColliderBuilder::ball(0.02),
                };
                let handle = world.insert_collider(collider.mass(masses[k] as Real), Some(link));
                if k == 4 {
                    feet.push((link, handle));
                }
                if k == 2 {
                    tibias.push(link);
                }
                let s = chain[k];
                let (lo, hi) = s.limits();
                let q0 = stand[s.index()];
                let joint = RevoluteJointBuilder::new(g.axes[k])
                    .local_anchor1(origin - parent_origin)
                    .local_anchor2(Vector::ZERO)
                    .contacts_enabled(false)
                    .limits([(lo - q0) as Real, (hi - q0) as Real])
                    .motor_model(MotorModel::ForceBased);
                let joint = match b.servo {
                    ServoKind::Webots => joint.motor_velocity(0.0, HARD_MOTOR_DAMPING),
                    ServoKind::DcMotor => joint.motor_position(0.0, b.servo_stiffness as Real, b.servo_damping as Real),
                }
                .motor_max_force(b.max_torque(s) as Real);
                // The chain is a tree hanging from the torso: insertion cannot fail.
                if let Some(h) = world.insert_multibody_joint(parent, link, joint) {
                    motors.push((h, s, q0));
                }
                parent = link;
                parent_origin = origin;
            }
        }
        Robot {
            world,
            torso,
            motors,
            floor,
            feet,
            tibias,
            stiffness: b.servo_stiffness as Real,
            damping: b.servo_damping as Real,
        }
    }

    /// Sets every servo's target angle (rad, Nao's convention) and its torque limit for this
    /// step ([`BodyParams::torque_limit`]).
    fn command(&mut self, angles: &[f64; SERVO_COUNT], body: &BodyParams) {
        for &(h, s, q0) in &self.motors {
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(h) {
                let Some(link) = mb.link(id) else { continue };
                let omega = mb.joint_velocity(link).get(0).copied().unwrap_or(0.0) as f64;
                let q = link.joint.coords()[3] as f64;
                let target = angles[s.index()] - q0;
                let limit = body.torque_limit(s, omega, (target - q) * omega > 0.0);
                let Some(link) = mb.link_mut(id) else { continue };
                let data = &mut link.joint.data;
                match body.servo {
                    ServoKind::Webots => {
                        let velocity = body.webots_velocity(s, target, q);
                        data.set_motor_velocity(JointAxis::AngX, velocity as Real, HARD_MOTOR_DAMPING)
                    }
                    ServoKind::DcMotor => {
                        data.set_motor_position(JointAxis::AngX, target as Real, self.stiffness, self.damping)
                    }
                }
                .set_motor_max_force(JointAxis::AngX, limit as Real);
            }
        }
    }

    /// Whether the floor touches any collider but the two feet after the last step: a contact
    /// point closer than 1 mm or one the floor pushed. Speculative contacts (rapier keeps points
    /// up to 2 cm apart, to catch fast bodies) are not touches. The manifolds are the narrow
    /// phase's of the last step, which runs before the step integrates: they describe the
    /// bodies one step (`dt`) before the torso pose the other fall rules read.
    fn touches_floor_off_the_feet(&self) -> bool {
        self.world.contact_pairs_with(self.floor).any(|pair| {
            let other = if pair.collider1 == self.floor {
                pair.collider2
            } else {
                pair.collider1
            };
            !self.feet.iter().any(|&(_, sole)| sole == other)
                && pair
                    .solver_manifolds()
                    .iter()
                    .any(|m| m.points.iter().any(|p| p.dist < 1.0e-3 || p.data.impulse > 0.0))
        })
    }

    /// Each foot's contact with the floor (right, left) after the last step.
    fn feet(&self, b: &BodyParams) -> [FootContact; 2] {
        let mut out = [FootContact::default(); 2];
        for (c, &(body, sole)) in out.iter_mut().zip(&self.feet) {
            if let Some(PairContacts::Rigid(r)) = self.world.contact_pair(self.floor, sole).map(|p| &p.contacts) {
                let (mut normal, mut friction) = (0.0, 0.0);
                for m in r.solver_manifolds() {
                    for p in &m.points {
                        normal += p.data.impulse as f64;
                        friction += p.data.tangent_impulse.norm() as f64;
                    }
                }
                c.normal_force = normal / b.dt;
                c.friction_force = friction / b.dt;
            }
            let (Some(rb), Some(co)) = (self.world.bodies.get(body), self.world.colliders.get(sole)) else {
                continue;
            };
            let (hl, hw, ht) = (b.foot_length / 2.0, b.foot_width / 2.0, b.sole_thickness / 2.0);
            let mut slowest = f64::INFINITY;
            let mut lowest = f64::INFINITY;
            for sx in [-1.0, 0.0, 1.0] {
                for sy in [-1.0, 0.0, 1.0] {
                    let p = co.position().transform_point(v(sx * hl, sy * hw, -ht));
                    let vel = rb.velocity_at_point(p);
                    slowest = slowest.min((vel.x as f64).hypot(vel.y as f64));
                    // The floor's top face is z = 0; a flat face's lowest point is a corner.
                    lowest = lowest.min(p.z as f64);
                    if sx == 0.0 && sy == 0.0 {
                        c.sole_x = p.x as f64;
                        c.sole_y = p.y as f64;
                    }
                }
            }
            c.slip_speed = slowest;
            c.sole_height = lowest;
        }
        out
    }

    fn torso_pose(&self) -> TorsoPose {
        let rb = &self.world.bodies[self.torso];
        let p = rb.translation();
        let up = *rb.rotation() * Vector::Z;
        TorsoPose {
            x: p.x as f64,
            y: p.y as f64,
            z: p.z as f64,
            tilt: (up.z as f64).clamp(-1.0, 1.0).acos(),
        }
    }
}

#[cfg(test)]
mod contact_tests {
    use super::*;

    /// Stands the robot for 0.5 s, then pushes the right foot's body horizontally (along x) with
    /// `force` newtons for 1 s; returns the right foot's normal force before the push and how far
    /// its sole's centre moved along x during the push.
    fn push_right_foot(body: &BodyParams, force: f64) -> (f64, f64) {
        let model = NaoModel::default();
        let mut robot = Robot::build(body, &model.standing_pose);
        let stand = model.standing_pose;
        let settle = (0.5 / body.dt).round() as usize;
        let mut load = 0.0;
        for _ in 0..settle {
            robot.command(&stand, body);
            robot.world.step();
            load = robot.feet(body)[0].normal_force;
        }
        let (foot, _) = robot.feet[0];
        let x0 = robot.world.bodies[foot].translation().x as f64;
        let push = (1.0 / body.dt).round() as usize;
        for _ in 0..push {
            robot.command(&stand, body);
            let rb = &mut robot.world.bodies[foot];
            rb.reset_forces(true);
            rb.add_force(v(force, 0.0, 0.0), true);
            robot.world.step();
        }
        let x1 = robot.world.bodies[foot].translation().x as f64;
        (load, x1 - x0)
    }

    #[test]
    fn a_foot_lifted_by_a_known_pose_peaks_at_the_height_worked_out_by_hand() {
        // The torso held at its standing height (a fixed body; gravity on), the right leg is
        // driven from standing (hip −0.4, knee 0.8, ankle −0.4) to hip −0.7, knee 1.4, ankle
        // −0.7: hip + knee + ankle stays 0, so the foot stays flat and parallel to the floor,
        // and the thigh and the shank both end 0.7 rad from the vertical instead of 0.4. The
        // ankle, and with it the whole sole, rises by (0.1 + 0.1029)·(cos 0.4 − cos 0.7)
        // = 0.2029·(0.921061 − 0.764842) = 0.031697 m. Along x the ankle goes from
        // 0.1·sin 0.4 − 0.1029·sin 0.4 = −0.001129 m to 0.1·sin 0.7 − 0.1029·sin 0.7
        // = −0.001868 m: −0.74 mm. The left foot stays on the floor: no lift.
        let b = BodyParams::default();
        let model = NaoModel::default();
        let mut robot = Robot::build(&b, &model.standing_pose);
        if let Some(rb) = robot.world.bodies.get_mut(robot.torso) {
            rb.set_body_type(RigidBodyType::Fixed, true);
        }
        let mut tracker = FeetTracker::new(b.dt, &robot.feet(&b));
        let mut pose = model.standing_pose;
        pose[Servo::RHipPitch.index()] = -0.7;
        pose[Servo::RKneePitch.index()] = 1.4;
        pose[Servo::RAnklePitch.index()] = -0.7;
        let mut command = model.standing_pose;
        for _ in 0..(1.0 / b.dt).round() as usize {
            for s in Servo::ALL {
                let i = s.index();
                let max_move = b.max_speed(s) * b.dt;
                command[i] += (pose[i] - command[i]).clamp(-max_move, max_move);
            }
            robot.command(&command, &b);
            robot.world.step();
            tracker.observe(&robot.feet(&b));
        }
        let r = tracker.report();
        // The servos sag under the lower leg's weight by a few milliradians: within 2 mm.
        assert!((r.feet[0].peak_height - 0.031697).abs() < 0.002, "{r:?}");
        assert!((r.feet[0].forward - -0.00074).abs() < 0.001, "{r:?}");
        // A lifted foot carries nothing.
        assert_eq!(r.feet[0].loaded_time, 0.0, "{r:?}");
        assert!(r.feet[1].peak_height.abs() < 0.001, "{r:?}");
        assert!(r.feet[1].forward.abs() < 0.001, "{r:?}");
    }

    #[test]
    fn the_feet_tracker_sums_loaded_slip_and_the_longest_flight() {
        // Made-up contacts at 10 ms steps: right loaded, sliding at 0.1 m/s, for 2 steps; then
        // both unloaded for 3 steps (30 ms flight); then left loaded for 1 step; then both
        // unloaded for 2 steps (20 ms). Right slid 2 · 0.1 · 0.01 = 2 mm while loaded; the
        // 4 N contact does not count (below 5 N). Flights 30 and 20 ms: longest 30, total 50.
        let foot = |n: f64, slip: f64, h: f64, x: f64| FootContact {
            normal_force: n,
            friction_force: 0.0,
            slip_speed: slip,
            sole_height: h,
            sole_x: x,
            sole_y: 0.0,
        };
        let off = foot(0.0, 0.3, 0.02, 0.0);
        let mut t = FeetTracker::new(0.01, &[foot(0.0, 0.0, 0.0, 0.10), foot(0.0, 0.0, 0.0, -0.05)]);
        for _ in 0..2 {
            t.observe(&[foot(20.0, 0.1, 0.0, 0.11), foot(4.0, 1.0, 0.005, -0.05)]);
        }
        for h in [0.01, 0.04, 0.03] {
            t.observe(&[foot(0.0, 0.5, h, 0.12), off]);
        }
        t.observe(&[off, foot(30.0, 0.0, 0.0, 0.0)]);
        t.observe(&[off, off]);
        t.observe(&[foot(0.0, 0.0, 0.0, 0.16), foot(0.0, 0.0, 0.0, 0.02)]);
        let r = t.report();
        assert!((r.feet[0].slip_loaded - 0.002).abs() < 1e-12, "{r:?}");
        assert!((r.feet[0].loaded_time - 0.02).abs() < 1e-12, "{r:?}");
        assert_eq!(r.feet[1].slip_loaded, 0.0, "{r:?}");
        assert!((r.feet[1].loaded_time - 0.01).abs() < 1e-12, "{r:?}");
        assert_eq!(r.feet[0].peak_height, 0.04, "{r:?}");
        assert_eq!(r.feet[1].peak_height, 0.02, "{r:?}");
        assert!((r.feet[0].forward - 0.06).abs() < 1e-12, "{r:?}");
        assert!((r.feet[1].forward - 0.07).abs() < 1e-12, "{r:?}");
        assert!((r.longest_flight - 0.03).abs() < 1e-12, "{r:?}");
        assert!((r.flight_time - 0.05).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn the_built_robot_weighs_the_sum_of_naos_h25_masses() {
        // By hand from "H25 – Masses": one leg below the pelvis 0.13530 + 0.39421 + 0.29159 +
        // 0.13892 + 0.16304 = 1.12306 kg; the lump above is the rest of 4.996 kg, 2.74988 kg.
        // The rapier world as built holds 11 bodies (the torso and five links a leg) whose
        // masses (f32) add up to 4.996 kg, the torso alone to 2.74988 kg.
        let b = BodyParams::default();
        let robot = Robot::build(&b, &NaoModel::default().standing_pose);
        assert_eq!(robot.world.bodies.len(), 11);
        let total: f64 = robot.world.bodies.iter().map(|(_, rb)| rb.mass() as f64).sum();
        assert!((total - 4.996).abs() < 1e-5, "{total}");
        let torso = robot.world.bodies[robot.torso].mass() as f64;
        assert!((torso - 2.74988).abs() < 1e-5, "{torso}");
        for &(foot, _) in &robot.feet {
            assert!((robot.world.bodies[foot].mass() as f64 - 0.16304).abs() < 1e-6);
        }
    }

    #[test]
    fn a_loaded_sole_grips_below_coulombs_bound_and_slides_above_it() {
        // Both models, each at μ 0.8 (Webots' μ 7 would need a push the legs cannot pass on).
        for b in [
            BodyParams::dc_motor(),
            BodyParams {
                friction: 0.8,
                ..BodyParams::webots()
            },
        ] {
            // The whole robot weighs 4.996 kg · 9.81 = 49.0 N, half of it on each foot: 24.5 N.
            // The pushed sole alone holds until μ·24.5 = 19.6 N, both soles together until
            // μ·W = 0.8 · 49.0 = 39.2 N.
            let (load, held) = push_right_foot(&b, 15.0);
            assert!(
                (load - 24.5).abs() < 2.5,
                "the right sole carries {load} N ({:?})",
                b.servo
            );
            // 15 N < 19.6 N: the sole stays within 2 mm over the second (the servos' sag under
            // the push).
            assert!(
                held.abs() < 0.002,
                "a 15 N push moved the sole {held} m ({:?})",
                b.servo
            );
            // 50 N > 39.2 N: the robot slides; with the 10.8 N excess on 5 kg it would move
            // ½ · 2.2 m/s² · (1 s)² = 1.1 m; anything beyond 0.2 m is sliding, not sag.
            let (_, slid) = push_right_foot(&b, 50.0);
            assert!(slid > 0.2, "a 50 N push moved the sole only {slid} m ({:?})", b.servo);
        }
    }
}
