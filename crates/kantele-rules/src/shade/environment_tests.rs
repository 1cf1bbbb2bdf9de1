//! Tests of the environment's preparation and lookups.

use glam::{Vec2, Vec3};
use kantele_lanes::{dispatch, Isa, LaneKernel};

use super::prepare::{equirect_direction, with_border};
use super::*;

/// Octahedral encoding and decoding are inverse, and the border repeats the texel across
/// each edge (so a read at the edge blends with its true neighbour).
#[test]
fn octahedral_mapping_round_trips() {
    for i in 0..500 {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / 500.0;
        let phi = i as f32 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let back = octahedral_decode(octahedral_encode(d));
        assert!((back - d).length() < 1e-5, "{d} -> {back}");
    }
    // A map whose texels hold their own direction reads back (close to) the direction
    // asked for everywhere, the folded half included.
    let size = 32;
    let inner: Vec<Vec3> = (0..size * size)
        .map(|i| {
            octahedral_decode(Vec2::new(
                ((i % size) as f32 + 0.5) / size as f32,
                ((i / size) as f32 + 0.5) / size as f32,
            ))
        })
        .collect();
    let level = with_border(size as u32, &inner);
    for i in 0..2000 {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
        let phi = i as f32 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let read = level.sample(d);
        assert!((read - d).length() < 0.12, "{d}: {read}");
    }
}

/// The split-sum table: `A + B` (a white metal's directional albedo) is at most 1, is close
/// to 1 for smooth surfaces, and falls with roughness at grazing angles.
#[test]
fn brdf_table_is_an_albedo() {
    for j in 0..BRDF_TABLE_SIZE {
        for i in 0..BRDF_TABLE_SIZE {
            let [a, b] = brdf_table()[j * BRDF_TABLE_SIZE + i];
            assert!(
                a >= 0.0 && b >= 0.0 && a + b <= 1.0 + 1e-3,
                "({i}, {j}): {a} {b}"
            );
        }
    }
    let [a, b] = brdf_ab(0.9, 0.05);
    assert!(a + b > 0.97, "{a} {b}");
    let [a, b] = brdf_ab(0.2, 1.0);
    assert!(a + b < 0.8, "{a} {b}");
}

/// A bright spot in the environment is seen in a mirror (roughness 0) only near its direction,
/// and spreads with roughness while its total stays put.
#[test]
fn prefiltering_spreads_a_spot_with_roughness() {
    let (w, h) = (128u32, 64u32);
    let spot = Vec3::new(0.0, 0.0, -1.0);
    let texels: Vec<Vec3> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = equirect_direction(x, y, w, h);
            if d.dot(spot) > 0.98 {
                Vec3::splat(10.0)
            } else {
                Vec3::splat(0.1)
            }
        })
        .collect();
    let env = Environment::from_equirect(w, h, &texels).expect("environment");
    let light = EnvironmentLight {
        environment: Arc::new(env),
        intensity: 1.0,
        rotation: 0.0,
    };
    let aside = Vec3::new(1.0, 0.0, -1.0).normalize();
    let mirror_centre = light.specular(spot, 0.0).x;
    let mirror_aside = light.specular(aside, 0.0).x;
    assert!(
        mirror_centre > 5.0 && mirror_aside < 0.2,
        "{mirror_centre} {mirror_aside}"
    );
    let rough_centre = light.specular(spot, 0.6).x;
    let rough_aside = light.specular(aside, 0.6).x;
    assert!(rough_centre < mirror_centre && rough_aside > mirror_aside);
    // Rotating the environment by 90° about +Y moves the spot from −Z to −X... seen from a
    // direction that was aside.
    let turned = EnvironmentLight {
        rotation: std::f32::consts::FRAC_PI_2,
        ..light.clone()
    };
    let moved = turned.specular(Vec3::new(-1.0, 0.0, 0.0), 0.0).x;
    assert!(moved > 5.0, "rotated spot: {moved}");
}

/// The studio has a dark floor, a brighter ceiling and is neutral (grey).
#[test]
fn studio_is_neutral_and_lit_from_above() {
    let studio = EnvironmentLight::studio();
    let up = studio.specular(Vec3::Y, 1.0);
    let down = studio.specular(-Vec3::Y, 1.0);
    assert!(up.x > 2.0 * down.x, "{up} {down}");
    assert!(up.x == up.y && up.y == up.z);
}

/// Malformed sources are refused with an error, not a panic.
#[test]
fn bad_sources_are_refused() {
    assert!(Environment::from_equirect(0, 0, &[]).is_err());
    assert!(Environment::from_equirect(4, 2, &[Vec3::ONE; 3]).is_err());
    let nan = vec![Vec3::NAN; 8];
    let env = Environment::from_equirect(4, 2, &nan).expect("NaN texels count as 0");
    assert!(env.irradiance_sh.iter().all(|c| *c == Vec3::ZERO));
}

/// Texels up to `f32::MAX` are clamped to [`MAX_RADIANCE`]: every prepared value (the levels'
/// texels, the harmonics) stays finite, as the lane lookups' reads of a row's two texels
/// require, and a lookup gives a finite radiance of that order.
#[test]
fn the_brightest_sources_prepare_finite_values() {
    let (width, height) = (64u32, 32u32);
    let texels: Vec<Vec3> = (0..width * height)
        .map(|i| match i % 3 {
            0 => Vec3::splat(f32::MAX),
            1 => Vec3::new(3e38, 1.0, 2e37),
            _ => Vec3::splat(MAX_RADIANCE),
        })
        .collect();
    let env = Environment::from_equirect(width, height, &texels).expect("an environment");
    assert!(env.irradiance_sh.iter().all(|c| c.is_finite()));
    for level in &env.levels {
        assert!(level.texels.iter().flatten().all(|c| c.is_finite()));
    }
    let light = EnvironmentLight {
        environment: Arc::new(env),
        intensity: 1.0,
        rotation: 0.0,
    };
    let radiance = light.specular(Vec3::new(0.3, 0.5, -0.8), 0.4);
    assert!(
        radiance.is_finite() && radiance.max_element() > 1e29,
        "{radiance}"
    );
}

/// Directions spread over the sphere (a Fibonacci spiral), some of them not unit.
fn spiral(i: usize, n: usize) -> Vec3 {
    let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
    let phi = i as f32 * 2.399_963;
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z) * (0.5 + (i % 3) as f32)
}

/// The specular lookup, written with the scalar reads of the levels: the reference the lane
/// lookup must match bit for bit.
fn specular_from_levels(environment: &Environment, r: Vec3, roughness: f32) -> Vec3 {
    let d = r.normalize_or_zero();
    let last = (SPECULAR_LEVELS - 1) as f32;
    let lod = if roughness.is_finite() {
        (roughness * last).clamp(0.0, last)
    } else {
        last
    };
    let level = lod.floor();
    let t = lod - level;
    let lo = environment.levels[level as usize].sample(d);
    if t == 0.0 {
        return lo;
    }
    let hi = environment.levels[(level as usize + 1).min(SPECULAR_LEVELS - 1)].sample(d);
    lo + (hi - lo) * t
}

/// The split-sum lookup with scalar reads of the table.
fn brdf_from_table(n_dot_v: f32, roughness: f32) -> [f32; 2] {
    let n = BRDF_TABLE_SIZE as f32;
    let coordinate = |v: f32| {
        let v = if v.is_finite() { v } else { 1.0 };
        (v * n - 0.5).clamp(0.0, n - 1.0)
    };
    let (x, y) = (coordinate(n_dot_v), coordinate(roughness));
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let size = BRDF_TABLE_SIZE;
    let (x0, y0) = (x0 as usize, y0 as usize);
    let (x1, y1) = ((x0 + 1).min(size - 1), (y0 + 1).min(size - 1));
    let t = |x: usize, y: usize| brdf_table()[y * size + x];
    let mut out = [0.0; 2];
    for (c, o) in out.iter_mut().enumerate() {
        let top = t(x0, y0)[c] + (t(x1, y0)[c] - t(x0, y0)[c]) * fx;
        let bottom = t(x0, y1)[c] + (t(x1, y1)[c] - t(x0, y1)[c]) * fx;
        *o = top + (bottom - top) * fy;
    }
    out
}

/// Eight lanes of lookups: specular radiance and the split-sum terms.
struct Lookups<'a> {
    light: &'a EnvironmentLight,
    directions: [Vec3; 8],
    roughness: [f32; 8],
    n_dot_v: [f32; 8],
}

impl LaneKernel for Lookups<'_> {
    type Output = [[f32; 8]; 5];

    fn run<L: Lanes>(self, lanes: L) -> Self::Output {
        let component = |c: usize| lanes.f32_from_array(self.directions.map(|d| d[c]));
        let r = [component(0), component(1), component(2)];
        let roughness = lanes.f32_from_array(self.roughness);
        let s = self.light.specular_lanes(lanes, &r, roughness);
        let ab = self
            .light
            .brdf_lanes(lanes, lanes.f32_from_array(self.n_dot_v), roughness);
        [
            s[0].to_array(),
            s[1].to_array(),
            s[2].to_array(),
            ab[0].to_array(),
            ab[1].to_array(),
        ]
    }
}

/// Each lane of the lane lookups reads its own levels and cells: the same bits as the scalar
/// reads of the levels and the table, on every instruction set, for directions all around
/// (unit or not, zero), every roughness between the levels and outside [0, 1], and NaN.
#[test]
fn lane_lookups_read_the_levels_bit_for_bit() {
    let light = EnvironmentLight::studio();
    let n = 400;
    let mut lookups = Vec::new();
    for chunk in 0..n / 8 {
        let mut directions = [Vec3::ZERO; 8];
        let mut roughness = [0.0f32; 8];
        let mut n_dot_v = [0.0f32; 8];
        for k in 0..8 {
            let i = chunk * 8 + k;
            directions[k] = if i == 5 { Vec3::ZERO } else { spiral(i, n) };
            roughness[k] = match i % 29 {
                27 => f32::NAN,
                28 => 1.7,
                j => j as f32 / 25.0 - 0.04,
            };
            n_dot_v[k] = match i % 31 {
                30 => f32::INFINITY,
                j => j as f32 / 28.0 - 0.05,
            };
        }
        lookups.push((directions, roughness, n_dot_v));
    }
    for isa in Isa::supported() {
        for &(directions, roughness, n_dot_v) in &lookups {
            let got = dispatch(
                isa,
                Lookups {
                    light: &light,
                    directions,
                    roughness,
                    n_dot_v,
                },
            );
            for k in 0..8 {
                let expected =
                    specular_from_levels(&light.environment, directions[k], roughness[k]);
                let [a, b] = brdf_from_table(n_dot_v[k], roughness[k]);
                let lane = [got[0][k], got[1][k], got[2][k], got[3][k], got[4][k]];
                assert_eq!(
                    lane.map(f32::to_bits),
                    [expected.x, expected.y, expected.z, a, b].map(f32::to_bits),
                    "{isa}: direction {}, roughness {}, NdotV {}",
                    directions[k],
                    roughness[k],
                    n_dot_v[k]
                );
            }
        }
    }
}
