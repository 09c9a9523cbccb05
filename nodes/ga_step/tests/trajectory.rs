//! The piecewise-linear trajectory of random individuals, against its definition: the knots at
//! i·T/20, each value between its interval's two knots, continuous across knots, and the 40 ms
//! samples equal to the function.

// A servo index addresses the angles and the knots at once.
#![allow(clippy::needless_range_loop)]

use mobil_ga_step::{Individual, NaoModel, INTERVALS};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn individual(seed: u64) -> (NaoModel, Individual) {
    let m = NaoModel::default();
    let ind = m.random_individual(&mut ChaCha8Rng::seed_from_u64(seed));
    (m, ind)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_knots_are_the_values_at_the_interval_ends(seed in any::<u64>()) {
        let (m, ind) = individual(seed);
        for i in 0..=INTERVALS {
            let t = i as f64 * m.step_time / INTERVALS as f64;
            let a = ind.angles_at(t, m.step_time);
            for s in 0..10 {
                prop_assert!((a[s] - ind.knots[s][i]).abs() < 1e-12);
            }
        }
    }

    /// Within interval j the value is the knots' weighted mean (1 − f)·k_j + f·k_{j+1}, f the
    /// fraction of the interval elapsed, computed here from the interval's own ends.
    #[test]
    fn values_between_knots_are_their_weighted_mean(seed in any::<u64>(), t in 0.0..2.0f64) {
        let (m, ind) = individual(seed);
        let h = m.step_time / INTERVALS as f64;
        let j = ((t / h) as usize).min(INTERVALS - 1);
        let f = (t - j as f64 * h) / h;
        let a = ind.angles_at(t, m.step_time);
        for s in 0..10 {
            let (k0, k1) = (ind.knots[s][j], ind.knots[s][j + 1]);
            prop_assert!((a[s] - ((1.0 - f) * k0 + f * k1)).abs() < 1e-9);
            prop_assert!(k0.min(k1) - 1e-12 <= a[s] && a[s] <= k0.max(k1) + 1e-12);
        }
    }

    /// Continuity: 1 µs either side of an inner knot the values differ by at most the steeper
    /// neighbouring slope × 1 µs (slopes are at most 2.2689 rad per 0.1 s, so < 1e-4).
    #[test]
    fn the_trajectory_is_continuous_at_the_knots(seed in any::<u64>(), i in 1..INTERVALS) {
        let (m, ind) = individual(seed);
        let t = i as f64 * m.step_time / INTERVALS as f64;
        let (a, b) = (ind.angles_at(t - 1e-6, m.step_time), ind.angles_at(t + 1e-6, m.step_time));
        for s in 0..10 {
            prop_assert!((a[s] - b[s]).abs() < 1e-4);
        }
    }

    #[test]
    fn samples_are_the_function_every_40_ms(seed in any::<u64>()) {
        let (m, ind) = individual(seed);
        let rows = ind.sample(&m);
        prop_assert_eq!(rows.len(), 51);
        for (k, (ms, a)) in rows.iter().enumerate() {
            prop_assert_eq!(*ms, 40 * k as u64);
            // k · 0.04 s in floating point may differ from k·40 ms / 1000 in the last bit.
            let f = ind.angles_at(k as f64 * 0.04, 2.0);
            for s in 0..10 {
                prop_assert!((a[s] - f[s]).abs() < 1e-12);
            }
        }
    }
}
