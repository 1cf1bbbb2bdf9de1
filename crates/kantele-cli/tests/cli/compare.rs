//! `kantele compare`: CPU against OpenGL, and the bugs it must catch.

use std::process::Command;

use crate::common::{kantele, ok, stderr, stdout, TempDir, BIN};

pub(crate) fn gl_available() -> bool {
    let o = kantele(&[
        "bench",
        "--builtin",
        "cube",
        "--backend",
        "gl",
        "--frames",
        "1",
        "--warmup",
        "0",
    ]);
    if !o.status.success() {
        kantele_testkit::skip(
            "gl",
            format!("the gl backend is unavailable here: {}", stderr(&o).trim()),
        );
    }
    o.status.success()
}

#[test]
fn compare_cpu_and_gl() {
    if !gl_available() {
        return;
    }
    let dir = TempDir::new("compare");
    let o = kantele(&[
        "compare",
        "--builtin",
        "cube",
        "--backends",
        "cpu,gl",
        "--out",
        &dir.s("cmp"),
        "--json",
    ]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).lines().next().unwrap()).unwrap();
    assert_eq!(v["passed"], true);
    for f in ["cube-cpu.png", "cube-gl.png", "cube-diff.png"] {
        assert!(dir.path("cmp").join(f).exists(), "{f} missing");
    }
    // A negative tolerance is a usage error (status 2), not a broken tolerance (status 1).
    let o = kantele(&["compare", "--builtin", "cube", "--max-mean-diff", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-mean-diff"));
}

/// `kantele compare` catches bugs planted in Kantele (built with the `fault-injection`
/// feature for tests): a flipped fill rule and a flipped texture V axis. The same comparison
/// passes without the fault.
#[test]
fn compare_catches_planted_bugs() {
    if !gl_available() {
        return;
    }
    let run = |fault: Option<&str>, scene: &str, extra: &[&str]| {
        let mut cmd = Command::new(BIN);
        cmd.args(["compare", "--builtin", scene, "--backends", "cpu,gl"])
            .args(extra);
        if let Some(f) = fault {
            cmd.env("KANTELE_FAULT", f);
        }
        cmd.output().expect("run kantele")
    };
    // Every edge of `pixel-edges` runs through pixel centres: with the right rule Kantele and
    // OpenGL agree exactly, with the wrong one about a tenth of the coverage differs.
    let exact = ["--max-coverage-diff", "0"];
    ok(&run(None, "pixel-edges", &exact));
    let o = run(Some("fill-rule"), "pixel-edges", &exact);
    assert_eq!(
        o.status.code(),
        Some(1),
        "fill-rule fault not caught: {}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("pixel-edges"), "{}", stderr(&o));
    // A mirrored texture V axis on the textured cube.
    ok(&run(None, "cube", &[]));
    let o = run(Some("flip-v"), "cube", &[]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "flip-v fault not caught: {}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("mean colour difference"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn compare_needs_two_backends() {
    let o = kantele(&["compare", "--builtin", "cube", "--backends", "cpu"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("kantele: error:"));
}
