//! The Nao's ten evolved leg servos (SPEC §8, the source's Table 1) and an individual: per servo a
//! piecewise-linear function of time over the step time T, given by its 21 knots at i·T/20.

use crate::error::GaError;
use serde::{Deserialize, Serialize};

/// Number of evolved servos.
pub const SERVO_COUNT: usize = 10;
/// Number of equal time intervals of the step (the paper's best runs: 20).
pub const INTERVALS: usize = 20;
/// Knots per servo: the interval ends 0, T/20, …, T.
pub const KNOTS: usize = INTERVALS + 1;
/// Inner knots per servo (the evolved ones; the first and last are the standing pose).
pub const INNER_KNOTS: usize = INTERVALS - 1;
/// Period of the motion file's rows and of [`Individual::sample`] (ms).
pub const SAMPLE_PERIOD_MS: u64 = 40;

/// One of the ten evolved leg servos, in the SPEC's (the source text's) order, which is the order
/// of the genome, of the motion file's columns and of every `[f64; 10]` in this crate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Servo {
    /// Right hip pitch.
    RHipPitch,
    /// Right hip roll.
    RHipRoll,
    /// Right knee pitch.
    RKneePitch,
    /// Right ankle pitch.
    RAnklePitch,
    /// Right ankle roll.
    RAnkleRoll,
    /// Left hip pitch.
    LHipPitch,
    /// Left hip roll.
    LHipRoll,
    /// Left knee pitch.
    LKneePitch,
    /// Left ankle pitch.
    LAnklePitch,
    /// Left ankle roll.
    LAnkleRoll,
}

impl Servo {
    /// All ten, in genome order.
    pub const ALL: [Servo; SERVO_COUNT] = [
        Servo::RHipPitch,
        Servo::RHipRoll,
        Servo::RKneePitch,
        Servo::RAnklePitch,
        Servo::RAnkleRoll,
        Servo::LHipPitch,
        Servo::LHipRoll,
        Servo::LKneePitch,
        Servo::LAnklePitch,
        Servo::LAnkleRoll,
    ];

    /// Position in the genome (0 … 9).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The joint's name as Webots' Nao model (and NAOqi) names its motor, used in motion files
    /// and joint trajectories. (The source's Table 1 misspells RAnkleRoll as "RAnkeRoll".)
    pub fn name(self) -> &'static str {
        match self {
            Servo::RHipPitch => "RHipPitch",
            Servo::RHipRoll => "RHipRoll",
            Servo::RKneePitch => "RKneePitch",
            Servo::RAnklePitch => "RAnklePitch",
            Servo::RAnkleRoll => "RAnkleRoll",
            Servo::LHipPitch => "LHipPitch",
            Servo::LHipRoll => "LHipRoll",
            Servo::LKneePitch => "LKneePitch",
            Servo::LAnklePitch => "LAnklePitch",
            Servo::LAnkleRoll => "LAnkleRoll",
        }
    }

    /// Angle limits (min, max) in rad, the source's Table 1. Roll limits mirror between the legs
    /// (a roll outwards is positive on the left, negative on the right).
    // Table 1's values as printed (4 decimals): 0.7854 is the table's, not π/4.
    #[allow(clippy::approx_constant)]
    pub fn limits(self) -> (f64, f64) {
        match self {
            Servo::RKneePitch | Servo::LKneePitch => (0.0, 2.2689),
            Servo::LAnkleRoll => (-0.7854, 0.4363),
            Servo::RAnkleRoll => (-0.4363, 0.7854),
            Servo::LHipRoll => (-0.4363, 0.7854),
            Servo::RHipRoll => (-0.7854, 0.4363),
            Servo::RAnklePitch | Servo::LAnklePitch => (-1.309, 0.7854),
            Servo::RHipPitch | Servo::LHipPitch => (-1.7453, 0.4363),
        }
    }

    /// `value` clamped into the servo's limits.
    pub fn clamp(self, value: f64) -> f64 {
        let (lo, hi) = self.limits();
        value.clamp(lo, hi)
    }
}

/// The ten joint names in genome order (Webots' names).
pub fn joint_names() -> [&'static str; SERVO_COUNT] {
    Servo::ALL.map(Servo::name)
}

/// What the source leaves open about the robot (SPEC §8 Decision): the standing pose at both ends
/// of the step and the step time T. `params/nao_step.yaml` holds the same values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NaoModel {
    /// T (s), in (0, 3600]: the duration of the step, split into 20 equal intervals; a whole
    /// number of 40 ms rows (the motion file has a row at T). Default 2.0 s, long enough for a
    /// statically stable step (see docs/ga_step.md, "Model").
    pub step_time: f64,
    /// The standing pose (rad), one angle per servo in genome order, each within its servo's
    /// limits: first and last knot of every individual, and the pose before the step. Default:
    /// knees 0.8, hip and ankle pitch −0.4, rolls 0 (hip + knee + ankle pitch = 0: the torso
    /// upright over flat feet; see docs/ga_step.md, "Model").
    pub standing_pose: [f64; SERVO_COUNT],
}

impl Default for NaoModel {
    fn default() -> Self {
        NaoModel {
            step_time: 2.0,
            standing_pose: [-0.4, 0.0, 0.8, -0.4, 0.0, -0.4, 0.0, 0.8, -0.4, 0.0],
        }
    }
}

impl NaoModel {
    /// Checks a positive step time of a whole number of 40 ms rows (at most an hour) and a finite
    /// standing pose within every servo's limits.
    pub fn validate(&self) -> Result<(), GaError> {
        let t = self.step_time;
        let ms = t * 1000.0;
        let rows = ms / SAMPLE_PERIOD_MS as f64;
        if !(t.is_finite() && t > 0.0 && t <= 3600.0 && (rows - rows.round()).abs() < 1e-9) {
            return Err(GaError::InvalidConfig {
                name: "step_time",
                value: t,
                reason: "must be a positive whole number of 40 ms rows, at most 3600 s",
            });
        }
        for s in Servo::ALL {
            let v = self.standing_pose[s.index()];
            let (lo, hi) = s.limits();
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(GaError::StandingPoseOutOfLimits {
                    servo: s.name(),
                    value: v,
                    min: lo,
                    max: hi,
                });
            }
        }
        Ok(())
    }

    /// T in whole milliseconds (valid after [`validate`](Self::validate)).
    pub fn step_time_ms(&self) -> u64 {
        (self.step_time * 1000.0).round() as u64
    }

    /// The time of knot `k` from the start of the step (ns), k·T/20: k·T_ms·1e6/20 =
    /// k·T_ms·50 000, exact in integers.
    pub fn knot_time_ns(&self, k: usize) -> u64 {
        k as u64 * (self.step_time_ms() * 1_000_000 / INTERVALS as u64)
    }

    /// The individual that stands still: every knot at the standing pose.
    pub fn standing(&self) -> Individual {
        Individual {
            knots: self.standing_pose.map(|v| [v; KNOTS]),
        }
    }

    /// The source's initialisation: first and last knot at the standing pose, each inner knot
    /// uniform over its servo's full range, drawn servo by servo, knot by knot (190 draws).
    pub fn random_individual<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Individual {
        let mut ind = self.standing();
        for s in Servo::ALL {
            let (lo, hi) = s.limits();
            for k in 1..KNOTS - 1 {
                ind.knots[s.index()][k] = lo + rng.random::<f64>() * (hi - lo);
            }
        }
        ind
    }
}

/// One individual: `knots[servo][i]` is the servo's angle (rad) at time i·T/20; between knots
/// the angle is linear in time (one continuous function per servo).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Individual {
    /// Knot values (rad), servo-major in genome order.
    pub knots: [[f64; KNOTS]; SERVO_COUNT],
}

impl Individual {
    /// The servos' angles (rad) at time `t` (s) of a step lasting `step_time` (s); t is clamped
    /// into [0, step_time].
    pub fn angles_at(&self, t: f64, step_time: f64) -> [f64; SERVO_COUNT] {
        let x = (t / step_time).clamp(0.0, 1.0) * INTERVALS as f64;
        let j = (x.floor() as usize).min(INTERVALS - 1);
        let f = x - j as f64;
        self.knots.map(|k| k[j] + (k[j + 1] - k[j]) * f)
    }

    /// The angles every 40 ms from 0 to T inclusive, as (time in ms, angles): the motion file's
    /// rows. Times are exact multiples of 40 ms (integer arithmetic, no accumulated drift).
    pub fn sample(&self, model: &NaoModel) -> Vec<(u64, [f64; SERVO_COUNT])> {
        let rows = model.step_time_ms() / SAMPLE_PERIOD_MS;
        (0..=rows)
            .map(|k| {
                let ms = k * SAMPLE_PERIOD_MS;
                (ms, self.angles_at(ms as f64 / 1000.0, model.step_time))
            })
            .collect()
    }

    /// The flattened inner knots, servo by servo (190 values): the vector the one-point
    /// crossover cuts.
    pub fn inner_knots(&self) -> Vec<f64> {
        self.knots
            .iter()
            .flat_map(|k| k[1..KNOTS - 1].iter().copied())
            .collect()
    }

    /// Clamps every knot into its servo's limits.
    pub fn clamp_to_limits(&mut self) {
        for s in Servo::ALL {
            for v in &mut self.knots[s.index()] {
                *v = s.clamp(*v);
            }
        }
    }

    /// Sets the first and last knot of every servo to `ends` (the pinned standing pose).
    pub fn pin_ends(&mut self, ends: &[f64; SERVO_COUNT]) {
        for (k, &v) in self.knots.iter_mut().zip(ends) {
            k[0] = v;
            k[KNOTS - 1] = v;
        }
    }

    /// The first knot of every servo (the standing pose in a valid individual).
    pub fn first_knots(&self) -> [f64; SERVO_COUNT] {
        self.knots.map(|k| k[0])
    }

    /// Checks finite knots within the limits and both ends at `model`'s standing pose.
    pub fn validate(&self, model: &NaoModel) -> Result<(), GaError> {
        for s in Servo::ALL {
            let (lo, hi) = s.limits();
            let k = &self.knots[s.index()];
            if let Some((i, &v)) = k
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && (lo..=hi).contains(*v)))
            {
                return Err(GaError::InvalidIndividual(format!(
                    "{} knot {i} = {v} is outside [{lo}, {hi}]",
                    s.name()
                )));
            }
            let stand = model.standing_pose[s.index()];
            if k[0] != stand || k[KNOTS - 1] != stand {
                return Err(GaError::InvalidIndividual(format!(
                    "{} ends at {} and {}, not at the standing pose {stand}",
                    s.name(),
                    k[0],
                    k[KNOTS - 1]
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn the_default_model_is_valid_and_upright() {
        let m = NaoModel::default();
        assert_eq!(m.validate(), Ok(()));
        assert_eq!(m.step_time_ms(), 2000);
        // Hip + knee + ankle pitch, per leg: −0.4 + 0.8 − 0.4 = 0.
        let p = m.standing_pose;
        assert!((p[0] + p[2] + p[3]).abs() < 1e-12 && (p[5] + p[7] + p[8]).abs() < 1e-12);
    }

    #[test]
    fn step_times_off_the_40_ms_grid_are_refused() {
        for t in [0.0, -2.0, 2.01, f64::NAN, f64::INFINITY] {
            let m = NaoModel {
                step_time: t,
                ..NaoModel::default()
            };
            assert!(
                matches!(m.validate(), Err(GaError::InvalidConfig { name: "step_time", .. })),
                "{t}"
            );
        }
        let m = NaoModel {
            step_time: 0.04,
            ..NaoModel::default()
        };
        assert_eq!(m.validate(), Ok(()));
    }

    #[test]
    fn a_standing_pose_outside_the_limits_is_refused() {
        let mut m = NaoModel::default();
        m.standing_pose[Servo::LKneePitch.index()] = -0.1;
        assert!(matches!(
            m.validate(),
            Err(GaError::StandingPoseOutOfLimits {
                servo: "LKneePitch",
                ..
            })
        ));
    }

    #[test]
    fn angles_are_linear_between_knots() {
        let m = NaoModel::default();
        let mut ind = m.standing();
        // RHipPitch: knot 3 (t = 0.3 s) at 0.2, knot 4 (0.4 s) at −0.6, the others at −0.4.
        ind.knots[0][3] = 0.2;
        ind.knots[0][4] = -0.6;
        let at = |t: f64| ind.angles_at(t, 2.0)[0];
        assert!((at(0.3) - 0.2).abs() < 1e-12);
        assert!((at(0.4) - -0.6).abs() < 1e-12);
        // A quarter into [0.3, 0.4]: 0.2 + 0.25·(−0.8) = 0.0.
        assert!(at(0.325).abs() < 1e-12);
        // Halfway into [0.2, 0.3]: (−0.4 + 0.2)/2 = −0.1.
        assert!((at(0.25) - -0.1).abs() < 1e-12);
        // Outside [0, T]: the end knots.
        assert_eq!(at(-1.0), -0.4);
        assert_eq!(at(5.0), -0.4);
        assert_eq!(at(2.0), -0.4);
    }

    #[test]
    fn sampling_has_51_rows_40_ms_apart_for_two_seconds() {
        let m = NaoModel::default();
        let rows = m.standing().sample(&m);
        assert_eq!(rows.len(), 51);
        assert_eq!(rows[0].0, 0);
        assert_eq!(rows[50].0, 2000);
        assert!(rows.windows(2).all(|w| w[1].0 - w[0].0 == 40));
    }

    #[test]
    fn random_individuals_are_valid_and_use_the_whole_range() {
        let m = NaoModel::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let (mut lo_seen, mut hi_seen) = ([f64::INFINITY; 10], [f64::NEG_INFINITY; 10]);
        for _ in 0..200 {
            let ind = m.random_individual(&mut rng);
            assert_eq!(ind.validate(&m), Ok(()));
            for s in Servo::ALL {
                for &v in &ind.knots[s.index()][1..KNOTS - 1] {
                    lo_seen[s.index()] = lo_seen[s.index()].min(v);
                    hi_seen[s.index()] = hi_seen[s.index()].max(v);
                }
            }
        }
        // 3800 uniform draws per servo: the extremes lie within 0.5 % of the range of the limits
        // (the chance of missing is (1 − 0.005)^3800 ≈ 5e-9 per end).
        for s in Servo::ALL {
            let (lo, hi) = s.limits();
            let r = hi - lo;
            assert!(lo_seen[s.index()] - lo < 0.005 * r, "{s:?}");
            assert!(hi - hi_seen[s.index()] < 0.005 * r, "{s:?}");
        }
    }
}
