//! What the shading rules' tests share: one-lane values and the white furnace's lighting.

use std::sync::Arc;

use glam::Vec3;
use kantele_lanes::{F32x8, Lanes, Scalar};

use super::environment::{Environment, EnvironmentLight};
use super::pbr::{PbrLighting, Tonemap};

/// `v` in every lane of the scalar lanes.
pub(crate) fn splat3(v: Vec3) -> [<Scalar as Lanes>::F32; 3] {
    [
        Scalar.splat_f32(v.x),
        Scalar.splat_f32(v.y),
        Scalar.splat_f32(v.z),
    ]
}

/// Lane 0 of three scalar lanes.
pub(crate) fn lane0(v: [<Scalar as Lanes>::F32; 3]) -> Vec3 {
    Vec3::new(v[0].extract(0), v[1].extract(0), v[2].extract(0))
}

/// A uniform environment of radiance 1 (a 64 × 32 white image).
pub(crate) fn white_environment() -> Environment {
    let white = vec![Vec3::ONE; 64 * 32];
    Environment::from_equirect(64, 32, &white).expect("environment")
}

/// The white furnace seen from `eye`: [`white_environment`] at intensity 1, unrotated, no
/// punctual lights, no exposure and no tone map.
pub(crate) fn furnace_lighting(eye: Vec3) -> PbrLighting {
    PbrLighting {
        lights: Vec::new(),
        environment: Some(EnvironmentLight {
            environment: Arc::new(white_environment()),
            intensity: 1.0,
            rotation: 0.0,
        }),
        eye,
        exposure: 1.0,
        tonemap: Tonemap::None,
        transmission: None,
    }
}
