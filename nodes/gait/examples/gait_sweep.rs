//! How the paper's table (SPEC §7, source 000) moves with the settings the paper does not give:
//! the state key's resolution (`key_quantum`), the tie rule (`tie_break`), k3 of evaluation (3),
//! and the stability margin,
//! forward reading, each row one complete search from the paper's start to (−10, 10). Which
//! setting, if any, brings A,(3) near the paper's 39 826 expansions and B,(1) near its 211
//! states, and what evaluation (3) does to the leg moves across the margin's range.
//!
//!     cargo run --release -p mobil_gait --example gait_sweep

use mobil_gait::{plan_paper_run, Evaluation, GaitConfig, LegAngleReading, QuadrupedModel, RuleSet, TieBreak};

const ROWS: [(RuleSet, u8); 6] = [
    (RuleSet::A, 1),
    (RuleSet::A, 2),
    (RuleSet::A, 3),
    (RuleSet::B, 1),
    (RuleSet::B, 2),
    (RuleSet::B, 3),
];

/// One row: "expanded / states (leg moves)", or why there is no plan.
fn row(cfg: &GaitConfig, set: RuleSet, evaluation: u8) -> String {
    let model = QuadrupedModel::paper(LegAngleReading::Forward);
    let eval = Evaluation::try_from(evaluation).expect("1..=3");
    let p = plan_paper_run(&model, cfg, set, eval);
    match p.failure {
        None => format!("{} / {} ({})", p.expanded, p.steps.len(), p.leg_moves()),
        Some(_) => format!("no plan in {}", p.expanded),
    }
}

fn main() {
    let paper = [
        "284 / 45",
        "284 / 45",
        "39826 / 40",
        "18948 / 211",
        "9072 / 168",
        "36672 / 100",
    ];
    println!("expanded / states in the plan (leg moves), forward reading; the paper's first");
    println!();
    println!("| setting | A,(1) | A,(2) | A,(3) | B,(1) | B,(2) | B,(3) |");
    println!("|---|---|---|---|---|---|---|");
    println!("| the paper | {} |", paper.join(" | "));
    let base = GaitConfig::default();
    for quantum in [1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5] {
        let cfg = GaitConfig {
            key_quantum: quantum,
            ..base.clone()
        };
        let cells: Vec<String> = ROWS.iter().map(|&(s, e)| row(&cfg, s, e)).collect();
        println!("| key {quantum:e} | {} |", cells.join(" | "));
    }
    for quantum in [1e-3, 1e-4] {
        let cfg = GaitConfig {
            key_quantum: quantum,
            tie_break: TieBreak::Newest,
            ..base.clone()
        };
        let cells: Vec<String> = ROWS.iter().map(|&(s, e)| row(&cfg, s, e)).collect();
        println!("| key {quantum:e}, ties newest first | {} |", cells.join(" | "));
    }
    println!();
    println!("| k3 (A's, B's) | A,(3) | B,(3) |");
    println!("|---|---|---|");
    for k3 in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0] {
        let cfg = GaitConfig {
            a3_k3: k3,
            b3_k3: k3,
            ..base.clone()
        };
        println!("| {k3} | {} | {} |", row(&cfg, RuleSet::A, 3), row(&cfg, RuleSet::B, 3));
    }
    println!();
    println!("| A's k3 | A,(3) |");
    println!("|---|---|");
    for i in 70..=80 {
        let k3 = f64::from(i) / 100.0;
        let cfg = GaitConfig {
            a3_k3: k3,
            ..base.clone()
        };
        println!("| {k3:.2} | {} |", row(&cfg, RuleSet::A, 3));
    }
    println!();
    println!("| stability margin | A,(1) | A,(3) | B,(1) | B,(3) |");
    println!("|---|---|---|---|---|");
    for margin in [0.0, 0.01, 0.02, 0.03, 0.05, 0.1, 0.15, 0.2] {
        let cfg = GaitConfig {
            stability_margin: margin,
            ..base.clone()
        };
        println!(
            "| {margin} | {} | {} | {} | {} |",
            row(&cfg, RuleSet::A, 1),
            row(&cfg, RuleSet::A, 3),
            row(&cfg, RuleSet::B, 1),
            row(&cfg, RuleSet::B, 3)
        );
    }
}
