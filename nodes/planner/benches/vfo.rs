//! Algorithm 2 (findSigmas) against the number of obstacles on a segment, next to brute-force
//! enumeration of all 2^Np decisions, and the real-time factor (the chosen path's drive time /
//! the optimisation's wall time). Budget: ≥ 100× real time at 20 obstacles.
//!
//! `cargo bench -p mobil_planner --bench vfo` prints a Markdown table. Layouts: `Np` obstacles
//! (r_p 0.15–0.30 m plus a 0.25 m robot radius, R = r + 0.4 m) scattered at random, without
//! overlapping forbidden zones, in a corridor ±1.5 m about a straight segment of 4 + 0.6·Np m
//! (start and goal outside every zone); five layouts per Np, medians reported. The brute force
//! simulates every Σ ∈ {−1, +1}^Np with no stops (the law is the same, so the same paths),
//! normalises the collision-free ones and takes the best; it is run up to Np = 12 (4096
//! simulations, about twenty seconds per layout here) and estimated beyond from its median
//! cost per simulation at Np ≤ 12 — a lower bound, as segments grow with Np — where it
//! becomes infeasible (2^20 ≈ 10^6 simulations).

use std::time::{Duration, Instant};

use mobil_geom::Pose2;
use mobil_planner::vfo::{
    find_sigmas, normalised, path_score, simulate_uninterrupted, Obstacle, OptimiseConfig, OptimiseWarning, RobotEnd,
    Segment, Sigma, VfoController, VfoGains, VfoWaypoint,
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
    let length = 4.0 + 0.6 * n as f64;
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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
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

fn main() {
    // `cargo bench` passes `--bench`; a filter argument picks the obstacle counts to run.
    let only: Option<usize> = std::env::args().skip(1).find_map(|a| a.parse().ok());
    let controller = VfoController::new(VfoGains::default()).expect("valid");
    let config = OptimiseConfig::default();
    let serial = OptimiseConfig { threads: 1, ..config };
    println!(
        "threads: {} available; T_p {} s; medians of {LAYOUTS} layouts",
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        config.time_step
    );
    println!();
    println!(
        "| Np | segment (m) | zones met | virtual robots | paths | \\|D\\| | Alg. 2, 1 thread (ms) | Alg. 2, all threads (ms) | brute force 2^Np (ms) | drive time (s) | real-time factor | caps hit (all layouts) |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    let mut per_sim = Vec::new();
    for n in [1, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30] {
        if only.is_some_and(|o| o != n) {
            continue;
        }
        let mut rows: Vec<[f64; 8]> = Vec::new();
        let mut brute_ms = Vec::new();
        let (mut time_capped, mut capped, mut unsafe_layouts) = (0, 0, 0);
        let mut length = 0.0;
        for seed in 0..LAYOUTS {
            let (obstacles, l) = layout(n, seed);
            length = l;
            let segment = Segment {
                waypoint: VfoWaypoint::new(l, 0.0, 0.0, 0.5).expect("valid"),
                last: true,
                obstacles: &obstacles,
            };
            let t0 = Instant::now();
            let one = find_sigmas(&Pose2::identity(), &controller, &segment, &serial).expect("valid");
            let t_one = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let all = find_sigmas(&Pose2::identity(), &controller, &segment, &config).expect("valid");
            let t_all = t1.elapsed().as_secs_f64();
            assert_eq!(one, all, "the thread count changed the result");
            for w in &all.warnings {
                match w {
                    OptimiseWarning::PathTimeCap { .. } => time_capped += 1,
                    OptimiseWarning::NoSafeSigma => unsafe_layouts += 1,
                    _ => capped += 1,
                }
            }
            if std::env::var_os("VFO_BENCH_DEBUG").is_some() {
                eprintln!(
                    "n {n} seed {seed}: {:?} fates {:?}",
                    all.warnings,
                    all.paths.iter().map(|p| (&p.fate, p.time)).collect::<Vec<_>>()
                );
            }
            let zones = all.sigmas.iter().filter(|s| **s != Sigma::Undecided).count();
            let drive = all.best.map_or(f64::NAN, |b| all.paths[b].time);
            rows.push([
                zones as f64,
                all.robots.len() as f64,
                all.paths.len() as f64,
                all.candidates() as f64,
                t_one * 1e3,
                t_all * 1e3,
                drive,
                drive / t_one.min(t_all),
            ]);
            if n <= BRUTE_MAX {
                let (brute, best) = brute_force(&segment, &config);
                per_sim.push(brute.time.as_secs_f64() / brute.simulations as f64);
                brute_ms.push(brute.time.as_secs_f64() * 1e3);
                // Every Σ the optimiser's candidates drive is among the brute force's, so the
                // brute force finds at least as many safe paths.
                assert!(best.is_some() || all.best.is_none(), "brute force found no safe Σ");
            }
        }
        let col = |i: usize| median(rows.iter().map(|r| r[i]).collect());
        let brute = if brute_ms.is_empty() {
            let est = median(per_sim.clone()) * (1u64 << n) as f64;
            format!("≥ {} (estimated, not run)", human(est))
        } else {
            format!("{:.1}", median(brute_ms))
        };
        println!(
            "| {n} | {length:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {:.2} | {:.2} | {brute} | {:.1} | {:.0}× | {} |",
            col(0),
            col(1),
            col(2),
            col(3),
            col(4),
            col(5),
            col(6),
            col(7),
            notes(time_capped, capped, unsafe_layouts)
        );
    }
}

/// The caps hit over the layouts of one row.
fn notes(time_capped: usize, capped: usize, unsafe_layouts: usize) -> String {
    let mut parts = Vec::new();
    if time_capped > 0 {
        parts.push(format!("{time_capped} paths over the time limit"));
    }
    if capped > 0 {
        parts.push(format!("{capped} optimisations capped"));
    }
    if unsafe_layouts > 0 {
        parts.push(format!("{unsafe_layouts} layouts without a safe Σ"));
    }
    parts.join(", ")
}

fn human(seconds: f64) -> String {
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.0} min", seconds / 60.0)
    } else if seconds < 2.0 * 86400.0 {
        format!("{:.0} h", seconds / 3600.0)
    } else if seconds < 2.0 * 365.0 * 86400.0 {
        format!("{:.0} days", seconds / 86400.0)
    } else {
        format!("{:.0} years", seconds / (365.0 * 86400.0))
    }
}
