//! The run's files, as pure functions over writers and readers: `fitness.csv`, Webots motion
//! files (writer and reader) and the best individual as a `trajectory_msgs/JointTrajectory`
//! in YAML; and their names in a run's output directory ([`OUTPUTS`],
//! [`generation_motion_name`]), with the temporary files a killed writer may leave
//! ([`is_own_temporary`], [`remove_temporaries`]).

use crate::error::MotionError;
use crate::ga::GenerationStats;
use crate::model::{joint_names, Individual, NaoModel, Servo, INTERVALS, KNOTS, SAMPLE_PERIOD_MS, SERVO_COUNT};
use std::io::{self, BufRead, Write};

/// The header line of `fitness.csv`.
pub const FITNESS_CSV_HEADER: &str = "generation,max,mean,min";

/// One row of `fitness.csv` (no newline): the generation, then max, mean and min fitness in
/// their shortest round-trip decimal form.
pub fn fitness_csv_row(stats: &GenerationStats) -> String {
    format!("{},{},{},{}", stats.generation, stats.max, stats.mean, stats.min)
}

/// `fitness.csv`: the header and one row per generation.
pub fn write_fitness_csv<W: Write>(mut w: W, history: &[GenerationStats]) -> io::Result<()> {
    writeln!(w, "{FITNESS_CSV_HEADER}")?;
    for h in history {
        writeln!(w, "{}", fitness_csv_row(h))?;
    }
    Ok(())
}

/// The first field of a motion file's header.
pub const MOTION_TAG: &str = "#WEBOTS_MOTION";
/// The motion format's version field.
pub const MOTION_VERSION: &str = "V1.0";

/// A row's time as Webots writes it, `MM:SS:mmm` (minutes, seconds, milliseconds).
pub fn motion_time(ms: u64) -> String {
    format!("{:02}:{:02}:{:03}", ms / 60_000, (ms / 1000) % 60, ms % 1000)
}

/// An angle with 4 decimals; a value that rounds to zero is written `0.0000`, never `-0.0000`.
fn angle(v: f64) -> String {
    let s = format!("{v:.4}");
    if s == "-0.0000" {
        "0.0000".to_owned()
    } else {
        s
    }
}

/// A Webots motion file of the individual (SPEC §8): the header `#WEBOTS_MOTION,V1.0,` followed
/// by the ten joint names (Webots' names, genome order), then a row every 40 ms from 0 to T
/// inclusive: `MM:SS:mmm,Pose<k>,` (k from 1) and the ten angles in rad with 4 decimals, all
/// separated by commas without spaces (the standard form; the source's writer adds spaces and an
/// empty field after the version). Only the ten evolved joints are listed: Webots leaves the
/// others (hip yaw-pitch, arms, head) where they are, at the standing pose.
pub fn write_motion<W: Write>(mut w: W, model: &NaoModel, individual: &Individual) -> io::Result<()> {
    writeln!(w, "{MOTION_TAG},{MOTION_VERSION},{}", joint_names().join(","))?;
    for (k, (ms, angles)) in individual.sample(model).into_iter().enumerate() {
        let values: Vec<String> = angles.iter().map(|&v| angle(v)).collect();
        writeln!(w, "{},Pose{},{}", motion_time(ms), k + 1, values.join(","))?;
    }
    Ok(())
}

/// One row of a motion file.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionRow {
    /// Time from the start (ms).
    pub time_ms: u64,
    /// The pose's label, as written (`Pose1`, …).
    pub label: String,
    /// One angle (rad) per joint, in the header's order.
    pub values: Vec<f64>,
}

/// A motion file's content.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// The joints' names, in column order.
    pub joint_names: Vec<String>,
    /// The rows, times strictly increasing.
    pub rows: Vec<MotionRow>,
}

impl Motion {
    /// The individual [`write_motion`] wrote this motion from, for `model`: each servo's column
    /// found by its Webots name, each inner knot read from the row at its time or, between rows,
    /// extrapolated along the line through the first and last rows of its interval before it
    /// (the motion is linear within an interval), clamped into the servo's limits; the first and
    /// last knots are the standing pose. A row's value is within 5·10⁻⁵ of the motion (4
    /// decimals), so an extrapolated knot r of the baseline past the last row is within
    /// 5·10⁻⁵·(1 + 2r): r = ¼ and 7.5e-5 rad for the default 2 s step, under 1.5e-4 for any
    /// step (r < 1: rows 40 ms apart, a knot less than 40 ms past the last). The result is
    /// then sampled as `write_motion` would and must give the file's rows, times exactly and
    /// values within [`MOTION_MATCH`], so a motion of another standing pose, another grid or no
    /// such individual at all is refused, as are a missing servo column, a row without its
    /// value, and a knot with fewer than two rows in its interval before it (possible only
    /// with intervals under 80 ms, a step under 1.6 s: at 0.88 s the knot at 88 ms has the
    /// row at 80 ms alone; 1.2 s passes).
    pub fn to_individual(&self, model: &NaoModel) -> Result<Individual, MotionError> {
        let not = |reason: String| MotionError::NotAStep(reason);
        model.validate().map_err(|e| not(format!("the model: {e}")))?;
        let step_ms = model.step_time_ms();
        let last = self.rows.last().map_or(0, |r| r.time_ms);
        if last != step_ms {
            return Err(not(format!(
                "the last row is at {last} ms, the step lasts {step_ms} ms"
            )));
        }
        // Knot k at k·T/20: whole milliseconds, T being a whole number of 40 ms rows.
        let knot_ms = |k: usize| k as u64 * step_ms / INTERVALS as u64;
        let mut cols = [0; SERVO_COUNT];
        for s in Servo::ALL {
            cols[s.index()] = self
                .joint_names
                .iter()
                .position(|n| n == s.name())
                .ok_or_else(|| not(format!("no column {}", s.name())))?;
        }
        let mut ind = model.standing();
        for s in Servo::ALL {
            let col = cols[s.index()];
            let value = |r: &MotionRow| {
                r.values
                    .get(col)
                    .copied()
                    .ok_or_else(|| not(format!("the row at {} ms has no {}", r.time_ms, s.name())))
            };
            for k in 1..KNOTS - 1 {
                let (start, ms) = (knot_ms(k - 1), knot_ms(k));
                let v = if let Some(r) = self.rows.iter().find(|r| r.time_ms == ms) {
                    value(r)?
                } else {
                    let before: Vec<&MotionRow> =
                        self.rows.iter().filter(|r| (start..ms).contains(&r.time_ms)).collect();
                    let (Some(a), Some(b)) = (before.first(), before.last()) else {
                        return Err(not(format!(
                            "knot {k} at {ms} ms has no row between it and the knot before"
                        )));
                    };
                    if b.time_ms <= a.time_ms {
                        return Err(not(format!(
                            "knot {k} at {ms} ms has fewer than two rows between it and the knot before"
                        )));
                    }
                    let (ta, tb) = (a.time_ms as f64, b.time_ms as f64);
                    let (va, vb) = (value(a)?, value(b)?);
                    vb + (vb - va) * (ms as f64 - tb) / (tb - ta)
                };
                ind.knots[s.index()][k] = s.clamp(v);
            }
        }
        // Written again, the individual must give this file's rows.
        let rows = ind.sample(model);
        if rows.len() != self.rows.len() {
            return Err(not(format!(
                "{} rows, a step of {step_ms} ms has {}",
                self.rows.len(),
                rows.len()
            )));
        }
        for (row, (ms, angles)) in self.rows.iter().zip(rows) {
            if row.time_ms != ms {
                return Err(not(format!("a row at {} ms where one at {ms} ms was due", row.time_ms)));
            }
            for s in Servo::ALL {
                let Some(&want) = row.values.get(cols[s.index()]) else {
                    return Err(not(format!("the row at {ms} ms has no {}", s.name())));
                };
                let got = angles[s.index()];
                // NaN (a hand-built row) is no match either.
                let matches = (got - want).abs() <= MOTION_MATCH;
                if !matches {
                    return Err(not(format!(
                        "{} at {ms} ms is {want}, and no individual of this model gives it ({got:.4} here)",
                        s.name()
                    )));
                }
            }
        }
        Ok(ind)
    }
}

/// How far (rad) a motion file's value may be from the individual
/// [`Motion::to_individual`] builds from it: 5·10⁻⁵ of the file's rounding plus 1.5·10⁻⁴ of
/// the knots' (the rows are interpolated between knots, so within the knots' error), with
/// room for rounding in the arithmetic.
pub const MOTION_MATCH: f64 = 2.5e-4;

fn parse_time(s: &str) -> Option<u64> {
    let mut parts = s.split(':');
    let (m, sec, ms) = (parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some() || sec.len() != 2 || ms.len() != 3 || m.len() < 2 {
        return None;
    }
    let digits = |t: &str| {
        t.bytes()
            .all(|b| b.is_ascii_digit())
            .then(|| t.parse::<u64>().ok())
            .flatten()
    };
    let (m, sec, ms) = (digits(m)?, digits(sec)?, digits(ms)?);
    (sec < 60).then(|| m.checked_mul(60_000)?.checked_add(sec * 1000 + ms))?
}

/// Reads a Webots motion file: the header `#WEBOTS_MOTION,V1.0,` and at least one joint name
/// (fields are trimmed and empty header fields skipped, so the source's spaced form reads too),
/// then rows of a `MM:SS:mmm` time, a label and one finite value per joint, times strictly
/// increasing. Blank lines are skipped.
pub fn read_motion<R: BufRead>(r: R) -> Result<Motion, MotionError> {
    let mut lines = r.lines().enumerate();
    let header = match lines.next() {
        Some((_, Ok(l))) => l,
        Some((_, Err(e))) => return Err(MotionError::Io(e.to_string())),
        None => return Err(MotionError::BadHeader),
    };
    let mut fields = header.split(',').map(str::trim);
    if fields.next() != Some(MOTION_TAG) || fields.next() != Some(MOTION_VERSION) {
        return Err(MotionError::BadHeader);
    }
    let joint_names: Vec<String> = fields.filter(|f| !f.is_empty()).map(str::to_owned).collect();
    if joint_names.is_empty() {
        return Err(MotionError::BadHeader);
    }
    let mut rows: Vec<MotionRow> = Vec::new();
    for (i, line) in lines {
        let line = line.map_err(|e| MotionError::Io(e.to_string()))?;
        if line.trim().is_empty() {
            continue;
        }
        let bad = |reason: String| MotionError::BadRow { line: i + 1, reason };
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != joint_names.len() + 2 {
            return Err(bad(format!(
                "{} fields, expected a time, a label and {} values",
                fields.len(),
                joint_names.len()
            )));
        }
        let time_ms = parse_time(fields[0]).ok_or_else(|| bad(format!("time `{}` is not MM:SS:mmm", fields[0])))?;
        if let Some(prev) = rows.last()
            && time_ms <= prev.time_ms
        {
            return Err(bad(format!(
                "time {} is not after {}",
                fields[0],
                motion_time(prev.time_ms)
            )));
        }
        if fields[1].is_empty() {
            return Err(bad("empty pose label".into()));
        }
        let values = fields[2..]
            .iter()
            .map(|f| f.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(|| bad("a joint value is not a finite number".into()))?;
        rows.push(MotionRow {
            time_ms,
            label: fields[1].to_owned(),
            values,
        });
    }
    Ok(Motion { joint_names, rows })
}

/// A float as YAML 1.1 (PyYAML, which `ros2 topic pub` uses) reads it back as a float: the
/// shortest round-trip decimal, never in exponent form, always with a point.
fn yaml_float(v: f64) -> String {
    let s = format!("{v}");
    if s.contains('.') {
        s
    } else {
        s + ".0"
    }
}

/// The individual as a `trajectory_msgs/JointTrajectory` in YAML (the form `ros2 topic pub`
/// takes): `joint_names` (genome order) and one point per knot (21, at i·T/20) with
/// `positions` (rad, shortest round-trip decimals, never in exponent form) and `time_from_start` as `{sec, nanosec}`.
/// The knots describe the piecewise-linear trajectory exactly for a follower that interpolates
/// linearly between positions-only points, as ros2_controllers' joint trajectory controller
/// does. The header is left empty (stamp 0: start on receipt).
pub fn write_joint_trajectory_yaml<W: Write>(mut w: W, model: &NaoModel, individual: &Individual) -> io::Result<()> {
    writeln!(w, "header:")?;
    writeln!(w, "  stamp: {{sec: 0, nanosec: 0}}")?;
    writeln!(w, "  frame_id: ''")?;
    writeln!(w, "joint_names: [{}]", joint_names().join(", "))?;
    writeln!(w, "points:")?;
    for k in 0..KNOTS {
        let ns = model.knot_time_ns(k);
        let positions: Vec<String> = individual.knots.iter().map(|s| yaml_float(s[k])).collect();
        writeln!(w, "  - positions: [{}]", positions.join(", "))?;
        writeln!(
            w,
            "    time_from_start: {{sec: {}, nanosec: {}}}",
            ns / 1_000_000_000,
            ns % 1_000_000_000
        )?;
    }
    Ok(())
}

/// Rows a motion file of `model`'s step has: T/40 ms + 1.
pub fn motion_rows(model: &NaoModel) -> u64 {
    model.step_time_ms() / SAMPLE_PERIOD_MS + 1
}

/// The checkpoint's file name in a run's output directory.
pub const CHECKPOINT: &str = "checkpoint.json";
/// The outputs with a fixed name (besides `best_gen_NNNN.motion`).
pub const OUTPUTS: [&str; 5] = [
    "fitness.csv",
    "fitness.svg",
    "best.motion",
    "best_trajectory.yaml",
    CHECKPOINT,
];
/// Generations between two `best_gen_NNNN.motion` files.
pub const MOTION_EVERY: u32 = 10;

/// The name of generation `g`'s motion file.
pub fn generation_motion_name(g: u32) -> String {
    format!("best_gen_{g:04}.motion")
}

/// Whether `name` is a temporary file of a run's outputs: one of their names (the fixed ones,
/// or `best_gen_` with four or more digits `.motion`) followed by `.tmp`.
pub fn is_own_temporary(name: &str) -> bool {
    let Some(output) = name.strip_suffix(".tmp") else {
        return false;
    };
    if OUTPUTS.contains(&output) {
        return true;
    }
    output
        .strip_prefix("best_gen_")
        .and_then(|rest| rest.strip_suffix(".motion"))
        .is_some_and(|digits| digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit()))
}

/// Removes the temporary files of a run's outputs from `dir` (left by a process killed while
/// writing); any other file, `*.tmp` or not, is left alone. Best effort.
pub fn remove_temporaries(dir: &std::path::Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        if e.file_name().to_str().is_some_and(is_own_temporary) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}
