//! Reference motions whose outcome is known without a simulation, to check the physics against:
//! the robot bobbing in place on both feet, and poses held after a ramp from standing; and
//! gentle random motions about the standing pose, for samples.

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
