//! The workload suite of `benches/workloads/`: it builds from the shared files, each workload
//! is what it says it is, and the CPU backend's picture of every one agrees with OpenGL's
//! within `kantele compare`'s bounds (the reference scenes' bounds).

use std::path::Path;
use std::process::Command;

use crate::common::{kantele, stderr, stdout, TempDir};
use crate::compare::gl_available;

/// The workloads the generator builds: name, draws at least, textures at least.
const WORKLOADS: [(&str, u64, u64); 9] = [
    ("city-1080p", 167, 20),
    ("billboards-blend-1080p", 241, 2),
    ("closeup-4k", 1, 1),
    ("interior-1080p", 287, 24),
    ("vertex-colors-1080p", 1, 0),
    ("cad-assembly-1080p", 2000, 0),
    ("cad-thumbnail-256", 115, 0),
    ("scan-1080p", 1, 0),
    ("scan-far-1080p", 1, 0),
];

#[test]
fn workloads_build_and_agree_with_opengl() {
    let shared = kantele_testkit::shared_root();
    if kantele_testkit::shared_dir("scenes").is_none()
        || kantele_testkit::shared_dir("realworld").is_none()
    {
        return;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/workloads/generate.py");
    let dir = TempDir::new("workloads");
    let generated = Command::new("python3")
        .arg(&script)
        .arg(dir.path("suite"))
        .arg("--shared")
        .arg(&shared)
        .output();
    let generated = match generated {
        Ok(output) => output,
        Err(e) => {
            kantele_testkit::skip("python", format!("python3 cannot be run: {e}"));
            return;
        }
    };
    assert!(
        generated.status.success(),
        "the generator failed: {}",
        stderr(&generated)
    );

    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path("suite").join("workloads.json")).expect("workloads.json"),
    )
    .expect("workloads.json is JSON");
    let entries = index.as_array().expect("a list");
    assert_eq!(entries.len(), WORKLOADS.len(), "{index}");
    for (name, draws, textures) in WORKLOADS {
        let entry = entries
            .iter()
            .find(|e| e["name"] == name)
            .unwrap_or_else(|| panic!("{name} missing from {index}"));
        assert!(entry["draws"].as_u64().unwrap() >= draws, "{entry}");
        assert!(entry["textures"].as_u64().unwrap() >= textures, "{entry}");
    }
    // The big scan is big: 16 times the statue's 99 938 triangles.
    let scan = entries.iter().find(|e| e["name"] == "scan-1080p").unwrap();
    assert_eq!(scan["triangles"], 99_938 * 16);

    if !gl_available() {
        return;
    }
    let suite = dir.s("suite");
    let o = kantele(&["compare", &suite, "--backends", "cpu,gl", "--json"]);
    let rows: Vec<serde_json::Value> = stdout(&o)
        .lines()
        .map(|line| serde_json::from_str(line).expect("one JSON object a line"))
        .collect();
    assert_eq!(rows.len(), WORKLOADS.len(), "{}", stderr(&o));
    for row in &rows {
        assert_eq!(row["passed"], true, "{row}");
        // Coverage agrees pixel for pixel (the bound allows 0.1%): the same triangles, the
        // same rules, at every scale from sub-pixel to 4K.
        assert_eq!(row["coverage_mismatches"], 0, "{row}");
    }
    assert!(o.status.success(), "{}", stderr(&o));
}
