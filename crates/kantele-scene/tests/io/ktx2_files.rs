//! KTX2 textures in glTF files: `KHR_texture_basisu` before its fallback, KTX2 in a core
//! `source` slot, and broken KTX2 files (`$KANTELE_SHARED/realworld/ktx2/uastc-256.ktx2`, a
//! 256 × 256 UASTC picture; skipped with a printed reason when absent).

use std::path::{Path, PathBuf};

use kantele_scene::{load_scene_with, LoadOptions, LoadedScene};
use serde_json::json;

use crate::common::{temp_dir, textured_quad, Gltf};

/// `uastc-256.ktx2`'s bytes, or `None` when the real-world files are absent.
fn uastc_256() -> Option<Vec<u8>> {
    let dir = kantele_testkit::shared_dir("realworld")?;
    Some(std::fs::read(dir.join("ktx2/uastc-256.ktx2")).expect("read uastc-256.ktx2"))
}

/// The textured quad with its texture showing `ktx2_file` (next to the scene) through
/// `KHR_texture_basisu`, the quad's PNG kept in `source` as the fallback when `fallback`.
fn basisu_quad(ktx2_file: &str, fallback: bool) -> Gltf {
    let mut g = textured_quad();
    let images = g.json["images"].as_array_mut().expect("images");
    images.push(json!({"uri": ktx2_file, "mimeType": "image/ktx2"}));
    let ktx2_image = images.len() - 1;
    let texture = &mut g.json["textures"][0];
    texture["extensions"] = json!({"KHR_texture_basisu": {"source": ktx2_image}});
    if !fallback {
        texture.as_object_mut().expect("texture").remove("source");
        g.json["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    }
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_basisu"]);
    g
}

fn load(path: &Path, strict: bool) -> Result<LoadedScene, kantele_scene::LoadError> {
    let options = LoadOptions {
        strict,
        ..LoadOptions::default()
    };
    load_scene_with(path, &options)
}

/// The RGBA bytes of texture `t`'s level-0 texel at (`x`, `y`).
fn texel(loaded: &LoadedScene, t: usize, x: u32, y: u32) -> [u8; 4] {
    let level = loaded.scene.textures[t].level(0).expect("level 0");
    level.packed(x, y).to_le_bytes()
}

/// A folder with `uastc-256.ktx2` (as `name`, with `bytes`) and the scene path in it.
fn folder_with(test: &str, name: &str, bytes: &[u8]) -> (PathBuf, PathBuf) {
    let dir = temp_dir(test);
    std::fs::write(dir.join(name), bytes).expect("write the KTX2 file");
    let scene = dir.join("scene.gltf");
    (dir, scene)
}

#[test]
fn basisu_texture_is_used_before_its_fallback() {
    let Some(ktx2) = uastc_256() else { return };
    let (_dir, scene) = folder_with("basisu-fallback", "picture.ktx2", &ktx2);
    basisu_quad("picture.ktx2", true).write_gltf_external(&scene);
    let loaded = load(&scene, true).expect("the scene loads");
    // Only the KTX2 image was loaded: the PNG fallback (2 × 2) was not.
    assert_eq!(loaded.info.texture_sizes, vec![(256, 256)]);
    let binding = loaded.scene.materials[0]
        .base_color_texture
        .expect("the base colour texture is bound");
    assert_eq!(binding.texture, 0);
    // Texels of the picture as the reference transcoder decodes them (the ochre band, the
    // orange stripe).
    assert_eq!(texel(&loaded, 0, 128, 70), [144, 122, 72, 255]);
    assert_eq!(texel(&loaded, 0, 20, 205), [112, 79, 25, 255]);
    assert!(!loaded
        .info
        .ignored
        .iter()
        .any(|e| e == "KHR_texture_basisu"));
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );
}

#[test]
fn required_basisu_without_fallback_loads_and_reports_colour_space() {
    let Some(ktx2) = uastc_256() else { return };
    let (_dir, scene) = folder_with("basisu-required", "picture.ktx2", &ktx2);
    let mut g = basisu_quad("picture.ktx2", false);
    // The same texture as occlusion too: linear data from a file that declares sRGB.
    g.json["materials"][0]["occlusionTexture"] = json!({"index": 0});
    g.write_gltf_external(&scene);
    let loaded = load(&scene, true).expect("the scene loads");
    let material = &loaded.scene.materials[0];
    assert!(material.base_color_texture.is_some());
    assert!(material.occlusion_texture.is_some());
    // One texture per colour space.
    assert_eq!(loaded.info.texture_sizes, vec![(256, 256), (256, 256)]);
    let notes: Vec<&String> = loaded
        .info
        .warnings
        .iter()
        .filter(|w| w.contains("declares sRGB"))
        .collect();
    assert_eq!(notes.len(), 1, "{:?}", loaded.info.warnings);
    assert!(notes[0].contains("picture.ktx2"), "{}", notes[0]);
}

#[test]
fn ktx2_in_the_core_source_slot_is_decoded() {
    let Some(ktx2) = uastc_256() else { return };
    // In the binary chunk of a `.glb`, declared `image/png` by the writer: the data decides.
    let dir = temp_dir("ktx2-core-glb");
    let mut g = textured_quad();
    g.images[0] = ktx2.clone();
    let glb = dir.join("scene.glb");
    g.write_glb(&glb);
    let loaded = load(&glb, true).expect("the .glb loads");
    assert_eq!(loaded.info.texture_sizes, vec![(256, 256)]);
    assert_eq!(texel(&loaded, 0, 128, 100), [71, 49, 30, 255]);
    // An external file named in `uri`, with no MIME type.
    let (_dir, scene) = folder_with("ktx2-core-uri", "picture.ktx2", &ktx2);
    let mut g = textured_quad();
    g.json["images"][0]["uri"] = json!("picture.ktx2");
    g.write_gltf_external(&scene);
    let loaded = load(&scene, true).expect("the .gltf loads");
    assert_eq!(loaded.info.texture_sizes, vec![(256, 256)]);
    // Describing the scene reads the size from the KTX2 header alone.
    let options = LoadOptions {
        decode_textures: false,
        ..LoadOptions::default()
    };
    let described = load_scene_with(&scene, &options).expect("described");
    assert_eq!(described.info.texture_sizes, vec![(256, 256)]);
}

#[test]
fn broken_ktx2_files_give_one_line_and_no_crash() {
    let Some(ktx2) = uastc_256() else { return };
    // Truncated in the level data, and with the level's blocks overwritten.
    let truncated = ktx2[..ktx2.len() / 2].to_vec();
    let mut scrambled = ktx2.clone();
    let body = scrambled.len() - 65536;
    for (i, b) in scrambled[body..].iter_mut().enumerate() {
        *b = (i as u8).wrapping_mul(151) ^ 0x5a;
    }
    for (name, bytes) in [("truncated", truncated), ("scrambled", scrambled)] {
        let (_dir, scene) = folder_with(name, "picture.ktx2", &bytes);
        basisu_quad("picture.ktx2", false).write_gltf_external(&scene);
        match load(&scene, false) {
            Ok(loaded) => {
                // Tolerant: a warning, the texture left out (or, for data the transcoder can
                // read, a texture of the declared size).
                if loaded.scene.materials[0].base_color_texture.is_none() {
                    let warning = loaded
                        .info
                        .warnings
                        .iter()
                        .find(|w| w.contains("picture.ktx2"))
                        .unwrap_or_else(|| panic!("{name}: no warning {:?}", loaded.info.warnings));
                    assert!(warning.contains("drawn untextured"), "{warning}");
                    assert!(!warning.contains('\n'), "{warning}");
                } else {
                    assert_eq!(loaded.info.texture_sizes, vec![(256, 256)], "{name}");
                }
            }
            Err(e) => panic!("{name}: a tolerant load failed: {e}"),
        }
        if name == "truncated" {
            let e = load(&scene, true).expect_err("strict refuses a truncated KTX2");
            let message = e.to_string();
            assert!(message.contains("picture.ktx2"), "{message}");
            assert!(!message.contains('\n'), "{message}");
        }
    }
}
