//! The `kantele` command: render, inspect, benchmark, compare and view scenes.

mod backends;
mod bench;
mod camera_math;
mod cli;
mod compare;
mod compare_cmd;
mod info;
mod output;
mod render_cmd;
mod scenes;
mod view;

use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::Parser;

use crate::cli::{Cli, Command};

/// Exit status of an error (usage errors included).
const EXIT_ERROR: u8 = 2;
/// Exit status of `compare` when a tolerance is broken.
const EXIT_TOLERANCE: u8 = 1;

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            return ExitCode::from(EXIT_ERROR);
        }
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("invalid arguments");
            let first = first.strip_prefix("error: ").unwrap_or(first);
            eprintln!("kantele: error: {} (see kantele --help)", one_line(first));
            return ExitCode::from(EXIT_ERROR);
        }
    };
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(&args).map(|()| true),
        Command::Info(args) => info::run(&args).map(|()| true),
        Command::Bench(args) => bench::run(&args).map(|()| true),
        Command::Compare(args) => compare_cmd::run(&args),
        Command::View(args) => view::run(args).map(|()| true),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(EXIT_TOLERANCE),
        Err(e) => {
            eprintln!("kantele: error: {}", one_line(&format!("{e:#}")));
            ExitCode::from(EXIT_ERROR)
        }
    }
}
