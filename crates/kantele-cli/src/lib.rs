//! The `kantele` command: render, inspect, benchmark, compare and view scenes. The binary is a
//! call of [`run_command_line`]; the Python package's `kantele` command calls it too, so one
//! build of the package gives both the module and the command.
//!
//! Scenes are glTF 2.0 / OBJ / PLY / STL files (loaded by `kantele-scene`) or built-ins
//! (`--builtin cube`), drawn by the rules of the reference scenes. Backends are `cpu` (Kantele)
//! and `gl` (the OpenGL reference, `kantele-gl`).
//!
//! - `render` writes PNG/EXR colour and, optionally, depth (PFM/EXR), normal and id images,
//!   plus a JSON sidecar ([`render_cmd`]).
//! - `info` describes a scene ([`info`]).
//! - `bench` times frames on one or more backends, giving the median after warm-up
//!   ([`bench`](mod@bench)).
//! - `compare` renders with several backends and measures how far the pictures differ, exiting
//!   with 1 when a tolerance is broken ([`compare_cmd`]).
//! - `thumbnail` writes a square PNG framed on a transparent background ([`thumbnail`]).
//! - `view` opens a window with an orbit camera (winit + softbuffer, [`view`]).
//!
//! The argument definitions are in [`cli`], and backend construction is in [`backends`].
//! Errors are printed as one line, `kantele: error: …`, on stderr and exit with status 2. This
//! crate is the only place where Kantele talks to people. The libraries return typed errors.
#![forbid(unsafe_code)]

mod animation;
mod backends;
mod bench;
mod camera_args;
mod cli;
mod compare;
mod compare_cmd;
mod frame_files;
mod frame_writer;
mod info;
mod output;
mod output_plan;
mod render_cmd;
mod scenes;
mod signals;
mod thumbnail;
#[cfg(feature = "viewer")]
mod view;

use std::ffi::OsString;

use clap::error::ErrorKind;
use clap::Parser;

use crate::cli::{Cli, Command};

/// Exit status of an error (usage errors included).
pub const EXIT_ERROR: u8 = 2;
/// Exit status of `compare` when a tolerance is broken.
pub const EXIT_TOLERANCE: u8 = 1;

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `kantele view` (needs the `viewer` feature).
#[cfg(feature = "viewer")]
fn run_view(args: cli::ViewArgs) -> anyhow::Result<()> {
    view::run(args)
}

/// `kantele view` in a build without the viewer.
#[cfg(not(feature = "viewer"))]
fn run_view(_: cli::ViewArgs) -> anyhow::Result<()> {
    anyhow::bail!("view: this kantele was built without the window viewer (cargo install --locked --path crates/kantele-cli --features viewer)")
}

/// The help that explains a usage error: the subcommand's, when the arguments name one.
fn help_command(args: impl IntoIterator<Item = String>) -> String {
    let command = <Cli as clap::CommandFactory>::command();
    args.into_iter()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .filter(|a| command.find_subcommand(a).is_some())
        .map_or_else(
            || "kantele --help".to_string(),
            |sub| format!("kantele {sub} --help"),
        )
}

/// clap's usage error as one line: the problem, what is missing, and its tips ("a similar
/// argument exists"), without the usage block; `help` names the help to read.
fn usage_error_line(text: &str, help: &str) -> String {
    let mut parts: Vec<String> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if !line.is_empty() {
            parts.push(line.strip_prefix("error: ").unwrap_or(line).to_string());
        }
    }
    if parts.is_empty() {
        parts.push("invalid arguments".into());
    }
    let mut message = parts[0].clone();
    for p in &parts[1..] {
        let sep = if message.ends_with(':') { " " } else { "; " };
        message.push_str(sep);
        message.push_str(p);
    }
    format!("{} (see {help})", one_line(&message))
}

/// Reports `KANTELE_ISA`, which the renderer reads without complaint: a value that names no
/// instruction-set level is an error; a level this CPU lacks gets a warning, and the renderer
/// uses its best level instead (the `isa` column of `bench` says which).
fn check_isa_env() -> Result<(), String> {
    if let Some(warning) = kantele::simd::Isa::env_warning()? {
        eprintln!("kantele: warning: {warning}");
    }
    Ok(())
}

/// Runs the `kantele` command on `args` (the program's name first, as `std::env::args_os` gives
/// them) and returns its exit status: 0, [`EXIT_TOLERANCE`] when `compare` finds a tolerance
/// broken, 130 when interrupted, else [`EXIT_ERROR`]. Errors and warnings go to stderr as one
/// line each. The `kantele` binary and the Python package's `kantele` command both call this.
pub fn run_command_line(args: impl IntoIterator<Item = OsString>) -> u8 {
    let args: Vec<OsString> = args.into_iter().collect();
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            let _ = e.print();
            return 0;
        }
        Err(e) if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            return EXIT_ERROR;
        }
        Err(e) => {
            let help = help_command(args.iter().map(|a| a.to_string_lossy().into_owned()));
            eprintln!(
                "kantele: error: {}",
                usage_error_line(&e.to_string(), &help)
            );
            return EXIT_ERROR;
        }
    };
    if let Err(message) = check_isa_env() {
        eprintln!("kantele: error: {message}");
        return EXIT_ERROR;
    }
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(&args).map(|()| true),
        Command::Info(args) => info::run(&args).map(|()| true),
        Command::Bench(args) => bench::run(&args).map(|()| true),
        Command::Compare(args) => compare_cmd::run(&args),
        Command::View(args) => run_view(args).map(|()| true),
        Command::Thumbnail(args) => thumbnail::run(&args).map(|()| true),
    };
    match result {
        Ok(true) => 0,
        Ok(false) => EXIT_TOLERANCE,
        Err(e) if e.is::<signals::Interrupted>() => {
            eprintln!("kantele: {e}");
            signals::EXIT_INTERRUPTED
        }
        Err(e) => {
            eprintln!("kantele: error: {}", one_line(&format!("{e:#}")));
            EXIT_ERROR
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn error_of(args: &[&str]) -> String {
        let help = help_command(args.iter().map(|a| a.to_string()));
        usage_error_line(&Cli::try_parse_from(args).unwrap_err().to_string(), &help)
    }

    #[test]
    fn usage_errors_point_to_the_subcommand_help() {
        let render = error_of(&["kantele", "render", "--bogus"]);
        assert!(render.ends_with("(see kantele render --help)"), "{render}");
        let thumbnail = error_of(&["kantele", "--size", "thumbnail", "a"]);
        assert!(
            thumbnail.ends_with("(see kantele thumbnail --help)"),
            "{thumbnail}"
        );
        let unknown = error_of(&["kantele", "rendr"]);
        assert!(unknown.ends_with("(see kantele --help)"), "{unknown}");
    }

    #[test]
    fn usage_errors_keep_clap_hints() {
        let missing = error_of(&["kantele", "render", "bunny.glb"]);
        assert!(missing.contains("--output"), "{missing}");
        let similar = error_of(&["kantele", "render", "x.glb", "--ouput", "a.png"]);
        assert!(
            similar.contains("similar argument exists: '--output'"),
            "{similar}"
        );
        assert!(!missing.contains('\n') && !similar.contains("Usage"));
    }
}
