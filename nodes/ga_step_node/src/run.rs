//! One run of the executable: the command line, a fresh or resumed state, the generation loop
//! with its outputs and progress bar, and the way it ends.

use crate::outputs::{self, CHECKPOINT};
use crate::ros_eval::RosEvaluator;
use anyhow::{anyhow, bail, Context as _};
use clap::{Parser, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use mobil_ga_step::{Crossover, Evaluator, GaSetup, GaState, StopReason};
use mobil_ga_step_sim::PhysicsEvaluator;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The crossover operator, as the option spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CrossoverArg {
    /// BLX-α (α = 0.7), an independent draw per knot and per child.
    Blx,
    /// λ·p1 + (1 − λ)·p2 and its mirror.
    Arithmetic,
    /// Swap the tails of the inner knots at a random cut.
    OnePoint,
    /// p1^ω·p2^(1−ω) on shifted values.
    Geometric,
    /// ½(p1+p2), 1.5p1 − 0.5p2, −0.5p1 + 1.5p2: the best two kept.
    Linear,
}

impl From<CrossoverArg> for Crossover {
    fn from(c: CrossoverArg) -> Crossover {
        match c {
            CrossoverArg::Blx => Crossover::Blx,
            CrossoverArg::Arithmetic => Crossover::Arithmetic,
            CrossoverArg::OnePoint => Crossover::OnePoint,
            CrossoverArg::Geometric => Crossover::Geometric,
            CrossoverArg::Linear => Crossover::Linear,
        }
    }
}

/// Who evaluates an individual.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EvaluatorArg {
    /// The built-in rigid-body simulation (rapier3d), on every core.
    Physics,
    /// An external simulator over ROS 2 (topics ga_step/candidate, ga_step/fell,
    /// ga_step/forward_distance, ga_step/fall_time), one individual at a time.
    Ros,
}

/// The command line.
#[derive(Debug, Clone, Parser)]
#[command(
    name = "ga_step",
    about = "Evolves a Nao humanoid's forward step by a genetic algorithm (SPEC §8).",
    long_about = "Evolves a Nao humanoid's forward step by a genetic algorithm (SPEC §8): ten leg servos as \
piecewise-linear functions over 20 intervals of the step time, evaluated in a physics simulation \
(or an external simulator over ROS 2), scored by the time until a fall and, for a step that does \
not fall, the forward distance.\n\n\
Writes into DIR: fitness.csv, fitness.svg, best.motion (Webots), best_gen_NNNN.motion every 10 \
generations, best_trajectory.yaml (trajectory_msgs/JointTrajectory) and checkpoint.json after every \
generation. Stops at the first non-falling forward step, when the mean fitness levels off \
(--level-window), or after G generations. Ctrl-C stops after the generation in flight (a second Ctrl-C at once); --resume \
continues to G exactly as an uninterrupted run would.",
    version
)]
pub struct Cli {
    /// Individuals per generation (and children made per generation).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub population: u32,
    /// Generations to run at most (generation 0 is the initial population).
    #[arg(long, value_name = "G")]
    pub generations: u32,
    /// Seed of the run's random numbers: the same seed gives the same run.
    #[arg(long, value_name = "S")]
    pub seed: u64,
    /// Crossover operator.
    #[arg(long, value_enum)]
    pub crossover: CrossoverArg,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Continue the run whose checkpoint is in DIR (same population, seed and crossover) up to G
    /// generations.
    #[arg(long)]
    pub resume: bool,
    /// Who evaluates an individual.
    #[arg(long, value_enum, default_value = "physics")]
    pub evaluator: EvaluatorArg,
    /// Threads evaluating the physics (0: one per core).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub threads: usize,
    /// Seconds to wait for an external simulator's answer to one candidate (--evaluator ros).
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
    pub eval_timeout: f64,
    /// Stop when the mean fitness rose by less than 0.1 % over this many generations; 0 turns
    /// the rule off (default 20, params/nao_step.yaml). A resume must repeat it.
    #[arg(long, value_name = "N")]
    pub level_window: Option<usize>,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Why it stopped.
    pub reason: StopReason,
    /// Generations done.
    pub generation: u32,
    /// Best fitness.
    pub best_fitness: f64,
    /// Whether the best falls.
    pub best_fell: bool,
    /// The best's forward distance (m).
    pub best_forward: f64,
    /// First generation with a non-falling forward step.
    pub first_step_generation: Option<u32>,
    /// Wall time of this invocation.
    pub wall: Duration,
}

impl Summary {
    /// The line printed at the end.
    pub fn line(&self, out: &Path) -> String {
        let why = match self.reason {
            StopReason::ForwardStep => "a non-falling forward step",
            StopReason::Levelled => "the mean fitness levelled off",
            StopReason::MaxGenerations => "the requested generations",
            StopReason::Interrupted => "an interrupt (resume with --resume)",
        };
        let step = match self.first_step_generation {
            Some(g) => format!("first forward step at generation {g}"),
            None => "no forward step yet".to_owned(),
        };
        format!(
            "ga_step: stopped at generation {} by {why}; best fitness {:.4} ({}, {:+.3} m forward); {step}; {:.1} s; wrote {}",
            self.generation,
            self.best_fitness,
            if self.best_fell { "falls" } else { "stands" },
            self.best_forward,
            self.wall.as_secs_f64(),
            out.display()
        )
    }
}

/// The setup the command line asks for.
pub fn setup_of(cli: &Cli) -> GaSetup {
    let mut setup = GaSetup::default();
    setup.ga.population = cli.population as usize;
    setup.ga.offspring = cli.population as usize;
    setup.ga.crossover = cli.crossover.into();
    if let Some(w) = cli.level_window {
        setup.ga.level_window = w;
    }
    setup
}

/// Checks that `dir` can be written: creates it, writes and removes a probe file.
fn check_writable(dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow!("cannot create output directory {}: {e}", dir.display()))?;
    let probe = dir.join(".ga_step.probe");
    std::fs::write(&probe, b"").map_err(|e| anyhow!("output directory {} is not writable: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Reads the checkpoint in `dir` and checks that it is the run the command line names.
fn resume_state(cli: &Cli, setup: &GaSetup) -> anyhow::Result<GaState> {
    let path = cli.out.join(CHECKPOINT);
    let state =
        mobil_ga_step::read_checkpoint(&path).map_err(|e| anyhow!("cannot resume from {}: {e}", path.display()))?;
    let mut differences = Vec::new();
    if state.seed != cli.seed {
        differences.push(format!("seed {} (asked {})", state.seed, cli.seed));
    }
    if state.setup.ga.population != setup.ga.population || state.setup.ga.offspring != setup.ga.offspring {
        differences.push(format!(
            "population {} (asked {})",
            state.setup.ga.population, setup.ga.population
        ));
    }
    if state.setup.ga.crossover != setup.ga.crossover {
        differences.push(format!(
            "crossover {} (asked {})",
            state.setup.ga.crossover, setup.ga.crossover
        ));
    }
    if state.setup.fitness.distance_on_fall != setup.fitness.distance_on_fall {
        let shape = |on: bool| {
            if on {
                "distance counted on a fall"
            } else {
                "distance counted only without a fall"
            }
        };
        differences.push(format!(
            "fitness {} (asked {})",
            shape(state.setup.fitness.distance_on_fall),
            shape(setup.fitness.distance_on_fall)
        ));
    }
    if state.setup.ga.level_window != setup.ga.level_window {
        differences.push(format!(
            "level window {} (asked {})",
            state.setup.ga.level_window, setup.ga.level_window
        ));
    }
    if state.setup.fitness.backward_allowance != setup.fitness.backward_allowance {
        differences.push(format!(
            "fitness backward allowance {} m (asked {} m)",
            state.setup.fitness.backward_allowance, setup.fitness.backward_allowance
        ));
    }
    if differences.is_empty() && state.setup != *setup {
        differences.push("other parameters of the robot, the algorithm or the fitness".to_owned());
    }
    if !differences.is_empty() {
        bail!(
            "the checkpoint in {} is of another run: {}",
            cli.out.display(),
            differences.join(", ")
        );
    }
    Ok(state)
}

/// The evaluator the command line asks for, and the threads to run it on.
enum Chosen {
    Physics(Box<PhysicsEvaluator>),
    Ros(Box<RosEvaluator>),
}

impl Chosen {
    fn evaluator(&self) -> &dyn Evaluator {
        match self {
            Chosen::Physics(p) => p.as_ref(),
            Chosen::Ros(r) => r.as_ref(),
        }
    }

    /// The error that stopped an external evaluator (its evaluations since are void).
    fn failure(&self) -> Option<String> {
        match self {
            Chosen::Physics(_) => None,
            Chosen::Ros(r) => r.failure().map(|e| e.to_string()),
        }
    }
}

/// Runs the command line to its end. `interrupt` is polled between generations.
pub fn run(cli: &Cli, interrupt: &AtomicBool) -> anyhow::Result<Summary> {
    let started = Instant::now();
    let setup = setup_of(cli);
    setup.validate().map_err(|e| anyhow!("{e}"))?;
    if !(cli.eval_timeout.is_finite() && cli.eval_timeout > 0.0) {
        bail!(
            "--eval-timeout must be a positive number of seconds, not {}",
            cli.eval_timeout
        );
    }
    check_writable(&cli.out)?;
    let checkpoint = cli.out.join(CHECKPOINT);
    let resumed = if cli.resume {
        Some(resume_state(cli, &setup)?)
    } else {
        if checkpoint.exists() {
            bail!(
                "{} already holds a run ({CHECKPOINT}); continue it with --resume or choose another --out",
                cli.out.display()
            );
        }
        None
    };
    let (chosen, threads) = match cli.evaluator {
        EvaluatorArg::Physics => (
            Chosen::Physics(Box::new(
                PhysicsEvaluator::new(setup.model.clone(), setup.fitness.clone()).map_err(|e| anyhow!("{e}"))?,
            )),
            cli.threads,
        ),
        EvaluatorArg::Ros => (
            Chosen::Ros(Box::new(
                RosEvaluator::new(
                    setup.model.clone(),
                    setup.fitness.clone(),
                    Duration::from_secs_f64(cli.eval_timeout),
                )
                .context("cannot start the ROS 2 evaluator")?,
            )),
            1,
        ),
    };
    let evaluator = chosen.evaluator();

    let bar = ProgressBar::new(cli.generations as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix} [{bar:30}] gen {pos}/{len}  {msg}  elapsed {elapsed_precise}  ETA {eta_precise}",
        )
        .map_err(|e| anyhow!("progress bar template: {e}"))?
        .progress_chars("=> "),
    );
    bar.set_prefix(format!("ga_step {}", setup.ga.crossover));
    let show = |bar: &ProgressBar, state: &GaState| {
        if let Some(s) = state.history.last() {
            bar.set_position(state.generation as u64);
            bar.set_message(format!("best {:.4}  mean {:.4}", s.max, s.mean));
        }
    };

    let mut state = match resumed {
        Some(state) => state,
        None => {
            let state = GaState::start(setup, cli.seed, evaluator, threads).map_err(|e| anyhow!("{e}"))?;
            if let Some(e) = chosen.failure() {
                bail!("{e}");
            }
            outputs::write_all(&cli.out, &state)?;
            state
        }
    };
    // A resumed run rewrites its outputs from the checkpoint (they may be older than it).
    if cli.resume {
        outputs::write_all(&cli.out, &state)?;
    }
    bar.reset_eta();
    show(&bar, &state);

    let mut failure: Option<anyhow::Error> = None;
    let reason = if interrupt.load(Ordering::SeqCst) {
        StopReason::Interrupted
    } else {
        state.run(evaluator, threads, cli.generations, |s| {
            if let Some(e) = chosen.failure() {
                // The generation just made holds void evaluations: keep the last checkpoint.
                failure = Some(anyhow!("{e}"));
                return ControlFlow::Break(());
            }
            if let Err(e) = outputs::write_all(&cli.out, s) {
                failure = Some(e);
                return ControlFlow::Break(());
            }
            show(&bar, s);
            if interrupt.load(Ordering::SeqCst) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
    };
    bar.finish_and_clear();
    if let Some(e) = failure {
        return Err(e);
    }
    let best = state.best();
    Ok(Summary {
        reason,
        generation: state.generation,
        best_fitness: best.fitness(),
        best_fell: best.evaluation.fell,
        best_forward: best.evaluation.forward_distance,
        first_step_generation: state.first_step_generation,
        wall: started.elapsed(),
    })
}
