//! Test support shared by Kantele's crates.
//!
//! A test that cannot run here (no OpenGL driver, no display, no shared test data) says why and
//! skips — unless the environment variable `KANTELE_REQUIRE` (a comma-separated list such as
//! `gl,display,scenes`) names what it lacks: then it fails, so a CI machine that is meant to have
//! the thing can never pass by skipping. `.ci/run` sets `KANTELE_REQUIRE` for what CI installs.
//!
//! [`compare`] measures how two renderings of one frame differ (coverage, colour, depth, a
//! difference image): `kantele compare` and the OpenGL agreement tests use it.
//!
//! The shared test data is found through `KANTELE_SHARED` ([`shared_root`]).
//!
//! [`demo`] holds the seed documents' two scenes written against the pipeline API, which the
//! core's reference-image and band tests and its `seeds` example render.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod compare;
pub mod demo;
/// Bodies of the `gltf` and `obj` fuzz targets in `fuzz/`, callable from stable tests (not a
/// public API).
#[doc(hidden)]
pub mod fuzz_targets;

use std::fmt::Display;
use std::path::{Path, PathBuf};

/// Whether `KANTELE_REQUIRE` names `what` (`gl`, `display`, `scenes`, `realworld`, `python`, …).
pub fn required(what: &str) -> bool {
    std::env::var("KANTELE_REQUIRE")
        .unwrap_or_default()
        .split(',')
        .any(|w| w.trim() == what)
}

/// Reports that a test cannot run for want of `what` ([`report_skip`]) and returns, or panics
/// when `KANTELE_REQUIRE` names `what`.
#[track_caller]
pub fn skip(what: &str, reason: impl Display) {
    if required(what) {
        panic!("KANTELE_REQUIRE names {what}, but {reason}");
    }
    report_skip(reason);
}

/// The variable naming the file every skip is appended to, one line each; `.ci/test` sets it
/// and ends its run with one line that sums the file up, Rust and Python skips together.
pub const SKIP_LOG_VAR: &str = "KANTELE_SKIP_LOG";

/// Says that the running test skips, and why, where a plain `cargo test` shows it: `skipping
/// TEST: REASON` written straight to the process's standard error (the harness captures only
/// `eprintln!`), and appended to the file `$KANTELE_SKIP_LOG` names, if any.
pub fn report_skip(reason: impl Display) {
    use std::io::Write;
    let line = skip_line(reason);
    let _ = writeln!(std::io::stderr().lock(), "{line}");
    if let Some(path) = std::env::var_os(SKIP_LOG_VAR).filter(|p| !p.is_empty()) {
        append_line(Path::new(&path), &line);
    }
}

/// `skipping TEST: REASON` on one line, the test named by its thread.
fn skip_line(reason: impl Display) -> String {
    let thread = std::thread::current();
    let text = format!("skipping {}: {reason}", thread.name().unwrap_or("a test"));
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Appends `line` to the file at `path` in one write, so that lines appended by parallel tests
/// and processes do not interleave; a log that cannot be written is left alone.
fn append_line(path: &Path, line: &str) {
    use std::io::Write;
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path);
    if let Ok(mut file) = file {
        let _ = file.write_all(format!("{line}\n").as_bytes());
    }
}

/// The folder of the test data that is not in the repository (`scenes/`, `realworld/`; see
/// `docs/rendering-rules.md`, "Reference scenes"): `$KANTELE_SHARED` when it is set and not
/// empty (give an absolute path: tests run in their crate's folder), else `../shared` beside the
/// checkout.
pub fn shared_root() -> PathBuf {
    match std::env::var_os("KANTELE_SHARED") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared"),
    }
}

/// `<shared_root>/<name>` (`scenes`, `realworld`) when it exists; otherwise [`skip`]s for
/// `name` and returns `None`.
#[track_caller]
pub fn shared_dir(name: &str) -> Option<PathBuf> {
    let dir = shared_root().join(name);
    if dir.is_dir() {
        Some(dir)
    } else {
        skip(name, format!("{} is absent", dir.display()));
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skips_are_appended_to_the_log_one_line_each() {
        let log = std::env::temp_dir().join(format!("kantele-skips-{}.log", std::process::id()));
        let _ = std::fs::remove_file(&log);
        append_line(&log, &skip_line("no thing\nhere"));
        append_line(&log, &skip_line("none either"));
        let text = std::fs::read_to_string(&log).unwrap();
        let _ = std::fs::remove_file(&log);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2, "{text}");
        assert!(
            lines[0].starts_with("skipping tests::skips_are_appended"),
            "{text}"
        );
        assert!(lines[0].ends_with(": no thing here"), "{text}");
    }

    #[test]
    fn require_list_is_comma_separated() {
        // Only reads the variable; the test does not change the environment (tests run in
        // parallel threads).
        let listed = std::env::var("KANTELE_REQUIRE").unwrap_or_default();
        for name in listed.split(',').filter(|n| !n.trim().is_empty()) {
            assert!(required(name.trim()));
        }
        assert!(!required("no-such-requirement-name"));
    }
}
