//! `ga_step`: evolves a Nao humanoid's forward step (see `ga_step --help`). Exit status 0 when
//! the run stops by itself, 130 after Ctrl-C (the run can be resumed), 1 on an error and 2 on a
//! bad command line; every error is one line on stderr. ROS arguments (for `--evaluator ros`)
//! follow `--ros-args`, as for the suite's other nodes.

use clap::Parser as _;
use mobil_ga_step::StopReason;
use mobil_ga_step_node::outputs::WRITING;
use mobil_ga_step_node::run::{run, Cli, EvaluatorArg, InterruptedBeforeStart};
use mobil_ros::args::split_ros_args;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn main() -> ExitCode {
    let (own, ros_args) = match split_ros_args(std::env::args().skip(1)) {
        Ok(split) => split,
        Err(e) => {
            eprintln!("ga_step: {e} (see ga_step --help)");
            return ExitCode::from(2);
        }
    };
    // Alone, it needs none of the required options (clap would ask for them first).
    if own.len() == 1 && own[0] == "--params-markdown" {
        print!(
            "{}\nThe parameter file (`--params FILE`, `ga_step: ros__parameters:`):\n\n{}",
            mobil_ga_step_node::run::options_markdown(),
            mobil_ga_step_node::params::keys_markdown()
        );
        return ExitCode::SUCCESS;
    }
    let cli = match Cli::try_parse_from(std::iter::once("ga_step".to_owned()).chain(own)) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // clap's message is several lines (the error, its details, usage, hints): keep the
            // error and its details, on one line.
            let text = e.to_string();
            let message = text
                .lines()
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect::<Vec<_>>()
                .join(" ");
            let message = message.trim_start_matches("error: ");
            eprintln!("ga_step: {message} (see ga_step --help)");
            return ExitCode::from(2);
        }
    };
    // Warnings and errors only, unless --ros-args --log-level asks for more: the progress bar
    // and the last line are the run's output.
    let mut ros_args = ros_args;
    if ros_args.log_level.is_none() {
        ros_args.log_level = Some("warn".to_owned());
    }
    mobil_ros::node::init_process(&ros_args);
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    let external = cli.evaluator == EvaluatorArg::Ros;
    let handler = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            // A second interrupt: stop now, but not in the middle of writing the outputs (the
            // lock is held until the process is gone, so no write starts either).
            let _writing = WRITING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            eprintln!("ga_step: interrupted again; stopped at once (resume with --resume)");
            std::process::exit(130);
        }
        if external {
            eprintln!(
                "ga_step: interrupted; stopping now, the generation in flight lost (Ctrl-C again to stop at once)"
            );
        } else {
            eprintln!("ga_step: interrupted; stopping after the generation in flight (Ctrl-C again to stop at once)");
        }
    });
    if let Err(e) = handler {
        eprintln!("ga_step: cannot handle Ctrl-C: {e}");
        return ExitCode::FAILURE;
    }
    match run(&cli, &ros_args, &interrupt) {
        Ok(summary) => {
            println!("{}", summary.line(&cli.out));
            if summary.reason == StopReason::Interrupted {
                ExitCode::from(130)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) if e.is::<InterruptedBeforeStart>() => {
            eprintln!("ga_step: {e}");
            ExitCode::from(130)
        }
        Err(e) => {
            let text = format!("{e:#}").replace('\n', " ");
            eprintln!("ga_step: {text}");
            ExitCode::FAILURE
        }
    }
}
