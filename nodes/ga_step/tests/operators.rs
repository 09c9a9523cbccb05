//! The variation operators against values worked out by hand or by a second method.

use mobil_ga_step::{
    arithmetic, blx, geometric, linear_candidates, mutate, one_point, one_point_at, BlxVariant, Individual, NaoModel,
    Servo, KNOTS,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn model() -> NaoModel {
    NaoModel::default()
}

/// The standing individual with every inner knot of `servo` at `v`.
fn with_servo(servo: Servo, v: f64) -> Individual {
    let mut ind = model().standing();
    for k in 1..KNOTS - 1 {
        ind.knots[servo.index()][k] = v;
    }
    ind
}

/// An individual at one end of every servo's range (inner knots), or at the other.
fn at_limits(upper: bool) -> Individual {
    let mut ind = model().standing();
    for s in Servo::ALL {
        let (lo, hi) = s.limits();
        for k in 1..KNOTS - 1 {
            ind.knots[s.index()][k] = if upper { hi } else { lo };
        }
    }
    ind
}

fn all_children(p1: &Individual, p2: &Individual, rng: &mut ChaCha8Rng) -> Vec<Individual> {
    let mut out = Vec::new();
    out.extend(blx(p1, p2, 0.7, BlxVariant::PerKnot, rng));
    out.extend(blx(p1, p2, 0.7, BlxVariant::SingleDraw, rng));
    out.extend(arithmetic(p1, p2, rng));
    out.extend(one_point(p1, p2, rng));
    out.extend(geometric(p1, p2, rng));
    out.extend(linear_candidates(p1, p2));
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Every crossover's children are valid: finite knots within the limits, ends at the
    /// standing pose, for random parents and for parents at opposite ends of every range (where
    /// BLX-α and the linear crossover reach furthest outside).
    #[test]
    fn crossovers_keep_knots_within_limits(seed in any::<u64>()) {
        let m = model();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (a, b) = (m.random_individual(&mut rng), m.random_individual(&mut rng));
        for (p1, p2) in [(&a, &b), (&at_limits(false), &at_limits(true)), (&at_limits(true), &a)] {
            for child in all_children(p1, p2, &mut rng) {
                prop_assert_eq!(child.validate(&m), Ok(()));
            }
        }
    }

    /// Arithmetic children lie between the parents knot by knot, and the two children sum to
    /// the parents' sum (λ·p1 + (1 − λ)·p2 + (1 − λ)·p1 + λ·p2 = p1 + p2).
    #[test]
    fn arithmetic_children_lie_between_the_parents(seed in any::<u64>()) {
        let m = model();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (p1, p2) = (m.random_individual(&mut rng), m.random_individual(&mut rng));
        let [c1, c2] = arithmetic(&p1, &p2, &mut rng);
        for s in 0..10 {
            for k in 0..KNOTS {
                let (a, b) = (p1.knots[s][k], p2.knots[s][k]);
                for c in [c1.knots[s][k], c2.knots[s][k]] {
                    prop_assert!(a.min(b) - 1e-12 <= c && c <= a.max(b) + 1e-12);
                }
                prop_assert!((c1.knots[s][k] + c2.knots[s][k] - a - b).abs() < 1e-12);
            }
        }
    }

    /// Geometric children also lie between the parents (a weighted geometric mean does).
    #[test]
    fn geometric_children_lie_between_the_parents(seed in any::<u64>()) {
        let m = model();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (p1, p2) = (m.random_individual(&mut rng), m.random_individual(&mut rng));
        for c in geometric(&p1, &p2, &mut rng) {
            for s in 0..10 {
                for k in 0..KNOTS {
                    let (a, b) = (p1.knots[s][k], p2.knots[s][k]);
                    prop_assert!(a.min(b) - 1e-12 <= c.knots[s][k] && c.knots[s][k] <= a.max(b) + 1e-12);
                }
            }
        }
    }
}

/// BLX-α with parents 0.2 and 0.5 (α = 0.7): d = 0.3, values in [0.2 − 0.21, 0.5 + 0.21] =
/// [−0.01, 0.71]. R/LAnklePitch ([−1.309, 0.7854]) hold the whole interval, so nothing is
/// clamped. 2000 crossovers × 2 children × 2 servos × 19 knots = 152 000 values: none outside,
/// both ends approached within 0.0005 (the chance of missing one is (1 − 0.0005/0.72)^152000
/// ≈ e^−105), and the share below 0.2 is 0.21/0.72 = 0.2917 (binomial σ = 0.0012; bound 0.006).
#[test]
fn blx_samples_the_documented_interval() {
    let (mut p1, mut p2) = (with_servo(Servo::RAnklePitch, 0.2), with_servo(Servo::RAnklePitch, 0.5));
    for k in 1..KNOTS - 1 {
        p1.knots[Servo::LAnklePitch.index()][k] = 0.5;
        p2.knots[Servo::LAnklePitch.index()][k] = 0.2;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let (mut lo, mut hi, mut below, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0usize, 0usize);
    for _ in 0..2000 {
        for c in blx(&p1, &p2, 0.7, BlxVariant::PerKnot, &mut rng) {
            for s in [Servo::RAnklePitch, Servo::LAnklePitch] {
                for &v in &c.knots[s.index()][1..KNOTS - 1] {
                    assert!((-0.01..=0.71).contains(&v), "{v}");
                    lo = lo.min(v);
                    hi = hi.max(v);
                    below += usize::from(v < 0.2);
                    n += 1;
                }
            }
            // Every other servo: both parents stand, d = 0, the child stands.
            assert_eq!(
                c.knots[Servo::RKneePitch.index()],
                model().standing().knots[Servo::RKneePitch.index()]
            );
        }
    }
    assert_eq!(n, 152_000);
    assert!(lo < -0.01 + 0.0005 && hi > 0.71 - 0.0005, "[{lo}, {hi}]");
    let share = below as f64 / n as f64;
    assert!((share - 0.21 / 0.72).abs() < 0.006, "{share}");
}

/// Near a limit BLX-α's interval is cut: knee parents 0.0 and 0.5 give [−0.35, 0.85], clamped
/// at 0, so a share 0.35/1.2 = 0.2917 of the values is exactly 0.
#[test]
fn blx_clamps_to_the_servo_limits() {
    let (p1, p2) = (with_servo(Servo::LKneePitch, 0.0), with_servo(Servo::LKneePitch, 0.5));
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut zero, mut n) = (0usize, 0usize);
    for _ in 0..2000 {
        for c in blx(&p1, &p2, 0.7, BlxVariant::PerKnot, &mut rng) {
            for &v in &c.knots[Servo::LKneePitch.index()][1..KNOTS - 1] {
                assert!((0.0..=0.85).contains(&v));
                zero += usize::from(v == 0.0);
                n += 1;
            }
        }
    }
    assert!((zero as f64 / n as f64 - 0.35 / 1.2).abs() < 0.01);
}

/// The source's single-draw BLX: one position u for every knot and both children, so the
/// children are identical and knots whose parents agree in (min, max) agree in the child.
#[test]
fn single_draw_blx_gives_identical_children_of_one_position() {
    let m = model();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut p1, p2) = (m.random_individual(&mut rng), m.random_individual(&mut rng));
    // Knot 3 of RAnklePitch: parents 0.2, 0.5; knot 4: parents 0.5, 0.2 (the same interval).
    let i = Servo::RAnklePitch.index();
    let mut p2 = p2;
    (p1.knots[i][3], p2.knots[i][3], p1.knots[i][4], p2.knots[i][4]) = (0.2, 0.5, 0.5, 0.2);
    let mut probe = rng.clone();
    let u: f64 = probe.random();
    let [c1, c2] = blx(&p1, &p2, 0.7, BlxVariant::SingleDraw, &mut rng);
    assert_eq!(c1, c2);
    assert_eq!(c1.knots[i][3], c1.knots[i][4]);
    assert!((c1.knots[i][3] - (-0.01 + 0.72 * u)).abs() < 1e-12);
    // The generator moved by exactly one draw.
    assert_eq!(rng.random::<u64>(), probe.random::<u64>());
}

/// One-point crossover swaps tails of the flattened inner knots: with the cut at c, child 1's
/// vector is p1's first c values then p2's, child 2 the mirror; the cut can fall inside a
/// servo (c = 25: servo 0 from p1, servo 1's first 6 knots from p1, the rest from p2).
#[test]
fn one_point_swaps_tails() {
    let m = model();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let (p1, p2) = (m.random_individual(&mut rng), m.random_individual(&mut rng));
    let (v1, v2) = (p1.inner_knots(), p2.inner_knots());
    assert_eq!(v1.len(), 190);
    for cut in [1, 19, 25, 100, 189] {
        let [c1, c2] = one_point_at(&p1, &p2, cut);
        let e1: Vec<f64> = v1[..cut].iter().chain(&v2[cut..]).copied().collect();
        let e2: Vec<f64> = v2[..cut].iter().chain(&v1[cut..]).copied().collect();
        assert_eq!(c1.inner_knots(), e1);
        assert_eq!(c2.inner_knots(), e2);
    }
    let [c1, _] = one_point_at(&p1, &p2, 25);
    assert_eq!(c1.knots[0], p1.knots[0]);
    assert_eq!(c1.knots[1][..7], p1.knots[1][..7]);
    assert_eq!(c1.knots[1][7..KNOTS - 1], p2.knots[1][7..KNOTS - 1]);
    // Random cuts: each child is p1's head and p2's tail at a cut in 1 … 189; over 2000
    // crossovers every cut is drawn (expected 10.6 times each).
    let mut seen = [false; 190];
    for _ in 0..2000 {
        let [c1, c2] = one_point(&p1, &p2, &mut rng);
        let (w1, w2) = (c1.inner_knots(), c2.inner_knots());
        let cut = (1..190).find(|&c| w1[..c] == v1[..c] && w1[c..] == v2[c..]).unwrap();
        assert_eq!(w2[..cut], v2[..cut]);
        assert_eq!(w2[cut..], v1[cut..]);
        seen[cut] = true;
    }
    assert!(seen[1..].iter().all(|&s| s));
}

/// Geometric crossover on the shifted range, worked out for one ω: knee parents 0 and 1
/// (limits [0, 2.2689], shifted to 1 and 2) give 2^(1−ω) − 1 and 2^ω − 1; hip pitch parents at
/// its limits −1.7453 and 0.4363 (shifted to 1 and 3.1816) give 3.1816^(1−ω) − 2.7453 and
/// 3.1816^ω − 2.7453.
#[test]
fn geometric_works_on_the_shifted_range() {
    let (mut p1, mut p2) = (with_servo(Servo::RKneePitch, 0.0), with_servo(Servo::RKneePitch, 1.0));
    let h = Servo::LHipPitch.index();
    for k in 1..KNOTS - 1 {
        p1.knots[h][k] = -1.7453;
        p2.knots[h][k] = 0.4363;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let w: f64 = rng.clone().random();
    let [c1, c2] = geometric(&p1, &p2, &mut rng);
    let k = Servo::RKneePitch.index();
    assert!((c1.knots[k][5] - (2f64.powf(1.0 - w) - 1.0)).abs() < 1e-12);
    assert!((c2.knots[k][5] - (2f64.powf(w) - 1.0)).abs() < 1e-12);
    assert!((c1.knots[h][5] - (3.1816f64.powf(1.0 - w) - 2.7453)).abs() < 1e-12);
    assert!((c2.knots[h][5] - (3.1816f64.powf(w) - 2.7453)).abs() < 1e-12);
}

/// Linear crossover's candidates: ankle parents 0.2 and 0.5 give 0.35, 0.05 and 0.65; knee
/// parents 2.0 and 0.5 give 1.25, 2.75 (clamped to 2.2689) and −0.25 (clamped to 0).
#[test]
fn linear_candidates_are_the_mean_and_two_extrapolations() {
    let (mut p1, mut p2) = (with_servo(Servo::RAnklePitch, 0.2), with_servo(Servo::RAnklePitch, 0.5));
    let kn = Servo::RKneePitch.index();
    for k in 1..KNOTS - 1 {
        p1.knots[kn][k] = 2.0;
        p2.knots[kn][k] = 0.5;
    }
    let c = linear_candidates(&p1, &p2);
    let an = Servo::RAnklePitch.index();
    let ankle = [0.35, 0.05, 0.65];
    let knee = [1.25, 2.2689, 0.0];
    for i in 0..3 {
        assert!((c[i].knots[an][7] - ankle[i]).abs() < 1e-12);
        assert!((c[i].knots[kn][7] - knee[i]).abs() < 1e-12);
        assert_eq!(c[i].knots[an][0], -0.4);
    }
}

/// The mutation, checked against its record by a second implementation: at most 10 distinct
/// intervals touched; every drawn amount within (−1/6, 1/6]; replaying the picks (move both
/// knots, skip the pinned ends, clamp) gives the child; every other knot is unchanged; a knot
/// touched once and not clamped moved by at most 1/6; the ends stay at the standing pose.
#[test]
fn mutation_moves_at_most_ten_intervals_by_a_sixth() {
    let m = model();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let step = 1.0 / 6.0;
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for _ in 0..500 {
        let parent = m.random_individual(&mut rng);
        let (child, picks) = mutate(&parent, 10, step, &mut rng);
        assert_eq!(picks.len(), 10);
        assert_eq!(child.validate(&m), Ok(()));
        let mut intervals: Vec<(usize, usize)> = picks.iter().map(|p| (p.servo, p.interval)).collect();
        intervals.sort();
        intervals.dedup();
        assert!(intervals.len() <= 10);
        let mut replay = parent.clone();
        let mut touched = [[0u32; KNOTS]; 10];
        for p in &picks {
            assert!(p.servo < 10 && p.interval < 20);
            for (j, &d) in p.moves.iter().enumerate() {
                assert!(-step < d && d <= step, "{d}");
                lo = lo.min(d);
                hi = hi.max(d);
                let k = p.interval + j;
                if k != 0 && k != KNOTS - 1 {
                    let (a, b) = Servo::ALL[p.servo].limits();
                    replay.knots[p.servo][k] = (replay.knots[p.servo][k] + d).clamp(a, b);
                    touched[p.servo][k] += 1;
                }
            }
        }
        assert_eq!(child, replay);
        for (s, row) in touched.iter().enumerate() {
            let (a, b) = Servo::ALL[s].limits();
            for (k, &times) in row.iter().enumerate() {
                let (c, p) = (child.knots[s][k], parent.knots[s][k]);
                match times {
                    0 => assert_eq!(c, p),
                    1 if c > a && c < b => assert!((c - p).abs() <= step),
                    _ => {}
                }
            }
        }
    }
    // 10 000 amounts: both ends of (−1/6, 1/6] approached within 0.001.
    assert!(lo < -step + 0.001 && hi > step - 0.001);
}
