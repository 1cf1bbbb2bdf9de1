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

/// Reports that a test cannot run for want of `what`: prints `skipping: REASON` and returns, or
/// panics when `KANTELE_REQUIRE` names `what`.
#[track_caller]
pub fn skip(what: &str, reason: impl Display) {
    if required(what) {
        panic!("KANTELE_REQUIRE names {what}, but {reason}");
    }
    eprintln!("skipping: {reason}");
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
