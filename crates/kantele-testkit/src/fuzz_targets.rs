//! Bodies of the `gltf`, `obj`, `ply`, `stl` and `draco` fuzz targets (`fuzz/` at the repository root),
//! as plain functions so that a stable test can replay the corpus without a nightly toolchain.
//!
//! Each loads the fuzzer's bytes as a scene file in a private, otherwise empty folder (the read
//! policy confines the scene to it) under a 64 MiB budget, and renders what loads at 32 × 32
//! on the CPU backend (`gltf` inputs with animations also with their first animation, posed
//! again after loading). A load error is a valid outcome; a panic in Kantele's own code (also one
//! the loader's panic net caught), an abort, a scene the loader accepts but the backend refuses,
//! or a failed render is a defect.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use kantele::backend::{Backend, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};

use kantele_scene::{AnimationChoice, LoadError, LoadOptions, LoadedScene};

/// Memory budget of a fuzzed load: small enough that no input can exhaust the fuzzer's memory
/// within the budget's rules.
pub const FUZZ_MAX_MEMORY: u64 = 64 << 20;

/// The line that separates the OBJ text from the MTL text in an `obj` input.
pub const MTL_SEPARATOR: &[u8] = b"\n#--mtl--\n";

/// The `gltf` target: the bytes as a `.glb` (when they start with the GLB magic) or `.gltf`
/// file.
pub fn gltf(data: &[u8]) {
    let name = if data.starts_with(b"glTF") {
        "scene.glb"
    } else {
        "scene.gltf"
    };
    let folder = fresh_folder();
    let scene = folder.join(name);
    std::fs::write(&scene, data).expect("write the fuzz input");
    let result = load(&scene);
    check_and_render(result);
    if data.windows(10).any(|w| w == b"animations") {
        check_and_render(load_animated(&scene, data));
    }
}

/// Loads the scene with its first animation at a time taken from the input (0 to 10 s, and
/// past the keys), then poses it again at another time: posing the scene it was loaded with at
/// a finite time never fails.
fn load_animated(scene: &Path, data: &[u8]) -> Result<LoadedScene, LoadError> {
    let hash = data
        .iter()
        .fold(0u32, |h, &b| h.wrapping_mul(31).wrapping_add(u32::from(b)));
    let time = (hash % 1000) as f32 / 100.0;
    let options = LoadOptions {
        max_memory: FUZZ_MAX_MEMORY,
        animation: Some(AnimationChoice::Index(0)),
        time,
        ..LoadOptions::default()
    };
    let mut loaded = kantele_scene::load_scene_with(scene, &options)?;
    if let Some(player) = loaded.animation.take() {
        player
            .pose(&mut loaded.scene, 10.0 - time)
            .unwrap_or_else(|e| panic!("posing the scene it was loaded with failed: {e}"));
    }
    Ok(loaded)
}

/// The `obj` target: the bytes up to [`MTL_SEPARATOR`] as `scene.obj`, the rest as
/// `scene.mtl` (which the OBJ text may name with `mtllib scene.mtl`).
pub fn obj(data: &[u8]) {
    let (obj, mtl) = match data
        .windows(MTL_SEPARATOR.len())
        .position(|w| w == MTL_SEPARATOR)
    {
        Some(at) => (&data[..at], &data[at + MTL_SEPARATOR.len()..]),
        None => (data, &[][..]),
    };
    let folder = fresh_folder();
    let scene = folder.join("scene.obj");
    std::fs::write(&scene, obj).expect("write the fuzz input");
    std::fs::write(folder.join("scene.mtl"), mtl).expect("write the fuzz input");
    let result = load(&scene);
    check_and_render(result);
}

/// The `ply` target: the bytes as `scene.ply`.
pub fn ply(data: &[u8]) {
    load_and_render_as(data, "scene.ply");
}

/// The `stl` target: the bytes as `scene.stl`.
pub fn stl(data: &[u8]) {
    load_and_render_as(data, "scene.stl");
}

/// The `draco` target: the bytes as a `KHR_draco_mesh_compression` stream, the one primitive
/// of a `.glb` whose accessors declare the counts of the stream's header
/// (`kantele_scene::draco_stream_glb`).
pub fn draco(data: &[u8]) {
    load_and_render_as(&kantele_scene::draco_stream_glb(data), "scene.glb");
}

/// Writes the bytes as the file `name` in a fresh folder, loads it and renders what loads.
fn load_and_render_as(data: &[u8], name: &str) {
    let folder = fresh_folder();
    let scene = folder.join(name);
    std::fs::write(&scene, data).expect("write the fuzz input");
    let result = load(&scene);
    check_and_render(result);
}

/// A folder of this process and thread, emptied.
fn fresh_folder() -> PathBuf {
    let thread = format!("{:?}", std::thread::current().id());
    let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
    let folder = std::env::temp_dir().join(format!("kantele-fuzz-{}-{thread}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).expect("create the fuzz folder");
    folder
}

fn load(scene: &Path) -> Result<LoadedScene, LoadError> {
    let options = LoadOptions {
        max_memory: FUZZ_MAX_MEMORY,
        ..LoadOptions::default()
    };
    kantele_scene::load_scene_with(scene, &options)
}

/// Fails on a caught panic from Kantele's own code; renders a loaded scene.
fn check_and_render(result: Result<LoadedScene, LoadError>) {
    let loaded = match result {
        Ok(loaded) => loaded,
        Err(error) => {
            let message = error.to_string();
            if message.contains("the parser failed") {
                // Dependencies' known panics are caught by design; ours are defects.
                let file = kantele_scene::last_caught_panic_file().unwrap_or_default();
                assert!(
                    !is_kantele_source(&file),
                    "Kantele's own code panicked in {file}: {message}"
                );
            }
            return;
        }
    };
    let scene = Arc::new(loaded.scene);
    CPU.with(|cell| {
        let mut slot = cell.borrow_mut();
        let cpu = slot.get_or_insert_with(|| {
            CpuBackend::new(CpuOptions {
                threads: Some(1),
                ..CpuOptions::default()
            })
            .expect("a CPU backend")
        });
        cpu.load(scene.clone())
            .unwrap_or_else(|e| panic!("the loader accepted a scene the backend refuses: {e}"));
        for pass in [Pass::Color, Pass::Normals, Pass::Ids] {
            let view = FrameView {
                pass,
                ..FrameView::with_camera(&scene, &scene.camera, 32, 32)
            };
            cpu.render(&view)
                .unwrap_or_else(|e| panic!("rendering a loaded scene failed: {e}"));
            let frame = cpu.read_frame().expect("read the frame back");
            assert_eq!(frame.color.len(), 32 * 32);
        }
    });
}

thread_local! {
    /// One CPU backend per thread, reused across inputs: a backend per input would start (and
    /// leave exiting) a worker thread each time, which is slow and which LeakSanitizer reports
    /// as a leak of the exiting thread's thread-local destructors.
    static CPU: RefCell<Option<CpuBackend>> = const { RefCell::new(None) };
}

/// Whether a panic location lies in Kantele's crates rather than in a dependency.
fn is_kantele_source(file: &str) -> bool {
    let file = file.replace('\\', "/");
    !file.contains("/.cargo/") && !file.contains("/rustc/") && file.contains("kantele")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panic_locations_are_told_apart() {
        assert!(is_kantele_source("crates/kantele-scene/src/accessor.rs"));
        assert!(is_kantele_source(
            "/src/kantele/crates/kantele-rules/src/setup.rs"
        ));
        assert!(!is_kantele_source(
            "/root/.cargo/registry/src/index.crates.io-1/gltf-json-1.4.1/src/path.rs"
        ));
        assert!(!is_kantele_source(
            "/rustc/abc/library/core/src/slice/index.rs"
        ));
    }
}
