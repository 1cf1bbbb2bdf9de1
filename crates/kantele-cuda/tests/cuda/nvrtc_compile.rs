//! Every kernel source compiles with NVRTC, with no error and no warning, for the oldest and the
//! newest GPU generation CUDA 13 supports; the record layouts agree with Rust (the sources
//! `static_assert` them against the generated defines), and a wrong layout is caught.
//!
//! NVRTC needs no GPU. Without the library the tests skip with a message, unless
//! `KANTELE_REQUIRE` names `nvrtc` (CI), when they fail.

use kantele_cuda::defines::define_options;
use kantele_cuda::kernels::{compile_options, COMMON_HEADER, SOURCES};
use kantele_cuda::nvrtc::Nvrtc;

fn required() -> bool {
    std::env::var("KANTELE_REQUIRE")
        .map(|v| v.split([',', ' ']).any(|s| s == "nvrtc"))
        .unwrap_or(false)
}

fn nvrtc() -> Option<Nvrtc> {
    match Nvrtc::load() {
        Ok(n) => Some(n),
        Err(e) if required() => panic!("KANTELE_REQUIRE=nvrtc but {e}"),
        Err(e) => {
            kantele_testkit::report_skip(e);
            None
        }
    }
}

/// The compute capabilities checked: Turing (the oldest CUDA 13 supports) and Hopper (H100/H200).
const ARCHES: [u32; 2] = [75, 90];

#[test]
fn every_kernel_compiles_without_warnings() {
    let Some(nvrtc) = nvrtc() else { return };
    let (major, minor) = nvrtc.version().expect("version");
    eprintln!("NVRTC {major}.{minor} from {}", nvrtc.path());
    for arch in ARCHES {
        let options = compile_options(arch);
        for source in SOURCES {
            let compiled = nvrtc
                .compile(source.name, source.source, &[COMMON_HEADER], &options)
                .unwrap_or_else(|e| panic!("compute_{arch}: {e}"));
            assert!(
                compiled.log.is_empty(),
                "{} (compute_{arch}) compiled with messages:\n{}",
                source.name,
                compiled.log
            );
            for entry in source.entry_points {
                assert!(
                    compiled.ptx.contains(&format!(".entry {entry}(")),
                    "{}: no entry point {entry} in the PTX",
                    source.name
                );
            }
            // No fused multiply-add in the geometry stages: every product rounds on its own, as
            // on the CPU. (The fragment stages call `log2f` / `powf` for texture LOD and sRGB,
            // whose library code uses FMA internally; those values are not bit-exact rules.)
            let geometry = ["vertex.cu", "primitive.cu", "binning.cu"].contains(&source.name);
            assert!(
                !geometry || !compiled.ptx.contains("fma.rn.f32"),
                "{} contains a fused f32 multiply-add",
                source.name
            );
        }
    }
}

#[test]
fn a_layout_that_disagrees_with_rust_is_rejected() {
    let Some(nvrtc) = nvrtc() else { return };
    let mut options = compile_options(90);
    for o in options.iter_mut() {
        if o.starts_with("-DKANTELE_TRIANGLE_SETUP_SIZE=") {
            *o = "-DKANTELE_TRIANGLE_SETUP_SIZE=224".to_string();
        }
    }
    let err = nvrtc
        .compile(
            SOURCES[0].name,
            SOURCES[0].source,
            &[COMMON_HEADER],
            &options,
        )
        .expect_err("a wrong size must not compile");
    assert!(err.to_string().contains("TriangleSetup size"), "{err}");
}

#[test]
fn kernels_refuse_to_compile_without_the_rules() {
    let Some(nvrtc) = nvrtc() else { return };
    let options: Vec<String> = compile_options(90)
        .into_iter()
        .filter(|o| !define_options().contains(o))
        .collect();
    let err = nvrtc
        .compile(
            SOURCES[1].name,
            SOURCES[1].source,
            &[COMMON_HEADER],
            &options,
        )
        .expect_err("no defines, no kernel");
    assert!(err.to_string().contains("-D defines"), "{err}");
}
