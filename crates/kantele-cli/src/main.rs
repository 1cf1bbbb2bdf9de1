//! The `kantele` command: render, inspect, benchmark, compare and view scenes.
//!
//! Scenes are glTF 2.0 / OBJ files (loaded by `kantele-io`) or built-ins (`--builtin cube`),
//! drawn by the rules of the reference scenes. Backends are `cpu` (Kantele) and `gl` (the
//! OpenGL reference, `kantele-gl`).
//!
//! - `render` writes PNG/EXR colour and, optionally, depth (PFM/EXR), normal and id images,
//!   plus a JSON sidecar ([`render_cmd`]).
//! - `info` describes a scene ([`info`]).
//! - `bench` times frames on one or more backends, giving the median after warm-up
//!   ([`bench`](mod@bench)).
//! - `compare` renders with several backends and measures how far the pictures differ, exiting
//!   with 1 when a tolerance is broken ([`compare_cmd`]).
//! - `view` opens a window with an orbit camera (winit + softbuffer, [`view`]).
//!
//! The argument definitions are in [`cli`], and backend construction is in [`backends`].
//! Errors are printed as one line, `kantele: error: …`, on stderr and exit with status 2. This
//! crate is the only place where Kantele talks to people. The libraries return typed errors.

mod backends;
mod bench;
mod camera_args;
mod cli;
mod compare;
mod compare_cmd;
mod frame_files;
mod info;
mod output;
mod output_plan;
mod render_cmd;
mod scenes;
mod signals;
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
        Err(e) if e.is::<signals::Interrupted>() => {
            eprintln!("kantele: {e}");
            ExitCode::from(signals::EXIT_INTERRUPTED)
        }
        Err(e) => {
            eprintln!("kantele: error: {}", one_line(&format!("{e:#}")));
            ExitCode::from(EXIT_ERROR)
        }
    }
}
