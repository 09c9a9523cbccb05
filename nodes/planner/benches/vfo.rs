//! Algorithm 2 (findSigmas) against the number of obstacles on a segment, next to brute-force
//! enumeration of all 2^Np decisions, and the real-time factor (the chosen path's drive time /
//! the optimisation's wall time on one thread). Budgets: at 20 obstacles every layout ≥ 150×
//! real time and the median ≥ 600×; at 40 obstacles no layout stops on a cap and the median is
//! ≥ 150×; two threads ≥ 1.6× as fast as one over the 40-obstacle layouts.
//!
//! `cargo bench -p mobil_planner --bench vfo [Np …]` prints Markdown tables: the medians per
//! Np, every layout of 20, 40 and 60 obstacles, and per set the slowest layout, the median and
//! the threads' speed-up (total one-thread time over total all-threads time). Layouts: `Np`
//! obstacles (r_p 0.15–0.30 m plus a 0.25 m robot radius, R = r + 0.4 m) scattered at random
//! in a corridor ±1.5 m about a straight segment of 4 + 0.6·min(Np, 40) m (start and goal
//! outside every zone; 60 obstacles share the 28 m of 40, since beyond it the straight drive
//! alone nears the default 120 s per-path limit); five layouts per Np. Each optimisation is
//! timed three times and the fastest counts; the one- and all-thread results must be equal.
//! The brute force simulates every Σ ∈ {−1, +1}^Np with no stops (the law is the same, so the
//! same paths), normalises the collision-free ones and takes the best; it is run up to
//! Np = 12 (4096 simulations, seconds per layout) and estimated beyond from its median cost per
//! simulation at Np ≤ 12 — a lower bound, as segments grow with Np.

use std::time::{Duration, Instant};

use mobil_geom::Pose2;
use mobil_planner::vfo::{
    find_sigmas, normalised, path_score, simulate_uninterrupted, Obstacle, Optimisation, OptimiseConfig,
    OptimiseWarning, RobotEnd, Segment, Sigma, VfoController, VfoGains, VfoWaypoint,
};
use nalgebra::Point2;

const LAYOUTS: u64 = 5;
const BRUTE_MAX: usize = 12;

struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `n` obstacles on a segment from (0, 0) to (length, 0).
fn layout(n: usize, seed: u64) -> (Vec<Obstacle>, f64) {
    let length = 4.0 + 0.6 * n.min(40) as f64;
    let mut rng = Lcg(seed * 7919 + n as u64);
    let mut obstacles: Vec<Obstacle> = Vec::new();
    let ends = [Point2::new(0.0, 0.0), Point2::new(length, 0.0)];
    while obstacles.len() < n {
        let r = 0.25 + 0.15 + 0.15 * rng.next();
        let centre = Point2::new(1.5 + (length - 3.0) * rng.next(), -1.5 + 3.0 * rng.next());
        let Ok(o) = Obstacle::new(centre, r, r + 0.4) else {
            continue;
        };
        let apart = obstacles
            .iter()
            .all(|p| p.distance(&centre) > p.forbidden_radius() + r - 0.5);
        let clear = ends.iter().all(|e| o.distance(e) > o.influence_radius());
        if apart && clear {
            obstacles.push(o);
        }
    }
    (obstacles, length)
}

/// The middle value (the upper of the two middle ones for an even count); NaN for none.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

struct Brute {
    time: Duration,
    simulations: usize,
}

/// Every Σ ∈ {−1, +1}^n simulated through; the best collision-free one by Ψ_z.
fn brute_force(segment: &Segment<'_>, config: &OptimiseConfig) -> (Brute, Option<f64>) {
    let n = segment.obstacles.len();
    let controller = VfoController::new(VfoGains::default()).expect("valid");
    let start = Instant::now();
    let mut candidates = Vec::new();
    for bits in 0u64..(1 << n) {
        let sigmas: Vec<Sigma> = (0..n)
            .map(|k| if bits >> k & 1 == 0 { Sigma::Right } else { Sigma::Left })
            .collect();
        let (x, _, end) =
            simulate_uninterrupted(&Pose2::identity(), &controller, segment, &sigmas, config).expect("valid");
        if matches!(end, RobotEnd::Reached { .. }) {
            candidates.push(x);
        }
    }
    let best = normalised(&candidates)
        .iter()
        .map(|psi| path_score(psi, &config.weights))
        .fold(None, |b: Option<f64>, s| Some(b.map_or(s, |b| b.max(s))));
    (
        Brute {
            time: start.elapsed(),
            simulations: 1 << n,
        },
        best,
    )
}

/// Obstacle counts of the summary table.
const COUNTS: [usize; 15] = [1, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 60];
/// Obstacle counts whose layouts are listed one by one.
const LISTED: [usize; 3] = [20, 40, 60];
/// Each optimisation is timed this many times; the fastest counts (the others met the machine's
/// other work).
const REPEATS: usize = 3;

/// One layout's figures.
struct Run {
    seed: u64,
    zones: usize,
    robots: usize,
    paths: usize,
    candidates: usize,
    simulated: f64,
    /// Wall time on one thread and on all threads (s).
    one: f64,
    all: f64,
    drive: f64,
    capped: bool,
    time_capped: usize,
    unsafe_layout: bool,
}

impl Run {
    /// The chosen path's drive time over the one-thread wall time (`None` without a path).
    fn factor(&self) -> Option<f64> {
        self.drive.is_finite().then(|| self.drive / self.one)
    }
}

/// The median of the layouts' real-time factors, those without a path left out.
fn median_factor(runs: &[Run]) -> String {
    let factors: Vec<f64> = runs.iter().filter_map(Run::factor).collect();
    if factors.is_empty() {
        "—".to_string()
    } else {
        format!("{:.0}×", median(factors))
    }
}

/// The fastest of [`REPEATS`] runs of Algorithm 2 (wall time in s) and its result.
fn timed(segment: &Segment<'_>, config: &OptimiseConfig) -> (f64, Optimisation) {
    let controller = VfoController::new(VfoGains::default()).expect("valid");
    let mut best = f64::INFINITY;
    let mut result = None;
    for _ in 0..REPEATS {
        let t = Instant::now();
        let r = find_sigmas(&Pose2::identity(), &controller, segment, config).expect("valid");
        best = best.min(t.elapsed().as_secs_f64());
        result = Some(r);
    }
    (best, result.expect("REPEATS > 0"))
}

fn run_layout(n: usize, seed: u64, config: &OptimiseConfig, brute: &mut Vec<(f64, usize)>) -> Run {
    let serial = OptimiseConfig { threads: 1, ..*config };
    let (obstacles, l) = layout(n, seed);
    let segment = Segment {
        waypoint: VfoWaypoint::new(l, 0.0, 0.0, 0.5).expect("valid"),
        last: true,
        obstacles: &obstacles,
    };
    let (one, r1) = timed(&segment, &serial);
    let (all, r) = timed(&segment, config);
    assert_eq!(r1, r, "the thread count changed the result");
    if std::env::var_os("VFO_BENCH_DEBUG").is_some() {
        eprintln!(
            "n {n} seed {seed}: {:?} fates {:?}",
            r.warnings,
            r.paths.iter().map(|p| (&p.fate, p.time)).collect::<Vec<_>>()
        );
    }
    if n <= BRUTE_MAX {
        let (b, best) = brute_force(&segment, config);
        brute.push((b.time.as_secs_f64(), b.simulations));
        // Every Σ the optimiser's candidates drive is among the brute force's, so the brute
        // force finds at least as many safe paths.
        assert!(best.is_some() || r.best.is_none(), "brute force found no safe Σ");
    }
    Run {
        seed,
        zones: r.sigmas.iter().filter(|s| **s != Sigma::Undecided).count(),
        robots: r.robots.len(),
        paths: r.paths.len(),
        candidates: r.candidates(),
        simulated: r.simulated_time,
        one,
        all,
        drive: r.best.map_or(f64::NAN, |b| r.paths[b].time),
        capped: r.warnings.iter().any(|w| {
            matches!(
                w,
                OptimiseWarning::VirtualRobotCap { .. } | OptimiseWarning::TotalTimeCap { .. }
            )
        }),
        time_capped: r
            .warnings
            .iter()
            .filter(|w| matches!(w, OptimiseWarning::PathTimeCap { .. }))
            .count(),
        unsafe_layout: r.warnings.contains(&OptimiseWarning::NoSafeSigma),
    }
}

fn main() {
    // `cargo bench` passes `--bench`; number arguments pick the obstacle counts to run.
    let only: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let config = OptimiseConfig::default();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "threads: {threads} available; T_p {} s; {LAYOUTS} layouts per Np, medians; each optimisation the fastest of {REPEATS}",
        config.time_step
    );
    println!();
    println!(
        "| Np | segment (m) | zones met | virtual robots | paths | \\|D\\| | Alg. 2, 1 thread (ms) | Alg. 2, {threads} threads (ms) | brute force 2^Np (ms) | drive time (s) | real-time factor, 1 thread | caps hit (all layouts) |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    let mut per_sim = Vec::new();
    let mut listed: Vec<(usize, Vec<Run>)> = Vec::new();
    for n in COUNTS {
        if !only.is_empty() && !only.contains(&n) {
            continue;
        }
        let mut brute = Vec::new();
        let runs: Vec<Run> = (0..LAYOUTS)
            .map(|seed| run_layout(n, seed, &config, &mut brute))
            .collect();
        per_sim.extend(brute.iter().map(|(t, sims)| t / *sims as f64));
        let col = |f: &dyn Fn(&Run) -> f64| median(runs.iter().map(f).collect());
        let brute_cell = if !brute.is_empty() {
            format!("{:.1}", median(brute.iter().map(|(t, _)| t * 1e3).collect()))
        } else if per_sim.is_empty() {
            "not run".to_string()
        } else {
            let est = median(per_sim.clone()) * 2f64.powi(n as i32);
            format!("≥ {} (estimated, not run)", human(est))
        };
        println!(
            "| {n} | {:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {:.2} | {:.2} | {brute_cell} | {:.1} | {} | {} |",
            layout(n, 0).1,
            col(&|r| r.zones as f64),
            col(&|r| r.robots as f64),
            col(&|r| r.paths as f64),
            col(&|r| r.candidates as f64),
            col(&|r| r.one * 1e3),
            col(&|r| r.all * 1e3),
            median(runs.iter().map(|r| r.drive).filter(|d| d.is_finite()).collect()),
            median_factor(&runs),
            notes(&runs)
        );
        if LISTED.contains(&n) {
            listed.push((n, runs));
        }
    }
    if listed.is_empty() {
        return;
    }
    println!();
    println!(
        "| Np | layout | virtual robots | simulated (s) | drive time (s) | 1 thread (ms) | {threads} threads (ms) | speed-up | real-time factor, 1 thread | caps hit |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for (n, runs) in &listed {
        for r in runs {
            println!(
                "| {n} | {} | {} | {:.0} | {:.1} | {:.1} | {:.1} | {:.2}× | {} | {} |",
                r.seed,
                r.robots,
                r.simulated,
                r.drive,
                r.one * 1e3,
                r.all * 1e3,
                r.one / r.all,
                r.factor().map_or("— (no path)".to_string(), |f| format!("{f:.0}×")),
                notes(std::slice::from_ref(r))
            );
        }
    }
    println!();
    println!("| Np | slowest layout, 1 thread | median, 1 thread | {threads} threads against 1 over the set | layouts capped |");
    println!("|---:|---:|---:|---:|---:|");
    for (n, runs) in &listed {
        let slowest = runs.iter().filter_map(Run::factor).fold(f64::INFINITY, f64::min);
        let one: f64 = runs.iter().map(|r| r.one).sum();
        let all: f64 = runs.iter().map(|r| r.all).sum();
        println!(
            "| {n} | {slowest:.0}× | {} | {:.2}× | {} of {} |",
            median_factor(runs),
            one / all,
            runs.iter().filter(|r| r.capped).count(),
            runs.len()
        );
    }
}

/// The caps hit over some layouts.
fn notes(runs: &[Run]) -> String {
    let time_capped: usize = runs.iter().map(|r| r.time_capped).sum();
    let capped = runs.iter().filter(|r| r.capped).count();
    let unsafe_layouts = runs.iter().filter(|r| r.unsafe_layout).count();
    let mut parts = Vec::new();
    let plural = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    if time_capped > 0 {
        parts.push(plural(
            time_capped,
            "path over the time limit",
            "paths over the time limit",
        ));
    }
    if capped > 0 {
        parts.push(plural(capped, "optimisation capped", "optimisations capped"));
    }
    if unsafe_layouts > 0 {
        parts.push(plural(
            unsafe_layouts,
            "layout without a safe Σ",
            "layouts without a safe Σ",
        ));
    }
    parts.join(", ")
}

fn human(seconds: f64) -> String {
    let year = 365.0 * 86400.0;
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.0} min", seconds / 60.0)
    } else if seconds < 2.0 * 86400.0 {
        format!("{:.0} h", seconds / 3600.0)
    } else if seconds < 2.0 * year {
        format!("{:.0} days", seconds / 86400.0)
    } else if seconds < 1e4 * year {
        format!("{:.0} years", seconds / year)
    } else {
        format!("{:.0e} years", seconds / year)
    }
}
