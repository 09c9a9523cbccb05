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
//! - **Interrupts** ([`find_sigmas_until`]): the caller's closure is asked before every virtual
//!   robot and every [`INTERRUPT_CHECK_STEPS`] steps of each virtual robot. [`Interrupt::Cancel`]
//!   (the result is no longer wanted: a cancel, a new goal, shutdown) ends the optimisation at
//!   once with [`PlannerError::Stopped`]; [`Interrupt::Budget`] (the caller's wall-clock budget
//!   is spent) abandons the virtual robots under way and the pending branches and returns the
//!   best candidate so far with [`OptimiseWarning::WallTimeBudget`], as the caps do. The clock
//!   is the caller's: the library reads none.
//!
//! **Order and threads.** The pending branches are a stack (LIFO, depth first: σ = +1 before
//! σ = −1), and the caps and interrupts are checked before each virtual robot is taken from it,
//! in that serial order. With `threads` > 1, helper threads simulate the branches ahead of it
//! (the earliest in that order first) while the optimiser takes their results in order
//! (the private module `speculate`); a branch's simulation and children depend on the branch
//! alone, so the result (Σ, every virtual robot, every path, every warning) is the same for any
//! number of threads, and what was simulated beyond a cap is thrown away. The helpers start
//! after the first few virtual robots: a small segment is done before a thread starts.
//!
//! **A step's cost.** A virtual robot evaluates only the obstacles near it: a list of those
//! whose influence zone lies within a margin, rebuilt after it has driven half of the margin;
//! one distance per listed obstacle and step serves the zone test, H*, Ḣ* and the danger.

use std::num::NonZeroUsize;
use std::sync::atomic::{AtomicBool, Ordering as AtomicOrdering};

use mobil_geom::Pose2;
use nalgebra::Point2;

use super::controller::{guide, integrate_from, measure, Aim, Near, Nearby, StepOutcome, VfoController, VfoWaypoint};
use super::obstacles::{potential, Obstacle, Sigma};
use super::quality::{normalised, path_score, PathIndices, QualityWeights};
use super::speculate::{speculate, Keyed};
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
    /// Most virtual robots per optimisation. Default 16 384 (2^14): the bench's 40-obstacle
    /// layouts need up to 9 500 (docs/experiments/vfo.md), far beyond the |D| of any layout
    /// the paper shows.
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
    /// Most simulated time over all virtual robots of one optimisation (s). Default 80 000 s:
    /// about a second of computation on one core at T_p = 0.01 s (the bench measures 11–14 µs
    /// per simulated second); the bench's 40-obstacle layouts need up to 57 000 s.
    pub max_total_time_s: f64,
    /// Threads that simulate virtual robots; 0 = the machine's available parallelism, which also
    /// bounds a larger value. The result does not depend on it (see the module docs). Default 0.
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
            max_virtual_robots: 16_384,
            max_path_time_s: 120.0,
            path_time_factor: 3.0,
            path_time_margin_s: 20.0,
            max_total_time_s: 80_000.0,
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
        if self.max_virtual_robots == 0 {
            return Err(PlannerError::InvalidConfig {
                name: "max_virtual_robots",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }

    /// `threads`, at most the machine's available parallelism (more would only queue).
    fn thread_count(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, NonZeroUsize::get);
        if self.threads > 0 {
            self.threads.min(cores)
        } else {
            cores
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
    /// Its place in the serial order (see [`Key`]).
    key: Key,
    state: RobotState,
    sigmas: Vec<Sigma>,
    edges: Vec<DecisionEdge>,
    indices: PathIndices,
    last_stop: Option<usize>,
}

/// A branch's choices from the segment's start: 0 for the first (σ = +1, or the only) child,
/// 1 for the second (σ = −1). Keys compare lexicographically, a prefix first: the depth-first
/// order in which the serial optimiser takes the branches.
type Key = Vec<u8>;

impl Keyed for Branch {
    type Key = Key;
    fn key(&self) -> &Key {
        &self.key
    }
}

impl Branch {
    /// The child that goes on from this branch's next stop, `choice` its last key element.
    fn child(&self, choice: u8) -> Branch {
        let mut child = self.clone();
        child.key.push(choice);
        child
    }
}

/// A branch simulated to its next stop: its virtual robot and what follows.
struct Advance {
    /// The virtual robot (its parent is set when it is taken in order).
    robot: VirtualRobot,
    next: Next,
}

/// What follows a virtual robot.
enum Next {
    /// The path goes on: one child (key + 0), or two (σ = +1 at key + 0, σ = −1 at key + 1).
    Children(usize),
    /// The path ends.
    End {
        fate: PathFate,
        sigmas: Vec<Sigma>,
        indices: PathIndices,
        time: f64,
    },
    /// The caller interrupted it.
    Interrupted,
}

/// Simulates a branch to its next stop and forms its children (the same for every branch with
/// this state, whichever thread runs it).
fn advance(
    mut branch: Branch,
    segment: &Segment<'_>,
    config: &OptimiseConfig,
    time_limit: f64,
    interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
) -> (Advance, Vec<Branch>) {
    let piece = simulate(
        segment,
        config,
        time_limit,
        branch.state.clone(),
        &branch.sigmas,
        true,
        interrupt,
    );
    let robot = VirtualRobot {
        parent: None,
        sigmas: branch.sigmas.clone(),
        path: piece.path,
        time: piece.time,
        end: piece.end,
    };
    branch.state = piece.state;
    branch.indices = branch.indices.merge(&piece.indices);
    let fate = match piece.end {
        RobotEnd::Entry { obstacle } => {
            let edge = DecisionEdge {
                from: branch.last_stop,
                to: obstacle,
                sigmas: branch.sigmas.clone(),
            };
            if branch.edges.contains(&edge) {
                PathFate::Cyclic { edge }
            } else {
                branch.edges.push(edge);
                branch.last_stop = Some(obstacle);
                let children = if branch.sigmas.get(obstacle) == Some(&Sigma::Undecided) {
                    let mut right = branch.child(0);
                    let mut left = branch.child(1);
                    right.sigmas[obstacle] = Sigma::Right;
                    left.sigmas[obstacle] = Sigma::Left;
                    vec![right, left]
                } else {
                    vec![branch.child(0)]
                };
                let next = Next::Children(children.len());
                return (Advance { robot, next }, children);
            }
        }
        RobotEnd::Reached { vortex } => PathFate::Candidate { vortex },
        RobotEnd::Collided { obstacle } => PathFate::Collided { obstacle },
        RobotEnd::TimeCap => PathFate::TimeCap,
        RobotEnd::Interrupted => {
            return (
                Advance {
                    robot,
                    next: Next::Interrupted,
                },
                Vec::new(),
            )
        }
    };
    let next = Next::End {
        fate,
        sigmas: branch.sigmas,
        indices: branch.indices,
        time: branch.state.time,
    };
    (Advance { robot, next }, Vec::new())
}

/// The result of simulating one virtual robot.
struct Piece {
    state: RobotState,
    indices: PathIndices,
    path: Vec<Point2<f64>>,
    time: f64,
    end: RobotEnd,
}

/// How far beyond its influence radius an obstacle is kept in a virtual robot's near list
/// (m). The list is rebuilt once the robot has driven half of it: at 0.3 m/s and T_p = 0.01 s
/// every 33 steps, a distance per obstacle against the four per obstacle and step that
/// evaluating the law over all of them cost (0.1, 0.2 and 0.3 m measured alike).
const NEAR_MARGIN: f64 = 0.2;

/// The obstacles whose influence zone a point within `NEAR_MARGIN` of `point` can be in
/// (ascending); the others are outside their zones there, so their flags in `inside` go down.
fn near_list(obstacles: &[Obstacle], point: &Point2<f64>, near: &mut Vec<usize>, inside: &mut [bool]) {
    near.clear();
    for (k, (o, flag)) in obstacles.iter().zip(inside.iter_mut()).enumerate() {
        if o.distance(point) <= o.influence_radius() + NEAR_MARGIN {
            near.push(k);
        } else {
            *flag = false;
        }
    }
}

/// F_s: simulates from `state` with `sigmas` until the next stop (a zone entry, the waypoint, a
/// collision or the path time cap), accumulating X_n from zero.
///
/// Each step evaluates only the obstacles of a near list, rebuilt whenever the robot has driven
/// `NEAR_MARGIN / 2` since the last build: an obstacle left out is farther than
/// `NEAR_MARGIN / 2` beyond its influence radius there, so V, V' and the zone test are exactly
/// those of the full sum.
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
    let obstacles = segment.obstacles;
    let aim = Aim {
        waypoint: &segment.waypoint,
        guide: guide(&segment.waypoint),
        last: segment.last,
    };
    let mut indices = PathIndices::default();
    let mut path = vec![state.pose.position()];
    let mut travelled_since_point = 0.0;
    let start_time = state.time;
    let mut steps = 0usize;
    let mut sincos = state.pose.yaw.sin_cos();
    let mut near = Vec::with_capacity(obstacles.len());
    near_list(obstacles, &state.pose.position(), &mut near, &mut state.inside);
    // Distance driven since the near list was built.
    let mut since_near = 0.0;
    // The obstacles whose zone holds the current position.
    let mut nearby = Vec::new();
    measure(obstacles, Near::Only(&near), &state.pose.position(), &mut nearby);
    let end = loop {
        steps += 1;
        if steps.is_multiple_of(INTERRUPT_CHECK_STEPS) && interrupt().is_some() {
            break RobotEnd::Interrupted;
        }
        if since_near > 0.5 * NEAR_MARGIN {
            // `nearby` stays right: it was measured within NEAR_MARGIN of the old list's point.
            near_list(obstacles, &state.pose.position(), &mut near, &mut state.inside);
            since_near = 0.0;
        }
        if let Some(obstacle) = entry(&near, &nearby, &mut state.inside)
            && stop_at_entries
        {
            break RobotEnd::Entry { obstacle };
        }
        let step = state
            .controller
            .step_among(&state.pose, sincos, &aim, obstacles, sigmas, &nearby);
        match step.outcome {
            StepOutcome::Reached { vortex } => break RobotEnd::Reached { vortex },
            StepOutcome::Collision { obstacle } => break RobotEnd::Collided { obstacle },
            StepOutcome::Drive => {}
        }
        if state.time >= time_limit {
            break RobotEnd::TimeCap;
        }
        (state.pose, sincos) = integrate_from(&state.pose, sincos, step.v, step.omega, dt);
        state.time += dt;
        let moved = step.v.abs() * dt;
        since_near += moved;
        // The near list holds within NEAR_MARGIN of where it was built; a longer step (a large
        // T_p) measures every obstacle.
        let candidates = if since_near <= NEAR_MARGIN {
            Near::Only(&near)
        } else {
            Near::All
        };
        let here = state.pose.position();
        measure(obstacles, candidates, &here, &mut nearby);
        let danger: f64 = nearby
            .iter()
            .filter_map(|n| {
                let o = obstacles.get(n.k)?;
                Some(potential(n.d, o.forbidden_radius(), o.influence_radius()))
            })
            .sum();
        indices.accumulate(step.v, step.omega, danger, dt);
        travelled_since_point += moved;
        if travelled_since_point >= config.path_resolution {
            path.push(here);
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

/// The first zone (lowest index) the point is inside and was not before, from the obstacles
/// of `near` and those of them whose zone holds the point (`nearby`, both ascending); updates
/// `inside` for every zone of `near` left. Zones entered after the returned one are found on
/// the next call.
fn entry(near: &[usize], nearby: &[Nearby], inside: &mut [bool]) -> Option<usize> {
    let mut found = None;
    let mut within = nearby.iter().map(|n| n.k).peekable();
    for &k in near {
        let inside_zone = within.next_if_eq(&k).is_some();
        let Some(flag) = inside.get_mut(k) else {
            continue;
        };
        if !inside_zone {
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

/// [`find_sigmas`] that asks `interrupt` before each virtual robot and every [`INTERRUPT_CHECK_STEPS`]
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
    let first = Branch {
        key: Key::new(),
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
    };
    let work = |branch: Branch, closed: &AtomicBool| {
        // Work ahead of a finished optimisation is thrown away: it stops at once.
        let stop = || {
            if closed.load(AtomicOrdering::Relaxed) {
                Some(Interrupt::Cancel)
            } else {
                interrupt()
            }
        };
        advance(branch, segment, config, time_limit, &stop)
    };
    let mut result = Optimisation {
        sigmas: vec![Sigma::Undecided; n],
        best: None,
        paths: Vec::new(),
        robots: Vec::new(),
        warnings: Vec::new(),
        simulated_time: 0.0,
    };
    speculate(threads, first, &work, |speculation| {
        // The serial stack: keys and the virtual robots of the path so far.
        let mut stack: Vec<(Key, Vec<usize>)> = vec![(Key::new(), Vec::new())];
        while let Some((key, _)) = stack.last() {
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
            // `None` only if a helper thread panicked, which the scope raises again.
            let Some(Advance { mut robot, next }) = speculation.take(key) else {
                break;
            };
            let Some((key, mut robots)) = stack.pop() else {
                break;
            };
            if matches!(next, Next::Interrupted) {
                // A cancel ends it here; on the budget the stack is abandoned, this branch too.
                if interrupt() == Some(Interrupt::Cancel) {
                    return Err(PlannerError::Stopped);
                }
                result.warnings.push(OptimiseWarning::WallTimeBudget {
                    pending: stack.len() + 1,
                });
                break;
            }
            let id = result.robots.len();
            robot.parent = robots.last().copied();
            result.simulated_time += robot.time;
            result.robots.push(robot);
            robots.push(id);
            match next {
                Next::Children(count) => {
                    // The second child below the first: the first is taken next.
                    for choice in (0..count).rev() {
                        let mut child = key.clone();
                        child.push(choice as u8);
                        stack.push((child, robots.clone()));
                    }
                }
                Next::End {
                    fate,
                    sigmas,
                    indices,
                    time,
                } => {
                    if fate == PathFate::TimeCap {
                        result.warnings.push(OptimiseWarning::PathTimeCap {
                            path: result.paths.len(),
                        });
                    }
                    result.paths.push(ExploredPath {
                        sigmas,
                        indices,
                        robots,
                        time,
                        fate,
                        normalised: None,
                        score: None,
                    });
                }
                Next::Interrupted => {}
            }
        }
        Ok(())
    })?;
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
