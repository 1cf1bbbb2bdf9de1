//! Tests of the PBR rules: the lane code against Appendix B's formulas evaluated in `f64`, the
//! light falloffs against the `KHR_lights_punctual` formulas, tone maps, and the white furnace.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use kantele_lanes::{F32x8, Lanes, Scalar};

use super::*;
use crate::scene::{LightKind, PunctualLight};
use crate::shade::environment::EnvironmentLight;
use crate::shade::test_support::{furnace_lighting, lane0, splat3, white_environment};

fn surface(
    base: Vec3,
    metallic: f32,
    roughness: f32,
    normal: Vec3,
    position: Vec3,
) -> Surface<Scalar> {
    Surface {
        base: splat3(base),
        metallic: Scalar.splat_f32(metallic),
        roughness: Scalar.splat_f32(roughness),
        occlusion: Scalar.splat_f32(1.0),
        normal: splat3(normal.normalize()),
        position: splat3(position),
        dielectric_f0: splat3(Vec3::splat(DIELECTRIC_F0)),
        specular_weight: Scalar.splat_f32(1.0),
        clearcoat: None,
        sheen: None,
        transmission: None,
    }
}

/// No emission.
fn dark() -> [<Scalar as Lanes>::F32; 3] {
    splat3(Vec3::ZERO)
}

/// Appendix B in `f64`: `(1 − F) c_diff / π + F D V`, times `NdotL` and the light.
fn appendix_b(base: DVec3, metallic: f64, roughness: f64, n: DVec3, v: DVec3, l: DVec3) -> DVec3 {
    appendix_b_specular(base, metallic, roughness, DVec3::splat(0.04), 1.0, n, v, l)
}

/// [`appendix_b`] with `KHR_materials_specular`'s dielectric reflectance `f0_d` and weight
/// `w`: the metal's Fresnel (F0 = base, F90 = 1) mixed by `metallic` with the dielectric's
/// (F0 = f0_d, F90 = 1) scaled by `w`.
#[allow(clippy::too_many_arguments)]
fn appendix_b_specular(
    base: DVec3,
    metallic: f64,
    roughness: f64,
    f0_d: DVec3,
    w: f64,
    n: DVec3,
    v: DVec3,
    l: DVec3,
) -> DVec3 {
    let h = (l + v).normalize();
    let n_dot_l = n.dot(l).clamp(0.0, 1.0);
    if n_dot_l == 0.0 {
        return DVec3::ZERO;
    }
    let n_dot_v = n.dot(v).clamp(0.0, 1.0);
    let n_dot_h = n.dot(h).clamp(0.0, 1.0);
    let v_dot_h = v.dot(h).clamp(0.0, 1.0);
    let c_diff = base * (1.0 - metallic);
    let k = (1.0 - v_dot_h).powi(5);
    let dielectric_f = (f0_d + (DVec3::ONE - f0_d) * k) * w;
    let metal_f = base + (DVec3::ONE - base) * k;
    let f = dielectric_f.lerp(metal_f, metallic);
    let alpha = roughness.max(MIN_PUNCTUAL_ROUGHNESS as f64).powi(2);
    let a2 = alpha * alpha;
    let d = a2 / (PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
    let vis = 0.5
        / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
            + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt());
    ((DVec3::ONE - f) * c_diff / PI + f * d * vis) * n_dot_l
}

/// A sphere under one directional light: the lane code matches Appendix B in `f64` at points
/// spread over it, for dielectrics and metals, smooth and rough.
#[test]
fn a_sphere_under_a_directional_light_matches_appendix_b() {
    let to_light = Vec3::new(0.3, 0.8, 0.5).normalize();
    let eye = Vec3::new(0.0, 0.0, 5.0);
    let lighting = PbrLighting {
        lights: vec![FrameLight::directional(to_light, Vec3::new(2.0, 1.5, 1.0))],
        environment: None,
        eye,
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: None,
    };
    let mut checked = 0;
    for base in [
        Vec3::new(0.9, 0.5, 0.2),
        Vec3::splat(1.0),
        Vec3::splat(0.02),
    ] {
        for metallic in [0.0, 0.5, 1.0] {
            for roughness in [0.0, 0.1, 0.35, 0.7, 1.0] {
                for i in 0..40 {
                    // Points on the unit sphere facing the eye (a spiral).
                    let t = (i as f32 + 0.5) / 40.0;
                    let z = t;
                    let phi = i as f32 * 2.399_963;
                    let r = (1.0 - z * z).sqrt();
                    let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                    let s = surface(base, metallic, roughness, n, n);
                    let got = lane0(shade(Scalar, &lighting, &s, &dark()));
                    let v = (eye - n).normalize().as_dvec3();
                    let want = appendix_b(
                        base.as_dvec3(),
                        metallic as f64,
                        roughness as f64,
                        n.as_dvec3(),
                        v,
                        to_light.as_dvec3(),
                    ) * DVec3::new(2.0, 1.5, 1.0);
                    let error = (got.as_dvec3() - want).abs().max_element();
                    let bound = 1e-5 + 1e-4 * want.abs().max_element();
                    assert!(
                        error <= bound,
                        "base {base} metallic {metallic} roughness {roughness} n {n}: {got} vs {want}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 3 * 3 * 5 * 40);
}

/// Point and spot lights fall off by `KHR_lights_punctual`'s formulas: inverse square, the
/// range window `clamp(1 − (d/r)⁴, 0, 1)` and the cone `clamp(cos θ × scale + offset, 0, 1)²`.
#[test]
fn point_and_spot_falloff_follow_the_formulas() {
    let (inner, outer) = (0.3f64, 0.6f64);
    let spot = PunctualLight {
        kind: LightKind::Spot {
            inner_cone_angle: inner as f32,
            outer_cone_angle: outer as f32,
        },
        color: Vec3::ONE,
        position: Vec3::new(0.0, 4.0, 0.0),
        direction: Vec3::new(0.0, -1.0, 0.0),
        range: Some(6.0),
    };
    let point = PunctualLight {
        kind: LightKind::Point,
        range: None,
        ..spot
    };
    for (light, ranged) in [(spot, true), (point, false)] {
        let frame = FrameLight::new(&light);
        for i in 0..50 {
            let x = i as f32 * 0.13;
            let p = Vec3::new(x, 0.5 - x * 0.2, 0.3);
            let (l, attenuation) = light_arrival(Scalar, &frame, &splat3(p));
            let d = light.position.as_dvec3() - p.as_dvec3();
            let distance = d.length();
            let mut want = 1.0 / (distance * distance);
            if ranged {
                want *= (1.0 - (distance / 6.0).powi(4)).clamp(0.0, 1.0);
                let cos = (-d / distance).dot(DVec3::new(0.0, -1.0, 0.0));
                let scale = 1.0 / (inner.cos() - outer.cos());
                let cone = (cos * scale - outer.cos() * scale).clamp(0.0, 1.0);
                want *= cone * cone;
            }
            let got = attenuation.extract(0) as f64;
            assert!(
                (got - want).abs() <= 1e-5 + 1e-4 * want,
                "{light:?} at {p}: {got} vs {want}"
            );
            let l = lane0(l).as_dvec3();
            assert!((l - d / distance).length() < 1e-5);
        }
    }
}

/// PBR Neutral keeps colours below its compression start (after the small offset), maps
/// every colour into [0, 1], and keeps order; ACES stays in [0, 1] and is monotonic.
#[test]
fn tone_maps_keep_range_and_order() {
    let map = |t: Tonemap, v: f32| lane0(tonemap(Scalar, t, 1.0, splat3(Vec3::splat(v)))).x;
    // Grey 0.5: offset 0.04 removed, nothing compressed.
    assert!((map(Tonemap::PbrNeutral, 0.5) - 0.46).abs() < 1e-6);
    let mut previous = [0.0f32; 2];
    for i in 0..200 {
        let v = i as f32 * 0.1;
        for (k, t) in [Tonemap::PbrNeutral, Tonemap::Aces].into_iter().enumerate() {
            let out = map(t, v);
            assert!((0.0..=1.0).contains(&out), "{t:?}({v}) = {out}");
            assert!(out >= previous[k], "{t:?} is not monotonic at {v}");
            previous[k] = out;
        }
    }
    assert_eq!(map(Tonemap::None, 3.5), 3.5);
    for t in [Tonemap::None, Tonemap::PbrNeutral, Tonemap::Aces] {
        assert_eq!(Tonemap::from_name(t.name()), Some(t));
    }
}

/// The white furnace: in a uniform white environment of radiance 1, white spheres reflect
/// what the split-sum model keeps of it. Dielectrics (diffuse × (1 − F0 A − B) + specular ×
/// (F0 A + B)) come out 1 within the table's interpolation; metals come out `A + B`, below 1 by
/// the single-scattering GGX model's known energy loss (up to 0.7 of the light is lost, at
/// roughness 1 and grazing angles; stated in docs/rendering-rules.md), and never above 1.
#[test]
fn white_furnace() {
    let environment = white_environment();
    // Irradiance ÷ π of a uniform radiance-1 sky is 1 in every direction.
    for n in [
        Vec3::X,
        Vec3::Y,
        -Vec3::Z,
        Vec3::new(0.3, -0.5, 0.8).normalize(),
    ] {
        let light = EnvironmentLight {
            environment: std::sync::Arc::new(environment.clone()),
            intensity: 1.0,
            rotation: 0.4,
        };
        let e = lane0(light.irradiance_lanes(Scalar, &splat3(n)));
        assert!(
            (e - Vec3::ONE).abs().max_element() < 0.01,
            "irradiance {e} at {n}"
        );
        for roughness in [0.0, 0.3, 1.0] {
            let s = lane0(light.specular_lanes(Scalar, &splat3(n), Scalar.splat_f32(roughness)));
            assert!(
                (s - Vec3::ONE).abs().max_element() < 0.01,
                "specular {s} at {n}"
            );
        }
    }
    let lighting = furnace_lighting(Vec3::new(0.0, 0.0, 10.0));
    for roughness in [0.0f32, 0.25, 0.5, 0.75, 1.0] {
        for i in 0..20 {
            let z = (i as f32 + 0.5) / 20.0;
            let n = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
            let dielectric = lane0(shade(
                Scalar,
                &lighting,
                &surface(Vec3::ONE, 0.0, roughness, n, n),
                &dark(),
            ));
            assert!(
                (dielectric - Vec3::ONE).abs().max_element() < 0.02,
                "dielectric roughness {roughness} at {n}: {dielectric}"
            );
            let metal = lane0(shade(
                Scalar,
                &lighting,
                &surface(Vec3::ONE, 1.0, roughness, n, n),
                &dark(),
            ));
            let n_dot_v = n.dot((Vec3::new(0.0, 0.0, 10.0) - n).normalize());
            let [a, b] = crate::shade::environment::brdf_ab(n_dot_v, roughness);
            assert!(
                (metal - Vec3::splat(a + b)).abs().max_element() < 0.01 && metal.x <= 1.01,
                "metal roughness {roughness} at {n}: {metal}, A + B = {}",
                a + b
            );
            assert!(
                a + b >= 0.3,
                "roughness {roughness}, NdotV {n_dot_v}: A + B = {}",
                a + b
            );
        }
    }
}

/// `KHR_materials_ior` and `KHR_materials_specular`: with any dielectric reflectance (from the
/// IOR and a specular colour) and specular weight, a sphere under one directional light
/// matches the `f64` formula; weight 0 leaves pure Lambert diffuse (`base / π × NdotL` for a
/// dielectric).
#[test]
fn specular_and_ior_follow_the_formulas() {
    let to_light = Vec3::new(-0.4, 0.7, 0.6).normalize();
    let eye = Vec3::new(0.0, 0.0, 5.0);
    let lighting = PbrLighting {
        lights: vec![FrameLight::directional(to_light, Vec3::ONE)],
        environment: None,
        eye,
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: None,
    };
    let f0_of_ior = |ior: f64| ((ior - 1.0) / (ior + 1.0)).powi(2);
    let base = Vec3::new(0.8, 0.3, 0.1);
    for ior in [1.0, 1.33, 1.5, 2.4] {
        for color in [Vec3::ONE, Vec3::new(1.0, 0.2, 0.5), Vec3::splat(30.0)] {
            // The loader's value, clamped as the shading clamps it.
            let f0_d = (Vec3::splat(f0_of_ior(ior) as f32) * color).min(Vec3::ONE);
            for w in [0.0f32, 0.5, 1.0] {
                for metallic in [0.0f32, 0.6] {
                    for i in 0..30 {
                        let z = (i as f32 + 0.5) / 30.0;
                        let phi = i as f32 * 2.399_963;
                        let r = (1.0 - z * z).sqrt();
                        let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                        let mut s = surface(base, metallic, 0.4, n, n);
                        s.dielectric_f0 = splat3(f0_d);
                        s.specular_weight = Scalar.splat_f32(w);
                        let got = lane0(shade(Scalar, &lighting, &s, &dark())).as_dvec3();
                        let v = (eye - n).normalize().as_dvec3();
                        let want = appendix_b_specular(
                            base.as_dvec3(),
                            metallic as f64,
                            0.4,
                            f0_d.as_dvec3(),
                            w as f64,
                            n.as_dvec3(),
                            v,
                            to_light.as_dvec3(),
                        );
                        let bound = 1e-5 + 1e-4 * want.abs().max_element();
                        assert!(
                            (got - want).abs().max_element() <= bound,
                            "ior {ior} colour {color} w {w} metallic {metallic} n {n}: {got} vs {want}"
                        );
                        if w == 0.0 && metallic == 0.0 {
                            let lambert = base.as_dvec3() / PI
                                * n.as_dvec3().dot(to_light.as_dvec3()).max(0.0);
                            assert!((got - lambert).abs().max_element() <= 1e-5);
                        }
                    }
                }
            }
        }
    }
}

/// `KHR_materials_clearcoat` under one directional light: a coat of weight `k` scales what
/// lies under it (emission included) by `1 − k F_coat(N_c·V)` and adds `k ×` its own GGX lobe
/// (F0 0.04, its roughness and normal), as evaluated in `f64`; a coat of weight 0 changes no
/// bit.
#[test]
fn a_clear_coat_layers_over_the_base() {
    let to_light = Vec3::new(0.2, 0.6, 0.8).normalize();
    let eye = Vec3::new(0.0, 0.0, 5.0);
    let color = Vec3::new(1.5, 1.0, 0.5);
    let lighting = PbrLighting {
        lights: vec![FrameLight::directional(to_light, color)],
        environment: None,
        eye,
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: None,
    };
    let base = Vec3::new(0.1, 0.4, 0.9);
    let emissive = Vec3::new(0.05, 0.0, 0.2);
    for i in 0..40 {
        let z = (i as f32 + 0.5) / 40.0;
        let phi = i as f32 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let plain = surface(base, 0.3, 0.6, n, n);
        let under = lane0(shade(Scalar, &lighting, &plain, &splat3(emissive))).as_dvec3();
        let mut zero_coat = plain;
        zero_coat.clearcoat = Some(ClearcoatLayer {
            factor: Scalar.splat_f32(0.0),
            roughness: Scalar.splat_f32(0.2),
            normal: splat3(Vec3::Z),
        });
        let same = lane0(shade(Scalar, &lighting, &zero_coat, &splat3(emissive)));
        assert_eq!(same.as_dvec3(), under, "a coat of weight 0 changes nothing");
        for (k, coat_roughness) in [(1.0f32, 0.0f32), (0.5, 0.3), (0.8, 1.0)] {
            // The coat's own normal: tilted from the base's.
            let coat_normal = (n + Vec3::new(0.1, -0.05, 0.0)).normalize();
            let mut coated = plain;
            coated.clearcoat = Some(ClearcoatLayer {
                factor: Scalar.splat_f32(k),
                roughness: Scalar.splat_f32(coat_roughness),
                normal: splat3(coat_normal),
            });
            let got = lane0(shade(Scalar, &lighting, &coated, &splat3(emissive))).as_dvec3();
            let (nc, v, l) = (
                coat_normal.as_dvec3(),
                (eye - n).normalize().as_dvec3(),
                to_light.as_dvec3(),
            );
            let h = (l + v).normalize();
            let schlick = |cos: f64| 0.04 + 0.96 * (1.0 - cos.clamp(0.0, 1.0)).powi(5);
            let n_dot_l = nc.dot(l).clamp(0.0, 1.0);
            let n_dot_v = nc.dot(v).clamp(0.0, 1.0);
            let n_dot_h = nc.dot(h).clamp(0.0, 1.0);
            let alpha = (coat_roughness as f64)
                .max(MIN_PUNCTUAL_ROUGHNESS as f64)
                .powi(2);
            let a2 = alpha * alpha;
            let d = a2 / (PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
            let denominator = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
                + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
            let vis = if denominator > 0.0 {
                0.5 / denominator
            } else {
                0.0
            };
            let lobe = color.as_dvec3() * (n_dot_l * schlick(v.dot(h)) * d * vis);
            let k = k as f64;
            let want = under * (1.0 - k * schlick(n_dot_v)) + lobe * k;
            let bound = 2e-5 + 2e-4 * want.abs().max_element();
            assert!(
                (got - want).abs().max_element() <= bound,
                "coat {k} roughness {coat_roughness} at {n}: {got} vs {want}"
            );
        }
    }
}

/// A white furnace under a clear coat: a white dielectric under a smooth coat of weight 1
/// still comes out 1 (what the coat reflects, the layer under it no longer receives), and
/// rough coats lose light but never create it: the layer under the coat is dimmed by the
/// coat's Fresnel at `N·V`, while the rough coat reflects less than that (its split-sum
/// albedo), up to 30% of the light at grazing angles — the layering of the extension
/// and of the glTF sample viewer, which do not compensate it.
#[test]
fn a_clear_coat_conserves_energy_in_the_furnace() {
    let eye = Vec3::new(0.0, 0.0, 10.0);
    let lighting = furnace_lighting(eye);
    for coat_roughness in [0.0f32, 0.5, 1.0] {
        for i in 0..20 {
            let z = 0.3 + 0.7 * (i as f32 + 0.5) / 20.0;
            let n = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
            let mut s = surface(Vec3::ONE, 0.0, 0.5, n, n);
            s.clearcoat = Some(ClearcoatLayer {
                factor: Scalar.splat_f32(1.0),
                roughness: Scalar.splat_f32(coat_roughness),
                normal: splat3(n),
            });
            let out = lane0(shade(Scalar, &lighting, &s, &dark()));
            assert!(
                out.max_element() <= 1.02,
                "coat roughness {coat_roughness} at {n}: {out}"
            );
            let floor = if coat_roughness == 0.0 { 0.97 } else { 0.7 };
            assert!(
                out.min_element() >= floor,
                "coat roughness {coat_roughness} at {n}: {out}"
            );
        }
    }
}
