//! The CPU backend's 8-bit sRGB target gives every built-in and reference scene's colour frame
//! byte for byte as the `f32` target's 8-bit picture, with the same depth; its normals and ids
//! passes stay `f32`.

use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::rop::TargetFormat;
use kantele::scene::Scene;
use kantele::simd::Isa;

fn render(scene: &Arc<Scene>, pass: Pass, target: TargetFormat, isa: Isa) -> FrameImage {
    let mut cpu = CpuBackend::new(CpuOptions {
        threads: Some(3),
        isa: Some(isa),
        target,
        ..CpuOptions::default()
    })
    .expect("cpu backend");
    assert_eq!(cpu.target(), target.name());
    cpu.load(scene.clone()).expect("load");
    let view = FrameView {
        pass,
        ..FrameView::of_scene(scene)
    };
    cpu.render(&view).expect("render");
    cpu.read_frame().expect("read")
}

/// Colour frames: the same sRGB bytes and depth bits; other passes: the same values.
fn check(name: &str, scene: Scene, isas: &[Isa], passes: &[Pass]) {
    let scene = Arc::new(scene);
    for &pass in passes {
        let reference = render(&scene, pass, TargetFormat::LinearF32, Isa::selected());
        let depth = |f: &FrameImage| f.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
        for &isa in isas {
            let image = render(&scene, pass, TargetFormat::Srgb8, isa);
            assert!(
                depth(&image) == depth(&reference),
                "{name} {pass:?} {isa}: depth"
            );
            match pass {
                Pass::Color => assert!(
                    image.to_rgba8(true) == reference.to_rgba8(true),
                    "{name} {isa}: the 8-bit target's picture differs"
                ),
                Pass::Normals | Pass::Ids => assert!(
                    image.color == reference.color,
                    "{name} {pass:?} {isa}: not drawn at f32"
                ),
            }
        }
    }
}

#[test]
fn srgb8_target_matches_the_f32_target_on_built_in_scenes() {
    let isas: Vec<Isa> = [Isa::Scalar, Isa::selected()].into_iter().collect();
    for &(name, _) in kantele_scene::builtin_scenes() {
        let loaded = kantele_scene::builtin_scene(name).expect("built-in scene");
        check(
            name,
            loaded.scene,
            &isas,
            &[Pass::Color, Pass::Normals, Pass::Ids],
        );
    }
}

#[test]
fn srgb8_target_matches_the_f32_target_on_reference_scenes() {
    let Some(files) = crate::common::reference_scene_files() else {
        return;
    };
    for path in files {
        let loaded = kantele_scene::load_scene(&path).expect("load");
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        check(&name, loaded.scene, &[Isa::selected()], &[Pass::Color]);
    }
}
