//! Tests of the transmission rules: the backdrop's chain and lookups (scalar and every
//! instruction set), the refracted path, Beer's law, and a transmissive surface's colour
//! against the formulas.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use kantele_lanes::{dispatch, F32x8, Isa, LaneKernel, Lanes, Scalar};

use super::*;
use crate::shade::pbr::{self, PbrLighting, Surface, Tonemap, DIELECTRIC_F0};
use crate::shade::test_support::{lane0, splat3};

/// A `w` × `h` picture whose pixel (x, y) is (x, y, x + 10 y).
fn ramp(w: u32, h: u32) -> Vec<[f32; 4]> {
    (0..h)
        .flat_map(|y| (0..w).map(move |x| [x as f32, y as f32, (x + 10 * y) as f32, 1.0]))
        .collect()
}

#[test]
fn the_chain_halves_down_to_one_texel_with_box_means() {
    let b = Backdrop::new(5, 3, &ramp(5, 3)).expect("backdrop");
    assert_eq!(b.level_count(), 3);
    let sizes: Vec<_> = (0..3)
        .map(|k| b.level(k).map(|(w, h, _)| (w, h)).unwrap())
        .collect();
    assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
    let (_, _, level0) = b.level(0).unwrap();
    assert_eq!(level0[7], [2.0, 1.0, 12.0]);
    // Level 1 texel (1, 0): the mean of (2..=3, 0..=1).
    let (_, _, level1) = b.level(1).unwrap();
    assert_eq!(level1[1], [2.5, 0.5, 7.5]);
    assert!(b.level(3).is_none());
}

#[test]
fn bad_pictures_are_refused_and_bad_values_cleaned() {
    assert!(Backdrop::new(0, 3, &[]).is_none());
    assert!(Backdrop::new(2, 2, &ramp(2, 1)).is_none());
    assert!(Backdrop::new(MAX_BACKDROP_SIZE + 1, 1, &ramp(MAX_BACKDROP_SIZE + 1, 1)).is_none());
    let pixels = [
        [f32::NAN, -1.0, f32::INFINITY, 1.0],
        [1.0, f32::NEG_INFINITY, 2.0e38, 0.0],
    ];
    let b = Backdrop::new(2, 1, &pixels).expect("backdrop");
    let (_, _, level0) = b.level(0).unwrap();
    assert_eq!(level0, [[0.0, 0.0, MAX_RADIANCE], [1.0, 0.0, MAX_RADIANCE]]);
    assert!(b.level(1).unwrap().2[0].iter().all(|c| c.is_finite()));
}

#[test]
fn backdrop_sizes_fit_the_limit_and_keep_the_aspect() {
    assert_eq!(backdrop_size(640, 480), (640, 480));
    assert_eq!(backdrop_size(0, 0), (1, 1));
    assert_eq!(backdrop_size(4096, 2160), (2048, 1080));
    assert_eq!(backdrop_size(100, 100_000), (2, 2048));
}

#[test]
fn lookups_hit_texel_centres_blend_levels_and_clamp_to_the_edge() {
    let b = Backdrop::new(4, 2, &ramp(4, 2)).expect("backdrop");
    // The centre of texel (2, 1) at level 0.
    assert_eq!(
        b.sample(Vec2::new(2.5 / 4.0, 1.5 / 2.0), 0.0),
        Vec3::new(2.0, 1.0, 12.0)
    );
    // Halfway between texels (1, 0) and (2, 0).
    assert_eq!(
        b.sample(Vec2::new(0.5, 0.25), 0.0),
        Vec3::new(1.5, 0.0, 1.5)
    );
    // Outside the picture: the edge texel (and a NaN coordinate reads the first column).
    assert_eq!(
        b.sample(Vec2::new(7.0, -3.0), 0.0),
        Vec3::new(3.0, 0.0, 3.0)
    );
    assert_eq!(
        b.sample(Vec2::new(f32::NAN, 0.0), 0.0),
        Vec3::new(0.0, 0.0, 0.0)
    );
    // Level 2 is the 1 × 1 mean; lod past the chain reads it, and lod 1.5 is halfway.
    let mean = Vec3::new(1.5, 0.5, 6.5);
    assert_eq!(b.sample(Vec2::splat(0.3), 9.0), mean);
    let level1 = b.sample(Vec2::splat(0.5), 1.0);
    let halfway = b.sample(Vec2::splat(0.5), 1.5);
    assert!((halfway - (level1 + mean) * 0.5).abs().max_element() < 1e-6);
}

/// Backdrop lookups and the exponential on eight lanes of every instruction set.
struct Lookups<'a> {
    backdrop: &'a Backdrop,
    u: [f32; 8],
    v: [f32; 8],
    lod: [f32; 8],
}

impl LaneKernel for Lookups<'_> {
    type Output = [[f32; 8]; 4];

    fn run<L: Lanes>(self, lanes: L) -> Self::Output {
        let uv = [lanes.f32_from_array(self.u), lanes.f32_from_array(self.v)];
        let lod = lanes.f32_from_array(self.lod);
        let s = self.backdrop.sample_lanes(lanes, uv, lod);
        let e = exp2_nonpositive(lanes, lanes.f32_from_array(self.u));
        [
            s[0].to_array(),
            s[1].to_array(),
            s[2].to_array(),
            e.to_array(),
        ]
    }
}

#[test]
fn every_instruction_set_reads_the_same_bits() {
    let b = Backdrop::new(37, 11, &ramp(37, 11)).expect("backdrop");
    let mut inputs = Vec::new();
    for chunk in 0..40 {
        let mut u = [0.0f32; 8];
        let mut v = [0.0f32; 8];
        let mut lod = [0.0f32; 8];
        for k in 0..8 {
            let i = (chunk * 8 + k) as f32;
            u[k] = (i * 0.618_034).fract() * 1.4 - 0.2;
            v[k] = (i * 0.414_213_6).fract() * 1.4 - 0.2;
            lod[k] = match (chunk * 8 + k) % 13 {
                11 => f32::NAN,
                12 => f32::INFINITY,
                j => j as f32 * 0.55 - 0.3,
            };
        }
        inputs.push((u, v, lod));
    }
    for isa in Isa::supported() {
        for &(u, v, lod) in &inputs {
            let got = dispatch(
                isa,
                Lookups {
                    backdrop: &b,
                    u,
                    v,
                    lod,
                },
            );
            for k in 0..8 {
                let expected = b.sample(Vec2::new(u[k], v[k]), lod[k]);
                let e = exp2_nonpositive(Scalar, Scalar.splat_f32(u[k])).extract(0);
                let lane = [got[0][k], got[1][k], got[2][k], got[3][k]];
                assert_eq!(
                    lane.map(f32::to_bits),
                    [expected.x, expected.y, expected.z, e].map(f32::to_bits),
                    "{isa:?} at {:?}",
                    (u[k], v[k], lod[k])
                );
            }
        }
    }
}

#[test]
fn exp2_matches_f64_to_two_millionths() {
    let mut x = -130.0f32;
    while x <= 0.0 {
        let got = f64::from(exp2_nonpositive(Scalar, Scalar.splat_f32(x)).extract(0));
        let exact = f64::from(x.max(-126.0)).exp2();
        assert!(
            ((got - exact) / exact).abs() < 2e-6,
            "2^{x}: {got} vs {exact}"
        );
        x += 0.013;
    }
    assert_eq!(
        exp2_nonpositive(Scalar, Scalar.splat_f32(0.0)).extract(0),
        1.0
    );
    assert_eq!(
        exp2_nonpositive(Scalar, Scalar.splat_f32(3.0)).extract(0),
        1.0
    );
    assert_eq!(
        exp2_nonpositive(Scalar, Scalar.splat_f32(-1.0)).extract(0),
        0.5
    );
}

fn layer(thickness: f32, volume: Volume) -> TransmissionLayer<Scalar> {
    TransmissionLayer {
        factor: Scalar.splat_f32(1.0),
        thickness: Scalar.splat_f32(thickness),
        volume,
    }
}

fn volume(ior: f32, color: Vec3, distance: f32, model: Mat4) -> Volume {
    let b = Backdrop::new(8, 8, &ramp(8, 8)).expect("backdrop");
    Volume::new(ior, color, distance, &model, &b)
}

#[test]
fn the_view_ray_bends_by_snells_law_over_the_scaled_thickness() {
    let n = Vec3::Z;
    let view = Vec3::new(0.6, 0.0, 0.8); // 36.87° from the normal
    let v = volume(
        1.5,
        Vec3::ONE,
        f32::INFINITY,
        Mat4::from_scale(Vec3::splat(2.0)),
    );
    let path = lane0(refraction_path(
        Scalar,
        &layer(0.5, v),
        &splat3(n),
        &splat3(view),
    ));
    // Length: thickness × scale; sin θt = sin θi / ior; the path goes into the surface.
    assert!((path.length() - 1.0).abs() < 1e-6, "{path}");
    let sin_t = path.x.abs() / path.length();
    assert!((sin_t - 0.6 / 1.5).abs() < 1e-6, "{sin_t}");
    assert!(path.x < 0.0 && path.z < 0.0, "{path}");
    // IOR 1 goes straight on; a thin wall has no path.
    let straight = volume(1.0, Vec3::ONE, f32::INFINITY, Mat4::IDENTITY);
    let path = lane0(refraction_path(
        Scalar,
        &layer(2.0, straight),
        &splat3(n),
        &splat3(view),
    ));
    assert!((path + view * 2.0).length() < 1e-6, "{path}");
    let thin = lane0(refraction_path(
        Scalar,
        &layer(0.0, v),
        &splat3(n),
        &splat3(view),
    ));
    assert_eq!(thin, Vec3::ZERO);
}

#[test]
fn volumes_dim_the_light_by_beers_law() {
    // Half the light left after one attenuation distance, a quarter after two.
    let v = volume(1.5, Vec3::new(0.5, 1.0, 0.25), 1.5, Mat4::IDENTITY);
    let path = splat3(Vec3::new(0.0, 0.0, -3.0));
    let out = lane0(attenuate(Scalar, &v, &path, splat3(Vec3::ONE)));
    let expected = Vec3::new(0.25, 1.0, 0.0625);
    assert!((out - expected).abs().max_element() < 1e-6, "{out}");
    // Without a distance nothing is lost; a black channel loses everything.
    let clear = volume(1.5, Vec3::splat(0.1), f32::INFINITY, Mat4::IDENTITY);
    assert_eq!(clear.attenuation, Vec3::ZERO);
    let black = volume(1.5, Vec3::new(0.0, 1.0, 1.0), 1.0, Mat4::IDENTITY);
    let out = lane0(attenuate(Scalar, &black, &path, splat3(Vec3::ONE)));
    assert!(out.x < 1e-30 && out.y == 1.0, "{out}");
}

#[test]
fn the_centre_of_the_view_projects_to_the_centre_of_the_backdrop() {
    let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
    let projection = Mat4::perspective_rh_gl(1.0, 2.0, 0.1, 100.0);
    let vp = projection * view;
    let uv = backdrop_uv(Scalar, &vp, &splat3(Vec3::ZERO));
    assert!((uv[0].extract(0) - 0.5).abs() < 1e-6 && (uv[1].extract(0) - 0.5).abs() < 1e-6);
    // Up in the world is up in the picture (v towards 0), right is right.
    let up = backdrop_uv(Scalar, &vp, &splat3(Vec3::new(0.5, 0.5, 0.0)));
    assert!(up[0].extract(0) > 0.5 && up[1].extract(0) < 0.5);
}

/// A white thin-walled pane of full transmission, IOR 1.5, roughness 0, facing the eye, in
/// front of a uniform backdrop of 0.6 with no other light: it shows the backdrop × (1 − F_ss
/// E_ss), the part the specular reflection leaves (the split-sum terms at N·V = 1).
#[test]
fn a_clear_pane_shows_the_backdrop_less_its_reflection() {
    let backdrop = Arc::new(Backdrop::new(4, 4, &[[0.6, 0.6, 0.6, 1.0]; 16]).expect("backdrop"));
    let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
    let vp = Mat4::perspective_rh_gl(1.0, 1.0, 0.1, 10.0) * view;
    let lighting = PbrLighting {
        lights: Vec::new(),
        environment: None,
        eye: Vec3::new(0.0, 0.0, 3.0),
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: Some(TransmissionView {
            backdrop: backdrop.clone(),
            view_projection: vp,
        }),
    };
    let shade = |transmission: f32| {
        let v = Volume::new(1.5, Vec3::ONE, f32::INFINITY, &Mat4::IDENTITY, &backdrop);
        let surface = Surface {
            base: splat3(Vec3::ONE),
            metallic: Scalar.splat_f32(0.0),
            roughness: Scalar.splat_f32(0.0),
            occlusion: Scalar.splat_f32(1.0),
            normal: splat3(Vec3::Z),
            position: splat3(Vec3::ZERO),
            dielectric_f0: splat3(Vec3::splat(DIELECTRIC_F0)),
            specular_weight: Scalar.splat_f32(1.0),
            clearcoat: None,
            sheen: None,
            transmission: Some(TransmissionLayer {
                factor: Scalar.splat_f32(transmission),
                ..layer(0.0, v)
            }),
        };
        lane0(pbr::shade(Scalar, &lighting, &surface, &splat3(Vec3::ZERO)))
    };
    let [a, b] = crate::shade::environment::brdf_ab(1.0, 0.0);
    let expected = 0.6 * (1.0 - (DIELECTRIC_F0 * a + b));
    let full = shade(1.0);
    assert!(
        (full - Vec3::splat(expected)).abs().max_element() < 1e-6,
        "{full} vs {expected}"
    );
    assert!(expected > 0.55, "{expected}");
    // Half the transmission, half the light from behind (nothing else lights the pane).
    let half = shade(0.5);
    assert!((half - full * 0.5).abs().max_element() < 1e-6, "{half}");
}

/// A point light behind a clear pane shines through it towards the eye by the transmitted
/// lobe, and not at all through an opaque one.
#[test]
fn punctual_light_behind_a_pane_comes_through() {
    let backdrop = Arc::new(Backdrop::new(1, 1, &[[0.0; 4]]).expect("backdrop"));
    let eye = Vec3::new(0.0, 0.0, 3.0);
    let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y);
    let shade = |light_z: f32, transmission: Option<f32>| {
        let light = crate::scene::PunctualLight {
            kind: crate::scene::LightKind::Point,
            color: Vec3::splat(4.0),
            position: Vec3::new(0.0, 0.0, light_z),
            direction: Vec3::NEG_Z,
            range: None,
        };
        let lighting = PbrLighting {
            lights: vec![pbr::FrameLight::new(&light)],
            environment: None,
            eye,
            exposure: 1.0,
            tonemap: Tonemap::None,
            transmission: Some(TransmissionView {
                backdrop: backdrop.clone(),
                view_projection: Mat4::perspective_rh_gl(1.0, 1.0, 0.1, 10.0) * view,
            }),
        };
        let v = Volume::new(1.5, Vec3::ONE, f32::INFINITY, &Mat4::IDENTITY, &backdrop);
        let surface = Surface {
            base: splat3(Vec3::ONE),
            metallic: Scalar.splat_f32(0.0),
            roughness: Scalar.splat_f32(0.3),
            occlusion: Scalar.splat_f32(1.0),
            normal: splat3(Vec3::Z),
            position: splat3(Vec3::ZERO),
            dielectric_f0: splat3(Vec3::splat(DIELECTRIC_F0)),
            specular_weight: Scalar.splat_f32(1.0),
            clearcoat: None,
            sheen: None,
            transmission: transmission.map(|t| TransmissionLayer {
                factor: Scalar.splat_f32(t),
                ..layer(0.0, v)
            }),
        };
        lane0(pbr::shade(Scalar, &lighting, &surface, &splat3(Vec3::ZERO)))
    };
    let through = shade(-2.0, Some(1.0));
    assert!(through.x > 0.1, "{through}");
    assert_eq!(shade(-2.0, None), Vec3::ZERO);
    // The transmitted lobe at N·H = 1 (light straight behind): × (1 − F) c_diff D V NdotL.
    let alpha = 0.3f32 * 0.3;
    let d = 1.0 / (std::f32::consts::PI * alpha * alpha);
    // NdotL = NdotV = 1: V = 0.5 / (1 + 1); the light's radiance is 4 / 2².
    let expected = 4.0 / 4.0 * (1.0 - DIELECTRIC_F0) * d * 0.25;
    assert!(
        (through.x - expected).abs() / expected < 1e-4,
        "{through} vs {expected}"
    );
    // A fully transmissive pane lit from the front keeps its reflection and loses its diffuse
    // light, (1 − F) c_diff / π (normal incidence, radiance 1).
    let front = shade(2.0, Some(1.0));
    let opaque = shade(2.0, None);
    let diffuse = (1.0 - DIELECTRIC_F0) / std::f32::consts::PI;
    assert!(
        ((opaque.x - front.x) - diffuse).abs() < 1e-5,
        "{front} vs {opaque}"
    );
}

#[test]
fn the_backdrop_memory_is_counted_at_its_size() {
    assert_eq!(
        backdrop_bytes(640, 480),
        640 * 480 * BACKDROP_BYTES_PER_PIXEL
    );
    // A 4K frame's backdrop is scaled to 2048 wide.
    assert_eq!(
        backdrop_bytes(4096, 2160),
        2048 * 1080 * BACKDROP_BYTES_PER_PIXEL
    );
    let scene = |shading, transmission| crate::scene::Scene {
        shading,
        materials: vec![crate::scene::Material {
            transmission,
            ..crate::scene::Material::default()
        }],
        ..crate::scene::Scene::default()
    };
    use crate::scene::Shading::{Lambert, Pbr};
    assert!(scene(Pbr, 0.5).has_transmission());
    assert!(!scene(Pbr, 0.0).has_transmission());
    assert!(!scene(Lambert, 0.5).has_transmission());
}
