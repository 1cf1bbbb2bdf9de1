//! Tests of the sheen rules: the lane logarithm and distribution against `f64`, the albedo
//! table against an independent integral, eight lanes of every instruction set against one, a
//! sheen under one light against the formulas, and the white furnace.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use kantele_lanes::{dispatch, F32x8, Isa, LaneKernel, Lanes, Scalar};

use super::*;
use crate::shade::pbr::{shade, FrameLight, PbrLighting, Surface, Tonemap, DIELECTRIC_F0};
use crate::shade::test_support::{furnace_lighting, lane0, splat3};

#[test]
fn log2_matches_f64() {
    let mut x = f32::MIN_POSITIVE;
    while x <= 4.0 {
        let got = f64::from(log2_positive(Scalar, Scalar.splat_f32(x)).extract(0));
        let exact = f64::from(x).log2();
        assert!(
            (got - exact).abs() < 4e-7 * exact.abs().max(1.0),
            "log2 {x}: {got} vs {exact}"
        );
        x *= 1.000_9;
    }
    for (x, exact) in [(1.0f32, 0.0f32), (0.5, -1.0), (0.25, -2.0), (2.0, 1.0)] {
        assert_eq!(log2_positive(Scalar, Scalar.splat_f32(x)).extract(0), exact);
    }
}

#[test]
fn charlie_distribution_matches_f64() {
    for roughness in [0.045f64, 0.1, 0.3, 0.6, 1.0] {
        let alpha = roughness * roughness;
        for i in 0..=50 {
            let n_dot_h = i as f64 / 50.0;
            let sin2 = 1.0 - n_dot_h * n_dot_h;
            let exact = charlie_d_f64(alpha, sin2);
            let lanes = Scalar;
            let got = charlie_d(
                lanes,
                lanes.splat_f32(alpha as f32),
                lanes.splat_f32(0.5 / alpha as f32),
                lanes.splat_f32(n_dot_h as f32),
            )
            .extract(0);
            assert!(
                (f64::from(got) - exact).abs() <= 2e-4 * exact + 1e-18,
                "roughness {roughness}, NdotH {n_dot_h}: {got} vs {exact}"
            );
        }
    }
}

/// `E` by a different quadrature: uniform in the light's polar angle and azimuth over the
/// whole hemisphere, much finer.
fn albedo_by_angles(n_dot_v: f64, roughness: f64) -> f64 {
    let roughness = roughness.max(f64::from(MIN_PUNCTUAL_ROUGHNESS));
    let alpha = roughness * roughness;
    let v = DVec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let (steps_theta, steps_phi) = (1200, 360);
    let (dt, dp) = (PI / 2.0 / steps_theta as f64, 2.0 * PI / steps_phi as f64);
    let mut sum = 0.0;
    for a in 0..steps_theta {
        let theta = (a as f64 + 0.5) * dt;
        for b in 0..steps_phi {
            let phi = (b as f64 + 0.5) * dp;
            let l = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let h = (v + l).normalize();
            let visibility = charlie_v_f64(alpha, l.z, v.z);
            sum += charlie_d_f64(alpha, 1.0 - h.z * h.z) * visibility * l.z * theta.sin();
        }
    }
    sum * dt * dp
}

#[test]
fn the_albedo_table_matches_an_independent_integral() {
    let n = BRDF_TABLE_SIZE;
    let table = sheen_table();
    for (i, j) in [
        (0, 0),
        (3, 1),
        (16, 2),
        (31, 3),
        (1, 10),
        (20, 16),
        (5, 31),
        (31, 31),
    ] {
        let n_dot_v = (i as f64 + 0.5) / n as f64;
        let roughness = (j as f64 + 0.5) / n as f64;
        let exact = albedo_by_angles(n_dot_v, roughness);
        let got = f64::from(table[j * n + i]);
        assert!(
            (got - exact).abs() < 0.005 + 0.01 * exact,
            "cell ({i}, {j}): {got} vs {exact}"
        );
    }
    // The lobe reflects at most the light it receives but at the grazing views of the
    // smoothest sheens (the first column, NdotV = 1/64, roughness below 0.2), where the
    // visibility's clamp to 1 lets it reflect up to 1.45 times that.
    for j in 0..n {
        for i in 0..n {
            let e = table[j * n + i];
            let limit = if i == 0 && j < 7 { 1.46 } else { 1.0 };
            assert!((0.0..=limit).contains(&e), "albedo {e} at ({i}, {j})");
        }
    }
}

/// The lookup and the lobe on eight lanes of every instruction set.
struct Lobe {
    n_dot_v: [f32; 8],
    roughness: [f32; 8],
}

impl LaneKernel for Lobe {
    type Output = [[f32; 8]; 3];

    fn run<L: Lanes>(self, lanes: L) -> Self::Output {
        let n_dot_v = lanes.f32_from_array(self.n_dot_v);
        let roughness = lanes.f32_from_array(self.roughness);
        let layer = SheenLayer::<L> {
            color: [lanes.splat_f32(0.7); 3],
            roughness,
        };
        let terms = layer.terms(lanes, n_dot_v);
        let d = charlie_d(lanes, terms.alpha, terms.exponent, n_dot_v);
        [
            terms.albedo.to_array(),
            d.to_array(),
            log2_positive(lanes, n_dot_v).to_array(),
        ]
    }
}

#[test]
fn every_instruction_set_computes_the_same_bits() {
    for chunk in 0..30 {
        let mut n_dot_v = [0.0f32; 8];
        let mut roughness = [0.0f32; 8];
        for k in 0..8 {
            let i = (chunk * 8 + k) as f32;
            n_dot_v[k] = (i * 0.618_034).fract() * 0.999 + 0.001;
            roughness[k] = (i * 0.414_213_6).fract() * 1.2 - 0.1;
        }
        let expected = dispatch(Isa::Scalar, Lobe { n_dot_v, roughness });
        for isa in Isa::supported() {
            let got = dispatch(isa, Lobe { n_dot_v, roughness });
            assert_eq!(
                got.map(|a| a.map(f32::to_bits)),
                expected.map(|a| a.map(f32::to_bits)),
                "{isa:?}"
            );
        }
    }
}

fn sheen_surface(base: Vec3, n: Vec3, color: Vec3, roughness: f32) -> Surface<Scalar> {
    Surface {
        base: splat3(base),
        metallic: Scalar.splat_f32(0.0),
        roughness: Scalar.splat_f32(1.0),
        occlusion: Scalar.splat_f32(1.0),
        normal: splat3(n.normalize()),
        position: splat3(n.normalize()),
        dielectric_f0: splat3(Vec3::splat(DIELECTRIC_F0)),
        specular_weight: Scalar.splat_f32(0.0),
        clearcoat: None,
        sheen: Some(SheenLayer {
            color: splat3(color),
            roughness: Scalar.splat_f32(roughness),
        }),
        transmission: None,
    }
}

/// A sheen over a Lambert base (specular weight 0) under one directional light: the base
/// `base / π × NdotL`, scaled by `1 − max(color) E(NdotV)`, plus `color × D × V × NdotL`, all
/// in `f64` but for `E`, read from the table.
#[test]
fn a_sheen_under_a_directional_light_matches_the_formulas() {
    let eye = Vec3::new(0.0, 0.0, 10.0);
    let to_light = Vec3::new(0.6, 0.5, 0.62).normalize();
    let lighting = PbrLighting {
        lights: vec![FrameLight::directional(to_light, Vec3::new(2.0, 1.8, 1.5))],
        environment: None,
        eye,
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: None,
    };
    let base = Vec3::new(0.3, 0.1, 0.05);
    let color = Vec3::new(0.9, 0.6, 0.8);
    for roughness in [0.0f32, 0.3, 0.7, 1.0] {
        for n in [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.5, 0.3, 0.8),
            Vec3::new(-0.7, 0.2, 0.4),
            Vec3::new(0.9, 0.1, 0.1),
        ] {
            let s = sheen_surface(base, n, color, roughness);
            let got = lane0(shade(Scalar, &lighting, &s, &splat3(Vec3::ZERO)));
            let n = n.normalize().as_dvec3();
            let v = (eye.as_dvec3() - n).normalize();
            let l = to_light.as_dvec3();
            let h = (v + l).normalize();
            let (n_dot_l, n_dot_v) = (n.dot(l).max(0.0), n.dot(v).max(0.0));
            let n_dot_h = n.dot(h).max(0.0);
            let r = f64::from(roughness.max(MIN_PUNCTUAL_ROUGHNESS));
            let d = charlie_d_f64(r * r, 1.0 - n_dot_h * n_dot_h);
            let visibility = charlie_v_f64(r * r, n_dot_l, n_dot_v);
            let e = f64::from(sheen_albedo(n_dot_v as f32, r as f32));
            let scale = (1.0 - f64::from(color.max_element()) * e).max(0.0);
            let radiance = DVec3::new(2.0, 1.8, 1.5);
            let expected = radiance
                * n_dot_l
                * (base.as_dvec3() / PI * scale + color.as_dvec3() * d * visibility);
            let error = (got.as_dvec3() - expected).abs().max_element();
            assert!(
                error < 1e-4 * expected.max_element().max(1.0),
                "roughness {roughness}, n {n}: {got} vs {expected}"
            );
        }
    }
}

/// The white furnace with a sheen: over a white dielectric base (which alone reflects all of a
/// uniform white environment) the layer takes `max(color) E` of the base's light and gives back
/// `color × E` of its own, so a white sheen keeps the furnace at 1 and a coloured one tints it
/// by exactly that exchange — but at the grazing views of the smoothest sheens, where `E`
/// exceeds 1 (see the albedo table's test) and the base is scaled by 0.
#[test]
fn a_sheen_keeps_the_white_furnace() {
    let lighting = furnace_lighting(Vec3::new(0.0, 0.0, 10.0));
    for roughness in [0.0f32, 0.3, 0.6, 1.0] {
        for i in 0..16 {
            let z = (i as f32 + 0.5) / 16.0;
            let n = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
            let mut s = sheen_surface(Vec3::ONE, n, Vec3::ONE, roughness);
            s.specular_weight = Scalar.splat_f32(1.0);
            let got = lane0(shade(Scalar, &lighting, &s, &splat3(Vec3::ZERO)));
            let n_dot_v = n.dot((lighting.eye - n).normalize());
            let e = sheen_albedo(n_dot_v, roughness.max(MIN_PUNCTUAL_ROUGHNESS));
            let white = if e <= 1.0 { 1.0 } else { e };
            assert!(
                (got - Vec3::splat(white)).abs().max_element() < 0.03,
                "white sheen, roughness {roughness} at {n}: {got}, E = {e}"
            );
            if n_dot_v > 1.0 / 32.0 {
                assert!(e <= 1.0, "E = {e} at NdotV {n_dot_v}");
            }
            let tint = Vec3::new(1.0, 0.5, 0.0);
            let mut s = sheen_surface(Vec3::ONE, n, tint, roughness);
            s.specular_weight = Scalar.splat_f32(1.0);
            let got = lane0(shade(Scalar, &lighting, &s, &splat3(Vec3::ZERO)));
            let expected = Vec3::ONE * (1.0 - e).max(0.0) + tint * e;
            assert!(
                (got - expected).abs().max_element() < 0.03,
                "tinted sheen, roughness {roughness} at {n}: {got} vs {expected}"
            );
        }
    }
}
