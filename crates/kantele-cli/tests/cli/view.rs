//! `kantele view` under a virtual display (compiled with the `viewer` feature only; see
//! `main.rs`).

use std::process::Command;

use crate::common::{ok, TempDir, BIN};
use crate::distinct_colors;

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
        .unwrap_or(false)
}

#[test]
fn viewer_under_xvfb() {
    if !on_path("xvfb-run") {
        kantele_testkit::skip(
            "display",
            "xvfb-run is not on PATH (apt-get install xvfb xauth)",
        );
        return;
    }
    let dir = TempDir::new("view");
    let shot = dir.s("shot.png");
    let o = Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 1024x768x24",
            BIN,
            "view",
            "--builtin",
            "cube",
            "--size",
            "160x120",
        ])
        .args(["--frames", "5", "--screenshot", &shot])
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run xvfb-run");
    ok(&o);
    let img = image::open(&shot).unwrap().to_rgba8();
    assert!(img.width() > 0 && img.height() > 0);
    assert!(distinct_colors(&img) > 1, "screenshot is uniform");
}
