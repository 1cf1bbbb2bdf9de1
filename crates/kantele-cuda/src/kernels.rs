//! The kernel sources (`kernels/*.cu`, embedded at build time), how they are compiled with NVRTC,
//! and the on-disk cache of the resulting PTX, keyed by a hash of everything that affects it.

use std::path::{Path, PathBuf};

use crate::defines::define_options;
use crate::nvrtc::{Header, Nvrtc, NvrtcError};

/// The shared header every stage includes.
pub const COMMON_HEADER: Header<'static> = Header {
    name: "common.cuh",
    source: include_str!("../kernels/common.cuh"),
};

/// One compiled unit: a stage of the pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelSource {
    /// File name under `kernels/`.
    pub name: &'static str,
    /// Its text.
    pub source: &'static str,
    /// The `extern "C"` entry points it defines.
    pub entry_points: &'static [&'static str],
}

/// Every stage, in pipeline order.
pub const SOURCES: [KernelSource; 7] = [
    KernelSource {
        name: "vertex.cu",
        source: include_str!("../kernels/vertex.cu"),
        entry_points: &["kantele_draw_matrices", "kantele_vertex"],
    },
    KernelSource {
        name: "primitive.cu",
        source: include_str!("../kernels/primitive.cu"),
        entry_points: &["kantele_primitive"],
    },
    KernelSource {
        name: "binning.cu",
        source: include_str!("../kernels/binning.cu"),
        entry_points: &[
            "kantele_bin_count",
            "kantele_bin_fill",
            "kantele_bin_ranges",
            "kantele_scan_blocks",
            "kantele_scan_add",
        ],
    },
    KernelSource {
        name: "raster.cu",
        source: include_str!("../kernels/raster.cu"),
        entry_points: &["kantele_raster"],
    },
    KernelSource {
        name: "resolve.cu",
        source: include_str!("../kernels/resolve.cu"),
        entry_points: &["kantele_resolve_rgba8"],
    },
    KernelSource {
        name: "baselines.cu",
        source: include_str!("../kernels/baselines.cu"),
        entry_points: &[
            "kantele_clear",
            "kantele_ocot_triangle",
            "kantele_ocmt_batch",
        ],
    },
    KernelSource {
        name: "layout.cu",
        source: include_str!("../kernels/layout.cu"),
        entry_points: &["kantele_layout_probe"],
    },
];

/// NVRTC options for a GPU of compute capability `arch` (e.g. 90 for sm_90).
///
/// `--fmad=false`: no multiply-add is contracted, so every product and sum rounds on its own as
/// on the CPU (the stage rules need it for bit-exact coverage and depth). Division and square
/// root stay IEEE-rounded (NVRTC's defaults `--prec-div=true`, `--prec-sqrt=true`), and
/// denormals are kept (`--ftz=false`).
pub fn compile_options(arch: u32) -> Vec<String> {
    let mut options = vec![
        format!("--gpu-architecture=compute_{arch}"),
        "--fmad=false".to_string(),
        "--ftz=false".to_string(),
        "--prec-div=true".to_string(),
        "--prec-sqrt=true".to_string(),
        "--std=c++17".to_string(),
    ];
    options.extend(define_options());
    options
}

/// 64-bit FNV-1a: a stable hash for cache keys (not for security).
pub fn fnv1a(data: &[u8], mut hash: u64) -> u64 {
    for &b in data {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// The cache key of one source: its text, the shared header, the options and NVRTC's version.
pub fn cache_key(source: &KernelSource, options: &[String], nvrtc_version: (i32, i32)) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325;
    for part in [source.name, source.source, COMMON_HEADER.source] {
        h = fnv1a(part.as_bytes(), h);
        h = fnv1a(&[0xff], h);
    }
    for o in options {
        h = fnv1a(o.as_bytes(), h);
        h = fnv1a(&[0xfe], h);
    }
    fnv1a(
        format!("nvrtc {}.{}", nvrtc_version.0, nvrtc_version.1).as_bytes(),
        h,
    )
}

/// The cache folder: `$KANTELE_CUDA_CACHE`, else `$XDG_CACHE_HOME/kantele/cuda`, else
/// `$HOME/.cache/kantele/cuda`; `None` when none is known.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(dir) = var("KANTELE_CUDA_CACHE") {
        return Some(PathBuf::from(dir));
    }
    if let Some(xdg) = var("XDG_CACHE_HOME") {
        return Some(PathBuf::from(xdg).join("kantele").join("cuda"));
    }
    var("HOME").map(|home| {
        PathBuf::from(home)
            .join(".cache")
            .join("kantele")
            .join("cuda")
    })
}

/// Compiled PTX of every source, from the cache in `dir` when present, else compiled (and
/// stored, best effort: a cache that cannot be written only costs start-up time).
pub fn compile_all(
    nvrtc: &Nvrtc,
    arch: u32,
    dir: Option<&Path>,
) -> Result<Vec<(KernelSource, String)>, NvrtcError> {
    let options = compile_options(arch);
    let version = nvrtc.version()?;
    let mut out = Vec::with_capacity(SOURCES.len());
    for source in SOURCES {
        let key = cache_key(&source, &options, version);
        let file = dir.map(|d| d.join(format!("{}-{key:016x}.ptx", source.name)));
        if let Some(ptx) = file.as_ref().and_then(|f| std::fs::read_to_string(f).ok()) {
            if ptx.contains(".entry") {
                out.push((source, ptx));
                continue;
            }
        }
        let compiled = nvrtc.compile(source.name, source.source, &[COMMON_HEADER], &options)?;
        if let (Some(dir), Some(file)) = (dir, file) {
            let _ = std::fs::create_dir_all(dir);
            let tmp = file.with_extension(format!("tmp{}", std::process::id()));
            if std::fs::write(&tmp, &compiled.ptx).is_ok() {
                let _ = std::fs::rename(&tmp, &file);
            }
        }
        out.push((source, compiled.ptx));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_point_is_defined_in_its_source() {
        for s in SOURCES {
            assert!(s.source.contains("#include \"common.cuh\""), "{}", s.name);
            for e in s.entry_points {
                assert!(
                    s.source.contains(&format!("__global__ void {e}("))
                        || s.source.contains(&format!("\n    {e}(")),
                    "{} does not define {e}",
                    s.name
                );
            }
        }
    }

    #[test]
    fn no_kernel_retypes_a_stage_constant() {
        // The rules come in as defines; a literal 256, 64 or 16384 in a .cu file would be a copy.
        for text in SOURCES
            .iter()
            .map(|s| s.source)
            .chain([COMMON_HEADER.source])
        {
            for banned in ["16384", "0.000001", "1e-6", "<< 8", "1 << 24"] {
                assert!(!text.contains(banned), "kernel source contains {banned}");
            }
        }
    }

    #[test]
    fn cache_keys_change_with_source_options_and_compiler() {
        let options = compile_options(90);
        assert!(options.iter().any(|o| o == "--fmad=false"));
        assert!(options
            .iter()
            .any(|o| o.starts_with("-DKANTELE_SUBPIXEL_BITS=")));
        let a = cache_key(&SOURCES[0], &options, (13, 0));
        assert_eq!(a, cache_key(&SOURCES[0], &options, (13, 0)));
        assert_ne!(a, cache_key(&SOURCES[1], &options, (13, 0)));
        assert_ne!(a, cache_key(&SOURCES[0], &compile_options(75), (13, 0)));
        assert_ne!(a, cache_key(&SOURCES[0], &options, (13, 1)));
    }
}
