//! Roulette selection and operator choice against their probabilities (chi-square bounds with
//! fixed seeds), and best-N replacement against a sort done by hand.

use mobil_ga_step::{
    choose_operator, replace_best, roulette, roulette_excluding, Evaluation, NaoModel, Operator, Scored,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Pearson's chi-square of observed counts against expected probabilities (slots with
/// probability 0 must be empty and are left out).
fn chi_square(counts: &[usize], p: &[f64]) -> f64 {
    let n: usize = counts.iter().sum();
    counts
        .iter()
        .zip(p)
        .filter(|(_, p)| **p > 0.0)
        .map(|(&c, &p)| {
            let e = n as f64 * p;
            (c as f64 - e).powi(2) / e
        })
        .sum()
}

fn spin(f: impl Fn(&mut ChaCha8Rng) -> usize, slots: usize, n: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut counts = vec![0; slots];
    for _ in 0..n {
        counts[f(&mut rng)] += 1;
    }
    counts
}

/// Fitness 1, 2, 3, 4, 0: shares 0.1, 0.2, 0.3, 0.4 and never the last. 100 000 spins; with 3
/// degrees of freedom chi-square exceeds 16.27 with probability 0.001.
#[test]
fn roulette_frequencies_follow_fitness_shares() {
    let fitness = [1.0, 2.0, 3.0, 4.0, 0.0];
    let p = [0.1, 0.2, 0.3, 0.4, 0.0];
    let counts = spin(|r| roulette(&fitness, r), 5, 100_000, 1);
    assert_eq!(counts[4], 0);
    let x2 = chi_square(&counts, &p);
    assert!(x2 < 16.27, "{counts:?}: chi-square {x2}");
}

/// Negative and non-finite fitness count as 0: fitness −1, NaN, 2, ∞ selects only slot 2.
#[test]
fn roulette_ignores_negative_and_non_finite_fitness() {
    let fitness = [-1.0, f64::NAN, 2.0, f64::INFINITY];
    let counts = spin(|r| roulette(&fitness, r), 4, 1000, 2);
    assert_eq!(counts, [0, 0, 1000, 0]);
}

/// All fitness zero: uniform over the five (4 degrees of freedom: 18.47 at 0.001).
#[test]
fn roulette_with_all_zero_fitness_is_uniform() {
    let fitness = [0.0; 5];
    let counts = spin(|r| roulette(&fitness, r), 5, 50_000, 3);
    let x2 = chi_square(&counts, &[0.2; 5]);
    assert!(x2 < 18.47, "{counts:?}: chi-square {x2}");
}

/// The second parent: never the excluded one; among the others by fitness (excluding slot 3 of
/// 1, 2, 3, 4 leaves shares 1/6, 2/6, 3/6, 2 degrees of freedom: 13.82 at 0.001), uniform when
/// the others all score 0.
#[test]
fn roulette_excluding_skips_the_first_parent() {
    let fitness = [1.0, 2.0, 3.0, 4.0];
    let counts = spin(|r| roulette_excluding(&fitness, 3, r), 4, 60_000, 4);
    assert_eq!(counts[3], 0);
    let x2 = chi_square(&counts, &[1.0 / 6.0, 2.0 / 6.0, 3.0 / 6.0, 0.0]);
    assert!(x2 < 13.82, "{counts:?}: chi-square {x2}");

    let fitness = [0.0, 5.0, 0.0, 0.0];
    let counts = spin(|r| roulette_excluding(&fitness, 1, r), 4, 30_000, 5);
    assert_eq!(counts[1], 0);
    let x2 = chi_square(&counts, &[1.0 / 3.0, 0.0, 1.0 / 3.0, 1.0 / 3.0]);
    assert!(x2 < 13.82, "{counts:?}: chi-square {x2}");
}

/// Operator choice 0.7 / 0.3: over 100 000 choices the crossover share is within 4 binomial
/// standard deviations (√(0.21/100 000) = 0.00145) of 0.7.
#[test]
fn operator_choice_is_seventy_thirty() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let n = 100_000;
    let crossovers = (0..n)
        .filter(|_| choose_operator(0.7, 0.3, &mut rng) == Operator::Crossover)
        .count();
    assert!(
        (crossovers as f64 / n as f64 - 0.7).abs() < 4.0 * 0.00145,
        "{crossovers}"
    );
    // Weight 0 never chosen.
    assert!((0..1000).all(|_| choose_operator(1.0, 0.0, &mut rng) == Operator::Crossover));
}

fn scored(f: f64, tag: f64) -> Scored {
    // The tag marks the individual (its first inner knot of RHipRoll) to tell equal fitness apart.
    let mut individual = NaoModel::default().standing();
    individual.knots[1][1] = tag;
    Scored {
        individual,
        evaluation: Evaluation {
            fitness: f,
            fell: false,
            t_fall: 3.0,
            forward_distance: 0.0,
        },
    }
}

/// Best-100 of 100 parents (fitness 0, 1, …, 99) and 100 children (fitness 0.5, 1.5, …, 99.5):
/// the kept fitnesses are 49.5, 50, 50.5, …, 99.5 (the top 100 of the 200 values), in
/// descending order; at equal fitness a parent stays ahead of a child.
#[test]
fn best_100_replacement_keeps_the_top_of_both() {
    let parents: Vec<Scored> = (0..100).map(|i| scored(i as f64, 0.0)).collect();
    let children: Vec<Scored> = (0..100).map(|i| scored(i as f64 + 0.5, 0.1)).collect();
    let kept = replace_best(parents, children, 100);
    let f: Vec<f64> = kept.iter().map(Scored::fitness).collect();
    let expected: Vec<f64> = (0..100).map(|i| 99.5 - 0.5 * i as f64).collect();
    assert_eq!(f, expected);

    let parents = vec![scored(1.0, 0.0), scored(0.5, 0.0)];
    let children = vec![scored(1.0, 0.1), scored(2.0, 0.1)];
    let kept = replace_best(parents, children, 2);
    assert_eq!(kept[0].fitness(), 2.0);
    assert_eq!((kept[1].fitness(), kept[1].individual.knots[1][1]), (1.0, 0.0));
}
