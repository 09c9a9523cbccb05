//! Long searches: B,(3) from the paper's start toward goals 10 to 1 000 [j] away (along the
//! paper's direction, (−1, 1)/√2), the time per expansion against the goal's distance. Budget:
//! the time per expansion at 1 000 [j] within 1.3× of that at 10 [j] — a search that slows as
//! it grows is paying for memory, not work.
//!
//!     cargo bench -p mobil_gait --bench long
//!
//! Each search runs three times and the least thread CPU time counts
//! (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`: time the thread waited for a core is not in it).
//! The search's memory is estimated from its distinct states and the sizes of what it stores
//! for each (`mobil_gait::search::bytes_per_state`).

use mobil_gait::search::{bytes_per_state, search, SearchEnd};
use mobil_gait::{BodyPose, Evaluation, GaitConfig, GaitProblem, GaitState, QuadrupedModel, RuleSet};
use nalgebra::Point2;
use std::f64::consts::PI;
use std::hint::black_box;

/// CPU time the calling thread has run (ns).
fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer to a local.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "CLOCK_THREAD_CPUTIME_ID");
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

fn main() {
    let cfg = GaitConfig::default();
    let model = QuadrupedModel::paper(cfg.reading);
    let start = GaitState::nominal(
        &model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 1.5 * PI,
        },
    );
    println!("B,(3) from the paper's start; goal d [j] away toward (−1, 1); least thread CPU time of 3");
    println!();
    println!(
        "| d [j] | expanded | generated | distinct | plan states | time (ms) | per expansion (µs) | against 10 [j] | memory (MB) |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut first = None;
    for d in [10.0, 30.0, 100.0, 300.0, 1000.0] {
        let goal = Point2::new(-d / 2f64.sqrt(), d / 2f64.sqrt());
        let mut best = u64::MAX;
        let mut result = None;
        let problem = GaitProblem {
            model: &model,
            cfg: &cfg,
            goal,
            set: RuleSet::B,
            eval: Evaluation::Three,
            weights: cfg.weights(RuleSet::B, Evaluation::Three),
        };
        for _ in 0..3 {
            let t = thread_cpu_ns();
            let r = search(&problem, start, cfg.max_expansions, &mut || false);
            best = best.min(thread_cpu_ns() - t);
            result = Some(black_box(r));
        }
        let p = result.expect("ran");
        assert_eq!(p.end, SearchEnd::Goal, "B,(3) reaches a goal {d} [j] away");
        let per = best as f64 / 1e3 / f64::from(p.expanded);
        let base = *first.get_or_insert(per);
        println!(
            "| {d:.0} | {} | {} | {} | {} | {:.1} | {per:.2} | {:.2}× | {:.1} |",
            p.expanded,
            p.generated,
            p.distinct,
            p.path.len(),
            best as f64 / 1e6,
            per / base,
            f64::from(p.distinct) * bytes_per_state::<GaitProblem<'_>>() as f64 / 1e6,
        );
    }
}
