//! End-to-end tests of the `kantele` binary, one module per command or subject. One test binary:
//! a binary per file would compile the shared generic code and link every dependency into each
//! (in a clean build, 31 test binaries took a quarter of CI's compile time).
//!
//! Tests that need the real renderer and loaders (built-in scenes, shared scenes) are written
//! against the expected behaviour. Tests reading `$KANTELE_SHARED/scenes` skip with a message
//! when the directory is absent; the viewer test skips when `xvfb-run` is not on PATH.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Output;

#[path = "../common/mod.rs"]
mod common;

mod bands;
mod choices;
mod compare;
mod errors;
mod info_bench;
mod msaa;
mod render;
mod render_data;
mod shared_scenes;
mod texture_memory;
mod thumbnail;
mod workloads;
// The viewer is an optional feature; the lean build has no `view` command to test.
#[cfg(feature = "viewer")]
mod view;

use common::{stderr, TempDir};

/// A failure: non-zero status, exactly one line `kantele: error: ...` mentioning `needle`, no
/// panic, nothing written to `dir`.
fn assert_clean_failure(o: &Output, needle: &str, dir: &TempDir, keep: &[&str]) {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert!(!err.contains("panicked"), "panic: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line on stderr, got: {err}");
    assert!(lines[0].starts_with("kantele: error: "), "{err}");
    assert!(
        lines[0].contains(needle),
        "message should mention '{needle}': {err}"
    );
    let left: Vec<String> = dir
        .files()
        .into_iter()
        .filter(|f| !keep.contains(&f.as_str()))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

fn shared_scenes() -> Option<PathBuf> {
    kantele_testkit::shared_dir("scenes")
}

fn distinct_colors(img: &image::RgbaImage) -> usize {
    img.pixels().map(|p| p.0).collect::<HashSet<_>>().len()
}

/// Reads a single-channel PFM file: width, height and the values, top row first.
fn read_pfm(path: &Path) -> (u32, u32, Vec<f32>) {
    let data = std::fs::read(path).unwrap();
    let text_end = {
        let mut newlines = 0;
        data.iter()
            .position(|&b| {
                if b == b'\n' {
                    newlines += 1;
                }
                newlines == 3
            })
            .unwrap()
            + 1
    };
    let header = std::str::from_utf8(&data[..text_end]).unwrap();
    let mut it = header.split_whitespace();
    assert_eq!(it.next(), Some("Pf"));
    let w: u32 = it.next().unwrap().parse().unwrap();
    let h: u32 = it.next().unwrap().parse().unwrap();
    assert_eq!(it.next(), Some("-1.0"));
    let vals: Vec<f32> = data[text_end..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(vals.len(), (w * h) as usize);
    // PFM stores rows bottom to top; return them top to bottom like every other image here.
    let vals = vals
        .chunks_exact(w as usize)
        .rev()
        .flatten()
        .copied()
        .collect();
    (w, h, vals)
}
