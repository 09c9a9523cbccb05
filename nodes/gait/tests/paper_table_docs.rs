//! The paper's table as docs/experiments/gait-paper-table.md gives it (and README's line) is
//! what the code computes: every row's expanded / generated / plan length / leg moves under
//! both readings of Tab. 1, and the rearward A,(3) row's failure, run again here from the
//! table's own text.

use mobil_gait::{plan_paper_run, Evaluation, GaitConfig, LegAngleReading, QuadrupedModel, RuleSet};

/// (expanded, generated, plan length, leg moves), or the failure's expansions and generated
/// states.
#[derive(Debug, PartialEq)]
enum Row {
    Plan(u64, u64, u64, u64),
    NoPlan { expansions: u64, generated: u64 },
}

fn numbers(cell: &str) -> Vec<u64> {
    cell.split(|c: char| !c.is_ascii_digit() && c != ' ')
        .flat_map(|part| {
            // "200 000" is one number: digits separated by single spaces within a part.
            let joined: String = part.split_whitespace().collect::<Vec<_>>().join("");
            joined.parse::<u64>().ok()
        })
        .collect()
}

fn parse(cell: &str) -> Row {
    let cell = cell.trim();
    if cell.starts_with("no plan") {
        // "no plan within 200 000 expansions (923 482 generated; 0.59 s)"
        let n = numbers(cell.split('(').next().unwrap_or(""));
        let g = numbers(cell.split('(').nth(1).and_then(|s| s.split(';').next()).unwrap_or(""));
        return Row::NoPlan {
            expansions: n.first().copied().unwrap_or(0),
            generated: g.first().copied().unwrap_or(0),
        };
    }
    let n: Vec<u64> = cell.split('/').filter_map(|s| s.trim().parse().ok()).collect();
    assert_eq!(n.len(), 4, "not four numbers: {cell}");
    Row::Plan(n[0], n[1], n[2], n[3])
}

fn computed(reading: LegAngleReading, set: RuleSet, evaluation: u8) -> Row {
    let cfg = GaitConfig {
        reading,
        ..GaitConfig::default()
    };
    let model = QuadrupedModel::paper(reading);
    let eval = Evaluation::try_from(evaluation).expect("1..=3");
    let p = plan_paper_run(&model, &cfg, set, eval);
    match p.failure {
        None => Row::Plan(
            u64::from(p.expanded),
            u64::from(p.generated),
            p.steps.len() as u64,
            p.leg_moves() as u64,
        ),
        Some(_) => Row::NoPlan {
            expansions: u64::from(p.expanded),
            generated: u64::from(p.generated),
        },
    }
}

#[test]
fn the_docs_gait_table_is_what_the_code_computes() {
    let page = include_str!("../../../docs/experiments/gait-paper-table.md");
    let rows: Vec<&str> = page
        .lines()
        .filter(|l| l.starts_with("| A,(") || l.starts_with("| B,("))
        .collect();
    assert_eq!(rows.len(), 6, "the table's six rows");
    for line in rows {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | row | paper | forward | CPU ms | rearward |
        let row = cells[1];
        let set = if row.starts_with('A') { RuleSet::A } else { RuleSet::B };
        let evaluation: u8 = row[3..4].parse().expect("evaluation digit");
        for (reading, cell) in [
            (LegAngleReading::Forward, cells[3]),
            (LegAngleReading::Rearward, cells[5]),
        ] {
            assert_eq!(computed(reading, set, evaluation), parse(cell), "{row}, {reading:?}");
        }
    }
    // README's line for the experiment quotes B,(3)'s expansions, forward reading.
    let readme = include_str!("../../../README.md");
    let Row::Plan(expanded, ..) = computed(LegAngleReading::Forward, RuleSet::B, 3) else {
        panic!("B,(3) plans");
    };
    assert!(
        readme.contains(&format!("({expanded} states expanded for B,(3)")),
        "README's gait line should quote {expanded} expansions"
    );
}
