//! The `kantele` binary: the command line of [`kantele_cli::run_command_line`].
#![forbid(unsafe_code)]

use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(kantele_cli::run_command_line(std::env::args_os()))
}
