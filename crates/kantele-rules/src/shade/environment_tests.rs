//! Tests of the environment's preparation and lookups.

use glam::{Vec2, Vec3};

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
