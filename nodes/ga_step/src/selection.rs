//! Roulette selection of parents, roulette choice of the operator and best-N replacement
//! (SPEC §8).

use crate::evaluate::Evaluation;
use crate::model::Individual;
use rand::Rng;
use serde::{Deserialize, Serialize};

/// An individual with its evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    /// The knots.
    pub individual: Individual,
    /// Its evaluation.
    pub evaluation: Evaluation,
}

impl Scored {
    /// The fitness.
    pub fn fitness(&self) -> f64 {
        self.evaluation.fitness
    }
}

/// A weight for the roulette: non-finite or negative counts as 0.
fn weight(f: f64) -> f64 {
    if f.is_finite() && f > 0.0 {
        f
    } else {
        0.0
    }
}

/// Roulette over `n` slots with weights `w(i)`, slot `skip` (if any) excluded; one draw.
fn spin<R: Rng + ?Sized>(n: usize, w: impl Fn(usize) -> f64, skip: Option<usize>, rng: &mut R) -> usize {
    let w = |i: usize| if Some(i) == skip { 0.0 } else { weight(w(i)) };
    let total: f64 = (0..n).map(w).sum();
    let slots = n - usize::from(skip.is_some_and(|s| s < n));
    if total > 0.0 && total.is_finite() {
        let target = rng.random::<f64>() * total;
        let mut cum = 0.0;
        let mut last = 0;
        for i in 0..n {
            let wi = w(i);
            if wi > 0.0 {
                cum += wi;
                last = i;
                if target < cum {
                    return i;
                }
            }
        }
        // Rounding left the target at the very top: the last slot with a weight.
        last
    } else {
        // All weights zero: uniform over the slots.
        let k = rng.random_range(0..slots as u32) as usize;
        match skip {
            Some(s) if k >= s => k + 1,
            _ => k,
        }
    }
}

/// Roulette selection: index i with probability f_i / Σf (fitness must be ≥ 0; a negative or
/// non-finite value counts as 0). When every fitness is 0 the choice is uniform. One draw.
///
/// # Panics
/// If `fitness` is empty (there is nothing to choose; a population has at least 2).
pub fn roulette<R: Rng + ?Sized>(fitness: &[f64], rng: &mut R) -> usize {
    spin(fitness.len(), |i| fitness[i], None, rng)
}

/// Roulette selection among all indices but `exclude` (the second parent of a crossover, so the
/// two parents differ): probability f_i / Σ_{j≠exclude} f_j, uniform over the others when they
/// all have fitness 0. One draw.
///
/// # Panics
/// If `fitness` has fewer than two entries (there is no other parent).
pub fn roulette_excluding<R: Rng + ?Sized>(fitness: &[f64], exclude: usize, rng: &mut R) -> usize {
    spin(fitness.len(), |i| fitness[i], Some(exclude), rng)
}

/// Which operator makes the next offspring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Operator {
    /// A crossover of two roulette-selected parents.
    Crossover,
    /// A mutation of one roulette-selected parent.
    Mutation,
}

/// Roulette choice of the operator (SPEC §8: crossover 0.7, mutation 0.3): crossover with
/// probability w_c / (w_c + w_m). One draw.
pub fn choose_operator<R: Rng + ?Sized>(crossover_weight: f64, mutation_weight: f64, rng: &mut R) -> Operator {
    let u = rng.random::<f64>() * (crossover_weight + mutation_weight);
    if u < crossover_weight {
        Operator::Crossover
    } else {
        Operator::Mutation
    }
}

/// Best-N replacement (SPEC Decision): the `n` fittest of parents and offspring together,
/// fittest first. The sort is stable with the parents first, so on equal fitness a parent stays
/// ahead of a child and an earlier child ahead of a later one.
pub fn replace_best(parents: Vec<Scored>, offspring: Vec<Scored>, n: usize) -> Vec<Scored> {
    let mut all = parents;
    all.extend(offspring);
    all.sort_by(|a, b| b.fitness().total_cmp(&a.fitness()));
    all.truncate(n);
    all
}
