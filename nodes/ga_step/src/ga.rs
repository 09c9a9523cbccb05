//! The generation loop: initial population, offspring by roulette-chosen operators, parallel
//! evaluation, best-N replacement, statistics and stop rules, on one seeded ChaCha8 stream.
//!
//! Every random draw of a run comes from the state's one generator, in this order: the initial
//! population (individual by individual, see [`NaoModel::random_individual`]); then per
//! generation, offspring by offspring: the operator ([`choose_operator`]), the parent or parents
//! ([`roulette`], then [`roulette_excluding`]) and the operator's own draws (see each operator).
//! Evaluation draws nothing and its results are stored by index, so a run depends on its seed
//! alone, not on the number of threads.

use crate::config::{Crossover, FitnessConfig, GaConfig};
use crate::error::GaError;
use crate::evaluate::{evaluate_all, Evaluation, Evaluator};
use crate::model::{Individual, NaoModel};
use crate::operators::{arithmetic, best_two_of_three, blx, geometric, linear_candidates, mutate, one_point};
use crate::selection::{choose_operator, replace_best, roulette, roulette_excluding, Operator, Scored};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// The generator of a run.
pub type GaRng = ChaCha8Rng;

/// Everything a run is defined by besides its seed: the robot, the GA and the fitness formula.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GaSetup {
    /// Step time and standing pose.
    pub model: NaoModel,
    /// The algorithm's parameters.
    pub ga: GaConfig,
    /// The fitness formula's constants.
    pub fitness: FitnessConfig,
}

impl GaSetup {
    /// Validates all three parts.
    pub fn validate(&self) -> Result<(), GaError> {
        self.model.validate()?;
        self.ga.validate()?;
        self.fitness.validate()
    }
}

/// One generation's figures (a row of `fitness.csv` and more).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenerationStats {
    /// Generation number; 0 is the initial population.
    pub generation: u32,
    /// Highest fitness in the population.
    pub max: f64,
    /// Mean fitness of the population.
    pub mean: f64,
    /// Lowest fitness in the population.
    pub min: f64,
    /// Whether the best individual falls.
    pub best_fell: bool,
    /// The best individual's forward distance (m).
    pub best_forward: f64,
    /// Evaluations that returned a negative or non-finite fitness (counted as 0) this generation.
    pub invalid_fitness: u32,
    /// Evaluations made this generation.
    pub evaluations: u32,
}

/// Why a run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// The best individual makes a non-falling forward step (only with `stop_at_step`).
    ForwardStep,
    /// The mean fitness rose by less than `level_tolerance` (relative) over `level_window`
    /// generations (never with a window of 0).
    Levelled,
    /// The requested number of generations is done.
    MaxGenerations,
    /// The caller asked to stop (see [`GaState::run`]); the run can be resumed.
    Interrupted,
}

/// A run between generations: what a checkpoint holds.
#[derive(Debug, Clone, PartialEq)]
pub struct GaState {
    /// The run's definition.
    pub setup: GaSetup,
    /// The seed of the generator.
    pub seed: u64,
    /// Generations done (0: the initial population is evaluated).
    pub generation: u32,
    /// The population, fittest first.
    pub population: Vec<Scored>,
    /// One row per generation, 0 … `generation`.
    pub history: Vec<GenerationStats>,
    /// The first generation whose best individual made a non-falling forward step, if any.
    pub first_step_generation: Option<u32>,
    rng: GaRng,
}

/// What one offspring step made: children kept as they are, or the linear crossover's three
/// candidates of which the best `keep` survive evaluation.
enum Brood {
    Plain(Vec<Individual>),
    Linear(Box<[Individual; 3]>, usize),
}

fn stats(generation: u32, population: &[Scored], invalid: u32, evaluations: u32) -> GenerationStats {
    let f = population.iter().map(Scored::fitness);
    let max = f.clone().fold(f64::NEG_INFINITY, f64::max);
    let min = f.clone().fold(f64::INFINITY, f64::min);
    let mean = f.sum::<f64>() / population.len() as f64;
    let best = &population[0].evaluation;
    GenerationStats {
        generation,
        max,
        mean,
        min,
        best_fell: best.fell,
        best_forward: best.forward_distance,
        invalid_fitness: invalid,
        evaluations,
    }
}

/// Evaluates a batch, replacing bad fitness by 0; returns the evaluations and how many were bad.
fn evaluate_batch<E: Evaluator + ?Sized>(
    evaluator: &E,
    batch: &[Individual],
    threads: usize,
) -> (Vec<Evaluation>, u32) {
    let mut invalid = 0;
    let evals = evaluate_all(evaluator, batch, threads)
        .into_iter()
        .map(|e| {
            let (e, bad) = e.sanitised();
            invalid += u32::from(bad);
            e
        })
        .collect();
    (evals, invalid)
}

impl GaState {
    /// Starts a run: validates the setup, draws the initial population from the seed and
    /// evaluates it (generation 0) on `threads` threads (0: one per core).
    pub fn start<E: Evaluator + ?Sized>(
        setup: GaSetup,
        seed: u64,
        evaluator: &E,
        threads: usize,
    ) -> Result<GaState, GaError> {
        setup.validate()?;
        let mut rng = GaRng::seed_from_u64(seed);
        let batch: Vec<Individual> = (0..setup.ga.population)
            .map(|_| setup.model.random_individual(&mut rng))
            .collect();
        let (evals, invalid) = evaluate_batch(evaluator, &batch, threads);
        let n = batch.len() as u32;
        let scored = batch
            .into_iter()
            .zip(evals)
            .map(|(individual, evaluation)| Scored { individual, evaluation })
            .collect();
        let population = replace_best(Vec::new(), scored, setup.ga.population);
        let mut state = GaState {
            history: vec![stats(0, &population, invalid, n)],
            setup,
            seed,
            generation: 0,
            population,
            first_step_generation: None,
            rng,
        };
        state.note_step();
        Ok(state)
    }

    /// Rebuilds a state from its parts (a checkpoint's), the generator at `word_pos` 32-bit words
    /// into the seed's stream. Checks the setup, the population (size, valid individuals,
    /// fittest first, fitness ≥ 0) and the history (one row per generation).
    pub fn from_parts(
        setup: GaSetup,
        seed: u64,
        generation: u32,
        population: Vec<Scored>,
        history: Vec<GenerationStats>,
        first_step_generation: Option<u32>,
        word_pos: u128,
    ) -> Result<GaState, GaError> {
        setup.validate()?;
        let bad = |m: String| Err(GaError::StateMismatch(m));
        if population.len() != setup.ga.population {
            return bad(format!(
                "{} individuals for a population of {}",
                population.len(),
                setup.ga.population
            ));
        }
        for (i, s) in population.iter().enumerate() {
            s.individual.validate(&setup.model)?;
            let f = s.fitness();
            if !(f.is_finite() && f >= 0.0) {
                return bad(format!("individual {i} has fitness {f}"));
            }
        }
        if population.windows(2).any(|w| w[0].fitness() < w[1].fitness()) {
            return bad("population not sorted fittest first".into());
        }
        if history.len() != generation as usize + 1
            || history.iter().enumerate().any(|(i, h)| h.generation as usize != i)
        {
            return bad(format!("history of {} rows for generation {generation}", history.len()));
        }
        if first_step_generation.is_some_and(|g| g > generation) {
            return bad("first step after the current generation".into());
        }
        let mut rng = GaRng::seed_from_u64(seed);
        rng.set_word_pos(word_pos);
        Ok(GaState {
            setup,
            seed,
            generation,
            population,
            history,
            first_step_generation,
            rng,
        })
    }

    /// The generator's position in its stream (32-bit words), for a checkpoint.
    pub fn rng_word_pos(&self) -> u128 {
        self.rng.get_word_pos()
    }

    /// The fittest individual.
    pub fn best(&self) -> &Scored {
        &self.population[0]
    }

    fn note_step(&mut self) {
        if self.first_step_generation.is_none() && self.best().evaluation.is_forward_step(&self.setup.fitness) {
            self.first_step_generation = Some(self.generation);
        }
    }

    /// Draws one generation's offspring (all random draws of the generation happen here).
    fn breed(&mut self) -> Vec<Brood> {
        let ga = &self.setup.ga;
        let fitness: Vec<f64> = self.population.iter().map(Scored::fitness).collect();
        let pop = &self.population;
        let rng = &mut self.rng;
        let mut broods = Vec::new();
        let mut made = 0;
        while made < ga.offspring {
            let room = ga.offspring - made;
            match choose_operator(ga.crossover_weight, ga.mutation_weight, rng) {
                Operator::Crossover => {
                    let i = roulette(&fitness, rng);
                    let j = roulette_excluding(&fitness, i, rng);
                    let (p1, p2) = (&pop[i].individual, &pop[j].individual);
                    let keep = room.min(2);
                    let children = match ga.crossover {
                        Crossover::Blx => blx(p1, p2, ga.blx_alpha, ga.blx_variant, rng),
                        Crossover::Arithmetic => arithmetic(p1, p2, rng),
                        Crossover::OnePoint => one_point(p1, p2, rng),
                        Crossover::Geometric => geometric(p1, p2, rng),
                        Crossover::Linear => {
                            broods.push(Brood::Linear(Box::new(linear_candidates(p1, p2)), keep));
                            made += keep;
                            continue;
                        }
                    };
                    broods.push(Brood::Plain(children.into_iter().take(keep).collect()));
                    made += keep;
                }
                Operator::Mutation => {
                    let i = roulette(&fitness, rng);
                    let (child, _) = mutate(&pop[i].individual, ga.mutation_picks, ga.mutation_step, rng);
                    broods.push(Brood::Plain(vec![child]));
                    made += 1;
                }
            }
        }
        broods
    }

    /// Runs one generation: offspring, their evaluation on `threads` threads (0: one per core),
    /// best-N replacement, statistics. Returns the offspring as they competed for places, in
    /// the order they were made (of a linear crossover's candidates, the best two, best first).
    pub fn next_generation<E: Evaluator + ?Sized>(&mut self, evaluator: &E, threads: usize) -> Vec<Scored> {
        let broods = self.breed();
        let batch: Vec<Individual> = broods
            .iter()
            .flat_map(|b| match b {
                Brood::Plain(c) => c.clone(),
                Brood::Linear(c, _) => c.to_vec(),
            })
            .collect();
        let (evals, invalid) = evaluate_batch(evaluator, &batch, threads);
        let mut scored = batch
            .into_iter()
            .zip(evals)
            .map(|(individual, evaluation)| Scored { individual, evaluation });
        let mut offspring = Vec::new();
        for b in &broods {
            match b {
                Brood::Plain(c) => offspring.extend(scored.by_ref().take(c.len())),
                Brood::Linear(_, keep) => {
                    let three: Vec<Scored> = scored.by_ref().take(3).collect();
                    let best = best_two_of_three([three[0].fitness(), three[1].fitness(), three[2].fitness()]);
                    offspring.extend(best.iter().take(*keep).map(|&k| three[k].clone()));
                }
            }
        }
        let evaluations = broods
            .iter()
            .map(|b| match b {
                Brood::Plain(c) => c.len() as u32,
                Brood::Linear(..) => 3,
            })
            .sum();
        let parents = std::mem::take(&mut self.population);
        self.population = replace_best(parents, offspring.clone(), self.setup.ga.population);
        self.generation += 1;
        self.history
            .push(stats(self.generation, &self.population, invalid, evaluations));
        self.note_step();
        offspring
    }

    /// Why the run should stop now, if it should: a forward step (with `stop_at_step`), the
    /// mean levelled off, or `max_generations` reached, tested in that order.
    pub fn stop_reason(&self, max_generations: u32) -> Option<StopReason> {
        let ga = &self.setup.ga;
        if ga.stop_at_step && self.first_step_generation.is_some() {
            return Some(StopReason::ForwardStep);
        }
        let g = self.generation as usize;
        if ga.level_window > 0 && g >= ga.level_window {
            let (then, now) = (self.history[g - ga.level_window].mean, self.history[g].mean);
            if now - then <= ga.level_tolerance * then.abs() {
                return Some(StopReason::Levelled);
            }
        }
        (self.generation >= max_generations).then_some(StopReason::MaxGenerations)
    }

    /// Runs generations until a stop rule holds, calling `after` after each one (to write a
    /// checkpoint, a progress line); returns why it stopped. `after` returning
    /// `ControlFlow::Break` stops the run between generations ([`StopReason::Interrupted`]: an
    /// interrupt loses no finished generation). A state that already meets a rule returns at
    /// once, so a resumed run ends where the uninterrupted one does.
    pub fn run<E: Evaluator + ?Sized>(
        &mut self,
        evaluator: &E,
        threads: usize,
        max_generations: u32,
        mut after: impl FnMut(&GaState) -> ControlFlow<()>,
    ) -> StopReason {
        loop {
            if let Some(r) = self.stop_reason(max_generations) {
                return r;
            }
            self.next_generation(evaluator, threads);
            if after(self).is_break() {
                return StopReason::Interrupted;
            }
        }
    }
}
