//! The per-pixel path gives the same picture, bit for bit, for every instruction set, traversal
//! strategy and thread count: every reference scene and every built-in scene, rendered with the
//! scalar build (the readable reference) and with each SIMD build the machine has.

use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::raster::Strategy;
use kantele::scene::Scene;
use kantele::simd::Isa;

fn render(
    scene: &Arc<Scene>,
    pass: Pass,
    isa: Isa,
    threads: usize,
    strategy: Strategy,
) -> FrameImage {
    let mut cpu = CpuBackend::new(CpuOptions {
        threads: Some(threads),
        strategy,
        isa: Some(isa),
        ..CpuOptions::default()
    })
    .expect("cpu backend");
    cpu.load(scene.clone()).expect("load");
    let view = FrameView {
        pass,
        ..FrameView::of_scene(scene)
    };
    cpu.render(&view).expect("render");
    cpu.read_frame().expect("read")
}

/// Renders `scene` with the scalar reference and with every supported SIMD level (each with
/// another strategy and thread count) and asserts identical colour and depth bits.
fn check(name: &str, scene: Scene, passes: &[Pass]) {
    let scene = Arc::new(scene);
    let simd: Vec<Isa> = Isa::ALL
        .into_iter()
        .filter(|i| *i != Isa::Scalar && i.is_supported())
        .collect();
    let configs = [
        (3, Strategy::Bisector),
        (2, Strategy::Block),
        (8, Strategy::Adaptive),
        (1, Strategy::BoundingBox),
    ];
    for &pass in passes {
        let reference = render(&scene, pass, Isa::Scalar, 1, Strategy::Incremental);
        let bits = |f: &FrameImage| {
            (
                f.color
                    .iter()
                    .flatten()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>(),
                f.depth.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            )
        };
        let expected = bits(&reference);
        for (i, isa) in simd.iter().enumerate() {
            let (threads, strategy) = configs[i % configs.len()];
            let image = render(&scene, pass, *isa, threads, strategy);
            assert!(
                bits(&image) == expected,
                "{name} ({pass:?}): {isa} with {strategy} on {threads} threads differs from scalar"
            );
        }
    }
}

#[test]
fn simd_builds_match_the_scalar_reference_on_built_in_scenes() {
    for &(name, _) in kantele_scene::builtin_scenes() {
        let loaded = kantele_scene::builtin_scene(name).expect("built-in scene");
        check(name, loaded.scene, &[Pass::Color, Pass::Normals, Pass::Ids]);
    }
}

#[test]
fn simd_builds_match_the_scalar_reference_on_reference_scenes() {
    let Some(files) = crate::common::reference_scene_files() else {
        return;
    };
    for path in files {
        let loaded = kantele_scene::load_scene(&path).expect("load");
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        check(&name, loaded.scene, &[Pass::Color]);
    }
}
