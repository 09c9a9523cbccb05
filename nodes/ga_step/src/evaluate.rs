//! Fitness evaluation: the [`Evaluator`] trait an evaluator implements (the physics simulation,
//! an external simulator), parallel evaluation of a batch over the cores, and
//! [`TestLandscape`], a cheap analytic evaluator for tests and benchmarks.
//!
//! Parallelism uses `std::thread::scope` rather than rayon: no new dependency, a few lines, and
//! the scheduling stays in view. The batch's indices are handed out one at a time through an
//! atomic counter, so a thread that draws quick evaluations (a robot that falls early ends its
//! simulation early) takes more of them; each result is stored at its individual's index, so
//! the output never depends on the number of threads or on their timing. Evaluation draws no
//! random numbers, which keeps a seeded run reproducible whatever the thread count.

use crate::config::FitnessConfig;
use crate::model::{Individual, NaoModel, Servo, INTERVALS, KNOTS};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// What one evaluation found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// The fitness (≥ 0; see [`FitnessConfig::fitness`]).
    pub fitness: f64,
    /// Whether the robot fell.
    pub fell: bool,
    /// Time (s) of the fall, or T_sim without one.
    pub t_fall: f64,
    /// Forward distance (m) the torso moved (at the fall, or at the end).
    pub forward_distance: f64,
}

impl Evaluation {
    /// An evaluation from what the simulation saw, with the fitness of the SPEC's formula;
    /// without a fall t_fall is T_sim whatever `t_fall` says.
    pub fn from_outcome(
        config: &FitnessConfig,
        step_time: f64,
        fell: bool,
        t_fall: f64,
        forward_distance: f64,
    ) -> Evaluation {
        let fitness = config.fitness(step_time, fell.then_some(t_fall), forward_distance);
        let t_fall = if fell { t_fall } else { config.sim_time(step_time) };
        Evaluation {
            fitness,
            fell,
            t_fall,
            forward_distance,
        }
    }

    /// A non-falling forward step: no fall and at least `step_min_forward` forward (the stop
    /// rule's test).
    pub fn is_forward_step(&self, config: &FitnessConfig) -> bool {
        !self.fell && self.forward_distance >= config.step_min_forward
    }

    /// The evaluation with a negative or non-finite fitness replaced by 0 (roulette selection
    /// needs f ≥ 0), and whether it had to be.
    pub fn sanitised(self) -> (Evaluation, bool) {
        if self.fitness.is_finite() && self.fitness >= 0.0 {
            (self, false)
        } else {
            (Evaluation { fitness: 0.0, ..self }, true)
        }
    }
}

/// Evaluates one individual. Must be pure (the same individual always gives the same
/// evaluation, whatever else runs at the time), so runs are reproducible, and `Sync`, so a
/// batch is evaluated on several threads at once.
pub trait Evaluator: Sync {
    /// Runs the individual's step and scores it.
    fn evaluate(&self, individual: &Individual) -> Evaluation;
}

/// Worker threads to use for `threads`: itself when positive, else the machine's available
/// parallelism (1 if unknown).
pub fn resolve_threads(threads: usize) -> usize {
    if threads > 0 {
        threads
    } else {
        std::thread::available_parallelism().map_or(1, usize::from)
    }
}

/// Evaluates every individual, on `threads` threads (0: one per core), returning the
/// evaluations in the individuals' order. With one thread (or one individual) it runs on the
/// caller's thread.
pub fn evaluate_all<E: Evaluator + ?Sized>(
    evaluator: &E,
    individuals: &[Individual],
    threads: usize,
) -> Vec<Evaluation> {
    let threads = resolve_threads(threads).min(individuals.len());
    if threads <= 1 {
        return individuals.iter().map(|i| evaluator.evaluate(i)).collect();
    }
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Evaluation>>> = Mutex::new(vec![None; individuals.len()]);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                let mut mine = Vec::new();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(ind) = individuals.get(i) else { break };
                    mine.push((i, evaluator.evaluate(ind)));
                }
                // A poisoned lock means another worker panicked; scope() re-raises that panic.
                if let Ok(mut r) = results.lock() {
                    for (i, e) in mine {
                        r[i] = Some(e);
                    }
                }
            });
        }
    });
    let results = results.into_inner().unwrap_or_else(|p| p.into_inner());
    results
        .into_iter()
        .zip(individuals)
        // Every index was taken by exactly one worker and stored; a gap is impossible unless a
        // worker panicked, which scope() has already propagated.
        .map(|(e, ind)| e.unwrap_or_else(|| evaluator.evaluate(ind)))
        .collect()
}

/// A **test evaluator**, not physics: a smooth analytic landscape over the knots for tests and
/// benchmarks of the genetic algorithm. It measures the normalised RMS distance d ∈ [0, 1] of an
/// individual's inner knots from a fixed target trajectory (each knot's difference divided by
/// its servo's range), and reports a fall when d > 0.25 at t_fall = T_sim·(1 − d), and a forward
/// distance 0.1·(1 − 4d) m; the fitness is the [`FitnessConfig`]'s. So the optimum (d = 0)
/// scores 1 + w·(0.1 + b), a non-falling forward step of 4 cm needs d ≤ 0.15, standing still
/// (d ≈ 0.21) does not fall but steps only 1.5 cm, and a random individual (d ≈ 0.38: its RMS expectation
/// with uniform knots) falls.
#[derive(Debug, Clone)]
pub struct TestLandscape {
    model: NaoModel,
    fitness: FitnessConfig,
    target: Individual,
}

impl TestLandscape {
    /// The landscape for `model` and `fitness`. Its target: the standing pose plus, per servo s,
    /// 0.3·range·sin(π·i/10 + 0.6·s) at knot i (within every servo's limits with the default
    /// standing pose; clamped otherwise), ends pinned.
    pub fn new(model: NaoModel, fitness: FitnessConfig) -> TestLandscape {
        let mut target = model.standing();
        for s in Servo::ALL {
            let (lo, hi) = s.limits();
            for k in 1..KNOTS - 1 {
                let phase = std::f64::consts::PI * k as f64 / 10.0 + 0.6 * s.index() as f64;
                target.knots[s.index()][k] = s.clamp(model.standing_pose[s.index()] + 0.3 * (hi - lo) * phase.sin());
            }
        }
        TestLandscape { model, fitness, target }
    }

    /// The target trajectory (fitness maximum).
    pub fn target(&self) -> &Individual {
        &self.target
    }

    /// The normalised RMS distance d of `individual`'s inner knots from the target.
    pub fn distance(&self, individual: &Individual) -> f64 {
        let mut sum = 0.0;
        for s in Servo::ALL {
            let (lo, hi) = s.limits();
            for k in 1..KNOTS - 1 {
                let e = (individual.knots[s.index()][k] - self.target.knots[s.index()][k]) / (hi - lo);
                sum += e * e;
            }
        }
        (sum / (Servo::ALL.len() * (INTERVALS - 1)) as f64).sqrt()
    }
}

impl Evaluator for TestLandscape {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        let d = self.distance(individual);
        let t_sim = self.fitness.sim_time(self.model.step_time);
        let fell = d > 0.25;
        Evaluation::from_outcome(
            &self.fitness,
            self.model.step_time,
            fell,
            t_sim * (1.0 - d),
            0.1 * (1.0 - 4.0 * d),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_scores_the_landscape_maximum() {
        let l = TestLandscape::new(NaoModel::default(), FitnessConfig::default());
        let e = l.evaluate(l.target());
        // d = 0: no fall, 0.1 m forward, f = 1 + 2·(0.1 + 1) = 3.2.
        assert_eq!(l.distance(l.target()), 0.0);
        assert!(!e.fell);
        assert!((e.fitness - 3.2).abs() < 1e-12);
    }

    #[test]
    fn standing_still_is_a_short_non_falling_step_on_the_landscape() {
        let m = NaoModel::default();
        let l = TestLandscape::new(m.clone(), FitnessConfig::default());
        // Standing: knot k of servo s is off by 0.3·sin(πk/10 + 0.6s) of its range. Over a full
        // period (k = 0 … 19) the 20 values of sin² sum to 10, so over k = 1 … 19 they sum to
        // 10 − sin²(0.6s); d² = 0.09 · Σ_s (10 − sin²(0.6s)) / 190.
        let sum: f64 = (0..10).map(|s| 10.0 - (0.6 * s as f64).sin().powi(2)).sum();
        let d_expected = (0.09 * sum / 190.0).sqrt();
        let d = l.distance(&m.standing());
        assert!((d - d_expected).abs() < 1e-12, "{d} vs {d_expected}");
        assert!((0.20..0.22).contains(&d));
        let e = l.evaluate(&m.standing());
        // No fall (d ≤ 0.25): f = 1 + 2·(0.1·(1 − 4d) + 1).
        assert!(!e.fell);
        assert!((e.fitness - (1.0 + 2.0 * (0.1 * (1.0 - 4.0 * d_expected) + 1.0))).abs() < 1e-12);
        assert!(!e.is_forward_step(&FitnessConfig::default()));
    }

    #[test]
    fn sanitised_zeroes_bad_fitness() {
        let e = Evaluation {
            fitness: f64::NAN,
            fell: true,
            t_fall: 1.0,
            forward_distance: 0.0,
        };
        let (s, bad) = e.sanitised();
        assert!(bad);
        assert_eq!(s.fitness, 0.0);
        let ok = Evaluation { fitness: 0.5, ..e };
        assert_eq!(ok.sanitised(), (ok, false));
    }
}
