//! The ROS-free half of the external evaluator (`ga_step --evaluator ros`, whose transport is
//! the executable's): the candidate's identifying name, the simulator's answer read from its
//! named values, and the score of a candidate left without a usable answer. The candidate's
//! knots are at [`NaoModel::knot_time_ns`].

use crate::config::FitnessConfig;
use crate::evaluate::Evaluation;
use crate::model::NaoModel;

/// The evaluation of a candidate without a usable answer (none after every attempt, or one
/// with missing or bad values): 0, as a fall at 0 s.
pub const VOID: Evaluation = Evaluation {
    fitness: 0.0,
    fell: true,
    t_fall: 0.0,
    forward_distance: 0.0,
};

/// The name that identifies candidate `n` (counted from 1 in a run) in its message.
pub fn candidate_name(n: u64) -> String {
    format!("candidate {n}")
}

/// A simulator's answer, read from its named values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Whether the robot fell.
    pub fell: bool,
    /// When it fell (s), 0 without a fall.
    pub fall_time: f64,
    /// The torso's forward displacement (m).
    pub forward_distance: f64,
}

impl Outcome {
    /// Reads the named values of an answer, `names[i]` ↔ `values[i]`: `fell` (0 or 1),
    /// `forward_distance` (finite) and, for a fall, `fall_time` (finite, ≥ 0). The reason when
    /// one is missing or bad.
    pub fn from_named(names: &[String], values: &[f64]) -> Result<Outcome, String> {
        if names.len() != values.len() {
            return Err(format!("{} names but {} positions", names.len(), values.len()));
        }
        let value = |key: &str| names.iter().position(|n| n == key).map(|i| values[i]);
        let fell = match value("fell") {
            Some(1.0) => true,
            Some(0.0) => false,
            Some(v) => return Err(format!("fell = {v}, expected 0 or 1")),
            None => return Err("no `fell`".into()),
        };
        let forward_distance = match value("forward_distance") {
            Some(v) if v.is_finite() => v,
            Some(v) => return Err(format!("forward_distance = {v} is not finite")),
            None => return Err("no `forward_distance`".into()),
        };
        let fall_time = match (fell, value("fall_time")) {
            (false, _) => 0.0,
            (true, Some(t)) if t.is_finite() && t >= 0.0 => t,
            (true, Some(t)) => return Err(format!("fall_time = {t}, expected a finite time ≥ 0")),
            (true, None) => return Err("a fall without `fall_time`".into()),
        };
        Ok(Outcome {
            fell,
            fall_time,
            forward_distance,
        })
    }

    /// The answer's evaluation under `fitness` for a step of `model`.
    pub fn evaluation(&self, fitness: &FitnessConfig, model: &NaoModel) -> Evaluation {
        Evaluation::from_outcome(
            fitness,
            model.step_time,
            self.fell,
            self.fall_time,
            self.forward_distance,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn knots_at_twentieths_of_the_step_time() {
        let model = NaoModel::default();
        // T = 2.0 s: a knot every 0.1 s.
        let t = |k| model.knot_time_ns(k);
        assert_eq!((t(0), t(1), t(crate::KNOTS - 1)), (0, 100_000_000, 2_000_000_000));
        assert_eq!(candidate_name(7), "candidate 7");
    }

    #[test]
    fn an_answer_is_read_from_its_named_values() {
        let upright = Outcome::from_named(&names(&["forward_distance", "fell"]), &[0.12, 0.0]).unwrap();
        assert_eq!(
            (upright.fell, upright.fall_time, upright.forward_distance),
            (false, 0.0, 0.12)
        );
        let fall = Outcome::from_named(&names(&["fell", "fall_time", "forward_distance"]), &[1.0, 1.5, -0.1]).unwrap();
        assert_eq!((fall.fell, fall.fall_time), (true, 1.5));
        let fitness = FitnessConfig::default();
        let model = NaoModel::default();
        assert_eq!(
            fall.evaluation(&fitness, &model),
            Evaluation::from_outcome(&fitness, model.step_time, true, 1.5, -0.1)
        );
        let bad = [
            (names(&["fell"]), vec![], "1 names but 0 positions"),
            (names(&["forward_distance"]), vec![0.0], "no `fell`"),
            (names(&["fell", "forward_distance"]), vec![0.5, 0.0], "fell = 0.5"),
            (names(&["fell"]), vec![0.0], "no `forward_distance`"),
            (names(&["fell", "forward_distance"]), vec![0.0, f64::NAN], "not finite"),
            (
                names(&["fell", "forward_distance"]),
                vec![1.0, 0.0],
                "without `fall_time`",
            ),
            (
                names(&["fell", "forward_distance", "fall_time"]),
                vec![1.0, 0.0, -1.0],
                "fall_time = -1",
            ),
        ];
        for (n, v, want) in bad {
            let e = Outcome::from_named(&n, &v).unwrap_err();
            assert!(e.contains(want), "{e}");
        }
    }
}
