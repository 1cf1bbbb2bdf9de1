//! Tests of the specular-glossiness conversion: the extension's own examples (a white
//! dielectric, gold), glossiness, the range of every result over a grid of inputs, and the
//! round trip from grey metallic-roughness materials through the published inverse conversion.

use glam::Vec3;

use super::*;

fn convert(diffuse: Vec3, specular: Vec3, glossiness: f32) -> MetallicRoughness {
    to_metallic_roughness(SpecularGlossiness {
        diffuse,
        specular,
        glossiness,
    })
}

fn assert_close(a: Vec3, b: Vec3, tolerance: f32) {
    assert!(
        (a - b).abs().max_element() <= tolerance,
        "{a} is not within {tolerance} of {b}"
    );
}

#[test]
fn white_diffuse_without_specular_is_a_white_dielectric() {
    let m = convert(Vec3::ONE, Vec3::ZERO, 1.0);
    assert_eq!(m.metallic, 0.0);
    // diffuse / (1 − F0) clamps to 1.
    assert_eq!(m.base_color, Vec3::ONE);
    assert_eq!(m.roughness, 0.0);
}

#[test]
fn dielectric_specular_keeps_the_diffuse_colour_scaled() {
    // Specular at exactly F0: the quadratic's root is 0, and base = diffuse × 0.96 / 0.96.
    let diffuse = Vec3::new(0.5, 0.25, 0.125);
    let m = convert(diffuse, Vec3::splat(DIELECTRIC_F0), 0.5);
    assert!(m.metallic.abs() < 1e-6, "metallic {}", m.metallic);
    assert_close(m.base_color, diffuse, 1e-5);
}

#[test]
fn gold_specular_with_black_diffuse_is_a_gold_metal() {
    // The extension's own example of gold.
    let gold = Vec3::new(1.0, 0.766, 0.336);
    let m = convert(Vec3::ZERO, gold, 1.0);
    assert!((m.metallic - 1.0).abs() < 1e-4, "metallic {}", m.metallic);
    assert_close(m.base_color, gold, 1e-3);
}

#[test]
fn roughness_is_one_minus_glossiness() {
    for g in [0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0] {
        let m = convert(Vec3::splat(0.5), Vec3::splat(0.3), g);
        assert_eq!(m.roughness, 1.0 - g, "glossiness {g}");
    }
}

#[test]
fn results_stay_in_range_over_a_grid_of_inputs() {
    let steps = [0.0, 0.02, 0.04, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0];
    for &dr in &steps {
        for &dg in &steps {
            for &s in &steps {
                for &sb in &steps {
                    for &g in &[0.0, 0.5, 1.0] {
                        let diffuse = Vec3::new(dr, dg, 0.5);
                        let specular = Vec3::new(s, s, sb);
                        let m = convert(diffuse, specular, g);
                        let b = m.base_color;
                        assert!(
                            b.is_finite() && b.cmpge(Vec3::ZERO).all() && b.cmple(Vec3::ONE).all(),
                            "base {b} for diffuse {diffuse}, specular {specular}"
                        );
                        assert!(
                            (0.0..=1.0).contains(&m.metallic),
                            "metallic {} for diffuse {diffuse}, specular {specular}",
                            m.metallic
                        );
                        assert!((0.0..=1.0).contains(&m.roughness));
                    }
                }
            }
        }
    }
}

#[test]
fn metallic_grows_with_specular_brightness() {
    let mut last = -1.0;
    for k in 0..=20 {
        let s = k as f32 / 20.0;
        let m = convert(Vec3::splat(0.2), Vec3::splat(s), 0.5).metallic;
        assert!(m >= last, "metallic {m} after {last} at specular {s}");
        last = m;
    }
    assert!(last > 0.99, "white specular gives metallic {last}");
}

#[test]
fn out_of_range_and_nan_inputs_are_clamped() {
    let m = convert(Vec3::new(f32::NAN, 2.0, -1.0), Vec3::splat(f32::NAN), 1.5);
    assert!(m.base_color.is_finite() && m.metallic.is_finite());
    assert_eq!(m.roughness, 0.0);
    let m = convert(Vec3::ONE, Vec3::ZERO, -0.5);
    assert_eq!(m.roughness, 1.0);
}

/// The published inverse (`ConvertToSpecularGlossiness` of the same file), for the round trip.
fn to_specular_glossiness(base: Vec3, metallic: f32, roughness: f32) -> SpecularGlossiness {
    let specular = Vec3::splat(DIELECTRIC_F0).lerp(base, metallic);
    let one_minus_specular_strength = 1.0 - specular.max_element();
    let diffuse = base
        * ((1.0 - DIELECTRIC_F0) * (1.0 - metallic) / one_minus_specular_strength.max(EPSILON));
    SpecularGlossiness {
        diffuse,
        specular,
        glossiness: 1.0 - roughness,
    }
}

#[test]
fn grey_metallic_roughness_materials_survive_the_round_trip() {
    for grey in [0.05, 0.1, 0.25, 0.5, 0.75, 0.9] {
        for metallic in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let base = Vec3::splat(grey);
            let back = to_metallic_roughness(to_specular_glossiness(base, metallic, 0.3));
            assert!(
                (back.metallic - metallic).abs() < 2e-3,
                "grey {grey}, metallic {metallic}: back {}",
                back.metallic
            );
            assert_close(back.base_color, base, 2e-3);
            assert!((back.roughness - 0.3).abs() < 1e-6);
        }
    }
}
