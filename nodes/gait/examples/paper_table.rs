//! Reproduces the paper's experiment (SPEC §7): start at the origin with the legs nominal, goal
//! (−10, 10); set A from φ = π/4 and set B from φ = 3π/2; evaluations (1), (2), (3) with the
//! paper's k; under both readings of Tab. 1's "max angle". One complete search per row.
//!
//!     cargo run --release -p mobil_gait --example paper_table [-- --margin M] [--reading forward|rearward]

use mobil_gait::{plan_paper_run, Evaluation, GaitConfig, LegAngleReading, QuadrupedModel, RuleSet};
use std::time::Instant;

/// The paper's (expanded, plan length) for each row.
const PAPER: [(RuleSet, u8, u32, u32); 6] = [
    (RuleSet::A, 1, 284, 45),
    (RuleSet::A, 2, 284, 45),
    (RuleSet::A, 3, 39826, 40),
    (RuleSet::B, 1, 18948, 211),
    (RuleSet::B, 2, 9072, 168),
    (RuleSet::B, 3, 36672, 100),
];

/// CPU time the calling thread has run (ns): a loaded machine does not inflate it.
fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer to a local.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
    } else {
        0
    }
}

fn main() {
    let mut cfg = GaitConfig::default();
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--margin") {
        cfg.stability_margin = args
            .get(i + 1)
            .and_then(|m| m.parse().ok())
            .unwrap_or(cfg.stability_margin);
    }
    println!(
        "margin {} key {} tolerance {} limit {}",
        cfg.stability_margin, cfg.key_quantum, cfg.goal_tolerance, cfg.max_expansions
    );
    println!("reading  | row   | paper exp / len | ours exp / gen / len | leg moves | CPU ms | wall ms | result");
    let readings: Vec<LegAngleReading> = match args.iter().position(|a| a == "--reading") {
        Some(i) => args.get(i + 1).and_then(|r| r.parse().ok()).into_iter().collect(),
        None => vec![LegAngleReading::Forward, LegAngleReading::Rearward],
    };
    for reading in readings {
        let cfg = GaitConfig { reading, ..cfg.clone() };
        let model = QuadrupedModel::paper(reading);
        for (set, e, p_exp, p_len) in PAPER {
            let eval = Evaluation::try_from(e).expect("1..=3");
            let (t, cpu) = (Instant::now(), thread_cpu_ns());
            let p = plan_paper_run(&model, &cfg, set, eval);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let cpu_ms = (thread_cpu_ns() - cpu) as f64 / 1e6;
            println!(
                "{:8} | {},({}) | {:6} / {:3}    | {:6} / {:7} / {:3} | {:9} | {:6.1} | {:7.1} | {}",
                format!("{reading:?}"),
                set,
                e,
                p_exp,
                p_len,
                p.expanded,
                p.generated,
                p.steps.len(),
                p.leg_moves(),
                cpu_ms,
                ms,
                p.failure.map_or("goal".to_string(), |f| f.to_string())
            );
        }
    }
}
