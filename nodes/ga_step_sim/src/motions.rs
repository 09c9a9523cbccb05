//! Reference motions whose outcome is known without a simulation, to check the physics against:
//! the robot bobbing in place on both feet, and poses held after a ramp from standing; and
//! gentle random motions about the standing pose, for samples; and a hand-made forward step
//! ([`forward_step`]), the evaluator's control experiment.

use crate::body::{leg_chain, BodyParams};
use mobil_ga_step::{Individual, NaoModel, Servo, KNOTS};

/// Both legs bob in place: knees `stand + 2a·s(t)`, hip and ankle pitch `stand − a·s(t)` with
/// s(t) = sin(2π·t/period), rolls at the standing pose. Hip + knee + ankle pitch stays what it is
/// standing (0 for the default pose), so the torso stays upright over flat feet and only rises
/// and sinks; nothing pushes it along x or y. The knots sample s at i·T/20 (T/20 = 0.1 s by
/// default); with the period a divisor of 2T/20·k the first and last knots are the standing pose.
pub fn knee_bob(model: &NaoModel, amplitude: f64, period: f64) -> Individual {
    let mut ind = model.standing();
    let dt = model.step_time / (KNOTS - 1) as f64;
    for k in 1..KNOTS - 1 {
        let s = (2.0 * std::f64::consts::PI * k as f64 * dt / period).sin();
        for (servo, gain) in [
            (Servo::RKneePitch, 2.0),
            (Servo::LKneePitch, 2.0),
            (Servo::RHipPitch, -1.0),
            (Servo::LHipPitch, -1.0),
            (Servo::RAnklePitch, -1.0),
            (Servo::LAnklePitch, -1.0),
        ] {
            let i = servo.index();
            ind.knots[i][k] = servo.clamp(model.standing_pose[i] + gain * amplitude * s);
        }
    }
    ind
}

/// The pose `angles` (servo, rad; the others standing) reached by a straight ramp from standing
/// over the first `ramp_knots` intervals and held to the end of the step (the last knot stays the
/// standing pose, as every individual's: the return starts at T − T/20).
pub fn ramp_to(model: &NaoModel, angles: &[(Servo, f64)], ramp_knots: usize) -> Individual {
    let mut ind = model.standing();
    let ramp = ramp_knots.max(1);
    for &(servo, target) in angles {
        let i = servo.index();
        let q0 = model.standing_pose[i];
        for k in 1..KNOTS - 1 {
            let f = (k as f64 / ramp as f64).min(1.0);
            ind.knots[i][k] = servo.clamp(q0 + (target - q0) * f);
        }
    }
    ind
}

/// A gentle random motion: every inner knot uniform within `fraction` of its servo's range
/// about the standing pose (stand + fraction·(hi − lo)·(2u − 1), u from `uniform` in [0, 1),
/// drawn servo by servo, knot by knot), clamped into the limits. 0.05–0.125 give motions that
/// mostly stay up for a while; the generator is the caller's, so a sample is reproducible.
pub fn gentle(model: &NaoModel, fraction: f64, uniform: &mut dyn FnMut() -> f64) -> Individual {
    let mut ind = model.standing();
    for s in Servo::ALL {
        let (lo, hi) = s.limits();
        for k in 1..KNOTS - 1 {
            let v = model.standing_pose[s.index()] + fraction * (hi - lo) * (2.0 * uniform() - 1.0);
            ind.knots[s.index()][k] = s.clamp(v);
        }
    }
    ind
}

/// A hand-made open-loop forward step ([`forward_step`]): how far each foot moves, how far the
/// torso sways over the stance foot, how high a foot is lifted and how far the torso sinks while
/// stepping (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    /// Forward distance of each foot, and so of the torso (m).
    pub length: f64,
    /// Lateral shift of the torso over the stance foot (m).
    pub sway: f64,
    /// Height a swing foot is lifted (m).
    pub lift: f64,
    /// How far the torso sinks below its standing height while stepping (m), to keep both legs
    /// within reach with the torso swayed and a foot ahead.
    pub dip: f64,
}

impl Default for StepPlan {
    fn default() -> Self {
        StepPlan {
            length: 0.06,
            sway: 0.045,
            lift: 0.03,
            dip: 0.015,
        }
    }
}

/// A key instant of the hand-made step: its time as a fraction of T, the torso's displacement
/// (forward, left, down), the right and the left foot's (forward, up).
type StepKey = (f64, [f64; 3], [f64; 2], [f64; 2]);

/// The hand-made step's key instants as fractions of the step time T, each with the torso's
/// displacement (forward, left, down) and each foot's (forward, up), in units of the plan's
/// length, sway, dip and lift: sway onto the left foot, lift the right, swing it ahead, put it
/// down, carry the torso over it, lift the left, swing it ahead, put it down, sway back to the
/// middle. Between instants every displacement follows a smoothstep.
const STEP_KEYS: [StepKey; 10] = [
    (0.00, [0.0, 0.0, 0.0], [0.0, 0.0], [0.0, 0.0]),
    (0.20, [0.0, 1.0, 1.0], [0.0, 0.0], [0.0, 0.0]),
    (0.25, [0.0, 1.0, 1.0], [0.0, 1.0], [0.0, 0.0]),
    (0.35, [0.0, 1.0, 1.0], [1.0, 1.0], [0.0, 0.0]),
    (0.40, [0.0, 1.0, 1.0], [1.0, 0.0], [0.0, 0.0]),
    (0.60, [1.0, -1.0, 1.0], [1.0, 0.0], [0.0, 0.0]),
    (0.65, [1.0, -1.0, 1.0], [1.0, 0.0], [0.0, 1.0]),
    (0.75, [1.0, -1.0, 1.0], [1.0, 0.0], [1.0, 1.0]),
    (0.80, [1.0, -1.0, 1.0], [1.0, 0.0], [1.0, 0.0]),
    (1.00, [1.0, 0.0, 0.0], [1.0, 0.0], [1.0, 0.0]),
];

/// A hand-made open-loop forward step as an individual (knots in the genome's format): the
/// step's key instants (sway onto the left foot, lift the right, swing it ahead, put it down,
/// carry the torso over it, lift the left, swing it ahead, put it down, sway back) scaled by
/// `plan`, sampled at the knots, each leg's angles from [`BodyParams::leg_angles`] with the torso upright and the soles flat; the first and last knots
/// the standing pose. `None` if a knot is out of a leg's reach or a servo's limits.
pub fn forward_step(model: &NaoModel, body: &BodyParams, plan: &StepPlan) -> Option<Individual> {
    let mut ind = model.standing();
    let scale = |torso: [f64; 3], right: [f64; 2], left: [f64; 2]| {
        (
            [torso[0] * plan.length, torso[1] * plan.sway, -torso[2] * plan.dip],
            [
                [right[0] * plan.length, right[1] * plan.lift],
                [left[0] * plan.length, left[1] * plan.lift],
            ],
        )
    };
    for k in 1..KNOTS - 1 {
        let f = k as f64 / (KNOTS - 1) as f64;
        let i = STEP_KEYS.iter().position(|key| key.0 >= f)?;
        let (t0, a_torso, a_r, a_l) = STEP_KEYS[i.saturating_sub(1)];
        let (t1, b_torso, b_r, b_l) = STEP_KEYS[i];
        let u = if t1 > t0 {
            ((f - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let w = u * u * (3.0 - 2.0 * u);
        let mix = |a: f64, b: f64| a + (b - a) * w;
        let (torso, feet) = scale(
            [0, 1, 2].map(|j| mix(a_torso[j], b_torso[j])),
            [0, 1].map(|j| mix(a_r[j], b_r[j])),
            [0, 1].map(|j| mix(a_l[j], b_l[j])),
        );
        for (side, left) in [false, true].into_iter().enumerate() {
            let chain = leg_chain(left);
            let stand = chain.map(|s| model.standing_pose[s.index()]);
            let a0 = body.ankle_from_hip(&stand);
            let ankle = [
                a0[0] + feet[side][0] - torso[0],
                a0[1] - torso[1],
                a0[2] + feet[side][1] - torso[2],
            ];
            let q = body.leg_angles(ankle)?;
            for (s, angle) in chain.into_iter().zip(q) {
                let (lo, hi) = s.limits();
                if !(lo..=hi).contains(&angle) {
                    return None;
                }
                ind.knots[s.index()][k] = angle;
            }
        }
    }
    Some(ind)
}
