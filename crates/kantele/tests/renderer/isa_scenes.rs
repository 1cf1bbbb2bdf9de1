//! Whole scenes drawn by the library's kernels at every instruction set this CPU has: Lambert and
//! PBR materials, textures, normal maps, vertex colours, blending, image-based and punctual
//! light, one and four samples per pixel, and the normals and ids passes. Every picture is
//! bit-identical to the scalar reference's.
//!
//! The library's own unit tests compile its shading kernels for the scalar reference and one
//! vector level only (`kantele_cpu::pipeline`'s `shading_isas`): this is where every level of
//! the real shaders is compared.

use std::path::Path;
use std::sync::Arc;

use kantele::backend::{Backend, FrameView, Pass};
use kantele::cpu::CpuBackend;
use kantele::multisample::SampleCount;
use kantele::pipeline::RendererOptions;
use kantele::scene::Scene;
use kantele::simd::Isa;
use kantele_scene::{builtin_scene, load_scene};

/// The colour and depth of one frame of `scene` at `isa`, as bits.
fn frame_bits(scene: &Arc<Scene>, isa: Isa, samples: SampleCount, pass: Pass) -> Vec<u32> {
    let mut backend = CpuBackend::new(RendererOptions {
        isa: Some(isa),
        samples,
        ..RendererOptions::default()
    })
    .expect("backend");
    assert_eq!(backend.isa(), isa.name(), "the backend draws with {isa}");
    backend.load(Arc::clone(scene)).expect("load");
    // Small frames of the scene's own aspect: the point is every kernel, not many pixels.
    let (width, height) = scene.resolution;
    let width = (120 * width / height.max(1)).max(1);
    let view = FrameView {
        pass,
        ..FrameView::with_camera(scene, &scene.camera, width, 120)
    };
    backend.render(&view).expect("render");
    let image = backend.read_frame().expect("frame");
    let drawn = image.depth.iter().filter(|&&d| d < 1.0).count();
    assert!(drawn > 500, "{isa}: only {drawn} pixels drawn");
    image
        .color
        .iter()
        .flat_map(|c| c.map(f32::to_bits))
        .chain(image.depth.iter().map(|d| d.to_bits()))
        .collect()
}

/// Asserts that every supported level draws `scene` as the scalar reference does.
fn assert_levels_agree(name: &str, scene: Scene, samples: SampleCount, pass: Pass) {
    let scene = Arc::new(scene);
    let reference = frame_bits(&scene, Isa::Scalar, samples, pass);
    for isa in Isa::supported().filter(|&isa| isa != Isa::Scalar) {
        let got = frame_bits(&scene, isa, samples, pass);
        let differing = got.iter().zip(&reference).filter(|(a, b)| a != b).count();
        assert!(
            differing == 0,
            "{name} ({samples:?}, {pass:?}): {isa} differs from scalar in {differing} values"
        );
    }
}

#[test]
fn built_in_scenes_are_identical_at_every_level() {
    for name in [
        "cube",
        "teapot",
        "ground",
        "pbr-spheres",
        "pbr-lights",
        "pbr-glass",
        "pbr-sheen",
    ] {
        let scene = builtin_scene(name).expect("built-in scene").scene;
        assert_levels_agree(name, scene, SampleCount::X1, Pass::Color);
    }
}

#[test]
fn multisampled_and_other_passes_are_identical_at_every_level() {
    for name in ["teapot", "pbr-lights"] {
        let scene = || builtin_scene(name).expect("built-in scene").scene;
        assert_levels_agree(name, scene(), SampleCount::X4, Pass::Color);
        assert_levels_agree(name, scene(), SampleCount::X1, Pass::Normals);
        assert_levels_agree(name, scene(), SampleCount::X1, Pass::Ids);
    }
}

#[test]
fn real_files_are_identical_at_every_level() {
    let Some(root) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    for file in [
        "pbr/NormalTangentTest.glb",
        "CesiumMilkTruck/glTF-Binary/CesiumMilkTruck.glb",
        "VertexColorTest/glTF-Binary/VertexColorTest.glb",
        "ClearCoatTest/glTF-Binary/ClearCoatTest.glb",
        "AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb",
    ] {
        let path = root.join(file);
        let scene = load_scene(Path::new(&path))
            .unwrap_or_else(|e| panic!("{file}: {e}"))
            .scene;
        assert_levels_agree(file, scene, SampleCount::X1, Pass::Color);
    }
}
