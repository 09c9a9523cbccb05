//! One run of the executable: the command line, a fresh or resumed state, the generation loop
//! with its outputs and progress bar, and the way it ends.

use crate::outputs;
use crate::ros_eval::{RosEvalError, RosEvaluator, MAX_IN_FLIGHT};
use anyhow::{anyhow, bail, Context as _};
use clap::{Parser, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use mobil_ga_step::output::{remove_temporaries, CHECKPOINT};
use mobil_ga_step::{
    check_resume, Crossover, Evaluator, EvaluatorTag, GaSetup, GaState, ResumeRefusal, RunSummary, StopReason,
    MAX_POPULATION,
};
use mobil_ga_step_sim::{PhysicsEvaluator, PHYSICS_VERSION};
use mobil_ros::args::RosArgs;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The longest `--eval-timeout` (s): one day. Longer is no timeout at all, and past about
/// 10¹¹ s a deadline no longer fits the clock.
pub const MAX_EVAL_TIMEOUT_S: f64 = 86_400.0;

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
    /// An external simulator over ROS 2 (topics ga_step/candidate and ga_step/outcome; node
    /// name, namespace and topics remapped by --ros-args -r …), one individual at a time per
    /// simulator; with --pool, simulators serving the same topics in namespaces below the
    /// node's share the candidates.
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
(--level-window), or after G generations. Ctrl-C stops after the generation in flight (with \
--evaluator ros at once, the generation in flight lost); a second Ctrl-C stops at once, after the \
file being written if any; --resume continues to G exactly as an uninterrupted run would.\n\n\
With --evaluator ros, ROS arguments follow --ros-args (e.g. --ros-args -r __ns:=/sim1 \
-r ga_step/candidate:=/webots/candidate).",
    version
)]
pub struct Cli {
    /// Individuals per generation (and children made per generation).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=MAX_POPULATION as i64))]
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
    /// Threads evaluating the physics (0: one per core); with --evaluator ros, the most candidates
    /// in flight at once, one per simulator (0: 64).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub threads: usize,
    /// Seconds to wait for an external simulator's answer to one candidate, and for a simulator
    /// to appear (--evaluator ros); at most 86400.
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
    pub eval_timeout: f64,
    /// With --evaluator ros: also use every simulator serving the topics in a namespace below
    /// the node's (e.g. /sim1/ga_step/candidate), found as it appears, one candidate each.
    #[arg(long)]
    pub pool: bool,
    /// Parameter file of the robot, the fitness and the algorithm (params/nao_step.yaml's
    /// form); without it the built-in defaults, which are that file's values. A resume must
    /// repeat it.
    #[arg(long, value_name = "FILE")]
    pub params: Option<PathBuf>,
    /// Stop when the mean fitness rose by less than the parameter file's level_tolerance over
    /// this many generations; 0 turns the rule off (without it: the file's level_window). A
    /// resume must repeat it.
    #[arg(long, value_name = "N")]
    pub level_window: Option<usize>,
    /// Print the options and the parameter file's keys as Markdown tables (as docs/ has them)
    /// and exit. Given alone; the executable answers it before parsing the other options.
    #[arg(long, exclusive = true)]
    pub params_markdown: bool,
    /// Testing only: pause this many ms inside each output's write (after its temporary file is
    /// written, before the rename), holding the write lock.
    #[arg(long, value_name = "MS", default_value_t = 0, hide = true)]
    pub write_delay_ms: u64,
}

/// The command line's options as a Markdown table (option, value, default, description), from
/// the one declaration above; hidden options are left out.
pub fn options_markdown() -> String {
    use clap::CommandFactory as _;
    use mobil_ros::docs::{cell, markdown_table};
    let command = Cli::command();
    let rows: Vec<Vec<String>> = command
        .get_arguments()
        .filter(|a| !a.is_hide_set())
        .filter_map(|a| {
            let long = a.get_long()?;
            let takes_value = a.get_action().takes_values();
            let choices: Vec<String> = a
                .get_possible_values()
                .iter()
                .filter(|_| takes_value)
                .map(|v| format!("`{}`", v.get_name()))
                .collect();
            let value = if !takes_value {
                String::new()
            } else if !choices.is_empty() {
                choices.join(", ")
            } else {
                a.get_value_names()
                    .map(|n| n.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" "))
                    .unwrap_or_default()
            };
            let defaults: Vec<String> = a
                .get_default_values()
                .iter()
                .map(|v| format!("`{}`", v.to_string_lossy()))
                .collect();
            let default = if a.is_required_set() {
                "required".to_owned()
            } else {
                defaults.join(", ")
            };
            let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
            Some(vec![format!("`--{long}`"), cell(&value), default, cell(&help)])
        })
        .collect();
    markdown_table(&["option", "value", "default", "description"], &rows)
}

/// The setup the command line asks for: the parameter file's (or the defaults) with the
/// options' population, crossover and level window.
pub fn setup_of(cli: &Cli) -> anyhow::Result<GaSetup> {
    let mut setup = match &cli.params {
        Some(path) => mobil_ga_step::params::read_setup(path)?,
        None => GaSetup::default(),
    };
    setup.ga.population = cli.population as usize;
    setup.ga.offspring = cli.population as usize;
    setup.ga.crossover = cli.crossover.into();
    if let Some(w) = cli.level_window {
        setup.ga.level_window = w;
    }
    Ok(setup)
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
fn resume_state(cli: &Cli, setup: &GaSetup, asked: &EvaluatorTag) -> anyhow::Result<GaState> {
    let path = cli.out.join(CHECKPOINT);
    let (state, recorded) = mobil_ga_step::read_checkpoint_tagged(&path)
        .map_err(|e| anyhow!("cannot resume from {}: {e}", path.display()))?;
    match check_resume(&state, &recorded, cli.seed, setup, asked) {
        Ok(()) => {}
        Err(ResumeRefusal::Retired) => bail!(
            "cannot resume from {}: its run was scored by the robust score with a fall's distance counted, which is no longer offered (the worse of two outcomes is not the lower score there)",
            path.display()
        ),
        Err(ResumeRefusal::OtherRun(differences)) => bail!(
            "the checkpoint in {} is of another run: {}",
            cli.out.display(),
            differences.join(", ")
        ),
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
    fn failure(&self) -> Option<RosEvalError> {
        match self {
            Chosen::Physics(_) => None,
            Chosen::Ros(r) => r.failure(),
        }
    }

    /// An external evaluator's void scores (candidates unanswered, scored 0).
    fn void_scores(&self) -> Option<u64> {
        match self {
            Chosen::Physics(_) => None,
            Chosen::Ros(r) => Some(r.void_scores()),
        }
    }
}

/// The evaluator `arg` names, as a checkpoint records it.
pub fn evaluator_tag(arg: EvaluatorArg) -> EvaluatorTag {
    match arg {
        EvaluatorArg::Physics => EvaluatorTag::Physics {
            physics_version: PHYSICS_VERSION,
        },
        EvaluatorArg::Ros => EvaluatorTag::Ros,
    }
}

/// An interrupt that came before generation 0 was whole: no output was written (DIR itself
/// may have been created).
#[derive(Debug, thiserror::Error)]
#[error("interrupted during generation 0; no output written")]
pub struct InterruptedBeforeStart;

/// Runs the command line to its end. `interrupt` is polled between generations, and by the ROS
/// evaluator while it waits; `ros_args` name, place and remap the ROS evaluator's node.
pub fn run(cli: &Cli, ros_args: &RosArgs, interrupt: &Arc<AtomicBool>) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let setup = setup_of(cli)?;
    setup.validate().map_err(|e| anyhow!("{e}"))?;
    let timeout_ok = cli.eval_timeout.is_finite() && cli.eval_timeout > 0.0 && cli.eval_timeout <= MAX_EVAL_TIMEOUT_S;
    if cli.evaluator == EvaluatorArg::Ros && !timeout_ok {
        bail!(
            "--eval-timeout must be a number of seconds within (0, {MAX_EVAL_TIMEOUT_S}], not {}",
            cli.eval_timeout
        );
    }
    if cli.pool && cli.evaluator != EvaluatorArg::Ros {
        bail!("--pool needs --evaluator ros");
    }
    let tag = evaluator_tag(cli.evaluator);
    // The built-in physics refuses a setup it cannot score before anything is created in DIR.
    let physics = match cli.evaluator {
        EvaluatorArg::Physics => {
            Some(PhysicsEvaluator::new(setup.model.clone(), setup.fitness.clone()).map_err(|e| anyhow!("{e}"))?)
        }
        EvaluatorArg::Ros => None,
    };
    // The checkpoint is judged before anything is created in DIR.
    let checkpoint = cli.out.join(CHECKPOINT);
    let resumed = if cli.resume {
        Some(resume_state(cli, &setup, &tag)?)
    } else {
        if checkpoint.exists() {
            bail!(
                "{} already holds a run ({CHECKPOINT}); continue it with --resume or choose another --out",
                cli.out.display()
            );
        }
        None
    };
    check_writable(&cli.out)?;
    outputs::WRITE_DELAY_MS.store(cli.write_delay_ms, Ordering::Relaxed);
    let (chosen, threads) = match physics {
        Some(p) => (Chosen::Physics(Box::new(p)), cli.threads),
        None => (
            Chosen::Ros(Box::new(
                RosEvaluator::new(
                    setup.model.clone(),
                    setup.fitness.clone(),
                    Duration::from_secs_f64(cli.eval_timeout),
                    cli.pool,
                    ros_args,
                    interrupt.clone(),
                )
                .context("cannot start the ROS 2 evaluator")?,
            )),
            // A thread per candidate in flight: each waits for a free simulator.
            if cli.threads == 0 { MAX_IN_FLIGHT } else { cli.threads },
        ),
    };
    let evaluator = chosen.evaluator();
    // Once the evaluator is up, just before the first write: a run that could not start leaves
    // DIR as it was.
    remove_temporaries(&cli.out);

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
            let void = match chosen.void_scores() {
                Some(v) if v > 0 => format!("  unanswered {v}"),
                _ => String::new(),
            };
            bar.set_message(format!("best {:.4}  mean {:.4}{void}", s.max, s.mean));
        }
    };

    let mut state = match resumed {
        Some(state) => state,
        None => {
            let state = GaState::start(setup, cli.seed, evaluator, threads).map_err(|e| anyhow!("{e}"))?;
            match chosen.failure() {
                Some(RosEvalError::Interrupted(_)) => return Err(InterruptedBeforeStart.into()),
                Some(e) => bail!("{e}"),
                None => {}
            }
            outputs::write_all(&cli.out, &state, &tag)?;
            state
        }
    };
    // A resumed run rewrites its outputs from the checkpoint (they may be older than it).
    if cli.resume {
        outputs::write_all(&cli.out, &state, &tag)?;
    }
    bar.reset_eta();
    show(&bar, &state);

    let mut failure: Option<anyhow::Error> = None;
    // Set when the generation just made is void (an interrupted external evaluation).
    let mut lost = false;
    let reason = if interrupt.load(Ordering::SeqCst) {
        StopReason::Interrupted
    } else {
        state.run(evaluator, threads, cli.generations, |s| {
            match chosen.failure() {
                // The generation just made holds void evaluations: keep the last checkpoint.
                Some(RosEvalError::Interrupted(_)) => {
                    lost = true;
                    return ControlFlow::Break(());
                }
                Some(e) => {
                    failure = Some(anyhow!("{e}"));
                    return ControlFlow::Break(());
                }
                None => {}
            }
            if let Err(e) = outputs::write_all(&cli.out, s, &tag) {
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
    RunSummary::of(&state, reason, lost, started.elapsed(), chosen.void_scores())
        .ok_or_else(|| anyhow!("no statistics of the generation the outputs hold"))
}
