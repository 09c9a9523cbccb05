//! What a run leaves in its output directory, every file written atomically (to `<name>.tmp`,
//! synced, renamed, the directory synced), so an interrupted run never leaves a half-written
//! file; the writes hold [`WRITING`], which a second Ctrl-C takes before it exits, and a run
//! starts by removing the `.tmp` files of these names a killed run may have left (no other;
//! the names and that rule are `mobil_ga_step::output`'s):
//! - `fitness.csv`: `generation,max,mean,min`, one row per generation;
//! - `fitness.svg`: max, mean and min fitness per generation (the source's Fig. 2–3);
//! - `best.motion`: the best individual as a Webots motion file, and `best_gen_NNNN.motion`, the
//!   best of generation NNNN, every 10 generations (0, 10, 20, …);
//! - `best_trajectory.yaml`: the best individual as a `trajectory_msgs/JointTrajectory` (YAML);
//! - `checkpoint.json`: the run's state (see `mobil_ga_step::checkpoint`).

use mobil_ga_step::output::{generation_motion_name, CHECKPOINT, MOTION_EVERY};
use mobil_ga_step::{
    write_fitness_csv, write_joint_trajectory_yaml, write_motion, EvaluatorTag, GaState, GenerationStats,
};
use mobil_tools::plot::{SeriesPanel, Stroke, Svg};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

/// Held while a generation's outputs are written: whoever must end the process at once (a
/// second Ctrl-C) takes it first, so the process ends between two files' writes, never in one.
pub static WRITING: Mutex<()> = Mutex::new(());

/// A pause (ms) between writing each output's temporary file and renaming it, 0 by default: a
/// test's way to land a signal while a write holds [`WRITING`] (`ga_step`'s hidden
/// `--write-delay-ms`).
pub static WRITE_DELAY_MS: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically: to `<path>.tmp`, synced, renamed over `path`, the
/// directory synced. On failure the temporary file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        let delay = WRITE_DELAY_MS.load(Ordering::Relaxed);
        if delay > 0 {
            std::thread::sleep(std::time::Duration::from_millis(delay));
        }
        std::fs::rename(&tmp, path)?;
        mobil_ga_step::checkpoint::sync_parent(path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// `fitness.svg`: max (dark), mean (blue) and min (grey, dashed) fitness per generation, with a
/// title line naming the crossover and the seed.
pub fn fitness_svg(history: &[GenerationStats], title: &str) -> String {
    let series = |f: fn(&GenerationStats) -> f64| -> Vec<(f64, f64)> {
        history.iter().map(|s| (s.generation as f64, f(s))).collect()
    };
    let (max, mean, min) = (series(|s| s.max), series(|s| s.mean), series(|s| s.min));
    // 8 % headroom above the best, so its line stays clear of the frame and the axis name.
    let top = max.iter().map(|p| p.1).filter(|v| v.is_finite()).fold(0.0, f64::max);
    let headroom = [(0.0, 1.08 * top)];
    let panel = SeriesPanel::fit(60.0, 40.0, 640.0, 300.0, &[&max, &mean, &min, &headroom]);
    let mut svg = Svg::new(730.0, 400.0);
    svg.text(60.0, 24.0, 14.0, title);
    svg.series_axes(&panel, "generation", "fitness");
    svg.series(&panel, &min, Stroke::dashed("#8c8c8c", 1.5));
    svg.series(&panel, &mean, Stroke::solid("#1f5fbf", 1.8));
    svg.series(&panel, &max, Stroke::solid("#141414", 2.2));
    svg.text(60.0, 392.0, 11.0, "max — black, mean — blue, min — grey dashed");
    svg.finish()
}

/// Writes every output of `state` (scored by `evaluator`) into `dir` (the checkpoint last, so
/// that a checkpoint on disk always has its outputs beside it), holding [`WRITING`].
pub fn write_all(dir: &Path, state: &GaState, evaluator: &EvaluatorTag) -> anyhow::Result<()> {
    let _writing = WRITING.lock().unwrap_or_else(PoisonError::into_inner);
    let write = |name: &str, bytes: &[u8]| -> anyhow::Result<()> {
        let path = dir.join(name);
        write_atomic(&path, bytes).map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))
    };
    let mut csv = Vec::new();
    write_fitness_csv(&mut csv, &state.history)?;
    write("fitness.csv", &csv)?;
    let title = format!(
        "ga_step: crossover {}, population {}, seed {}",
        state.setup.ga.crossover, state.setup.ga.population, state.seed
    );
    write("fitness.svg", fitness_svg(&state.history, &title).as_bytes())?;
    let best = &state.best().individual;
    let mut motion = Vec::new();
    write_motion(&mut motion, &state.setup.model, best)?;
    write("best.motion", &motion)?;
    if state.generation.is_multiple_of(MOTION_EVERY) {
        write(&generation_motion_name(state.generation), &motion)?;
    }
    let mut yaml = Vec::new();
    write_joint_trajectory_yaml(&mut yaml, &state.setup.model, best)?;
    write("best_trajectory.yaml", &yaml)?;
    let path = dir.join(CHECKPOINT);
    mobil_ga_step::write_checkpoint(state, evaluator, &path)
        .map_err(|e| anyhow::anyhow!("cannot write the checkpoint: {e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(g: u32, max: f64, mean: f64, min: f64) -> GenerationStats {
        GenerationStats {
            generation: g,
            max,
            mean,
            min,
            best_fell: true,
            best_forward: 0.0,
            invalid_fitness: 0,
            evaluations: 10,
        }
    }

    #[test]
    fn the_plot_draws_three_series_over_the_generations() {
        let h = [row(0, 0.5, 0.2, 0.0), row(1, 0.8, 0.4, 0.1), row(2, 1.1, 0.6, 0.2)];
        let svg = fitness_svg(&h, "t");
        assert!(svg.starts_with("<svg"));
        assert_eq!(svg.matches("<polyline").count(), 3);
        // The max series' last point is at the panel's right edge, x = 60 + 640; the value axis
        // runs 0 … 1.08·1.1 = 1.188 over 300 px from y = 40, so 1.1 sits at
        // 40 + (1.188 − 1.1)/1.188·300 = 62.2.
        assert!(svg.contains("700.0,62.2"), "{svg}");
    }

    #[test]
    fn an_atomic_write_replaces_the_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("ga_step_atomic_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert!(!dir.join("a.txt.tmp").exists());
        // A directory that does not exist: an error, and nothing left behind.
        assert!(write_atomic(&dir.join("missing/b.txt"), b"x").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
