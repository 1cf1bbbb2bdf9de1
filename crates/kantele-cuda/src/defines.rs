//! The `-D` defines every kernel is compiled with: the stage rules and record layouts, taken
//! from the Rust core and this crate so that no number is retyped in a `.cu` file.

use std::mem::size_of;

use kantele_rules::fixed;
use kantele_rules::geometry::clip::{MAX_CLIPPED_VERTICES, W_EPSILON, W_RELATIVE_EPSILON};
use kantele_rules::setup::TriangleSetup;
use kantele_rules::shade::texture::{Filter, MinFilter, Wrap};
use kantele_rules::vertex::StandardVertex;

use crate::records::{
    filter_code, min_filter_code, pass_code, wrap_code, DrawIssue, DrawRecord, FrameUniforms,
    LevelRecord, SlotInfo, TextureRecord, DRAW_ALPHA_BLEND, DRAW_ALPHA_MASK, DRAW_DOUBLE_SIDED,
    DRAW_EMISSIVE_TEXTURED, DRAW_FRONT_CW, DRAW_TEXTURED, DRAW_UNLIT, DRAW_VERTEX_COLORS,
};
use kantele_rules::backend::Pass;

/// Varyings of the built-in material shader: world normal (3), texcoord (2), colour (4).
/// `kantele_rules::material` keeps its count private; a test checks this against
/// `MaterialShader::varying_count`.
pub const MATERIAL_VARYINGS: usize = 9;

/// Triangle slots per binning chunk (one warp walks one chunk in order).
pub const BIN_CHUNK: u32 = 256;

/// Words (u64) of the frame status record (overflow counts and stage counters).
pub const STATUS_WORDS: usize = 12;

/// A C float literal that reads back as exactly `v`.
fn float_literal(v: f32) -> String {
    format!("{}f", floating_literal(format!("{v:?}")))
}

/// A C double literal that reads back as exactly `v`.
fn double_literal(v: f64) -> String {
    floating_literal(format!("{v:?}"))
}

/// Rust's shortest round-trip text of a number (`Debug`), made a C floating literal: `16384`
/// becomes `16384.0`, text with a point or an exponent stays as it is.
fn floating_literal(text: String) -> String {
    if text.contains(['.', 'e', 'E']) {
        text
    } else {
        format!("{text}.0")
    }
}

/// `(name, value)` pairs of every define.
pub fn defines() -> Vec<(String, String)> {
    let mut d: Vec<(String, String)> = Vec::new();
    let mut int = |name: &str, value: i64| d.push((name.to_string(), value.to_string()));
    int("KANTELE_SUBPIXEL_BITS", fixed::SUBPIXEL_BITS as i64);
    int("KANTELE_TILE_LOG2", fixed::TILE_LOG2 as i64);
    int("KANTELE_BLOCK_LOG2", fixed::BLOCK_LOG2 as i64);
    int("KANTELE_SUBPIXEL_LIMIT", fixed::SUBPIXEL_LIMIT);
    int(
        "KANTELE_SMALL_BOX_PIXELS",
        kantele_rules::setup::SMALL_BOX_PIXELS,
    );
    int("KANTELE_MAX_CLIPPED_VERTICES", MAX_CLIPPED_VERTICES as i64);
    int("KANTELE_VARYINGS", MATERIAL_VARYINGS as i64);
    int("KANTELE_BIN_CHUNK", BIN_CHUNK as i64);
    int("KANTELE_STATUS_WORDS", STATUS_WORDS as i64);

    type T = TriangleSetup;
    int("KANTELE_TRIANGLE_SETUP_SIZE", size_of::<T>() as i64);
    int("KANTELE_DRAW_RECORD_SIZE", size_of::<DrawRecord>() as i64);
    int(
        "KANTELE_STANDARD_VERTEX_SIZE",
        size_of::<StandardVertex>() as i64,
    );
    int(
        "KANTELE_TEXTURE_RECORD_SIZE",
        size_of::<TextureRecord>() as i64,
    );
    int("KANTELE_LEVEL_RECORD_SIZE", size_of::<LevelRecord>() as i64);
    int(
        "KANTELE_FRAME_UNIFORMS_SIZE",
        size_of::<FrameUniforms>() as i64,
    );
    int("KANTELE_SLOT_INFO_SIZE", size_of::<SlotInfo>() as i64);
    int("KANTELE_DRAW_ISSUE_SIZE", size_of::<DrawIssue>() as i64);

    for (name, flag) in [
        ("KANTELE_DRAW_UNLIT", DRAW_UNLIT),
        ("KANTELE_DRAW_DOUBLE_SIDED", DRAW_DOUBLE_SIDED),
        ("KANTELE_DRAW_ALPHA_MASK", DRAW_ALPHA_MASK),
        ("KANTELE_DRAW_ALPHA_BLEND", DRAW_ALPHA_BLEND),
        ("KANTELE_DRAW_TEXTURED", DRAW_TEXTURED),
        ("KANTELE_DRAW_FRONT_CW", DRAW_FRONT_CW),
        ("KANTELE_DRAW_EMISSIVE_TEXTURED", DRAW_EMISSIVE_TEXTURED),
        ("KANTELE_DRAW_VERTEX_COLORS", DRAW_VERTEX_COLORS),
        ("KANTELE_TRIANGLE_FRONT_FACING", TriangleSetup::FRONT_FACING),
        ("KANTELE_TRIANGLE_SWAPPED", TriangleSetup::SWAPPED),
    ] {
        int(name, flag as i64);
    }
    for (name, code) in [
        ("KANTELE_WRAP_REPEAT", wrap_code(Wrap::Repeat)),
        ("KANTELE_WRAP_CLAMP_TO_EDGE", wrap_code(Wrap::ClampToEdge)),
        (
            "KANTELE_WRAP_MIRRORED_REPEAT",
            wrap_code(Wrap::MirroredRepeat),
        ),
        ("KANTELE_FILTER_NEAREST", filter_code(Filter::Nearest)),
        ("KANTELE_FILTER_LINEAR", filter_code(Filter::Linear)),
        ("KANTELE_MIN_NEAREST", min_filter_code(MinFilter::Nearest)),
        ("KANTELE_MIN_LINEAR", min_filter_code(MinFilter::Linear)),
        (
            "KANTELE_MIN_NEAREST_MIPMAP_NEAREST",
            min_filter_code(MinFilter::NearestMipmapNearest),
        ),
        (
            "KANTELE_MIN_LINEAR_MIPMAP_NEAREST",
            min_filter_code(MinFilter::LinearMipmapNearest),
        ),
        (
            "KANTELE_MIN_NEAREST_MIPMAP_LINEAR",
            min_filter_code(MinFilter::NearestMipmapLinear),
        ),
        (
            "KANTELE_MIN_LINEAR_MIPMAP_LINEAR",
            min_filter_code(MinFilter::LinearMipmapLinear),
        ),
        ("KANTELE_PASS_COLOR", pass_code(Pass::Color)),
        ("KANTELE_PASS_NORMALS", pass_code(Pass::Normals)),
        ("KANTELE_PASS_IDS", pass_code(Pass::Ids)),
    ] {
        int(name, code as i64);
    }
    d.push((
        "KANTELE_GUARD_BAND_PIXELS".into(),
        float_literal(fixed::GUARD_BAND_PIXELS),
    ));
    d.push(("KANTELE_W_EPSILON".into(), float_literal(W_EPSILON)));
    d.push((
        "KANTELE_W_RELATIVE_EPSILON".into(),
        double_literal(W_RELATIVE_EPSILON),
    ));
    d
}

/// The defines as NVRTC options (`-DNAME=VALUE`).
pub fn define_options() -> Vec<String> {
    defines()
        .into_iter()
        .map(|(name, value)| format!("-D{name}={value}"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;
    use kantele::material::{Lighting, MaterialShader};
    use kantele::pipeline::Shader;
    use kantele_rules::scene::Material;

    #[test]
    fn material_varying_count_matches_the_core() {
        let material = Material::default();
        let lighting = Lighting {
            to_light: glam::Vec3::Z,
            light_color: glam::Vec3::ONE,
            ambient: 0.1,
        };
        let shader = MaterialShader::new(
            Mat4::IDENTITY,
            Mat4::IDENTITY,
            lighting,
            &material,
            None,
            Pass::Color,
            (1, 1),
        );
        assert_eq!(shader.varying_count(), MATERIAL_VARYINGS);
    }

    #[test]
    fn float_literals_read_back_exactly() {
        for v in [16384.0f32, 1e-6, 0.1, -3.5, 1.0] {
            let text = float_literal(v);
            assert!(text.ends_with('f'), "{text}");
            let parsed: f32 = text.trim_end_matches('f').parse().expect("number");
            assert_eq!(parsed.to_bits(), v.to_bits(), "{text}");
        }
        assert_eq!(float_literal(16384.0), "16384.0f");
        for v in [W_RELATIVE_EPSILON, 1.0, 0.1, -2.5e-300] {
            let text = double_literal(v);
            let parsed: f64 = text.parse().expect("number");
            assert_eq!(parsed.to_bits(), v.to_bits(), "{text}");
        }
    }

    #[test]
    fn every_define_is_unique_and_layouts_are_the_cores() {
        let d = defines();
        let mut names: Vec<&str> = d.iter().map(|(n, _)| n.as_str()).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(names.len(), before, "duplicate define");
        let get = |name: &str| {
            d.iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v.clone())
                .expect("define present")
        };
        assert_eq!(
            get("KANTELE_TRIANGLE_SETUP_SIZE"),
            size_of::<TriangleSetup>().to_string()
        );
        assert_eq!(
            get("KANTELE_SUBPIXEL_BITS"),
            fixed::SUBPIXEL_BITS.to_string()
        );
        assert_eq!(get("KANTELE_W_EPSILON"), float_literal(W_EPSILON));
        assert_eq!(
            get("KANTELE_W_RELATIVE_EPSILON"),
            double_literal(W_RELATIVE_EPSILON)
        );
        // Plain data of the sizes the kernels assume (8-byte alignment for the i64 fields).
        assert_eq!(size_of::<TriangleSetup>() % 8, 0);
    }
}
