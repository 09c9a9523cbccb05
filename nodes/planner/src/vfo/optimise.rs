//! Algorithm 2 of the VFO paper (findSigmas), as SPEC §5 states it: virtual robots — the
//! [`VfoController`] (with Algorithm 3) and unicycle kinematics — simulated from the segment's
//! start choose the decisions Σ that maximise Ψ_z.
//!
//! - A virtual robot stops on entering the influence zone of any obstacle (d_k crossing R_k
//!   from outside), even one whose σ is set, even inside other zones; a start inside a zone is
//!   an entry at t = 0 (one stop per such zone, in index order).
//! - At each stop the edge (p_last, p_j, Σ_v) is formed (p_last the previous stop's obstacle,
//!   `None` at the start; Σ_v before σ_j is set). An edge already in the branch's set means a
//!   cyclic path: the branch is dropped. Otherwise it is added, the indices merged, and, if σ_j
//!   is undecided, the branch continues with σ_j = +1 and a copy with σ_j = −1 is pushed.
//! - A path ends as a candidate when the law reaches the waypoint (Algorithm 1, or the end test
//!   at the last waypoint), or is dropped on a collision (d ≤ r), a cycle, or when its simulated
//!   time exceeds [`path_time_limit`] (a warning).
//! - Candidates are normalised together and the largest Ψ_z wins; ties (within 1e-12) go to
//!   fewer decided σ, then to the lexicographically smaller Σ (undecided < +1 < −1).
//! - Caps: at most `max_virtual_robots` virtual robots and `max_total_time_s` of simulated time
//!   per optimisation; when one is hit the pending branches are abandoned and the best
//!   candidate so far is returned with a warning.
//! - **Interrupts** ([`find_sigmas_until`]): the caller's closure is asked before every batch
//!   and every [`INTERRUPT_CHECK_STEPS`] steps of each virtual robot. [`Interrupt::Cancel`]
//!   (the result is no longer wanted: a cancel, a new goal, shutdown) ends the optimisation at
//!   once with [`PlannerError::Stopped`]; [`Interrupt::Budget`] (the caller's wall-clock budget
//!   is spent) abandons the virtual robots under way and the pending branches and returns the
//!   best candidate so far with [`OptimiseWarning::WallTimeBudget`], as the caps do. The clock
//!   is the caller's: the library reads none.
//!
//! **Parallel branches.** The pending branches are a stack (LIFO, depth first). The optimiser
//! pops up to `batch` branches at a time (the top of the stack first), simulates them — one
//! virtual robot each, up to its next stop — on up to `threads` threads
//! (`std::thread::scope`), then handles the results in pop order, pushing each one's children
//! (−1 first, so +1 is on top). The schedule depends on `batch` alone, never on the number of
//! threads, so the result (Σ, every virtual robot, every warning) is the same on any machine;
//! the caps are checked between batches. Threads are used for batches of at least
//! [`PARALLEL_MIN_BATCH`] branches, where they can pay (the bench measures it).
//! `std::thread::scope` needs no dependency: each task is a whole virtual robot, coarse
//! enough that a work-stealing pool (rayon) would have nothing to balance.

use std::num::NonZeroUsize;

use mobil_geom::Pose2;
use nalgebra::Point2;

use super::controller::{integrate_unicycle, StepOutcome, VfoController, VfoWaypoint};
use super::obstacles::{Obstacle, Sigma};
use super::quality::{normalised, path_score, PathIndices, QualityWeights};
use crate::error::{positive_finite, PlannerError};

/// Settings of Algorithm 2; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimiseConfig {
    /// K_D, K_B, K_E, K_S. Default the paper's {1, 2, 1, 1}.
    pub weights: QualityWeights,
    /// T_p (s): the virtual robots' integration step and the indices' sampling period (SPEC
    /// §5 Decision: T_p = the integration step). Default 0.01 s: 3 mm of path at 0.3 m/s. A node
    /// stepping once per odometry message sets it to that period (`vfo.time_step`).
    pub time_step: f64,
    /// Most virtual robots per optimisation. Default 4096: 2^12 leaves, far beyond the |D| of
    /// any layout the paper shows, and about a second of work at 30 obstacles.
    pub max_virtual_robots: usize,
    /// A path whose simulated time from the segment start exceeds this (s) is dropped with a
    /// warning. Default 120 s: 36 m at 0.3 m/s, beyond any segment the planner is given.
    pub max_path_time_s: f64,
    /// A path is also dropped (with the same warning) once its simulated time exceeds
    /// `path_time_factor` (> 0) × the straight drive time (‖e*‖ at the start / U_2) plus
    /// `path_time_margin_s`, when that is below `max_path_time_s`. Default 3 (see
    /// docs/experiments/vfo.md, "The per-path time limit").
    pub path_time_factor: f64,
    /// See `path_time_factor` (s). Default 20: the slow final approach at the last waypoint
    /// (v = min(U_2, ‖H*‖)·cos e_a) plus turning round at the start.
    pub path_time_margin_s: f64,
    /// Most simulated time over all virtual robots of one optimisation (s). Default 20 000 s:
    /// about a second of computation at 50 steps per simulated second.
    pub max_total_time_s: f64,
    /// Branches simulated per batch (fixes the schedule; see the module docs). Default 8.
    pub batch: usize,
    /// Threads for a batch; 0 = the machine's available parallelism. Default 0.
    pub threads: usize,
    /// A point of a virtual robot's path is kept every this much path (m), for display. Default
    /// 0.05.
    pub path_resolution: f64,
}

impl Default for OptimiseConfig {
    fn default() -> Self {
        OptimiseConfig {
            weights: QualityWeights::default(),
            time_step: 0.01,
            max_virtual_robots: 4096,
            max_path_time_s: 120.0,
            path_time_factor: 3.0,
            path_time_margin_s: 20.0,
            max_total_time_s: 20_000.0,
            batch: 8,
            threads: 0,
            path_resolution: 0.05,
        }
    }
}

impl OptimiseConfig {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlannerError> {
        self.weights.validate()?;
        positive_finite("time_step", self.time_step)?;
        positive_finite("max_path_time_s", self.max_path_time_s)?;
        positive_finite("path_time_factor", self.path_time_factor)?;
        positive_finite("path_time_margin_s", self.path_time_margin_s)?;
        positive_finite("max_total_time_s", self.max_total_time_s)?;
        positive_finite("path_resolution", self.path_resolution)?;
        for (name, value) in [("max_virtual_robots", self.max_virtual_robots), ("batch", self.batch)] {
            if value == 0 {
                return Err(PlannerError::InvalidConfig {
                    name,
                    value: 0.0,
                    reason: "must be at least 1",
                });
            }
        }
        Ok(())
    }

    fn thread_count(&self) -> usize {
        if self.threads > 0 {
            self.threads
        } else {
            std::thread::available_parallelism().map_or(1, NonZeroUsize::get)
        }
    }
}

/// How one virtual robot's simulation ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RobotEnd {
    /// It entered the influence zone of obstacle `obstacle` (a stop of Algorithm 2).
    Entry {
        /// The obstacle's index.
        obstacle: usize,
    },
    /// The law reached the waypoint (`vortex`: through Algorithm 3's enlarged ϵ_i).
    Reached {
        /// Algorithm 3 fired.
        vortex: bool,
    },
    /// It entered the forbidden zone of obstacle `obstacle`.
    Collided {
        /// The obstacle's index.
        obstacle: usize,
    },
    /// Its path's simulated time exceeded [`path_time_limit`].
    TimeCap,
    /// The caller interrupted it ([`Interrupt`]); its path is abandoned.
    Interrupted,
}

/// Why the caller stops an optimisation before its end ([`find_sigmas_until`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interrupt {
    /// The result is no longer wanted: [`PlannerError::Stopped`] at once.
    Cancel,
    /// The wall-clock budget is spent: the best candidate so far, with a warning.
    Budget,
}

/// A virtual robot asks the caller's interrupt closure every this many steps (at the default
/// T_p = 0.01 s, every 0.32 s of simulated time, some tens of microseconds of computation).
pub const INTERRUPT_CHECK_STEPS: usize = 32;

/// One virtual robot: the simulation from one stop to the next.
#[derive(Debug, Clone, PartialEq)]
pub struct VirtualRobot {
    /// The virtual robot it continues (`None` for the first one of the segment).
    pub parent: Option<usize>,
    /// Σ it drove with.
    pub sigmas: Vec<Sigma>,
    /// Its path (m), from its start to its end, a point every `path_resolution`.
    pub path: Vec<Point2<f64>>,
    /// Simulated time of this virtual robot alone (s).
    pub time: f64,
    /// How it ended.
    pub end: RobotEnd,
}

/// An edge of the decision graph: (p_last, p_j, Σ_v) (SPEC §5).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct DecisionEdge {
    /// The previous stop's obstacle (`None`: the segment's start).
    pub from: Option<usize>,
    /// The obstacle whose zone was entered.
    pub to: usize,
    /// Σ_v before σ_to was set.
    pub sigmas: Vec<Sigma>,
}

/// What became of one path (a leaf of the decision tree).
#[derive(Debug, Clone, PartialEq)]
pub enum PathFate {
    /// It reached the waypoint: a member of D.
    Candidate {
        /// Algorithm 3 ended it.
        vortex: bool,
    },
    /// It entered the forbidden zone of `obstacle`.
    Collided {
        /// The obstacle's index.
        obstacle: usize,
    },
    /// Its edge was already in its edge set: a cyclic decision path.
    Cyclic {
        /// The repeated edge.
        edge: DecisionEdge,
    },
    /// Its simulated time exceeded [`path_time_limit`].
    TimeCap,
}

/// One path explored: its Σ, its indices, the virtual robots it is made of, its fate and, for
/// a candidate, its normalised indices and Ψ_z.
#[derive(Debug, Clone, PartialEq)]
pub struct ExploredPath {
    /// Σ at its end.
    pub sigmas: Vec<Sigma>,
    /// X: the indices merged over its virtual robots.
    pub indices: PathIndices,
    /// Indices of its virtual robots in [`Optimisation::robots`], first to last.
    pub robots: Vec<usize>,
    /// Simulated time from the segment start (s).
    pub time: f64,
    /// Candidate or dropped, and why.
    pub fate: PathFate,
    /// [Ψ_D, Ψ_B, Ψ_E, Ψ_S] over the candidates (candidates only).
    pub normalised: Option<[f64; 4]>,
    /// Ψ_z (candidates only).
    pub score: Option<f64>,
}

/// A limit hit during an optimisation (returned, not logged: the caller decides).
#[derive(Debug, Clone, PartialEq)]
pub enum OptimiseWarning {
    /// `max_virtual_robots` reached; `pending` branches were abandoned.
    VirtualRobotCap {
        /// The cap.
        limit: usize,
        /// Branches left unexplored.
        pending: usize,
    },
    /// The caller's wall-clock budget was spent ([`Interrupt::Budget`]); `pending` branches
    /// (the virtual robots under way among them) were abandoned.
    WallTimeBudget {
        /// Branches left unexplored.
        pending: usize,
    },
    /// `max_total_time_s` reached; `pending` branches were abandoned.
    TotalTimeCap {
        /// The cap (s).
        limit: f64,
        /// Branches left unexplored.
        pending: usize,
    },
    /// Path `path` was dropped on [`path_time_limit`].
    PathTimeCap {
        /// Its index in [`Optimisation::paths`].
        path: usize,
    },
    /// No path reached the waypoint without collision: no safe Σ exists (or none was found
    /// within the caps). Not given when the wall-clock budget cut the search short before any
    /// candidate ([`OptimiseWarning::WallTimeBudget`] alone says so).
    NoSafeSigma,
}

/// The result of Algorithm 2 for one segment, with everything it explored.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimisation {
    /// Σ_o: the best candidate's Σ (every σ undecided if there is none).
    pub sigmas: Vec<Sigma>,
    /// Index of the best candidate in `paths`.
    pub best: Option<usize>,
    /// Every path explored, in the order they ended.
    pub paths: Vec<ExploredPath>,
    /// Every virtual robot, in the order they were simulated.
    pub robots: Vec<VirtualRobot>,
    /// Limits hit.
    pub warnings: Vec<OptimiseWarning>,
    /// Simulated time over all virtual robots (s).
    pub simulated_time: f64,
}

impl Optimisation {
    /// Ψ_z of the chosen path (`None` without one).
    pub fn score(&self) -> Option<f64> {
        self.best.and_then(|b| self.paths.get(b)).and_then(|p| p.score)
    }

    /// The chosen path's points, its virtual robots' paths joined.
    pub fn best_path(&self) -> Vec<Point2<f64>> {
        self.best
            .and_then(|b| self.paths.get(b))
            .map_or_else(Vec::new, |p| self.path_points(p))
    }

    /// A path's points, its virtual robots' paths joined.
    pub fn path_points(&self, path: &ExploredPath) -> Vec<Point2<f64>> {
        let mut points: Vec<Point2<f64>> = Vec::new();
        for r in path.robots.iter().filter_map(|&i| self.robots.get(i)) {
            let skip = usize::from(!points.is_empty() && r.path.first() == points.last());
            points.extend(r.path.iter().skip(skip));
        }
        points
    }

    /// The number of candidates (|D|).
    pub fn candidates(&self) -> usize {
        self.paths.iter().filter(|p| p.score.is_some()).count()
    }
}

/// The segment a virtual robot drives: its waypoint, whether it is the last one, the known
/// obstacles and the law's gains.
#[derive(Debug, Clone, Copy)]
pub struct Segment<'a> {
    /// The waypoint q_i.
    pub waypoint: VfoWaypoint,
    /// Whether it is the last waypoint (the end test, no Algorithm 3).
    pub last: bool,
    /// Every known obstacle (σ indices follow it).
    pub obstacles: &'a [Obstacle],
}

/// A virtual robot's state: the pose, the law's state, which zones it is inside.
#[derive(Debug, Clone)]
struct RobotState {
    pose: Pose2,
    controller: VfoController,
    inside: Vec<bool>,
    /// Simulated time since the segment start.
    time: f64,
}

/// A pending branch of Algorithm 2.
#[derive(Debug, Clone)]
struct Branch {
    state: RobotState,
    sigmas: Vec<Sigma>,
    edges: Vec<DecisionEdge>,
    indices: PathIndices,
    last_stop: Option<usize>,
    robots: Vec<usize>,
}

/// The result of simulating one virtual robot.
struct Piece {
    state: RobotState,
    indices: PathIndices,
    path: Vec<Point2<f64>>,
    time: f64,
    end: RobotEnd,
}

/// F_s: simulates from `state` with `sigmas` until the next stop (a zone entry, the waypoint, a
/// collision or the path time cap), accumulating X_n from zero.
fn simulate(
    segment: &Segment<'_>,
    config: &OptimiseConfig,
    time_limit: f64,
    mut state: RobotState,
    sigmas: &[Sigma],
    stop_at_entries: bool,
    interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
) -> Piece {
    let dt = config.time_step;
    let mut indices = PathIndices::default();
    let mut path = vec![state.pose.position()];
    let mut travelled_since_point = 0.0;
    let start_time = state.time;
    let mut steps = 0usize;
    let end = loop {
        steps += 1;
        if steps.is_multiple_of(INTERRUPT_CHECK_STEPS) && interrupt().is_some() {
            break RobotEnd::Interrupted;
        }
        if let Some(obstacle) = entry(segment.obstacles, &state.pose.position(), &mut state.inside)
            && stop_at_entries
        {
            break RobotEnd::Entry { obstacle };
        }
        let step = state
            .controller
            .step(&state.pose, &segment.waypoint, segment.last, segment.obstacles, sigmas);
        match step.outcome {
            StepOutcome::Reached { vortex } => break RobotEnd::Reached { vortex },
            StepOutcome::Collision { obstacle } => break RobotEnd::Collided { obstacle },
            StepOutcome::Drive => {}
        }
        if state.time >= time_limit {
            break RobotEnd::TimeCap;
        }
        state.pose = integrate_unicycle(&state.pose, step.v, step.omega, dt);
        state.time += dt;
        let danger: f64 = segment
            .obstacles
            .iter()
            .map(|o| o.potential_at(&state.pose.position()))
            .sum();
        indices.accumulate(step.v, step.omega, danger, dt);
        travelled_since_point += step.v.abs() * dt;
        if travelled_since_point >= config.path_resolution {
            path.push(state.pose.position());
            travelled_since_point = 0.0;
        }
    };
    if path.last() != Some(&state.pose.position()) {
        path.push(state.pose.position());
    }
    Piece {
        time: state.time - start_time,
        state,
        indices,
        path,
        end,
    }
}

/// The first zone (lowest index) the point is inside and was not before; updates `inside`
/// for every zone left. Zones entered after the returned one are found on the next call.
fn entry(obstacles: &[Obstacle], point: &Point2<f64>, inside: &mut [bool]) -> Option<usize> {
    let mut found = None;
    for (k, (o, flag)) in obstacles.iter().zip(inside.iter_mut()).enumerate() {
        let within = o.distance(point) <= o.influence_radius();
        if !within {
            *flag = false;
        } else if !*flag && found.is_none() {
            *flag = true;
            found = Some(k);
        }
    }
    found
}

/// Algorithm 2 (findSigmas) for `segment` from the real robot's `start` pose and law state
/// `controller` (cloned into every virtual robot, so they continue the real robot's θ_a and
/// ϵ_i). Σ starts undecided for every obstacle, as in the paper.
pub fn find_sigmas(
    start: &Pose2,
    controller: &VfoController,
    segment: &Segment<'_>,
    config: &OptimiseConfig,
) -> Result<Optimisation, PlannerError> {
    find_sigmas_until(start, controller, segment, config, &|| None)
}

/// [`find_sigmas`] that asks `interrupt` between batches and every [`INTERRUPT_CHECK_STEPS`]
/// steps of a virtual robot whether to stop (module docs): [`Interrupt::Cancel`] returns
/// [`PlannerError::Stopped`], [`Interrupt::Budget`] the best candidate so far with
/// [`OptimiseWarning::WallTimeBudget`].
pub fn find_sigmas_until(
    start: &Pose2,
    controller: &VfoController,
    segment: &Segment<'_>,
    config: &OptimiseConfig,
    interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
) -> Result<Optimisation, PlannerError> {
    config.validate()?;
    crate::docking::check_pose("virtual robot start", start)?;
    let n = segment.obstacles.len();
    let threads = config.thread_count();
    let time_limit = path_time_limit(start, segment, controller, config);
    let mut stack = vec![Branch {
        state: RobotState {
            pose: *start,
            controller: *controller,
            inside: vec![false; n],
            time: 0.0,
        },
        sigmas: vec![Sigma::Undecided; n],
        edges: Vec::new(),
        indices: PathIndices::default(),
        last_stop: None,
        robots: Vec::new(),
    }];
    let mut result = Optimisation {
        sigmas: vec![Sigma::Undecided; n],
        best: None,
        paths: Vec::new(),
        robots: Vec::new(),
        warnings: Vec::new(),
        simulated_time: 0.0,
    };
    while !stack.is_empty() {
        match interrupt() {
            Some(Interrupt::Cancel) => return Err(PlannerError::Stopped),
            Some(Interrupt::Budget) => {
                result
                    .warnings
                    .push(OptimiseWarning::WallTimeBudget { pending: stack.len() });
                break;
            }
            None => {}
        }
        if result.robots.len() >= config.max_virtual_robots {
            result.warnings.push(OptimiseWarning::VirtualRobotCap {
                limit: config.max_virtual_robots,
                pending: stack.len(),
            });
            break;
        }
        if result.simulated_time >= config.max_total_time_s {
            result.warnings.push(OptimiseWarning::TotalTimeCap {
                limit: config.max_total_time_s,
                pending: stack.len(),
            });
            break;
        }
        let take = config
            .batch
            .min(stack.len())
            .min(config.max_virtual_robots - result.robots.len());
        let batch: Vec<Branch> = (0..take).filter_map(|_| stack.pop()).collect();
        let pieces = simulate_batch(segment, config, time_limit, &batch, threads, interrupt);
        let cut = pieces.iter().filter(|p| p.end == RobotEnd::Interrupted).count();
        // A cancel ends it here; on the budget the batch's finished pieces still count, the
        // interrupted ones and the stack are abandoned below.
        if cut > 0 && interrupt() == Some(Interrupt::Cancel) {
            return Err(PlannerError::Stopped);
        }
        for (mut branch, piece) in batch.into_iter().zip(pieces) {
            if piece.end == RobotEnd::Interrupted {
                continue;
            }
            let id = result.robots.len();
            result.simulated_time += piece.time;
            result.robots.push(VirtualRobot {
                parent: branch.robots.last().copied(),
                sigmas: branch.sigmas.clone(),
                path: piece.path,
                time: piece.time,
                end: piece.end,
            });
            branch.robots.push(id);
            branch.state = piece.state;
            let fate = match piece.end {
                RobotEnd::Entry { obstacle } => {
                    let edge = DecisionEdge {
                        from: branch.last_stop,
                        to: obstacle,
                        sigmas: branch.sigmas.clone(),
                    };
                    if branch.edges.contains(&edge) {
                        branch.indices = branch.indices.merge(&piece.indices);
                        Some(PathFate::Cyclic { edge })
                    } else {
                        branch.edges.push(edge);
                        branch.indices = branch.indices.merge(&piece.indices);
                        branch.last_stop = Some(obstacle);
                        if branch.sigmas.get(obstacle) == Some(&Sigma::Undecided) {
                            let mut left = branch.clone();
                            left.sigmas[obstacle] = Sigma::Left;
                            branch.sigmas[obstacle] = Sigma::Right;
                            stack.push(left);
                        }
                        stack.push(branch);
                        continue;
                    }
                }
                RobotEnd::Reached { vortex } => {
                    branch.indices = branch.indices.merge(&piece.indices);
                    Some(PathFate::Candidate { vortex })
                }
                RobotEnd::Collided { obstacle } => {
                    branch.indices = branch.indices.merge(&piece.indices);
                    Some(PathFate::Collided { obstacle })
                }
                RobotEnd::TimeCap => {
                    branch.indices = branch.indices.merge(&piece.indices);
                    result.warnings.push(OptimiseWarning::PathTimeCap {
                        path: result.paths.len(),
                    });
                    Some(PathFate::TimeCap)
                }
                // Skipped above.
                RobotEnd::Interrupted => None,
            };
            if let Some(fate) = fate {
                result.paths.push(ExploredPath {
                    sigmas: branch.sigmas,
                    indices: branch.indices,
                    robots: branch.robots,
                    time: branch.state.time,
                    fate,
                    normalised: None,
                    score: None,
                });
            }
        }
        if cut > 0 {
            result.warnings.push(OptimiseWarning::WallTimeBudget {
                pending: stack.len() + cut,
            });
            break;
        }
    }
    choose(&mut result, &config.weights);
    Ok(result)
}

/// The simulated time a path may take from `start` (see `path_time_factor`).
pub fn path_time_limit(
    start: &Pose2,
    segment: &Segment<'_>,
    controller: &VfoController,
    config: &OptimiseConfig,
) -> f64 {
    let straight = (segment.waypoint.position - start.position()).norm() / controller.gains().speed;
    (config.path_time_factor * straight + config.path_time_margin_s).min(config.max_path_time_s)
}

/// Fewest branches in a batch worth spreading over threads: below, the scoped threads'
/// start-up (tens of µs each, more on a loaded machine) costs about what the few virtual
/// robots of a small layout take (the bench: with up to 4 obstacles, Algorithm 2 took
/// 0.4–2 ms on one thread and 1.4–17 ms on two, at a load of 4–5 other builds).
pub const PARALLEL_MIN_BATCH: usize = 4;

/// Simulates every branch of a batch to its next stop, on up to `threads` threads; the
/// results come back in the batch's order.
fn simulate_batch(
    segment: &Segment<'_>,
    config: &OptimiseConfig,
    time_limit: f64,
    batch: &[Branch],
    threads: usize,
    interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
) -> Vec<Piece> {
    let run = |b: &Branch| simulate(segment, config, time_limit, b.state.clone(), &b.sigmas, true, interrupt);
    let workers = threads.min(batch.len());
    if workers <= 1 || batch.len() < PARALLEL_MIN_BATCH {
        return batch.iter().map(run).collect();
    }
    let chunk = batch.len().div_ceil(workers);
    std::thread::scope(|scope| {
        let handles: Vec<_> = batch
            .chunks(chunk)
            .map(|part| scope.spawn(move || part.iter().map(run).collect::<Vec<Piece>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| match h.join() {
                Ok(pieces) => pieces,
                Err(panic) => std::panic::resume_unwind(panic),
            })
            .collect()
    })
}

/// Normalises the candidates and picks the best by Ψ_z with the tie rule.
fn choose(result: &mut Optimisation, weights: &QualityWeights) {
    let members: Vec<usize> = (0..result.paths.len())
        .filter(|&i| matches!(result.paths[i].fate, PathFate::Candidate { .. }))
        .collect();
    let indices: Vec<PathIndices> = members.iter().map(|&i| result.paths[i].indices).collect();
    for (&i, psi) in members.iter().zip(normalised(&indices)) {
        result.paths[i].normalised = Some(psi);
        result.paths[i].score = Some(path_score(&psi, weights));
    }
    let mut best: Option<usize> = None;
    for &i in &members {
        best = match best {
            None => Some(i),
            Some(b) if better(&result.paths[i], &result.paths[b]) => Some(i),
            keep => keep,
        };
    }
    result.best = best;
    match best {
        Some(b) => result.sigmas = result.paths[b].sigmas.clone(),
        // Cut short by the caller's budget before any candidate, nothing was proven unsafe.
        None if result
            .warnings
            .iter()
            .any(|w| matches!(w, OptimiseWarning::WallTimeBudget { .. })) => {}
        None => result.warnings.push(OptimiseWarning::NoSafeSigma),
    }
}

/// Whether candidate `a` beats `b`: larger Ψ_z; within 1e-12, fewer decided σ, then the
/// lexicographically smaller Σ.
fn better(a: &ExploredPath, b: &ExploredPath) -> bool {
    let (sa, sb) = (
        a.score.unwrap_or(f64::NEG_INFINITY),
        b.score.unwrap_or(f64::NEG_INFINITY),
    );
    if (sa - sb).abs() > 1e-12 * sa.abs().max(sb.abs()).max(1.0) {
        return sa > sb;
    }
    let decided = |p: &ExploredPath| p.sigmas.iter().filter(|s| **s != Sigma::Undecided).count();
    (decided(a), &a.sigmas) < (decided(b), &b.sigmas)
}

/// One uninterrupted run of the law with a fixed Σ from `start` (no stops at zone entries):
/// its indices, path and end. Merged over the stops, Algorithm 2's pieces of the same Σ give
/// the same indices (SPEC §5); tests use this as the second method.
pub fn simulate_uninterrupted(
    start: &Pose2,
    controller: &VfoController,
    segment: &Segment<'_>,
    sigmas: &[Sigma],
    config: &OptimiseConfig,
) -> Result<(PathIndices, Vec<Point2<f64>>, RobotEnd), PlannerError> {
    config.validate()?;
    crate::docking::check_pose("virtual robot start", start)?;
    let state = RobotState {
        pose: *start,
        controller: *controller,
        inside: vec![false; segment.obstacles.len()],
        time: 0.0,
    };
    let limit = path_time_limit(start, segment, controller, config);
    let piece = simulate(segment, config, limit, state, sigmas, false, &|| None);
    Ok((piece.indices, piece.path, piece.end))
}
