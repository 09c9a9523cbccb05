//! The genetic algorithm's and the fitness formula's parameters, each default justified on its
//! field or on the docs page it cites; `params/nao_step.yaml` holds the same values (its test
//! loads it). Both structs deserialize from a flat parameter section: a missing key takes its
//! default.

use crate::error::GaError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The built-in physics' model of the robot (the parameter `physics`; the built-in physics
/// only, an external simulator has its own).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PhysicsModel {
    /// The Nao of Webots, the source's simulator: its motors (position control by velocity,
    /// maxTorque, maxVelocity), its foot and the floor contact of its Nao worlds, 20 ms steps
    /// (docs/ga_step.md, "The physics evaluator").
    #[default]
    Webots,
    /// The earlier model from Aldebaran's motor datasheet: a PD servo limited to the motor's
    /// continuous torque, μ 0.8, 5 ms steps (docs/experiments/ga-step-physics.md).
    DcMotor,
}

impl PhysicsModel {
    /// The parameter's spelling: `webots` or `dc-motor`.
    pub fn name(self) -> &'static str {
        match self {
            PhysicsModel::Webots => "webots",
            PhysicsModel::DcMotor => "dc-motor",
        }
    }
}

impl std::fmt::Display for PhysicsModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The crossover operator of a run (SPEC §8; the names are the `--crossover` option's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Crossover {
    /// BLX-α: each child value uniform in [min − α·d, max + α·d], d = |p1 − p2|.
    Blx,
    /// λ·p1 + (1 − λ)·p2 and the mirror, one λ per crossover.
    Arithmetic,
    /// Swap the tails of the flattened inner-knot vector at a random cut.
    OnePoint,
    /// p1^ω·p2^(1−ω) on values shifted to [1, 1 + max − min], one ω per crossover.
    Geometric,
    /// ½(p1 + p2), 1.5·p1 − 0.5·p2, −0.5·p1 + 1.5·p2: the best two by fitness.
    Linear,
}

impl Crossover {
    /// All five, in the SPEC's order.
    pub const ALL: [Crossover; 5] = [
        Crossover::OnePoint,
        Crossover::Arithmetic,
        Crossover::Geometric,
        Crossover::Linear,
        Crossover::Blx,
    ];

    /// The option's spelling: `blx`, `arithmetic`, `one-point`, `geometric`, `linear`.
    pub fn name(self) -> &'static str {
        match self {
            Crossover::Blx => "blx",
            Crossover::Arithmetic => "arithmetic",
            Crossover::OnePoint => "one-point",
            Crossover::Geometric => "geometric",
            Crossover::Linear => "linear",
        }
    }
}

impl fmt::Display for Crossover {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Crossover {
    type Err = GaError;
    fn from_str(s: &str) -> Result<Self, GaError> {
        Crossover::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| GaError::UnknownCrossover(s.to_owned()))
    }
}

/// How BLX-α draws its random positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BlxVariant {
    /// Standard BLX-α (SPEC Decision, as in the source's cited reference): an independent draw
    /// per knot and per child.
    PerKnot,
    /// The source's code: one draw per crossover for every knot of both children, which are
    /// therefore identical.
    SingleDraw,
}

/// The genetic algorithm's parameters (the population size, the crossover and the seed are the
/// executable's options; the rest are the SPEC's values or Decisions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GaConfig {
    /// Individuals kept per generation. Default 100, the source's.
    pub population: usize,
    /// Children made per generation before replacement (each evaluated once; the linear
    /// crossover evaluates three candidates per two children). Default 100, one population's
    /// worth: the source does not say (GAAP's breeder), and λ = μ keeps one generation's cost at
    /// 100 evaluations (plus the linear crossover's extra third).
    pub offspring: usize,
    /// The crossover operator. Default BLX-α, the source's best.
    pub crossover: Crossover,
    /// α of BLX-α. Default 0.7, the source's.
    pub blx_alpha: f64,
    /// BLX-α's draws. Default [`BlxVariant::PerKnot`] (SPEC Decision).
    pub blx_variant: BlxVariant,
    /// Roulette weight of crossover when choosing the operator of the next offspring. Default
    /// 0.7 (the source's `RouletteSelector(0.7)` beside the crossover).
    pub crossover_weight: f64,
    /// Roulette weight of mutation. Default 0.3, the source's "mutation 0.3" (SPEC: a share of
    /// offspring, not a per-child probability).
    pub mutation_weight: f64,
    /// (servo, interval) picks per mutation, with replacement. Default 10, the source's code.
    pub mutation_picks: usize,
    /// Half-width (rad) of the uniform move of each picked knot. Default 1/6, the source's
    /// `(0.5 − random)/3`.
    pub mutation_step: f64,
    /// Generations over which the mean fitness must rise by `level_tolerance` for the run to go
    /// on; 0 turns the rule off. Default 20, a seventh of the source's slower run (see
    /// docs/ga_step.md, "Stopping").
    pub level_window: usize,
    /// Relative rise of the mean fitness over `level_window` generations below which it has
    /// levelled off. Default 0.001 (0.1 %): the mean can only rise under best-N replacement,
    /// so a rise this small over 20 generations means nearly every child is worse than the
    /// population it would join.
    pub level_tolerance: f64,
    /// Stop as soon as the best individual makes a non-falling forward step (the source stopped
    /// its runs there). Default true.
    pub stop_at_step: bool,
}

impl Default for GaConfig {
    fn default() -> Self {
        GaConfig {
            population: 100,
            offspring: 100,
            crossover: Crossover::Blx,
            blx_alpha: 0.7,
            blx_variant: BlxVariant::PerKnot,
            crossover_weight: 0.7,
            mutation_weight: 0.3,
            mutation_picks: 10,
            mutation_step: 1.0 / 6.0,
            level_window: 20,
            level_tolerance: 0.001,
            stop_at_step: true,
        }
    }
}

/// The largest population (and offspring count): 10 000, a hundred times the source's 100. Its
/// checkpoint is about 40 MB, written every generation, and one generation takes the built-in
/// physics minutes (see docs/ga_step.md, "Checkpoints and resume" and "Speed").
pub const MAX_POPULATION: usize = 10_000;

pub(crate) fn check(name: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<(), GaError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(GaError::InvalidConfig { name, value, reason })
    }
}

impl GaConfig {
    /// Checks a population of at least 2 and offspring of at least 1 (both at most
    /// [`MAX_POPULATION`]),
    /// α ≥ 0, non-negative operator weights with a positive sum, a positive mutation step, a
    /// window of at least 1 and a non-negative tolerance.
    pub fn validate(&self) -> Result<(), GaError> {
        let p = self.population as f64;
        check(
            "population",
            p,
            (2..=MAX_POPULATION).contains(&self.population),
            "must be within 2 … 10 000",
        )?;
        let o = self.offspring as f64;
        check(
            "offspring",
            o,
            (1..=MAX_POPULATION).contains(&self.offspring),
            "must be within 1 … 10 000",
        )?;
        check("blx_alpha", self.blx_alpha, self.blx_alpha >= 0.0, "must be ≥ 0")?;
        check(
            "crossover_weight",
            self.crossover_weight,
            self.crossover_weight >= 0.0,
            "must be ≥ 0",
        )?;
        check(
            "mutation_weight",
            self.mutation_weight,
            self.mutation_weight >= 0.0,
            "must be ≥ 0",
        )?;
        let sum = self.crossover_weight + self.mutation_weight;
        check(
            "mutation_weight",
            sum,
            sum > 0.0,
            "crossover_weight + mutation_weight must be > 0",
        )?;
        let picks = self.mutation_picks as f64;
        check(
            "mutation_picks",
            picks,
            self.mutation_picks <= 1_000_000,
            "must be at most 1 000 000",
        )?;
        check(
            "mutation_step",
            self.mutation_step,
            self.mutation_step > 0.0,
            "must be > 0",
        )?;
        check(
            "level_tolerance",
            self.level_tolerance,
            self.level_tolerance >= 0.0,
            "must be ≥ 0",
        )
    }
}

/// The fitness of an evaluation and the fall test an evaluator applies (SPEC §8 Decision, read
/// so that a fall never pays and an upright step is ranked by how far it goes): f = t_fall / T_sim
/// for a step that falls (< 1), and f = 1 + w·max(0, Δx + b) for one that does not (≥ 1), b the
/// [`backward_allowance`](FitnessConfig::backward_allowance). T_sim = T + `settle_time`. So a fall
/// < any upright individual ≤ standing still (1 + w·b) < a forward step: no fall can outscore an
/// upright individual, and among upright ones a shuffle backward scores less than standing, a
/// forward step more, by its signed distance. Two earlier shapes stay selectable: b = 0 gives
/// f = 1 + w·max(0, Δx), under which every upright individual that does not gain ground scores
/// exactly 1 (runs bred backward shufflers and levelled off there); and
/// [`distance_on_fall`](FitnessConfig::distance_on_fall) with b = 0 is the SPEC's example,
/// f = t_fall / T_sim + w·max(0, Δx) for every step, under which a forward lunge that falls at
/// 1–2 s scores above standing and above any short upright step, and selection breeds lunges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FitnessConfig {
    /// Time (s) simulated after the step ends, with the servos holding the standing pose, so a
    /// step that ends off balance is seen to fall. Default 1.0 s: half the step again; a Nao
    /// tipping from rest off its support edge is down in well under a second (a 0.3 m inverted
    /// pendulum's time constant √(h/g) is 0.17 s).
    pub settle_time: f64,
    /// w (1/m): fitness per metre of forward distance. Default 2.0: not falling for the whole
    /// time scores at least 1 (standing still 1 + w·b = 3), and a 10 cm step adds 0.2, so a fall before 80 % of T_sim loses more than
    /// a 10 cm gain buys back (staying up matters most, as in the source: its robots first
    /// learned not to fall), while among non-falling individuals distance decides.
    pub forward_weight: f64,
    /// h₀ (m): the torso frame below this height is a fall. Default 0.20, below the 0.214 m of
    /// a full squat (the standing pose: about 0.32 m), so the rule is a backstop to the tilt and
    /// floor-contact rules (see docs/ga_step.md, "Fitness").
    pub fall_height: f64,
    /// θ₀ (rad): a torso tilted more than this from upright (pitch or roll) is a fall. Default
    /// 0.5 rad (29°): a Nao standing with its torso leaning that far has its centre of mass
    /// beyond its feet.
    pub fall_tilt: f64,
    /// Forward distance (m) that makes a non-falling step "a forward step" (the stop rule).
    /// Default 0.04 m, the default maximum step length of Nao's own walk (ALMotion's MaxStepX).
    pub step_min_forward: f64,
    /// Whether a fall's forward distance counts too: `true` is the SPEC's example shape
    /// f = t_fall / T_sim + w·max(0, Δx) for every step, `false` counts distance only for a step
    /// that does not fall. Default `false`: with a fall's distance counted, runs bred falling
    /// lunges (see docs/experiments/ga-step-fitness.md).
    pub distance_on_fall: bool,
    /// b (m), ≥ 0: the backward distance an upright individual may move before its fitness
    /// bottoms out at 1, f = 1 + w·max(0, Δx + b). Default 1.0 m; 0 gives the upright-only shape,
    /// under which runs bred backward shufflers (see docs/experiments/ga-step-fitness.md).
    pub backward_allowance: f64,
    /// Whether the built-in physics also scores an individual under a second solver setting and
    /// keeps the worse outcome (a fall under either is a fall, at the earlier time; upright under
    /// both scores the smaller Δx). Default `true` (see docs/experiments/ga-step-physics.md). The
    /// built-in physics refuses it with [`distance_on_fall`](Self::distance_on_fall); others ignore it.
    pub robust_check: bool,
    /// The built-in physics' model of the robot. Default [`PhysicsModel::Webots`]; others
    /// ignore it.
    pub physics: PhysicsModel,
}

impl Default for FitnessConfig {
    fn default() -> Self {
        FitnessConfig {
            settle_time: 1.0,
            forward_weight: 2.0,
            fall_height: 0.20,
            fall_tilt: 0.5,
            step_min_forward: 0.04,
            distance_on_fall: false,
            backward_allowance: 1.0,
            robust_check: true,
            physics: PhysicsModel::Webots,
        }
    }
}

impl FitnessConfig {
    /// Checks settle time ≥ 0, w ≥ 0, h₀ > 0, 0 < θ₀ < π/2, a step distance ≥ 0 and a backward
    /// allowance ≥ 0.
    pub fn validate(&self) -> Result<(), GaError> {
        check("settle_time", self.settle_time, self.settle_time >= 0.0, "must be ≥ 0")?;
        check(
            "forward_weight",
            self.forward_weight,
            self.forward_weight >= 0.0,
            "must be ≥ 0",
        )?;
        check("fall_height", self.fall_height, self.fall_height > 0.0, "must be > 0")?;
        check(
            "fall_tilt",
            self.fall_tilt,
            self.fall_tilt > 0.0 && self.fall_tilt < std::f64::consts::FRAC_PI_2,
            "must be within (0, π/2)",
        )?;
        check(
            "step_min_forward",
            self.step_min_forward,
            self.step_min_forward >= 0.0,
            "must be ≥ 0",
        )?;
        check(
            "backward_allowance",
            self.backward_allowance,
            self.backward_allowance >= 0.0,
            "must be ≥ 0",
        )
    }

    /// The shape's description for messages: which distance counts, and the allowance.
    pub fn shape(&self) -> String {
        let fall = if self.distance_on_fall {
            "distance counted on a fall"
        } else {
            "distance counted only without a fall"
        };
        format!("{fall}, backward allowance {} m", self.backward_allowance)
    }

    /// T_sim (s): the simulated duration of one evaluation, the step time plus the settle time.
    pub fn sim_time(&self, step_time: f64) -> f64 {
        step_time + self.settle_time
    }

    /// The fitness of a step (see [`FitnessConfig`]): `t_fall` is the time of the fall, `None`
    /// without one. A fall scores t_fall / T_sim, t_fall clamped into [0, T_sim] (plus
    /// w·max(0, Δx) with [`FitnessConfig::distance_on_fall`]); no fall scores 1 + w·max(0, Δx + b).
    /// Never negative; a non-finite input gives 0.
    pub fn fitness(&self, step_time: f64, t_fall: Option<f64>, forward_distance: f64) -> f64 {
        let t_sim = self.sim_time(step_time);
        let distance = self.forward_weight * forward_distance.max(0.0);
        let f = match t_fall {
            None => 1.0 + self.forward_weight * (forward_distance + self.backward_allowance).max(0.0),
            Some(t) if self.distance_on_fall => t.clamp(0.0, t_sim) / t_sim + distance,
            // A NaN distance still makes the fitness 0 below, as under the other shape.
            Some(t) => t.clamp(0.0, t_sim) / t_sim + 0.0 * forward_distance,
        };
        if f.is_finite() {
            f
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert_eq!(GaConfig::default().validate(), Ok(()));
        assert_eq!(FitnessConfig::default().validate(), Ok(()));
    }

    #[test]
    fn crossover_names_round_trip() {
        for c in Crossover::ALL {
            assert_eq!(c.name().parse::<Crossover>(), Ok(c));
        }
        assert_eq!("blx".parse::<Crossover>(), Ok(Crossover::Blx));
        assert_eq!("one-point".parse::<Crossover>(), Ok(Crossover::OnePoint));
        assert!(matches!(
            "onepoint".parse::<Crossover>(),
            Err(GaError::UnknownCrossover(_))
        ));
    }

    #[test]
    fn bad_values_are_refused() {
        let c = GaConfig {
            population: 1,
            ..GaConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(GaError::InvalidConfig { name: "population", .. })
        ));
        let c = GaConfig {
            crossover_weight: 0.0,
            mutation_weight: 0.0,
            ..GaConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(GaError::InvalidConfig {
                name: "mutation_weight",
                ..
            })
        ));
        let c = GaConfig {
            blx_alpha: f64::NAN,
            ..GaConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(GaError::InvalidConfig { name: "blx_alpha", .. })
        ));
        let f = FitnessConfig {
            fall_tilt: 2.0,
            ..FitnessConfig::default()
        };
        assert!(matches!(
            f.validate(),
            Err(GaError::InvalidConfig { name: "fall_tilt", .. })
        ));
        for b in [-0.1, f64::NAN] {
            let f = FitnessConfig {
                backward_allowance: b,
                ..FitnessConfig::default()
            };
            assert!(matches!(
                f.validate(),
                Err(GaError::InvalidConfig {
                    name: "backward_allowance",
                    ..
                })
            ));
        }
    }

    #[test]
    fn an_upright_individual_is_ranked_by_its_signed_distance() {
        let f = FitnessConfig::default();
        // T = 2 s, T_sim = 3 s, w = 2 /m, b = 1 m.
        assert_eq!((f.forward_weight, f.backward_allowance), (2.0, 1.0));
        let eq = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // A fall at 1.5 s: 1.5/3 = 0.5, whatever its distance.
        assert!(eq(f.fitness(2.0, Some(1.5), 0.3), 0.5));
        assert!(eq(f.fitness(2.0, Some(1.5), -0.5), 0.5));
        // Upright, 0.5 m backward: 1 + 2·(−0.5 + 1) = 2.0.
        assert!(eq(f.fitness(2.0, None, -0.5), 2.0));
        // Standing still: 1 + 2·1 = 3.0.
        assert!(eq(f.fitness(2.0, None, 0.0), 3.0));
        // Upright, 0.1 m forward: 1 + 2·1.1 = 3.2.
        assert!(eq(f.fitness(2.0, None, 0.1), 3.2));
        // Upright, 1.2 m backward: 1 + 2·max(0, −0.2) = 1.0, still above every fall.
        assert!(eq(f.fitness(2.0, None, -1.2), 1.0));
        assert!(f.fitness(2.0, Some(3.0), 5.0) <= f.fitness(2.0, None, -5.0));
    }

    #[test]
    fn a_zero_allowance_is_the_previous_shape() {
        let f = FitnessConfig {
            backward_allowance: 0.0,
            ..FitnessConfig::default()
        };
        // T = 2 s, T_sim = 3 s, w = 2 /m.
        // No fall, 5 cm forward: 1 + 2·0.05 = 1.1.
        assert!((f.fitness(2.0, None, 0.05) - 1.1).abs() < 1e-12);
        // A fall at 1.5 s, 10 cm forward: 1.5/3 = 0.5, the distance does not count.
        assert!((f.fitness(2.0, Some(1.5), 0.10) - 0.5).abs() < 1e-12);
        // Backwards counts as 0; t_fall beyond T_sim counts as T_sim, below 0 as 0.
        assert!((f.fitness(2.0, None, -0.3) - 1.0).abs() < 1e-12);
        assert!((f.fitness(2.0, Some(9.0), 0.2) - 1.0).abs() < 1e-12);
        assert_eq!(f.fitness(2.0, Some(-1.0), 0.2), 0.0);
        // Non-finite inputs score 0.
        assert_eq!(f.fitness(2.0, Some(f64::NAN), 0.1), 0.0);
        assert_eq!(f.fitness(2.0, None, f64::INFINITY), 0.0);
        assert_eq!(f.fitness(2.0, Some(1.0), f64::NAN), 0.0);
    }

    #[test]
    fn a_lunge_that_falls_scores_below_standing_and_below_an_upright_step() {
        let f = FitnessConfig {
            backward_allowance: 0.0,
            ..FitnessConfig::default()
        };
        assert!(!f.distance_on_fall);
        // The lunge: falls at 1.5 s of T_sim = 3 s, 0.8 m forward: 1.5/3 = 0.5.
        let lunge = f.fitness(2.0, Some(1.5), 0.8);
        // Standing still for all of T_sim: 1. An upright 10 cm step: 1 + 2·0.1 = 1.2.
        let standing = f.fitness(2.0, None, 0.0);
        let step = f.fitness(2.0, None, 0.1);
        assert!((lunge - 0.5).abs() < 1e-12, "{lunge}");
        assert_eq!(standing, 1.0);
        assert!((step - 1.2).abs() < 1e-12, "{step}");
        // A fall at the very end still scores at most standing still's 1.
        assert!(f.fitness(2.0, Some(3.0), 5.0) <= standing);
    }

    #[test]
    fn the_spec_example_shape_counts_a_falls_distance() {
        let f = FitnessConfig {
            distance_on_fall: true,
            backward_allowance: 0.0,
            ..FitnessConfig::default()
        };
        // The same lunge: 0.5 + 2·0.8 = 2.1, above standing (1.0) and the 10 cm step (1.2).
        assert!((f.fitness(2.0, Some(1.5), 0.8) - 2.1).abs() < 1e-12);
        assert!((f.fitness(2.0, None, 0.1) - 1.2).abs() < 1e-12);
        assert_eq!(f.fitness(2.0, None, 0.0), 1.0);
        // A fall at 80 % of T_sim (2.4 s) with 10 cm: 0.8 + 0.2 = 1.0, as standing still.
        assert!((f.fitness(2.0, Some(2.4), 0.1) - 1.0).abs() < 1e-12);
    }
}
