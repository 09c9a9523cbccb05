//! The variation operators of SPEC §8: five crossovers and the source's mutation (with the SPEC's
//! Decision). Every operator returns individuals with knots clamped into the servo limits and
//! the first and last knots copied from the first parent (the standing pose, which every valid
//! individual shares), so rounding cannot move them.
//!
//! Random draws come from the caller's generator in a documented order, so a run is
//! reproducible from its seed.

use crate::config::BlxVariant;
use crate::model::{Individual, Servo, INNER_KNOTS, INTERVALS, KNOTS, SERVO_COUNT};
use rand::Rng;

/// Inner knots of an individual (10 servos × 19): the length of the one-point crossover's vector.
pub const INNER_TOTAL: usize = SERVO_COUNT * INNER_KNOTS;

/// A child built knot by knot from two parents: `f(servo, knot, p1 value, p2 value)` for every
/// inner knot (servo-major), clamped, ends pinned to p1's.
fn combine(p1: &Individual, p2: &Individual, mut f: impl FnMut(Servo, usize, f64, f64) -> f64) -> Individual {
    let mut child = p1.clone();
    for s in Servo::ALL {
        let i = s.index();
        for k in 1..KNOTS - 1 {
            child.knots[i][k] = s.clamp(f(s, k, p1.knots[i][k], p2.knots[i][k]));
        }
    }
    child
}

/// One BLX-α value: `u` ∈ [0, 1) mapped onto [min − α·d, max + α·d], d = |a − b| (the source's
/// `generateNew`: `(max + 2·d·α − min)·u + min − d·α`). Parents 0.2 and 0.5 with α = 0.7 give
/// [−0.01, 0.71).
pub fn blx_value(a: f64, b: f64, alpha: f64, u: f64) -> f64 {
    let (lo, hi) = (a.min(b), a.max(b));
    let d = hi - lo;
    lo - alpha * d + u * (d + 2.0 * alpha * d)
}

/// BLX-α crossover (SPEC §8). [`BlxVariant::PerKnot`]: an independent draw per inner knot and
/// per child (child 1's 190 knots servo by servo, then child 2's); [`BlxVariant::SingleDraw`]:
/// the source's code, one draw for every knot of both children, which come out identical.
/// Values beyond a servo's limits are clamped to them.
pub fn blx<R: Rng + ?Sized>(
    p1: &Individual,
    p2: &Individual,
    alpha: f64,
    variant: BlxVariant,
    rng: &mut R,
) -> [Individual; 2] {
    match variant {
        BlxVariant::PerKnot => {
            let c1 = combine(p1, p2, |_, _, a, b| blx_value(a, b, alpha, rng.random::<f64>()));
            let c2 = combine(p1, p2, |_, _, a, b| blx_value(a, b, alpha, rng.random::<f64>()));
            [c1, c2]
        }
        BlxVariant::SingleDraw => {
            let u = rng.random::<f64>();
            let c = combine(p1, p2, |_, _, a, b| blx_value(a, b, alpha, u));
            [c.clone(), c]
        }
    }
}

/// Arithmetic crossover (SPEC Decision): λ·p1 + (1 − λ)·p2 and (1 − λ)·p1 + λ·p2, one
/// λ ∈ [0, 1) per crossover (one draw). Children lie between the parents, knot by knot.
pub fn arithmetic<R: Rng + ?Sized>(p1: &Individual, p2: &Individual, rng: &mut R) -> [Individual; 2] {
    let l = rng.random::<f64>();
    [
        combine(p1, p2, |_, _, a, b| l * a + (1.0 - l) * b),
        combine(p1, p2, |_, _, a, b| (1.0 - l) * a + l * b),
    ]
}

/// One-point crossover (SPEC Decision) at a given cut: the inner knots flattened servo by servo
/// (see [`Individual::inner_knots`]); child 1 takes p1's first `cut` values and p2's tail,
/// child 2 the mirror.
pub fn one_point_at(p1: &Individual, p2: &Individual, cut: usize) -> [Individual; 2] {
    let pos = |s: Servo, k: usize| s.index() * INNER_KNOTS + (k - 1);
    [
        combine(p1, p2, |s, k, a, b| if pos(s, k) < cut { a } else { b }),
        combine(p1, p2, |s, k, a, b| if pos(s, k) < cut { b } else { a }),
    ]
}

/// One-point crossover (SPEC Decision): a cut uniform in 1 … 189 (one draw), so each child has at
/// least one inner knot from each parent; see [`one_point_at`].
pub fn one_point<R: Rng + ?Sized>(p1: &Individual, p2: &Individual, rng: &mut R) -> [Individual; 2] {
    let cut = rng.random_range(1..INNER_TOTAL as u32) as usize;
    one_point_at(p1, p2, cut)
}

/// Geometric crossover (SPEC Decision): on each servo's values shifted to the positive range,
/// v ↦ v − min + 1 ∈ [1, 1 + max − min], child 1 = p1^ω·p2^(1−ω), child 2 = p1^(1−ω)·p2^ω,
/// shifted back; one ω ∈ [0, 1) per crossover (one draw). A weighted geometric mean lies between
/// its arguments, so children lie between the parents.
pub fn geometric<R: Rng + ?Sized>(p1: &Individual, p2: &Individual, rng: &mut R) -> [Individual; 2] {
    let w = rng.random::<f64>();
    let mean = |s: Servo, a: f64, b: f64, w: f64| {
        let lo = s.limits().0;
        let (a, b) = (a - lo + 1.0, b - lo + 1.0);
        (w * a.ln() + (1.0 - w) * b.ln()).exp() - 1.0 + lo
    };
    [
        combine(p1, p2, |s, _, a, b| mean(s, a, b, w)),
        combine(p1, p2, |s, _, a, b| mean(s, a, b, 1.0 - w)),
    ]
}

/// The linear crossover's three candidates (SPEC Decision): ½(p1 + p2), 1.5·p1 − 0.5·p2 and
/// −0.5·p1 + 1.5·p2, clamped into the limits. No random draw; the GA keeps the best two by
/// fitness ([`best_two_of_three`]).
pub fn linear_candidates(p1: &Individual, p2: &Individual) -> [Individual; 3] {
    [
        combine(p1, p2, |_, _, a, b| 0.5 * a + 0.5 * b),
        combine(p1, p2, |_, _, a, b| 1.5 * a - 0.5 * b),
        combine(p1, p2, |_, _, a, b| -0.5 * a + 1.5 * b),
    ]
}

/// Indices of the two highest fitnesses, best first; on a tie the earlier candidate wins.
pub fn best_two_of_three(fitness: [f64; 3]) -> [usize; 2] {
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| fitness[j].total_cmp(&fitness[i]));
    [idx[0], idx[1]]
}

/// One pick of a mutation: the interval's two knots moved by `moves` (rad) before clamping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MutationPick {
    /// Servo index (genome order).
    pub servo: usize,
    /// Interval 0 … 19, between knots `interval` and `interval + 1`.
    pub interval: usize,
    /// The amounts drawn for the interval's left and right knot; a pinned end knot (0 or 20)
    /// ignores its amount.
    pub moves: [f64; 2],
}

/// The source's mutation with the SPEC's Decision: `picks` times, pick a servo (uniform over 10)
/// and an interval (uniform over 20), with replacement, and move both knots of that interval by
/// independent amounts uniform in (−step, step] (the source's `(0.5 − u)/3` for step 1/6):
/// four draws per pick in that order. The function stays continuous (knots are shared between
/// neighbouring intervals), the first and last knots stay at the standing pose (their amounts
/// are drawn and ignored) and each moved knot is clamped into its servo's limits at once.
pub fn mutate<R: Rng + ?Sized>(
    parent: &Individual,
    picks: usize,
    step: f64,
    rng: &mut R,
) -> (Individual, Vec<MutationPick>) {
    let mut child = parent.clone();
    let mut record = Vec::with_capacity(picks);
    for _ in 0..picks {
        let servo = rng.random_range(0..SERVO_COUNT as u32) as usize;
        let interval = rng.random_range(0..INTERVALS as u32) as usize;
        let moves = [
            (0.5 - rng.random::<f64>()) * 2.0 * step,
            (0.5 - rng.random::<f64>()) * 2.0 * step,
        ];
        let s = Servo::ALL[servo];
        for (k, m) in [(interval, moves[0]), (interval + 1, moves[1])] {
            if k != 0 && k != KNOTS - 1 {
                let v = &mut child.knots[servo][k];
                *v = s.clamp(*v + m);
            }
        }
        record.push(MutationPick { servo, interval, moves });
    }
    (child, record)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blx_value_spans_the_source_example() {
        // Parents 0.2 and 0.5, α = 0.7: d = 0.3, interval [0.2 − 0.21, 0.5 + 0.21].
        assert!((blx_value(0.2, 0.5, 0.7, 0.0) - -0.01).abs() < 1e-15);
        assert!((blx_value(0.5, 0.2, 0.7, 1.0) - 0.71).abs() < 1e-15);
        assert!((blx_value(0.2, 0.5, 0.7, 0.5) - 0.35).abs() < 1e-15);
    }

    #[test]
    fn best_two_keeps_the_earlier_on_ties() {
        assert_eq!(best_two_of_three([0.1, 0.3, 0.2]), [1, 2]);
        assert_eq!(best_two_of_three([0.5, 0.5, 0.5]), [0, 1]);
        assert_eq!(best_two_of_three([0.0, 0.2, 0.2]), [1, 2]);
    }
}
