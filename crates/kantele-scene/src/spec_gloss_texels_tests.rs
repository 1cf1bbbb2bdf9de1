//! Tests of the texel conversion: each texel follows the rules' conversion, sizes and
//! resampling, the factors, and the memory budget.

use glam::{Vec3, Vec4};
use kantele_rules::shade::spec_gloss::{to_metallic_roughness, SpecularGlossiness};
use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};

use super::*;

fn srgb(width: u32, height: u32, rgba: &[u8]) -> Texture {
    Texture::from_rgba8(width, height, rgba, ColorSpace::Srgb).expect("a valid texture")
}

fn nearest_clamp() -> Sampler {
    Sampler {
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
        mag_filter: Filter::Nearest,
        min_filter: MinFilter::Nearest,
    }
}

fn texel(t: &Texture, x: u32, y: u32) -> Vec4 {
    t.level(0).expect("level 0").texel(x, y)
}

#[test]
fn converted_size_is_the_larger_along_each_axis() {
    assert_eq!(converted_size(None, None), None);
    assert_eq!(converted_size(Some((4, 2)), None), Some((4, 2)));
    assert_eq!(converted_size(None, Some((1, 8))), Some((1, 8)));
    assert_eq!(converted_size(Some((4, 2)), Some((1, 8))), Some((4, 8)));
}

#[test]
fn every_texel_follows_the_rules_conversion() {
    // Two texels: a white dielectric and a gold metal.
    let diffuse = srgb(2, 1, &[255, 255, 255, 200, 0, 0, 0, 255]);
    let gold = [255, 228, 157];
    let specular_glossiness = srgb(2, 1, &[0, 0, 0, 255, gold[0], gold[1], gold[2], 128]);
    let factors = SpecGlossFactors::default();
    let mut budget = Budget::new(1 << 20);
    let converted = convert_textures(
        factors,
        Some(Source {
            texture: &diffuse,
            sampler: nearest_clamp(),
        }),
        Some(Source {
            texture: &specular_glossiness,
            sampler: nearest_clamp(),
        }),
        &mut budget,
    )
    .expect("converts");
    assert_eq!(converted.base_color.source_color_space(), ColorSpace::Srgb);
    assert_eq!(
        converted.metallic_roughness.source_color_space(),
        ColorSpace::Linear
    );
    for x in 0..2 {
        let d = texel(&diffuse, x, 0);
        let sg = texel(&specular_glossiness, x, 0);
        let expected = to_metallic_roughness(SpecularGlossiness {
            diffuse: d.truncate(),
            specular: sg.truncate(),
            glossiness: sg.w,
        });
        let base = texel(&converted.base_color, x, 0);
        let mr = texel(&converted.metallic_roughness, x, 0);
        assert!((base.truncate() - expected.base_color).abs().max_element() < 0.01);
        assert_eq!(base.w, d.w, "the diffuse alpha is kept");
        assert!((mr.y - expected.roughness).abs() < 0.003);
        assert!((mr.z - expected.metallic).abs() < 0.003);
    }
    assert!(texel(&converted.metallic_roughness, 0, 0).z < 0.01);
    assert!(texel(&converted.metallic_roughness, 1, 0).z > 0.99);
}

#[test]
fn factors_multiply_the_texels_and_a_missing_source_reads_white() {
    let diffuse = srgb(1, 1, &[255, 255, 255, 255]);
    let factors = SpecGlossFactors {
        diffuse: Vec4::new(0.5, 0.25, 1.0, 0.5),
        specular: Vec3::ZERO,
        glossiness: 0.25,
    };
    let mut budget = Budget::new(1 << 20);
    let converted = convert_textures(
        factors,
        Some(Source {
            texture: &diffuse,
            sampler: nearest_clamp(),
        }),
        None,
        &mut budget,
    )
    .expect("converts");
    let expected = to_metallic_roughness(SpecularGlossiness {
        diffuse: Vec3::new(0.5, 0.25, 1.0),
        specular: Vec3::ZERO,
        glossiness: 0.25,
    });
    let base = texel(&converted.base_color, 0, 0);
    assert!((base.truncate() - expected.base_color).abs().max_element() < 0.01);
    assert_eq!(base.w, 1.0, "the factor's alpha stays out of the texture");
    let mr = texel(&converted.metallic_roughness, 0, 0);
    assert!((mr.y - 0.75).abs() < 0.003);
    assert_eq!(mr.z, 0.0);
}

#[test]
fn a_smaller_source_is_resampled_to_the_larger() {
    // A 4 × 2 diffuse and a 1 × 1 specular-glossiness texture: 4 × 2 results, every texel
    // reading the one specular-glossiness texel.
    let diffuse = srgb(4, 2, &[128; 32]);
    let specular_glossiness = srgb(1, 1, &[10, 10, 10, 51]);
    let mut budget = Budget::new(1 << 20);
    let converted = convert_textures(
        SpecGlossFactors::default(),
        Some(Source {
            texture: &diffuse,
            sampler: nearest_clamp(),
        }),
        Some(Source {
            texture: &specular_glossiness,
            sampler: Sampler {
                mag_filter: Filter::Linear,
                ..nearest_clamp()
            },
        }),
        &mut budget,
    )
    .expect("converts");
    assert_eq!(
        (converted.base_color.width(), converted.base_color.height()),
        (4, 2)
    );
    let first = texel(&converted.metallic_roughness, 0, 0);
    for y in 0..2 {
        for x in 0..4 {
            assert_eq!(texel(&converted.metallic_roughness, x, y), first);
        }
    }
    assert!((first.y - 0.8).abs() < 0.003, "roughness {}", first.y);
}

#[test]
fn the_budget_is_charged_before_converting() {
    let diffuse = srgb(64, 64, &[255; 64 * 64 * 4]);
    let mut budget = Budget::new(64 * 64 * 10);
    let refused = convert_textures(
        SpecGlossFactors::default(),
        Some(Source {
            texture: &diffuse,
            sampler: nearest_clamp(),
        }),
        None,
        &mut budget,
    );
    assert!(matches!(refused, Err(ImageError::Budget(m)) if m.contains("64x64")));
}
